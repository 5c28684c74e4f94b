/* Materials: which node's material a surface point takes.
 *
 * The rule (docs/scene-format.md, "Materials"): walk down from the root; at
 * each operator whose arguments hold materials of their own, go into the
 * argument that decides the set operation at the point, and stop where the
 * subtree below holds none. The deciding argument is the one a sharp set
 * operation would take the value of: a union's most-inside argument, an
 * intersection's most-outside one, a difference's most-outside among the
 * first argument and the complements of the others. A blend keeps that
 * choice: its surface leaves each argument's where the others are far, and
 * in the blend region the boundary runs where the arguments are equally
 * inside. lb__material_score states it once for the POV-Ray writer too. */
#include "../evaluation/tape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t lb_scene_material_count(const lb_scene *s) {
    return s ? 1 + s->nmats : 0;
}

int lb_scene_material(const lb_scene *s, size_t i, lb_material *out) {
    if (!s || !out || i > s->nmats) return 0;
    if (i == 0) {
        const lb_render *R = &s->render;
        memcpy(out->color, R->color, sizeof out->color);
        out->ambient = R->ambient;
        out->diffuse = R->diffuse;
        out->specular = R->specular;
    } else {
        *out = s->mats[i - 1];
    }
    return 1;
}

lb_setop lb__material_op(const lb__node *n) {
    switch (n->family) {
    case LB__F_DISPLACEMENT:
    case LB__F_CONIC:
    case LB__F_SCALE:
    case LB__F_BOUNDED:
    case LB__F_SOFT_HYPER:
    case LB__F_SOFT_CONIC:
    case LB__F_RFUNCTION:
    case LB__F_PERLIN:
        return n->op;
    default:
        return LB_UNION; /* soft_sum, ricci, local_union, clean_union */
    }
}

/* The deciding argument has the smallest score: the sign and offset that
 * turn argument i's value a into "how far inside the result it keeps" */
void lb__material_score(const lb__node *n, lb_convention conv, size_t i, double *sign,
                        double *offset) {
    *offset = 0.0;
    if (n->family == LB__F_MIN || n->family == LB__F_MAX) {
        *sign = n->family == LB__F_MIN ? 1.0 : -1.0; /* the value taken */
        return;
    }
    const int zero = conv == LB_CONVENTION_ZERO;
    const double inside = zero ? 1.0 : -1.0; /* most inside: smallest (zero), largest (soft) */
    const lb_setop op = lb__material_op(n);
    if (op == LB_UNION) {
        *sign = inside;
    } else if (op == LB_INTERSECTION || i == 0) {
        *sign = -inside;
    } else {
        /* the complement's most-outside: zero -(-a) = a, soft 1 - a */
        *sign = zero ? 1.0 : -1.0;
        *offset = zero ? 0.0 : 1.0;
    }
}

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
    if (n->has_transform) lb__affine_compose(&n->to_local, Ap, &A);
    size_t best = 0;
    double bs = INFINITY;
    for (size_t i = 0; i < n->k && n->k > 1; ++i) {
        double v, g[3], sign, off;
        const lb_status s = lb__ref_eval(n->args[i], conv, &A, ev, X, &v, g, err);
        if (s) return s;
        lb__material_score(n, conv, i, &sign, &off);
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
        if (s->nodes[i]->family == LB__F_LOCAL)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: %s: a local_union needs its intersection curves; allowed: pass "
                            "the scene's compiled evaluator as ev",
                            FN, s->nodes[i]->path);
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
