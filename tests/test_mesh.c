/* Meshing: topology (closed, consistently oriented, 2-manifold, Euler
 * characteristic), accuracy (every vertex on the surface, normals from the
 * gradient), volumes against exact formulas, no self-intersections, thread
 * independence, fields built to be ambiguous, the region cap, progress,
 * cancel and bad options. Topology and volume are computed here from the
 * arrays, independently of the mesher. */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"

#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "scenelist.h"
#include "testfs.h"
#include "../libblend/src/meshing/mesh_internal.h"

/* ---- helpers ---- */

typedef struct built {
    lb_scene *sc;
    lb_evaluator *ev;
    lb_mesh *m;
} built;

static void build_text(const char *text, const lb_mesh_options *o, built *B) {
    lb_error e = {LB_OK, ""};
    memset(B, 0, sizeof *B);
    if (lb_scene_parse(text, strlen(text), "test.json", &B->sc, &e) ||
        lb_evaluator_create(B->sc, &B->ev, &e) || lb_mesh_create(B->ev, o, &B->m, &e))
        fail_msg("%s", e.message);
}

/* path meshed at res cells with flags, threads and simplify (lb_mesh_options) */
static void build_file_s(const char *path, unsigned res, unsigned flags, int threads,
                         double simplify, built *B) {
    lb_error e = {LB_OK, ""};
    memset(B, 0, sizeof *B);
    if (lb_scene_load(path, &B->sc, &e) || lb_evaluator_create(B->sc, &B->ev, &e))
        fail_msg("%s: %s", path, e.message);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    assert_true(lb_scene_bounds(B->sc, o.bmin, o.bmax));
    o.resolution = res;
    o.flags = flags;
    o.threads = threads;
    o.simplify = simplify;
    if (lb_mesh_create(B->ev, &o, &B->m, &e)) fail_msg("%s: %s", path, e.message);
}

static void build_file(const char *path, unsigned res, unsigned flags, int threads, built *B) {
    build_file_s(path, res, flags, threads, 0.0, B);
}

static void unbuild(built *B) {
    lb_mesh_free(B->m);
    lb_evaluator_free(B->ev);
    lb_scene_free(B->sc);
}

static int cmp_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

typedef struct topo {
    int closed, oriented, manifold;
    long euler;
    size_t boundary_edges;
    double volume;
} topo;

/* Every directed edge once; closed when each has its reverse; manifold
 * when, in addition, the triangles around every vertex form one cycle. */
static topo topology(const lb_mesh *m) {
    topo t = {1, 1, 1, 0, 0, 0.0};
    const size_t nt = m->ntriangles, nv = m->nvertices;
    uint64_t *d = malloc((3 * nt + 1) * sizeof *d);
    assert_non_null(d);
    for (size_t i = 0; i < nt; ++i)
        for (int c = 0; c < 3; ++c) {
            const uint64_t a = m->triangles[3 * i + c], b = m->triangles[3 * i + (c + 1) % 3];
            d[3 * i + c] = a * nv + b;
            if (a == b) t.manifold = 0;
        }
    qsort(d, 3 * nt, sizeof *d, cmp_u64);
    size_t undirected = 0;
    for (size_t i = 0; i < 3 * nt; ++i) {
        if (i && d[i] == d[i - 1]) t.oriented = 0;
        const uint64_t a = d[i] / nv, b = d[i] % nv, r = b * nv + a;
        if (!bsearch(&r, d, 3 * nt, sizeof *d, cmp_u64)) {
            t.closed = 0;
            t.boundary_edges++;
            undirected++;
        } else if (a < b) {
            undirected++;
        }
    }
    /* vertex links: next[corner] around each vertex must be one cycle */
    size_t *first = calloc(nv + 1, sizeof *first);
    uint64_t *link = malloc((3 * nt + 1) * sizeof *link); /* (vertex, next, prev) packed */
    uint32_t *lnext = malloc((3 * nt + 1) * sizeof *lnext), *lprev = malloc((3 * nt + 1) * 4);
    assert_true(first && link && lnext && lprev);
    for (size_t i = 0; i < 3 * nt; ++i) first[m->triangles[i] + 1]++;
    for (size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
    size_t *fill = malloc((nv + 1) * sizeof *fill);
    assert_non_null(fill);
    memcpy(fill, first, (nv + 1) * sizeof *fill);
    for (size_t i = 0; i < nt; ++i)
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = m->triangles[3 * i + c];
            const size_t k = fill[v]++;
            lnext[k] = m->triangles[3 * i + (c + 1) % 3];
            lprev[k] = m->triangles[3 * i + (c + 2) % 3];
        }
    size_t used = 0;
    for (size_t v = 0; v < nv; ++v) {
        const size_t s = first[v], e = first[v + 1];
        if (s == e) continue;
        ++used;
        if (!t.closed) continue;
        /* walk: from corner s, the next corner is the one whose lnext is our lprev */
        size_t cur = s, steps = 0;
        do {
            size_t nx = e;
            for (size_t k = s; k < e; ++k)
                if (lnext[k] == lprev[cur]) {
                    nx = k;
                    break;
                }
            if (nx == e) break;
            cur = nx;
            ++steps;
        } while (cur != s && steps <= e - s);
        if (cur != s || steps != e - s) t.manifold = 0;
    }
    t.euler = (long)used - (long)undirected + (long)nt;
    for (size_t i = 0; i < nt; ++i) {
        const double *p = m->positions + 3 * (size_t)m->triangles[3 * i];
        const double *q = m->positions + 3 * (size_t)m->triangles[3 * i + 1];
        const double *r = m->positions + 3 * (size_t)m->triangles[3 * i + 2];
        t.volume += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                     p[2] * (q[0] * r[1] - q[1] * r[0])) /
                    6.0;
    }
    if (!t.closed) t.manifold = 0;
    free(d);
    free(first);
    free(link);
    free(lnext);
    free(lprev);
    free(fill);
    return t;
}

static void expect_closed_manifold(const char *what, const lb_mesh *m) {
    const topo t = topology(m);
    if (!t.closed || !t.oriented || !t.manifold || !(t.volume > 0.0))
        fail_msg("%s: closed %d oriented %d manifold %d volume %g (%zu triangles, %zu boundary "
                 "edges)",
                 what, t.closed, t.oriented, t.manifold, t.volume, m->ntriangles, t.boundary_edges);
}

static int setup(void **state) {
    (void)state;
    return collect_scenes();
}

#define HEAD "{\"format\": \"libblend-scene\", \"version\": 1, "

/* Every vertex of B's mesh on the surface of max(phi, region box) to 1e-6
 * cells, with the normal of the gradient there (what: for the messages). */
static void vertices_on_surface(const built *B, const char *what, tally_t *acc, tally_t *nrm) {
    const size_t n = B->m->nvertices;
    double *x = malloc(7 * (n ? n : 1) * sizeof *x);
    assert_non_null(x);
    double *y = x + n, *z = y + n, *v = z + n, *gx = v + n, *gy = gx + n, *gz = gy + n;
    for (size_t i = 0; i < n; ++i) {
        x[i] = B->m->positions[3 * i];
        y[i] = B->m->positions[3 * i + 1];
        z[i] = B->m->positions[3 * i + 2];
    }
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_evaluator_eval(B->ev, n, x, y, z, v, gx, gy, gz, 0, &e), LB_OK);
    double lo[3], hi[3];
    lb_scene_bounds(B->sc, lo, hi);
    const int soft = lb_scene_convention(B->sc) == LB_CONVENTION_SOFT;
    const double h = fmin(B->m->cell[0], fmin(B->m->cell[1], B->m->cell[2]));
    for (size_t i = 0; i < n; ++i) {
        /* phi_c written out here: the field, or the region box where it is larger */
        double phi = soft ? 0.5 - v[i] : v[i];
        double g[3] = {soft ? -gx[i] : gx[i], soft ? -gy[i] : gy[i], soft ? -gz[i] : gz[i]};
        const double P[3] = {x[i], y[i], z[i]};
        for (int d = 0; d < 3; ++d) {
            if (lo[d] - P[d] > phi) {
                phi = lo[d] - P[d];
                g[0] = g[1] = g[2] = 0.0;
                g[d] = -1.0;
            }
            if (P[d] - hi[d] > phi) {
                phi = P[d] - hi[d];
                g[0] = g[1] = g[2] = 0.0;
                g[d] = 1.0;
            }
        }
        const double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        tally_check(acc, fabs(phi) <= 1e-6 * h * gl,
                    "%s: vertex %zu: |phi| = %g, |grad| = %g, h = %g", what, i, fabs(phi), gl, h);
        const double *N = B->m->normals + 3 * i;
        const double dot = gl > 0.0 ? (N[0] * g[0] + N[1] * g[1] + N[2] * g[2]) / gl : 1.0;
        const double nl = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        tally_check(nrm, fabs(nl - 1.0) < 1e-9 && dot > 1.0 - 1e-9,
                    "%s: vertex %zu: normal length %g, cosine to the gradient %g", what, i, nl,
                    dot);
    }
    free(x);
}

/* ---- tests ---- */

/* Every scene, two resolutions: closed, oriented, manifold, positive volume;
 * every vertex on the surface of max(phi, region box) to 1e-6 cells, with
 * the normal of the gradient there. */
static void test_scenes_closed_and_accurate(void **state) {
    (void)state;
    tally_t acc = {"vertices on the surface", 0, 0, 0};
    tally_t nrm = {"normals from the gradient", 0, 0, 0};
    const unsigned res[2] = {24, 56};
    for (size_t s = 0; s < nscenes; ++s)
        for (int r = 0; r < 2; ++r) {
            built B;
            build_file(scene_paths[s], res[r], 0, 0, &B);
            char what[1100];
            snprintf(what, sizeof what, "%.1000s at %u", scene_paths[s], res[r]);
            assert_true(B.m->ntriangles > 100);
            expect_closed_manifold(what, B.m);
            vertices_on_surface(&B, what, &acc, &nrm);
            unbuild(&B);
        }
    tally_end(&acc, 100000);
    tally_end(&nrm, 100000);
}

/* The sharp shapes of tests/data/features, meshed after the scenes. */
static const char *const sharp[] = {"cube",          "rotated-cube",        "two-boxes",
                                    "cylinder-slab", "local-union-spheres", "clean-union-spheres"};
#define NSHARP (sizeof sharp / sizeof sharp[0])

/* Case s of the scenes then the sharp shapes into path: 0 when papers_only
 * and s is a scene that is not one of the papers' (skip it). */
static int case_path(size_t s, int papers_only, char *path, size_t n) {
    if (s < nscenes) {
        if (papers_only && !strstr(scene_paths[s], "/scenes/hsu")) return 0;
        snprintf(path, n, "%s", scene_paths[s]);
    } else {
        snprintf(path, n, "%s/tests/data/features/%s.json", SOURCE_DIR, sharp[s - nscenes]);
    }
    return 1;
}

/* The same mesh, bit for bit, for 1, 2 and 3 threads: every scene, and
 * with LB_MESH_FEATURES also the sharp shapes of tests/data/features (the
 * feature points are placed per block and flipped over the merged mesh),
 * then the sharp shapes, S1, S2 and the stool again simplified (features
 * and simplify = 0.1: the simplification's parallel passes, over regions
 * of 32 cells, 8 to 27 of them at 40 cells; every scene would take minutes
 * under ThreadSanitizer), and S2 and the stool meshed coarse first. */
static void test_threads_identical(void **state) {
    (void)state;
    for (int pass = 0; pass < 4; ++pass) {
        /* 0: the scenes; 1: the scenes and the sharp shapes with features;
         * 2: those again, simplified; 3: S2 and the stool meshed coarse
         * first (LB_MESH_COARSE_FIRST) */
        const unsigned flags = pass == 3 ? LB_MESH_COARSE_FIRST : pass ? LB_MESH_FEATURES : 0u;
        const double simplify = pass == 2 ? 0.1 : pass == 3 ? 0.25 : 0.0;
        for (size_t s = 0; s < nscenes + (pass == 1 || pass == 2 ? NSHARP : 0); ++s) {
            char path[1100];
            case_path(s, 0, path, sizeof path);
            if (pass == 2 && s < nscenes && !strstr(path, "/bench-s") &&
                !strstr(path, "-fig7-stool"))
                continue;
            if (pass == 3 && !strstr(path, "/bench-s2") && !strstr(path, "-fig7-stool")) continue;
            built A, B, C;
            build_file_s(path, 40, flags, 1, simplify, &A);
            build_file_s(path, 40, flags, 2, simplify, &B);
            build_file_s(path, 40, flags, 3, simplify, &C);
            const lb_mesh *ms[2] = {B.m, C.m};
            for (int k = 0; k < 2; ++k) {
                const lb_mesh *m = ms[k];
                if (m->nvertices != A.m->nvertices || m->ntriangles != A.m->ntriangles ||
                    memcmp(m->positions, A.m->positions, 3 * m->nvertices * sizeof(double)) ||
                    memcmp(m->normals, A.m->normals, 3 * m->nvertices * sizeof(double)) ||
                    memcmp(m->triangles, A.m->triangles, 3 * m->ntriangles * sizeof(uint32_t)))
                    fail_msg("%s (flags %u, simplify %g): %d threads differ from 1", path, flags,
                             simplify, k + 2);
            }
            unbuild(&A);
            unbuild(&B);
            unbuild(&C);
        }
    }
}

