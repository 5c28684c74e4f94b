/* Binary conic BT_2: closed form against the root-solved conic and a
 * long-double reference, p = 0 against the hyper-ellipsoidal operator with
 * p_i = 2, the non-blending region, m-independence of the zero set, duality
 * and gradients (docs/operators.md sections 4 and 10). */
#include "testlib.h"
#include "../libblend/src/common/internal.h"

#define N_CASES 100000

typedef struct {
    double x[2], r[2], m[2], p;
} cc_case;

static void sample(rng_t *g, cc_case *c, int wide) {
    const double rr = wide ? 1e3 : 1e2, mr = wide ? 1e3 : 10.0;
    for (int i = 0; i < 2; ++i) {
        c->r[i] = rng_log(g, 1.0 / rr, rr);
        c->m[i] = rng_unit(g) < 0.2 ? 1.0 : rng_log(g, 1.0 / mr, mr);
    }
    const double u = rng_unit(g);
    const double rp = c->r[0] * c->r[1];
    if (u < 0.2)
        c->p = 0.0;
    else if (u < 0.3) /* nearly degenerate: within 1e-2 .. 1e-6 of r1 r2 */
        c->p = (1.0 - pow(10.0, -rng_range(g, 2.0, 6.0))) * rp;
    else if (u < 0.6)
        c->p = rng_range(g, -3.0, 0.95) * rp;
    else
        c->p = -rng_log(g, 3.0, 1e3) * rp;
    const double mag = pow(10.0, rng_range(g, -3.0, wide ? 6.0 : 3.0));
    const double h0 = (rng_unit(g) < 0.5 ? -mag : mag) / fmax(c->m[0], c->m[1]);
    for (int i = 0; i < 2; ++i)
        c->x[i] = rng_unit(g) < 0.8 ? c->m[i] * h0 + rng_range(g, -0.2, 1.5) * c->r[i]
                                    : pow(10.0, rng_range(g, -3.0, wide ? 6.0 : 3.0)) *
                                          (rng_unit(g) < 0.5 ? -1 : 1);
}

static long double ld_H(const cc_case *c, long double u1, long double u2) {
    const long double r1 = c->r[0], r2 = c->r[1], p = c->p;
    return r2 * r2 * u1 * u1 + r1 * r1 * u2 * u2 + r1 * r1 * r2 * r2 - 2 * r2 * r2 * r1 * u1 -
           2 * r1 * r1 * r2 * u2 + 2 * p * u1 * u2;
}
typedef struct {
    const cc_case *c;
    long double v1, v2;
} ld_ctx;
static long double ld_T(long double s, const void *vctx) {
    const ld_ctx *k = vctx;
    return ld_H(k->c, k->v1 - k->c->m[0] * s, k->v2 - k->c->m[1] * s);
}
/* independent reference: region test and bisection in long double, written
 * from the spec's region-II inequalities */
static double ref_conic(const cc_case *c) {
    const long double x1 = c->x[0], x2 = c->x[1], r1 = c->r[0], r2 = c->r[1], m1 = c->m[0],
                      m2 = c->m[1];
    const long double h1 = fminl(x1 / m1, x2 / m2);
    const int region2 = m2 * x1 - m1 * (x2 - r2) > 0 && m2 * (x1 - r1) - m1 * x2 < 0;
    if (!region2) return (double)h1;
    const long double h2 = (r1 * x2 + r2 * x1 - r1 * r2) / (r1 * m2 + r2 * m1);
    const ld_ctx k = {c, x1 - m1 * h1, x2 - m2 * h1};
    return (double)(h1 + ld_bisect(ld_T, &k, h2 - h1, 0.0L));
}

static double scale_of(const cc_case *c, double h) {
    return fabs(h) + fmax(c->r[0] / c->m[0], c->r[1] / c->m[1]);
}

typedef struct {
    const cc_case *c;
    lb_setop op;
} eval_ctx;
static double eval_fn(const double *x, const void *vctx) {
    const eval_ctx *e = vctx;
    double v = NAN;
    lb_conic(e->op, x, e->c->r, e->c->p, e->c->m, &v, NULL, NULL);
    return v;
}

