/* The displacement blend's pieces that need no root solver (displacement.c
 * has the rest): the bracket, the non-blending test, the closed form for
 * all p_i = 2 and the gradient at the root. Inline, so the compiled evaluator's batch loop
 * (evaluation/eval_points.c) gets them specialised for a small, constant k
 * and computes exactly what lb__bt_union computes. */
#ifndef LIBBLEND_BT_TWO_H
#define LIBBLEND_BT_TWO_H

#include "../common/internal.h"

/* The reciprocals of lb__bt_setup alone: they depend only on r and m, so a
 * batch over many points computes them once (the same bits as per point). */
static inline void lb__bt_recip(size_t k, const double *r, const double *m, double *ir,
                                double *im) {
    for (size_t i = 0; i < k; ++i) {
        const double inv = 1.0 / (r[i] * m[i]);
        ir[i] = m[i] * inv;
        im[i] = r[i] * inv;
    }
}

/* lb__bt_setup with the reciprocals given (lb__bt_recip). */
static inline void lb__bt_setup_recip(size_t k, const double *x, const double *r, const double *im,
                                      double *b, double *lo, double *hi, size_t *argmin) {
    double a = INFINITY, c = INFINITY;
    size_t j = 0;
    for (size_t i = 0; i < k; ++i) {
        b[i] = (x[i] - r[i]) * im[i];
        const double hi_i = x[i] * im[i];
        if (b[i] < a) a = b[i];
        if (hi_i < c) {
            c = hi_i;
            j = i;
        }
    }
    *lo = a;
    *hi = c;
    *argmin = j;
}

/* Reciprocals, the bracket [min (x-r)/m, min x/m] and its argmin. */
static inline void lb__bt_setup(size_t k, const double *x, const double *r, const double *m,
                                double *ir, double *im, double *b, double *lo, double *hi,
                                size_t *argmin) {
    lb__bt_recip(k, r, m, ir, im);
    lb__bt_setup_recip(k, x, r, im, b, lo, hi, argmin);
}

/* v / m: v itself when m is 1 (the default slope), the same bits without
 * the division, which the non-blending region below takes twice per point. */
static inline double lb__over_m(double v, double m) {
    return m == 1.0 ? v : v / m;
}

/* Non-blending region: no argument but the argmin j is within its range at
 * h = x_j/m_j (every other breakpoint b_i >= hi). Then BT = x_j/m_j exactly. */
static inline int lb__bt_alone(size_t k, const double *x, const double *m, const double *b,
                               double hi, size_t j, double *dx, double *dr, double *dm) {
    for (size_t i = 0; i < k; ++i)
        if (i != j && b[i] < hi) return 0;
    for (size_t i = 0; i < k; ++i) {
        if (dx) dx[i] = i == j ? lb__over_m(1.0, m[j]) : 0.0;
        if (dr) dr[i] = 0.0;
        if (dm) dm[i] = i == j ? -x[j] / (m[j] * m[j]) : 0.0;
    }
    return 1;
}

/* Closed form for all p_i = 2, given the breakpoints b_i = (x_i - r_i)/m_i.
 * T is convex and piecewise quadratic. Start at h = hi with S = the terms
 * active there; with d_i = h - b_i >= 0 and c_i = m_i/r_i,
 *   Q_S(h + s) = sum_S c_i^2 (s + d_i)^2 - 1 = A s^2 + 2 B s + C - 1
 * equals T on [max_S b_i, h]. Its larger root (cancellation-free form, s <= 0)
 * is the answer when every term of S is still active there; otherwise
 * T > 0 at the largest breakpoint of S to the right of that root, so move h
 * there and drop that term. Each pass drops a term: no sorting. */
static inline double lb__bt_two(size_t k, double *b, const double *m, const double *ir, double lo,
                                double hi) {
    /* S = the terms with b_i < hi; a dropped term gets b_i = +inf (b is the
     * caller's scratch, read by nothing after this) */
    double h = hi;
    for (size_t pass = 0; pass <= k; ++pass) {
        double A = 0.0, B = 0.0, C = 0.0;
        for (size_t i = 0; i < k; ++i) {
            if (!(b[i] < hi)) continue;
            const double c = m[i] * ir[i], c2 = c * c, d = h - b[i];
            A += c2;
            B += c2 * d;
            C += c2 * d * d;
        }
        const double e = C - 1.0; /* T(h) >= 0 */
        const double D = B * B - A * e;
        double s = -INFINITY;
        if (e <= 0.0)
            s = 0.0;
        else if (D >= 0.0)
            s = -e / (B + sqrt(D));
        const double hq = h + s;
        /* the largest breakpoint of S right of hq: it is inactive at hq */
        size_t drop = k;
        double bd = -INFINITY;
        for (size_t i = 0; i < k; ++i)
            if (b[i] < hi && b[i] > hq && b[i] > bd) {
                bd = b[i];
                drop = i;
            }
        if (drop == k) {
            h = hq;
            break;
        }
        b[drop] = INFINITY;
        h = bd;
    }
    if (h < lo) h = lo;
    if (h > hi) h = hi;
    return h;
}

