/* Every family's operator at one point, through the public per-family
 * functions (the rows' apply column in families.def), and lb__op_apply,
 * the one dispatch through the rows. */
#include "family_fns.h"

void lb__local_in(const lb__op *o, lb_convention conv, const double f[2], double g[2]) {
    const double s = o->lp.zero_scale;
    for (int i = 0; i < 2; ++i)
        g[i] = conv == LB_CONVENTION_ZERO ? LB__LOCAL_ISO * (1.0 - f[i] / s) : f[i];
}

double lb__local_out(const lb__op *o, lb_convention conv, double u) {
    if (conv == LB_CONVENTION_ZERO) return o->lp.zero_scale * (1.0 - u / LB__LOCAL_ISO);
    /* UC2(0, 0) = 0 rounds to about -1e-17: soft fields stay >= 0 */
    return u > 0.0 ? u : 0.0;
}

lb_status lb__clean_apply(const lb__op *o, lb_convention conv, const double *x, double *value,
                          double *dx, lb_error *err) {
    double g[2], u = 0.0, gu[2];
    lb__local_in(o, conv, x, g);
    const lb_status s = lb_clean_union(LB_CLEAN_UC, g, LB__LOCAL_ISO, o->lp.alpha, &u, gu, err);
    if (s) return s;
    *value = lb__local_out(o, conv, u);
    if (dx) { /* zero: the scalings -C/s in and -s/C out cancel */
        dx[0] = gu[0];
        dx[1] = gu[1];
    }
    return LB_OK;
}

lb_status lb__op_apply(const lb__op *o, lb_convention conv, const double *x, const double *c,
                       const double *g, double *value, double *dx, double *dc, double *dg,
                       lb_error *err) {
    const lb__family_row *row = lb__family_info(o->family);
    if (!row->apply) return lb__fail(err, LB_ERR_INTERNAL, "node %s: not an operator", o->path);
    if (o->bulge)
        return lb_bulge((lb_bulge_family)row->bulge_family, o->op, &o->bp, x, g, g + 3, value, dx,
                        dg, dg ? dg + 3 : NULL, err);
    return row->apply(o, conv, x, c, g, value, dx, dc, dg, err);
}

/* the unused columns of the common signature */
#define UNUSED (void)conv, (void)c, (void)g, (void)dc, (void)dg

lb_status lb__apply_displacement(const lb__op *o, lb_convention conv, const double *x,
                                 const double *c, const double *g, double *value, double *dx,
                                 double *dc, double *dg, lb_error *err) {
    UNUSED;
    return lb_displacement(o->op, o->k, x, o->r, o->p, o->m, value, dx, err);
}

lb_status lb__apply_conic(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    UNUSED;
    return lb_conic(o->op, x, o->r, o->shape, o->m, value, dx, err);
}

lb_status lb__apply_scale(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    UNUSED;
    return lb_scale(o->op, o->k, x, o->r, o->p, value, dx, err);
}

lb_status lb__apply_bounded(const lb__op *o, lb_convention conv, const double *x, const double *c,
                            const double *g, double *value, double *dx, double *dc, double *dg,
                            lb_error *err) {
    (void)conv, (void)g, (void)dg;
    return lb_bounded(o->op, o->k, x, c, o->p, value, dx, dc, err);
}

lb_status lb__apply_soft_hyper(const lb__op *o, lb_convention conv, const double *x,
                               const double *c, const double *g, double *value, double *dx,
                               double *dc, double *dg, lb_error *err) {
    UNUSED;
    return lb_soft_hyper(o->op, o->k, x, o->r, o->p, o->m, value, dx, err);
}

lb_status lb__apply_soft_conic(const lb__op *o, lb_convention conv, const double *x,
                               const double *c, const double *g, double *value, double *dx,
                               double *dc, double *dg, lb_error *err) {
    UNUSED;
    return lb_soft_conic(o->op, x, o->r, o->shape, o->m, value, dx, err);
}

