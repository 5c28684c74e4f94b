/* One operator node at one point, through the public per-family functions:
 * the single place that maps a scene node to the core operator it names. */
#include "scene_internal.h"

void lb__local_in(const lb__node *n, lb_convention conv, const double f[2], double g[2]) {
    const double s = n->lp.zero_scale;
    for (int i = 0; i < 2; ++i)
        g[i] = conv == LB_CONVENTION_ZERO ? LB__LOCAL_ISO * (1.0 - f[i] / s) : f[i];
}

double lb__local_out(const lb__node *n, lb_convention conv, double u) {
    if (conv == LB_CONVENTION_ZERO) return n->lp.zero_scale * (1.0 - u / LB__LOCAL_ISO);
    /* UC2(0, 0) = 0 rounds to about -1e-17: soft fields stay >= 0 */
    return u > 0.0 ? u : 0.0;
}

lb_status lb__clean_apply(const lb__node *n, lb_convention conv, const double *x, double *value,
                          double *dx, lb_error *err) {
    double g[2], u = 0.0, gu[2];
    lb__local_in(n, conv, x, g);
    const lb_status s = lb_clean_union(LB_CLEAN_UC, g, LB__LOCAL_ISO, n->lp.alpha, &u, gu, err);
    if (s) return s;
    *value = lb__local_out(n, conv, u);
    if (dx) { /* zero: the scalings -C/s in and -s/C out cancel */
        dx[0] = gu[0];
        dx[1] = gu[1];
    }
    return LB_OK;
}

lb_status lb__node_apply(const lb__node *n, lb_convention conv, const double *x, const double *c,
                         const double *g, double *value, double *dx, double *dc, double *dg,
                         lb_error *err) {
    const size_t k = n->k;
    switch (n->family) {
    case LB__F_DISPLACEMENT:
    case LB__F_CONIC:
    case LB__F_SCALE:
        if (n->bulge) {
            const lb_bulge_family bf = n->family == LB__F_DISPLACEMENT ? LB_BULGE_DISPLACEMENT
                                       : n->family == LB__F_CONIC      ? LB_BULGE_CONIC
                                                                       : LB_BULGE_SCALE;
            return lb_bulge(bf, n->op, &n->bp, x, g, g + 3, value, dx, dg, dg ? dg + 3 : NULL, err);
        }
        if (n->family == LB__F_DISPLACEMENT)
            return lb_displacement(n->op, k, x, n->r, n->p, n->m, value, dx, err);
        if (n->family == LB__F_CONIC)
            return lb_conic(n->op, x, n->r, n->shape, n->m, value, dx, err);
        return lb_scale(n->op, k, x, n->r, n->p, value, dx, err);
    case LB__F_BOUNDED:
        return lb_bounded(n->op, k, x, c, n->p, value, dx, dc, err);
    case LB__F_SOFT_HYPER:
        return lb_soft_hyper(n->op, k, x, n->r, n->p, n->m, value, dx, err);
    case LB__F_SOFT_CONIC:
        return lb_soft_conic(n->op, x, n->r, n->shape, n->m, value, dx, err);
    case LB__F_MIN:
        return lb_classic(LB_MIN, k, x, 0.0, value, dx, err);
    case LB__F_MAX:
        return lb_classic(LB_MAX, k, x, 0.0, value, dx, err);
    case LB__F_RFUNCTION:
        return lb_classic(n->op == LB_UNION ? LB_RFUNC_UNION : LB_RFUNC_INTERSECTION, k, x, 0.0,
                          value, dx, err);
    case LB__F_SOFT_SUM:
        return lb_classic(LB_SOFT_SUM, k, x, 0.0, value, dx, err);
    case LB__F_RICCI:
        return lb_classic(LB_RICCI_UNION, k, x, n->shape, value, dx, err);
    case LB__F_PERLIN: {
        const lb_status s = lb_classic(n->op == LB_UNION          ? LB_PERLIN_UNION
                                       : n->op == LB_INTERSECTION ? LB_PERLIN_INTERSECTION
                                                                  : LB_PERLIN_DIFFERENCE,
                                       k, x, 0.0, value, dx, err);
        /* the products leave [0, 1] where a soft union took an argument
         * above 1: floored at 0, so the result stays a soft field */
        if (!s && *value < 0.0) {
            *value = 0.0;
            if (dx)
                for (size_t i = 0; i < k; ++i) dx[i] = 0.0;
        }
        return s;
    }
    case LB__F_COMPLEMENT:
        /* soft: 1 - f, floored at 0 where a soft union took f above 1, so the
         * result stays a soft field (>= 0) */
        if (conv == LB_CONVENTION_SOFT && x[0] > 1.0) {
            *value = 0.0;
            if (dx) dx[0] = 0.0;
            return LB_OK;
        }
        *value = conv == LB_CONVENTION_ZERO ? -x[0] : 1.0 - x[0];
        if (dx) dx[0] = -1.0;
        return LB_OK;
    case LB__F_LOCAL: /* without its curves (the compiled evaluator has them): UC */
    case LB__F_CLEAN:
        return lb__clean_apply(n, conv, x, value, dx, err);
    case LB__F_LEVEL: {
        /* the argument's h-level set becomes the surface: zero f - h; soft
         * f - h + 0.5, floored at 0 so the result stays a soft field */
        const double v = conv == LB_CONVENTION_ZERO ? x[0] - n->shape : x[0] - n->shape + 0.5;
        const int floored = conv == LB_CONVENTION_SOFT && v < 0.0;
        *value = floored ? 0.0 : v;
        if (dx) dx[0] = floored ? 0.0 : 1.0;
        return LB_OK;
    }
    case LB__F_GROUP:
        *value = x[0];
        if (dx) dx[0] = 1.0;
        return LB_OK;
    case LB__F_PRIMITIVE:
    case LB__F_COUNT:
        break;
    }
    return lb__fail(err, LB_ERR_INTERNAL, "node %s: not an operator", n->path);
}
