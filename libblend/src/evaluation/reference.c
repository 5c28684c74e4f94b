/* The reference evaluator: a plain recursive walk of the scene's nodes,
 * the baseline the compiled evaluator is tested and benchmarked against.
 * It takes the compiled evaluator only for what the walk cannot find by
 * itself: a local_union's intersection curves. */
#include "tape.h"

#include <stdlib.h>
#include <string.h>

/* Everything is evaluated in world coordinates: A maps world points into the
 * parent frame of node n, so gradients (and bulge angles) are world ones. */
static lb_status ref_eval(const lb__node *n, lb_convention conv, const lb__affine *A,
                          const lb_evaluator *ev, const double X[3], double *v, double g[3],
                          lb_error *err);

/* Hessian-vector term of bulge elimination: the operator depends on the
 * argument gradients g_i, so its gradient has a term H_i dg_i. The analytic
 * first derivatives of the argument are differenced along dg_i. */
static lb_status hvp(const lb__node *a, lb_convention conv, const lb__affine *A,
                     const lb_evaluator *ev, const double X[3], const double d[3], double out[3],
                     lb_error *err) {
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    out[0] = out[1] = out[2] = 0.0;
    if (!(len > 0.0)) return LB_OK;
    const double eps = 1e-5 * (1.0 + fabs(X[0]) + fabs(X[1]) + fabs(X[2]));
    double Xp[3], Xm[3], vp, vm, gp[3], gm[3];
    for (int i = 0; i < 3; ++i) {
        Xp[i] = X[i] + eps * d[i] / len;
        Xm[i] = X[i] - eps * d[i] / len;
    }
    lb_status s;
    if ((s = ref_eval(a, conv, A, ev, Xp, &vp, gp, err)) ||
        (s = ref_eval(a, conv, A, ev, Xm, &vm, gm, err)))
        return s;
    for (int i = 0; i < 3; ++i) out[i] = (gp[i] - gm[i]) / (2.0 * eps) * len;
    return LB_OK;
}

/* A local_union inside its blending volumes, from the curves the compiled
 * evaluator found for this (node, map): the nearest segment by brute force
 * over every segment, then the public operators (clean union, Barthe's
 * blend, the mix) and Wyvill's kernel written out. Outside every volume the
 * result is lb__op_apply's clean union, untouched. */
static lb_status ref_local(const lb__node *n, lb_convention conv, const lb__affine *A,
                           const lb_evaluator *ev, const double X[3], const double f[2],
                           const double gf[6], double *v, double gv[3], lb_error *err) {
    const struct lb__curves *C = NULL;
    for (size_t i = 0; i < ev->n && !C; ++i)
        if (ev->ins[i].code == LB__I_OP && ev->ins[i].node == n &&
            memcmp(&ev->ins[i].A, A, sizeof *A) == 0)
            C = ev->ins[i].curves;
    if (!C || !C->nseg) return LB_OK;
    double best = 1.0, Q[3] = {0, 0, 0}, dist = 0.0;
    size_t bc = 0;
    for (size_t sg = 0; sg < C->nseg; ++sg) {
        const double *a = C->pts + 3 * C->seg[2 * sg], *b = C->pts + 3 * C->seg[2 * sg + 1];
        double ab = 0.0, ax = 0.0;
        for (int d = 0; d < 3; ++d) {
            ab += (b[d] - a[d]) * (b[d] - a[d]);
            ax += (b[d] - a[d]) * (X[d] - a[d]);
        }
        const double t = ab > 0.0 ? fmin(1.0, fmax(0.0, ax / ab)) : 0.0;
        double P[3], dd = 0.0;
        for (int d = 0; d < 3; ++d) {
            P[d] = a[d] + t * (b[d] - a[d]);
            dd += (X[d] - P[d]) * (X[d] - P[d]);
        }
        const double r = sqrt(dd) / C->comp[C->segc[sg]].R;
        if (r < best) {
            best = r;
            bc = C->segc[sg];
            memcpy(Q, P, sizeof P);
            dist = sqrt(dd);
        }
    }
    if (!(best < 1.0)) return LB_OK;
    const lb__component *K = &C->comp[bc];
    double g[2], uc, ub, u, guc[2], gub[2], gm[3];
    lb__local_in(&n->o, conv, f, g);
    const double a2 = best * best;
    const double w = 1.0 - 4.0 / 9.0 * a2 * a2 * a2 + 17.0 / 9.0 * a2 * a2 - 22.0 / 9.0 * a2;
    const double dw = -24.0 / 9.0 * a2 * a2 * best + 68.0 / 9.0 * a2 * best - 44.0 / 9.0 * best;
    lb_status s;
    if ((s = lb_clean_union(LB_CLEAN_UC, g, LB__LOCAL_ISO, n->o.lp.alpha, &uc, guc, err)) ||
        (s = lb_barthe_blend(g, K->p, K->q, &ub, gub, err)) ||
        (s = lb_local_mix(uc, ub, w, n->o.lp.exponent, &u, gm, err)))
        return s;
    *v = lb__local_out(&n->o, conv, u);
    /* zero: g = C (1 - f / s) in, s (1 - U / C) out */
    const double kin = conv == LB_CONVENTION_ZERO ? -LB__LOCAL_ISO / n->o.lp.zero_scale : 1.0;
    const double kout = conv == LB_CONVENTION_ZERO ? -n->o.lp.zero_scale / LB__LOCAL_ISO : 1.0;
    for (int d = 0; d < 3; ++d) {
        const double du = (gm[0] * guc[0] + gm[1] * gub[0]) * gf[d] +
                          (gm[0] * guc[1] + gm[1] * gub[1]) * gf[3 + d];
        const double dv = dist > 0.0 ? gm[2] * dw / K->R * (X[d] - Q[d]) / dist : 0.0;
        gv[d] = kout * (kin * du + dv);
    }
    return LB_OK;
}

