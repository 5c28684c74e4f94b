/* Bulge elimination for binary blends [hsu2006 5; hsu-bounded 2.5].
 *
 * The ranges become R_i = r_i (1 - cos theta + omega), theta the angle
 * between the argument gradients; for the displacement and conic families the
 * m_i may also become M_i(cos theta, G = |g1|/|g2|) (docs/operators.md
 * section 4). The base operator is evaluated with (R, M) and its derivatives
 * with respect to r and m are chained through cos theta and G, so the
 * derivatives with respect to g1 and g2 are exact.
 * Intersection and difference: the angle is taken between the gradients as
 * they enter the dual union (a subtracted argument's gradient is negated). */
#include "../common/internal.h"

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static lb_status bulge_check(lb_bulge_family family, lb_setop op, const lb_bulge_params *bp,
                             const double x[2], const double g1[3], const double g2[3],
                             const double *value, lb_error *err) {
    static const char fn[] = "lb_bulge";
    lb_status s;
    if (!bp) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: params is NULL", fn);
    if (family != LB_BULGE_DISPLACEMENT && family != LB_BULGE_CONIC && family != LB_BULGE_SCALE)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: family = %d; allowed: LB_BULGE_DISPLACEMENT (0), LB_BULGE_CONIC (1), "
                        "LB_BULGE_SCALE (2)",
                        fn, (int)family);
    if ((s = lb__check_setop(fn, op, err)) || (s = lb__check_out(fn, value, err)) ||
        (s = lb__check_finite(fn, "x", 2, x, err)) ||
        (s = lb__check_range(fn, "g1", 3, g1, -LB_BULGE_MAX_GRAD, 1, LB_BULGE_MAX_GRAD, 1,
                             "finite, |g1 component| <= 1e30", err)) ||
        (s = lb__check_range(fn, "g2", 3, g2, -LB_BULGE_MAX_GRAD, 1, LB_BULGE_MAX_GRAD, 1,
                             "finite, |g2 component| <= 1e30", err)))
        return s;
    if (bp->flags & ~(unsigned)(LB_BULGE_RANGE | LB_BULGE_SLOPE))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: flags = %u; allowed: a combination of LB_BULGE_RANGE (1) and "
                        "LB_BULGE_SLOPE (2)",
                        fn, bp->flags);
    if (family == LB_BULGE_SCALE && (bp->flags & LB_BULGE_SLOPE))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: LB_BULGE_SLOPE needs m, which the scale family does not have; use "
                        "LB_BULGE_RANGE only",
                        fn);
    const int range = (bp->flags & LB_BULGE_RANGE) != 0;
    if (range && (s = lb__check_range(fn, "params->omega", 1, &bp->omega, 0.0, 0, 1.0, 1,
                                      "0 < omega <= 1 (0.001 in the papers)", err)))
        return s;
    const double rmax = family == LB_BULGE_SCALE && op != LB_UNION
                            ? (range ? 1.0 / (2.0 + bp->omega) : 1.0)
                            : INFINITY;
    if (rmax < INFINITY && range) {
        for (int i = 0; i < 2; ++i)
            if (!(bp->r[i] > 0.0 && bp->r[i] <= rmax))
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s: params->r[%d] = %g is out of range; allowed: 0 < r <= "
                                "1/(2 + omega) = %g, so the range r (1 - cos + omega) stays <= 1",
                                fn, i, bp->r[i], rmax);
    }
    if (family == LB_BULGE_CONIC) {
        if ((s = lb__check_r_m(fn, "params->r", "params->m", 2, bp->r, bp->m, INFINITY,
                               LB_MIN_SLOPE, LB_MAX_SLOPE, err)))
            return s;
        const double f = range ? bp->omega * bp->omega : 1.0;
        const double pmax = bp->r[0] * bp->r[1] * f;
        if (!isfinite(bp->conic_p) || !(bp->conic_p < pmax))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: params->conic_p = %g is out of range; allowed: conic_p < %g "
                            "(r[0] r[1]%s, the smallest R_1 R_2)",
                            fn, bp->conic_p, pmax, range ? " omega^2" : "");
        return LB_OK;
    }
    return lb__check_blend_params(fn, 2, bp->r, bp->p,
                                  family == LB_BULGE_DISPLACEMENT ? bp->m : NULL, rmax, err);
}

