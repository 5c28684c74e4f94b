/* blendtool vdb: the scene's field as an OpenVDB narrow-band level set
 * (libblend's lb_level_set_create, written by the lbvdb module). */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char CMD[] = "vdb";

static bt_vdb api; /* one process, loaded once */
static int loaded;

const bt_vdb *bt_vdb_get(const char *cmd) {
    if (loaded) return &api;
    char why[3 * (PATH_MAX + 64) + 512];
    void *h = bt_module_open("LIBBLEND_VDB", "liblbvdb.so", "OpenVDB module", why, sizeof why);
    if (h) {
        api.level_set_file =
            (int (*)(const lb_level_set *, double, const lbv_meta *, size_t, const char *, unsigned,
                     unsigned char **, size_t *, char *, size_t))dlsym(h, "lbv_level_set_file");
        if (!api.level_set_file) {
            snprintf(why, sizeof why,
                     "the OpenVDB module liblbvdb.so lacks its functions (not the one built "
                     "with this blendtool)");
            dlclose(h);
            h = NULL;
        }
    }
    if (!h) {
        bt_error(cmd,
                 "%s; allowed: install OpenVDB 10 (Debian package libopenvdb10.0, or "
                 "libopenvdb-dev to build blendtool) or set LIBBLEND_VDB",
                 why);
        return NULL;
    }
    loaded = 1;
    return &api;
}

/* a number in [lo, hi] */
static int parse_real(const char *opt, const char *val, double lo, double hi, const char *what,
                      double *out) {
    char *end = NULL;
    errno = 0;
    const double t = strtod(val, &end);
    if (errno || end == val || *end || !(t >= lo && t <= hi)) {
        bt_error(CMD, "%s %s: expected %s", opt, val, what);
        return -1;
    }
    *out = t;
    return 0;
}

typedef struct vdb_args {
    const char *out, *scene_path;
    lb_level_set_options o;
    int have_bounds, have_res, quiet, blender;
    bt_set sets[BT_MAX_SETS];
    size_t nsets;
} vdb_args;

static int parse_grids(const char *val, unsigned *flags) {
    const char *p = val;
    *flags = 0;
    while (*p) {
        const size_t n = strcspn(p, ",");
        if (n == 5 && strncmp(p, "value", 5) == 0)
            *flags |= LB_LEVEL_SET_FIELD;
        else if (n == 8 && strncmp(p, "gradient", 8) == 0)
            *flags |= LB_LEVEL_SET_GRADIENT;
        else if (!(n == 7 && strncmp(p, "surface", 7) == 0)) {
            bt_error(CMD,
                     "--grids %s: unknown grid \"%.*s\"; allowed: a comma-separated list of "
                     "surface (always written), value, gradient",
                     val, (int)n, p);
            return -1;
        }
        p += n;
        if (*p == ',') ++p;
    }
    return 0;
}