/* Volumes at 128 cells across against the exact ones, and the Euler
 * characteristic of a sphere (2) and a torus (0). */
static void test_volumes_and_euler(void **state) {
    (void)state;
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    o.resolution = 128;
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -1.5;
        o.bmax[d] = 1.5;
    }
    static const struct {
        const char *text;
        double volume;
        long euler;
    } cases[] = {
        {HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"sphere\", \"radius\": 1}}",
         4.0 / 3.0 * M_PI, 2},
        {HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"ellipsoid\", \"semi_axes\": [1.2, "
              "0.7, 0.45], \"rotate\": [20, 35, -10], \"translate\": [0.05, -0.1, 0.1]}}",
         4.0 / 3.0 * M_PI * 1.2 * 0.7 * 0.45, 2},
        {HEAD "\"convention\": \"soft\", \"root\": {\"type\": \"sphere\", \"radius\": 0.9, "
              "\"kernel\": \"blinn\"}}",
         4.0 / 3.0 * M_PI * 0.729, 2},
        {HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"torus\", \"major_radius\": 0.9, "
              "\"minor_radius\": 0.35, \"axis\": [0, 1, 1]}}",
         2.0 * M_PI * M_PI * 0.9 * 0.35 * 0.35, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        built B;
        build_text(cases[i].text, &o, &B);
        expect_closed_manifold(cases[i].text, B.m);
        const topo t = topology(B.m);
        const double rel = fabs(t.volume - cases[i].volume) / cases[i].volume;
        fprintf(stderr, "  case %zu: %zu triangles, volume %.6f (exact %.6f, %.3f %%), euler %ld\n",
                i, B.m->ntriangles, t.volume, cases[i].volume, 100.0 * rel, t.euler);
        assert_true(rel < 0.005);
        assert_int_equal(t.euler, cases[i].euler);
        unbuild(&B);
    }
}

/* The cube cases, checked from their loops alone (the manifold argument of
 * cubes.c): in every case each crossing edge (corners of opposite signs) is
 * a vertex of exactly one loop and no other edge is; and for every pair of
 * cells that share a face with the same corner signs on it, the segments the
 * two draw on that face (consecutive loop vertices both on the face) are the
 * same ones, in opposite directions. */
static int on_face(int p, int q, int axis, int side) {
    return ((p & axis) != 0) == side && ((q & axis) != 0) == side;
}

static int segments(const lb__mctable *t, int cfg, int axis, int side, int seg[][2]) {
    const lb__mccase *c = &t->c[cfg];
    int n = 0, off = 0;
    for (int l = 0; l < c->nloop; ++l) {
        for (int v = 0; v < c->len[l]; ++v) {
            const int a = c->e[off + v], b = c->e[off + (v + 1) % c->len[l]];
            int ap, aq, bp, bq;
            lb__cube_edge(a, &ap, &aq);
            lb__cube_edge(b, &bp, &bq);
            if (on_face(ap, aq, axis, side) && on_face(bp, bq, axis, side)) {
                seg[n][0] = a;
                seg[n][1] = b;
                ++n;
            }
        }
        off += c->len[l];
    }
    return n;
}

/* the cube edge of a neighbour across the face (axis, 1) <-> (axis, 0) */
static int across(int e, int axis) {
    int p, q;
    lb__cube_edge(e, &p, &q);
    for (int f = 0; f < 12; ++f) {
        int fp, fq;
        lb__cube_edge(f, &fp, &fq);
        if (fp == (p ^ axis) && fq == (q ^ axis)) return f;
    }
    return -1;
}

static void test_cube_cases(void **state) {
    (void)state;
    lb__mctable t;
    lb__mctable_init(&t);
    assert_int_equal(lb__mctable_check(&t), 1);
    size_t pairs = 0, segs = 0;
    int maxlen = 0, maxloops = 0;
    for (int cfg = 0; cfg < 256; ++cfg) {
        int seen[12] = {0}, off = 0;
        for (int l = 0; l < t.c[cfg].nloop; ++l) {
            if (t.c[cfg].len[l] > maxlen) maxlen = t.c[cfg].len[l];
            for (int v = 0; v < t.c[cfg].len[l]; ++v) ++seen[t.c[cfg].e[off + v]];
            off += t.c[cfg].len[l];
        }
        if (t.c[cfg].nloop > maxloops) maxloops = t.c[cfg].nloop;
        for (int e = 0; e < 12; ++e) {
            int p, q;
            lb__cube_edge(e, &p, &q);
            const int crossing = ((cfg >> p) & 1) != ((cfg >> q) & 1);
            if (seen[e] != crossing)
                fail_msg("case %d: cube edge %d appears %d times (crossing: %d)", cfg, e, seen[e],
                         crossing);
        }
    }
    for (int axis = 1; axis <= 4; axis <<= 1)
        for (int a = 0; a < 256; ++a)
            for (int b = 0; b < 256; ++b) {
                /* a's corners on its +axis face equal b's on its -axis face */
                int same = 1;
                for (int o = 0; o < 8; ++o)
                    if ((o & axis) && ((a >> o) & 1) != ((b >> (o ^ axis)) & 1)) same = 0;
                if (!same) continue;
                ++pairs;
                int sa[12][2], sb[12][2];
                const int na = segments(&t, a, axis, 1, sa), nb = segments(&t, b, axis, 0, sb);
                if (na != nb)
                    fail_msg("cases %d | %d (axis %d): %d and %d segments", a, b, axis, na, nb);
                for (int i = 0; i < na; ++i) {
                    int found = 0;
                    for (int j = 0; j < nb; ++j)
                        found += across(sa[i][0], axis) == sb[j][1] &&
                                 across(sa[i][1], axis) == sb[j][0];
                    if (found != 1)
                        fail_msg("cases %d | %d (axis %d): segment %d -> %d not reversed once "
                                 "across the face",
                                 a, b, axis, sa[i][0], sa[i][1]);
                }
                segs += (size_t)na;
            }
    fprintf(stderr,
            "  cube cases: %zu face-sharing pairs, %zu segments matched, loops of at most %d "
            "vertices, at most %d per cell\n",
            pairs, segs, maxlen, maxloops);
    assert_true(maxlen <= LB__MAXPOLY && maxloops <= 4);
}

/* LB_MESH_TETRAHEDRA, the Kuhn split: every scene closed and manifold, with
 * about three times the triangles of the cube polygons on the same grid. */
static void test_tetrahedra_option(void **state) {
    (void)state;
    size_t ncube = 0, ntet = 0;
    for (size_t s = 0; s < nscenes; ++s) {
        built A, B;
        build_file(scene_paths[s], 32, 0, 0, &A);
        build_file(scene_paths[s], 32, LB_MESH_TETRAHEDRA, 0, &B);
        expect_closed_manifold(scene_paths[s], B.m);
        ncube += A.m->ntriangles;
        ntet += B.m->ntriangles;
        unbuild(&A);
        unbuild(&B);
    }
    fprintf(stderr, "  every scene at 32 cells: %zu triangles (cubes), %zu (tetrahedra), %.2fx\n",
            ncube, ntet, (double)ntet / (double)ncube);
    assert_true(ntet > 2.5 * ncube && ntet < 4.0 * ncube);
}

/* Fields built to be ambiguous for marching cubes: spheres on every other
 * node of a checkerboard (every cell face has diagonal inside corners),
 * two spheres touching exactly at a grid node (phi = 0 there), and a thin
 * torus whose tube is about one cell wide. */
static void test_ambiguous_fields(void **state) {
    (void)state;
    char *text = malloc(65536);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, 65536,
                                  HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"min\", "
                                       "\"args\": [");
    int first = 1;
    for (int k = 0; k < 6; ++k)
        for (int j = 0; j < 6; ++j)
            for (int i = 0; i < 6; ++i) {
                if ((i + j + k) % 2) continue;
                len += (size_t)snprintf(text + len, 65536 - len,
                                        "%s{\"type\": \"sphere\", \"center\": [%d, %d, %d], "
                                        "\"radius\": 0.74}",
                                        first ? "" : ", ", i, j, k);
                first = 0;
            }
    snprintf(text + len, 65536 - len, "]}}");
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -1.0;
        o.bmax[d] = 6.0;
    }
    /* cell size 1: the grid nodes are the lattice, every face ambiguous */
    o.cell_size = 1.0;
    o.flags = LB_MESH_OPEN_BOUNDARY;
    built B;
    build_text(text, &o, &B);
    expect_closed_manifold("checkerboard at cell size 1", B.m);
    unbuild(&B);
    o.flags = LB_MESH_OPEN_BOUNDARY | LB_MESH_TETRAHEDRA;
    build_text(text, &o, &B);
    expect_closed_manifold("checkerboard at cell size 1, tetrahedra", B.m);
    unbuild(&B);
    /* and at cell sizes that cut the spheres anywhere */
    const double sizes[3] = {0.5, 0.37, 0.21};
    for (int s = 0; s < 3; ++s) {
        o.cell_size = sizes[s];
        o.flags = 0;
        build_text(text, &o, &B);
        expect_closed_manifold("checkerboard", B.m);
        unbuild(&B);
    }
    free(text);
    /* touching at a node: min of two unit spheres at (+-1, 0, 0), node at 0 */
    static const char touch[] =
        HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"min\", \"args\": [{\"type\": "
             "\"sphere\", \"center\": [-1, 0, 0], \"radius\": 1}, {\"type\": \"sphere\", "
             "\"center\": [1, 0, 0], \"radius\": 1}]}}";
    o.cell_size = 0.25;
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -2.5;
        o.bmax[d] = 2.5;
    }
    build_text(touch, &o, &B);
    expect_closed_manifold("spheres touching at a node", B.m);
    unbuild(&B);
    static const char thin[] =
        HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"torus\", \"major_radius\": 1, "
             "\"minor_radius\": 0.06, \"axis\": [0.3, 1, 0.2]}}";
    o.cell_size = 0.1;
    build_text(thin, &o, &B);
    expect_closed_manifold("thin torus", B.m);
    unbuild(&B);
}

/* The region cuts a sphere in half: closed on the cut (half the volume),
 * or open with every boundary edge on the cutting plane. */
static void test_region_cap_and_open(void **state) {
    (void)state;
    static const char text[] =
        HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"sphere\", \"radius\": 1}}";
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    o.resolution = 96;
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -1.25;
        o.bmax[d] = 1.25;
    }
    o.bmax[2] = 0.0;
    built B;
    build_text(text, &o, &B);
    expect_closed_manifold("capped half sphere", B.m);
    topo t = topology(B.m);
    const double half = 2.0 / 3.0 * M_PI;
    assert_true(fabs(t.volume - half) / half < 0.005);
    double zmax = -INFINITY;
    for (size_t i = 0; i < B.m->nvertices; ++i) zmax = fmax(zmax, B.m->positions[3 * i + 2]);
    assert_true(zmax <= 1e-12);
    unbuild(&B);
    o.flags = LB_MESH_OPEN_BOUNDARY;
    build_text(text, &o, &B);
    t = topology(B.m);
    assert_false(t.closed);
    assert_true(t.oriented);
    assert_true(t.boundary_edges > 100);
    /* the open rim lies on the region's top face */
    for (size_t i = 0; i < B.m->nvertices; ++i) assert_true(B.m->positions[3 * i + 2] <= 1e-12);
    unbuild(&B);
}

/* ---- self-intersections: a triangle-triangle test over a grid ---- */