lb_status lb_bulge(lb_bulge_family family, lb_setop op, const lb_bulge_params *bp,
                   const double x[2], const double g1[3], const double g2[3], double *value,
                   double dx[2], double dg1[3], double dg2[3], lb_error *err) {
    lb_status st = bulge_check(family, op, bp, x, g1, g2, value, err);
    if (st) return st;
    const int range = (bp->flags & LB_BULGE_RANGE) != 0;
    const int slope = (bp->flags & LB_BULGE_SLOPE) != 0;
    const double sig = op == LB_DIFFERENCE ? -1.0 : 1.0; /* g2 as it enters the union */

    /* cos theta and its derivatives, from unit vectors (so tiny or huge
     * gradients neither underflow nor overflow) */
    const double n1 = lb__norm3(g1), n2 = lb__norm3(g2);
    /* a gradient shorter than LB_BULGE_MIN_GRAD counts as zero: the angle is
     * undefined there, and d cos / d g ~ 1/|g| would overflow */
    const int both = n1 >= LB_BULGE_MIN_GRAD && n2 >= LB_BULGE_MIN_GRAD;
    double cs = 0.0, dc1[3] = {0, 0, 0}, dc2[3] = {0, 0, 0};
    if (both) {
        double e1[3], e2[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = g1[a] / n1;
            e2[a] = g2[a] / n2;
        }
        cs = sig * dot3(e1, e2);
        if (cs > 1.0) cs = 1.0;
        if (cs < -1.0) cs = -1.0;
        for (int a = 0; a < 3; ++a) {
            dc1[a] = (sig * e2[a] - cs * e1[a]) / n1;
            dc2[a] = (sig * e1[a] - cs * e2[a]) / n2;
        }
    }
    /* ranges */
    double R[2], dRdc[2];
    for (int i = 0; i < 2; ++i) {
        R[i] = range ? bp->r[i] * (1.0 - cs + bp->omega) : bp->r[i];
        dRdc[i] = range ? -bp->r[i] : 0.0;
    }
    /* slopes */
    double M[2] = {bp->m[0], bp->m[1]}, dMdc[2] = {0, 0}, dMdG[2] = {0, 0};
    double dG1[3] = {0, 0, 0}, dG2[3] = {0, 0, 0};
    if (slope && both) {
        const double G = n1 / n2, cp = cs > 0.0 ? cs : 0.0, on = cs > 0.0 ? 1.0 : 0.0;
        const double m1 = bp->m[0], m2 = bp->m[1];
        if (m1 > m2 * G) {
            M[1] = m2 + (m1 / G - m2) * cp;
            dMdc[1] = (m1 / G - m2) * on;
            dMdG[1] = cp > 0.0 ? -(m1 / G) / G * cp : 0.0; /* no 0 * inf when cp = 0 */
        } else {
            M[0] = m1 + (m2 * G - m1) * cp;
            dMdc[0] = (m2 * G - m1) * on;
            dMdG[0] = m2 * cp;
        }
        for (int a = 0; a < 3; ++a) {
            dG1[a] = g1[a] / n1 / n2;
            dG2[a] = -G * (g2[a] / n2) / n2;
        }
        /* gradients of wildly different size push M_i past any sensible
         * slope: keep it in [LB_MIN_SLOPE, LB_MAX_SLOPE] (flat there) */
        for (int i = 0; i < 2; ++i)
            if (!(M[i] >= LB_MIN_SLOPE && M[i] <= LB_MAX_SLOPE)) {
                M[i] = M[i] > LB_MAX_SLOPE ? LB_MAX_SLOPE : LB_MIN_SLOPE;
                dMdc[i] = dMdG[i] = 0.0;
            }
    }
    /* base operator */
    double u, du[2], dr[2] = {0, 0}, dm[2] = {0, 0}, sg[2] = {1, 1}, out = 1.0;
    if (family == LB_BULGE_SCALE) {
        u = lb__scale_setop(op, 2, x, R, bp->p, lb__exponent_mode(2, bp->p), du, dr);
    } else {
        double xt[2];
        lb__dual_args(op, 2, x, xt, sg);
        out = op == LB_UNION ? 1.0 : -1.0;
        if (family == LB_BULGE_CONIC)
            u = lb__conic_union(xt, R, bp->conic_p, M, du, dr, dm);
        else
            u = lb__bt_union(2, xt, R, bp->p, M, lb__exponent_mode(2, bp->p), du, dr, dm);
        u *= out;
        for (int i = 0; i < 2; ++i) {
            du[i] *= out * sg[i];
            dr[i] *= out;
            dm[i] *= out;
        }
    }
    *value = u;
    if (dx)
        for (int i = 0; i < 2; ++i) dx[i] = du[i];
    const double dcos = dr[0] * dRdc[0] + dr[1] * dRdc[1] + dm[0] * dMdc[0] + dm[1] * dMdc[1];
    const double dGt = dm[0] * dMdG[0] + dm[1] * dMdG[1];
    for (int a = 0; a < 3; ++a) {
        if (dg1) dg1[a] = dcos * dc1[a] + dGt * dG1[a];
        if (dg2) dg2[a] = dcos * dc2[a] + dGt * dG2[a];
    }
    return LB_OK;
}
