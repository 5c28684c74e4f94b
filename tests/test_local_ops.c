/* Local blending's operators (lb_clean_union, lb_barthe_blend,
 * lb_local_mix) against the spec's properties, 100,000 random cases each
 * (fixed seeds):
 *  - UC2 / UC3 / UC = C exactly on the union surface max(f1, f2) = C;
 *  - UC3 / UC = f1 exactly where f2 = 0 (local support, alpha = 0);
 *  - no contraction inside: UC(f, C) = f exactly for C <= f <= 2C;
 *  - C1 away from the union surface: one-sided derivatives agree across
 *    w = 0 (the convolution weight's border), the diagonal and the
 *    inside-both border; gradients against central differences elsewhere;
 *  - UR, UC2 against their formulas written here in long double;
 *  - UB against a long-double bisection of its ellipse equation (1e-12),
 *    max outside the wedge, tangent to x = u and y = u at the wedge's lines
 *    (value and gradient), homogeneous of degree 1, >= max, symmetric;
 *  - the interpolation's ends and gradient; finite outputs on extremes;
 *    invalid parameters rejected with their names. */
#include "testlib.h"

static rng_t R = {0x10ca1b1e};

static double f_clean(const double *x, const void *ctx) {
    const double *prm = ctx; /* kind, C, alpha1, alpha2 */
    double v = NAN;
    const double a[2] = {prm[2], prm[3]};
    lb_clean_union((lb_clean_kind)(int)prm[0], x, prm[1], a, &v, NULL, NULL);
    return v;
}

static double clean(lb_clean_kind kind, double f1, double f2, double C, const double *alpha,
                    double g[2]) {
    const double f[2] = {f1, f2};
    double v = NAN;
    lb_error e = {LB_OK, ""};
    if (lb_clean_union(kind, f, C, alpha, &v, g, &e) != LB_OK) fail_msg("%s", e.message);
    return v;
}

/* the weight, independently: (4uv/(u+v)^2)^4 or 0 */
static long double w_ref(long double f1, long double f2, long double a1, long double a2) {
    const long double u = f1 - a1 * f2, v = f2 - a2 * f1;
    if (u <= 1e-300L || v <= 1e-300L) return 0.0L;
    const long double t = 4.0L * u * v / ((u + v) * (u + v));
    return t * t * t * t;
}

