/* Classic operators against their closed forms, and primitives: ray-linear
 * scaling, the surface at rho = 1, soft kernels keeping that surface at 0.5,
 * and gradients against central differences. */
#include "testlib.h"

#define N_CASES 100000

typedef struct {
    lb_classic_kind kind;
    size_t k;
    double param;
} cl_ctx;
static double cl_eval(const double *x, const void *vctx) {
    const cl_ctx *c = vctx;
    double v = NAN;
    lb_classic(c->kind, c->k, x, c->param, &v, NULL, NULL);
    return v;
}

static void test_classic(void **state) {
    (void)state;
    rng_t g = {51};
    tally_t val = {"classic values vs closed forms", 0, 0, 0};
    tally_t gd = {"classic gradients vs differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        cl_ctx c = {(lb_classic_kind)(n % 9), rng_int(&g, 1, 6), rng_range(&g, 1.0, 8.0)};
        if (c.kind == LB_RFUNC_UNION || c.kind == LB_RFUNC_INTERSECTION) c.k = 2;
        double x[8], v, gr[8];
        for (size_t i = 0; i < c.k; ++i) x[i] = rng_range(&g, -2.0, 2.0);
        if (c.kind >= LB_SOFT_SUM)
            for (size_t i = 0; i < c.k; ++i) x[i] = rng_range(&g, 0.0, 1.0);
        assert_int_equal(lb_classic(c.kind, c.k, x, c.param, &v, gr, NULL), LB_OK);
        long double e = 0; /* expected, written from the spec */
        switch (c.kind) {
        case LB_MIN:
            e = INFINITY;
            for (size_t i = 0; i < c.k; ++i) e = fminl(e, x[i]);
            break;
        case LB_MAX:
            e = -INFINITY;
            for (size_t i = 0; i < c.k; ++i) e = fmaxl(e, x[i]);
            break;
        case LB_RFUNC_UNION:
            e = x[0] + x[1] - sqrtl((long double)x[0] * x[0] + (long double)x[1] * x[1]);
            break;
        case LB_RFUNC_INTERSECTION:
            e = x[0] + x[1] + sqrtl((long double)x[0] * x[0] + (long double)x[1] * x[1]);
            break;
        case LB_SOFT_SUM:
            for (size_t i = 0; i < c.k; ++i) e += x[i];
            break;
        case LB_RICCI_UNION:
            for (size_t i = 0; i < c.k; ++i) e += powl(x[i], c.param);
            e = powl(e, 1.0L / c.param);
            break;
        case LB_PERLIN_UNION:
            e = 1;
            for (size_t i = 0; i < c.k; ++i) e *= 1 - x[i];
            e = 1 - e;
            break;
        case LB_PERLIN_INTERSECTION:
            e = 1;
            for (size_t i = 0; i < c.k; ++i) e *= x[i];
            break;
        case LB_PERLIN_DIFFERENCE:
            e = x[0];
            for (size_t i = 1; i < c.k; ++i) e *= 1 - x[i];
            break;
        }
        tally_check(&val, fabsl(v - e) <= 1e-14L * (1 + fabsl(e)),
                    "case %d kind %d: %.17g vs %.17Lg", n, (int)c.kind, v, e);
        double step[8];
        for (size_t i = 0; i < c.k; ++i) step[i] = 1e-4;
        tally_grad(&gd, cl_eval, &c, c.k, x, gr, step, "case %d kind %d", n, (int)c.kind);
    }
    tally_end(&val, N_CASES);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

static void make_prim(rng_t *g, lb_primitive *P, int kind) {
    double c[3], a[3], d[3], q[3];
    for (int i = 0; i < 3; ++i) {
        c[i] = rng_range(g, -1, 1);
        a[i] = rng_range(g, 0.3, 2.0);
        d[i] = rng_range(g, -1, 1);
        q[i] = c[i] + rng_range(g, -1, 1);
    }
    d[0] += 1.5;
    lb_status s = LB_OK;
    switch (kind) {
    case LB_PRIM_ELLIPSOID:
        s = lb_primitive_ellipsoid(P, c, a, NULL);
        break;
    case LB_PRIM_LP:
        s = lb_primitive_lp(P, c, a, rng_range(g, 1.0, 8.0), NULL);
        break;
    case LB_PRIM_SUPERQUADRIC:
        s = lb_primitive_superquadric(P, c, a, rng_range(g, 0.2, 2.0), rng_range(g, 0.2, 2.0),
                                      NULL);
        break;
    case LB_PRIM_SLAB:
        s = lb_primitive_slab(P, c, d, a[0], NULL);
        break;
    case LB_PRIM_HALFSPACE:
        s = lb_primitive_halfspace(P, c, d, a[0], NULL);
        break;
    case LB_PRIM_CYLINDER:
        s = lb_primitive_cylinder(P, c, d, a[0], NULL);
        break;
    case LB_PRIM_CAPSULE:
        s = lb_primitive_capsule(P, c, q, a[0], NULL);
        break;
    case LB_PRIM_TORUS:
        s = lb_primitive_torus(P, c, d, a[0] + 1.0, a[1] * 0.4, NULL);
        break;
    }
    assert_int_equal(s, LB_OK);
}

static double prim_eval(const double *X, const void *vctx) {
    return lb_primitive_eval((const lb_primitive *)vctx, X, NULL);
}

static void test_primitives(void **state) {
    (void)state;
    rng_t g = {52};
    tally_t rl = {"ray-linear: rho(c + t v) = t rho(c + v)", 0, 0, 0};
    tally_t sf = {"soft kernels: K(1) = 0.5, same surface", 0, 0, 0};
    tally_t gd = {"primitive gradients vs differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        lb_primitive P;
        const int kind = n % 8;
        make_prim(&g, &P, kind);
        double v[3], X[3], Y[3];
        for (int i = 0; i < 3; ++i) v[i] = rng_range(&g, -2, 2);
        const double t = rng_range(&g, 0.01, 10.0);
        /* the centre of a ray-linear shape: c; the capsule and torus are
         * distance-like, so they are checked on their skeleton scaling only */
        if (kind <= LB_PRIM_HALFSPACE) {
            for (int i = 0; i < 3; ++i) {
                X[i] = P.c[i] + v[i];
                Y[i] = P.c[i] + t * v[i];
            }
            const double a = lb_primitive_rho(&P, X, NULL), b = lb_primitive_rho(&P, Y, NULL);
            tally_check(&rl, fabs(b - t * a) <= 1e-12 * (1 + t * a), "case %d kind %d: %g vs %g", n,
                        kind, b, t * a);
        }
        /* soft versions: 0.5 exactly where rho = 1, decreasing in rho */
        for (int i = 0; i < 3; ++i) X[i] = P.c[i] + v[i];
        const double rho = lb_primitive_rho(&P, X, NULL);
        const double f0 = lb_primitive_eval(&P, X, NULL);
        int ok = fabs(f0 - (rho - 1.0)) <= 1e-15 * (1 + rho);
        for (int kern = LB_KERNEL_WYVILL; kern <= LB_KERNEL_BLINN; ++kern) {
            lb_primitive S = P;
            assert_int_equal(lb_primitive_soften(&S, (lb_kernel)kern, NULL), LB_OK);
            const double fs = lb_primitive_eval(&S, X, NULL);
            ok &= (rho < 1.0) == (fs > 0.5) || fabs(rho - 1.0) < 1e-12;
            ok &= fs >= 0.0 && fs <= 1.0;
        }
        tally_check(&sf, ok, "case %d kind %d", n, kind);
        /* gradients of the zero and soft fields */
        lb_primitive S = P;
        lb_primitive_soften(&S, (lb_kernel)(n % 3), NULL);
        double gr[3];
        lb_primitive_eval(&S, X, gr);
        const double step[3] = {1e-5, 1e-5, 1e-5};
        tally_grad(&gd, prim_eval, &S, 3, X, gr, step, "case %d kind %d kernel %d", n, kind, n % 3);
    }
    double wy = 0.0; /* Wyvill at a = 0.5 is exactly 0.5 */
    lb_primitive P;
    const double c0[3] = {0, 0, 0}, X1[3] = {1, 0, 0};
    lb_primitive_sphere(&P, c0, 1.0, NULL);
    lb_primitive_soften(&P, LB_KERNEL_WYVILL, NULL);
    wy = lb_primitive_eval(&P, X1, NULL);
    assert_true(fabs(wy - 0.5) <= 1e-15);
    tally_end(&rl, N_CASES / 2);
    tally_end(&sf, N_CASES);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_classic),
        cmocka_unit_test(test_primitives),
    };
    return cmocka_run_group_tests_name("classic_primitives", tests, NULL, NULL);
}
