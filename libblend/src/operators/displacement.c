/* Displacement family BT_k [hsu2006 3.1-3.4; Rockwood for m = 1].
 *
 * Union: the h with T(h) = sum_i [(r_i - x_i + m_i h)/r_i]+^p_i - 1 = 0.
 * T is continuous, increasing and (p_i >= 1) convex in h, with T = -1 at
 * lo = min_i (x_i - r_i)/m_i and T >= 0 at hi = min_i x_i/m_i. Three paths:
 *  - all p_i = 2: T is piecewise quadratic between the breakpoints
 *    b_i = (x_i - r_i)/m_i; walk the sorted breakpoints, then solve one
 *    quadratic in the shifted variable s = h - b_j (no cancellation: every
 *    term of its coefficients is non-negative);
 *  - integer p_i: safeguarded Newton from hi with t^(p-1) by products;
 *  - general p_i: the same with pow().
 * Gradient by the implicit function theorem, with w_i = (p_i/r_i) t_i^(p_i-1):
 * dh/dx_i = w_i / D, dh/dr_i = -w_i (x_i - m_i h)/(r_i D), dh/dm_i = -w_i h / D,
 * D = sum_j m_j w_j. */
#include "../common/internal.h"
#include "../solver/root.h"

typedef struct {
    size_t k;
    const double *x, *r, *p, *m;
    int mode;
} bt_ctx;

static void bt_T(double h, const void *vctx, double *T, double *dT) {
    const bt_ctx *c = vctx;
    double sum = -1.0, dsum = 0.0;
    for (size_t i = 0; i < c->k; ++i) {
        const double t = (c->r[i] - (c->x[i] - c->m[i] * h)) / c->r[i];
        if (t > 0.0) {
            const double tp1 = lb__pow_m1(t, c->p[i], c->mode);
            sum += tp1 * t;
            dsum += c->p[i] * c->m[i] / c->r[i] * tp1;
        }
    }
    *T = sum;
    *dT = dsum;
}

static void bt_bracket(size_t k, const double *x, const double *r, const double *m, double *lo,
                       double *hi, size_t *argmin) {
    double a = INFINITY, b = INFINITY;
    size_t j = 0;
    for (size_t i = 0; i < k; ++i) {
        const double lo_i = (x[i] - r[i]) / m[i], hi_i = x[i] / m[i];
        if (lo_i < a) a = lo_i;
        if (hi_i < b) {
            b = hi_i;
            j = i;
        }
    }
    *lo = a;
    *hi = b;
    *argmin = j;
}

/* Derivatives at the root h (shared by every path). */
static void bt_grads(size_t k, const double *x, const double *r, const double *p, const double *m,
                     int mode, double h, size_t argmin, double *dx, double *dr, double *dm) {
    if (!dx && !dr && !dm) return;
    double w[LB_MAX_ARITY];
    double D = 0.0;
    for (size_t i = 0; i < k; ++i) {
        const double t = (r[i] - (x[i] - m[i] * h)) / r[i];
        w[i] = t > 0.0 ? p[i] / r[i] * lb__pow_m1(t, p[i], mode) : 0.0;
        D += m[i] * w[i];
    }
    if (!(D > 0.0)) { /* rounding left no active term: the Min branch */
        for (size_t i = 0; i < k; ++i) w[i] = 0.0;
        w[argmin] = 1.0;
        D = m[argmin];
    }
    for (size_t i = 0; i < k; ++i) {
        const double wi = w[i] / D;
        if (dx) dx[i] = wi;
        if (dr) dr[i] = -wi * (x[i] - m[i] * h) / r[i];
        if (dm) dm[i] = -wi * h;
    }
}

