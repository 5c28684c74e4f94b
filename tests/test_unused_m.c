/* lb_scene_unused_m: the nodes whose m can change nothing.
 *
 * Two kinds of checks. The list itself, on scenes built to cover every way
 * up the tree: a blend under min, max, complement, a transformed ref, an
 * R-function or a clean union only (listed), under a blend, a level or a
 * local union (not listed), a def reached both ways (not listed), a def
 * reached only through min (listed once), caller arrays shorter than the
 * list, NULL. And the property the list claims, on the field itself: for
 * every listed scene, setting m back to 1 leaves the sign of the field the
 * same at every point of a 41^3 grid (the surface does not move), while
 * the field's largest slope on that grid grows (m only steepens); for the
 * not-listed scenes, m = 1 moves the surface (signs differ somewhere). */
#include "testlib.h"

#include <stdlib.h>

#define HEAD "{\"format\": \"libblend-scene\", \"version\": 1, "
#define BOUNDS "\"bounds\": {\"min\": [-2, -2, -2], \"max\": [3, 3, 2]}, "
#define ZERO(defs, root) HEAD "\"convention\": \"zero\", " BOUNDS defs "\"root\": " root "}"
#define SOFT(root) HEAD "\"convention\": \"soft\", " BOUNDS "\"root\": " root "}"
#define S(x, y) "{\"type\": \"sphere\", \"center\": [" #x ", " #y ", 0], \"radius\": 1}"
#define W(x, y)                                                                                    \
    "{\"type\": \"sphere\", \"center\": [" #x ", " #y ", 0], \"radius\": 1, \"kernel\": "          \
    "\"wyvill\"}"
/* the blend whose m is in question: m = 0.4 (the "@" is replaced by 1) */
#define MB                                                                                         \
    "{\"type\": \"displacement\", \"op\": \"union\", \"r\": 0.5, \"m\": 0.4@, \"args\": [" S(      \
        0, 0) ", " S(1.2, 0) "]}"
#define SMB                                                                                        \
    "{\"type\": \"soft_hyper\", \"op\": \"union\", \"r\": 0.5, \"m\": 0.4@, \"args\": [" W(        \
        0, 0) ", " W(1.2, 0) "]}"
#define BLEND(a, b)                                                                                \
    "{\"type\": \"displacement\", \"op\": \"union\", \"r\": 0.6, \"args\": [" a ", " b "]}"

typedef struct row {
    const char *name;
    const char *text;
    size_t listed;    /* how many nodes lb_scene_unused_m names */
    const char *path; /* the first one's JSON path (listed > 0) */
} row;

static const row ROWS[] = {
    {"root blend", ZERO("", MB), 1, "$.root"},
    {"under min", ZERO("", "{\"type\": \"min\", \"args\": [" MB ", " S(0, 2) "]}"), 1,
     "$.root.args[0]"},
    {"under max", ZERO("", "{\"type\": \"max\", \"args\": [" MB ", " S(0.6, 0.3) "]}"), 1,
     "$.root.args[0]"},
    {"under complement, inside max",
     ZERO("", "{\"type\": \"max\", \"args\": [" S(
                  0.6, 0) ", {\"type\": \"complement\", \"args\": [" MB "]}]}"),
     1, "$.root.args[1].args[0]"},
    {"under rfunction",
     ZERO("", "{\"type\": \"rfunction\", \"op\": \"union\", \"args\": [" MB ", " S(0, 2.5) "]}"), 1,
     "$.root.args[0]"},
    {"def only under min, twice",
     ZERO("\"defs\": {\"d\": " MB "}, ",
          "{\"type\": \"min\", \"args\": [{\"ref\": \"d\"}, {\"ref\": \"d\", \"translate\": [0, 0, "
          "0.5]}]}"),
     1, "$.defs.d"},
    {"soft under clean_union",
     SOFT("{\"type\": \"clean_union\", \"args\": [" SMB ", " W(0, 2.2) "]}"), 1, "$.root.args[0]"},
    {"under a blend", ZERO("", BLEND(MB, S(0.5, 1.6))), 0, NULL},
    {"under min under a blend",
     ZERO("", BLEND("{\"type\": \"min\", \"args\": [" MB ", " S(3, 3) "]}", S(0.5, 1.6))), 0, NULL},
    {"under level", ZERO("", "{\"type\": \"level\", \"level\": 0.3, \"args\": [" MB "]}"), 0, NULL},
    {"def under min and under a blend",
     ZERO("\"defs\": {\"d\": " MB "}, ", "{\"type\": \"min\", \"args\": [{\"ref\": \"d\"}, " BLEND(
                                             "{\"ref\": \"d\"}", S(0.5, 1.6)) "]}"),
     0, NULL},
    {"soft under local_union",
     SOFT("{\"type\": \"local_union\", \"args\": [" SMB ", " W(0.6, 1.2) "]}"), 0, NULL},
};

