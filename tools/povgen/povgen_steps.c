/* povgen's step counts: the include's root-solved macros unroll a fixed
 * number of Newton steps; povgen runs the very recurrence the SDL performs
 * against the C library over random cases in the documented ranges and
 * returns enough steps for every case to reach its early exit, refusing
 * (exit 1) when a case misses the C value by more than 1e-10. */
#define _POSIX_C_SOURCE 200809L
#include "povgen.h"

#include "../../libblend/src/common/splitmix.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- the documented ranges, checked against the C library ---- */

typedef lb__splitmix rng;
static double unit(rng *r) {
    return lb__splitmix_unit(r);
}
static double logu(rng *r, double a, double b) {
    return exp(log(a) + (log(b) - log(a)) * unit(r));
}
/* p in [P_MIN, P_MAX]: 2 (the closed form), an integer, or general */
static double rand_p(rng *g) {
    const double u = unit(g);
    const double p = u < 0.3   ? 2.0
                     : u < 0.6 ? (double)(1 + (int)(unit(g) * P_MAX))
                               : logu(g, P_MIN, P_MAX);
    return p < P_MIN ? 2.0 : p;
}

/* A solver's verdict over its random cases: the steps it needs, or exit. */
static int steps_needed(const char *what, int worst, double maxerr) {
    if (worst > 400 || maxerr > 1e-10) {
        fprintf(stderr, "povgen: the %s SDL recurrence misses the C library (%d steps, error %g)\n",
                what, worst, maxerr);
        exit(1);
    }
    fprintf(stderr, "povgen: %s: %d steps cover every case (error <= %.2g)\n", what, worst, maxerr);
    return worst + 2;
}

/* The recurrence of LB_Displacement's SDL, step for step (same formulas,
 * same order of operations as the emitted text). Returns the value and the
 * number of Newton steps evaluated. */
static double step_sim(int k, const double *d, const double *r, const double *p, const double *m,
                       int steps, int *used) {
    double h = INFINITY, lo = INFINITY;
    for (int i = 0; i < k; ++i) {
        h = fmin(h, d[i] / m[i]);
        lo = fmin(lo, (d[i] - r[i]) / m[i]);
    }
    for (int n = 0; n < steps; ++n) {
        double T = -1.0, D = 0.0;
        for (int i = 0; i < k; ++i) {
            const double u = (r[i] - d[i] + m[i] * h) / r[i];
            T += pow(fmax(0.0, u), p[i]);
            D += (p[i] * m[i] / r[i]) * (u > 0.0) * pow(fmax(0.0, u), p[i] - 1.0);
        }
        const double dl = T / D;
        *used = n + 1;
        if (fabs(dl) - TOL * (1.0 + fabs(h)) <= 0.0) return h - dl;
        h = fmax(lo, h - dl);
    }
    *used = steps + 1;
    return h;
}

/* One case: the SDL recurrence against lb_displacement. */
static void displacement_case(int k, const double *d, const double *r, const double *p,
                              const double *m, int *worst, double *maxerr) {
    int used = 0;
    const double v = step_sim(k, d, r, p, m, 400, &used);
    double ref;
    lb_error e;
    if (lb_displacement(LB_UNION, (size_t)k, d, r, p, m, &ref, NULL, &e)) {
        fprintf(stderr, "povgen: %s\n", e.message);
        exit(1);
    }
    const double err = fabs(v - ref) / (1.0 + fabs(ref));
    if (used > *worst) *worst = used;
    if (err > *maxerr) *maxerr = err;
}

int choose_steps(void) {
    rng g = {20261122};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        const int k = 1 + (int)(unit(&g) * KMAX);
        double d[KMAX], r[KMAX], p[KMAX], m[KMAX];
        const double scale = logu(&g, 0.01, 10.0);
        for (int i = 0; i < k; ++i) {
            r[i] = scale * logu(&g, 0.05, 1.0);
            d[i] = scale * (2.0 * unit(&g) - 1.0);
            p[i] = rand_p(&g);
            m[i] = logu(&g, M_MIN, M_MAX);
        }
        displacement_case(k, d, r, p, m, &worst, &maxerr);
    }
    /* the scale method's use: d = -1 (B_A, m = y/min y >= 1) or d = 1 (B_S, m = y/max y
     * in (1 - r, 1]) */
    for (int c = 0; c < 200000; ++c) {
        const int k = 1 + (int)(unit(&g) * KMAX);
        const int bs = c & 1;
        double d[KMAX], r[KMAX], p[KMAX], m[KMAX];
        for (int i = 0; i < k; ++i) {
            r[i] = logu(&g, 0.01, bs ? 1.0 : 100.0);
            d[i] = bs ? 1.0 : -1.0;
            m[i] = i == 0 ? 1.0
                   : bs   ? 1.0 - r[i] * unit(&g)
                          : 1.0 + logu(&g, 1e-6, 1.0) * (1.0 + r[i]);
            if (!(m[i] > 0.0)) m[i] = 1e-3;
            p[i] = rand_p(&g);
        }
        displacement_case(k, d, r, p, m, &worst, &maxerr);
    }
    return steps_needed("displacement", worst, maxerr);
}

