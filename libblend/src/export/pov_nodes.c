/* The POV-Ray writer's node DAG: one #declare'd function per node (per
 * node and world frame under a local_union), the operators as the rows of
 * the family registry say (LB__POV_* forms, the include's macros). */
#include "pov_internal.h"

/* Does the subtree hold a local_union? (memoised: scenes are DAGs) Such
 * subtrees are written once per world frame they are used in, because each
 * use has blending volumes of its own. */
static int has_local(pctx *c, const lb__node *n) {
    if ((lb__op_flags(&n->o) & LB__R_CURVES)) return 1;
    if (n->o.family == LB__F_PRIMITIVE) return 0;
    for (size_t i = 0; i < c->nl; ++i)
        if (c->lnodes[i] == n) return c->lflag[i];
    int f = 0;
    for (size_t i = 0; i < n->o.k && !f; ++i)
        f = has_local(c, n->args[i]) || (n->bounds && has_local(c, n->bounds[i]));
    if (c->nl == c->lcap) {
        const size_t nc = c->lcap ? 2 * c->lcap : 64;
        const lb__node **a = realloc(c->lnodes, nc * sizeof *a);
        if (a) c->lnodes = a;
        int *q = a ? realloc(c->lflag, nc * sizeof *q) : NULL;
        if (q) c->lflag = q;
        if (!a || !q) return f; /* not remembered: found again next time */
        c->lcap = nc;
    }
    c->lnodes[c->nl] = n;
    c->lflag[c->nl++] = f;
    return f;
}

/* The k nodes args written, their function numbers into *ids (the caller
 * frees it; NULL on failure). */
static lb_status emit_list(pctx *c, size_t k, lb__node *const *args, int **ids) {
    *ids = malloc(k * sizeof **ids);
    if (!*ids) return lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    for (size_t i = 0; i < k; ++i) {
        const lb_status s = lb__pov_emit(c, args[i], &(*ids)[i]);
        if (s) {
            free(*ids);
            *ids = NULL;
            return s;
        }
    }
    return LB_OK;
}

/* The nodes args written, then an array of them named LB<tag><aid>. */
static lb_status emit_array(pctx *c, size_t k, lb__node *const *args, char tag, int aid) {
    int *ids;
    const lb_status s = emit_list(c, k, args, &ids);
    if (s) return s;
    sb(c->b, "#declare LB%c%d = array[%zu] {", tag, aid, k);
    for (size_t i = 0; i < k; ++i) sb(c->b, "%sLBn%d", i ? ", " : "", ids[i]);
    sb(c->b, "};\n");
    free(ids);
    return LB_OK;
}

static lb_status emit_node(pctx *c, const lb__node *n, int id);

/* the id n was written under for the world frame F (n's own frame), or -1:
 * a node holding a local_union is written once per frame, others once */
int lb__pov_written_id(pctx *c, const lb__node *n, const lb__affine *F) {
    const int keyed = has_local(c, n);
    for (size_t i = 0; i < c->ndone; ++i)
        if (c->done[i] == n && (!keyed || memcmp(&c->doneA[i], F, sizeof *F) == 0))
            return c->ids[i];
    return -1;
}

/* the three coordinates y = M x + t as function arguments */
void lb__pov_affine_args(sbuf *b, const lb__affine *A) {
    for (int r = 0; r < 3; ++r)
        sb(b, "%s%.17g * x + %.17g * y + %.17g * z + %.17g", r ? ", " : "", A->M[3 * r],
           A->M[3 * r + 1], A->M[3 * r + 2], A->t[r]);
}

/* One declaration per node (per node and world frame under a local_union):
 * shared defs stay shared. */
lb_status lb__pov_emit(pctx *c, const lb__node *n, int *out) {
    const lb__affine saved = c->A;
    lb__affine A = saved;
    if (n->has_transform) lb__affine_compose(n->to_local, &saved, &A);
    const int known = lb__pov_written_id(c, n, &A);
    if (known >= 0) {
        *out = known;
        return LB_OK;
    }
    const int id = c->next++;
    c->A = A;
    lb_status s = emit_node(c, n, id);
    c->A = saved;
    if (s) return s;
    if (c->ndone == c->cap) {
        const size_t nc = c->cap ? 2 * c->cap : 64;
        const lb__node **d = realloc(c->done, nc * sizeof *d);
        if (d) c->done = d;
        int *q = d ? realloc(c->ids, nc * sizeof *q) : NULL;
        if (q) c->ids = q;
        lb__affine *fa = q ? realloc(c->doneA, nc * sizeof *fa) : NULL;
        if (fa) c->doneA = fa;
        if (!fa) return lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        c->cap = nc;
    }
    c->done[c->ndone] = n;
    c->doneA[c->ndone] = A;
    c->ids[c->ndone++] = id;
    *out = id;
    return c->b->oom ? lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN) : LB_OK;
}

