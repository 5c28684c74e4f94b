/* Bounded primitives [hsu-bounded 3]: scale-method set operations whose range
 * r_i is a position function R_i built from argument i's bounding solid c_i:
 *   union:        R_i = (x_i + 1)/(c_i + 1) - 1
 *   intersection: R_i = 1 - (x_i + 1)/(c_i + 1)
 *   difference:   R_0 as intersection, R_1.. as union
 * R_i is floored at omega where c_i <= -1 or the bounding solid does not
 * contain the primitive (R_i < omega), and capped at 1 where the operator
 * needs B_S (every argument of an intersection or difference). */
#include "../common/internal.h"

lb_status lb_bounded(lb_setop op, size_t k, const double *x, const double *c, const double *p,
                     double *value, double *grad_x, double *grad_c, lb_error *err) {
    static const char fn[] = "lb_bounded";
    lb_status s;
    if ((s = lb__check_setop(fn, op, err)) || (s = lb__check_k(fn, k, 1, LB_MAX_ARITY, err)) ||
        (s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", k, x, err)) ||
        (s = lb__check_finite(fn, "c", k, c, err)) || (s = lb__check_p(fn, k, p, err)))
        return s;
    double R[LB_MAX_ARITY], dRdx[LB_MAX_ARITY], dRdc[LB_MAX_ARITY];
    double dv[LB_MAX_ARITY], dr[LB_MAX_ARITY];
    for (size_t i = 0; i < k; ++i) {
        const int union_like = op == LB_UNION || (op == LB_DIFFERENCE && i > 0);
        const double cap = op == LB_UNION ? INFINITY : 1.0;
        const double q = c[i] + 1.0;
        double Ri = LB_BOUNDED_OMEGA, gx = 0.0, gc = 0.0;
        if (q > 0.0) {
            const double ratio = (x[i] + 1.0) / q;
            const double sgn = union_like ? 1.0 : -1.0;
            const double cand = sgn * (ratio - 1.0);
            if (cand > LB_BOUNDED_OMEGA && cand <= cap) {
                Ri = cand;
                gx = sgn / q;
                gc = -sgn * ratio / q;
            } else if (cand > cap) {
                Ri = cap;
            }
        }
        R[i] = Ri;
        dRdx[i] = gx;
        dRdc[i] = gc;
    }
    *value = lb__scale_setop(op, k, x, R, p, lb__exponent_mode(k, p), dv, dr);
    for (size_t i = 0; i < k; ++i) {
        if (grad_x) grad_x[i] = dv[i] + dr[i] * dRdx[i];
        if (grad_c) grad_c[i] = dr[i] * dRdc[i];
    }
    return LB_OK;
}
