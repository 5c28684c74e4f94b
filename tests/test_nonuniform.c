/* Non-uniform scaling for soft objects: B_Sk (union), B_Ak (intersection),
 * difference, and the binary conic variants, against long-double bisection
 * of the defining equations in h, with the invariants of
 * docs/operators.md sections 7 and 10. */
#include "testlib.h"

#define N_CASES 100000

typedef struct {
    size_t k;
    double x[8], r[8], p[8], m[8];
    int union_like;
} nu_case;

static long double s_of(long double h, double m) {
    return powl(0.5L, 1.0L - m) * powl(h, m);
}

static long double T_ld(long double h, const void *vctx) {
    const nu_case *c = vctx;
    long double s = 0.0L;
    for (size_t i = 0; i < c->k; ++i) {
        const long double z = c->x[i] / s_of(h, c->m[i]);
        const long double t =
            c->union_like ? (c->r[i] - 1.0L + z) / c->r[i] : (1.0L + c->r[i] - z) / c->r[i];
        if (t > 0.0L) s += powl(t, (long double)c->p[i]);
    }
    return c->union_like ? 1.0L - s : s - 1.0L;
}

static long double nb_ld(const nu_case *c) { /* Max / Min of 0.5 (x/0.5)^(1/m) */
    long double v = c->union_like ? -INFINITY : INFINITY;
    for (size_t i = 0; i < c->k; ++i) {
        if (c->x[i] <= 0) continue;
        const long double a = 0.5L * powl(c->x[i] / 0.5L, 1.0L / c->m[i]);
        v = c->union_like ? fmaxl(v, a) : fminl(v, a);
    }
    return v;
}

static double ref_hyper(const nu_case *c) {
    long double mn = INFINITY, mx = -INFINITY;
    for (size_t i = 0; i < c->k; ++i) {
        mn = fminl(mn, c->x[i]);
        mx = fmaxl(mx, c->x[i]);
    }
    if (!c->union_like && mn <= 0) return 0.0;
    if (c->union_like && mx <= 0) return 0.0;
    const long double nb = nb_ld(c);
    if (!c->union_like) return (double)ld_bisect(T_ld, c, nb * 1e-30L, nb);
    long double hi = nb;
    while (T_ld(hi, c) < 0) hi *= 2;
    return (double)ld_bisect(T_ld, c, nb, hi);
}

static void sample(rng_t *g, nu_case *c, size_t k, int union_like, int wide) {
    c->k = k;
    c->union_like = union_like;
    for (size_t i = 0; i < k; ++i) {
        c->r[i] = union_like ? rng_range(g, 1e-3, 1.0) : rng_log(g, 1e-3, wide ? 10.0 : 2.0);
        if (union_like && rng_unit(g) < 0.15) c->r[i] = 1.0;
        c->p[i] = wide ? rng_p(g) : fmin(rng_p(g), 16.0);
        c->m[i] = rng_unit(g) < 0.2
                      ? 1.0
                      : rng_log(g, wide ? LB_SOFT_MIN_SLOPE : 0.2, wide ? LB_SOFT_MAX_SLOPE : 5.0);
        c->x[i] = rng_unit(g) < 0.7 ? rng_range(g, 0.2, 0.9) : rng_log(g, 1e-3, 1.0);
    }
}

typedef struct {
    const nu_case *c;
    lb_setop op;
    int conic;
    double cp;
} eval_ctx;
static double eval_fn(const double *x, const void *vctx) {
    const eval_ctx *e = vctx;
    double v = NAN;
    if (e->conic)
        lb_soft_conic(e->op, x, e->c->r, e->cp, e->c->m, &v, NULL, NULL);
    else
        lb_soft_hyper(e->op, e->c->k, x, e->c->r, e->c->p, e->c->m, &v, NULL, NULL);
    return v;
}