static int tri_tri(const lb_mesh *m, size_t i, size_t j) {
    return tris_cross(m->positions, m->triangles + 3 * i, m->triangles + 3 * j);
}

typedef struct entry {
    uint64_t cell;
    uint32_t tri;
} entry;

static int cmp_entry(const void *a, const void *b) {
    const entry *x = a, *y = b;
    return x->cell < y->cell ? -1 : x->cell > y->cell ? 1 : (x->tri > y->tri) - (x->tri < y->tri);
}

static size_t self_intersections(const lb_mesh *m, size_t *pairs) {
    /* bins of two cells: a triangle of the grid lies in one cell, so in at
     * most 2^3 bins (a simplified one in more: the array grows) */
    const double bin = 2.0 * fmax(m->cell[0], fmax(m->cell[1], m->cell[2]));
    size_t cap = 8 * m->ntriangles + 1, n = 0;
    entry *E = malloc(cap * sizeof *E);
    assert_non_null(E);
    for (size_t t = 0; t < m->ntriangles; ++t) {
        long lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            double a = INFINITY, b = -INFINITY;
            for (int c = 0; c < 3; ++c) {
                const double x = m->positions[3 * (size_t)m->triangles[3 * t + c] + d];
                a = fmin(a, x);
                b = fmax(b, x);
            }
            lo[d] = (long)floor((a - m->origin[d]) / bin);
            hi[d] = (long)floor((b - m->origin[d]) / bin);
        }
        for (long z = lo[2]; z <= hi[2]; ++z)
            for (long y = lo[1]; y <= hi[1]; ++y)
                for (long x = lo[0]; x <= hi[0]; ++x) {
                    if (n == cap) {
                        cap *= 2;
                        E = realloc(E, cap * sizeof *E);
                        assert_non_null(E);
                    }
                    E[n].cell = ((uint64_t)(z + 2) * 1048576u + (uint64_t)(y + 2)) * 1048576u +
                                (uint64_t)(x + 2);
                    E[n].tri = (uint32_t)t;
                    ++n;
                }
    }
    qsort(E, n, sizeof *E, cmp_entry);
    size_t hits = 0;
    *pairs = 0;
    for (size_t s = 0; s < n;) {
        size_t e = s;
        while (e < n && E[e].cell == E[s].cell) ++e;
        for (size_t i = s; i < e; ++i)
            for (size_t j = i + 1; j < e; ++j) {
                ++*pairs;
                if (tri_tri(m, E[i].tri, E[j].tri)) {
                    if (hits < 4)
                        fprintf(stderr, "  triangles %u and %u intersect\n", E[i].tri, E[j].tri);
                    ++hits;
                }
            }
        s = e;
    }
    free(E);
    return hits;
}

static void test_no_self_intersections(void **state) {
    (void)state;
    const unsigned res[2] = {64, 128};
    size_t checked = 0;
    for (size_t s = 0; s < nscenes; ++s) {
        if (!strstr(scene_paths[s], "/scenes/hsu")) continue; /* the papers' scenes */
        for (int r = 0; r < 2; ++r) {
            built B;
            build_file(scene_paths[s], res[r], 0, 0, &B);
            size_t pairs = 0;
            const size_t hits = self_intersections(B.m, &pairs);
            if (hits)
                fail_msg("%s at %u: %zu intersecting triangle pairs", scene_paths[s], res[r], hits);
            checked += pairs;
            unbuild(&B);
        }
    }
    fprintf(stderr, "  %zu nearby triangle pairs tested\n", checked);
    assert_true(checked > 1000000);
}

/* With LB_MESH_FEATURES (a vertex on each crease, up to half a cell outside
 * its cell, and the flips that join them): the papers' scenes and the sharp
 * shapes of tests/data/features, still free of self-intersections, closed
 * and manifold. */
static void test_no_self_intersections_features(void **state) {
    (void)state;
    const unsigned res[2] = {64, 128};
    size_t checked = 0;
    for (size_t s = 0; s < nscenes + NSHARP; ++s) {
        char path[1100];
        if (!case_path(s, 1, path, sizeof path)) continue;
        for (int r = 0; r < 2; ++r) {
            built B;
            build_file(path, res[r], LB_MESH_FEATURES, 0, &B);
            const topo t = topology(B.m);
            if (!t.closed || !t.oriented || !t.manifold)
                fail_msg("%s at %u with features: closed %d oriented %d manifold %d", path, res[r],
                         t.closed, t.oriented, t.manifold);
            size_t pairs = 0;
            const size_t hits = self_intersections(B.m, &pairs);
            if (hits) fail_msg("%s at %u: %zu intersecting triangle pairs", path, res[r], hits);
            checked += pairs;
            unbuild(&B);
        }
    }
    fprintf(stderr, "  %zu nearby triangle pairs tested\n", checked);
    assert_true(checked > 1000000);
}

/* Simplified (features and simplify = 0.25 cells, the moves the largest
 * tolerance here allows): the papers' scenes and the sharp shapes still
 * free of self-intersections, closed and manifold, and fewer triangles. */
/* Under the sanitizers (LB_TEST_SANITIZERS) at 64 cells only: the memory
 * checks see the same code there, and the 128-cell geometry is the
 * Release build's check (the simplification at 128 took 90 s of ASan's). */
#ifndef LB_TEST_SANITIZERS
#define LB_TEST_SANITIZERS 0
#endif
static void test_no_self_intersections_simplify(void **state) {
    (void)state;
    const unsigned res[2] = {64, 128};
    const int nres = LB_TEST_SANITIZERS ? 1 : 2;
    size_t checked = 0, before = 0, after = 0;
    for (size_t s = 0; s < nscenes + NSHARP; ++s) {
        char path[1100];
        if (!case_path(s, 1, path, sizeof path)) continue;
        for (int r = 0; r < nres; ++r) {
            built A, B;
            build_file_s(path, res[r], LB_MESH_FEATURES, 0, 0.0, &A);
            build_file_s(path, res[r], LB_MESH_FEATURES, 0, 0.25, &B);
            const topo t = topology(B.m);
            if (!t.closed || !t.oriented || !t.manifold)
                fail_msg("%s at %u simplified: closed %d oriented %d manifold %d", path, res[r],
                         t.closed, t.oriented, t.manifold);
            if (!(B.m->ntriangles < A.m->ntriangles))
                fail_msg("%s at %u: %zu triangles simplified, %zu before", path, res[r],
                         B.m->ntriangles, A.m->ntriangles);
            size_t pairs = 0;
            const size_t hits = self_intersections(B.m, &pairs);
            if (hits)
                fail_msg("%s at %u simplified: %zu intersecting triangle pairs", path, res[r],
                         hits);
            checked += pairs;
            before += A.m->ntriangles;
            after += B.m->ntriangles;
            unbuild(&A);
            unbuild(&B);
        }
    }
    fprintf(stderr, "  %zu nearby triangle pairs tested; %zu triangles simplified to %zu\n",
            checked, before, after);
    assert_true(checked > (nres == 2 ? 100000u : 20000u));
}

/* Coarse first (LB_MESH_COARSE_FIRST): every scene and the sharp shapes at
 * 64 cells (and the papers' and bench scenes at 128) closed, oriented,
 * manifold, free of self-intersections, every vertex on the surface of
 * phi_c to 1e-6 cells, fewer triangles than the uniform mesh where anything
 * is meshed coarse; and on a sphere, whose distance is known, every point of
 * every triangle within the tolerance. Under the sanitizers and Wine (the
 * CI's time) the papers', bench and sharp scenes at 64 cells only: the
 * Release build checks the rest. */
#ifdef _WIN32
#define LB_TEST_SLOW 1
#else
#define LB_TEST_SLOW LB_TEST_SANITIZERS
#endif
static void test_coarse_first(void **state) {
    (void)state;
    tally_t acc = {"coarse first: vertices on the surface", 0, 0, 0};
    tally_t nrm = {"coarse first: normals from the gradient", 0, 0, 0};
    const unsigned res[2] = {64, 128};
    const int nres = LB_TEST_SLOW ? 1 : 2;
    size_t checked = 0, before = 0, after = 0, vertices = 0;
    for (size_t s = 0; s < nscenes + NSHARP; ++s) {
        char path[1100];
        case_path(s, 0, path, sizeof path);
        if (LB_TEST_SLOW && s < nscenes && !strstr(path, "/scenes/hsu") &&
            !strstr(path, "/bench-s"))
            continue;
        for (int r = 0; r < nres; ++r) {
            if (r && s < nscenes && !strstr(path, "/scenes/hsu") && !strstr(path, "/bench-s"))
                continue;
            built A, B;
            build_file_s(path, res[r], 0, 0, 0.0, &A);
            build_file_s(path, res[r], LB_MESH_COARSE_FIRST, 0, 0.25, &B);
            char what[1200];
            snprintf(what, sizeof what, "%.1000s at %u coarse first", path, res[r]);
            if (A.m->ntriangles) expect_closed_manifold(what, B.m);
            if (!(B.m->ntriangles <= A.m->ntriangles))
                fail_msg("%s: %zu triangles, %zu uniform", what, B.m->ntriangles, A.m->ntriangles);
            size_t pairs = 0;
            const size_t hits = self_intersections(B.m, &pairs);
            if (hits) fail_msg("%s: %zu intersecting triangle pairs", what, hits);
            vertices_on_surface(&B, what, &acc, &nrm);
            checked += pairs;
            vertices += B.m->nvertices;
            before += A.m->ntriangles;
            after += B.m->ntriangles;
            unbuild(&A);
            unbuild(&B);
        }
    }
    fprintf(stderr,
            "  coarse first: %zu triangles for %zu uniform, %zu vertices on the surface, "
            "%zu nearby triangle pairs tested\n",
            after, before, vertices, checked);
    assert_true(after < before * 3 / 4 && checked > 10000u);
    tally_end(&acc, LB_TEST_SLOW ? 50000 : 100000);
    tally_end(&nrm, LB_TEST_SLOW ? 50000 : 100000);
    /* a sphere of radius 1.3: the distance of points over every triangle
     * (barycentric steps of a tenth) within the tolerance of its surface */
    static const char text[] =
        HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"sphere\", \"radius\": 1.3}}";
    for (int r = 0; r < nres; ++r) {
        lb_mesh_options o;
        lb_mesh_options_init(&o);
        for (int d = 0; d < 3; ++d) {
            o.bmin[d] = -1.5;
            o.bmax[d] = 1.5;
        }
        o.resolution = res[r];
        o.flags = LB_MESH_COARSE_FIRST;
        o.simplify = 0.25;
        built B, U;
        build_text(text, &o, &B);
        o.flags = 0;
        o.simplify = 0.0;
        build_text(text, &o, &U);
        expect_closed_manifold("sphere coarse first", B.m);
        const double h = B.m->cell[0];
        double worst = 0.0;
        for (size_t t = 0; t < B.m->ntriangles; ++t) {
            const double *P[3];
            for (int k = 0; k < 3; ++k) P[k] = B.m->positions + 3 * B.m->triangles[3 * t + k];
            for (int i = 0; i <= 10; ++i)
                for (int j = 0; i + j <= 10; ++j) {
                    double X[3];
                    for (int d = 0; d < 3; ++d)
                        X[d] =
                            P[0][d] + 0.1 * i * (P[1][d] - P[0][d]) + 0.1 * j * (P[2][d] - P[0][d]);
                    const double dist = fabs(sqrt(X[0] * X[0] + X[1] * X[1] + X[2] * X[2]) - 1.3);
                    if (dist > worst) worst = dist;
                }
        }
        fprintf(stderr,
                "  sphere at %u cells coarse first: %zu triangles (%zu uniform), largest "
                "distance %.4f cells\n",
                res[r], B.m->ntriangles, U.m->ntriangles, worst / h);
        if (!(worst <= 0.25 * h)) fail_msg("sphere at %u: %g cells off", res[r], worst / h);
        if (!(B.m->ntriangles < U.m->ntriangles / 2))
            fail_msg("sphere at %u: %zu triangles, %zu uniform", res[r], B.m->ntriangles,
                     U.m->ntriangles);
        unbuild(&B);
        unbuild(&U);
    }
}

/* Flat regions merged (LB_MESH_MERGE_FLAT, with features): the papers'
 * scenes and the sharp shapes closed, oriented, manifold and free of
 * self-intersections; no more triangles than without; every vertex one of
 * the unmerged mesh's (the same position and normal, bit for bit); the
 * same bytes with 1 and 2 threads; and the boxes in a few triangles. */