static void test_clean_properties(void **st) {
    (void)st;
    tally_t surf = {"clean: = C on the union surface", 0, 0, 0};
    tally_t zero = {"clean: = f1 where f2 = 0", 0, 0, 0};
    tally_t inside = {"clean UC: no contraction, UC(f, C) = f", 0, 0, 0};
    tally_t formula = {"clean: UR, UC2, UC3, UC vs long double", 0, 0, 0};
    tally_t grad = {"clean: gradients vs central differences", 0, 0, 0};
    for (int t = 0; t < 100000; ++t) {
        const double C = rng_unit(&R) < 0.5 ? 0.5 : rng_log(&R, 1e-3, 1e3);
        const lb_clean_kind k = (lb_clean_kind)rng_int(&R, 1, 3);
        double g[2];
        /* the union surface: one argument exactly C, the other at most C */
        const double o = rng_range(&R, 0.0, C);
        tally_check(&surf, clean(k, C, o, C, NULL, g) == C && clean(k, o, C, C, NULL, g) == C,
                    "kind %d C %g other %g", k, C, o);
        if (k != LB_CLEAN_UC2) {
            const double f1 = rng_range(&R, 0.0, 2.0 * C);
            tally_check(&zero, clean(k, f1, 0.0, C, NULL, g) == f1, "kind %d f1 %g", k, f1);
        }
        {
            const double f = rng_range(&R, C, 2.0 * C);
            tally_check(&inside,
                        clean(LB_CLEAN_UC, f, C, C, NULL, g) == f &&
                            clean(LB_CLEAN_UC, C, f, C, NULL, g) == f,
                        "C %g f %g", C, f);
        }
        /* values against the formulas in long double */
        const long double f1 = rng_range(&R, 0.0, 2.0 * C), f2 = rng_range(&R, 0.0, 2.0 * C);
        const double a1 = rng_unit(&R) < 0.5 ? 0.0 : rng_range(&R, 0.0, 0.9);
        const double a2 = rng_unit(&R) < 0.5 ? 0.0 : rng_range(&R, 0.0, 0.9);
        const double alpha[2] = {a1, a2};
        const long double Cl = C, a = f1 - Cl, b = f2 - Cl;
        const long double urv = f1 + f2 + sqrtl(f1 * f1 + f2 * f2);
        const long double uc2v = Cl + (a + b + sqrtl(a * a + b * b)) / (2.0L - sqrtl(2.0L));
        const long double mx = f1 > f2 ? f1 : f2, w = w_ref(f1, f2, a1, a2);
        const long double uc3v = (1.0L - w) * mx + w * uc2v;
        const long double V = mx < Cl                  ? uc2v
                              : (f1 >= Cl && f2 >= Cl) ? Cl + sqrtl(a * a + b * b)
                                                       : mx;
        const long double ucv = (1.0L - w) * mx + w * V;
        const double got[4] = {clean(LB_CLEAN_UR, (double)f1, (double)f2, C, alpha, g),
                               clean(LB_CLEAN_UC2, (double)f1, (double)f2, C, alpha, g),
                               clean(LB_CLEAN_UC3, (double)f1, (double)f2, C, alpha, g),
                               clean(LB_CLEAN_UC, (double)f1, (double)f2, C, alpha, g)};
        const long double want[4] = {urv, uc2v, uc3v, ucv};
        for (int i = 0; i < 4; ++i)
            tally_check(&formula, fabsl(got[i] - want[i]) <= 1e-13L * (fabsl(want[i]) + Cl),
                        "kind %d f (%Lg, %Lg) C %g alpha (%g, %g): %.17g vs %.17Lg", i, f1, f2, C,
                        a1, a2, got[i], want[i]);
        /* gradients, away from the union surface and the diagonal */
        const double x[2] = {(double)f1, (double)f2};
        if (fabs(x[0] - x[1]) > 1e-3 * C && fabs(fmax(x[0], x[1]) - C) > 1e-3 * C &&
            fmin(x[0], x[1]) > 1e-3 * C) {
            const double prm[4] = {(double)k, C, a1, a2};
            clean(k, x[0], x[1], C, alpha, g);
            const double step[2] = {1e-4 * C, 1e-4 * C};
            tally_grad(&grad, f_clean, prm, 2, x, g, step, "kind %d f (%g, %g) C %g", k, x[0], x[1],
                       C);
        }
    }
    tally_end(&surf, 100000);
    tally_end(&zero, 60000);
    tally_end(&inside, 100000);
    tally_end(&formula, 400000);
    tally_end(&grad, 50000);
    assert_true(grad.tight > grad.checked / 2);
}

/* One-sided derivatives across a border: grad at border + e and border - e
 * along direction d agree to 1e-5 (relative to their size). */
static void c1_across(tally_t *t, lb_clean_kind k, const double p[2], const double d[2], double C,
                      const double *alpha) {
    const double e = 1e-9 * C;
    double ga[2], gb[2];
    clean(k, p[0] + e * d[0], p[1] + e * d[1], C, alpha, ga);
    clean(k, p[0] - e * d[0], p[1] - e * d[1], C, alpha, gb);
    const double s = 1.0 + fabs(ga[0]) + fabs(ga[1]);
    tally_check(t, fabs(ga[0] - gb[0]) <= 1e-5 * s && fabs(ga[1] - gb[1]) <= 1e-5 * s,
                "kind %d at (%g, %g) C %g: (%g, %g) vs (%g, %g)", k, p[0], p[1], C, ga[0], ga[1],
                gb[0], gb[1]);
}