static int parse_args(int argc, char **argv, vdb_args *A) {
    const char *val = NULL;
    memset(A, 0, sizeof *A);
    lb_level_set_options_init(&A->o);
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option(CMD, argc, argv, &i, "-o", &val)) ||
            (r = bt_option(CMD, argc, argv, &i, "--output", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            A->out = val;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--resolution", &val))) {
            long n = 0;
            if (r < 0 ||
                bt_parse_long(CMD, "--resolution", val, 1, LB_LEVEL_SET_MAX_VOXELS_PER_AXIS,
                              "voxels along the longest side", &n))
                return BT_EXIT_BAD_INPUT;
            A->o.resolution = (unsigned)n;
            A->have_res = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--voxel-size", &val))) {
            if (r < 0 || parse_real("--voxel-size", val, 1e-300, HUGE_VAL,
                                    "a positive voxel size in scene units", &A->o.voxel_size))
                return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--band", &val))) {
            char what[96];
            snprintf(what, sizeof what, "the band's half width in voxels, 1 to %g",
                     LB_LEVEL_SET_MAX_BAND);
            if (r < 0 || parse_real("--band", val, 1.0, LB_LEVEL_SET_MAX_BAND, what, &A->o.band))
                return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--bounds", &val))) {
            if (r < 0 || bt_bounds_arg(CMD, val, A->o.bmin, A->o.bmax)) return BT_EXIT_BAD_INPUT;
            A->have_bounds = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--voxel-centres", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            if (strcmp(val, "openvdb") && strcmp(val, "blender")) {
                bt_error(CMD,
                         "--voxel-centres %s; allowed: openvdb (voxel (i, j, k) at (i H, j H, "
                         "k H): OpenVDB, Houdini) or blender (placed so that Blender, which "
                         "puts voxel centres half a voxel up, shows them there)",
                         val);
                return BT_EXIT_BAD_INPUT;
            }
            A->blender = !strcmp(val, "blender");
        } else if ((r = bt_option(CMD, argc, argv, &i, "--grids", &val))) {
            if (r < 0 || parse_grids(val, &A->o.flags)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--threads", &val))) {
            if (r < 0 || bt_parse_threads(CMD, val, &A->o.threads)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--set", &val))) {
            if (r < 0 || bt_set_arg(CMD, val, A->sets, &A->nsets, BT_MAX_SETS))
                return BT_EXIT_BAD_INPUT;
        } else if (strcmp(argv[i], "--quiet") == 0 || strcmp(argv[i], "-q") == 0) {
            A->quiet = 1;
        } else if (bt_scene_arg(CMD, argv[i], &A->scene_path)) {
            return BT_EXIT_BAD_INPUT;
        }
    }
    if (A->have_res && A->o.voxel_size > 0.0) {
        bt_error(CMD, "--resolution and --voxel-size both given; allowed: one of them (the "
                      "voxel size, or the voxels along the longest side)");
        return BT_EXIT_BAD_INPUT;
    }
    if (!A->scene_path || !A->out) {
        bt_error(CMD, "%s; usage: blendtool vdb SCENE -o OUT.vdb",
                 !A->scene_path ? "no scene given" : "no output given (-o OUT.vdb)");
        return BT_EXIT_BAD_INPUT;
    }
    return BT_EXIT_OK;
}

int bt_vdb_bytes(const char *cmd, const char *scene_path, const lb_level_set *ls, int blender,
                 const uint64_t hash[2], const bt_set *sets, size_t nsets, unsigned threads,
                 unsigned char **data, size_t *size) {
    const bt_vdb *V = bt_vdb_get(cmd);
    if (!V) return BT_EXIT_INTERNAL;
    char hex[33], settings[160], params[4096], err[1024] = "";
    bt_hash_hex(hash, hex);
    snprintf(settings, sizeof settings, "voxel_size %.17g band %g voxel_centres %s", ls->voxel_size,
             ls->band, blender ? "blender" : "openvdb");
    size_t o = 0;
    params[0] = '\0';
    for (size_t i = 0; i < nsets && o + 1 < sizeof params; ++i) {
        const int n = snprintf(params + o, sizeof params - o, "%s%s", i ? " " : "", sets[i].path);
        if (n > 0) o += (size_t)n;
    }
    const lbv_meta meta[4] = {{"libblend:scene_hash", hex},
                              {"libblend:version", BT_VERSION},
                              {"libblend:level_set", settings},
                              {"libblend:parameters", params}};
    if (V->level_set_file(ls, blender ? -0.5 : 0.0, meta, 4, hex, threads, data, size, err,
                          sizeof err)) {
        bt_error(cmd, "%s: writing the level set failed: %s", scene_path, err);
        return BT_EXIT_INTERNAL;
    }
    return BT_EXIT_OK;
}