static int cmp_vertex(const void *a, const void *b) {
    return memcmp(a, b, 6 * sizeof(double));
}

static void test_merge_flat(void **state) {
    (void)state;
    const unsigned res[2] = {64, 128};
    const int nres = LB_TEST_SANITIZERS ? 1 : 2;
    size_t checked = 0, before = 0, after = 0, merged = 0;
    for (size_t s = 0; s < nscenes + NSHARP; ++s) {
        char path[1100];
        if (!case_path(s, 1, path, sizeof path)) continue;
        for (int r = 0; r < nres; ++r) {
            built A, B, C;
            build_file(path, res[r], LB_MESH_FEATURES, 1, &A);
            build_file(path, res[r], LB_MESH_FEATURES | LB_MESH_MERGE_FLAT, 1, &B);
            build_file(path, res[r], LB_MESH_FEATURES | LB_MESH_MERGE_FLAT, 2, &C);
            const lb_mesh *a = A.m, *b = B.m;
            const topo t = topology(b);
            if (!t.closed || !t.oriented || !t.manifold)
                fail_msg("%s at %u merged: closed %d oriented %d manifold %d", path, res[r],
                         t.closed, t.oriented, t.manifold);
            if (b->ntriangles > a->ntriangles)
                fail_msg("%s at %u: %zu triangles merged, %zu before", path, res[r], b->ntriangles,
                         a->ntriangles);
            if (C.m->nvertices != b->nvertices || C.m->ntriangles != b->ntriangles ||
                memcmp(C.m->positions, b->positions, 3 * b->nvertices * sizeof(double)) ||
                memcmp(C.m->triangles, b->triangles, 3 * b->ntriangles * sizeof(uint32_t)))
                fail_msg("%s at %u merged: 1 and 2 threads differ", path, res[r]);
            /* each merged vertex (position and normal) among the unmerged */
            double *va = malloc(6 * a->nvertices * sizeof *va);
            assert_non_null(va);
            for (size_t v = 0; v < a->nvertices; ++v) {
                memcpy(va + 6 * v, a->positions + 3 * v, 3 * sizeof(double));
                memcpy(va + 6 * v + 3, a->normals + 3 * v, 3 * sizeof(double));
            }
            qsort(va, a->nvertices, 6 * sizeof *va, cmp_vertex);
            for (size_t v = 0; v < b->nvertices; ++v) {
                double key[6];
                memcpy(key, b->positions + 3 * v, 3 * sizeof(double));
                memcpy(key + 3, b->normals + 3 * v, 3 * sizeof(double));
                if (!bsearch(key, va, a->nvertices, 6 * sizeof *va, cmp_vertex))
                    fail_msg("%s at %u merged: vertex %zu is not one of the unmerged mesh's", path,
                             res[r], v);
            }
            free(va);
            size_t pairs = 0;
            const size_t hits = self_intersections(b, &pairs);
            if (hits)
                fail_msg("%s at %u merged: %zu intersecting triangle pairs", path, res[r], hits);
            checked += pairs;
            before += a->ntriangles;
            after += b->ntriangles;
            merged += b->ntriangles < a->ntriangles;
            if (strstr(path, "/cube.json") || strstr(path, "/rotated-cube.json"))
                if (b->ntriangles != 12 || b->nvertices != 8)
                    fail_msg("%s at %u merged: %zu triangles, %zu vertices (want 12, 8)", path,
                             res[r], b->ntriangles, b->nvertices);
            unbuild(&A);
            unbuild(&B);
            unbuild(&C);
        }
    }
    fprintf(stderr,
            "  %zu nearby triangle pairs tested; %zu triangles merged to %zu (%zu meshes)\n",
            checked, before, after, merged);
    assert_true(merged >= 8 && after < before);
}

/* ---- progress, cancel, bad options ---- */

typedef struct prog {
    int calls;
    double last;
    int monotone;
    int cancel_at;
} prog;

static int on_progress(double f, void *user) {
    prog *p = user;
    if (f < p->last || f < 0.0 || f > 1.0) p->monotone = 0;
    p->last = f;
    return ++p->calls == p->cancel_at;
}

/* S2 (64 spheres) compiled, with default options over its bounds */
static void load_s2(lb_scene **sc, lb_evaluator **ev, lb_mesh_options *o) {
    char path[1100];
    snprintf(path, sizeof path, "%s/scenes/bench-s2-64-spheres.json", SOURCE_DIR);
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_scene_load(path, sc, &e), LB_OK);
    assert_int_equal(lb_evaluator_create(*sc, ev, &e), LB_OK);
    lb_mesh_options_init(o);
    lb_scene_bounds(*sc, o->bmin, o->bmax);
}

static void test_progress_and_cancel(void **state) {
    (void)state;
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_mesh_options o;
    load_s2(&sc, &ev, &o);
    o.resolution = 64;
    o.threads = 2;
    prog p = {0, 0.0, 1, -1};
    o.progress = on_progress;
    o.user = &p;
    lb_mesh *m = NULL;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_true(p.calls >= 3 && p.monotone && p.last == 1.0);
    lb_mesh_free(m);
    /* the callback cancels */
    prog q = {0, 0.0, 1, 3};
    o.user = &q;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_ERR_CANCELLED);
    assert_null(m);
    assert_non_null(strstr(e.message, "cancelled"));
    /* the flag cancels */
    volatile int flag = 1;
    o.progress = NULL;
    o.cancel = &flag;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_ERR_CANCELLED);
    assert_null(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

typedef struct simp_prog {
    double last;
    int monotone, in_simplify, cancel; /* calls within (0.5, 0.95]; cancel at the first */
} simp_prog;

static int on_simp_progress(double f, void *user) {
    simp_prog *p = user;
    if (f < p->last) p->monotone = 0;
    p->last = f;
    if (f > 0.5 && f <= 0.95) {
        ++p->in_simplify;
        return p->cancel;
    }
    return 0;
}

/* The simplification's own refusals (meshing/simplify.c, called directly
 * on a mesh of the cube): over the memory cap it fails before allocating,
 * naming the cap; with the cancel flag set it stops within CHECK_EVERY
 * vertices tried. */
static void test_simplify_limits(void **state) {
    (void)state;
    char path[1100];
    snprintf(path, sizeof path, "%s/tests/data/features/cube.json", SOURCE_DIR);
    built B;
    build_file(path, 64, LB_MESH_FEATURES, 0, &B);
    lb__grid g;
    memset(&g, 0, sizeof g);
    for (int d = 0; d < 3; ++d) {
        g.origin[d] = B.m->origin[d];
        g.h[d] = B.m->cell[d];
        g.cells[d] = B.m->cells[d];
        g.N[d] = B.m->cells[d] + 1;
    }
    g.closed = 1;
    assert_true(lb_scene_bounds(B.sc, g.bmin, g.bmax));
    lb_error e = {LB_OK, ""};
    const size_t nt = B.m->ntriangles;
    assert_int_equal(
        lb__simplify(B.ev, &g, B.m, NULL, 0.1, (size_t)1 << 20, 2, NULL, NULL, NULL, 0, 1, &e),
        LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "simplifying"));
    assert_non_null(strstr(e.message, "memory cap of 1 MiB"));
    assert_int_equal(B.m->ntriangles, nt); /* untouched */
    volatile int flag = 1;
    assert_int_equal(
        lb__simplify(B.ev, &g, B.m, NULL, 0.1, (size_t)1 << 30, 2, &flag, NULL, NULL, 0, 1, &e),
        LB_ERR_CANCELLED);
    assert_non_null(strstr(e.message, "cancelled"));
    unbuild(&B);
    /* through lb_mesh_create: the simplification reports progress of its
     * own (between 0.5 and 0.95, monotone), and a callback returning
     * non-zero there cancels it; on the cylinder cut by a slab, whose
     * curved wall is left to the collapses after the flat caps are merged
     * (the cube has no vertex left to move by then) */
    snprintf(path, sizeof path, "%s/tests/data/features/cylinder-slab.json", SOURCE_DIR);
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    assert_int_equal(lb_scene_load(path, &sc, &e), LB_OK);
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    assert_true(lb_scene_bounds(sc, o.bmin, o.bmax));
    o.resolution = 64;
    o.flags = LB_MESH_FEATURES;
    o.simplify = 0.1;
    simp_prog p = {0.0, 1, 0, 0};
    o.progress = on_simp_progress;
    o.user = &p;
    lb_mesh *m = NULL;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_true(p.monotone && p.last == 1.0 && p.in_simplify >= 3);
    assert_true(m->ntriangles > 20 && m->ntriangles < 1000); /* 190 (17,612 unsimplified) */
    lb_mesh_free(m);
    simp_prog q = {0.0, 1, 0, 1};
    o.user = &q;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_ERR_CANCELLED);
    assert_null(m);
    assert_true(q.in_simplify == 1);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

/* Over the memory cap, the message names the largest resolution that
 * fits: following it works, one more does not. Also an empty region: a
 * valid mesh with no triangles, written in every format. */
static void test_memory_cap_and_empty(void **state) {
    (void)state;
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_mesh_options o;
    load_s2(&sc, &ev, &o);
    o.threads = 1;
    o.max_memory = (size_t)12 << 20; /* 96 blocks */
    o.resolution = 4096;
    lb_mesh *m = NULL;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_ERR_INVALID_ARGUMENT);
    const char *at = strstr(e.message, "a resolution of at most ");
    assert_non_null(at);
    const unsigned fit = (unsigned)strtoul(at + strlen("a resolution of at most "), NULL, 10);
    assert_true(fit >= 16 && fit < 4096);
    o.resolution = fit;
    if (lb_mesh_create(ev, &o, &m, &e) != LB_OK)
        fail_msg("the suggested %u fails: %s", fit, e.message);
    assert_true(m->ntriangles > 0);
    lb_mesh_free(m);
    m = NULL;
    o.resolution = fit + 1;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_ERR_INVALID_ARGUMENT);
    assert_null(m);
    /* a region with no surface in it */
    o.max_memory = 0;
    o.resolution = 16;
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = 100.0;
        o.bmax[d] = 101.0;
    }
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_int_equal(m->nvertices, 0);
    assert_int_equal(m->ntriangles, 0);
    static const char *const ext[] = {"ply", "obj", "stl", "glb"};
    for (int i = 0; i < 4; ++i) {
        char out[64];
        snprintf(out, sizeof out, "empty-mesh-test.%s", ext[i]);
        if (lb_mesh_write(m, out, LB_MESH_FORMAT_AUTO, &e) != LB_OK)
            fail_msg("%s: %s", out, e.message);
        FILE *f = fopen(out, "rb");
        assert_non_null(f);
        fseek(f, 0, SEEK_END);
        const long size = ftell(f);
        fclose(f);
        assert_true(ext[i][0] == 'o' || size > 0);
        remove(out);
    }
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

/* docs/meshing.md "The smallest feature kept": a sphere of radius just over
 * half the cell diagonal, anywhere relative to the grid, is always meshed
 * closed. */
static void test_min_feature(void **state) {
    (void)state;
    rng_t r = {20261201};
    const double h = 2.0 / 16.0, rad = 1.001 * 0.5 * sqrt(3.0) * h;
    int kept = 0;
    for (int t = 0; t < 400; ++t) {
        const double c[3] = {rng_range(&r, -h, h), rng_range(&r, -h, h), rng_range(&r, -h, h)};
        char text[512];
        const int n = snprintf(text, sizeof text,
                               "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":"
                               "\"zero\",\"root\":{\"type\":\"sphere\",\"center\":[%.17g,%.17g,"
                               "%.17g],\"radius\":%.17g}}",
                               c[0], c[1], c[2], rad);
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        lb_error e = {LB_OK, ""};
        assert_int_equal(lb_scene_parse(text, (size_t)n, "small.json", &sc, &e), LB_OK);
        assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
        lb_mesh_options o;
        lb_mesh_options_init(&o);
        for (int d = 0; d < 3; ++d) {
            o.bmin[d] = -1.0;
            o.bmax[d] = 1.0;
        }
        o.resolution = 16;
        o.threads = 1;
        lb_mesh *m = NULL;
        assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
        if (m->ntriangles == 0)
            fail_msg("a sphere of radius %g (cell %g) at (%g, %g, %g) vanished", rad, h, c[0], c[1],
                     c[2]);
        expect_closed_manifold("small sphere", m);
        kept += m->ntriangles > 0;
        lb_mesh_free(m);
        lb_evaluator_free(ev);
        lb_scene_free(sc);
    }
    assert_int_equal(kept, 400);
}