static lb_status ref_eval(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                          const lb_evaluator *ev, const double X[3], double *v, double g[3],
                          lb_error *err);

lb_status lb__ref_eval(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                       const lb_evaluator *ev, const double X[3], double *v, double g[3],
                       lb_error *err) {
    return ref_eval(n, conv, Ap, ev, X, v, g, err);
}

static lb_status ref_eval(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                          const lb_evaluator *ev, const double X[3], double *v, double g[3],
                          lb_error *err) {
    lb__affine A = *Ap;
    if (n->has_transform) lb__affine_compose(n->to_local, Ap, &A);
    lb_status s = LB_OK;
    if (n->o.family == LB__F_PRIMITIVE) {
        double L[3], gl[3];
        lb__affine_apply(&A, X, L);
        *v = lb_primitive_eval(&n->prim, L, gl);
        lb__affine_pullback(&A, gl, g);
        return LB_OK;
    }
    const size_t k = n->o.k;
    double small[8 * 10];
    double *x = k <= 8 ? small : malloc(k * (2 + 3 + 2 + 3) * sizeof *x);
    if (!x) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", n->o.path);
    double *c = x + k, *ga = c + k, *dx = ga + 3 * k, *dc = dx + k, *gb = dc + k;
    double dg[6] = {0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < k && !s; ++i) {
        s = ref_eval(n->args[i], conv, &A, ev, X, &x[i], ga + 3 * i, err);
        if (!s && n->bounds) s = ref_eval(n->bounds[i], conv, &A, ev, X, &c[i], gb + 3 * i, err);
    }
    if (!s) s = lb__op_apply(&n->o, conv, x, c, ga, v, dx, dc, dg, err);
    if (!s) {
        g[0] = g[1] = g[2] = 0.0;
        for (size_t i = 0; i < k; ++i)
            for (int d = 0; d < 3; ++d) {
                g[d] += dx[i] * ga[3 * i + d];
                if (n->bounds) g[d] += dc[i] * gb[3 * i + d];
            }
        for (size_t i = 0; i < 2 && n->o.bulge && !s; ++i) {
            double h[3];
            s = hvp(n->args[i], conv, &A, ev, X, dg + 3 * i, h, err);
            for (int d = 0; d < 3; ++d) g[d] += h[d];
        }
    }
    if (!s && (lb__op_flags(&n->o) & LB__R_CURVES) && ev)
        s = ref_local(n, conv, &A, ev, X, x, ga, v, g, err);
    if (x != small) free(x);
    return s;
}

static lb_status walk(const lb_scene *s, const lb_evaluator *ev, const double X[3], double *value,
                      double grad[3], lb_error *err) {
    if (!s || !s->root || !X || !value)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_scene_eval_reference: scene, X and value must be non-NULL");
    for (int i = 0; i < 3; ++i)
        if (!(fabs(X[i]) <= LB_SCENE_MAX_COORD))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "lb_scene_eval_reference: X[%d] = %g; allowed: |X| <= %g", i, X[i],
                            LB_SCENE_MAX_COORD);
    for (size_t i = 0; i < s->nnodes && !ev; ++i)
        if ((lb__op_flags(&s->nodes[i]->o) & LB__R_CURVES))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "lb_scene_eval_reference: %s: a local_union needs its intersection "
                            "curves, which the compiled evaluator finds; allowed: scenes without "
                            "local_union (use lb_evaluator_eval)",
                            s->nodes[i]->o.path);
    if (s->root->walk_cost > LB_SCENE_MAX_COST)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_scene_eval_reference: the plain walk would visit %.3g nodes per "
                        "point (shared defs once per use); allowed: at most %d: use the compiled "
                        "evaluator (lb_evaluator_eval), which shares them",
                        s->root->walk_cost, LB_SCENE_MAX_COST);
    double g[3];
    lb__affine id;
    lb__affine_identity(&id);
    lb_status st = ref_eval(s->root, s->convention, &id, ev, X, value, g, err);
    if (!st && grad) memcpy(grad, g, sizeof g);
    return st;
}

lb_status lb_scene_eval_reference(const lb_scene *s, const double X[3], double *value,
                                  double grad[3], lb_error *err) {
    return walk(s, NULL, X, value, grad, err);
}

lb_status lb__scene_eval_walk(const lb_scene *s, const lb_evaluator *ev, const double X[3],
                              double *value, double grad[3], lb_error *err) {
    return walk(s, ev, X, value, grad, err);
}
