// lbvdb: level sets written through OpenVDB (lbvdb.h is the contract).
#include "lbvdb.h"

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <cstring>
#include <exception>
#include <mutex>
#include <sstream>
#include <string>

namespace {

void say(char *err, size_t errlen, const char *what) {
    if (err && errlen) std::snprintf(err, errlen, "%s", what);
}

template <typename GridT, typename Fill>
typename GridT::Ptr band_grid(const lb_level_set *ls, double shift,
                              typename GridT::ValueType background, Fill fill) {
    auto grid = GridT::create(background);
    auto &tree = grid->tree();
    for (size_t i = 0; i < ls->nleaves; ++i) {
        const int32_t *o = ls->origins + 3 * i;
        auto *leaf = tree.touchLeaf(openvdb::Coord(o[0], o[1], o[2]));
        const uint64_t *act = ls->active + 8 * i;
        for (openvdb::Index n = 0; n < LB_LEVEL_SET_LEAF_VOXELS; ++n) {
            const bool on = (act[n / 64] >> (n % 64)) & 1u;
            const typename GridT::ValueType v = fill(i, n, on);
            if (on)
                leaf->setValueOn(n, v);
            else
                leaf->setValueOff(n, v);
        }
    }
    auto xform = openvdb::math::Transform::createLinearTransform(ls->voxel_size);
    if (shift != 0.0) xform->postTranslate(openvdb::Vec3d(shift * ls->voxel_size));
    grid->setTransform(xform);
    return grid;
}

void restore_signs(openvdb::FloatGrid &grid, const lb_level_set *ls) {
    auto &tree = grid.tree();
    for (size_t i = 0; i < ls->nleaves; ++i) {
        const int32_t *o = ls->origins + 3 * i;
        auto *leaf = tree.probeLeaf(openvdb::Coord(o[0], o[1], o[2]));
        if (!leaf) continue;
        const uint64_t *act = ls->active + 8 * i;
        for (openvdb::Index n = 0; n < LB_LEVEL_SET_LEAF_VOXELS; ++n) {
            const int32_t x = o[0] + static_cast<int32_t>(n >> 6),
                          y = o[1] + static_cast<int32_t>((n >> 3) & 7u),
                          z = o[2] + static_cast<int32_t>(n & 7u);
            const bool in = x >= ls->imin[0] && x <= ls->imax[0] && y >= ls->imin[1] &&
                            y <= ls->imax[1] && z >= ls->imin[2] && z <= ls->imax[2];
            if (in && !((act[n / 64] >> (n % 64)) & 1u))
                leaf->setValueOnly(n, ls->values[i * LB_LEVEL_SET_LEAF_VOXELS + n]);
        }
    }
}

// OpenVDB writes a random UUID into every file header (magic, file version,
// library version, a flag, then 36 characters): replaced by one made from
// the seed, after checking the bytes there are a UUID
bool set_uuid(std::string &bytes, const char *seed) {
    const size_t at = 8 + 4 + 4 + 4 + 1;
    if (bytes.size() < at + 36 || std::strlen(seed) < 32) return false;
    for (size_t k = 0; k < 36; ++k) {
        const char c = bytes[at + k];
        const bool dash = k == 8 || k == 13 || k == 18 || k == 23;
        if (dash ? c != '-' : !std::isxdigit(static_cast<unsigned char>(c))) return false;
    }
    for (size_t k = 0, s = 0; k < 36; ++k)
        if (!(k == 8 || k == 13 || k == 18 || k == 23))
            bytes[at + k] = static_cast<char>(std::tolower(static_cast<unsigned char>(seed[s++])));
    return true;
}

} // namespace

