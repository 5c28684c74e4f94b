/* Local blending over a box: an interval containing a local_union or
 * clean_union, from its children's intervals and whether a blending volume
 * reaches the box. */
#include "local_internal.h"

static double ur_val(double a, double b) {
    return a + b + hypot(a, b);
}

void lb__local_bounds(const lb_evaluator *ev, const lb__instr *in, const lb__iv x[2],
                      const double bc[3], const double br[3], lb__iv *out) {
    const lb__op *nd = in->op;
    const lb_convention conv = ev->conv;
    double lo[2], hi[2];
    if (!isfinite(x[0].lo) || !isfinite(x[0].hi) || !isfinite(x[1].lo) || !isfinite(x[1].hi)) {
        /* a child unbounded on the box: nothing finite is known (the
         * interval scheme's rule, eval_bounds.c) */
        out->lo = conv == LB_CONVENTION_SOFT ? 0.0 : -INFINITY;
        out->hi = INFINITY;
        return;
    }
    for (int a = 0; a < 2; ++a) {
        double f[2] = {x[a].lo, x[a].hi}, g[2];
        lb__local_in(nd, conv, f, g);
        lo[a] = g[0] < g[1] ? g[0] : g[1];
        hi[a] = g[0] < g[1] ? g[1] : g[0];
    }
    const double C = LB__LOCAL_ISO, K = 2.0 - sqrt(2.0);
    const double w0 = hi[0] - lo[0], w1 = hi[1] - lo[1];
    if (br[0] == 0.0 && br[1] == 0.0 && br[2] == 0.0 && w0 <= 1e-9 * (1.0 + fabs(lo[0])) &&
        w1 <= 1e-9 * (1.0 + fabs(lo[1]))) {
        /* a point, its children known to rounding: the value at the middle,
         * padded by the slope times the children's widths (the tests' point
         * boxes are exact; the hull below is for boxes) */
        const double m[2] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])};
        double gu[2], gb[2], u = lb__clean_eval(LB_CLEAN_UC, m, C, nd->lp.alpha, gu);
        double slope = fabs(gu[0]) * w0 + fabs(gu[1]) * w1;
        uint32_t c = 0;
        double Q[3], dist = 0.0;
        const double a = (lb__op_flags(nd) & LB__R_CURVES)
                             ? lb__local_nearest(in->curves, bc, &c, Q, &dist)
                             : 1.0;
        if (a < 1.0 && in->curves->comp[c].R >= ev->sharp_below) {
            const lb__component *P = &in->curves->comp[c];
            double dw, gm[3];
            const double ub = lb__barthe_eval(m, P->p, P->q, gb);
            slope += fabs(gb[0]) * w0 + fabs(gb[1]) * w1;
            if (lb_local_mix(u, ub, lb__wyvill(a, &dw), nd->lp.exponent, &u, gm, NULL)) u = ub;
        }
        const double pad = 2.0 * slope + 1e-12 * (1.0 + fabs(u));
        const double o1 = lb__local_out(nd, conv, u - pad), o2 = lb__local_out(nd, conv, u + pad);
        out->lo = o1 < o2 ? o1 : o2;
        out->hi = o1 < o2 ? o2 : o1;
        return;
    }
    /* max is always among the convex combination's ends */
    double ulo = lo[0] > lo[1] ? lo[0] : lo[1], uhi = hi[0] > hi[1] ? hi[0] : hi[1];
    /* the clean union's weight is 0 on the whole box (alpha 0 and one child
     * at most LB_SOFT_MIN_FIELD): UC is max there, exactly */
    const int wzero = nd->lp.alpha[0] == 0.0 && nd->lp.alpha[1] == 0.0 &&
                      (hi[0] <= LB_SOFT_MIN_FIELD || hi[1] <= LB_SOFT_MIN_FIELD);
    if (wzero) {
    } else if (ulo < C) { /* outside both can occur: UC2 is increasing in both */
        const double v1 = C + ur_val(lo[0] - C, lo[1] - C) / K;
        const double v2 = C + ur_val(hi[0] - C, hi[1] - C) / K;
        if (v1 < ulo) ulo = v1;
        if (v2 > uhi) uhi = v2;
    }
    if (!wzero && hi[0] >= C && hi[1] >= C) { /* inside both can occur */
        const double v2 = C + hypot(hi[0] - C, hi[1] - C);
        if (v2 > uhi) uhi = v2;
    }
    if ((lb__op_flags(nd) & LB__R_CURVES) && lb__local_reaches(in->curves, bc, br)) {
        /* UB >= max, increasing in both: its largest value at the top corner */
        const struct lb__curves *Cv = in->curves;
        for (size_t c = 0; c < Cv->ncomp; ++c) {
            const double xy[2] = {hi[0], hi[1]};
            double ub = 0.0;
            if (lb_barthe_blend(xy, Cv->comp[c].p, Cv->comp[c].q, &ub, NULL, NULL) == LB_OK &&
                ub > uhi)
                uhi = ub;
        }
    }
    ulo -= 1e-9 * (1.0 + fabs(ulo));
    uhi += 1e-9 * (1.0 + fabs(uhi));
    const double o1 = lb__local_out(nd, conv, ulo), o2 = lb__local_out(nd, conv, uhi);
    out->lo = o1 < o2 ? o1 : o2;
    out->hi = o1 < o2 ? o2 : o1;
}
