/* lb_evaluator_extent: a sound and tight box around the solid.
 *
 * - Closed forms: 300 random primitives (spheres, capsules, rotated
 *   ellipsoids; zero and soft convention) whose axis-aligned boxes are known
 *   exactly: the extent contains that box (sound, to 1e-9) and exceeds it by
 *   at most 3 tol on each side (tight), in a search box 40 times the
 *   primitive's size.
 * - Blends, where no closed form exists: a three-sphere displacement union,
 *   a bounded blend and a local union of two soft capsules; every vertex of
 *   a 96-cell mesh of the solid (vertices on the surface) lies inside the
 *   extent, and the extent exceeds the mesh's box by at most 3 tol + a cell.
 * - Flags: a slab (unbounded) touches the search box; a sphere outside it is
 *   empty; one cut by it touches (and the search stops there); an absurdly
 *   small tol stops at the pass cap with a result that is still sound
 *   (COARSE).
 * - Bad arguments: NULL pointers, tol <= 0, an inverted or non-finite box. */
#include "testlib.h"

#include <stdlib.h>

static lb_scene *parse(const char *text) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_scene_parse(text, strlen(text), "x.json", &sc, &e);
    if (s) fail_msg("%s\n%s", e.message, text);
    return sc;
}

static void extent_of(const char *text, const double smin[3], const double smax[3], double tol,
                      double lo[3], double hi[3], int *flags) {
    lb_scene *sc = parse(text);
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    assert_int_equal(lb_evaluator_extent(ev, smin, smax, tol, lo, hi, flags, &e), LB_OK);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

#define HEADC "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"%s\", \"root\": "
#define HEADS                                                                                      \
    "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"soft\", \"bounds\": "      \
    "{\"min\": [-1.6, -1.6, -1.3], \"max\": [2.8, 2.8, 1.3]}, \"root\": "
#define HEAD "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\", \"root\": "

static void test_closed_forms(void **state) {
    (void)state;
    rng_t rng = {12345};
    tally_t t = {"closed forms", 0, 0, 0};
    char text[1024];
    for (int i = 0; i < 300; ++i) {
        const int soft = i % 2, kind = i / 2 % 3;
        const char *kern = soft ? ", \"kernel\": \"wyvill\"" : "";
        double c[3], lo[3], hi[3], size = 0.0;
        for (int d = 0; d < 3; ++d) c[d] = rng_range(&rng, -5, 5);
        if (kind == 0) {
            const double r = rng_log(&rng, 0.05, 3);
            snprintf(text, sizeof text,
                     HEADC "{\"type\": \"sphere\", \"center\": [%.17g, %.17g, %.17g], \"radius\": "
                           "%.17g%s}}",
                     soft ? "soft" : "zero", c[0], c[1], c[2], r, kern);
            for (int d = 0; d < 3; ++d) lo[d] = c[d] - r, hi[d] = c[d] + r;
            size = 2 * r;
        } else if (kind == 1) {
            double e2[3];
            const double r = rng_log(&rng, 0.05, 1);
            for (int d = 0; d < 3; ++d) e2[d] = c[d] + rng_range(&rng, -3, 3);
            snprintf(text, sizeof text,
                     HEADC "{\"type\": \"capsule\", \"start\": [%.17g, %.17g, %.17g], \"end\": "
                           "[%.17g, %.17g, %.17g], \"radius\": %.17g%s}}",
                     soft ? "soft" : "zero", c[0], c[1], c[2], e2[0], e2[1], e2[2], r, kern);
            for (int d = 0; d < 3; ++d) {
                lo[d] = fmin(c[d], e2[d]) - r, hi[d] = fmax(c[d], e2[d]) + r;
                size = fmax(size, hi[d] - lo[d]);
            }
        } else {
            double a[3], ang = rng_range(&rng, 0, 3.14159);
            for (int d = 0; d < 3; ++d) a[d] = rng_log(&rng, 0.1, 2);
            /* rotated by ang about z: the box half-extents are the rows' norms of R diag(a) */
            const double co = cos(ang), si = sin(ang);
            snprintf(text, sizeof text,
                     HEADC "{\"type\": \"ellipsoid\", \"translate\": [%.17g, %.17g, %.17g], "
                           "\"rotate\": [0, 0, %.17g], \"semi_axes\": [%.17g, %.17g, %.17g]%s}}",
                     soft ? "soft" : "zero", c[0], c[1], c[2], ang * 180.0 / 3.141592653589793,
                     a[0], a[1], a[2], kern);
            const double h[3] = {hypot(co * a[0], si * a[1]), hypot(si * a[0], co * a[1]), a[2]};
            for (int d = 0; d < 3; ++d) {
                lo[d] = c[d] - h[d], hi[d] = c[d] + h[d];
                size = fmax(size, 2 * h[d]);
            }
        }
        double smin[3], smax[3], olo[3], ohi[3];
        for (int d = 0; d < 3; ++d) smin[d] = c[d] - 20 * size - 3, smax[d] = c[d] + 20 * size + 3;
        const double tol = size / 64;
        int flags = -1;
        extent_of(text, smin, smax, tol, olo, ohi, &flags);
        tally_check(&t, flags == 0, "case %d: flags %d", i, flags);
        for (int d = 0; d < 3; ++d) {
            tally_check(&t, olo[d] <= lo[d] + 1e-9 && ohi[d] >= hi[d] - 1e-9,
                        "case %d (kind %d): axis %d extent [%.9g, %.9g] misses [%.9g, %.9g]", i,
                        kind, d, olo[d], ohi[d], lo[d], hi[d]);
            tally_check(&t, olo[d] >= lo[d] - 3 * tol && ohi[d] <= hi[d] + 3 * tol,
                        "case %d (kind %d): axis %d extent [%.9g, %.9g] loose around [%.9g, %.9g], "
                        "tol %g",
                        i, kind, d, olo[d], ohi[d], lo[d], hi[d], tol);
        }
    }
    tally_end(&t, 300 * 7);
}

/* every vertex of a mesh of the solid inside the extent; the extent close
 * to the mesh's box */
static void check_mesh(tally_t *t, const char *name, const char *text, const double bmin[3],
                       const double bmax[3]) {
    lb_scene *sc = parse(text);
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_evaluator_create(sc, &ev, &e)) fail_msg("%s: %s", name, e.message);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    memcpy(o.bmin, bmin, sizeof o.bmin);
    memcpy(o.bmax, bmax, sizeof o.bmax);
    o.resolution = 96;
    o.threads = 1;
    lb_mesh *m = NULL;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_true(m->nvertices > 100);
    double smin[3], smax[3], lo[3], hi[3], mlo[3], mhi[3], longest = 0.0;
    for (int d = 0; d < 3; ++d) {
        const double w = bmax[d] - bmin[d];
        smin[d] = bmin[d] - 10 * w; /* a search box far larger than the solid */
        smax[d] = bmax[d] + 10 * w;
        longest = fmax(longest, w);
        mlo[d] = INFINITY, mhi[d] = -INFINITY;
    }
    const double tol = longest / 128, cell = longest / 96;
    int flags = -1;
    assert_int_equal(lb_evaluator_extent(ev, smin, smax, tol, lo, hi, &flags, &e), LB_OK);
    tally_check(t, flags == 0, "%s: flags %d", name, flags);
    size_t outside = 0;
    for (size_t v = 0; v < m->nvertices; ++v)
        for (int d = 0; d < 3; ++d) {
            const double x = m->positions[3 * v + d];
            mlo[d] = fmin(mlo[d], x), mhi[d] = fmax(mhi[d], x);
            outside += x < lo[d] - 1e-9 || x > hi[d] + 1e-9;
        }
    tally_check(t, outside == 0, "%s: %zu vertex coordinates outside the extent", name, outside);
    for (int d = 0; d < 3; ++d)
        tally_check(t, lo[d] >= mlo[d] - 3 * tol - cell && hi[d] <= mhi[d] + 3 * tol + cell,
                    "%s: axis %d extent [%.6g, %.6g] loose around the mesh's [%.6g, %.6g]", name, d,
                    lo[d], hi[d], mlo[d], mhi[d]);
    fprintf(stderr,
            "  %-26s extent [%.4f %.4f %.4f]..[%.4f %.4f %.4f], mesh box "
            "[%.4f %.4f %.4f]..[%.4f %.4f %.4f]\n",
            name, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], mlo[0], mlo[1], mlo[2], mhi[0], mhi[1],
            mhi[2]);
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

