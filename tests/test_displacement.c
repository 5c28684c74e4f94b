/* BT_k (displacement family): values against a long-double bisection of the
 * defining equation, the invariants of docs/operators.md sections 4
 * and 10, and gradients against central differences. */
#include "testlib.h"
#include "../libblend/src/common/internal.h"

#define N_CASES 100000

typedef struct {
    size_t k;
    double x[64], r[64], p[64], m[64];
} bt_case;

typedef struct {
    const bt_case *c;
} ref_ctx;

static long double ref_T(long double h, const void *vctx) {
    const bt_case *c = ((const ref_ctx *)vctx)->c;
    long double s = -1.0L;
    for (size_t i = 0; i < c->k; ++i) {
        const long double t =
            ((long double)c->r[i] - (long double)c->x[i] + (long double)c->m[i] * h) / c->r[i];
        if (t > 0.0L) s += powl(t, (long double)c->p[i]);
    }
    return s;
}

static double ref_union(const bt_case *c);
/* d h / d x_i by the implicit function theorem, in long double at the
 * long-double root */
static void ref_grad(const bt_case *c, long double h, long double *g) {
    long double D = 0.0L;
    for (size_t i = 0; i < c->k; ++i) {
        const long double t =
            ((long double)c->r[i] - (long double)c->x[i] + (long double)c->m[i] * h) / c->r[i];
        g[i] = t > 0.0L ? c->p[i] / (long double)c->r[i] * powl(t, c->p[i] - 1.0L) : 0.0L;
        D += c->m[i] * g[i];
    }
    for (size_t i = 0; i < c->k; ++i) g[i] /= D;
}

static double ref_union(const bt_case *c) {
    long double lo = INFINITY, hi = INFINITY;
    for (size_t i = 0; i < c->k; ++i) {
        const long double a = ((long double)c->x[i] - c->r[i]) / c->m[i];
        const long double b = (long double)c->x[i] / c->m[i];
        if (a < lo) lo = a;
        if (b < hi) hi = b;
    }
    const ref_ctx ctx = {c};
    return (double)ld_bisect(ref_T, &ctx, lo, hi);
}

/* scale of the problem: |h| plus the widest range of a term active at h */
static double scale_at(const bt_case *c, double h) {
    double s = fabs(h);
    double w = 0.0;
    for (size_t i = 0; i < c->k; ++i)
        if (c->x[i] - c->m[i] * h < c->r[i] && c->r[i] / c->m[i] > w) w = c->r[i] / c->m[i];
    return s + w;
}

/* wide: the ranges (r 1e-3..1e3, p 1.05..64, m 1e-3..1e3, |x| <= 1e6);
 * otherwise moderate ones (r 1e-2..1e2, p 1.05..16, m 0.1..10, |x| <= 1e3)
 * on which central differences are trustworthy. */
static void sample_scaled(rng_t *g, bt_case *c, int wide) {
    c->k = rng_unit(g) < 0.95 ? rng_int(g, 1, 8) : rng_int(g, 9, 64);
    double mmax = 0.0;
    const double rr = wide ? 1e3 : 1e2, mr = wide ? 1e3 : 10.0;
    for (size_t i = 0; i < c->k; ++i) {
        c->r[i] = rng_log(g, 1.0 / rr, rr);
        c->p[i] = wide ? rng_p(g) : fmin(rng_p(g), 16.0);
        c->m[i] = rng_unit(g) < 0.2 ? 1.0 : rng_log(g, 1.0 / mr, mr);
        if (c->m[i] > mmax) mmax = c->m[i];
    }
    if (rng_unit(g) < 0.15) /* same p everywhere: exercises the fast paths */
        for (size_t i = 1; i < c->k; ++i) c->p[i] = c->p[0];
    const double mode = rng_unit(g);
    if (mode < 0.6) { /* around one h0: most arguments inside their ranges */
        const double mag = pow(10.0, rng_range(g, -3.0, wide ? 6.0 : 3.0));
        const double h0 = (rng_unit(g) < 0.5 ? -mag : mag) / mmax;
        for (size_t i = 0; i < c->k; ++i)
            c->x[i] = c->m[i] * h0 + rng_range(g, -0.2, 1.5) * c->r[i];
    } else if (mode < 0.8) { /* independent, wide */
        for (size_t i = 0; i < c->k; ++i) {
            const double mag = pow(10.0, rng_range(g, -3.0, wide ? 6.0 : 3.0));
            c->x[i] = rng_unit(g) < 0.5 ? -mag : mag;
        }
    } else { /* ties and near-ties */
        const double v = rng_range(g, -10.0, 10.0);
        for (size_t i = 0; i < c->k; ++i) {
            c->m[i] = 1.0;
            c->x[i] = v + (rng_unit(g) < 0.5 ? 0.0 : 1e-9 * rng_range(g, -1, 1));
        }
    }
}