lb_status lb__apply_min(const lb__op *o, lb_convention conv, const double *x, const double *c,
                        const double *g, double *value, double *dx, double *dc, double *dg,
                        lb_error *err) {
    UNUSED;
    return lb_classic(LB_MIN, o->k, x, 0.0, value, dx, err);
}

lb_status lb__apply_max(const lb__op *o, lb_convention conv, const double *x, const double *c,
                        const double *g, double *value, double *dx, double *dc, double *dg,
                        lb_error *err) {
    UNUSED;
    return lb_classic(LB_MAX, o->k, x, 0.0, value, dx, err);
}

lb_status lb__apply_rfunction(const lb__op *o, lb_convention conv, const double *x, const double *c,
                              const double *g, double *value, double *dx, double *dc, double *dg,
                              lb_error *err) {
    UNUSED;
    return lb_classic(o->op == LB_UNION ? LB_RFUNC_UNION : LB_RFUNC_INTERSECTION, o->k, x, 0.0,
                      value, dx, err);
}

lb_status lb__apply_soft_sum(const lb__op *o, lb_convention conv, const double *x, const double *c,
                             const double *g, double *value, double *dx, double *dc, double *dg,
                             lb_error *err) {
    UNUSED;
    return lb_classic(LB_SOFT_SUM, o->k, x, 0.0, value, dx, err);
}

lb_status lb__apply_ricci(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    UNUSED;
    return lb_classic(LB_RICCI_UNION, o->k, x, o->shape, value, dx, err);
}

lb_status lb__apply_perlin(const lb__op *o, lb_convention conv, const double *x, const double *c,
                           const double *g, double *value, double *dx, double *dc, double *dg,
                           lb_error *err) {
    UNUSED;
    const lb_status s = lb_classic(o->op == LB_UNION          ? LB_PERLIN_UNION
                                   : o->op == LB_INTERSECTION ? LB_PERLIN_INTERSECTION
                                                              : LB_PERLIN_DIFFERENCE,
                                   o->k, x, 0.0, value, dx, err);
    /* the products leave [0, 1] where a soft union took an argument above
     * 1: floored at 0, so the result stays a soft field */
    if (!s && *value < 0.0) {
        *value = 0.0;
        if (dx)
            for (size_t i = 0; i < o->k; ++i) dx[i] = 0.0;
    }
    return s;
}

lb_status lb__apply_complement(const lb__op *o, lb_convention conv, const double *x,
                               const double *c, const double *g, double *value, double *dx,
                               double *dc, double *dg, lb_error *err) {
    (void)o, (void)c, (void)g, (void)dc, (void)dg, (void)err;
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
}

lb_status lb__apply_group(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    UNUSED;
    (void)o, (void)err;
    *value = x[0];
    if (dx) dx[0] = 1.0;
    return LB_OK;
}

/* local_union without its curves (the compiled evaluator has them) and
 * clean_union: the clean union UC */
lb_status lb__apply_clean(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    (void)c, (void)g, (void)dc, (void)dg;
    return lb__clean_apply(o, conv, x, value, dx, err);
}

lb_status lb__apply_level(const lb__op *o, lb_convention conv, const double *x, const double *c,
                          const double *g, double *value, double *dx, double *dc, double *dg,
                          lb_error *err) {
    (void)c, (void)g, (void)dc, (void)dg, (void)err;
    /* the argument's h-level set becomes the surface: zero f - h; soft
     * f - h + 0.5, floored at 0 so the result stays a soft field */
    const double v = conv == LB_CONVENTION_ZERO ? x[0] - o->shape : x[0] - o->shape + 0.5;
    const int floored = conv == LB_CONVENTION_SOFT && v < 0.0;
    *value = floored ? 0.0 : v;
    if (dx) dx[0] = floored ? 0.0 : 1.0;
    return LB_OK;
}