/* A flat union of 4096 spheres (one BT_4096 node: 16^3 lattice, spacing
 * 0.5, radius 0.3, range 0.1, p = 2): its values satisfy the operator's
 * defining equation sum_i [(r - x_i + h)/r]+^2 = 1 at random points, with
 * the spheres' fields x_i = |X - c_i| / radius - 1 computed here, and agree
 * with the reference walk; a min of the same 4096 is their smallest x_i; the mesh is closed,
 * oriented and manifold, every vertex on the surface, the same for 1 and 2 threads. */
static void test_wide_union(void **state) {
    (void)state;
    enum { N = 16, K = N * N * N };
    const double sp = 0.5, rad = 0.3, r = 0.1;
    size_t cap = (size_t)K * 96 + 512, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    len += (size_t)snprintf(text, cap,
                            HEAD "\"convention\": \"zero\", \"root\": {\"type\": "
                                 "\"displacement\", \"op\": \"union\", \"r\": %g, \"p\": 2, "
                                 "\"args\": [",
                            r);
    for (int i = 0; i < K; ++i)
        len += (size_t)snprintf(
            text + len, cap - len,
            "%s{\"type\": \"sphere\", \"center\": [%g, %g, %g], \"radius\": %g}", i ? ", " : "",
            sp * (i % N), sp * (i / N % N), sp * (i / (N * N)), rad);
    len += (size_t)snprintf(text + len, cap - len, "]}}");
    assert_true(len < cap);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -0.5;
        o.bmax[d] = sp * (N - 1) + 0.5;
    }
    o.resolution = 96;
    o.threads = 1;
    built A;
    build_text(text, &o, &A);
    /* the same spheres in one min node: the sharp union, point by point */
    {
        const char *args = strstr(text, "\"args\": [");
        assert_non_null(args);
        char *mtext = malloc(strlen(args) + 256);
        assert_non_null(mtext);
        snprintf(mtext, strlen(args) + 256,
                 HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"min\", %s", args);
        lb_scene *ms = NULL;
        lb_evaluator *me = NULL;
        lb_error e = {LB_OK, ""};
        if (lb_scene_parse(mtext, strlen(mtext), "min4096.json", &ms, &e) ||
            lb_evaluator_create(ms, &me, &e))
            fail_msg("%s", e.message);
        free(mtext);
        rng_t q = {64};
        for (int j = 0; j < 200; ++j) {
            const double X[3] = {rng_range(&q, -0.5, 8.0), rng_range(&q, -0.5, 8.0),
                                 rng_range(&q, -0.5, 8.0)};
            double v, gx, gy, gz, xmin = INFINITY;
            assert_int_equal(lb_evaluator_eval(me, 1, X, X + 1, X + 2, &v, &gx, &gy, &gz, 1, &e),
                             LB_OK);
            for (int i = 0; i < K; ++i) {
                const double dx = X[0] - sp * (i % N), dy = X[1] - sp * (i / N % N),
                             dz = X[2] - sp * (i / (N * N));
                const double xi = sqrt(dx * dx + dy * dy + dz * dz) / rad - 1.0;
                if (xi < xmin) xmin = xi;
            }
            if (!(fabs(v - xmin) <= 1e-12)) fail_msg("min of 4096: %.17g, want %.17g", v, xmin);
        }
        lb_evaluator_free(me);
        lb_scene_free(ms);
    }
    free(text);
    /* values against the defining equation */
    rng_t g = {4096};
    enum { P = 2000 };
    double *X = malloc(7 * P * sizeof *X);
    assert_non_null(X);
    double *Y = X + P, *Z = Y + P, *V = Z + P, *GX = V + P, *GY = GX + P, *GZ = GY + P;
    for (int j = 0; j < P; ++j) {
        X[j] = rng_range(&g, -0.5, 8.0);
        Y[j] = rng_range(&g, -0.5, 8.0);
        Z[j] = rng_range(&g, -0.5, 8.0);
    }
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_evaluator_eval(A.ev, P, X, Y, Z, V, GX, GY, GZ, 2, &e), LB_OK);
    double worst = 0.0;
    int blended = 0;
    for (int j = 0; j < P; ++j) {
        double sum = 0.0, xmin = INFINITY;
        int active = 0;
        for (int i = 0; i < K; ++i) {
            const double dx = X[j] - sp * (i % N), dy = Y[j] - sp * (i / N % N),
                         dz = Z[j] - sp * (i / (N * N));
            const double xi = sqrt(dx * dx + dy * dy + dz * dz) / rad - 1.0; /* rho - 1 */
            if (xi < xmin) xmin = xi;
            const double t = (r - xi + V[j]) / r;
            if (t > 0.0) {
                sum += t * t;
                ++active;
            }
        }
        if (!(V[j] <= xmin + 1e-15))
            fail_msg("point %d (%.17g, %.17g, %.17g): BT = %.17g above min x_i = %.17g", j, X[j],
                     Y[j], Z[j], V[j], xmin);
        if (fabs(sum - 1.0) > worst) worst = fabs(sum - 1.0);
        blended += active > 1;
    }
    if (!(worst < 1e-9)) fail_msg("defining equation off by %g", worst);
    assert_true(blended > 50); /* the sample reaches the blends */
    /* the reference walk (lb_displacement of all 4096 arguments, its heap
     * scratch) agrees with the compiled evaluator (culled per chunk) */
    for (int j = 0; j < P; j += 20) {
        double rv, rg[3];
        assert_int_equal(lb_scene_eval_reference(A.sc, (double[3]){X[j], Y[j], Z[j]}, &rv, rg, &e),
                         LB_OK);
        if (!(fabs(rv - V[j]) <= 1e-12 * (1.0 + fabs(rv))) || !(fabs(rg[0] - GX[j]) <= 1e-9) ||
            !(fabs(rg[1] - GY[j]) <= 1e-9) || !(fabs(rg[2] - GZ[j]) <= 1e-9))
            fail_msg("point %d: reference %.17g (%g, %g, %g), evaluator %.17g (%g, %g, %g)", j, rv,
                     rg[0], rg[1], rg[2], V[j], GX[j], GY[j], GZ[j]);
    }
    free(X);
    expect_closed_manifold("4096 spheres", A.m);
    assert_true(A.m->ntriangles > 100000);
    /* every vertex on the surface */
    const size_t nv = A.m->nvertices;
    double *w = malloc(7 * nv * sizeof *w);
    assert_non_null(w);
    for (size_t v = 0; v < nv; ++v)
        for (int d = 0; d < 3; ++d) w[d * nv + v] = A.m->positions[3 * v + d];
    assert_int_equal(lb_evaluator_eval(A.ev, nv, w, w + nv, w + 2 * nv, w + 3 * nv, w + 4 * nv,
                                       w + 5 * nv, w + 6 * nv, 2, &e),
                     LB_OK);
    const double h = (o.bmax[0] - o.bmin[0]) / o.resolution;
    for (size_t v = 0; v < nv; ++v) {
        const double gn = sqrt(w[4 * nv + v] * w[4 * nv + v] + w[5 * nv + v] * w[5 * nv + v] +
                               w[6 * nv + v] * w[6 * nv + v]);
        if (!(fabs(w[3 * nv + v]) <= 1e-6 * h * gn))
            fail_msg("vertex %zu: |f| = %g, |grad f| = %g", v, fabs(w[3 * nv + v]), gn);
    }
    free(w);
    /* thread independence */
    o.threads = 2;
    lb_mesh *m2 = NULL;
    assert_int_equal(lb_mesh_create(A.ev, &o, &m2, &e), LB_OK);
    assert_int_equal(m2->nvertices, A.m->nvertices);
    assert_int_equal(m2->ntriangles, A.m->ntriangles);
    assert_memory_equal(m2->positions, A.m->positions, 3 * nv * sizeof *m2->positions);
    assert_memory_equal(m2->triangles, A.m->triangles, 3 * A.m->ntriangles * sizeof *m2->triangles);
    lb_mesh_free(m2);
    unbuild(&A);
}

/* lb_mesh_edges against a sort of the corners' vertex pairs done here: the
 * same set of edges, each corner's edge joining that corner's two vertices,
 * first-appearance numbering, and on a closed manifold mesh every edge used
 * by exactly two corners (3/2 edges per triangle). Bad input is refused. */