/* a primitive: its include function, with its kernel (soft) */
static void emit_primitive(sbuf *b, const lb__node *n, int id, const char *name) {
    const lb_primitive *P = &n->prim;
    const char *base = P->kernel == LB_KERNEL_NONE ? name : "LBr";
    sb(b, "#declare %s%d = ", base, id);
    switch (P->kind) {
    case LB_PRIM_ELLIPSOID:
        sb(b, "LB_Ellipsoid(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>)\n", P->c[0], P->c[1],
           P->c[2], P->a[0], P->a[1], P->a[2]);
        break;
    case LB_PRIM_LP:
        sb(b, "LB_LP(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n", P->c[0], P->c[1],
           P->c[2], P->a[0], P->a[1], P->a[2], P->s0);
        break;
    case LB_PRIM_SUPERQUADRIC:
        sb(b, "LB_Superquadric(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g, %.17g)\n",
           P->c[0], P->c[1], P->c[2], P->a[0], P->a[1], P->a[2], P->s0, P->s1);
        break;
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE:
        sb(b, "%s(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n",
           P->kind == LB_PRIM_SLAB ? "LB_Slab" : "LB_Halfspace", P->c[0], P->c[1], P->c[2], P->n[0],
           P->n[1], P->n[2], P->s0);
        break;
    case LB_PRIM_CYLINDER:
        sb(b, "LB_Cylinder(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n", P->c[0],
           P->c[1], P->c[2], P->n[0], P->n[1], P->n[2], P->s0);
        break;
    case LB_PRIM_CAPSULE:
        sb(b, "LB_Capsule(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n", P->c[0], P->c[1],
           P->c[2], P->q[0], P->q[1], P->q[2], P->s0);
        break;
    case LB_PRIM_TORUS:
        sb(b, "LB_Torus(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g, %.17g)\n", P->c[0],
           P->c[1], P->c[2], P->n[0], P->n[1], P->n[2], P->s0, P->s1);
        break;
    }
    if (P->kernel != LB_KERNEL_NONE)
        sb(b, "#declare %s%d = function(x, y, z) { %s(LBr%d(x, y, z) + 1) }\n", name, id,
           P->kernel == LB_KERNEL_WYVILL ? "LB_Wyvill" : "LB_Blinn", id);
}

/* the row's parameters in the include's order, r, p, m (the row's scalar
 * parameter in its key's place, or last) */
static void emit_params(sbuf *b, const lb__family_row *row, const lb__node *n) {
    static const char *const order[] = {"r", "p", "m"};
    const double *const arrays[] = {n->o.r, n->o.p, n->o.m};
    int shape_done = 0;
    for (int i = 0; i < 3; ++i) {
        const lb__param *p = lb__family_param(row, order[i]);
        if (p) {
            sb(b, ", ");
            arr(b, n->o.k, arrays[i], p->def);
        } else if (row->shape && strcmp(row->shape->key, order[i]) == 0) {
            sb(b, ", %.17g", n->o.shape);
            shape_done = 1;
        }
    }
    if (row->shape && !shape_done) sb(b, ", %.17g", n->o.shape);
}

/* an operator written with a macro of the include (LB__POV_MACRO): a
 * binary one takes its two argument functions, a k-ary one arrays */
static lb_status emit_macro(pctx *c, const lb__family_row *row, const lb__node *n, int id,
                            const char *name) {
    sbuf *b = c->b;
    lb_status s;
    const char *macro = row->pov[1] ? row->pov[n->o.op] : row->pov[0];
    const int with_op = row->ops && !row->pov[1];
    if (row->kmin == 2 && row->kmax == 2) {
        int a, d;
        if ((s = lb__pov_emit(c, n->args[0], &a)) || (s = lb__pov_emit(c, n->args[1], &d)))
            return s;
        sb(b, "#declare %s%d = %s(", name, id, macro);
        if (with_op) sb(b, "%d, ", (int)n->o.op);
        sb(b, "LBn%d, LBn%d", a, d);
    } else {
        if ((s = emit_array(c, n->o.k, n->args, 'a', id))) return s;
        if ((row->flags & LB__R_BOUNDING) && (s = emit_array(c, n->o.k, n->bounds, 'c', id)))
            return s;
        sb(b, "#declare %s%d = %s(", name, id, macro);
        if (with_op) sb(b, "%d, ", (int)n->o.op);
        sb(b, "LBa%d", id);
        if (row->flags & LB__R_BOUNDING) sb(b, ", LBc%d", id);
    }
    emit_params(b, row, n);
    sb(b, ")\n");
    return LB_OK;
}

/* an operator written out in SDL (min, max, complement, level, a
 * transformed ref) */
