/* Scale method B_A / B_S and the zero-convention B_U, B_I, B_D, and bounded
 * primitives: values against a long-double bisection of the defining
 * equations in h (not the 1/h reduction the library uses), Ricci's operator,
 * homogeneity (Euler), the non-blending regions, the bounded blending region
 * and gradients against central differences. */
#include "testlib.h"
#include "../libblend/src/common/internal.h"

#define N_CASES 100000

typedef struct {
    size_t k;
    double y[16], r[16], p[16];
    int max_like;
} sc_case;

static long double T_ld(long double h, const void *vctx) {
    const sc_case *c = vctx;
    long double s = -1.0L;
    for (size_t i = 0; i < c->k; ++i) {
        const long double yh = (long double)c->y[i] / h;
        const long double t =
            c->max_like ? (yh - 1.0L + c->r[i]) / c->r[i] : (1.0L + c->r[i] - yh) / c->r[i];
        if (t > 0.0L) s += powl(t, (long double)c->p[i]);
    }
    return c->max_like ? -s : s; /* increasing in h for the bisection */
}

static long double ref_scale(const sc_case *c) {
    long double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < c->k; ++i) {
        lo = fminl(lo, c->y[i]);
        hi = fmaxl(hi, c->y[i]);
    }
    if (!c->max_like) {
        if (lo <= 0) return lo;
        long double a = INFINITY;
        for (size_t i = 0; i < c->k; ++i) a = fminl(a, c->y[i] / (1.0L + c->r[i]));
        return ld_bisect(T_ld, c, a, lo);
    }
    if (hi <= 0) return hi;
    long double b = hi;
    while (T_ld(b, c) < 0) b *= 2; /* grow the bracket */
    return ld_bisect(T_ld, c, hi, b);
}

static void sample(rng_t *g, sc_case *c, int wide, int max_like) {
    c->k = rng_int(g, 1, 8);
    c->max_like = max_like;
    const double base = pow(10.0, rng_range(g, wide ? -3.0 : -1.0, wide ? 6.0 : 2.0));
    for (size_t i = 0; i < c->k; ++i) {
        c->r[i] = max_like ? rng_range(g, 1e-3, 1.0) : rng_log(g, 1e-3, wide ? 1e3 : 10.0);
        if (max_like && rng_unit(g) < 0.2) c->r[i] = 1.0;
        c->p[i] = wide ? rng_p(g) : fmin(rng_p(g), 16.0);
        c->y[i] = base * rng_range(g, 0.3, 2.0);
        if (rng_unit(g) < 0.05) c->y[i] = -c->y[i];
    }
}

typedef struct {
    const sc_case *c;
    int which; /* 0 B_A, 1 B_S */
} eval_ctx;
static double eval_fn(const double *y, const void *vctx) {
    const eval_ctx *e = vctx;
    double v = NAN;
    if (e->which == 0)
        lb_scale_ba(e->c->k, y, e->c->r, e->c->p, &v, NULL, NULL);
    else
        lb_scale_bs(e->c->k, y, e->c->r, e->c->p, &v, NULL, NULL);
    return v;
}