static int cmp_pair(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Corner normals (lb_mesh.corner_normals): NULL unless asked for
 * (LB_MESH_CORNER_NORMALS) and on a smooth scene (S1: no crease); on the cube
 * added normals, each of unit length, used, and owned by one vertex. A mesh
 * whose corner normals or triangles name entries out of range is refused by
 * both writers before a byte is written. (Their directions against the
 * closed forms: tests/mesh/test_mesh_features.py.) */
/* ---- the feature point's fit (features.c), against closed forms ---- */

static double fit_rand(unsigned long long *s) { /* uniform in [0, 1) */
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static void fit_unit(unsigned long long *s, double v[3]) {
    double l;
    do {
        for (int d = 0; d < 3; ++d) v[d] = 2.0 * fit_rand(s) - 1.0;
        l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (!(l > 0.1 && l <= 1.0));
    for (int d = 0; d < 3; ++d) v[d] /= l;
}

static double fit_dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void fit_cross(const double *a, const double *b, double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* a point on the plane through K with unit normal n, up to r from K */
static void fit_on_plane(unsigned long long *s, const double *K, const double *n, double r,
                         double *p) {
    double u[3];
    fit_unit(s, u);
    const double un = fit_dot(u, n), t = r * fit_rand(s);
    for (int d = 0; d < 3; ++d) p[d] = K[d] + t * (u[d] - un * n[d]);
}

/* The fit's moments about c for m points and normals: A = sum n n^T and
 * g = sum n (n . (p - c)), added to A and g. */
static void fit_moments(const double *P, const double *N, int m, const double *c, double A[3][3],
                        double g[3]) {
    for (int q = 0; q < m; ++q) {
        const double *nq = N + 3 * q, *pq = P + 3 * q;
        double r = 0.0;
        for (int d = 0; d < 3; ++d) r += nq[d] * (pq[d] - c[d]);
        for (int d = 0; d < 3; ++d) {
            g[d] += nq[d] * r;
            for (int e = 0; e < 3; ++e) A[d][e] += nq[d] * nq[e];
        }
    }
}

/* The largest eigenvalue of the symmetric A and its unit vector, by power
 * iteration from v (not orthogonal to it); enough steps for the vector to
 * settle when the next eigenvalue is within 3 % of it. */
static double fit_power(const double A[3][3], double v[3]) {
    double w = 0.0;
    for (int k = 0; k < 20000; ++k) {
        double u[3];
        for (int d = 0; d < 3; ++d) u[d] = A[d][0] * v[0] + A[d][1] * v[1] + A[d][2] * v[2];
        w = sqrt(fit_dot(u, u));
        for (int d = 0; d < 3; ++d) v[d] = u[d] / w;
    }
    return w;
}

/* lb__feature_qef's point for tangent planes whose least-squares point is
 * known without its method: three planes meet in one corner (the point
 * itself); two planes at 30 to 150 degrees meet in a line (the point of it
 * nearest the mass point: the direction along the line is the mass
 * point's); planes whose normals lie within 3 degrees of one (the mass
 * point moved along the largest direction of sum n n^T, found here by
 * power iteration, to the least squares along it); and a corner outside
 * the box, where the box's nearest point to it is the answer for
 * orthogonal planes (the squared distances separate by axis). Each kind
 * 300 times, in random orientations. */
static void test_feature_fit(void **state) {
    (void)state;
    unsigned long long s = 12345;
    const double lo[3] = {-4, -4, -4}, hi[3] = {4, 4, 4};
    double worst[5] = {0, 0, 0, 0, 0};
    for (int it = 0; it < 300; ++it) {
        double K[3], P[3 * LB__MAXPOLY], N[3 * LB__MAXPOLY], x[3], nn[3][3];
        for (int d = 0; d < 3; ++d) K[d] = 2.0 * fit_rand(&s) - 1.0;
        /* three planes, normals at least 30 degrees apart and not near one
         * plane (their triple product at least 0.3) */
        do {
            for (int k = 0; k < 3; ++k) fit_unit(&s, nn[k]);
            double c[3];
            fit_cross(nn[0], nn[1], c);
            if (fabs(fit_dot(c, nn[2])) < 0.3) continue;
            if (fabs(fit_dot(nn[0], nn[1])) > 0.866 || fabs(fit_dot(nn[0], nn[2])) > 0.866 ||
                fabs(fit_dot(nn[1], nn[2])) > 0.866)
                continue;
            break;
        } while (1);
        int m = 0;
        for (int k = 0; k < 3; ++k)
            for (int q = 0; q < 2; ++q, ++m) {
                fit_on_plane(&s, K, nn[k], 0.5, P + 3 * m);
                memcpy(N + 3 * m, nn[k], sizeof nn[k]);
            }
        assert_int_equal(lb__feature_qef(P, N, m, lo, hi, x), 1);
        for (int d = 0; d < 3; ++d) worst[0] = fmax(worst[0], fabs(x[d] - K[d]));

        /* two planes through the line K + s t */
        double t[3], a[3], b[3];
        fit_unit(&s, t);
        fit_unit(&s, a);
        const double at = fit_dot(a, t);
        for (int d = 0; d < 3; ++d) a[d] -= at * t[d];
        const double al = sqrt(fit_dot(a, a));
        for (int d = 0; d < 3; ++d) a[d] /= al;
        fit_cross(t, a, b);
        const double th = (30.0 + 120.0 * fit_rand(&s)) * M_PI / 180.0;
        for (int d = 0; d < 3; ++d) {
            nn[0][d] = a[d];
            nn[1][d] = cos(th) * a[d] + sin(th) * b[d];
        }
        const int m2 = 2 + it % 6; /* 2 to 7 points, both planes */
        double c[3] = {0, 0, 0};
        for (int q = 0; q < m2; ++q) {
            fit_on_plane(&s, K, nn[q % 2], 0.5, P + 3 * q);
            memcpy(N + 3 * q, nn[q % 2], sizeof nn[0]);
            for (int d = 0; d < 3; ++d) c[d] += P[3 * q + d] / m2;
        }
        assert_int_equal(lb__feature_qef(P, N, m2, lo, hi, x), 1);
        double ck[3];
        for (int d = 0; d < 3; ++d) ck[d] = c[d] - K[d];
        const double along = fit_dot(ck, t);
        for (int d = 0; d < 3; ++d) worst[1] = fmax(worst[1], fabs(x[d] - (K[d] + along * t[d])));

        /* normals within 3 degrees of n0, points near one plane */
        double n0[3], A[3][3] = {{0}}, g[3] = {0, 0, 0};
        fit_unit(&s, n0);
        const int m3 = 3 + it % 5; /* 3 to 7 points (a polygon has at most 7) */
        for (int d = 0; d < 3; ++d) c[d] = 0.0;
        for (int q = 0; q < m3; ++q) {
            double w[3];
            fit_unit(&s, w);
            for (int d = 0; d < 3; ++d) N[3 * q + d] = n0[d] + 0.05 * w[d];
            const double l = sqrt(fit_dot(N + 3 * q, N + 3 * q));
            for (int d = 0; d < 3; ++d) N[3 * q + d] /= l;
            fit_on_plane(&s, K, n0, 0.5, P + 3 * q);
            for (int d = 0; d < 3; ++d) P[3 * q + d] += 0.01 * (2.0 * fit_rand(&s) - 1.0);
            for (int d = 0; d < 3; ++d) c[d] += P[3 * q + d] / m3;
        }
        assert_true(acos(fmin(1.0, fit_dot(N, n0))) < 3.0 * M_PI / 180.0);
        fit_moments(P, N, m3, c, A, g);
        double v[3] = {n0[0], n0[1], n0[2]};
        const double w1 = fit_power(A, v);
        assert_int_equal(lb__feature_qef(P, N, m3, lo, hi, x), 1);
        const double step = fit_dot(v, g) / w1;
        for (int d = 0; d < 3; ++d) worst[2] = fmax(worst[2], fabs(x[d] - (c[d] + step * v[d])));

        /* the two planes again, their normals tilted by up to 2 degrees
         * (a curved crease): the direction along the crease has a small
         * eigenvalue, under the cut, and the mass point's part of the
         * least squares along it is dropped. The decomposition here: the
         * largest and smallest eigenvectors by power iteration (on A and
         * on trace - A), the middle one their cross product. */
        const int m5 = 3 + it % 5; /* 3 to 7: two normals alone span no third direction */
        double B3[3][3] = {{0}}, h[3] = {0, 0, 0};
        for (int d = 0; d < 3; ++d) c[d] = 0.0;
        for (int q = 0; q < m5; ++q) {
            double w[3];
            fit_unit(&s, w);
            for (int d = 0; d < 3; ++d) N[3 * q + d] = nn[q % 2][d] + 0.035 * w[d];
            const double l = sqrt(fit_dot(N + 3 * q, N + 3 * q));
            for (int d = 0; d < 3; ++d) N[3 * q + d] /= l;
            fit_on_plane(&s, K, nn[q % 2], 0.5, P + 3 * q);
            for (int d = 0; d < 3; ++d) c[d] += P[3 * q + d] / m5;
        }
        fit_moments(P, N, m5, c, B3, h);
        const double tr = B3[0][0] + B3[1][1] + B3[2][2];
        double C3[3][3], v1[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]},
                         v3[3] = {t[0], t[1], t[2]}, v2[3];
        for (int d = 0; d < 3; ++d)
            for (int e = 0; e < 3; ++e) C3[d][e] = (d == e ? tr : 0.0) - B3[d][e];
        const double e1 = fit_power(B3, v1), e3 = tr - fit_power(C3, v3);
        fit_cross(v1, v3, v2);
        double e2 = 0.0;
        for (int d = 0; d < 3; ++d)
            for (int e = 0; e < 3; ++e) e2 += v2[d] * B3[d][e] * v2[e];
        /* the case this checks: the middle direction kept, the smallest not
         * (the fit's cut is 2 % of the largest) */
        assert_true(e2 > 0.05 * e1 && e3 < 0.01 * e1 && e3 > 0.0);
        assert_int_equal(lb__feature_qef(P, N, m5, lo, hi, x), 1);
        const double s1 = fit_dot(v1, h) / e1, s2 = fit_dot(v2, h) / e2;
        for (int d = 0; d < 3; ++d)
            worst[4] = fmax(worst[4], fabs(x[d] - (c[d] + s1 * v1[d] + s2 * v2[d])));

        /* three orthogonal planes in a random frame meeting outside a box:
         * the box point nearest the corner, in that frame's coordinates
         * (the squared distances to the planes are the frame's axes), is
         * found when the box is that frame's: use the world axes */
        const double blo[3] = {-0.5, -0.5, -0.5}, bhi[3] = {0.5, 0.5, 0.5};
        double Kout[3];
        for (int d = 0; d < 3; ++d) Kout[d] = 3.0 * (2.0 * fit_rand(&s) - 1.0);
        m = 0;
        for (int k = 0; k < 3; ++k) {
            double e[3] = {0, 0, 0};
            e[k] = 1.0;
            for (int q = 0; q < 2; ++q, ++m) {
                fit_on_plane(&s, Kout, e, 0.4, P + 3 * m);
                memcpy(N + 3 * m, e, sizeof e);
            }
        }
        assert_int_equal(lb__feature_qef(P, N, m, blo, bhi, x), 1);
        for (int d = 0; d < 3; ++d)
            worst[3] = fmax(worst[3], fabs(x[d] - fmin(fmax(Kout[d], blo[d]), bhi[d])));
    }
    printf("feature fit, largest distance from the closed form: corner %.3g, crease %.3g, "
           "near-flat %.3g, clamped corner %.3g, curved crease %.3g\n",
           worst[0], worst[1], worst[2], worst[3], worst[4]);
    for (int k = 0; k < 5; ++k) assert_true(worst[k] <= 1e-9);
}

static void test_corner_normals(void **state) {
    (void)state;
    char path[1100];
    built A, B, C;
    snprintf(path, sizeof path, "%s/scenes/bench-s1-three-spheres.json", SOURCE_DIR);
    build_file(path, 64, 0, 0, &A);
    assert_null(A.m->corner_normals);
    assert_int_equal(A.m->nnormals, A.m->nvertices);
    build_file(path, 64, LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS, 0, &B);
    assert_null(B.m->corner_normals);
    assert_int_equal(B.m->nnormals, B.m->nvertices);
    unbuild(&A);
    unbuild(&B);
    snprintf(path, sizeof path, "%s/tests/data/features/cube.json", SOURCE_DIR);
    build_file(path, 32, LB_MESH_FEATURES, 0, &C); /* not asked for */
    assert_null(C.m->corner_normals);
    assert_int_equal(C.m->nnormals, C.m->nvertices);
    unbuild(&C);
    build_file(path, 32, LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS, 0, &C);
    const lb_mesh *m = C.m;
    const size_t nv = m->nvertices, nx = m->nnormals - nv;
    assert_true(m->nnormals > nv);
    uint32_t *owner = malloc(nx * sizeof *owner);
    assert_non_null(owner);
    for (size_t i = 0; i < nx; ++i) owner[i] = UINT32_MAX;
    for (size_t c = 0; c < 3 * m->ntriangles; ++c) {
        const uint32_t n = m->corner_normals[c], v = m->triangles[c];
        if (n < nv) {
            assert_int_equal(n, v);
            continue;
        }
        assert_true(n < m->nnormals);
        if (owner[n - nv] != UINT32_MAX) assert_int_equal(owner[n - nv], v);
        owner[n - nv] = v;
    }
    for (size_t i = 0; i < nx; ++i) {
        assert_true(owner[i] != UINT32_MAX);
        const double *q = m->normals + 3 * (nv + i);
        assert_true(fabs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 1.0) < 1e-12);
    }
    free(owner);
    /* refused before writing: a corner naming a normal past the end, another
     * vertex's normal, a triangle naming a vertex past the end */
    char dir[512], out[600];
    assert_int_equal(test_mkdtemp(dir, sizeof dir, "lb-corners"), 0);
    char sout[600];
    snprintf(out, sizeof out, "%s/bad.glb", dir);
    snprintf(sout, sizeof sout, "%s/stream.bin", dir);
    lb_mesh bad = *m;
    uint32_t *cn = malloc(3 * m->ntriangles * sizeof *cn),
             *tri = malloc(3 * m->ntriangles * sizeof *tri);
    assert_true(cn && tri);
    memcpy(cn, m->corner_normals, 3 * m->ntriangles * sizeof *cn);
    memcpy(tri, m->triangles, 3 * m->ntriangles * sizeof *tri);
    bad.corner_normals = cn;
    bad.triangles = tri;
    const size_t t = m->ntriangles / 2;
    struct {
        uint32_t *arr;
        uint32_t value;
        const char *says;
    } rows[3] = {{cn, (uint32_t)m->nnormals, "has normal"},
                 {cn, tri[3 * t] ? 0u : 1u, "has normal"},
                 {tri, (uint32_t)nv, "names vertex"}};
    for (int r = 0; r < 3; ++r) {
        const uint32_t keep = rows[r].arr[3 * t];
        rows[r].arr[3 * t] = rows[r].value;
        for (int f = LB_MESH_FORMAT_PLY; f <= LB_MESH_FORMAT_GLB; ++f) {
            lb_error e = {LB_OK, ""};
            assert_int_equal(lb_mesh_write(&bad, out, (lb_mesh_format)f, &e),
                             LB_ERR_INVALID_ARGUMENT);
            char want[64];
            snprintf(want, sizeof want, "triangle %zu", t);
            if (!strstr(e.message, want) || !strstr(e.message, rows[r].says))
                fail_msg("row %d format %d: \"%s\"", r, f, e.message);
            FILE *probe = fopen(out, "rb");
            if (probe) fail_msg("row %d: %s was written", r, out);
            FILE *st = fopen(sout, "w+b");
            assert_non_null(st);
            assert_int_equal(lb_mesh_write_stream(&bad, st, (lb_mesh_format)f, &e),
                             LB_ERR_INVALID_ARGUMENT);
            assert_int_equal(ftell(st), 0);
            fclose(st);
            remove(sout);
        }
        rows[r].arr[3 * t] = keep;
    }
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_mesh_write(&bad, out, LB_MESH_FORMAT_GLB, &e), LB_OK);
    remove(out);
    test_rmdir(dir);
    free(cn);
    free(tri);
    unbuild(&C);
}

static void test_edges(void **state) {
    (void)state;
    size_t checked = 0;
    for (size_t sidx = 0; sidx < nscenes; ++sidx) {
        built B;
        build_file(scene_paths[sidx], 40, 0, 2, &B);
        const lb_mesh *m = B.m;
        const size_t nt = m->ntriangles, nc = 3 * nt;
        if (!nt) {
            unbuild(&B);
            continue;
        }
        uint32_t *edges = malloc(2 * nc * sizeof *edges), *ce = malloc(nc * sizeof *ce);
        uint64_t *key = malloc(nc * sizeof *key);
        unsigned *uses = calloc(nc, sizeof *uses);
        assert_true(edges && ce && key && uses);
        size_t ne = 0;
        lb_error e = {LB_OK, ""};
        assert_int_equal(lb_mesh_edges(m, edges, ce, &ne, &e), LB_OK);
        assert_int_equal(2 * ne, nc); /* closed and manifold: two corners per edge */
        size_t next = 0; /* first appearance: corner order introduces edges 0, 1, 2, ... */
        for (size_t q = 0; q < nc; ++q) {
            const uint32_t a = m->triangles[q], b = m->triangles[q - q % 3 + (q % 3 + 1) % 3];
            const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
            assert_true(ce[q] < ne);
            assert_true(ce[q] <= next);
            if (ce[q] == next) ++next;
            assert_int_equal(edges[2 * ce[q]], lo);
            assert_int_equal(edges[2 * ce[q] + 1], hi);
            uses[ce[q]]++;
            key[q] = (uint64_t)lo << 32 | hi;
        }
        for (size_t i = 0; i < ne; ++i) assert_int_equal(uses[i], 2);
        ++checked;
        qsort(key, nc, sizeof *key, cmp_pair);
        size_t distinct = 0;
        for (size_t q = 0; q < nc; ++q) distinct += q == 0 || key[q] != key[q - 1];
        assert_int_equal(distinct, ne);
        free(edges);
        free(ce);
        free(key);
        free(uses);
        unbuild(&B);
    }
    assert_true(checked >= 17);
    /* an open mesh has boundary edges with one corner each */
    built O;
    build_file(scene_paths[0], 40, LB_MESH_OPEN_BOUNDARY, 1, &O);
    {
        const size_t nc = 3 * O.m->ntriangles;
        uint32_t *edges = malloc(2 * nc * sizeof *edges), *ce = malloc(nc * sizeof *ce);
        size_t ne = 0;
        assert_int_equal(lb_mesh_edges(O.m, edges, ce, &ne, NULL), LB_OK);
        assert_true(ne >= nc / 2 && ne <= nc);
        free(edges);
        free(ce);
    }
    unbuild(&O);
    /* a hand-made mesh: a vertex index out of range is named */
    uint32_t tri[6] = {0, 1, 2, 2, 1, 7};
    lb_mesh bad;
    memset(&bad, 0, sizeof bad);
    bad.nvertices = 4;
    bad.ntriangles = 2;
    bad.triangles = tri;
    uint32_t edges[12], ce[6];
    size_t ne = 99;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_mesh_edges(&bad, edges, ce, &ne, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "triangle 1 names vertex 7"));
    assert_int_equal(ne, 0);
    bad.nvertices = 8;
    assert_int_equal(lb_mesh_edges(&bad, edges, ce, &ne, &e), LB_OK);
    assert_int_equal(ne, 5); /* 01 12 02 17 27 */
    const uint32_t want[10] = {0, 1, 1, 2, 0, 2, 1, 7, 2, 7};
    for (int i = 0; i < 10; ++i) assert_int_equal(edges[i], want[i]);
    const uint32_t wce[6] = {0, 1, 2, 1, 3, 4};
    for (int i = 0; i < 6; ++i) assert_int_equal(ce[i], wce[i]);
}

