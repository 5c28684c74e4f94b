/* Finite in, finite out: every family on extreme but valid inputs (huge and
 * tiny arguments up to LB_MAX_ABS_ARG, ranges, slopes, exponents at their
 * limits, ties, zeros, subnormals). A caller from Python or Blender must never get NaN or Inf
 * back for finite input. */
#include "testlib.h"

#define N_CASES 200000

static double wild(rng_t *g) {
    static const double pool[] = {
        0.0, -0.0, 1e-310, -1e-310, 1e-300, -1e-300, LB_MAX_ABS_ARG, -LB_MAX_ABS_ARG, 1e-3, -1e-3,
        1.0, -1.0, 0.5,    2.0,     1e6,    -1e6};
    const double u = rng_unit(g);
    if (u < 0.5) return pool[rng_int(g, 0, sizeof pool / sizeof pool[0] - 1)];
    const double e = rng_range(g, -300.0, 99.9); /* the supported range: |x| <= 1e100 */
    return (rng_unit(g) < 0.5 ? -1.0 : 1.0) * pow(10.0, e);
}
static double pos(rng_t *g, double lo_exp, double hi_exp) {
    return pow(10.0, rng_range(g, lo_exp, hi_exp));
}

static void test_finite_everywhere(void **state) {
    (void)state;
    rng_t g = {61};
    tally_t t = {"finite value and gradient on extreme input", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        const size_t k = rng_int(&g, 1, 6);
        double x[8], y[8], r[8], r1[8], p[8], m[8], ms[8], c[8], v = NAN, gr[8], gc[8];
        for (size_t i = 0; i < k; ++i) {
            x[i] = wild(&g);
            y[i] = rng_unit(&g) < 0.5 ? rng_unit(&g) : fmin(fabs(wild(&g)), 1.0); /* soft: [0, 1] */
            r[i] = pos(&g, -3, 3);
            r1[i] = fmin(r[i], 1.0);
            p[i] = rng_unit(&g) < 0.5 ? (double)rng_int(&g, 2, 64) : rng_range(&g, 1.0001, 64.0);
            m[i] = pos(&g, -3, 3);
            ms[i] = rng_log(&g, LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE); /* soft families */
            c[i] = wild(&g);
        }
        if (rng_unit(&g) < 0.1)
            for (size_t i = 1; i < k; ++i) x[i] = x[0]; /* ties */
        const lb_setop op = (lb_setop)rng_int(&g, 0, 2);
        lb_status st = LB_OK;
        lb_error err = {LB_OK, ""};
        const char *which = "";
        switch (n % 8) {
        case 0:
            which = "displacement";
            st = lb_displacement(op, k, x, r, p, m, &v, gr, &err);
            break;
        case 1: {
            which = "conic";
            const double cp = rng_range(&g, -5.0, 0.99) * r[0] * r[1 % k];
            const double r2[2] = {r[0], r[1 % k]}, m2[2] = {m[0], m[1 % k]};
            st = lb_conic(op, x, r2, cp, m2, &v, gr, &err);
            break;
        }
        case 2:
            which = "scale";
            st = lb_scale(op, k, x, r1, p, &v, gr, &err);
            break;
        case 3:
            which = "bounded";
            st = lb_bounded(op, k, x, c, p, &v, gr, gc, &err);
            break;
        case 4:
            which = "soft_hyper";
            st = lb_soft_hyper(op, k, y, r1, p, ms, &v, gr, &err);
            break;
        case 5: {
            which = "soft_conic";
            const double r2[2] = {r1[0], r1[1 % k]}, m2[2] = {ms[0], ms[1 % k]},
                         y2[2] = {y[0], y[1 % k]};
            st =
                lb_soft_conic(op, y2, r2, rng_range(&g, -3, 0.9) * r2[0] * r2[1], m2, &v, gr, &err);
            break;
        }
        case 6: {
            which = "bulge";
            /* gradients within the bulge operator's accepted |component| <= 1e30 */
            double g1[3], g2[3];
            for (int a = 0; a < 3; ++a) {
                g1[a] = fmax(fmin(wild(&g), 1e30), -1e30);
                g2[a] = fmax(fmin(wild(&g), 1e30), -1e30);
            }
            lb_bulge_params bp = {
                {r1[0] * 0.4, r1[1 % k] * 0.4}, {p[0], p[1 % k]}, 0.0, {m[0], m[1 % k]}, 1e-3,
                LB_BULGE_RANGE | LB_BULGE_SLOPE};
            const lb_bulge_family fam = (lb_bulge_family)rng_int(&g, 0, 1);
            double d1[3], d2[3];
            st = lb_bulge(fam, op, &bp, x, g1, g2, &v, gr, d1, d2, &err);
            if (st == LB_OK && !(all_finite(3, d1) && all_finite(3, d2))) v = NAN;
            break;
        }
        case 7: {
            which = "scale_ba/bs";
            st = n & 8 ? lb_scale_bs(k, x, r1, p, &v, gr, NULL)
                       : lb_scale_ba(k, x, r, p, &v, gr, &err);
            break;
        }
        }
        const size_t ng = (n % 8 == 1 || n % 8 == 5 || n % 8 == 6) ? 2 : k;
        tally_check(&t, st == LB_OK && isfinite(v) && all_finite(ng, gr),
                    "case %d (%s op %d k %zu): status %d value %g %s", n, which, (int)op, k,
                    (int)st, v, st ? err.message : "");
    }
    tally_end(&t, N_CASES);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_finite_everywhere)};
    return cmocka_run_group_tests_name("extremes", tests, NULL, NULL);
}