static void test_clean_c1(void **st) {
    (void)st;
    tally_t wz = {"clean: C1 across w = 0 (alpha > 0)", 0, 0, 0};
    tally_t diag = {"clean: C1 across the diagonal", 0, 0, 0};
    tally_t ins = {"clean UC: C1 across the inside-both border", 0, 0, 0};
    for (int t = 0; t < 100000; ++t) {
        const double C = 0.5;
        const lb_clean_kind k = rng_unit(&R) < 0.5 ? LB_CLEAN_UC3 : LB_CLEAN_UC;
        /* w = 0 where u = f1 - a1 f2 = 0: f1 = a1 f2, inside one or outside both */
        const double a1 = rng_range(&R, 0.05, 0.9), f2 = rng_range(&R, 0.01, 1.0);
        const double alpha[2] = {a1, 0.0}, p[2] = {a1 * f2, f2}, d[2] = {1.0, 0.0};
        if (fabs(fmax(p[0], p[1]) - C) > 1e-6) c1_across(&wz, k, p, d, C, alpha);
        /* the diagonal, outside both or inside both */
        const double f = rng_unit(&R) < 0.5 ? rng_range(&R, 0.01, 0.49) : rng_range(&R, 0.51, 1.0);
        const double q[2] = {f, f}, dd[2] = {1.0, -1.0};
        c1_across(&diag, k, q, dd, C, NULL);
        /* the inside-both border f2 = C, f1 > C */
        const double f1 = rng_range(&R, 0.51, 1.0), b[2] = {f1, C}, db[2] = {0.0, 1.0};
        const double b2[2] = {C, f1}, db2[2] = {1.0, 0.0};
        c1_across(&ins, LB_CLEAN_UC, b, db, C, NULL);
        c1_across(&ins, LB_CLEAN_UC, b2, db2, C, NULL);
    }
    tally_end(&wz, 90000);
    tally_end(&diag, 100000);
    tally_end(&ins, 200000);
}

/* the ellipse equation h(u) = ((x - p u)/(1 - p))^2 + ((y - q u)/(1 - q))^2 - u^2,
 * decreasing on the arc's bracket */
typedef struct {
    long double x, y, p, q;
} ell;
static long double neg_h(long double u, const void *c) {
    const ell *E = c;
    const long double a = (E->x - E->p * u) / (1.0L - E->p), b = (E->y - E->q * u) / (1.0L - E->q);
    return -(a * a + b * b - u * u);
}

static double f_barthe(const double *x, const void *ctx) {
    const double *pq = ctx;
    double v = NAN;
    lb_barthe_blend(x, pq[0], pq[1], &v, NULL, NULL);
    return v;
}

static double barthe(double x, double y, double p, double q, double g[2]) {
    const double xy[2] = {x, y};
    double v = NAN;
    lb_error e = {LB_OK, ""};
    if (lb_barthe_blend(xy, p, q, &v, g, &e) != LB_OK) fail_msg("%s", e.message);
    return v;
}

