/* Displacement family BT_k [hsu2006 3.1-3.4; Rockwood for m = 1].
 *
 * Union: the h with T(h) = sum_i [(r_i - x_i + m_i h)/r_i]+^p_i - 1 = 0.
 * T is continuous, increasing and (p_i >= 1) convex in h, with T = -1 at
 * lo = min_i (x_i - r_i)/m_i and T >= 0 at hi = min_i x_i/m_i. Paths:
 *  - non-blending (no argument but the argmin within its range at hi):
 *    min_i x_i/m_i exactly, no solve;
 *  - all p_i = 2: T is piecewise quadratic between the breakpoints
 *    b_i = (x_i - r_i)/m_i; a closed form per active set (bt_two), with
 *    cancellation-free quadratics in a shifted variable;
 *  - integer p_i: the shared solver (Halley from hi) with powers by products;
 *  - general p_i: the same with one pow() per active term and evaluation.
 * Gradient by the implicit function theorem, with w_i = (p_i/r_i) t_i^(p_i-1):
 * dh/dx_i = w_i / D, dh/dr_i = -w_i (x_i - m_i h)/(r_i D), dh/dm_i = -w_i h / D,
 * D = sum_j m_j w_j. */
#include "../common/internal.h"
#include "../solver/root.h"
#include "bt_two.h"

#include <stdlib.h>

typedef struct {
    size_t k;
    const double *x, *r, *p, *m, *ir, *im; /* ir = 1/r, im = 1/m */
    int mode;
    double *w;     /* w_i at the last evaluation (for the gradient) */
    double h_last; /* where w was computed */
} bt_ctx;

static LB__ALWAYS_INLINE void bt_T(double h, const void *vctx, double *T, double *dT, double *d2T,
                                   double *smooth) {
    bt_ctx *c = (bt_ctx *)vctx; /* owned by lb__bt_union_newton; w is scratch */
    double sum = -1.0, dsum = 0.0, d2sum = 0.0, rad = INFINITY;
    for (size_t i = 0; i < c->k; ++i) {
        const double t = (c->r[i] - (c->x[i] - c->m[i] * h)) * c->ir[i];
        /* term i has its kink at t = 0, |t| r/m away in h */
        const double d = fabs(t) * c->r[i] * c->im[i];
        if (d < rad) rad = d;
        double wi = 0.0;
        if (t > 0.0) {
            /* t^(p-2) once, then t^(p-1) and t^p by products: no division */
            const double tp2 = c->mode != LB__P_GENERAL ? lb__ipow(t, (unsigned)c->p[i] - 2u)
                                                        : pow(t, c->p[i] - 2.0);
            const double tp1 = tp2 * t;
            const double mr = c->m[i] * c->ir[i];
            sum += tp1 * t;
            wi = c->p[i] * c->ir[i] * tp1;
            dsum += c->m[i] * wi;
            d2sum += (c->p[i] - 1.0) * mr * mr * c->p[i] * tp2;
        }
        c->w[i] = wi;
    }
    c->h_last = h;
    *T = sum;
    *dT = dsum;
    *d2T = d2sum;
    *smooth = 0.5 * rad;
}

static double bt_newton_ws(size_t k, const double *x, const double *r, const double *p,
                           const double *m, int mode, double *dx, double *dr, double *dm,
                           double *ws) {
    double *ir = ws, *im = ws + k, *b = ws + 2 * k, *w = ws + 3 * k;
    double lo, hi;
    size_t j;
    lb__bt_setup(k, x, r, m, ir, im, b, &lo, &hi, &j);
    if (lb__bt_alone(k, x, m, b, hi, j, dx, dr, dm)) return lb__over_m(x[j], m[j]);
    bt_ctx ctx = {k, x, r, p, m, ir, im, mode == LB__P_TWO ? LB__P_INTEGER : mode, w, NAN};
    const double h = lb__root_solve(bt_T, &ctx, lo, hi, hi);
    /* w at h: the last evaluation's, moved to h to first order when the solver
     * accepted a last (tiny, asymptotic) step without evaluating it; an
     * active set that changed over that step is recomputed */
    const double dh = h - ctx.h_last;
    int reuse = 1;
    for (size_t i = 0; i < k && reuse && dh != 0.0; ++i) {
        const double t = (r[i] - (x[i] - m[i] * h)) * ir[i];
        if ((t > 0.0) != (w[i] > 0.0)) reuse = 0;
        if (!(w[i] > 0.0)) continue;
        /* w_i = (p/r) t^(p-1) and t moved by the factor (1 + u), u = (m/r) dh / t:
         * w *= (1 + u)^(p-1), to second order while (p-1)|u| <= 1e-4 (the
         * remainder is below ((p-1)|u|)^3 / 6 ~ 2e-13 relative) */
        const double tl = (r[i] - (x[i] - m[i] * ctx.h_last)) * ir[i];
        const double u = m[i] * ir[i] * dh / tl, pm = p[i] - 1.0;
        if (fabs(pm * u) > 1e-4) reuse = 0;
        w[i] *= 1.0 + pm * u * (1.0 + 0.5 * (pm - 1.0) * u);
    }
    lb__bt_grads(k, x, r, p, m, ir, ctx.mode, h, j, reuse ? w : NULL, w, dx, dr, dm);
    return h;
}