/* Derivatives at the root h from w_i (wl, or recomputed when wl is NULL;
 * p NULL means every p_i = 2); w is k doubles of scratch (may be wl). */
static inline void lb__bt_grads(size_t k, const double *x, const double *r, const double *p,
                                const double *m, const double *ir, int mode, double h,
                                size_t argmin, const double *wl, double *w, double *dx, double *dr,
                                double *dm) {
    if (!dx && !dr && !dm) return;
    double D = 0.0;
    for (size_t i = 0; i < k; ++i) {
        if (wl) {
            w[i] = wl[i];
        } else {
            const double t = (r[i] - (x[i] - m[i] * h)) * ir[i];
            const double pi = p ? p[i] : 2.0;
            w[i] = t > 0.0 ? pi * ir[i] * lb__pow_m1(t, pi, mode) : 0.0;
        }
        D += m[i] * w[i];
    }
    if (!(D > 0.0)) { /* rounding left no active term: the Min branch */
        for (size_t i = 0; i < k; ++i) w[i] = 0.0;
        w[argmin] = 1.0;
        D = m[argmin];
    }
    const double iD = 1.0 / D;
    for (size_t i = 0; i < k; ++i) {
        const double wi = w[i] * iD;
        if (dx) dx[i] = wi;
        if (dr) dr[i] = -wi * (x[i] - m[i] * h) * ir[i];
        if (dm) dm[i] = -wi * h;
    }
}

/* BT_k union with every p_i = 2 (lb__bt_union's LB__P_TWO path, also the
 * compiled evaluator's batch loop): the value, and the derivatives by the
 * arguments, ranges and slopes (each of dx, dr, dm may be NULL). ws: 4k
 * doubles of scratch. */
static inline double lb__bt_two_union_ws(size_t k, const double *x, const double *r,
                                         const double *m, double *dx, double *dr, double *dm,
                                         double *ws) {
    double *ir = ws, *im = ws + k, *b = ws + 2 * k, *w = ws + 3 * k;
    double lo, hi;
    size_t j;
    lb__bt_setup(k, x, r, m, ir, im, b, &lo, &hi, &j);
    if (lb__bt_alone(k, x, m, b, hi, j, dx, dr, dm)) return lb__over_m(x[j], m[j]);
    const double h = lb__bt_two(k, b, m, ir, lo, hi);
    lb__bt_grads(k, x, r, NULL, m, ir, LB__P_INTEGER, h, j, NULL, w, dx, dr, dm);
    return h;
}

/* The same for k <= LB_MAX_ARITY, with scratch on the stack. */
static inline double lb__bt_two_union(size_t k, const double *x, const double *r, const double *m,
                                      double *dx, double *dr, double *dm) {
    double ws[4 * LB_MAX_ARITY];
    return lb__bt_two_union_ws(k, x, r, m, dx, dr, dm, ws);
}

/* lb__bt_two_union with the reciprocals of r and m given (lb__bt_recip):
 * the same value and derivatives by the arguments, bit for bit. ws: 2k
 * doubles of scratch. */
static inline double lb__bt_two_union_recip(size_t k, const double *x, const double *r,
                                            const double *m, const double *ir, const double *im,
                                            double *dx, double *ws) {
    double *b = ws, *w = ws + k;
    double lo, hi;
    size_t j;
    lb__bt_setup_recip(k, x, r, im, b, &lo, &hi, &j);
    if (lb__bt_alone(k, x, m, b, hi, j, dx, NULL, NULL)) return lb__over_m(x[j], m[j]);
    const double h = lb__bt_two(k, b, m, ir, lo, hi);
    lb__bt_grads(k, x, r, NULL, m, ir, LB__P_INTEGER, h, j, NULL, w, dx, NULL, NULL);
    return h;
}

#endif