static void test_barthe(void **st) {
    (void)st;
    tally_t ref = {"UB vs long-double ellipse root", 0, 0, 0};
    tally_t out = {"UB = max outside the wedge", 0, 0, 0};
    tally_t tan = {"UB tangent to x = u, y = u", 0, 0, 0};
    tally_t hom = {"UB homogeneous, >= max, symmetric", 0, 0, 0};
    tally_t grad = {"UB gradients vs central differences", 0, 0, 0};
    tally_t ift = {"UB gradients vs implicit function theorem", 0, 0, 0};
    for (int t = 0; t < 100000; ++t) {
        const double p = rng_unit(&R) < 0.2 ? 0.0 : rng_range(&R, 0.0, 0.95);
        const double q = rng_unit(&R) < 0.2 ? 0.0 : rng_range(&R, 0.0, 0.95);
        const double scale = rng_log(&R, 1e-3, 1e3);
        /* a point strictly inside the wedge q x < y < x / p */
        const double x = scale * rng_range(&R, 0.01, 1.0);
        const double yhi = p > 0.0 ? fmin(x / p, 1e3 * x) : 1e3 * x;
        const double y = q * x + (yhi - q * x) * rng_range(&R, 1e-6, 1.0 - 1e-6);
        double g[2];
        const double u = barthe(x, y, p, q, g);
        ell E = {x, y, p, q};
        long double lo = x > y ? x : y, hi = INFINITY;
        if (p > 0.0) hi = fminl(hi, (long double)x / p);
        if (q > 0.0) hi = fminl(hi, (long double)y / q);
        if (!isfinite((double)hi)) hi = (long double)x + y;
        const long double want = ld_bisect(neg_h, &E, lo, hi);
        tally_check(&ref, fabsl(u - want) <= 1e-12L * want, "x %g y %g p %g q %g: %.17g vs %.17Lg",
                    x, y, p, q, u, want);
        /* the gradient by the implicit function theorem on h(u; x, y) = 0 at
         * the long-double root: du/dx = -h_x / h_u */
        {
            const long double P2 = (1.0L - p) * (1.0L - p), Q2 = (1.0L - q) * (1.0L - q);
            const long double ax = (x - p * want) / P2, ay = (y - q * want) / Q2;
            const long double hu = -2.0L * p * ax - 2.0L * q * ay - 2.0L * want;
            const long double gx = -2.0L * ax / hu, gy = -2.0L * ay / hu;
            tally_check(&ift,
                        fabsl(g[0] - gx) <= 1e-9L * (fabsl(gx) + fabsl(gy)) &&
                            fabsl(g[1] - gy) <= 1e-9L * (fabsl(gx) + fabsl(gy)),
                        "x %g y %g p %g q %g: (%g, %g) vs (%Lg, %Lg)", x, y, p, q, g[0], g[1], gx,
                        gy);
        }
        /* outside the wedge: max, exactly */
        const double yo = q * x * rng_range(&R, 0.0, 1.0);
        tally_check(&out, barthe(x, yo, p, q, g) == x && g[0] == 1.0 && g[1] == 0.0,
                    "x %g y %g p %g q %g", x, yo, p, q);
        /* at the wedge's line y = q x (from inside) the value tends to x and
         * the gradient to (1, 0): the level set meets x = u tangentially */
        if (q > 0.01 && q < 0.9 && p * q < 0.8) {
            const double yt = q * x * (1.0 + 1e-10);
            const double ut = barthe(x, yt, p, q, g);
            tally_check(&tan,
                        fabs(ut - x) <= 1e-7 * x && fabs(g[0] - 1.0) <= 1e-3 && fabs(g[1]) <= 1e-3,
                        "x %g p %g q %g: u %.17g g (%g, %g)", x, p, q, ut, g[0], g[1]);
        }
        /* homogeneity, >= max, symmetry (x, y, p, q) -> (y, x, q, p) */
        const double s = rng_log(&R, 1e-2, 1e2);
        double g2[2];
        const double us = barthe(s * x, s * y, p, q, g2), sw = barthe(y, x, q, p, g2);
        /* and at the ends of the double range, where x^2 + y^2 would
         * underflow or overflow (x = 4e-321, y = 7e-171 once gave 0 / 0) */
        const double sx = rng_log(&R, 1e-290, 1e90);
        double g3[2];
        const double ux = barthe(sx * x, sx * y, p, q, g3);
        barthe(x, y, p, q, g);
        tally_check(&hom,
                    fabs(us - s * u) <= 1e-13 * s * u && u >= fmax(x, y) &&
                        fabs(sw - u) <= 1e-13 * u && fabs(ux - sx * u) <= 1e-13 * sx * u &&
                        fabs(g3[0] - g[0]) + fabs(g3[1] - g[1]) <= 1e-9 * (fabs(g[0]) + fabs(g[1])),
                    "x %g y %g p %g q %g s %g: %.17g vs %.17g", x, y, p, q, sx, ux, sx * u);
        /* gradient */
        const double pq[2] = {p, q}, xy[2] = {x, y};
        const double step[2] = {1e-4 * fmin(x, y - q * x), 1e-4 * fmin(y, yhi - y)};
        barthe(x, y, p, q, g);
        if (step[0] > 1e-9 * x && step[1] > 1e-9 * x)
            tally_grad(&grad, f_barthe, pq, 2, xy, g, step, "x %g y %g p %g q %g", x, y, p, q);
    }
    tally_end(&ref, 100000);
    tally_end(&ift, 100000);
    tally_end(&out, 100000);
    tally_end(&tan, 30000);
    tally_end(&hom, 100000);
    tally_end(&grad, 50000);
    assert_true(grad.tight > grad.checked / 2);
}