/* ---- soft non-uniform blends: bracketed Newton in lambda = ln h ---- */

/* T and T' of the soft k-ary blend in lambda, as the SDL computes them */
static void soft_TD(int u, int k, const double *a, const double *r, const double *p,
                    const double *m, double lam, double *T, double *D) {
    double s = 0.0, d = 0.0;
    for (int i = 0; i < k; ++i) {
        const double z = exp(a[i] - m[i] * lam);
        const double t = u ? (r[i] - 1.0 + z) / r[i] : (1.0 + r[i] - z) / r[i];
        if (t > 0.0) {
            s += pow(t, p[i]);
            d += p[i] / r[i] * pow(t, p[i] - 1.0) * m[i] * z;
        }
    }
    *T = u ? 1.0 - s : s - 1.0;
    *D = d;
}

/* The SDL's bracketed Newton in lambda, shared by the soft solvers: start
 * at `lam`, Newton inside [lo, hi], bisection otherwise; exit when
 * |T/D| < LTOL. *used becomes the most steps any call evaluated. */
typedef void (*td_fn)(const void *ctx, double lam, double *T, double *D);

static double bnewton_sim(td_fn td, const void *ctx, double lo, double hi, double lam, int steps,
                          int *used) {
    for (int n = 0; n < steps; ++n) {
        double T, D;
        td(ctx, lam, &T, &D);
        if (n + 1 > *used) *used = n + 1;
        const double st = T / D;
        if (fabs(st) - LTOL <= 0.0) return fmin(hi, fmax(lo, lam - st));
        if (T > 0.0)
            hi = lam;
        else
            lo = lam;
        const double nx = lam - st;
        lam = nx > lo && nx < hi ? nx : 0.5 * (lo + hi);
    }
    *used = steps + 1;
    return lam;
}

typedef struct sh {
    int u, k;
    const double *a, *r, *p, *m;
} sh;

static void sh_TD(const void *c, double lam, double *T, double *D) {
    const sh *q = c;
    soft_TD(q->u, q->k, q->a, q->r, q->p, q->m, lam, T, D);
}

int choose_soft_steps(void) {
    rng g = {424242};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        const int u = c & 1;
        const int k = 1 + (int)(unit(&g) * KMAX);
        double x[KMAX], r[KMAX], p[KMAX], m[KMAX], a[KMAX];
        for (int i = 0; i < k; ++i) {
            x[i] = unit(&g) < 0.1 ? 1e-9 * unit(&g) : unit(&g);
            r[i] = u ? logu(&g, 0.02, 1.0) : logu(&g, 0.02, 3.0);
            if (u && unit(&g) < 0.1) r[i] = 1.0;
            p[i] = rand_p(&g);
            m[i] = logu(&g, 0.05, 20.0);
        }
        double ref;
        lb_error e;
        if (lb_soft_hyper(u ? LB_UNION : LB_INTERSECTION, (size_t)k, x, r, p, m, &ref, NULL, &e)) {
            fprintf(stderr, "povgen: %s\n", e.message);
            exit(1);
        }
        /* the SDL's brackets */
        int npos = 0;
        double nb = u ? -INFINITY : INFINITY, other = u ? -INFINITY : INFINITY;
        for (int i = 0; i < k; ++i) {
            a[i] = log(x[i]) + (1.0 - m[i]) * LN2;
            npos += x[i] > 0.0;
        }
        for (int i = 0; i < k; ++i) {
            nb = u ? fmax(nb, a[i] / m[i]) : fmin(nb, a[i] / m[i]);
            const double l = u ? (r[i] < 1.0 ? (a[i] - log1p(-r[i])) / m[i]
                                             : (a[i] + log((double)npos) / p[i]) / m[i])
                               : (a[i] - log1p(r[i])) / m[i];
            other = u ? fmax(other, l) : fmin(other, l);
        }
        int used = 0;
        const sh q = {u, k, a, r, p, m};
        const double lam = u ? bnewton_sim(sh_TD, &q, nb, other, nb, 400, &used)
                             : bnewton_sim(sh_TD, &q, other, nb, nb, 400, &used);
        const double v = exp(lam);
        const double err = fabs(v - ref) / fmax(1.0, fabs(ref));
        if (used > worst) worst = used;
        if (err > maxerr) maxerr = err;
    }
    return steps_needed("soft blends", worst, maxerr);
}

