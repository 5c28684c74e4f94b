/* Scene lifetime, accessors and the tree description. The reference walk
 * is evaluation/reference.c. */
#include "scene_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lb_scene_free(lb_scene *s) {
    if (!s) return;
    for (size_t i = 0; i < s->nnodes; ++i) {
        lb__node *n = s->nodes[i];
        free(n->args);
        free(n->bounds);
        free(n->o.r);
        free(n->o.p);
        free(n->o.m);
        free(n->o.path);
        free(n->def_name);
        free(n->to_local);
        free(n);
    }
    free(s->nodes);
    free(s->mats);
    free(s->name);
    free(s);
}

lb_convention lb_scene_convention(const lb_scene *s) {
    return s ? s->convention : LB_CONVENTION_ZERO;
}

int lb_scene_bounds(const lb_scene *s, double min[3], double max[3]) {
    if (!s || !s->has_bounds) return 0;
    if (min) memcpy(min, s->bmin, sizeof s->bmin);
    if (max) memcpy(max, s->bmax, sizeof s->bmax);
    return 1;
}

const lb_render *lb_scene_render(const lb_scene *s) {
    return s ? &s->render : NULL;
}

void lb_scene_stats_get(const lb_scene *s, lb_scene_stats *st) {
    if (!st) return;
    memset(st, 0, sizeof *st);
    if (!s) return;
    for (size_t i = 0; i < s->nnodes; ++i) {
        const lb__node *n = s->nodes[i];
        if (n->o.family == LB__F_GROUP) continue;
        st->nodes++;
        if (n->o.family == LB__F_PRIMITIVE)
            st->primitives++;
        else
            st->operators++;
    }
    st->depth = s->root ? s->root->depth : 0;
}

/* ---- describe ---- */

static void put_params(lb__text *b, const char *name, size_t k, const double *v) {
    if (!v) return;
    int same = 1;
    for (size_t i = 1; i < k; ++i) same &= v[i] == v[0];
    if (same) {
        lb__text_put(b, " %s=%g", name, v[0]);
        return;
    }
    lb__text_put(b, " %s=[", name);
    for (size_t i = 0; i < k; ++i) lb__text_put(b, "%s%g", i ? "," : "", v[i]);
    lb__text_put(b, "]");
}

static const char *op_name(lb_setop op) {
    return op == LB_UNION ? "union" : op == LB_INTERSECTION ? "intersection" : "difference";
}

static void describe(lb__text *b, const lb__node *n, int indent, const char *role,
                     const void **seen, size_t *nseen) {
    lb__text_put(b, "%*s%s", 2 * indent, "", role);
    if (n->def_name) {
        for (size_t i = 0; i < *nseen; ++i)
            if (seen[i] == n) {
                lb__text_put(b, "ref %s (shared, described above)\n", n->def_name);
                return;
            }
        seen[(*nseen)++] = n;
        lb__text_put(b, "[def %s] ", n->def_name);
    }
    if (n->o.family == LB__F_GROUP) {
        lb__text_put(b, "transform\n");
        describe(b, n->args[0], indent + 1, "", seen, nseen);
        return;
    }
    lb__text_put(b, "%s", n->type);
    if (n->o.family == LB__F_PRIMITIVE) {
        const lb_primitive *P = &n->prim;
        switch (P->kind) {
        case LB_PRIM_ELLIPSOID:
        case LB_PRIM_LP:
        case LB_PRIM_SUPERQUADRIC:
            lb__text_put(b, " center=(%g,%g,%g) semi_axes=(%g,%g,%g)", P->c[0], P->c[1], P->c[2],
                         P->a[0], P->a[1], P->a[2]);
            break;
        case LB_PRIM_CAPSULE:
            lb__text_put(b, " start=(%g,%g,%g) end=(%g,%g,%g) radius=%g", P->c[0], P->c[1], P->c[2],
                         P->q[0], P->q[1], P->q[2], P->s0);
            break;
        default:
            lb__text_put(b, " point=(%g,%g,%g) direction=(%g,%g,%g)", P->c[0], P->c[1], P->c[2],
                         P->n[0], P->n[1], P->n[2]);
            break;
        }
        if (P->kernel != LB_KERNEL_NONE)
            lb__text_put(b, " kernel=%s", P->kernel == LB_KERNEL_WYVILL ? "wyvill" : "blinn");
    } else {
        const lb__family_row *row = lb__family_info(n->o.family);
        if (row->ops) lb__text_put(b, " %s", op_name(n->o.op));
        lb__text_put(b, " k=%zu", n->o.k);
        put_params(b, "r", n->o.k, n->o.r);
        put_params(b, "p", n->o.k, n->o.p);
        put_params(b, "m", n->o.k, n->o.m);
        if (row->shape) lb__text_put(b, " %s=%g", row->shape->key, n->o.shape);
        if (n->o.bulge)
            lb__text_put(b, " bulge(%s%s omega=%g)", n->o.bp.flags & LB_BULGE_RANGE ? "range " : "",
                         n->o.bp.flags & LB_BULGE_SLOPE ? "slope" : "", n->o.bp.omega);
    }
    if (n->has_transform) lb__text_put(b, " +transform");
    lb__text_put(b, "\n");
    for (size_t i = 0; i < n->o.k && n->o.family != LB__F_PRIMITIVE; ++i) {
        describe(b, n->args[i], indent + 1, "", seen, nseen);
        if (n->bounds) describe(b, n->bounds[i], indent + 2, "bound: ", seen, nseen);
    }
}

size_t lb_scene_describe(const lb_scene *s, char *buf, size_t size) {
    if (!buf) size = 0; /* a NULL buffer with any size only measures */
    lb__text b = {buf, size, 0};
    if (buf && size) buf[0] = '\0';
    if (!s || !s->root) return 0;
    const void **seen = calloc(s->nnodes + 1, sizeof *seen);
    if (!seen) return 0;
    size_t nseen = 0;
    describe(&b, s->root, 0, "", seen, &nseen);
    free(seen);
    if (buf && size && b.len >= size) buf[size - 1] = '\0';
    return b.len;
}