static void sample(rng_t *g, bt_case *c) {
    sample_scaled(g, c, 1);
}

typedef struct {
    const bt_case *c;
    lb_setop op;
} eval_ctx;

static double eval_fn(const double *x, const void *vctx) {
    const eval_ctx *e = vctx;
    double v = NAN;
    lb_displacement(e->op, e->c->k, x, e->c->r, e->c->p, e->c->m, &v, NULL, NULL);
    return v;
}

static void test_values_against_reference(void **state) {
    (void)state;
    rng_t g = {1};
    tally_t val = {"value vs long-double reference", 0, 0, 0};
    tally_t fin = {"finite value and gradient", 0, 0, 0};
    tally_t sum = {"sum_i m_i dh/dx_i = 1, dh/dx_i >= 0", 0, 0, 0};
    tally_t nb = {"non-blending value = min x_i/m_i", 0, 0, 0};
    tally_t cf = {"p = 2 closed form = Newton solve", 0, 0, 0};
    tally_t gl = {"gradient vs long-double IFT reference", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        bt_case c;
        sample(&g, &c);
        double h, gr[64];
        lb_error e;
        assert_int_equal(lb_displacement(LB_UNION, c.k, c.x, c.r, c.p, c.m, &h, gr, &e), LB_OK);
        tally_check(&fin, isfinite(h) && all_finite(c.k, gr), "case %d: h = %g", n, h);
        const double ref = ref_union(&c);
        const double sc = scale_at(&c, ref);
        tally_check(&val, fabs(h - ref) <= 1e-12 * sc,
                    "case %d k=%zu: h = %.17g ref = %.17g (scale %g)", n, c.k, h, ref, sc);
        /* gradient at the reference root; where the root sits within rounding
         * of an activation boundary the two sides' gradients differ, so the
         * comparison uses the tolerance the value itself has */
        long double gref[64];
        ref_grad(&c, ref, gref);
        /* conditioning: an error dh in the root moves w_j = t_j^(p_j-1) by a
         * relative (p_j - 1) m_j dh / (r_j t_j); allow that for dh = 2e-12 sc */
        double emax = 0.0, ce[64];
        for (size_t i = 0; i < c.k; ++i) {
            const double t = (c.r[i] - (c.x[i] - c.m[i] * ref)) / c.r[i];
            ce[i] = t > 0.0 ? (c.p[i] - 1.0) * c.m[i] * 2e-12 * sc / (c.r[i] * t) : 0.0;
            emax = fmax(emax, ce[i]);
        }
        int gok = 1;
        for (size_t i = 0; i < c.k; ++i) {
            const long double tol =
                (1e-9L + 2.0L * (ce[i] + emax)) * fabsl(gref[i]) + 1e-12L / c.m[i];
            if (!(fabsl(gr[i] - gref[i]) <= tol || (ce[i] + emax) > 0.1)) gok = 0;
        }
        tally_check(&gl, gok, "case %d", n);
        double s = 0.0;
        int nonneg = 1;
        for (size_t i = 0; i < c.k; ++i) {
            s += c.m[i] * gr[i];
            if (gr[i] < 0.0) nonneg = 0;
        }
        tally_check(&sum, nonneg && fabs(s - 1.0) <= 1e-12, "case %d: sum = %.17g", n, s);
        /* non-blending region: only the argmin term is active at min x/m */
        size_t j = 0;
        for (size_t i = 1; i < c.k; ++i)
            if (c.x[i] / c.m[i] < c.x[j] / c.m[j]) j = i;
        const double hm = c.x[j] / c.m[j];
        int alone = 1;
        for (size_t i = 0; i < c.k; ++i)
            if (i != j && c.x[i] - c.m[i] * hm < c.r[i]) alone = 0;
        if (alone)
            tally_check(&nb, fabs(h - hm) <= 4.0 * DBL_EPSILON * (fabs(hm) + c.r[j] / c.m[j]),
                        "case %d: h = %.17g, min = %.17g", n, h, hm);
        /* p = 2 closed form against the generic Newton path */
        bt_case c2 = c;
        for (size_t i = 0; i < c.k; ++i) c2.p[i] = 2.0;
        const double a = lb__bt_union(c.k, c2.x, c2.r, c2.p, c2.m, LB__P_TWO, NULL, NULL, NULL);
        const double b =
            lb__bt_union_newton(c.k, c2.x, c2.r, c2.p, c2.m, LB__P_INTEGER, NULL, NULL, NULL);
        tally_check(&cf, fabs(a - b) <= 1e-12 * scale_at(&c2, b),
                    "case %d: closed %.17g newton %.17g", n, a, b);
    }
    tally_end(&val, N_CASES);
    tally_end(&fin, N_CASES);
    tally_end(&sum, N_CASES);
    tally_end(&nb, N_CASES / 20);
    tally_end(&cf, N_CASES);
    tally_end(&gl, N_CASES);
}