static void test_bad_options(void **state) {
    (void)state;
    static const char text[] =
        HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"sphere\", \"radius\": 1}}";
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    assert_int_equal(lb_scene_parse(text, strlen(text), "t.json", &sc, &e), LB_OK);
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    lb_mesh_options base;
    lb_mesh_options_init(&base);
    for (int d = 0; d < 3; ++d) {
        base.bmin[d] = -2;
        base.bmax[d] = 2;
    }
    static const struct {
        int field;
        double value;
        lb_status status;
        const char *msg;
    } rows[] = {
        {0, 0, LB_ERR_INVALID_ARGUMENT, "min < max on every axis"},
        {1, 0, LB_ERR_INVALID_ARGUMENT, "resolution = 0; allowed: 1 to 8192"},
        {1, 9000, LB_ERR_INVALID_ARGUMENT, "resolution = 9000; allowed: 1 to 8192"},
        {2, -1, LB_ERR_INVALID_ARGUMENT, "cell_size = -1; allowed: a positive number"},
        {2, 1e-6, LB_ERR_INVALID_ARGUMENT, "allowed: at most 8192 cells per axis"},
        {3, -2, LB_ERR_INVALID_ARGUMENT, "threads = -2"},
        {4, 64, LB_ERR_INVALID_ARGUMENT, "flags = 0x40"},
        {4, 32, LB_ERR_INVALID_ARGUMENT, "LB_MESH_COARSE_FIRST with simplify = 0"},
        {5, 1e9, LB_ERR_INVALID_ARGUMENT, "|value| <= 1e+09"},
        {6, 1 << 20, LB_ERR_INVALID_ARGUMENT, "over the memory cap of 1 MiB"},
        {7, NAN, LB_ERR_INVALID_ARGUMENT, "allowed: finite"},
        {8, -0.1, LB_ERR_INVALID_ARGUMENT, "simplify = -0.1 cells; allowed: 0 (off) to 1 cells"},
        {8, 1.5, LB_ERR_INVALID_ARGUMENT, "simplify = 1.5 cells; allowed: 0 (off) to 1 cells"},
        {8, NAN, LB_ERR_INVALID_ARGUMENT, "simplify = nan cells; allowed: 0 (off) to 1 cells"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
        lb_mesh_options o = base;
        switch (rows[i].field) {
        case 0:
            o.bmax[1] = o.bmin[1];
            break;
        case 1:
            o.resolution = (unsigned)rows[i].value;
            break;
        case 2:
            o.cell_size = rows[i].value;
            break;
        case 3:
            o.threads = (int)rows[i].value;
            break;
        case 4:
            o.flags = (unsigned)rows[i].value;
            break;
        case 5:
            o.bmax[0] = 2e9;
            break;
        case 6:
            o.max_memory = (size_t)rows[i].value;
            o.resolution = 512;
            break;
        case 7:
            o.bmin[2] = rows[i].value;
            break;
        case 8:
            o.simplify = rows[i].value;
            break;
        }
        lb_mesh *m = (lb_mesh *)&o; /* must be reset to NULL */
        e.message[0] = '\0';
        const lb_status s = lb_mesh_create(ev, &o, &m, &e);
        if (s != rows[i].status || !strstr(e.message, rows[i].msg) || m != NULL)
            fail_msg("row %zu: status %d, message \"%s\"; expected %d and \"%s\"", i, s, e.message,
                     rows[i].status, rows[i].msg);
    }
    assert_int_equal(lb_mesh_create(NULL, &base, NULL, &e), LB_ERR_INVALID_ARGUMENT);
    /* writing: an unknown extension and an unwritable folder leave nothing */
    lb_mesh *m = NULL;
    base.resolution = 16;
    assert_int_equal(lb_mesh_create(ev, &base, &m, &e), LB_OK);
    assert_int_equal(lb_mesh_write(m, "out.xyz", LB_MESH_FORMAT_AUTO, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, ".ply, .obj, .stl or .glb"));
    assert_int_equal(lb_mesh_write(m, "/nonexistent-dir/out.ply", LB_MESH_FORMAT_AUTO, &e),
                     LB_ERR_IO);
    assert_non_null(strstr(e.message, "/nonexistent-dir/out.ply"));
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

/* Incremental remeshing (lb_mesh_cache): a lattice of spheres in a blend,
 * its first two in a local union, meshed through one cache while one sphere
 * moves step by step (and then another), each mesh byte-identical to a
 * full lb_mesh_create of the same evaluator (positions, normals, triangles,
 * corner normals), with and without sharp features, on 1, 2 and 3 threads;
 * most blocks come from the cache, all of them for the same scene again.
 * Between steps a mesh is given back to the cache (lb_mesh_cache_recycle)
 * in turn: none, the cache's own output, or the full mesh with every byte
 * of its arrays overwritten (the next output must not depend on what they
 * held), and once an empty mesh of another region. */
static char *lattice_text(int moved, double dx, double dr, double r) {
    const size_t cap = 16384;
    char *t = malloc(cap);
    assert_non_null(t);
    int w = snprintf(t, cap,
                     "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\", "
                     "\"bounds\": {\"min\": [-2, -2, -2], \"max\": [2, 2, 2]}, \"root\": "
                     "{\"type\": \"displacement\", \"op\": \"union\", \"r\": %.17g, \"p\": 2, "
                     "\"m\": 1, \"args\": [{\"type\": \"local_union\", \"args\": ["
                     "{\"type\": \"sphere\", \"center\": [-1.2, -1.2, -1.2], \"radius\": 0.4}, "
                     "{\"type\": \"sphere\", \"center\": [-0.7, -1.2, -1.2], \"radius\": 0.3}]}",
                     r);
    for (int q = 0; q < 27; ++q) {
        double c[3] = {-1.2 + 1.2 * (q % 3), -1.2 + 1.2 * (q / 3 % 3), -1.2 + 1.2 * (q / 9)};
        if (q == 0) continue; /* the local union's */
        if (q == moved) c[0] += dx;
        w += snprintf(t + w, cap - (size_t)w,
                      ", {\"type\": \"sphere\", \"center\": [%.17g, %.17g, %.17g], \"radius\": "
                      "%.17g}",
                      c[0], c[1], c[2], q == moved ? 0.3 + dr : 0.3);
    }
    snprintf(t + w, cap - (size_t)w, "]}}");
    return t;
}

/* Options for lattice_text's region at res cells on threads threads. */
static lb_mesh_options lattice_options(unsigned res, int threads) {
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -2.0;
        o.bmax[d] = 2.0;
    }
    o.resolution = res;
    o.threads = threads;
    return o;
}

static int same_mesh(const lb_mesh *a, const lb_mesh *b) {
    if (a->nvertices != b->nvertices || a->ntriangles != b->ntriangles ||
        a->nnormals != b->nnormals || !a->corner_normals != !b->corner_normals)
        return 0;
    return !memcmp(a->positions, b->positions, 3 * a->nvertices * sizeof(double)) &&
           !memcmp(a->normals, b->normals, 3 * a->nnormals * sizeof(double)) &&
           !memcmp(a->triangles, b->triangles, 3 * a->ntriangles * sizeof(uint32_t)) &&
           (!a->corner_normals ||
            !memcmp(a->corner_normals, b->corner_normals, 3 * a->ntriangles * sizeof(uint32_t)));
}

static void test_mesh_cache(void **state) {
    (void)state;
    /* (edited sphere, its x offset, its radius's change, the blend's r) in
     * turn: the same scene, steps of 1 % of the region, another sphere,
     * back to the start; then the sphere grown, and the blend's range
     * doubled, which changes the content but not the length of the plans
     * of the selection's boxes (their blocks must not be carried over:
     * cache.c), and back */
    static const int moved[] = {-1, -1, 13, 13, 13, 5, -1, 13, -1, -1, -1};
    static const double dx[] = {0.0, 0.0, 0.04, 0.08, 0.12, -0.04, 0.0, 0.0, 0.0, 0.0, 0.0};
    static const double dr[] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0};
    static const double br[] = {0.15, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15, 0.3, 0.15};
    enum { NSTEP = sizeof moved / sizeof moved[0] };
    size_t reused_total = 0, blocks_total = 0;
    for (int variant = 0; variant < 3; ++variant)
        for (int threads = 1; threads <= 3; ++threads) {
            lb_error e = {LB_OK, ""};
            lb_mesh_cache *cache = NULL;
            assert_int_equal(lb_mesh_cache_create(&cache, &e), LB_OK);
            lb_mesh_options o = lattice_options(64, threads);
            /* 0: plain; 1: features and corner normals; 2: coarse first */
            o.flags = variant == 1   ? LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS
                      : variant == 2 ? LB_MESH_COARSE_FIRST
                                     : 0u;
            for (int step = 0; step < NSTEP; ++step) {
                /* coarse first: one step at another tolerance (meshed
                 * whole), the threads' decision tables kept from the
                 * steps before (cache.c) */
                o.simplify = variant == 2 ? (step == 9 ? 1.0 : 0.25) : 0.0;
                char *text = lattice_text(moved[step], dx[step], dr[step], br[step]);
                lb_scene *sc = NULL;
                lb_evaluator *ev = NULL;
                lb_mesh *mc = NULL, *mf = NULL;
                if (lb_scene_parse(text, strlen(text), "lattice.json", &sc, &e) ||
                    lb_evaluator_create(sc, &ev, &e) ||
                    lb_mesh_create_cached(ev, &o, cache, &mc, &e) ||
                    lb_mesh_create(ev, &o, &mf, &e))
                    fail_msg("step %d: %s", step, e.message);
                lb_mesh_cache_stats st;
                lb_mesh_cache_stats_get(cache, &st);
                if (!same_mesh(mc, mf))
                    fail_msg("variant %d, %d threads, step %d: the cached mesh differs from the "
                             "full one (%zu of %zu blocks from the cache)",
                             variant, threads, step, st.reused, st.blocks);
                if (step == 1 && st.reused != st.blocks)
                    fail_msg("the same scene again: %zu of %zu blocks", st.reused, st.blocks);
                if (step >= 1 && step < 7) { /* the small edits */
                    reused_total += st.reused;
                    blocks_total += st.blocks;
                }
                if (step % 3 == 1) {
                    lb_mesh_cache_recycle(cache, mc);
                    mc = NULL;
                } else if (step % 3 == 2) {
                    memset(mf->positions, 0xA5, 3 * mf->nvertices * sizeof(double));
                    memset(mf->normals, 0x5A, 3 * mf->nnormals * sizeof(double));
                    memset(mf->triangles, 0xFF, 3 * mf->ntriangles * sizeof(uint32_t));
                    const size_t before = st.bytes;
                    const size_t arrays =
                        6 * mf->nvertices * sizeof(double) + 3 * mf->ntriangles * sizeof(uint32_t);
                    lb_mesh_cache_recycle(cache, mf);
                    mf = NULL;
                    lb_mesh_cache_stats_get(cache, &st);
                    /* the arrays as allocated: at most a page more each */
                    if (st.bytes < before + arrays || st.bytes > before + arrays + 3 * 4096 + 64)
                        fail_msg("a mesh given back: the cache holds %zu bytes, expected %zu + %zu "
                                 "(+ at most 3 pages)",
                                 st.bytes, before, arrays);
                } else if (step == 3) { /* an empty mesh, of a region the surface misses */
                    lb_mesh_options q = o;
                    for (int d = 0; d < 3; ++d) {
                        q.bmin[d] = 1.9;
                        q.bmax[d] = 1.95;
                    }
                    lb_mesh *me = NULL;
                    if (lb_mesh_create(ev, &q, &me, &e)) fail_msg("empty region: %s", e.message);
                    assert_int_equal(me->ntriangles, 0);
                    lb_mesh_cache_recycle(cache, me);
                }
                lb_mesh_free(mc);
                lb_mesh_free(mf);
                lb_evaluator_free(ev);
                lb_scene_free(sc);
                free(text);
            }
            lb_mesh_cache_free(cache);
        }
    printf("mesh cache: %zu of %zu blocks from the cache\n", reused_total, blocks_total);
    assert_true(reused_total >= blocks_total / 2);
    lb_mesh_cache_stats st;
    lb_mesh_cache_stats_get(NULL, &st);
    assert_int_equal(st.blocks, 0);
    lb_mesh_cache_recycle(NULL, NULL); /* both NULL: nothing */
}

