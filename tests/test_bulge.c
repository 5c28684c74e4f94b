/* Bulge elimination: values against the base operators evaluated with the
 * spec's R_i(theta) and M_i(X) computed here, and derivatives with respect
 * to x, g1 and g2 against central differences. */
#include "testlib.h"

#define N_CASES 100000

typedef struct {
    lb_bulge_family fam;
    lb_setop op;
    lb_bulge_params bp;
} bg_case;

static double eval_fn(const double *a, const void *vctx) {
    const bg_case *c = vctx;
    double v = NAN;
    lb_bulge(c->fam, c->op, &c->bp, a, a + 2, a + 5, &v, NULL, NULL, NULL, NULL);
    return v;
}

/* the base operator with ranges R and slopes M */
static double base(const bg_case *c, const double x[2], const double R[2], const double M[2]) {
    double v = NAN;
    switch (c->fam) {
    case LB_BULGE_DISPLACEMENT:
        lb_displacement(c->op, 2, x, R, c->bp.p, M, &v, NULL, NULL);
        break;
    case LB_BULGE_CONIC:
        lb_conic(c->op, x, R, c->bp.conic_p, M, &v, NULL, NULL);
        break;
    case LB_BULGE_SCALE:
        lb_scale(c->op, 2, x, R, c->bp.p, &v, NULL, NULL);
        break;
    }
    return v;
}

static void test_bulge(void **state) {
    (void)state;
    rng_t g = {41};
    tally_t val = {"value = base operator with R(theta), M(X)", 0, 0, 0};
    tally_t fin = {"finite value and derivatives", 0, 0, 0};
    tally_t gd = {"derivatives (x, g1, g2) vs differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        bg_case c;
        c.fam = (lb_bulge_family)(n % 3);
        c.op = (lb_setop)((n / 3) % 3);
        c.bp.flags = (unsigned)rng_int(&g, 0, c.fam == LB_BULGE_SCALE ? 1 : 3);
        c.bp.omega = rng_range(&g, 1e-3, 0.1);
        const double rmax =
            c.fam == LB_BULGE_SCALE && c.op != LB_UNION ? 1.0 / (2.0 + c.bp.omega) : 2.0;
        for (int i = 0; i < 2; ++i) {
            c.bp.r[i] = rng_range(&g, 0.05, rmax);
            c.bp.p[i] = fmin(rng_p(&g), 8.0);
            c.bp.m[i] = rng_log(&g, 0.3, 3.0);
        }
        c.bp.conic_p = rng_range(&g, -2.0, 0.9) * c.bp.r[0] * c.bp.r[1] *
                       ((c.bp.flags & LB_BULGE_RANGE) ? c.bp.omega * c.bp.omega : 1.0);
        double a[8];
        a[0] = rng_range(&g, -0.5, 1.0);
        a[1] = rng_range(&g, -0.5, 1.0);
        for (int i = 2; i < 8; ++i) a[i] = rng_range(&g, -1.0, 1.0);
        if (rng_unit(&g) < 0.1) /* parallel gradients: cos theta = +-1 */
            for (int i = 0; i < 3; ++i) a[5 + i] = a[2 + i] * (rng_unit(&g) < 0.5 ? 2.0 : -0.5);
        double v, dx[2], dg1[3], dg2[3];
        assert_int_equal(lb_bulge(c.fam, c.op, &c.bp, a, a + 2, a + 5, &v, dx, dg1, dg2, NULL),
                         LB_OK);
        tally_check(&fin,
                    isfinite(v) && all_finite(2, dx) && all_finite(3, dg1) && all_finite(3, dg2),
                    "case %d", n);
        /* the spec's formulas, written out here */
        const double *g1 = a + 2, *g2 = a + 5;
        const double n1 = sqrt(g1[0] * g1[0] + g1[1] * g1[1] + g1[2] * g1[2]);
        const double n2 = sqrt(g2[0] * g2[0] + g2[1] * g2[1] + g2[2] * g2[2]);
        double cs = (g1[0] * g2[0] + g1[1] * g2[1] + g1[2] * g2[2]) / (n1 * n2);
        if (c.op == LB_DIFFERENCE) cs = -cs;
        double R[2], M[2] = {c.bp.m[0], c.bp.m[1]};
        for (int i = 0; i < 2; ++i)
            R[i] = (c.bp.flags & LB_BULGE_RANGE) ? c.bp.r[i] * (1 - cs + c.bp.omega) : c.bp.r[i];
        if (c.bp.flags & LB_BULGE_SLOPE) {
            const double G = n1 / n2, cp = fmax(cs, 0.0), m1 = c.bp.m[0], m2 = c.bp.m[1];
            if (m1 > m2 * G)
                M[1] = m2 + (m1 / G - m2) * cp;
            else
                M[0] = m1 + (m2 * G - m1) * cp;
            if (cs >= 1.0 - 1e-12) /* M1/M2 = G at cos theta = 1 */
                tally_check(&val, fabs(M[0] / M[1] - G) <= 1e-9 * G, "case %d: M ratio", n);
        }
        const double vb = base(&c, a, R, M);
        tally_check(&val, fabs(v - vb) <= 1e-12 * (1 + fabs(v)),
                    "case %d fam %d op %d flags %u: %.17g vs %.17g", n, (int)c.fam, (int)c.op,
                    c.bp.flags, v, vb);
        double gall[8] = {dx[0], dx[1], dg1[0], dg1[1], dg1[2], dg2[0], dg2[1], dg2[2]};
        double step[8];
        for (int i = 0; i < 8; ++i) step[i] = 1e-3 * (i < 2 ? fmin(c.bp.r[0], c.bp.r[1]) : 0.1);
        tally_grad(&gd, eval_fn, &c, 8, a, gall, step, "case %d fam %d op %d flags %u", n,
                   (int)c.fam, (int)c.op, c.bp.flags);
    }
    tally_end(&val, N_CASES);
    tally_end(&fin, N_CASES);
    fprintf(stderr, "  tightly checked derivatives: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_bulge)};
    return cmocka_run_group_tests_name("bulge", tests, NULL, NULL);
}
