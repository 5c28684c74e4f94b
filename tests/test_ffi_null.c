/* Every public function with every combination of NULL and valid pointer
 * arguments, and sizes 0, 1 and the largest, as a binding (ctypes, another
 * runtime) might pass them by mistake. Nothing may crash (this test runs in
 * the sanitizer build too); a call that fails returns a status and, when err
 * is given, the same status and a message; a call missing a pointer it
 * needs fails; functions that return a value instead of a status return NaN,
 * 0 or nothing for NULL. The combinations are generated: one bit of the
 * mask per pointer argument. */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"
#include "testfs.h"

#include <stdlib.h>

#define NARGS_MAX 10

typedef struct ctx {
    lb_scene *scene;
    lb_evaluator *ev;
    lb_mesh *mesh;
    char tmpdir[64];
} ctx;

static ctx C;
static long calls, failures_checked;

/* One enumerated function: call it with mask bit i set meaning "pointer
 * argument i is NULL"; `size` picks 0, 1 or the largest count. Returns the
 * status; *has_status is 0 for functions without one. */
typedef lb_status (*caller)(unsigned mask, int size, lb_error *err, int *has_status);

typedef struct fn_case {
    const char *name;
    int npointers;     /* err counts as the last pointer where the function has one */
    unsigned required; /* pointers whose NULL must make the call fail */
    caller call;
} fn_case;

#define P(i, v) ((mask >> (i)) & 1u ? NULL : (v))
static size_t sz(int size, size_t one) {
    return size == 0 ? 0 : size == 1 ? one : (size_t)-1 / 16;
}

static double X2[2] = {0.1, -0.2}, R2[2] = {0.5, 0.5}, P2[2] = {2, 2}, M2[2] = {1, 1};
static double G3a[3] = {1, 0, 0}, G3b[3] = {0, 1, 0};
static double outv, outg[LB_MAX_ARITY], outg2[LB_MAX_ARITY], dg1[3], dg2[3];

static lb_status c_version(unsigned mask, int size, lb_error *err, int *hs) {
    (void)mask, (void)size, (void)err;
    *hs = 0;
    assert_true(lb_version() > 0);
    for (int s = -1; s < 9; ++s) assert_non_null(lb_status_string((lb_status)s));
    return LB_OK;
}

static lb_status c_displacement(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_displacement(LB_UNION, sz(size, 2), P(0, X2), P(1, R2), P(2, P2), P(3, M2),
                           P(4, &outv), P(5, outg), P(6, err));
}
static lb_status c_conic(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    return lb_conic(LB_UNION, P(0, X2), P(1, R2), 0.0, P(2, M2), P(3, &outv), P(4, outg),
                    P(5, err));
}
static lb_status c_scale_ba(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_scale_ba(sz(size, 2), P(0, X2), P(1, R2), P(2, P2), P(3, &outv), P(4, outg),
                       P(5, err));
}
static lb_status c_scale_bs(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_scale_bs(sz(size, 2), P(0, X2), P(1, R2), P(2, P2), P(3, &outv), P(4, outg),
                       P(5, err));
}
static lb_status c_scale(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_scale(LB_UNION, sz(size, 2), P(0, X2), P(1, R2), P(2, P2), P(3, &outv), P(4, outg),
                    P(5, err));
}
static lb_status c_bounded(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_bounded(LB_UNION, sz(size, 2), P(0, X2), P(1, R2), P(2, P2), P(3, &outv), P(4, outg),
                      P(5, outg2), P(6, err));
}
static lb_status c_bulge(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    const lb_bulge_params bp = {{0.3, 0.3}, {2, 2}, 0.0, {1, 1}, 0.001, LB_BULGE_RANGE};
    return lb_bulge(LB_BULGE_DISPLACEMENT, LB_UNION, P(0, &bp), P(1, X2), P(2, G3a), P(3, G3b),
                    P(4, &outv), P(5, outg), P(6, dg1), P(7, dg2), P(8, err));
}
static double S2v[2] = {0.4, 0.6};
static lb_status c_soft_hyper(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_soft_hyper(LB_UNION, sz(size, 2), P(0, S2v), P(1, R2), P(2, P2), P(3, M2),
                         P(4, &outv), P(5, outg), P(6, err));
}
static lb_status c_soft_conic(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    return lb_soft_conic(LB_UNION, P(0, S2v), P(1, R2), 0.0, P(2, M2), P(3, &outv), P(4, outg),
                         P(5, err));
}
static lb_status c_classic(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_classic(LB_RFUNC_UNION, sz(size, 2), P(0, X2), 0.0, P(1, &outv), P(2, outg),
                      P(3, err));
}