static lb_status emit_inline(pctx *c, const lb__family_row *row, const lb__node *n, int id,
                             const char *name) {
    sbuf *b = c->b;
    lb_status s;
    const int zero = c->sc->convention == LB_CONVENTION_ZERO;
    int a;
    if (row->pov_form == LB__POV_SELECT) {
        int *ids;
        if ((s = emit_list(c, n->o.k, n->args, &ids))) return s;
        sb(b, "#declare %s%d = function(x, y, z) { %s(", name, id, row->pov[0]);
        for (size_t i = 0; i < n->o.k; ++i) sb(b, "%sLBn%d(x, y, z)", i ? ", " : "", ids[i]);
        /* POV-Ray's min and max take two or more */
        sb(b, "%s) }\n", n->o.k > 1 ? "" : row->select > 0 ? ", 1e300" : ", -1e300");
        free(ids);
        return LB_OK;
    }
    if ((s = lb__pov_emit(c, n->args[0], &a))) return s;
    if (row->pov_form == LB__POV_GROUP)
        sb(b, "#declare %s%d = LBn%d;\n", name, id, a);
    else if (row->pov_form == LB__POV_COMPLEMENT && zero)
        sb(b, "#declare %s%d = function(x, y, z) { -LBn%d(x, y, z) }\n", name, id, a);
    else if (row->pov_form == LB__POV_COMPLEMENT)
        sb(b, "#declare %s%d = function(x, y, z) { max(0, 1 - LBn%d(x, y, z)) }\n", name, id, a);
    else if (zero)
        sb(b, "#declare %s%d = function(x, y, z) { LBn%d(x, y, z) - %.17g }\n", name, id, a,
           n->o.shape);
    else
        sb(b, "#declare %s%d = function(x, y, z) { max(0, LBn%d(x, y, z) - %.17g) }\n", name, id, a,
           n->o.shape - 0.5);
    return LB_OK;
}

/* bulge elimination: the include's LB_Bulge over the family's operator */
static lb_status emit_bulge(pctx *c, const lb__family_row *row, const lb__node *n, int id,
                            const char *name) {
    int a, d;
    lb_status s;
    if ((s = lb__pov_emit(c, n->args[0], &a)) || (s = lb__pov_emit(c, n->args[1], &d))) return s;
    const lb_bulge_params *bp = &n->o.bp;
    sb(c->b,
       "#declare %s%d = LB_Bulge(%d, %d, LBn%d, LBn%d, array[2] {%.17g, %.17g}, array[2] "
       "{%.17g, %.17g}, %.17g, array[2] {%.17g, %.17g}, %u, %.17g, %.17g)\n",
       name, id, row->bulge_family, (int)n->o.op, a, d, bp->r[0], bp->r[1], bp->p[0], bp->p[1],
       bp->conic_p, bp->m[0], bp->m[1], bp->flags, bp->omega, c->eps);
    return LB_OK;
}

static lb_status emit_node(pctx *c, const lb__node *n, int id) {
    sbuf *b = c->b;
    const char *name = n->has_transform ? "LBl" : "LBn";
    const lb__family_row *row = lb__family_info(n->o.family);
    /* LB_Displacement takes any k (past 16 it re-evaluates its arguments per
     * step); the LB__R_POV16 rows are limited to the include's 16 */
    if ((row->flags & LB__R_POV16) && n->o.k > LB_POV_MAX_ARITY)
        return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %s: a %s blend of %zu arguments; allowed in POV-Ray: at most %d "
                        "(the include's limit; POV-Ray functions take at most 56 parameters)",
                        FN, n->o.path, n->type, n->o.k, LB_POV_MAX_ARITY);
    if (n->o.k > LB_MAX_ARITY)
        return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %s: a %s node of %zu arguments; allowed in POV-Ray: at most %d (the "
                        "include's functions run every argument at every point); mesh the scene "
                        "instead (blendtool mesh)",
                        FN, n->o.path, n->type, n->o.k, LB_MAX_ARITY);
    lb_status s = LB_OK;
    if (n->o.family == LB__F_PRIMITIVE) {
        emit_primitive(b, n, id, name);
    } else if (row->pov_form == LB__POV_LOCAL) {
        int a, d;
        if ((s = lb__pov_emit(c, n->args[0], &a)) || (s = lb__pov_emit(c, n->args[1], &d)))
            return s;
        if ((s = lb__pov_local(c, n, id, name, a, d))) return s;
    } else if (n->o.bulge) {
        if ((s = emit_bulge(c, row, n, id, name))) return s;
    } else if (row->pov_form == LB__POV_MACRO) {
        if ((s = emit_macro(c, row, n, id, name))) return s;
    } else if ((s = emit_inline(c, row, n, id, name))) {
        return s;
    }
    if (n->has_transform) {
        sb(b, "#declare LBn%d = function(x, y, z) { LBl%d(", id, id);
        affine_args(b, n->to_local);
        sb(b, ") }\n");
    }
    return LB_OK;
}