static void test_gradients(void **state) {
    (void)state;
    rng_t g = {2};
    tally_t t = {"gradient vs central differences (3 ops)", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        bt_case c;
        sample_scaled(&g, &c, 0);
        if (c.k > 8) c.k = 8;
        const lb_setop op = (lb_setop)(n % 3);
        double h, gr[64], step[64];
        assert_int_equal(lb_displacement(op, c.k, c.x, c.r, c.p, c.m, &h, gr, NULL), LB_OK);
        /* step: half the distance to the nearest activation boundary
         * a_j = r_j - x'_j + m_j h' = 0 of the union being evaluated, so the
         * field is smooth over the stencil */
        double xu[64], hu, gu[64];
        for (size_t i = 0; i < c.k; ++i)
            xu[i] = (op == LB_INTERSECTION || (op == LB_DIFFERENCE && i == 0)) ? -c.x[i] : c.x[i];
        lb_displacement(LB_UNION, c.k, xu, c.r, c.p, c.m, &hu, gu, NULL);
        for (size_t i = 0; i < c.k; ++i) {
            double safe = c.r[i];
            for (size_t j = 0; j < c.k; ++j) {
                const double aj = fabs(c.r[j] - xu[j] + c.m[j] * hu);
                const double rate = fabs((i == j ? -1.0 : 0.0) + c.m[j] * gu[i]);
                if (rate > 0.0) safe = fmin(safe, aj / rate);
            }
            step[i] = 0.5 * safe;
        }
        const eval_ctx ec = {&c, op};
        tally_grad(&t, eval_fn, &ec, c.k, c.x, gr, step, "case %d op %d k=%zu", n, (int)op, c.k);
    }
    fprintf(stderr, "  tightly checked: %ld of %ld\n", t.tight, t.checked);
    assert_true(t.tight >= N_CASES / 2);
    tally_end(&t, N_CASES);
}

/* The zero set does not depend on m: BT(x; m) < 0 exactly where HT(x) > 0,
 * for every m. Checked near the surface (x built to satisfy HT(x) ~ 0, then
 * nudged) against HT in long double, with a fresh random m each case. */
static long double ref_HT(const bt_case *c) {
    long double s = -1.0L;
    for (size_t i = 0; i < c->k; ++i) {
        const long double t = ((long double)c->r[i] - c->x[i]) / c->r[i];
        if (t > 0.0L) s += powl(t, (long double)c->p[i]);
    }
    return s;
}