static void test_blends(void **state) {
    (void)state;
    tally_t t = {"blends against their meshes", 0, 0, 0};
    const double b1[3] = {-1.6, -1.6, -1.3}, b2[3] = {2.8, 2.8, 1.3};
    check_mesh(&t, "displacement union",
               HEAD "{\"type\": \"displacement\", \"op\": \"union\", \"r\": 0.4, \"args\": ["
                    "{\"type\": \"sphere\", \"radius\": 1}, {\"type\": \"sphere\", "
                    "\"center\": [1.4, 0, 0], \"radius\": 0.8}, {\"type\": \"sphere\", "
                    "\"center\": [0, 1.5, 0.2], \"radius\": 0.7}]}}",
               b1, b2);
    check_mesh(&t, "bounded union",
               HEAD "{\"type\": \"bounded\", \"op\": \"union\", \"args\": ["
                    "{\"type\": \"sphere\", \"radius\": 1}, {\"type\": \"capsule\", "
                    "\"start\": [0, 0, 0], \"end\": [2, 1.5, 0], \"radius\": 0.3}], "
                    "\"bounds\": [{\"type\": \"sphere\", \"radius\": 1.5}, {\"type\": "
                    "\"sphere\", \"radius\": 1.5}]}}",
               b1, b2);
    check_mesh(&t, "soft local union",
               HEADS "{\"type\": \"local_union\", \"args\": [{\"type\": \"capsule\", "
                     "\"start\": [-0.9, 0, -0.3], \"end\": [0.9, 0, -0.3], \"radius\": 0.45, "
                     "\"kernel\": \"wyvill\"}, {\"type\": \"sphere\", \"center\": [0.3, 0, "
                     "0.45], \"radius\": 0.5, \"kernel\": \"wyvill\"}]}}",
               b1, b2);
    tally_end(&t, 3 * 5);
}