static lb_status c_clean(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    const double alpha[2] = {0.1, 0.2};
    return lb_clean_union((lb_clean_kind)(size + 1), P(0, S2v), 0.5, P(1, alpha), P(2, &outv),
                          P(3, outg), P(4, err));
}
static lb_status c_barthe(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    return lb_barthe_blend(P(0, S2v), 0.2, 0.3, P(1, &outv), P(2, outg), P(3, err));
}
static lb_status c_mix(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    return lb_local_mix(0.4, 0.6, 0.5 * size, 2.0, P(0, &outv), P(1, outg), P(2, err));
}

static const double C3[3] = {0, 0, 0}, A3[3] = {1, 1, 1}, N3[3] = {0, 0, 1}, Q3[3] = {1, 0, 0};
static lb_primitive prim;
static lb_status c_prims(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    /* every constructor with the same three pointer slots: out, the first
     * vector, and (where there is one) the second; err last */
    lb_status s = lb_primitive_sphere(P(0, &prim), P(1, C3), 1.0, P(3, err));
    lb_status t;
#define MERGE(call)                                                                                \
    t = (call);                                                                                    \
    if (t && !s) s = t;                                                                            \
    if (!t && s) s = t
    /* all must agree: with the same pointers NULL, each fails or each passes */
    MERGE(lb_primitive_ellipsoid(P(0, &prim), P(1, C3), P(2, A3), P(3, err)));
    MERGE(lb_primitive_lp(P(0, &prim), P(1, C3), P(2, A3), 3.0, P(3, err)));
    MERGE(lb_primitive_superquadric(P(0, &prim), P(1, C3), P(2, A3), 1.0, 1.0, P(3, err)));
    MERGE(lb_primitive_slab(P(0, &prim), P(1, C3), P(2, N3), 0.5, P(3, err)));
    MERGE(lb_primitive_halfspace(P(0, &prim), P(1, C3), P(2, N3), 0.0, P(3, err)));
    MERGE(lb_primitive_cylinder(P(0, &prim), P(1, C3), P(2, N3), 0.5, P(3, err)));
    MERGE(lb_primitive_capsule(P(0, &prim), P(1, C3), P(2, Q3), 0.5, P(3, err)));
    MERGE(lb_primitive_torus(P(0, &prim), P(1, C3), P(2, N3), 1.0, 0.2, P(3, err)));
#undef MERGE
    return s;
}
static lb_status c_prim_use(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 0;
    lb_primitive p;
    assert_int_equal(lb_primitive_sphere(&p, C3, 1.0, NULL), LB_OK);
    double g[3];
    const double v = lb_primitive_eval(P(0, &p), P(1, C3), P(2, g));
    const double w = lb_primitive_rho(P(0, &p), P(1, C3), P(2, g));
    if (mask & 3u)
        assert_true(isnan(v) && isnan(w));
    else
        assert_true(isfinite(v) && isfinite(w));
    *hs = 1;
    return lb_primitive_soften(P(3, &p), LB_KERNEL_WYVILL, P(4, err));
}

static const char SCENE[] = "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"zero\","
                            "\"bounds\":{\"min\":[-2,-2,-2],\"max\":[2,2,2]},"
                            "\"root\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1}}";