/* the scene text with "@" removed (m as written) or with "0.4@" made "1" */
static char *variant(const char *text, int m_one) {
    const size_t n = strlen(text);
    char *out = malloc(n + 1), *o = out;
    assert_non_null(out);
    for (const char *c = text; *c; ++c) {
        if (m_one && strncmp(c, "0.4@", 4) == 0) {
            *o++ = '1';
            c += 3;
        } else if (*c != '@') {
            *o++ = *c;
        }
    }
    *o = 0;
    return out;
}

static lb_scene *parse(const char *text) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_scene_parse(text, strlen(text), "m.json", &sc, &e);
    if (s) fprintf(stderr, "%s\n", e.message);
    assert_int_equal(s, LB_OK);
    return sc;
}

enum { G = 41 };

/* the field and its slope on a G^3 grid over the bounds */
static void grid(const lb_scene *sc, double *v, double *slope) {
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    const size_t n = (size_t)G * G * G;
    double *m = malloc(6 * n * sizeof *m);
    assert_non_null(m);
    double *x = m, *y = x + n, *z = y + n, *gx = z + n, *gy = gx + n, *gz = gy + n;
    double lo[3], hi[3];
    lb_scene_bounds(sc, lo, hi);
    for (size_t i = 0; i < n; ++i) {
        x[i] = lo[0] + (hi[0] - lo[0]) * (double)(i % G) / (G - 1);
        y[i] = lo[1] + (hi[1] - lo[1]) * (double)(i / G % G) / (G - 1);
        z[i] = lo[2] + (hi[2] - lo[2]) * (double)(i / G / G) / (G - 1);
    }
    assert_int_equal(lb_evaluator_eval(ev, n, x, y, z, v, gx, gy, gz, 1, &e), LB_OK);
    *slope = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double l = sqrt(gx[i] * gx[i] + gy[i] * gy[i] + gz[i] * gz[i]);
        if (l > *slope) *slope = l;
    }
    free(m);
    lb_evaluator_free(ev);
}

static void test_rows(void **state) {
    (void)state;
    const size_t n = (size_t)G * G * G;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    for (size_t r = 0; r < sizeof ROWS / sizeof *ROWS; ++r) {
        const row *R = &ROWS[r];
        char *t_m = variant(R->text, 0), *t_one = variant(R->text, 1);
        lb_scene *sc = parse(t_m), *one = parse(t_one);
        const char *paths[4] = {NULL, NULL, NULL, NULL};
        const size_t got = lb_scene_unused_m(sc, paths, 4);
        if (got != R->listed || (R->path && (!paths[0] || strcmp(paths[0], R->path))))
            fail_msg("%s: %zu listed (want %zu), first %s (want %s)", R->name, got, R->listed,
                     paths[0] ? paths[0] : "none", R->path ? R->path : "none");
        assert_int_equal(lb_scene_unused_m(one, NULL, 0), 0);
        double slope_m, slope_one;
        grid(sc, a, &slope_m);
        grid(one, b, &slope_one);
        size_t differ = 0, counted = 0;
        for (size_t i = 0; i < n; ++i) {
            const double level = lb_scene_convention(sc) == LB_CONVENTION_SOFT ? 0.5 : 0.0;
            const double da = a[i] - level, db = b[i] - level;
            if (fabs(da) < 1e-9 || fabs(db) < 1e-9) continue; /* on the surface */
            ++counted;
            differ += (da < 0) != (db < 0);
        }
        assert_true(counted > n / 2);
        printf("%-34s listed %zu, %zu of %zu grid points change side with m = 1, slope %.3g "
               "(m = 1: %.3g)\n",
               R->name, got, differ, counted, slope_m, slope_one);
        if (R->listed) {
            if (differ) fail_msg("%s: listed, but m = 1 moves the surface", R->name);
            if (!(slope_m > 1.5 * slope_one))
                fail_msg("%s: m = 0.4 should steepen the field: %g against %g", R->name, slope_m,
                         slope_one);
        } else if (!differ) {
            fail_msg("%s: not listed, but m = 1 moves nothing on the grid", R->name);
        }
        lb_scene_free(sc);
        lb_scene_free(one);
        free(t_m);
        free(t_one);
    }
    free(a);
    free(b);
}

/* caller arrays shorter than the list, counting only, NULL */
static void test_arrays(void **state) {
    (void)state;
    char *t = variant(ZERO("", "{\"type\": \"min\", \"args\": [" MB ", " MB ", " MB "]}"), 0);
    lb_scene *sc = parse(t);
    const char *paths[3] = {NULL, NULL, (const char *)1};
    assert_int_equal(lb_scene_unused_m(sc, paths, 2), 3);
    assert_string_equal(paths[0], "$.root.args[0]");
    assert_string_equal(paths[1], "$.root.args[1]");
    assert_ptr_equal(paths[2], (const char *)1); /* past max: untouched */
    assert_int_equal(lb_scene_unused_m(sc, NULL, 5), 3);
    assert_int_equal(lb_scene_unused_m(sc, paths, 0), 3);
    assert_int_equal(lb_scene_unused_m(NULL, paths, 3), 0);
    lb_scene_free(sc);
    free(t);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows),
        cmocka_unit_test(test_arrays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
