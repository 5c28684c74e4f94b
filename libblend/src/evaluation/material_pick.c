/* The material rule at points (scene/material.c states the rule and its
 * scores): a walk down from the root that evaluates the arguments with the
 * reference walk (reference.c), which needs the compiled evaluator for
 * local_union's curves. */
#include "tape.h"

#include <stdlib.h>
#include <string.h>

/* Recursive (depth <= LB_SCENE_MAX_DEPTH): Ap maps world coordinates to
 * n's parent frame. */
static lb_status pick(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                      const lb_evaluator *ev, const double X[3], size_t inherited, size_t *out,
                      lb_error *err) {
    const size_t eff = n->mat ? n->mat : inherited;
    if (!n->mat_below) {
        *out = eff;
        return LB_OK;
    }
    lb__affine A = *Ap;
    if (n->has_transform) lb__affine_compose(n->to_local, Ap, &A);
    size_t best = 0;
    double bs = INFINITY;
    for (size_t i = 0; i < n->o.k && n->o.k > 1; ++i) {
        double v, g[3], sign, off;
        const lb_status s = lb__ref_eval(n->args[i], conv, &A, ev, X, &v, g, err);
        if (s) return s;
        lb__material_score(&n->o, conv, i, &sign, &off);
        if (off + sign * v < bs) { /* ties: the first */
            bs = off + sign * v;
            best = i;
        }
    }
    return pick(n->args[best], conv, &A, ev, X, eff, out, err);
}

lb_status lb_scene_material_index(const lb_scene *s, const lb_evaluator *ev, size_t n,
                                  const double *x, const double *y, const double *z,
                                  uint32_t *index, lb_error *err) {
    static const char FN[] = "lb_scene_material_index";
    if (!s || !s->root || (n && (!x || !y || !z || !index)))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: scene, x, y, z and index must be non-NULL", FN);
    if (!s->root->mat_below) {
        for (size_t i = 0; i < n; ++i) index[i] = (uint32_t)s->root->mat;
        return LB_OK;
    }
    for (size_t i = 0; i < s->nnodes && !ev; ++i)
        if ((lb__op_flags(&s->nodes[i]->o) & LB__R_CURVES))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: %s: a local_union needs its intersection curves; allowed: pass "
                            "the scene's compiled evaluator as ev",
                            FN, s->nodes[i]->o.path);
    if (s->root->walk_cost > LB_SCENE_MAX_COST)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the walk would visit %.3g nodes per point; allowed: at most %d", FN,
                        s->root->walk_cost, LB_SCENE_MAX_COST);
    lb__affine id;
    lb__affine_identity(&id);
    for (size_t i = 0; i < n; ++i) {
        const double X[3] = {x[i], y[i], z[i]};
        for (int d = 0; d < 3; ++d)
            if (!(fabs(X[d]) <= LB_SCENE_MAX_COORD))
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s: point %zu: coordinate %d = %g; allowed: |value| <= %g", FN, i,
                                d, X[d], LB_SCENE_MAX_COORD);
        size_t m = 0;
        const lb_status st = pick(s->root, s->convention, &id, ev, X, 0, &m, err);
        if (st) return st;
        index[i] = (uint32_t)m;
    }
    return LB_OK;
}
