/* The ray-linear functions rho(X) of every primitive kind [hsu-bounded 2.1],
 * inline so the compiled evaluator's per-kind loops can specialise them.
 * lb_primitive_rho (shapes.c) is the public entry point. */
#ifndef LIBBLEND_RHO_H
#define LIBBLEND_RHO_H

#include "../common/internal.h"

static inline double lb__dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* rho = |v| / scale with gradient v / (|v| scale), 0 at v = 0. */
static inline double lb__norm_over(const double v[3], double scale, double *g) {
    const double len = sqrt(lb__dot3(v, v));
    if (g)
        for (int i = 0; i < 3; ++i) g[i] = len > 0.0 ? v[i] / (len * scale) : 0.0;
    return len / scale;
}

/* rho of a primitive of the given kind (a compile-time constant where the
 * caller loops over many points, so the switch folds away). g may be NULL. */
static inline double lb__rho(lb_primitive_kind kind, const lb_primitive *P, const double X[3],
                             double g[3]) {
    double d[3] = {X[0] - P->c[0], X[1] - P->c[1], X[2] - P->c[2]};
    switch (kind) {
    case LB_PRIM_ELLIPSOID: {
        double u[3];
        for (int i = 0; i < 3; ++i) u[i] = d[i] / P->a[i];
        const double f = sqrt(lb__dot3(u, u));
        if (g)
            for (int i = 0; i < 3; ++i) g[i] = f > 0.0 ? u[i] / (P->a[i] * f) : 0.0;
        return f;
    }
    case LB_PRIM_LP: {
        const double n = P->s0;
        double u[3], mx = 0.0, s = 0.0;
        for (int i = 0; i < 3; ++i) {
            u[i] = fabs(d[i]) / P->a[i];
            if (u[i] > mx) mx = u[i];
        }
        if (mx == 0.0) {
            if (g) g[0] = g[1] = g[2] = 0.0;
            return 0.0;
        }
        /* four pow() calls: (u_i/f)^(n-1) = (u_i/mx)^n / (u_i/mx) * (f/mx) / s */
        double Pn[3];
        for (int i = 0; i < 3; ++i) {
            Pn[i] = u[i] > 0.0 ? pow(u[i] / mx, n) : 0.0;
            s += Pn[i];
        }
        const double f1 = pow(s, 1.0 / n); /* rho at the scaled point, in [1, 3] */
        if (g)
            for (int i = 0; i < 3; ++i)
                g[i] = u[i] > 0.0
                           ? Pn[i] / (u[i] / mx) * (f1 / s) * (d[i] < 0.0 ? -1.0 : 1.0) / P->a[i]
                           : 0.0;
        return mx * f1;
    }
    case LB_PRIM_SUPERQUADRIC: {
        const double e1 = P->s0, e2 = P->s1, al = 2.0 / e2, be = 2.0 / e1;
        double u[3];
        for (int i = 0; i < 3; ++i) u[i] = fabs(d[i]) / P->a[i];
        /* scale by the largest |u| so the powers cannot overflow: rho is ray-linear */
        const double mx = fmax(u[0], fmax(u[1], u[2]));
        if (mx == 0.0) {
            if (g) g[0] = g[1] = g[2] = 0.0;
            return 0.0;
        }
        for (int i = 0; i < 3; ++i) u[i] /= mx;
        /* five pow() calls (four when e1 = e2); the gradient reuses them
         * (u^(a-1) = u^a / u) */
        const double P0 = u[0] > 0.0 ? pow(u[0], al) : 0.0;
        const double P1 = u[1] > 0.0 ? pow(u[1], al) : 0.0;
        const double P2 = u[2] > 0.0 ? pow(u[2], be) : 0.0;
        const double A = P0 + P1;
        const double B = al == be ? A : A > 0.0 ? pow(A, be / al) : 0.0;
        const double S = B + P2;
        const double f1 = pow(S, 1.0 / be); /* rho at the scaled point */
        if (g) {
            const double k = f1 / S;
            const double Ab = A > 0.0 ? B / A : 0.0;
            const double Pi[2] = {P0, P1};
            for (int i = 0; i < 2; ++i)
                g[i] = u[i] > 0.0 ? k * Ab * (Pi[i] / u[i]) * (d[i] < 0.0 ? -1.0 : 1.0) / P->a[i]
                                  : 0.0;
            g[2] = u[2] > 0.0 ? k * (P2 / u[2]) * (d[2] < 0.0 ? -1.0 : 1.0) / P->a[2] : 0.0;
        }
        return mx * f1;
    }
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE: {
        const double t = lb__dot3(P->n, d);
        const double sg = t < 0.0 ? (P->kind == LB_PRIM_SLAB ? -1.0 : 0.0) : 1.0;
        if (g)
            for (int i = 0; i < 3; ++i) g[i] = sg * P->n[i] / P->s0;
        return sg * t / P->s0;
    }
    case LB_PRIM_CYLINDER: {
        const double t = lb__dot3(P->n, d);
        double v[3];
        for (int i = 0; i < 3; ++i) v[i] = d[i] - t * P->n[i];
        return lb__norm_over(v, P->s0, g);
    }
    case LB_PRIM_CAPSULE: {
        double e[3], v[3];
        for (int i = 0; i < 3; ++i) e[i] = P->q[i] - P->c[i];
        const double ee = lb__dot3(e, e);
        double t = ee > 0.0 ? lb__dot3(d, e) / ee : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        for (int i = 0; i < 3; ++i) v[i] = d[i] - t * e[i];
        return lb__norm_over(v, P->s0, g);
    }
    case LB_PRIM_TORUS: {
        const double t = lb__dot3(P->n, d);
        double rad[3], v[3];
        for (int i = 0; i < 3; ++i) rad[i] = d[i] - t * P->n[i];
        const double rl = sqrt(lb__dot3(rad, rad));
        /* nearest circle point: along the radial direction (any direction on the axis) */
        for (int i = 0; i < 3; ++i) {
            const double dir = rl > 0.0 ? rad[i] / rl : 0.0;
            v[i] = rad[i] - P->s0 * dir + t * P->n[i];
        }
        if (!(rl > 0.0)) { /* on the axis: every circle point is equally near */
            const double f = sqrt(P->s0 * P->s0 + t * t) / P->s1;
            if (g)
                for (int i = 0; i < 3; ++i)
                    g[i] = f > 0.0 ? t * P->n[i] / (f * P->s1 * P->s1) : 0.0;
            return f;
        }
        return lb__norm_over(v, P->s1, g);
    }
    }
    if (g) g[0] = g[1] = g[2] = 0.0;
    return NAN;
}

#endif