static void test_zero_set_independent_of_m(void **state) {
    (void)state;
    rng_t g = {3};
    tally_t sg = {"sign(BT(x; m)) = -sign(HT(x)) for all m", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        bt_case c;
        sample(&g, &c);
        double S = 0.0;
        for (size_t i = 0; i + 1 < c.k; ++i) {
            c.x[i] = c.r[i] * rng_range(&g, 0.3, 1.5);
            const double t = 1.0 - c.x[i] / c.r[i];
            if (t > 0.0) S += pow(t, c.p[i]);
        }
        const size_t l = c.k - 1;
        c.x[l] = S < 1.0 ? c.r[l] * (1.0 - pow(1.0 - S, 1.0 / c.p[l])) : 0.0;
        const double nudge = pow(10.0, rng_range(&g, -12.0, -1.0)) * (rng_unit(&g) < 0.5 ? -1 : 1);
        for (size_t i = 0; i < c.k; ++i) c.x[i] += nudge * c.r[i];
        const long double HT = ref_HT(&c);
        if (fabsl(HT) < 1e-13L * (long double)c.k) continue; /* within rounding of the surface */
        for (int t = 0; t < 1; ++t) {
            for (size_t i = 0; i < c.k; ++i) c.m[i] = rng_log(&g, 1e-3, 1e3);
            double h;
            assert_int_equal(lb_displacement(LB_UNION, c.k, c.x, c.r, c.p, c.m, &h, NULL, NULL),
                             LB_OK);
            /* the math (long-double reference) and the library, each where the
             * value is resolvable from zero */
            const double ref = ref_union(&c), sc = scale_at(&c, ref);
            if (fabs(ref) > 1e-15 * sc)
                tally_check(&sg, HT > 0 ? ref < 0 : ref > 0, "case %d: HT = %Lg, ref = %g", n, HT,
                            ref);
            if (fabs(ref) > 1e-12 * sc)
                tally_check(&sg, HT > 0 ? h < 0 : h > 0, "case %d: HT = %Lg, BT = %g, ref %g", n,
                            HT, h, ref);
        }
    }
    tally_end(&sg, N_CASES);
}

static void test_duality_and_continuity(void **state) {
    (void)state;
    rng_t g = {4};
    tally_t du = {"intersection(x) = -union(-x), difference", 0, 0, 0};
    tally_t co = {"continuity across an activation boundary", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        bt_case c;
        sample(&g, &c);
        double xn[64], u, v, w, gu[64], gv[64], gw[64];
        for (size_t i = 0; i < c.k; ++i) xn[i] = -c.x[i];
        lb_displacement(LB_INTERSECTION, c.k, c.x, c.r, c.p, c.m, &v, gv, NULL);
        lb_displacement(LB_UNION, c.k, xn, c.r, c.p, c.m, &u, gu, NULL);
        int ok = v == -u;
        for (size_t i = 0; i < c.k; ++i) ok &= gv[i] == gu[i];
        xn[0] = c.x[0] * -1.0;
        for (size_t i = 1; i < c.k; ++i) xn[i] = c.x[i];
        lb_displacement(LB_DIFFERENCE, c.k, c.x, c.r, c.p, c.m, &w, gw, NULL);
        lb_displacement(LB_UNION, c.k, xn, c.r, c.p, c.m, &u, gu, NULL);
        ok &= w == -u && gw[0] == gu[0];
        for (size_t i = 1; i < c.k; ++i) ok &= gw[i] == -gu[i];
        tally_check(&du, ok, "case %d", n);
        /* continuity: move argument j across the boundary x_j = m_j h + r_j */
        if (c.k < 2) continue;
        double h;
        lb_displacement(LB_UNION, c.k, c.x, c.r, c.p, c.m, &h, NULL, NULL);
        const size_t j = rng_int(&g, 0, c.k - 1);
        c.x[j] = c.m[j] * h + c.r[j];
        const double d = 1e-7 * c.r[j];
        double a, b;
        c.x[j] += d;
        lb_displacement(LB_UNION, c.k, c.x, c.r, c.p, c.m, &a, NULL, NULL);
        c.x[j] -= 2.0 * d;
        lb_displacement(LB_UNION, c.k, c.x, c.r, c.p, c.m, &b, NULL, NULL);
        /* Lipschitz: |dh/dx_j| <= 1/m_j */
        tally_check(&co, fabs(a - b) <= 2.0 * d / c.m[j] * (1.0 + 1e-6) + 1e-12 * scale_at(&c, h),
                    "case %d: jump %g over step %g", n, a - b, 2 * d);
    }
    tally_end(&du, N_CASES);
    tally_end(&co, N_CASES / 2);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values_against_reference),
        cmocka_unit_test(test_gradients),
        cmocka_unit_test(test_zero_set_independent_of_m),
        cmocka_unit_test(test_duality_and_continuity),
    };
    return cmocka_run_group_tests_name("displacement", tests, NULL, NULL);
}
