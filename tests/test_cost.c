/* The cost model (scene.h, docs/scene-format.md "Cost"): generated scenes
 * of sibling and shared bulge-eliminated blends, nested chains and shared
 * arguments. The evaluator's real work (instruction runs, counted by the
 * tape runner itself, bulge re-runs included) must equal the model, grow
 * linearly with the number of siblings or shared copies, and stay within
 * LB_SCENE_MAX_COST_FACTOR times the tape; scenes over the limit are refused
 * with the JSON path of the costly node. Operation counts, not times. */
#include "testlib.h"

#include "../libblend/src/evaluation/tape.h"

#include <stdlib.h>

typedef struct sbuf {
    char *s;
    size_t n, cap;
} sbuf;

static void put(sbuf *b, const char *fmt, ...) {
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        const int w = vsnprintf(b->s + b->n, b->cap - b->n, fmt, ap);
        va_end(ap);
        assert_true(w >= 0);
        if (b->n + (size_t)w < b->cap) {
            b->n += (size_t)w;
            return;
        }
        b->cap = 2 * (b->n + (size_t)w) + 256;
        b->s = realloc(b->s, b->cap);
        assert_non_null(b->s);
    }
}

static void head(sbuf *b) {
    b->n = 0;
    put(b, "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"zero\",");
}

static void sphere(sbuf *b, double x, double r) {
    put(b, "{\"type\":\"sphere\",\"center\":[%g,0,0],\"radius\":%g}", x, r);
}

/* a scale difference with bulge elimination: the case */
static void bulge_pair(sbuf *b, double x) {
    put(b, "{\"type\":\"scale\",\"op\":\"difference\",\"r\":0.3,\"p\":2,"
           "\"bulge\":{\"range\":true},\"args\":[");
    sphere(b, x, 0.4);
    put(b, ",");
    sphere(b, x + 0.2, 0.3);
    put(b, "]}");
}

static lb_evaluator *compile(const sbuf *b, lb_status want, const char *want_msg) {
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    lb_status s = lb_scene_parse(b->s, b->n, "gen.json", &sc, &e);
    if (s) fail_msg("parse: %s", e.message);
    s = lb_evaluator_create(sc, &ev, &e);
    lb_scene_free(sc);
    if (s != want) fail_msg("compile: status %d, want %d: %s", s, want, e.message);
    if (want_msg && !strstr(e.message, want_msg))
        fail_msg("message \"%s\" lacks \"%s\"", e.message, want_msg);
    return ev;
}

/* Instruction runs for one chunk of points, counted by the tape runner. */
static size_t counted_runs(const lb_evaluator *ev) {
    double x[LB__CHUNK], y[LB__CHUNK], z[LB__CHUNK];
    for (int i = 0; i < LB__CHUNK; ++i) {
        x[i] = -1.0 + 0.1 * i;
        y[i] = 0.05 * (i % 7);
        z[i] = 0.03 * (i % 5);
    }
    double *regs = malloc(lb__regs_len(ev) * sizeof *regs);
    assert_non_null(regs);
    size_t count = 0;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb__tape_run_counted(ev, LB__CHUNK, x, y, z, regs, &count, &e), LB_OK);
    free(regs);
    return count;
}

/* cost(k) for k = 1..K: the model equals the count, and the count is
 * affine in k (equal steps), within the factor. */
static void check_linear(const char *what, void (*gen)(sbuf *, int), int K) {
    sbuf b = {0};
    size_t prev = 0, step = 0;
    for (int k = 1; k <= K; ++k) {
        gen(&b, k);
        lb_evaluator *ev = compile(&b, LB_OK, NULL);
        const size_t runs = counted_runs(ev);
        const double cost = lb_evaluator_cost(ev);
        if ((double)runs != cost)
            fail_msg("%s k=%d: counted %zu runs, model %.0f", what, k, runs, cost);
        if (cost > LB_SCENE_MAX_COST_FACTOR * (double)lb_evaluator_size(ev))
            fail_msg("%s k=%d: cost %.0f over %d x %zu", what, k, cost, LB_SCENE_MAX_COST_FACTOR,
                     lb_evaluator_size(ev));
        if (k == 2) step = runs - prev;
        if (k > 2 && runs - prev != step)
            fail_msg("%s: k=%d adds %zu runs, k=2 added %zu (not linear)", what, k, runs - prev,
                     step);
        prev = runs;
        lb_evaluator_free(ev);
    }
    /* each extra bulge pair: 3 instructions + 4 sphere re-runs = 7 */
    assert_int_equal(step, 7);
    free(b.s);
}

static void gen_siblings(sbuf *b, int k) {
    head(b);
    put(b, "\"root\":{\"type\":\"min\",\"args\":[");
    for (int i = 0; i < k; ++i) {
        if (i) put(b, ",");
        bulge_pair(b, 0.5 * i);
    }
    put(b, "]}}");
}

static void gen_shared(sbuf *b, int k) {
    head(b);
    put(b, "\"defs\":{\"b\":");
    bulge_pair(b, 0.0);
    put(b, "},\"root\":{\"type\":\"min\",\"args\":[");
    for (int i = 0; i < k; ++i)
        put(b, "%s{\"ref\":\"b\",\"translate\":[%g,0,0]}", i ? "," : "", 0.5 * i);
    put(b, "]}}");
}

/* siblings up to the arity limit: linear, and equal to the count */
static void test_sibling_bulges_linear(void **st) {
    (void)st;
    check_linear("siblings", gen_siblings, LB_MAX_ARITY);
    sbuf b = {0};
    gen_siblings(&b, LB_MAX_ARITY);
    lb_evaluator *ev = compile(&b, LB_OK, NULL);
    assert_true(lb_evaluator_cost(ev) == 7.0 * LB_MAX_ARITY + 1.0);
    assert_true((double)counted_runs(ev) == lb_evaluator_cost(ev));
    lb_evaluator_free(ev);
    free(b.s);
}