static void test_hyper(void **state) {
    (void)state;
    rng_t g = {31};
    tally_t ref = {"B_Sk / B_Ak vs long-double reference", 0, 0, 0};
    tally_t nb = {"non-blending = Max/Min of 0.5 (2x)^(1/m)", 0, 0, 0};
    tally_t iso = {"0.5 set independent of m", 0, 0, 0};
    tally_t dif = {"difference = B_A(x0, 1 - x1, ...)", 0, 0, 0};
    tally_t gd = {"gradient vs central differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        nu_case c;
        const int ul = n & 1;
        sample(&g, &c, rng_int(&g, 1, 6), ul, 1);
        double v, gr[8];
        assert_int_equal(
            lb_soft_hyper(ul ? LB_UNION : LB_INTERSECTION, c.k, c.x, c.r, c.p, c.m, &v, gr, NULL),
            LB_OK);
        const double vr = ref_hyper(&c);
        tally_check(&ref, fabs(v - vr) <= 1e-12 * fabs(vr) && all_finite(c.k, gr),
                    "case %d (%s): %.17g vs %.17g", n, ul ? "union" : "inter", v, vr);
        /* non-blending: only the extreme term is active at the Min/Max value */
        const double nbv = (double)nb_ld(&c);
        nu_case one = c;
        double T0 = (double)T_ld(nbv, &one);
        if (T0 == 0.0 || (ul ? T0 > -1e-15 : T0 < 1e-15))
            tally_check(&nb, fabs(v - nbv) <= 1e-12 * nbv, "case %d: %.17g vs %.17g", n, v, nbv);
        /* the 0.5 set: sign of (B - 0.5) does not depend on m */
        nu_case c2 = c;
        for (size_t i = 0; i < c.k; ++i)
            c2.m[i] = rng_log(&g, LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE);
        double v2;
        lb_soft_hyper(ul ? LB_UNION : LB_INTERSECTION, c.k, c2.x, c2.r, c2.p, c2.m, &v2, NULL,
                      NULL);
        if (fabs(v - 0.5) > 1e-12 && fabs(v2 - 0.5) > 1e-12)
            tally_check(&iso, (v > 0.5) == (v2 > 0.5), "case %d: %g vs %g", n, v, v2);
        /* difference */
        if (!ul) {
            double xd[8], vd, vi;
            for (size_t i = 0; i < c.k; ++i) xd[i] = i ? 1.0 - c.x[i] : c.x[i];
            lb_soft_hyper(LB_DIFFERENCE, c.k, c.x, c.r, c.p, c.m, &vd, NULL, NULL);
            lb_soft_hyper(LB_INTERSECTION, c.k, xd, c.r, c.p, c.m, &vi, NULL, NULL);
            tally_check(&dif, vd == vi, "case %d", n);
        }
        /* gradient, moderate */
        nu_case cm;
        const lb_setop op = (lb_setop)(n % 3);
        sample(&g, &cm, rng_int(&g, 1, 6), op == LB_UNION, 0);
        assert_int_equal(lb_soft_hyper(op, cm.k, cm.x, cm.r, cm.p, cm.m, &v, gr, NULL), LB_OK);
        double step[8];
        for (size_t i = 0; i < cm.k; ++i) step[i] = 1e-2 * fmin(cm.r[i], 1.0) * cm.x[i];
        const eval_ctx ec = {&cm, op, 0, 0.0};
        tally_grad(&gd, eval_fn, &ec, cm.k, cm.x, gr, step, "case %d op %d", n, (int)op);
    }
    tally_end(&ref, N_CASES);
    tally_end(&nb, N_CASES / 20);
    tally_end(&iso, N_CASES / 2);
    tally_end(&dif, N_CASES / 2);
    fprintf(stderr, "  tightly checked gradients: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

/* conic: H(u(h)) = 0 at the result, in long double, between the chord and the
 * non-blending value; p = 0 reproduces the hyper-ellipsoidal p = 2 operator */
static long double H_ld(long double r1, long double r2, long double p, long double u1,
                        long double u2) {
    return r2 * r2 * u1 * u1 + r1 * r1 * u2 * u2 + r1 * r1 * r2 * r2 - 2 * r2 * r2 * r1 * u1 -
           2 * r1 * r1 * r2 * u2 + 2 * p * u1 * u2;
}

static void test_conic(void **state) {
    (void)state;
    rng_t g = {32};
    tally_t ell = {"soft conic p = 0 = soft hyper p = 2", 0, 0, 0};
    tally_t res = {"soft conic root: H(u(h)) = 0 on the arc", 0, 0, 0};
    tally_t gd = {"soft conic gradient vs differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        nu_case c;
        const int ul = n & 1;
        const lb_setop op = ul ? LB_UNION : LB_INTERSECTION;
        sample(&g, &c, 2, ul, 1);
        const double p2[2] = {2.0, 2.0};
        double vh, vc, gc[2];
        lb_soft_hyper(op, 2, c.x, c.r, p2, c.m, &vh, NULL, NULL);
        assert_int_equal(lb_soft_conic(op, c.x, c.r, 0.0, c.m, &vc, gc, NULL), LB_OK);
        tally_check(&ell, fabs(vh - vc) <= 1e-12 * fabs(vh) && all_finite(2, gc),
                    "case %d: %.17g vs %.17g", n, vh, vc);
        const double cp = rng_range(&g, -3.0, 0.95) * c.r[0] * c.r[1];
        assert_int_equal(lb_soft_conic(op, c.x, c.r, cp, c.m, &vc, gc, NULL), LB_OK);
        long double u[2];
        int inside = 1;
        for (int i = 0; i < 2; ++i) {
            const long double z = c.x[i] / s_of(vc, c.m[i]);
            u[i] = ul ? 1.0L - z : z - 1.0L;
            if (!(u[i] > 1e-9L && u[i] < c.r[i] - 1e-9L)) inside = 0;
        }
        if (inside) { /* blended: on the conic arc, to rounding */
            const long double H = H_ld(c.r[0], c.r[1], cp, u[0], u[1]);
            const long double Hs = c.r[0] * c.r[0] * c.r[1] * c.r[1];
            tally_check(&res, fabsl(H) <= 1e-8L * Hs, "case %d: H = %Lg (scale %Lg)", n, H, Hs);
        }
        nu_case cm;
        const lb_setop op3 = (lb_setop)(n % 3);
        sample(&g, &cm, 2, op3 == LB_UNION, 0);
        const double cpm = rng_range(&g, -3.0, 0.9) * cm.r[0] * cm.r[1];
        double v, gr[2];
        assert_int_equal(lb_soft_conic(op3, cm.x, cm.r, cpm, cm.m, &v, gr, NULL), LB_OK);
        const double step[2] = {1e-3 * fmin(cm.r[0], 1.0) * cm.x[0],
                                1e-3 * fmin(cm.r[1], 1.0) * cm.x[1]};
        const eval_ctx ec = {&cm, op3, 1, cpm};
        tally_grad(&gd, eval_fn, &ec, 2, cm.x, gr, step, "case %d op %d", n, (int)op3);
    }
    tally_end(&ell, N_CASES);
    tally_end(&res, N_CASES / 20);
    fprintf(stderr, "  tightly checked gradients: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hyper),
        cmocka_unit_test(test_conic),
    };
    return cmocka_run_group_tests_name("nonuniform", tests, NULL, NULL);
}