/* Many small edits, each somewhere else: the cache's memory stays bounded
 * (its slabs' holes are moved out: cache.c) and every mesh is the full
 * one's bytes. */
static void test_mesh_cache_memory(void **state) {
    (void)state;
    lb_error e = {LB_OK, ""};
    lb_mesh_cache *cache = NULL;
    assert_int_equal(lb_mesh_cache_create(&cache, &e), LB_OK);
    const lb_mesh_options o = lattice_options(96, 2);
    size_t first = 0, most = 0;
    enum { NEDIT = 60 };
    for (int k = 0; k < NEDIT; ++k) {
        /* sphere 1..26 in turn, moved by 1 % or 2 % of the region */
        char *text = lattice_text(1 + (k * 7) % 26, 0.04 * (1 + (k / 26) % 2), 0.0, 0.15);
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        lb_mesh *mc = NULL, *mf = NULL;
        if (lb_scene_parse(text, strlen(text), "lattice.json", &sc, &e) ||
            lb_evaluator_create(sc, &ev, &e) || lb_mesh_create_cached(ev, &o, cache, &mc, &e))
            fail_msg("edit %d: %s", k, e.message);
        lb_mesh_cache_stats st;
        lb_mesh_cache_stats_get(cache, &st);
        if (k == 0) first = st.bytes;
        if (st.bytes > most) most = st.bytes;
        if (k % 10 == 9) { /* the bytes, now and then (a full mesh is slow) */
            if (lb_mesh_create(ev, &o, &mf, &e)) fail_msg("edit %d: %s", k, e.message);
            if (!same_mesh(mc, mf))
                fail_msg("edit %d: the cached mesh differs from the full one", k);
        }
        lb_mesh_free(mc);
        lb_mesh_free(mf);
        lb_evaluator_free(ev);
        lb_scene_free(sc);
        free(text);
    }
    printf("mesh cache memory: %zu bytes after the first mesh, at most %zu over %d edits\n", first,
           most, NEDIT);
    /* the slabs hold at most twice the live bytes and two slabs more (2.25
     * times); without moving the holes out: 3.7 times, and growing */
    if (2 * most > 5 * first)
        fail_msg("the cache grew from %zu to %zu bytes over %d edits (at most 2.5 times)", first,
                 most, NEDIT);
    lb_mesh_cache_free(cache);
}

/* A cached run cancelled part way (by the progress callback, at several
 * points) fails and leaves the cache as it was: the scene meshed before it
 * then comes all from the cache, and every mesh through the cache is the
 * full one's bytes. On one thread the calling thread makes every progress
 * call, so the points are spread over the run; on two, a worker may take
 * the blocks left after the second call, so a run may end before a later
 * point (its mesh is then checked, and the cache set back). */
static void test_mesh_cache_cancel(void **state) {
    (void)state;
    char *ta = lattice_text(-1, 0.0, 0.0, 0.15), *tb = lattice_text(13, 0.04, 0.0, 0.15);
    lb_error e = {LB_OK, ""};
    lb_scene *sa = NULL, *sb = NULL;
    lb_evaluator *ea = NULL, *eb = NULL;
    if (lb_scene_parse(ta, strlen(ta), "a.json", &sa, &e) || lb_evaluator_create(sa, &ea, &e) ||
        lb_scene_parse(tb, strlen(tb), "b.json", &sb, &e) || lb_evaluator_create(sb, &eb, &e))
        fail_msg("%s", e.message);
    for (int threads = 1; threads <= 2; ++threads) {
        lb_mesh_options o = lattice_options(64, threads);
        lb_mesh *fa = NULL, *fb = NULL, *m = NULL;
        lb_mesh_cache *cache = NULL;
        if (lb_mesh_create(ea, &o, &fa, &e) || lb_mesh_create(eb, &o, &fb, &e) ||
            lb_mesh_cache_create(&cache, &e) || lb_mesh_create_cached(ea, &o, cache, &m, &e))
            fail_msg("%s", e.message);
        lb_mesh_free(m);
        /* how many progress calls a whole incremental run makes */
        prog count = {0, 0.0, 1, -1};
        lb_mesh_cache *probe = NULL;
        o.progress = on_progress;
        o.user = &count;
        if (lb_mesh_cache_create(&probe, &e) || lb_mesh_create_cached(ea, &o, probe, &m, &e))
            fail_msg("%s", e.message);
        lb_mesh_free(m);
        count.calls = 0;
        if (lb_mesh_create_cached(eb, &o, probe, &m, &e)) fail_msg("%s", e.message);
        lb_mesh_free(m);
        lb_mesh_cache_free(probe);
        if (threads == 1) assert_true(count.calls >= 8);
        for (int k = 0; k < 4; ++k) {
            prog p = {0, 0.0, 1, 1 + k * (count.calls - 2) / 4};
            o.progress = on_progress;
            o.user = &p;
            if (count.calls < 6) p.cancel_at = 2 + k % 2; /* the second call: always made */
            const lb_status s = lb_mesh_create_cached(eb, &o, cache, &m, &e);
            if (s == LB_OK && threads > 1 && p.calls < p.cancel_at) { /* done before it */
                if (!same_mesh(m, fb)) fail_msg("%d threads: an edit not cancelled", threads);
                lb_mesh_free(m);
                o.progress = NULL;
                if (lb_mesh_create_cached(ea, &o, cache, &m, &e)) fail_msg("%s", e.message);
                lb_mesh_free(m);
                continue;
            }
            if (s != LB_ERR_CANCELLED || m)
                fail_msg("%d threads, cancelled at call %d of %d: status %d", threads, p.cancel_at,
                         count.calls, (int)s);
            o.progress = NULL;
            lb_mesh_cache_stats st;
            if (lb_mesh_create_cached(ea, &o, cache, &m, &e)) fail_msg("%s", e.message);
            lb_mesh_cache_stats_get(cache, &st);
            if (!same_mesh(m, fa) || st.reused != st.blocks)
                fail_msg("%d threads, after a run cancelled at call %d: %zu of %zu blocks from "
                         "the cache, %s",
                         threads, p.cancel_at, st.reused, st.blocks,
                         same_mesh(m, fa) ? "same bytes" : "other bytes");
            lb_mesh_free(m);
        }
        if (lb_mesh_create_cached(eb, &o, cache, &m, &e)) fail_msg("%s", e.message);
        if (!same_mesh(m, fb)) fail_msg("%d threads: the edit after cancelled runs", threads);
        lb_mesh_free(m);
        lb_mesh_free(fa);
        lb_mesh_free(fb);
        lb_mesh_cache_free(cache);
    }
    lb_evaluator_free(ea);
    lb_evaluator_free(eb);
    lb_scene_free(sa);
    lb_scene_free(sb);
    free(ta);
    free(tb);
}

/* With no argument every case runs; with names (e.g. "test_threads_identical"),
 * only those: the ThreadSanitizer build runs the cases that start threads
 * (tests/CMakeLists.txt, test_mesh_threaded). An unknown name fails. */
int main(int argc, char **argv) {
    const struct CMUnitTest all[] = {
        cmocka_unit_test(test_scenes_closed_and_accurate),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_volumes_and_euler),
        cmocka_unit_test(test_cube_cases),
        cmocka_unit_test(test_tetrahedra_option),
        cmocka_unit_test(test_ambiguous_fields),
        cmocka_unit_test(test_region_cap_and_open),
        cmocka_unit_test(test_no_self_intersections),
        cmocka_unit_test(test_no_self_intersections_features),
        cmocka_unit_test(test_no_self_intersections_simplify),
        cmocka_unit_test(test_coarse_first),
        cmocka_unit_test(test_merge_flat),
        cmocka_unit_test(test_progress_and_cancel),
        cmocka_unit_test(test_simplify_limits),
        cmocka_unit_test(test_bad_options),
        cmocka_unit_test(test_memory_cap_and_empty),
        cmocka_unit_test(test_min_feature),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_corner_normals),
        cmocka_unit_test(test_feature_fit),
        cmocka_unit_test(test_wide_union),
        cmocka_unit_test(test_mesh_cache),
        cmocka_unit_test(test_mesh_cache_memory),
        cmocka_unit_test(test_mesh_cache_cancel),
    };
    enum { NALL = sizeof all / sizeof all[0] };
    if (argc < 2) return cmocka_run_group_tests(all, setup, NULL);
    struct CMUnitTest some[NALL];
    size_t n = 0;
    for (int a = 1; a < argc; ++a) {
        size_t i = 0;
        while (i < NALL && strcmp(all[i].name, argv[a])) ++i;
        if (i == NALL || n == NALL) {
            fprintf(stderr, "test_mesh: no case named '%s'\n", argv[a]);
            return 2;
        }
        some[n++] = all[i];
    }
    return _cmocka_run_group_tests("test_mesh", some, n, setup, NULL);
}
