/* Scale method (Hsu-Lee) [hsu-bounded 2.4.2; hsu-nonuniform 2.3].
 *
 * B_A(y): h with sum_i [(1 + r_i - y_i/h)/r_i]+^p_i = 1. In g = 1/h every
 * term is linear, and with x_i = -1, m_i = y_i and h' = -g it is exactly the
 * displacement equation: B_A(y) = -1 / BT(-1, ..., -1; r, p, m = y).
 * B_S(y): sum_i [(y_i/h - 1 + r_i)/r_i]+^p_i = 1 likewise gives
 * B_S(y) = 1 / BT(1, ..., 1; r, p, m = y) over the y_i > 0 (for r_i <= 1 a
 * term with y_i <= 0 is never active). So the scale method shares the
 * displacement kernel, its p = 2 closed form and its integer-p path, and its
 * gradients follow from the displacement derivatives with respect to m and r.
 *
 * Zero convention: B_U(x) = B_AS(x + 1) - 1, B_I(x) = B_SA(x + 1) - 1,
 * B_D(x) = B_I(x_0, -x_1, ...), with B_AS(y) = B_A(y) if min y > 0 else
 * -B_S(-y) and B_SA(y) = B_S(y) if max y > 0 else -B_A(-y). Where B_S serves a
 * union (some x_i <= -1, outside the ray-linear range f >= -1) it uses
 * min(r_i, 1), because B_S needs r_i <= 1. */
#include "../common/internal.h"

/* Both operators are homogeneous of degree 1 (B(c y) = c B(y)). They are
 * solved on y / s, s = min y (B_A) or max y (B_S), over the arguments that can
 * be active: B_A's term i is active only where y_i < (1 + r_i) h <= (1 + r_i)
 * min y; B_S's only where y_i > (1 - r_i) h >= (1 - r_i) max y, and a B_S term
 * with y_i / max y below 1e-100 adds at most (1e-100)^p: below rounding.
 * So the kernel sees slopes y_i / s in [1e-100, 1 + r_i]: no overflow or
 * underflow for any finite input. dB/dy is of degree 0; dB/dr of degree 1. */
static double scale_kernel(int max_like, size_t k, const double *y, const double *r,
                           const double *p, int mode, double *dy, double *dr) {
    size_t j = 0;
    for (size_t i = 1; i < k; ++i)
        if (max_like ? y[i] > y[j] : y[i] < y[j]) j = i;
    for (size_t i = 0; i < k; ++i) {
        if (dy) dy[i] = 0.0;
        if (dr) dr[i] = 0.0;
    }
    if (max_like ? y[j] <= 0.0 : y[j] <= 0.0) { /* Max / Min branch */
        if (dy) dy[j] = 1.0;
        return y[j];
    }
    const double sc = y[j];
    double ys[LB_MAX_ARITY], ra[LB_MAX_ARITY], pa[LB_MAX_ARITY], xa[LB_MAX_ARITY];
    double q[LB_MAX_ARITY];
    size_t map[LB_MAX_ARITY], n = 0;
    for (size_t i = 0; i < k; ++i) {
        const double u = y[i] / sc;
        const int can = max_like ? (u > 1.0 - r[i] && u >= 1e-100) : (u < 1.0 + r[i]);
        if (!can && i != j) continue;
        ys[n] = u;
        ra[n] = r[i];
        pa[n] = p[i];
        xa[n] = max_like ? 1.0 : -1.0;
        map[n++] = i;
    }
    /* B_A: h' = BT(-1; m = u), B = -1/h'; B_S: g = BT(1; m = u), B = 1/g. With
     * q_i = w_i/D (the kernel's dx): dB/du_i = B q_i, and dB/dr_i =
     * q_i B (B - u_i)/r_i for both (no h'^2 or B^2 appears) */
    const double hp = lb__bt_union(n, xa, ra, pa, ys, mode, q, NULL, NULL);
    const double B = (max_like ? 1.0 : -1.0) / hp;
    for (size_t a = 0; a < n; ++a) {
        if (dy) dy[map[a]] = B * q[a];
        if (dr) dr[map[a]] = sc * (q[a] * B * (B - ys[a]) / ra[a]);
    }
    return sc * B;
}