static void test_mix_extremes_and_errors(void **st) {
    (void)st;
    lb_error e = {LB_OK, ""};
    double v, g[3];
    /* the ends are exact, the gradient is the formula's */
    for (int t = 0; t < 100000; ++t) {
        const double uc = rng_range(&R, 0, 1), ub = rng_range(&R, 0, 1), n = rng_range(&R, 1, 8);
        assert_int_equal(lb_local_mix(uc, ub, 0.0, n, &v, g, &e), LB_OK);
        assert_true(v == uc && g[0] == 1.0 && g[1] == 0.0);
        assert_int_equal(lb_local_mix(uc, ub, 1.0, n, &v, g, &e), LB_OK);
        assert_true(v == ub && g[0] == 0.0 && g[1] == 1.0);
        const double w = rng_range(&R, 0.01, 0.99);
        assert_int_equal(lb_local_mix(uc, ub, w, n, &v, g, &e), LB_OK);
        const double beta = pow(w, n);
        assert_true(fabs(v - ((1 - beta) * uc + beta * ub)) <= 1e-15);
        assert_true(fabs(g[2] - n * pow(w, n - 1) * (ub - uc)) <= 1e-13);
    }
    /* extremes: every accepted input gives finite outputs */
    static const double ext[] = {0.0, 1e-320, 1e-300, 1e-100, 0.5, 1.0, 1e100, -1e100, -0.5};
    const size_t ne = sizeof ext / sizeof ext[0];
    long finite = 0;
    for (size_t i = 0; i < ne; ++i)
        for (size_t j = 0; j < ne; ++j)
            for (int k = 0; k <= 3; ++k)
                for (int a = 0; a < 3; ++a) {
                    const double C = a == 0 ? 0.5 : a == 1 ? 1e-100 : 1e100;
                    const double alpha[2] = {a == 2 ? 0.999 : 0.0, a == 2 ? 0.5 : 0.0};
                    const double f[2] = {ext[i], ext[j]};
                    double gg[2];
                    assert_int_equal(lb_clean_union((lb_clean_kind)k, f, C, alpha, &v, gg, &e),
                                     LB_OK);
                    assert_true(isfinite(v) && isfinite(gg[0]) && isfinite(gg[1]));
                    for (int pq = 0; pq < 4; ++pq) {
                        const double P = pq <= 1 ? 0.0 : pq == 2 ? 0.5 : LB_BARTHE_MAX_PQ;
                        const double Q = pq == 0 ? 0.0 : fmin(1.0 - P, LB_BARTHE_MAX_PQ);
                        assert_int_equal(lb_barthe_blend(f, P, Q, &v, gg, &e), LB_OK);
                        if (!(isfinite(v) && isfinite(gg[0]) && isfinite(gg[1])))
                            fail_msg("UB(%g, %g) p %g: %g (%g, %g)", f[0], f[1], P, v, gg[0],
                                     gg[1]);
                        /* p = q = 0: the wedge is the open quadrant and UB
                         * the circle's radius there */
                        if (pq == 0 && f[0] > 0.0 && f[1] > 0.0 &&
                            !(fabs(v - hypot(f[0], f[1])) <= 1e-15 * hypot(f[0], f[1])))
                            fail_msg("UB(%g, %g) p = q = 0: %.17g, not hypot %.17g", f[0], f[1], v,
                                     hypot(f[0], f[1]));
                    }
                    ++finite;
                }
    assert_true(finite == (long)(ne * ne * 12));
    /* invalid calls: the status and the parameter's name */
    const double f[2] = {0.4, 0.6}, bad_alpha[2] = {1.0, 0.0}, nan2[2] = {NAN, 0.5};
    struct {
        lb_status got, want;
        const char *msg;
    } rows[] = {
        {lb_clean_union(LB_CLEAN_UC, f, 0.0, NULL, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT, "C"},
        {lb_clean_union(LB_CLEAN_UC, f, 0.5, bad_alpha, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT,
         "alpha"},
        {lb_clean_union((lb_clean_kind)4, f, 0.5, NULL, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT,
         "kind = 4"},
        {lb_clean_union(LB_CLEAN_UC, nan2, 0.5, NULL, &v, NULL, &e), LB_ERR_NOT_FINITE, "f[0]"},
        {lb_barthe_blend(f, 1.0, 0.5, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT, "p"},
        {lb_barthe_blend(f, 0.5, -0.1, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT, "q"},
        {lb_local_mix(0.4, 0.6, 1.5, 2.0, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT, "v"},
        {lb_local_mix(0.4, 0.6, 0.5, 0.5, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT, "n"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i)
        if (rows[i].got != rows[i].want) fail_msg("row %zu: status %d", i, rows[i].got);
    /* each message names its parameter (checked one at a time) */
    assert_int_equal(lb_barthe_blend(f, 1.0, 0.5, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "lb_barthe_blend: p = 1"));
    assert_int_equal(lb_clean_union(LB_CLEAN_UC, f, 0.5, bad_alpha, &v, NULL, &e),
                     LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "alpha"));
    assert_non_null(strstr(e.message, "0 <= alpha_i < 1"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean_properties),
        cmocka_unit_test(test_clean_c1),
        cmocka_unit_test(test_barthe),
        cmocka_unit_test(test_mix_extremes_and_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