/* The soft conic's two solves (chord, then H) in lambda, as the SDL does them. */
typedef struct sc {
    double a[2], r[2], m[2], p;
    int u, chord;
} sc;

static void sc_TD(const void *vc, double lam, double *T, double *D) {
    const sc *c = vc;
    double uu[2], du[2];
    for (int i = 0; i < 2; ++i) {
        const double z = exp(c->a[i] - c->m[i] * lam);
        uu[i] = c->u ? 1.0 - z : z - 1.0;
        du[i] = c->u ? c->m[i] * z : -c->m[i] * z;
    }
    const double sg = c->u ? 1.0 : -1.0;
    if (c->chord) {
        *T = sg * (uu[0] / c->r[0] + uu[1] / c->r[1] - 1.0);
        *D = sg * (du[0] / c->r[0] + du[1] / c->r[1]);
        return;
    }
    const double r1 = c->r[0], r2 = c->r[1], n = 1.0 / (r1 * r1 * r2 * r2);
    const double H = r2 * r2 * uu[0] * uu[0] + r1 * r1 * uu[1] * uu[1] + r1 * r1 * r2 * r2 -
                     2.0 * r2 * r2 * r1 * uu[0] - 2.0 * r1 * r1 * r2 * uu[1] +
                     2.0 * c->p * uu[0] * uu[1];
    const double H1 = 2.0 * (r2 * r2 * (uu[0] - r1) + c->p * uu[1]);
    const double H2 = 2.0 * (r1 * r1 * (uu[1] - r2) + c->p * uu[0]);
    *T = -sg * n * H;
    *D = -sg * n * (H1 * du[0] + H2 * du[1]);
}

int choose_sconic_steps(void) {
    rng g = {99};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        sc C;
        C.u = c & 1;
        double x[2];
        for (int i = 0; i < 2; ++i) {
            x[i] = unit(&g);
            C.r[i] = C.u ? logu(&g, 0.02, 1.0) : logu(&g, 0.02, 3.0);
            C.m[i] = logu(&g, 0.05, 20.0);
            C.a[i] = log(x[i]) + (1.0 - C.m[i]) * LN2;
        }
        C.p = C.r[0] * C.r[1] * (c % 5 == 0 ? 0.0 : -3.0 + 3.95 * unit(&g));
        double ref;
        lb_error e;
        if (lb_soft_conic(C.u ? LB_UNION : LB_INTERSECTION, x, C.r, C.p, C.m, &ref, NULL, &e)) {
            fprintf(stderr, "povgen: %s\n", e.message);
            exit(1);
        }
        const double l0 = C.a[0] / C.m[0], l1 = C.a[1] / C.m[1];
        const int j = C.u ? l1 > l0 : l1 < l0, o = 1 - j;
        const double nb = j ? l1 : l0;
        const double zo = exp(C.a[o] - C.m[o] * nb), uo = C.u ? 1.0 - zo : zo - 1.0;
        double v;
        int used = 0;
        if (uo >= C.r[o]) {
            v = exp(nb);
        } else {
            double far = C.u ? -INFINITY : INFINITY;
            for (int i = 0; i < 2; ++i) {
                const double l = (C.a[i] - log1p(C.u ? -0.5 * C.r[i] : 0.5 * C.r[i])) / C.m[i];
                far = C.u ? fmax(far, l) : fmin(far, l);
            }
            C.chord = 1;
            const double lc = C.u ? bnewton_sim(sc_TD, &C, nb, far, nb, 400, &used)
                                  : bnewton_sim(sc_TD, &C, far, nb, nb, 400, &used);
            C.chord = 0;
            const double lam = C.u ? bnewton_sim(sc_TD, &C, nb, lc, nb, 400, &used)
                                   : bnewton_sim(sc_TD, &C, lc, nb, nb, 400, &used);
            v = exp(lam);
        }
        const double err = fabs(v - ref) / fmax(1.0, fabs(ref));
        if (used > worst) worst = used;
        if (err > maxerr) maxerr = err;
    }
    return steps_needed("soft conic", worst, maxerr);
}