static void test_ba_bs(void **state) {
    (void)state;
    rng_t g = {21};
    tally_t ref = {"B_A, B_S vs long-double reference", 0, 0, 0};
    tally_t eul = {"Euler: sum y_i dB/dy_i = B", 0, 0, 0};
    tally_t hom = {"homogeneity B(c y) = c B(y)", 0, 0, 0};
    tally_t nb = {"non-blending B_A = min y", 0, 0, 0};
    tally_t ric = {"B_S with r = 1 is Ricci (sum y^p)^(1/p)", 0, 0, 0};
    tally_t gd = {"gradient vs central differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        const int which = n & 1;
        sc_case c;
        sample(&g, &c, 1, which);
        double v, gr[16];
        lb_status st = which ? lb_scale_bs(c.k, c.y, c.r, c.p, &v, gr, NULL)
                             : lb_scale_ba(c.k, c.y, c.r, c.p, &v, gr, NULL);
        assert_int_equal(st, LB_OK);
        const double vr = (double)ref_scale(&c);
        tally_check(&ref, fabs(v - vr) <= 1e-12 * fabs(vr) + 1e-300 && isfinite(v),
                    "case %d (%s): %.17g vs %.17g", n, which ? "B_S" : "B_A", v, vr);

        double s = 0.0;
        for (size_t i = 0; i < c.k; ++i) s += c.y[i] * gr[i];
        tally_check(&eul, fabs(s - v) <= 1e-10 * fabs(v), "case %d: %g vs %g", n, s, v);
        const double cs = rng_log(&g, 1e-2, 1e2);
        double ys[16], vs;
        for (size_t i = 0; i < c.k; ++i) ys[i] = cs * c.y[i];
        if (which)
            lb_scale_bs(c.k, ys, c.r, c.p, &vs, NULL, NULL);
        else
            lb_scale_ba(c.k, ys, c.r, c.p, &vs, NULL, NULL);
        tally_check(&hom, fabs(vs - cs * v) <= 1e-12 * fabs(cs * v), "case %d", n);
        if (!which) {
            size_t j = 0;
            for (size_t i = 1; i < c.k; ++i)
                if (c.y[i] < c.y[j]) j = i;
            int alone = c.y[j] > 0;
            for (size_t i = 0; i < c.k; ++i)
                if (i != j && c.y[i] < (1.0 + c.r[i]) * c.y[j]) alone = 0;
            if (alone)
                tally_check(&nb, fabs(v - c.y[j]) <= 64 * DBL_EPSILON * (1 + c.r[j]) * c.y[j],
                            "case %d: %.17g vs %.17g", n, v, c.y[j]);
        } else {
            double r1[16], ric_v, sp = 0.0;
            int pos = 1;
            for (size_t i = 0; i < c.k; ++i) {
                r1[i] = 1.0;
                c.p[i] = c.p[0];
                if (c.y[i] <= 0) pos = 0;
            }
            if (pos) {
                double mx = 0.0;
                for (size_t i = 0; i < c.k; ++i) mx = fmax(mx, c.y[i]);
                for (size_t i = 0; i < c.k; ++i) sp += pow(c.y[i] / mx, c.p[0]);
                lb_scale_bs(c.k, c.y, r1, c.p, &ric_v, NULL, NULL);
                tally_check(&ric, fabs(ric_v - mx * pow(sp, 1.0 / c.p[0])) <= 1e-12 * ric_v,
                            "case %d", n);
            }
        }
        /* gradients on moderate scales */
        sc_case cm;
        sample(&g, &cm, 0, which);
        lb_status st2 = which ? lb_scale_bs(cm.k, cm.y, cm.r, cm.p, &v, gr, NULL)
                              : lb_scale_ba(cm.k, cm.y, cm.r, cm.p, &v, gr, NULL);
        assert_int_equal(st2, LB_OK);
        double step[16];
        for (size_t i = 0; i < cm.k; ++i) step[i] = 1e-2 * fabs(cm.y[i]) * fmin(cm.r[i], 1.0);
        const eval_ctx ec = {&cm, which};
        tally_grad(&gd, eval_fn, &ec, cm.k, cm.y, gr, step, "case %d", n);
    }
    tally_end(&ref, N_CASES);
    tally_end(&eul, N_CASES);
    tally_end(&hom, N_CASES);
    tally_end(&nb, N_CASES / 50);
    tally_end(&ric, N_CASES / 4);
    fprintf(stderr, "  tightly checked gradients: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= N_CASES / 2);
    tally_end(&gd, N_CASES);
}

/* ---- zero-convention set operations and bounded primitives ---- */
typedef struct {
    size_t k;
    double x[16], r[16], c[16], p[16];
    lb_setop op;
    int bounded;
} z_case;

static double z_eval(const double *args, const void *vctx) {
    const z_case *z = vctx;
    double v = NAN;
    if (!z->bounded)
        lb_scale(z->op, z->k, args, z->r, z->p, &v, NULL, NULL);
    else
        lb_bounded(z->op, z->k, args, args + z->k, z->p, &v, NULL, NULL, NULL);
    return v;
}

/* long-double reference of B_U/B_I/B_D with ranges r, from the spec's formulas */
static long double ref_zero(lb_setop op, size_t k, const double *x, const double *r,
                            const double *p) {
    sc_case c = {k, {0}, {0}, {0}, 0};
    int min_like = op == LB_UNION;
    long double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < k; ++i) {
        c.y[i] = (op == LB_DIFFERENCE && i > 0 ? -x[i] : x[i]) + 1.0;
        c.r[i] = r[i];
        c.p[i] = p[i];
        lo = fminl(lo, c.y[i]);
        hi = fmaxl(hi, c.y[i]);
    }
    if (min_like ? lo > 0 : hi > 0) {
        c.max_like = !min_like;
        return ref_scale(&c) - 1.0L;
    }
    for (size_t i = 0; i < k; ++i) {
        c.y[i] = -c.y[i];
        if (min_like) c.r[i] = fmin(c.r[i], 1.0);
    }
    c.max_like = min_like;
    return -ref_scale(&c) - 1.0L;
}