static int file_bytes(const lb_level_set *ls, double shift, const lbv_meta *meta, size_t nmeta,
                      const char *uuid_seed, unsigned char **data, size_t *size, char *err,
                      size_t errlen) {
    try {
        const float bg = ls->background;
        openvdb::GridPtrVec grids;
        auto surface =
            band_grid<openvdb::FloatGrid>(ls, shift, bg, [&](size_t i, openvdb::Index n, bool) {
                return ls->values[i * LB_LEVEL_SET_LEAF_VOXELS + n];
            });
        surface->setName("surface");
        surface->setGridClass(openvdb::GRID_LEVEL_SET);
        // the flood fill gives the tiles outside the band their sign, and
        // also rewrites inactive voxels inside the leaves from their
        // neighbours' signs; where libblend evaluated such a voxel (inside the
        // region) its own sign is the field's, which the fill can get wrong
        // (a voxel outside the solid where the gradient vanishes, beside
        // inside voxels): those are put back
        openvdb::tools::signedFloodFill(surface->tree());
        restore_signs(*surface, ls);
        grids.push_back(surface);
        if (ls->fields) {
            auto value = band_grid<openvdb::FloatGrid>(
                ls, shift, 0.0f, [&](size_t i, openvdb::Index n, bool on) {
                    return on ? ls->fields[i * LB_LEVEL_SET_LEAF_VOXELS + n] : 0.0f;
                });
            value->setName("value");
            value->setGridClass(openvdb::GRID_UNKNOWN);
            grids.push_back(value);
        }
        if (ls->gradients) {
            const openvdb::Vec3f zero(0.0f);
            auto gradient = band_grid<openvdb::Vec3SGrid>(
                ls, shift, zero, [&](size_t i, openvdb::Index n, bool on) {
                    const float *g = ls->gradients + (i * LB_LEVEL_SET_LEAF_VOXELS + n) * 3;
                    return on ? openvdb::Vec3f(g[0], g[1], g[2]) : zero;
                });
            gradient->setName("gradient");
            gradient->setVectorType(openvdb::VEC_COVARIANT);
            grids.push_back(gradient);
        }
        for (auto &g : grids)
            for (size_t k = 0; k < nmeta; ++k)
                g->insertMeta(meta[k].key, openvdb::StringMetadata(meta[k].value));
        std::ostringstream os(std::ios_base::out | std::ios_base::binary);
        openvdb::io::Stream(os).write(grids);
        std::string bytes = os.str();
        if (!set_uuid(bytes, uuid_seed)) {
            say(err, errlen,
                "OpenVDB's file header is not the expected one (no UUID where "
                "version 10 writes it)");
            return -1;
        }
        *data = static_cast<unsigned char *>(std::malloc(bytes.size() ? bytes.size() : 1));
        if (!*data) {
            say(err, errlen, "out of memory");
            return -1;
        }
        std::memcpy(*data, bytes.data(), bytes.size());
        *size = bytes.size();
        return 0;
    } catch (const std::exception &e) {
        say(err, errlen, e.what());
    } catch (...) {
        say(err, errlen, "OpenVDB failed");
    }
    return -1;
}

extern "C" int lbv_level_set_file(const lb_level_set *ls, double shift, const lbv_meta *meta,
                                  size_t nmeta, const char *uuid_seed, unsigned threads,
                                  unsigned char **data, size_t *size, char *err, size_t errlen) {
    *data = nullptr;
    *size = 0;
    int rc = -1;
    try {
        static std::once_flag once;
        std::call_once(once, [] { openvdb::initialize(); });
        // OpenVDB's threaded steps (the flood fill) run on TBB's workers: in
        // an arena of the caller's count (1: the calling thread alone, no
        // worker made), one per CPU for 0
        tbb::task_arena arena(threads ? static_cast<int>(threads) : tbb::task_arena::automatic);
        arena.execute(
            [&] { rc = file_bytes(ls, shift, meta, nmeta, uuid_seed, data, size, err, errlen); });
    } catch (const std::exception &e) {
        say(err, errlen, e.what());
    } catch (...) {
        say(err, errlen, "OpenVDB failed");
    }
    return rc;
}