static lb_status c_scene_parse(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    lb_scene *s = NULL;
    const size_t len = size == 2 ? (size_t)-1 : size == 0 ? 0 : strlen(SCENE);
    lb_status st = lb_scene_parse(P(0, SCENE), len, P(1, "ffi.json"), P(2, &s), P(3, err));
    lb_scene_free(s);
    return st;
}
static lb_status c_scene_load(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_scene *s = NULL;
    lb_status st = lb_scene_load(P(0, "/dev/null"), P(1, &s), P(2, err));
    lb_scene_free(s);
    return st;
}
static lb_status c_scene_queries(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 0;
    double mn[3], mx[3];
    lb_scene_stats st;
    char buf[64];
    (void)lb_scene_convention(P(0, C.scene));
    const int b = lb_scene_bounds(P(0, C.scene), P(1, mn), P(2, mx));
    if (mask & 1u) assert_int_equal(b, 0); /* NULL min / max: only asks */
    (void)lb_scene_render(P(0, C.scene));
    lb_scene_stats_get(P(0, C.scene), P(3, &st));
    const size_t n = lb_scene_describe(P(0, C.scene), P(4, buf),
                                       size == 0   ? 0
                                       : size == 1 ? 1
                                                   : sizeof buf);
    if (mask & 1u) assert_int_equal(n, 0);
    if (!(mask & 1u)) assert_int_equal(n, lb_scene_describe(C.scene, NULL, 10));
    double loc[3], look[3], upv[3], ang;
    lb_pov_camera(P(0, C.scene), 1.0, P(1, loc), P(2, look), P(4, upv), P(3, &ang));
    *hs = 1;
    double v, g[3];
    return lb_scene_eval_reference(P(0, C.scene), P(1, C3), P(2, &v), P(3, g), P(5, err));
}
static lb_status c_materials(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 0;
    lb_material m;
    (void)lb_scene_material_count(P(0, C.scene));
    const int got = lb_scene_material(P(0, C.scene), (size_t)size, P(1, &m));
    if (mask & 3u) assert_int_equal(got, 0);
    *hs = 1;
    const double x[1] = {0}, y[1] = {0}, z[1] = {0};
    uint32_t idx[1];
    return lb_scene_material_index(P(0, C.scene), P(1, C.ev), 1, P(2, x), P(3, y), P(4, z),
                                   P(5, idx), P(6, err));
}
static lb_status c_render(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    const double loc[3] = {0, -5, 1}, at[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    const double lo[3] = {-2, -2, -2}, hi[3] = {2, 2, 2};
    lb_render_light L[3];
    lb_render_three_point(P(0, loc), P(1, at), P(2, up), P(3, L));
    *hs = 1;
    double h;
    return lb_render_floor_height(P(0, C.ev), P(1, lo), P(2, hi), P(3, up), 1, P(4, &h), P(5, err));
}
static lb_status c_evaluator(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    (void)size;
    lb_evaluator *ev = NULL;
    lb_status s = lb_evaluator_create(P(0, C.scene), P(1, &ev), P(2, err));
    (void)lb_evaluator_size(ev);
    (void)lb_evaluator_cost(ev);
    (void)lb_evaluator_compile_cost(ev);
    (void)lb_evaluator_convention(ev);
    lb_evaluator_free(ev);
    return s;
}
static lb_status c_eval(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    double x[2] = {0, 0.5}, y[2] = {0, 0}, z[2] = {0, 0}, v[2], g[3][2];
    const size_t n = size == 0 ? 0 : 2; /* a count past the buffers is no NULL misuse */
    return lb_evaluator_eval(P(0, C.ev), n, P(1, x), P(2, y), P(3, z), P(4, v), P(5, g[0]),
                             P(6, g[1]), P(7, g[2]), 1, P(8, err));
}
static lb_status c_bounds(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    double lo, hi;
    const double bmin[3] = {-1, -1, -1}, bmax[3] = {1, 1, 1};
    return lb_evaluator_bounds(P(0, C.ev), P(1, bmin), P(2, bmax), P(3, &lo), P(4, &hi), P(5, err));
}
static lb_status c_extent(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    double lo[3], hi[3];
    int flags;
    const double smin[3] = {-4, -4, -4}, smax[3] = {4, 4, 4};
    return lb_evaluator_extent(P(0, C.ev), P(1, smin), P(2, smax), 0.5, P(3, lo), P(4, hi),
                               P(5, &flags), P(6, err));
}
static lb_status c_unused_m(unsigned mask, int size, lb_error *err, int *hs) {
    (void)err;
    *hs = 0;
    const char *paths[2];
    (void)lb_scene_unused_m(P(0, C.scene), P(1, paths), (size_t)size);
    return LB_OK;
}
/* the test scene's bounds, 8 cells, one thread */
static void small_options(lb_mesh_options *o) {
    lb_mesh_options_init(o);
    for (int d = 0; d < 3; ++d) {
        o->bmin[d] = -2;
        o->bmax[d] = 2;
    }
    o->resolution = 8;
    o->threads = 1;
}

static lb_status c_mesh(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_mesh_options o;
    lb_mesh_options_init(NULL);
    small_options(&o);
    lb_mesh *m = NULL;
    lb_status s = lb_mesh_create(P(0, C.ev), P(1, &o), P(2, &m), P(3, err));
    lb_mesh_free(m);
    return s;
}
/* through a cache (NULL: the plain mesher), twice: the second run takes
 * its blocks from the first's */
static lb_status c_mesh_cached(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_mesh_options o;
    small_options(&o);
    lb_mesh_cache *cache = NULL;
    if (lb_mesh_cache_create(&cache, NULL)) return LB_ERR_NO_MEMORY;
    lb_status s = LB_OK;
    for (int round = 0; round < 2; ++round) {
        lb_mesh *m = NULL;
        s = lb_mesh_create_cached(P(0, C.ev), P(1, &o), P(2, cache), P(3, &m), P(4, err));
        lb_mesh_cache_recycle(P(2, cache), m); /* NULL cache: freed */
    }
    lb_mesh_cache_stats st;
    lb_mesh_cache_stats_get(P(2, cache), P(1, &st));
    lb_mesh_cache_free(cache);
    return s;
}
/* against the evaluator itself as the previous one: every curve copied */
static lb_status c_evaluator_reusing(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_evaluator *ev = NULL;
    size_t n = 0;
    lb_status s =
        lb_evaluator_create_reusing(P(0, C.scene), P(1, C.ev), P(2, &ev), P(3, &n), P(4, err));
    lb_evaluator_free(ev);
    return s;
}
static lb_status c_level_set(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_level_set_options o;
    lb_level_set_options_init(NULL);
    lb_level_set_options_init(&o);
    for (int d = 0; d < 3; ++d) {
        o.bmin[d] = -2;
        o.bmax[d] = 2;
    }
    o.resolution = 16;
    o.threads = 1;
    o.flags = LB_LEVEL_SET_FIELD | LB_LEVEL_SET_GRADIENT;
    lb_level_set *ls = NULL;
    lb_status s = lb_level_set_create(P(0, C.ev), P(1, &o), P(2, &ls), P(3, err));
    lb_level_set_free(ls);
    return s;
}
static lb_status c_mesh_cache_create(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    lb_mesh_cache *cache = NULL;
    lb_status s = lb_mesh_cache_create(P(0, &cache), P(1, err));
    lb_mesh_cache_free(cache);
    return s;
}
static lb_status c_mesh_edges(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    const size_t nc = 3 * C.mesh->ntriangles;
    uint32_t *edges = malloc(2 * nc * sizeof *edges), *corner = malloc(nc * sizeof *corner);
    assert_true(edges && corner);
    size_t ne = 0;
    lb_status s = lb_mesh_edges(P(0, C.mesh), P(1, edges), P(2, corner), P(3, &ne), P(4, err));
    free(edges);
    free(corner);
    return s;
}
static lb_status c_velocities(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    double *v = malloc(3 * C.mesh->nvertices * sizeof *v + 1);
    assert_non_null(v);
    /* size picks dt: 0 (refused), 0.1, and a huge step */
    const double dt = size == 0 ? 0.0 : size == 1 ? 0.1 : 1e300;
    lb_status s = lb_mesh_velocities(P(0, C.ev), P(1, C.ev), P(2, C.ev), P(3, C.mesh), dt, 1,
                                     P(4, v), P(5, err));
    free(v);
    return s;
}
static lb_status c_mesh_write(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    char path[128];
    snprintf(path, sizeof path, "%s/m.ply", C.tmpdir);
    lb_status s = lb_mesh_write(P(0, C.mesh), P(1, path), (lb_mesh_format)(size * 2), P(3, err));
    FILE *f = tmpfile();
    assert_non_null(f);
    lb_status t = lb_mesh_write_stream(P(0, C.mesh), P(2, f), LB_MESH_FORMAT_PLY, P(3, err));
    fclose(f);
    (void)lb_mesh_format_of(P(1, path));
    remove(path);
    return s ? s : t;
}
static lb_status c_pov(unsigned mask, int size, lb_error *err, int *hs) {
    (void)size;
    *hs = 1;
    char path[128];
    snprintf(path, sizeof path, "%s/s.pov", C.tmpdir);
    const lb_pov_options o = {0, 0, 0.0, 2.0, 1, 0, 0, 0.0, 0};
    double g;
    lb_status s =
        lb_scene_write_pov(P(0, C.scene), P(1, C.ev), P(2, &o), P(3, path), P(4, &g), P(5, err));
    remove(path);
    return s;
}
static lb_status c_output(unsigned mask, int size, lb_error *err, int *hs) {
    *hs = 1;
    char path[128];
    snprintf(path, sizeof path, "%s/o.bin", C.tmpdir);
    lb_output *o = NULL;
    lb_status s = lb_output_open(P(0, path), P(1, &o), P(4, err));
    (void)lb_output_stream(o);
    (void)lb_output_temp_name(o);
    lb_output_stream(NULL);
    lb_output_temp_name(NULL);
    lb_output_discard(NULL);
    if (!s) {
        if (mask & 8u)
            lb_output_discard(o);
        else
            s = lb_output_commit(o, P(4, err));
    } else {
        lb_status t = lb_output_commit(NULL, P(4, err));
        assert_int_not_equal(t, LB_OK);
    }
    lb_status t = lb_output_write_file(P(0, path), P(2, "abc"), (size_t)size, P(4, err));
    if ((mask & 4u) && size && !t)
        fail_msg("lb_output_write_file took NULL data of %d bytes", size);
    remove(path);
    return s ? s : t;
}

static const fn_case CASES[] = {
    {"lb_version / lb_status_string", 0, 0, c_version},
    {"lb_displacement", 7, 0x17, c_displacement},
    {"lb_conic", 6, 0x0b, c_conic},
    {"lb_scale_ba", 6, 0x0f, c_scale_ba},
    {"lb_scale_bs", 6, 0x0f, c_scale_bs},
    {"lb_scale", 6, 0x0f, c_scale},
    {"lb_bounded", 7, 0x0f, c_bounded},
    {"lb_bulge", 9, 0x13, c_bulge},
    {"lb_soft_hyper", 7, 0x17, c_soft_hyper},
    {"lb_soft_conic", 6, 0x0b, c_soft_conic},
    {"lb_classic", 4, 0x03, c_classic},
    {"lb_clean_union", 5, 0x05, c_clean},
    {"lb_barthe_blend", 4, 0x03, c_barthe},
    {"lb_local_mix", 3, 0x01, c_mix},
    {"lb_primitive_* constructors", 4, 0x03, c_prims},
    {"lb_primitive_eval / rho / soften", 5, 0x08, c_prim_use},
    {"lb_scene_parse", 4, 0x05, c_scene_parse},
    {"lb_scene_load", 3, 0x03, c_scene_load},
    {"lb_scene_* queries and reference walk", 6, 0x07, c_scene_queries},
    {"lb_scene_material*", 7, 0x3d, c_materials},
    {"lb_render_three_point / floor_height", 6, 0x1f, c_render},
    {"lb_evaluator_create", 3, 0x03, c_evaluator},
    {"lb_evaluator_eval", 9, 0x1f, c_eval},
    {"lb_evaluator_bounds", 6, 0x1f, c_bounds},
    {"lb_evaluator_extent", 7, 0x3f, c_extent},
    {"lb_scene_unused_m", 2, 0x00, c_unused_m},
    {"lb_mesh_create", 4, 0x07, c_mesh},
    {"lb_mesh_create_cached", 5, 0x0b, c_mesh_cached},
    {"lb_mesh_cache_create", 2, 0x01, c_mesh_cache_create},
    {"lb_level_set_create", 4, 0x07, c_level_set},
    {"lb_evaluator_create_reusing", 5, 0x05, c_evaluator_reusing},
    {"lb_mesh_write / _stream", 4, 0x07, c_mesh_write},
    {"lb_mesh_edges", 5, 0x0f, c_mesh_edges},
    {"lb_mesh_velocities", 6, 0x19, c_velocities},
    {"lb_scene_write_pov", 6, 0x0b, c_pov},
    {"lb_output_*", 5, 0x03, c_output},
};

static void test_every_null_combination(void **state) {
    (void)state;
    const size_t ncases = sizeof CASES / sizeof CASES[0];
    for (size_t c = 0; c < ncases; ++c) {
        const fn_case *F = &CASES[c];
        for (unsigned mask = 0; mask < (1u << F->npointers); ++mask)
            for (int size = 0; size < 3; ++size) {
                lb_error e = {LB_OK, ""};
                int hs = 0;
                const lb_status s = F->call(mask, size, &e, &hs);
                ++calls;
                if (!hs) continue;
                const int err_null = F->npointers && (mask >> (F->npointers - 1)) & 1u;
                if (s != LB_OK && !err_null) {
                    ++failures_checked;
                    if (e.status != s || !e.message[0])
                        fail_msg("%s mask %#x size %d: status %d but err says %d \"%s\"", F->name,
                                 mask, size, s, e.status, e.message);
                }
                /* size 0 is an empty count for eval: no pointer is needed */
                if ((mask & F->required) && s == LB_OK && !(size == 0 && F->call == c_eval))
                    fail_msg("%s mask %#x size %d: a required pointer is NULL but it succeeded",
                             F->name, mask, size);
            }
    }
    printf("%ld calls, %ld failures with messages checked\n", calls, failures_checked);
    assert_true(calls > 5000);
    assert_true(failures_checked > 2000);
}

/* Misuse beyond NULL, as a binding might commit it: counts that disagree
 * with their pointers, NaN and inverted boxes, negative thread counts, huge
 * coordinates. Each must be refused with a message (or, for functions
 * without a status, leave the output untouched or finite), never crash or
 * return a wrong answer with status 0. */
static void test_misuse_shapes(void **state) {
    (void)state;
    long refused = 0;
#define REFUSED(call)                                                                              \
    do {                                                                                           \
        lb_error e_ = {LB_OK, ""};                                                                 \
        const lb_status s_ = (call);                                                               \
        (void)e_;                                                                                  \
        if (s_ != LB_ERR_INVALID_ARGUMENT || !e_.message[0])                                       \
            fail_msg("%s: status %d \"%s\"", #call, s_, e_.message);                               \
        ++refused;                                                                                 \
    } while (0)
    /* a mesh whose counts disagree with its arrays */
    lb_mesh bad = *C.mesh;
    bad.triangles = NULL;
    bad.ntriangles = 5;
    uint32_t edges[64], corner[64];
    size_t ne = 0;
    REFUSED(lb_mesh_edges(&bad, edges, corner, &ne, &e_));
    bad = *C.mesh;
    bad.nvertices = 0; /* triangles naming vertices that are not there */
    static uint32_t ed2[1u << 20], ce2[1u << 20];
    if (3 * bad.ntriangles <= (1u << 20)) REFUSED(lb_mesh_edges(&bad, ed2, ce2, &ne, &e_));
    /* boxes: NaN, inverted, beyond the coordinate range; negative threads */
    const double up[3] = {0, 0, 1}, zero[3] = {0, 0, 0};
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, nan3[3] = {NAN, 0, 0},
                 big3[3] = {1e300, 1, 1};
    double h = 12345.0, blo, bhi;
    REFUSED(lb_render_floor_height(C.ev, lo, hi, up, -5, &h, &e_));
    REFUSED(lb_render_floor_height(C.ev, nan3, hi, up, 1, &h, &e_));
    REFUSED(lb_render_floor_height(C.ev, hi, lo, up, 1, &h, &e_));
    REFUSED(lb_render_floor_height(C.ev, lo, big3, up, 1, &h, &e_));
    REFUSED(lb_render_floor_height(C.ev, lo, hi, zero, 1, &h, &e_));
    assert_true(h == 12345.0); /* untouched on refusal */
    REFUSED(lb_evaluator_bounds(C.ev, nan3, hi, &blo, &bhi, &e_));
    REFUSED(lb_evaluator_bounds(C.ev, hi, lo, &blo, &bhi, &e_));
    double px = 0, py = 0, pz = 0, v = 0;
    REFUSED(lb_evaluator_eval(C.ev, 1, &px, &py, &pz, &v, NULL, NULL, NULL, -5, &e_));
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    memcpy(o.bmin, hi, sizeof o.bmin);
    memcpy(o.bmax, lo, sizeof o.bmax);
    o.resolution = 8;
    lb_mesh *m = NULL;
    REFUSED(lb_mesh_create(C.ev, &o, &m, &e_));
    memcpy(o.bmin, nan3, sizeof o.bmin);
    memcpy(o.bmax, hi, sizeof o.bmax);
    REFUSED(lb_mesh_create(C.ev, &o, &m, &e_));
    memcpy(o.bmin, lo, sizeof o.bmin);
    o.threads = -5;
    REFUSED(lb_mesh_create(C.ev, &o, &m, &e_));
    assert_null(m);
    /* a camera very far away: the lights are finite and around the target */
    const double far[3] = {1e200, -3e199, 2e199}, at[3] = {0, 0, 0};
    lb_render_light L[3];
    memset(L, 0, sizeof L);
    lb_render_three_point(far, at, up, L);
    for (int k = 0; k < 3; ++k) {
        double n2 = 0.0;
        for (int d = 0; d < 3; ++d) {
            assert_true(isfinite(L[k].location[d]));
            n2 += L[k].location[d] / 1e200 * (L[k].location[d] / 1e200);
        }
        assert_true(n2 > 0.01 && L[k].color[0] > 0.0); /* placed, at the camera's scale */
    }
    /* one beyond what a double holds: nothing written */
    const double huge[3] = {1.7e308, -1.7e308, 0};
    memset(L, 0, sizeof L);
    lb_render_three_point(huge, at, up, L);
    for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d) assert_true(L[k].location[d] == 0.0 && isfinite(L[k].color[d]));
#undef REFUSED
    printf("%ld misuse shapes refused with a message\n", refused);
    assert_true(refused >= 12);
}

static int setup(void **state) {
    (void)state;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(SCENE, strlen(SCENE), "ffi.json", &C.scene, &e) ||
        lb_evaluator_create(C.scene, &C.ev, &e))
        return -1;
    lb_mesh_options o;
    small_options(&o);
    if (lb_mesh_create(C.ev, &o, &C.mesh, &e)) return -1;
    return test_mkdtemp(C.tmpdir, sizeof C.tmpdir, "libblend-ffi");
}

static int teardown(void **state) {
    (void)state;
    lb_mesh_free(C.mesh);
    lb_evaluator_free(C.ev);
    lb_scene_free(C.scene);
    test_rmdir(C.tmpdir);
    return 0;
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_every_null_combination),
                                       cmocka_unit_test(test_misuse_shapes)};
    return cmocka_run_group_tests(tests, setup, teardown);
}