double lb__scale_ba(size_t k, const double *y, const double *r, const double *p, int mode,
                    double *dy, double *dr) {
    return scale_kernel(0, k, y, r, p, mode, dy, dr);
}

double lb__scale_bs(size_t k, const double *y, const double *r, const double *p, int mode,
                    double *dy, double *dr) {
    return scale_kernel(1, k, y, r, p, mode, dy, dr);
}

/* B_AS (Min-like) or B_SA (Max-like) of y = x' + 1, minus 1, where x' = x or,
 * with neg_tail, (x_0, -x_1, ..., -x_{k-1}); dx is with respect to x'. */
static double scale_zero(int min_like, int neg_tail, size_t k, const double *x, const double *r,
                         const double *p, int mode, double *dx, double *dr) {
    double y[LB_MAX_ARITY], ny[LB_MAX_ARITY], rr[LB_MAX_ARITY];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < k; ++i) {
        y[i] = (neg_tail && i > 0 ? -x[i] : x[i]) + 1.0;
        ny[i] = -y[i];
        rr[i] = r[i] < 1.0 ? r[i] : 1.0;
        if (y[i] < lo) lo = y[i];
        if (y[i] > hi) hi = y[i];
    }
    if (min_like) {
        if (lo > 0.0) return lb__scale_ba(k, y, r, p, mode, dx, dr) - 1.0;
        /* dual branch -B_S(-y), with B_S's r <= 1 */
        const double v = -lb__scale_bs(k, ny, rr, p, mode, dx, dr);
        if (dr)
            for (size_t i = 0; i < k; ++i) dr[i] = r[i] < 1.0 ? -dr[i] : 0.0;
        return v - 1.0;
    }
    if (hi > 0.0) return lb__scale_bs(k, y, r, p, mode, dx, dr) - 1.0;
    const double v = -lb__scale_ba(k, ny, r, p, mode, dx, dr);
    if (dr)
        for (size_t i = 0; i < k; ++i) dr[i] = -dr[i];
    return v - 1.0;
}

double lb__scale_setop(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                       int mode, double *dx, double *dr) {
    const double v = scale_zero(op == LB_UNION, op == LB_DIFFERENCE, k, x, r, p, mode, dx, dr);
    if (dx && op == LB_DIFFERENCE)
        for (size_t i = 1; i < k; ++i) dx[i] = -dx[i];
    return v;
}

static lb_status scale_check(const char *fn, size_t k, const double *y, const double *r,
                             const double *p, double rmax, const double *value, lb_error *err) {
    lb_status s;
    if ((s = lb__check_k(fn, k, 1, LB_MAX_ARITY, err)) || (s = lb__check_out(fn, value, err)) ||
        (s = lb__check_finite(fn, "x", k, y, err)) ||
        (s = lb__check_blend_params(fn, k, r, p, NULL, rmax, err)))
        return s;
    return LB_OK;
}

lb_status lb_scale_ba(size_t k, const double *y, const double *r, const double *p, double *value,
                      double *grad, lb_error *err) {
    lb_status s = scale_check("lb_scale_ba", k, y, r, p, INFINITY, value, err);
    if (s) return s;
    *value = lb__scale_ba(k, y, r, p, lb__exponent_mode(k, p), grad, NULL);
    return LB_OK;
}

lb_status lb_scale_bs(size_t k, const double *y, const double *r, const double *p, double *value,
                      double *grad, lb_error *err) {
    lb_status s = scale_check("lb_scale_bs", k, y, r, p, 1.0, value, err);
    if (s) return s;
    *value = lb__scale_bs(k, y, r, p, lb__exponent_mode(k, p), grad, NULL);
    return LB_OK;
}

lb_status lb_scale(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                   double *value, double *grad, lb_error *err) {
    static const char fn[] = "lb_scale";
    lb_status s = lb__check_setop(fn, op, err);
    if (s || (s = scale_check(fn, k, x, r, p, op == LB_UNION ? INFINITY : 1.0, value, err)))
        return s;
    *value = lb__scale_setop(op, k, x, r, p, lb__exponent_mode(k, p), grad, NULL);
    return LB_OK;
}