double lb__bt_union_newton(size_t k, const double *x, const double *r, const double *p,
                           const double *m, int mode, double *dx, double *dr, double *dm) {
    double ws[4 * LB_MAX_ARITY];
    if (k > LB_MAX_ARITY) return NAN;
    return bt_newton_ws(k, x, r, p, m, mode, dx, dr, dm, ws);
}

double lb__bt_union_ws(size_t k, const double *x, const double *r, const double *p, const double *m,
                       int mode, double *dx, double *dr, double *dm, double *ws) {
    if (mode != LB__P_TWO) return bt_newton_ws(k, x, r, p, m, mode, dx, dr, dm, ws);
    return lb__bt_two_union_ws(k, x, r, m, dx, dr, dm, ws); /* every p_i is 2 in this mode */
}

double lb__bt_union(size_t k, const double *x, const double *r, const double *p, const double *m,
                    int mode, double *dx, double *dr, double *dm) {
    double ws[4 * LB_MAX_ARITY];
    if (k > LB_MAX_ARITY) return NAN; /* wider calls bring their scratch (lb__bt_union_ws) */
    return lb__bt_union_ws(k, x, r, p, m, mode, dx, dr, dm, ws);
}

lb_status lb__check_blend_params(const char *fn, size_t k, const double *r, const double *p,
                                 const double *m, double rmax, lb_error *err) {
    lb_status s = lb__check_r_m(fn, "r", "m", k, r, m, rmax, LB_MIN_SLOPE, LB_MAX_SLOPE, err);
    if (s) return s;
    return lb__check_p(fn, k, p, err);
}

lb_status lb_displacement(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                          const double *m, double *value, double *grad, lb_error *err) {
    static const char fn[] = "lb_displacement";
    const int mode = lb__fast_mode_n(LB_MAX_ARITY_WIDE, k, x, r, p, m, INFINITY);
    if (!((unsigned)op <= LB_DIFFERENCE && value && mode >= 0)) {
        lb_status s;
        if ((s = lb__check_setop(fn, op, err)) ||
            (s = lb__check_k(fn, k, 1, LB_MAX_ARITY_WIDE, err)) ||
            (s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", k, x, err)) ||
            (s = lb__check_blend_params(fn, k, r, p, m, INFINITY, err)))
            return s;
        return lb__fail(err, LB_ERR_INTERNAL, "%s: parameter check disagreement", fn);
    }
    /* scratch: m's ones, the duals and their signs, the kernel's 4k; on the
     * stack up to LB_MAX_ARITY arguments, on the heap beyond */
    double stack[7 * LB_MAX_ARITY], *ws = stack;
    if (k > LB_MAX_ARITY && !(ws = malloc(7 * k * sizeof *ws)))
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory for %zu arguments", fn, k);
    double *ones = ws + 4 * k, *xt = ones + k, *sg = xt + k;
    if (!m) {
        for (size_t i = 0; i < k; ++i) ones[i] = 1.0;
        m = ones;
    }
    if (op == LB_UNION) {
        *value = lb__bt_union_ws(k, x, r, p, m, mode, grad, NULL, NULL, ws);
    } else {
        lb__dual_args(op, k, x, xt, sg);
        *value = -lb__bt_union_ws(k, xt, r, p, m, mode, grad, NULL, NULL, ws);
        if (grad)
            for (size_t i = 0; i < k; ++i) grad[i] *= -sg[i];
    }
    if (ws != stack) free(ws);
    return LB_OK;
}