static int run(int argc, char **argv) {
    vdb_args A;
    int rc = parse_args(argc, argv, &A);
    if (rc) return rc;
    lb_scene *scene = NULL;
    uint64_t hash[2] = {0, 0};
    rc = bt_load_scene_region(CMD, A.scene_path, A.sets, A.nsets, A.have_bounds, A.o.bmin, A.o.bmax,
                              &scene, hash);
    if (rc) return rc;
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_level_set *ls = NULL;
    unsigned char *bytes = NULL;
    size_t len = 0;
    bt_out w = {0};
    if ((rc = bt_compile(CMD, A.scene_path, scene, &ev))) goto done;
    /* the module and the output path are checked before the work */
    if (!bt_vdb_get(CMD)) {
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    if ((rc = bt_output_open(CMD, A.out, &w))) goto done;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const lb_status s = lb_level_set_create(ev, &A.o, &ls, &e);
    if (s) {
        rc = bt_fail(CMD, A.scene_path, s, &e);
        goto done;
    }
    if ((rc = bt_vdb_bytes(CMD, A.scene_path, ls, A.blender, hash, A.sets, A.nsets, A.o.threads,
                           &bytes, &len)))
        goto done;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (fwrite(bytes, 1, len, w.f) != len) {
        bt_error(CMD, "%s: writing the level set failed (%s); nothing was written", A.out,
                 strerror(errno));
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    if ((rc = bt_output_commit(CMD, &w))) goto done;
    if (!A.quiet)
        printf("%s: %zu active voxels in %zu leaves, voxel size %g, band %g voxels, %zu bytes, "
               "%.3f s\n",
               A.out, ls->nactive, ls->nleaves, ls->voxel_size, ls->band, len,
               (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
done:
    bt_output_discard(&w);
    free(bytes);
    lb_level_set_free(ls);
    lb_evaluator_free(ev);
    lb_scene_free(scene);
    return rc;
}

const bt_command bt_cmd_vdb = {
    "vdb", "the scene as an OpenVDB narrow-band level set (Blender, Houdini)",
    "usage: blendtool vdb SCENE -o OUT.vdb [--resolution N | --voxel-size H] [--band W]\n"
    "                     [--bounds x0,y0,z0,x1,y1,z1] [--grids value,gradient]\n"
    "                     [--voxel-centres openvdb|blender]\n"
    "                     [--threads N] [--quiet] [--set PATH=VALUE]...\n\n"
    "Writes the scene's surface inside the region (the scene's bounds, or --bounds) as\n"
    "an OpenVDB level set: a float grid named \"surface\" of class level set, in scene\n"
    "units (voxel (i, j, k) at (i H, j H, k H)), holding the signed distance estimate\n"
    "f / |grad f| (negative inside) on the voxels within W voxels of the surface and\n"
    "the right sign everywhere else. Blender imports it as a Volume object (Volume to\n"
    "Mesh turns it back into a surface), Houdini as a VDB primitive. Only the leaves\n"
    "(8^3 voxels) the field's interval bounds cannot rule out are computed. The\n"
    "grids carry the scene's hash, libblend's version, the voxel size, band and voxel\n"
    "centres, and the --set values as string metadata.\n"
    "  --resolution N  voxels along the region's longest side (default 128, at most 8192)\n"
    "  --voxel-size H  the voxel size instead of a resolution (at most 8192 voxels per axis)\n"
    "  --band W        the band's half width in voxels, 1 to 32 (default 3, OpenVDB's)\n"
    "  --voxel-centres openvdb (default): voxel (i, j, k) at (i H, j H, k H), as OpenVDB\n"
    "                  and Houdini read it; blender: the transform moved by -H/2 on each\n"
    "                  axis, so that Blender (which puts voxel centres at index + 1/2)\n"
    "                  shows the surface where it is\n"
    "  --grids LIST    extra grids on the band's voxels: value (the field f itself),\n"
    "                  gradient (grad f, a covariant vector grid)\n"
    "  --threads N     0 = one per CPU (default), 1 = single-threaded; the file is the\n"
    "                  same for every thread count\n"
    "  --quiet         no summary line\n"
    "  --set PATH=VALUE  override a scene value first (VALUE is JSON); repeatable\n"
    "Ctrl-C (SIGINT), SIGTERM and SIGHUP cancel at any phase: nothing is written. The\n"
    "output appears only when complete, byte for byte the same on every run.\n"
    "Exit status: 0 success, 2 bad scene or options (a band or voxel count out of range,\n"
    "or more leaves near the surface than the memory cap allows), 1 internal failure,\n"
    "OpenVDB missing or failure writing OUT, 130 / 143 / 129 ended by SIGINT / SIGTERM /\n"
    "SIGHUP.\n",
    run};