/* Closed form for all p_i = 2. */
static double bt_two(size_t k, const double *x, const double *r, const double *m, double lo,
                     double hi) {
    double b[LB_MAX_ARITY];
    size_t idx[LB_MAX_ARITY];
    if (k == 0) return hi;
    for (size_t i = 0; i < k; ++i) {
        b[i] = (x[i] - r[i]) / m[i];
        size_t j = i;
        while (j > 0 && b[idx[j - 1]] > b[i]) {
            idx[j] = idx[j - 1];
            --j;
        }
        idx[j] = i;
    }
    /* Sums over the active terms of c^2, c^2 d, c^2 d^2 with c = m/r and
     * d = pivot - b_i >= 0, so T(pivot + s) = A s^2 + 2 B s + C - 1. */
    double A = 0.0, B = 0.0, C = 0.0, piv = b[idx[0]];
    double h = hi;
    int solved = 0;
    for (size_t j = 0; j < k && !solved; ++j) {
        const size_t i = idx[j];
        if (j > 0) {
            const double d = b[i] - piv;
            const double Cn = C + d * (2.0 * B + A * d);
            if (Cn >= 1.0) { /* root between piv and b_i, with the current set */
                const double e = 1.0 - C;  /* >= 0 */
                h = piv + e / (B + sqrt(B * B + A * e));
                solved = 1;
                break;
            }
            B += A * d;
            C = Cn;
            piv = b[i];
        }
        const double c = m[i] / r[i];
        A += c * c;
    }
    if (!solved) {
        const double e = 1.0 - C;
        h = piv + e / (B + sqrt(B * B + A * e));
    }
    if (h < lo) h = lo;
    if (h > hi) h = hi;
    return h;
}

double lb__bt_union_newton(size_t k, const double *x, const double *r, const double *p,
                           const double *m, int mode, double *dx, double *dr, double *dm) {
    double lo, hi;
    size_t j;
    bt_bracket(k, x, r, m, &lo, &hi, &j);
    const bt_ctx ctx = {k, x, r, p, m, mode == LB__P_TWO ? LB__P_INTEGER : mode};
    const double h = lb__root_solve(bt_T, &ctx, lo, hi, hi);
    bt_grads(k, x, r, p, m, ctx.mode, h, j, dx, dr, dm);
    return h;
}

double lb__bt_union(size_t k, const double *x, const double *r, const double *p, const double *m,
                    int mode, double *dx, double *dr, double *dm) {
    if (mode != LB__P_TWO) return lb__bt_union_newton(k, x, r, p, m, mode, dx, dr, dm);
    double lo, hi;
    size_t j;
    bt_bracket(k, x, r, m, &lo, &hi, &j);
    const double h = bt_two(k, x, r, m, lo, hi);
    bt_grads(k, x, r, p, m, LB__P_INTEGER, h, j, dx, dr, dm);
    return h;
}

lb_status lb__check_blend_params(const char *fn, size_t k, const double *r, const double *p,
                                 const double *m, double rmax, lb_error *err) {
    lb_status s;
    if ((s = lb__check_range(fn, "r", k, r, 0.0, 0, rmax, 1, rmax == 1.0 ? "0 < r <= 1" : "r > 0",
                             err)))
        return s;
    if ((s = lb__check_range(fn, "p", k, p, 1.0, 0, LB_MAX_EXPONENT, 1, "1 < p <= 1000", err)))
        return s;
    if (m && (s = lb__check_range(fn, "m", k, m, 0.0, 0, INFINITY, 0, "m > 0", err))) return s;
    return LB_OK;
}

lb_status lb_displacement(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                          const double *m, double *value, double *grad, lb_error *err) {
    static const char fn[] = "lb_displacement";
    lb_status s;
    if ((s = lb__check_setop(fn, op, err)) || (s = lb__check_k(fn, k, 1, LB_MAX_ARITY, err)) ||
        (s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", k, x, err)) ||
        (s = lb__check_blend_params(fn, k, r, p, m, INFINITY, err)))
        return s;
    double ones[LB_MAX_ARITY], xt[LB_MAX_ARITY], sg[LB_MAX_ARITY];
    if (!m) {
        for (size_t i = 0; i < k; ++i) ones[i] = 1.0;
        m = ones;
    }
    lb__dual_args(op, k, x, xt, sg);
    const double h = lb__bt_union(k, xt, r, p, m, lb__exponent_mode(k, p), grad, NULL, NULL);
    const double out = op == LB_UNION ? 1.0 : -1.0;
    *value = out * h;
    if (grad)
        for (size_t i = 0; i < k; ++i) grad[i] *= out * sg[i];
    return LB_OK;
}
