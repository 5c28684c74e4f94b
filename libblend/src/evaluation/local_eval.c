/* Local blending at points: a local_union's value and gradient over a
 * chunk, from its children's registers and its curves (the mix of the clean
 * union and Barthe's blend by Wyvill's kernel of the distance to the nearest
 * curve, docs/local-blending.md), and the clean union's. */
#include "local_internal.h"

#include <string.h>

lb_status lb__local_run(const lb_evaluator *ev, const lb__instr *in, size_t n, const double *x,
                        const double *y, const double *z, double *regs, lb_error *err) {
    const lb__op *nd = in->op;
    const lb_convention conv = ev->conv;
    const double k = conv == LB_CONVENTION_ZERO ? -LB__LOCAL_ISO / nd->lp.zero_scale : 1.0;
    double *ov = lb__reg(regs, in->dst, 0), *ox = lb__reg(regs, in->dst, 1),
           *oy = lb__reg(regs, in->dst, 2), *oz = lb__reg(regs, in->dst, 3);
    const uint32_t r0 = in->src[0], r1 = in->src[1];
    /* a chunk (spatially compact: the evaluator sorts points) that no
     * blending volume reaches skips the distance queries */
    int reach = (lb__op_flags(nd) & LB__R_CURVES) && in->curves && in->curves->nseg;
    if (reach && n) {
        double bc[3], br[3];
        lb__points_box(x, y, z, n, bc, br);
        reach = lb__local_reaches(in->curves, bc, br);
    }
    for (size_t j = 0; j < n; ++j) {
        const double f[2] = {lb__reg(regs, r0, 0)[j], lb__reg(regs, r1, 0)[j]};
        double gf[2][3];
        for (int d = 0; d < 3; ++d) {
            gf[0][d] = lb__reg(regs, r0, 1 + d)[j];
            gf[1][d] = lb__reg(regs, r1, 1 + d)[j];
        }
        double g[2], guc[2];
        if (conv == LB_CONVENTION_SOFT) { /* the children as they are (lb__local_in, inline) */
            g[0] = f[0];
            g[1] = f[1];
        } else {
            lb__local_in(nd, conv, f, g);
        }
        if (!(fabs(g[0]) <= LB_MAX_ABS_ARG && fabs(g[1]) <= LB_MAX_ABS_ARG))
            return lb__fail(err, LB_ERR_NOT_FINITE,
                            "%s: a child's value %g, %g is not finite or beyond 1e100", nd->path,
                            f[0], f[1]);
        const double uc = lb__clean_eval(LB_CLEAN_UC, g, LB__LOCAL_ISO, nd->lp.alpha, guc);
        double u = uc, du[2] = {guc[0], guc[1]}, dv[3] = {0.0, 0.0, 0.0};
        if (reach) {
            const double X[3] = {x[j], y[j], z[j]};
            uint32_t c = 0;
            double Q[3] = {0.0, 0.0, 0.0}, dist = 0.0;
            const double a = lb__local_nearest(in->curves, X, &c, Q, &dist);
            if (a < 1.0 && in->curves->comp[c].R >= ev->sharp_below) {
                const lb__component *K = &in->curves->comp[c];
                double dw, gub[2], gm[3];
                const double v = lb__wyvill(a, &dw);
                const double ub = lb__barthe_eval(g, K->p, K->q, gub);
                lb_status s = lb_local_mix(uc, ub, v, nd->lp.exponent, &u, gm, err);
                if (s) return s;
                du[0] = gm[0] * guc[0] + gm[1] * gub[0];
                du[1] = gm[0] * guc[1] + gm[1] * gub[1];
                /* grad v = W'(a) / R (X - Q) / dist */
                if (dist > 0.0)
                    for (int d = 0; d < 3; ++d) dv[d] = gm[2] * dw / K->R * (X[d] - Q[d]) / dist;
            }
        }
        /* back to the scene's convention: zero f = s (1 - U / C) */
        const double out_k = conv == LB_CONVENTION_ZERO ? -nd->lp.zero_scale / LB__LOCAL_ISO : 1.0;
        ov[j] = conv == LB_CONVENTION_SOFT ? (u > 0.0 ? u : 0.0) : lb__local_out(nd, conv, u);
        double gg[3];
        for (int d = 0; d < 3; ++d)
            gg[d] = out_k * (k * (du[0] * gf[0][d] + du[1] * gf[1][d]) + dv[d]);
        ox[j] = gg[0];
        oy[j] = gg[1];
        oz[j] = gg[2];
    }
    return LB_OK;
}