static void test_setops_and_bounded(void **state) {
    (void)state;
    rng_t g = {22};
    tally_t ref = {"B_U/B_I/B_D vs long-double reference", 0, 0, 0};
    tally_t bref = {"bounded vs long-double reference", 0, 0, 0};
    tally_t breg = {"bounded: outside every bounding solid = Min/Max", 0, 0, 0};
    tally_t gd = {"set-op and bounded gradients vs differences", 0, 0, 0};
    for (int n = 0; n < N_CASES; ++n) {
        z_case z;
        z.k = rng_int(&g, 1, 6);
        z.op = (lb_setop)(n % 3);
        z.bounded = (n / 3) & 1;
        for (size_t i = 0; i < z.k; ++i) {
            z.x[i] = rng_range(&g, -1.0, 1.5);
            if (rng_unit(&g) < 0.05) z.x[i] = rng_range(&g, -3.0, -1.0); /* beyond ray-linear */
            z.r[i] = z.op == LB_UNION ? rng_log(&g, 1e-2, 3.0) : rng_range(&g, 1e-2, 1.0);
            z.p[i] = fmin(rng_p(&g), 16.0);
            z.c[i] = z.x[i] - rng_range(&g, -0.2, 1.0);
        }
        if (z.bounded && z.op == LB_UNION && rng_unit(&g) < 0.3) {
            /* a point outside every primitive and every bounding solid */
            double mn = INFINITY;
            for (size_t i = 0; i < z.k; ++i) mn = fmin(mn, z.x[i] = rng_range(&g, 0.0, 1.5));
            for (size_t i = 0; i < z.k; ++i) z.c[i] = mn + rng_unit(&g) * (z.x[i] - mn);
        }
        double v, gx[16], gc[16], args[32];
        if (!z.bounded) {
            assert_int_equal(lb_scale(z.op, z.k, z.x, z.r, z.p, &v, gx, NULL), LB_OK);
            const double vr = (double)ref_zero(z.op, z.k, z.x, z.r, z.p);
            tally_check(&ref, fabs(v - vr) <= 1e-12 * (1.0 + fabs(vr)),
                        "case %d op %d: %.17g vs %.17g", n, (int)z.op, v, vr);
        } else {
            assert_int_equal(lb_bounded(z.op, z.k, z.x, z.c, z.p, &v, gx, gc, NULL), LB_OK);
            double R[16];
            for (size_t i = 0; i < z.k; ++i) { /* the spec's R_i, floored and capped */
                const int ul = z.op == LB_UNION || (z.op == LB_DIFFERENCE && i > 0);
                double Ri = LB_BOUNDED_OMEGA;
                if (z.c[i] > -1.0) {
                    const double q = (z.x[i] + 1.0) / (z.c[i] + 1.0);
                    Ri = fmax(ul ? q - 1.0 : 1.0 - q, LB_BOUNDED_OMEGA);
                    if (z.op != LB_UNION) Ri = fmin(Ri, 1.0);
                }
                R[i] = Ri;
            }
            const double vr = (double)ref_zero(z.op, z.k, z.x, R, z.p);
            tally_check(&bref, fabs(v - vr) <= 1e-12 * (1.0 + fabs(vr)),
                        "case %d op %d: %.17g vs %.17g", n, (int)z.op, v, vr);
            /* union: where every bounding solid is outside (c_i >= 0, c_i >= min x),
             * nothing blends */
            if (z.op == LB_UNION) {
                double mn = INFINITY;
                int out = 1;
                for (size_t i = 0; i < z.k; ++i) mn = fmin(mn, z.x[i]);
                for (size_t i = 0; i < z.k; ++i) /* outside; the others' R_i above the floor */
                    if (!(z.c[i] >= 0.0 && z.c[i] >= mn &&
                          (z.x[i] == mn || (z.x[i] + 1) / (z.c[i] + 1) - 1 > LB_BOUNDED_OMEGA)))
                        out = 0;
                if (out && mn > -1.0)
                    tally_check(&breg, fabs(v - mn) <= 4 * DBL_EPSILON * (1 + fabs(mn)),
                                "case %d: %.17g vs min %.17g", n, v, mn);
            }
        }
        /* gradient: away from x = -1 (where B_AS switches branch) */
        int smooth = 1;
        for (size_t i = 0; i < z.k; ++i)
            if (z.x[i] < -0.9 || z.c[i] < -0.9) smooth = 0;
        if (!smooth) continue;
        double step[32];
        size_t na = z.bounded ? 2 * z.k : z.k;
        for (size_t i = 0; i < z.k; ++i) {
            args[i] = z.x[i];
            args[z.k + i] = z.c[i];
            step[i] = step[z.k + i] = 1e-2 * fmin(z.bounded ? 0.1 : z.r[i], 0.1);
        }
        double gall[32];
        for (size_t i = 0; i < z.k; ++i) {
            gall[i] = gx[i];
            gall[z.k + i] = z.bounded ? gc[i] : 0.0;
        }
        tally_grad(&gd, z_eval, &z, na, args, gall, step, "case %d op %d bounded %d", n, (int)z.op,
                   z.bounded);
    }
    tally_end(&ref, N_CASES / 3);
    tally_end(&bref, N_CASES / 3);
    tally_end(&breg, 50);
    fprintf(stderr, "  tightly checked gradients: %ld of %ld\n", gd.tight, gd.checked);
    assert_true(gd.tight >= gd.checked / 2);
    tally_end(&gd, N_CASES / 3);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ba_bs),
        cmocka_unit_test(test_setops_and_bounded),
    };
    return cmocka_run_group_tests_name("scale", tests, NULL, NULL);
}