static void test_flags(void **state) {
    (void)state;
    const double smin[3] = {-4, -4, -4}, smax[3] = {4, 4, 4};
    double lo[3], hi[3];
    int flags = 0;
    extent_of(HEAD "{\"type\": \"slab\", \"normal\": [0, 0, 1], \"half_width\": 0.5}}", smin, smax,
              0.05, lo, hi, &flags);
    assert_true(flags & LB_EXTENT_TOUCHES);
    /* it touches on x: the work stops there, the other sides stay sound (the search box) */
    assert_true(lo[0] <= -4 && hi[0] >= 4 && lo[2] <= -0.5 && hi[2] >= 0.5);
    extent_of(HEAD "{\"type\": \"sphere\", \"center\": [9, 0, 0], \"radius\": 1}}", smin, smax,
              0.05, lo, hi, &flags);
    assert_int_equal(flags, LB_EXTENT_EMPTY);
    extent_of(HEAD "{\"type\": \"sphere\", \"center\": [4, 0, 0], \"radius\": 1}}", smin, smax,
              0.05, lo, hi, &flags);
    assert_int_equal(flags, LB_EXTENT_TOUCHES);
    assert_true(lo[0] <= 3 && lo[0] > 2.8 && hi[0] >= 4);
    /* tol at the smallest allowed: the pass cap ends it, the box still holds the sphere */
    extent_of(HEAD "{\"type\": \"capsule\", \"start\": [0, 0, 0], \"end\": [1, 1, 1], "
                   "\"radius\": 0.5}}",
              smin, smax, 8e-12, lo, hi, &flags);
    assert_true(flags & LB_EXTENT_COARSE);
    for (int d = 0; d < 3; ++d) assert_true(lo[d] <= -0.5 && hi[d] >= 1.5);
}

static void test_bad_arguments(void **state) {
    (void)state;
    lb_scene *sc = parse(HEAD "{\"type\": \"sphere\", \"radius\": 1}}");
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    const double smin[3] = {-2, -2, -2}, smax[3] = {2, 2, 2}, inv[3] = {2, -2, -2};
    const double huge[3] = {-2, -2, 1e300};
    double lo[3] = {7, 7, 7}, hi[3] = {7, 7, 7};
    int flags = 7;
    assert_int_equal(lb_evaluator_extent(NULL, smin, smax, 0.1, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_int_equal(lb_evaluator_extent(ev, NULL, smax, 0.1, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_int_equal(lb_evaluator_extent(ev, smin, smax, 0.1, lo, hi, NULL, NULL),
                     LB_ERR_INVALID_ARGUMENT);
    assert_int_equal(lb_evaluator_extent(ev, smin, smax, 0.0, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "tol = 0"));
    assert_int_equal(lb_evaluator_extent(ev, smin, smax, NAN, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_int_equal(lb_evaluator_extent(ev, inv, smax, 0.1, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "search box x range [2, 2]"));
    assert_int_equal(lb_evaluator_extent(ev, smin, huge, 0.1, lo, hi, &flags, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_true(lo[0] == 7 && hi[0] == 7 && flags == 7); /* untouched on failure */
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_forms),
        cmocka_unit_test(test_blends),
        cmocka_unit_test(test_flags),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