static void test_shared_bulges_linear(void **st) {
    (void)st;
    check_linear("shared def", gen_shared, LB_MAX_ARITY);
}

/* a chain of bulges nested n deep over the same arguments, all
 * evaluated: the model equals the count at every depth up to the limit */
static void chain(sbuf *b, int depth, int big) {
    head(b);
    put(b, "\"root\":");
    for (int d = 0; d < depth; ++d)
        put(b, "{\"type\":\"displacement\",\"op\":\"union\",\"r\":0.3,\"p\":2,"
               "\"bulge\":{\"range\":true},\"args\":[");
    /* the innermost first argument: a union of `big` spheres */
    put(b, "{\"type\":\"min\",\"args\":[");
    for (int i = 0; i < big; ++i) {
        if (i) put(b, ",");
        sphere(b, 0.01 * i, 0.5);
    }
    put(b, "]}");
    for (int d = 0; d < depth; ++d) {
        put(b, ",");
        sphere(b, 1.0 + d, 0.5);
        put(b, "]}");
    }
    put(b, "}");
}

static void test_nested_chain(void **st) {
    (void)st;
    sbuf b = {0};
    for (int depth = 1; depth <= LB_SCENE_MAX_BULGE_NESTING; ++depth) {
        chain(&b, depth, 2);
        lb_evaluator *ev = compile(&b, LB_OK, NULL);
        assert_true((double)counted_runs(ev) == lb_evaluator_cost(ev));
        lb_evaluator_free(ev);
    }
    /* four levels over a large argument: about 81 runs per instruction,
     * over the factor: refused, naming the outermost bulge blend */
    chain(&b, 4, 200);
    lb_evaluator *ev = compile(&b, LB_ERR_INVALID_ARGUMENT, "$.root: the scene costs ");
    assert_null(ev);
    chain(&b, 4, 200);
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    assert_int_equal(lb_scene_parse(b.s, b.n, "gen.json", &sc, &e), LB_OK);
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "allowed: at most 64 times the tape size"));
    lb_scene_free(sc);
    free(b.s);
}

/* Defs that double at each level: 2^20 uses of one sphere under one
 * transform compile to one instruction per level; the plain walk would
 * visit all 2^21 nodes, and refuses. */
static void test_shared_doubling(void **st) {
    (void)st;
    sbuf b = {0};
    head(&b);
    put(&b, "\"defs\":{\"d0\":");
    sphere(&b, 0.0, 1.0);
    for (int i = 1; i <= 20; ++i)
        put(&b, ",\"d%d\":{\"type\":\"min\",\"args\":[{\"ref\":\"d%d\"},{\"ref\":\"d%d\"}]}", i,
            i - 1, i - 1);
    put(&b, "},\"root\":{\"ref\":\"d20\"}}");
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_scene_parse(b.s, b.n, "gen.json", &sc, &e), LB_OK);
    lb_evaluator *ev = NULL;
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    assert_int_equal(lb_evaluator_size(ev), 21);
    assert_true(lb_evaluator_cost(ev) == 21.0);
    assert_true(counted_runs(ev) == 21);
    const double X[3] = {0.5, 0, 0};
    sbuf one = {0};
    head(&one);
    put(&one, "\"root\":");
    sphere(&one, 0.0, 1.0);
    put(&one, "}");
    lb_evaluator *ev1 = compile(&one, LB_OK, NULL);
    free(one.s);
    double v = 0.0, g[3];
    assert_int_equal(lb_evaluator_eval(ev, 1, X, X + 1, X + 2, &v, NULL, NULL, NULL, 1, &e), LB_OK);
    double v1 = 0.0;
    assert_int_equal(lb_evaluator_eval(ev1, 1, X, X + 1, X + 2, &v1, NULL, NULL, NULL, 1, &e),
                     LB_OK);
    assert_true(v == v1); /* min of copies of one sphere is that sphere */
    assert_int_equal(lb_scene_eval_reference(sc, X, &v, g, &e), LB_ERR_INVALID_ARGUMENT);
    lb_evaluator_free(ev1);
    assert_non_null(strstr(e.message, "use the compiled evaluator"));
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    free(b.s);
}

/* Shared defs under distinct transforms: each copy is an instruction, and
 * past LB_SCENE_MAX_INSTRUCTIONS the scene is refused as bad input with the
 * path of the node where the tape overflowed. */
static void test_instruction_limit(void **st) {
    (void)st;
    sbuf b = {0};
    head(&b);
    put(&b, "\"defs\":{\"d0\":");
    sphere(&b, 0.0, 1.0);
    for (int i = 1; i <= 18; ++i)
        put(&b,
            ",\"d%d\":{\"type\":\"min\",\"args\":[{\"ref\":\"d%d\"},{\"ref\":\"d%d\","
            "\"translate\":[%d,0,0]}]}",
            i, i - 1, i - 1, 1 << i); /* distinct sums: 2^18 copies */
    put(&b, "},\"root\":{\"ref\":\"d18\"}}");
    lb_evaluator *ev = compile(&b, LB_ERR_INVALID_ARGUMENT, "instructions here");
    assert_null(ev);
    free(b.s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sibling_bulges_linear), cmocka_unit_test(test_shared_bulges_linear),
        cmocka_unit_test(test_nested_chain),          cmocka_unit_test(test_shared_doubling),
        cmocka_unit_test(test_instruction_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