static void test_values(void **state) {
    (void)state;
    rng_t g = {11};
    tally_t ref = {"conic vs long-double reference", 0, 0, 0};
    tally_t sol = {"closed form = root-solved conic", 0, 0, 0};
    tally_t ell = {"p = 0 = hyper-ellipsoidal p_i = 2", 0, 0, 0};
    tally_t fin = {"finite value and gradient", 0, 0, 0};
    tally_t sum = {"m1 dh/dx1 + m2 dh/dx2 = 1", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        cc_case c;
        sample(&g, &c, 1);
        double h, gr[2];
        assert_int_equal(lb_conic(LB_UNION, c.x, c.r, c.p, c.m, &h, gr, NULL), LB_OK);
        tally_check(&fin, isfinite(h) && all_finite(2, gr), "case %d", n);
        const double hr = ref_conic(&c), sc = scale_of(&c, hr);
        tally_check(&ref, fabs(h - hr) <= 1e-12 * sc, "case %d: %.17g vs %.17g (p %g)", n, h, hr,
                    c.p);
        const double hs = lb__conic_union_solved(c.x, c.r, c.p, c.m, NULL);
        tally_check(&sol, fabs(h - hs) <= 1e-12 * sc, "case %d: %.17g vs %.17g", n, h, hs);
        tally_check(&sum, fabs(c.m[0] * gr[0] + c.m[1] * gr[1] - 1.0) <= 1e-9, "case %d: %g %g", n,
                    gr[0], gr[1]);
        const double p2[2] = {2.0, 2.0};
        double he, h0;
        lb_displacement(LB_UNION, 2, c.x, c.r, p2, c.m, &he, NULL, NULL);
        lb_conic(LB_UNION, c.x, c.r, 0.0, c.m, &h0, NULL, NULL);
        tally_check(&ell, fabs(he - h0) <= 1e-12 * scale_of(&c, he), "case %d: %.17g vs %.17g", n,
                    he, h0);
    }
    tally_end(&ref, N_CASES);
    tally_end(&sol, N_CASES);
    tally_end(&ell, N_CASES);
    tally_end(&fin, N_CASES);
    tally_end(&sum, N_CASES);
}

static void test_invariants(void **state) {
    (void)state;
    rng_t g = {12};
    tally_t nb = {"outside region II = min(x1/m1, x2/m2)", 0, 0, 0};
    tally_t sg = {"sign of BT_2 independent of m", 0, 0, 0};
    tally_t du = {"intersection/difference duality", 0, 0, 0};
    tally_t gd = {"gradient vs central differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        cc_case c;
        sample(&g, &c, 1);
        double h;
        lb_conic(LB_UNION, c.x, c.r, c.p, c.m, &h, NULL, NULL);
        const int region2 = c.m[1] * c.x[0] - c.m[0] * (c.x[1] - c.r[1]) > 0 &&
                            c.m[1] * (c.x[0] - c.r[0]) - c.m[0] * c.x[1] < 0;
        if (!region2) tally_check(&nb, h == fmin(c.x[0] / c.m[0], c.x[1] / c.m[1]), "case %d", n);
        cc_case c2 = c;
        c2.m[0] = rng_log(&g, 1e-3, 1e3);
        c2.m[1] = rng_log(&g, 1e-3, 1e3);
        double h2;
        lb_conic(LB_UNION, c2.x, c2.r, c2.p, c2.m, &h2, NULL, NULL);
        if (fabs(h) > 1e-12 * scale_of(&c, h) && fabs(h2) > 1e-12 * scale_of(&c2, h2))
            tally_check(&sg, (h > 0) == (h2 > 0), "case %d: %g vs %g", n, h, h2);
        /* duality through the public API */
        double xn[2] = {-c.x[0], -c.x[1]}, u, v, gu[2], gv[2];
        lb_conic(LB_INTERSECTION, c.x, c.r, c.p, c.m, &v, gv, NULL);
        lb_conic(LB_UNION, xn, c.r, c.p, c.m, &u, gu, NULL);
        int ok = v == -u && gv[0] == gu[0] && gv[1] == gu[1];
        xn[1] = c.x[1];
        lb_conic(LB_DIFFERENCE, c.x, c.r, c.p, c.m, &v, gv, NULL);
        lb_conic(LB_UNION, xn, c.r, c.p, c.m, &u, gu, NULL);
        ok &= v == -u && gv[0] == gu[0] && gv[1] == -gu[1];
        tally_check(&du, ok, "case %d", n);
        /* gradient, moderate scales */
        cc_case cm;
        sample(&g, &cm, 0);
        const lb_setop op = (lb_setop)(n % 3);
        double val, gr[2];
        lb_conic(op, cm.x, cm.r, cm.p, cm.m, &val, gr, NULL);
        const double step[2] = {1e-3 * cm.r[0], 1e-3 * cm.r[1]};
        const eval_ctx ec = {&cm, op};
        tally_grad(&gd, eval_fn, &ec, 2, cm.x, gr, step, "case %d op %d", n, (int)op);
    }
    tally_end(&nb, N_CASES / 10);
    tally_end(&sg, N_CASES / 2);
    tally_end(&du, N_CASES);
    fprintf(stderr, "  tightly checked gradients: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values),
        cmocka_unit_test(test_invariants),
    };
    return cmocka_run_group_tests_name("conic", tests, NULL, NULL);
}
