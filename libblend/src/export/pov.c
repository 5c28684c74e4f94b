/* A scene as a POV-Ray 3.7 file (pov.h): the node DAG as #declare'd
 * functions built with povray_include/libblend.inc, one isosurface, camera,
 * lights and material. */
#define _POSIX_C_SOURCE 200809L
#include "../evaluation/tape.h"
#include "libblend/output.h"

#include <libblend/mesh.h>
#include <libblend/pov.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const char FN[] = "lb_scene_write_pov";

typedef struct sbuf {
    char *s;
    size_t n, cap;
    int oom;
} sbuf;

static void sb(sbuf *b, const char *fmt, ...) {
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int w = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (w < 0) {
            b->oom = 1;
            return;
        }
        if (b->s && b->n + (size_t)w < b->cap) {
            b->n += (size_t)w;
            return;
        }
        size_t nc = b->cap ? 2 * b->cap : 65536;
        while (nc < b->n + (size_t)w + 1) nc *= 2;
        char *q = realloc(b->s, nc);
        if (!q) {
            b->oom = 1;
            return;
        }
        b->s = q;
        b->cap = nc;
    }
}

/* user text in a comment: printable ASCII only */
static void sb_comment(sbuf *b, const char *label, const char *text) {
    if (!text || !*text) return;
    sb(b, "// %s: ", label);
    for (const char *c = text; *c && b->n < ((size_t)1 << 30); ++c)
        sb(b, "%c", *c >= 32 && *c < 127 ? *c : ' ');
    sb(b, "\n");
}

typedef struct pctx {
    sbuf *b;
    const lb_scene *sc;
    const lb__node **done;
    int *ids;
    size_t ndone, cap;
    int next;
    double eps; /* central-difference step of the bulge macros */
    const lb_evaluator *ev;
    lb__affine A;            /* world -> the parent frame of the node being written */
    lb__affine *doneA;       /* the frame each written node was written for */
    const lb__node **lnodes; /* nodes known to hold a local_union (or not: lflag) */
    int *lflag;
    size_t nl, lcap;
    lb_error *err;
    int ntex; /* material textures written (tex) */
} pctx;

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

static void arr(sbuf *b, size_t k, const double *v, double fallback) {
    sb(b, "array[%zu] {", k);
    for (size_t i = 0; i < k; ++i) sb(b, "%s%.17g", i ? ", " : "", v ? v[i] : fallback);
    sb(b, "}");
}

static lb_status emit(pctx *c, const lb__node *n, int *out);

/* The k nodes args written, their function numbers into *ids (the caller
 * frees it; NULL on failure). */
static lb_status emit_list(pctx *c, size_t k, lb__node *const *args, int **ids) {
    *ids = malloc(k * sizeof **ids);
    if (!*ids) return lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    for (size_t i = 0; i < k; ++i) {
        const lb_status s = emit(c, args[i], &(*ids)[i]);
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

/* ---- local_union: the blending volumes as data, distances unrolled ----
 *
 * Each component's blending volume becomes a tree of functions mirroring
 * the evaluator's hierarchy of segment boxes: a node returns
 * a = distance / R clamped at 1, and skips its subtree (select is lazy in
 * POV-Ray) when its box is R or farther from the point. The node's value
 * then picks the component with the smallest a, as the evaluator does. */

/* does the subtree under node i hold a segment of component k? */
static int bvh_has(const struct lb__curves *C, uint32_t i, size_t k) {
    const bvh_node *N = &C->bvh[i];
    if (!N->leaf) return bvh_has(C, N->left, k) || bvh_has(C, N->right, k);
    for (uint32_t j = 0; j < N->right; ++j)
        if (C->segc[N->left + j] == k) return 1;
    return 0;
}

/* declares the function of node i for component k; *fn receives its number */
static void bvh_emit(pctx *c, const struct lb__curves *C, uint32_t i, size_t k, int id, int *next,
                     int *fn) {
    const bvh_node *N = &C->bvh[i];
    const double R = C->comp[k].R;
    sbuf *b = c->b;
    if (!N->leaf) {
        const int l = bvh_has(C, N->left, k), r = bvh_has(C, N->right, k);
        int fl = -1, fr = -1;
        if (l) bvh_emit(c, C, N->left, k, id, next, &fl);
        if (r) bvh_emit(c, C, N->right, k, id, next, &fr);
        if (!l || !r) { /* one side only: its function is this node's */
            *fn = l ? fl : fr;
            return;
        }
        *fn = (*next)++;
        sb(b,
           "#declare LBv%d_%d = function(x, y, z) { select(lb_box2(x, y, z, %.17g, %.17g, %.17g, "
           "%.17g, %.17g, %.17g) - %.17g, min(LBv%d_%d(x, y, z), LBv%d_%d(x, y, z)), 1) }\n",
           id, *fn, N->lo[0], N->lo[1], N->lo[2], N->hi[0], N->hi[1], N->hi[2], R * R, id, fl, id,
           fr);
        return;
    }
    *fn = (*next)++;
    sb(b,
       "#declare LBv%d_%d = function(x, y, z) { select(lb_box2(x, y, z, %.17g, %.17g, %.17g, "
       "%.17g, %.17g, %.17g) - %.17g, min(1, sqrt(min(1e300",
       id, *fn, N->lo[0], N->lo[1], N->lo[2], N->hi[0], N->hi[1], N->hi[2], R * R);
    for (uint32_t j = 0; j < N->right; ++j) {
        const uint32_t sg = N->left + j;
        if (C->segc[sg] != k) continue;
        const double *pa = C->pts + 3 * C->seg[2 * sg], *pb = C->pts + 3 * C->seg[2 * sg + 1];
        const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], dz = pb[2] - pa[2];
        const double ll = dx * dx + dy * dy + dz * dz;
        sb(b, ", lb_seg2(x, y, z, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g)", pa[0], pa[1],
           pa[2], dx, dy, dz, ll > 0.0 ? 1.0 / ll : 0.0);
    }
    sb(b, ")) / %.17g), 1) }\n", R);
}

/* the inverse of y = M x + t */
static int affine_invert(const lb__affine *A, lb__affine *I) {
    const double *m = A->M;
    const double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8],
                 c02 = m[3] * m[7] - m[4] * m[6];
    const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
    if (!(fabs(det) > 0.0)) return -1;
    const double id = 1.0 / det;
    double *o = I->M;
    o[0] = c00 * id;
    o[1] = (m[2] * m[7] - m[1] * m[8]) * id;
    o[2] = (m[1] * m[5] - m[2] * m[4]) * id;
    o[3] = c01 * id;
    o[4] = (m[0] * m[8] - m[2] * m[6]) * id;
    o[5] = (m[2] * m[3] - m[0] * m[5]) * id;
    o[6] = c02 * id;
    o[7] = (m[1] * m[6] - m[0] * m[7]) * id;
    o[8] = (m[0] * m[4] - m[1] * m[3]) * id;
    for (int r = 0; r < 3; ++r)
        I->t[r] = -(o[3 * r] * A->t[0] + o[3 * r + 1] * A->t[1] + o[3 * r + 2] * A->t[2]);
    return 0;
}

static lb_status emit_local(pctx *c, const lb__node *n, int id, const char *name, int a, int d) {
    sbuf *b = c->b;
    const int zero = c->sc->convention == LB_CONVENTION_ZERO;
    const double S = n->o.lp.zero_scale, *al = n->o.lp.alpha;
    char in1[128], in2[128];
    if (zero) {
        snprintf(in1, sizeof in1, "0.5 * (1 - LBn%d(x, y, z) / %.17g)", a, S);
        snprintf(in2, sizeof in2, "0.5 * (1 - LBn%d(x, y, z) / %.17g)", d, S);
    } else {
        snprintf(in1, sizeof in1, "LBn%d(x, y, z)", a);
        snprintf(in2, sizeof in2, "LBn%d(x, y, z)", d);
    }
    /* this use's instruction: the node in this world frame */
    const lb__instr *ins = NULL;
    for (size_t i = 0; (lb__op_flags(&n->o) & LB__R_CURVES) && c->ev && i < c->ev->n && !ins; ++i) {
        const lb__instr *q = &c->ev->ins[i];
        if (q->code == LB__I_OP && q->node == n && memcmp(&q->A, &c->A, sizeof c->A) == 0) ins = q;
    }
    if ((lb__op_flags(&n->o) & LB__R_CURVES) && !ins)
        return lb__fail(c->err, LB_ERR_INTERNAL,
                        "%s: %s: the evaluator has no instruction for this "
                        "use of the local union (was ev compiled from this scene?)",
                        FN, n->path);
    const struct lb__curves *C = ins ? ins->curves : NULL;
    if ((lb__op_flags(&n->o) & LB__R_CURVES))
        sb(b, "// %s: local union, %zu blending volume%s\n", n->path[0] ? n->path : "root",
           C ? C->ncomp : 0, C && C->ncomp == 1 ? "" : "s");
    if (!C || !C->nseg) { /* no intersection: the clean union everywhere */
        sb(b,
           "#declare LBt%d = function(x, y, z, lbLg1, lbLg2) { lb_clean_uc(lbLg1, lbLg2, 0.5, "
           "%.17g, %.17g) }\n",
           id, al[0], al[1]);
    } else {
        lb__affine W; /* node frame -> world, where the curves live */
        if (affine_invert(&ins->A, &W))
            return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT, "%s: %s: a singular transform", FN,
                            n->path);
        const int ident = lb__affine_is_identity(&W);
        const size_t K = C->ncomp;
        int next = 0;
        sb(b,
           "#declare LBk%d_%zu = function(x, y, z, lbLg1, lbLg2, lbLa, lbLp, lbLq, lbLuc) { "
           "lb_local_at(lbLg1, lbLg2, lbLa, lbLp, lbLq, %.17g, lbLuc) }\n",
           id, K, n->o.lp.exponent);
        for (size_t k = K; k-- > 0;) {
            int root = -1;
            if (bvh_has(C, 0, k)) bvh_emit(c, C, 0, k, id, &next, &root);
            char dist[1024];
            if (root < 0)
                snprintf(dist, sizeof dist, "1");
            else if (ident)
                snprintf(dist, sizeof dist, "LBv%d_%d(x, y, z)", id, root);
            else {
                const double *M = W.M, *t = W.t;
                snprintf(dist, sizeof dist,
                         "LBv%d_%d(%.17g * x + %.17g * y + %.17g * z + %.17g, %.17g * x + %.17g * "
                         "y + %.17g * z + %.17g, %.17g * x + %.17g * y + %.17g * z + %.17g)",
                         id, root, M[0], M[1], M[2], t[0], M[3], M[4], M[5], t[1], M[6], M[7], M[8],
                         t[2]);
            }
            const lb__component *P = &C->comp[k];
            sb(b,
               "#declare LBh%d_%zu = function(x, y, z, lbLg1, lbLg2, lbLa, lbLp, lbLq, lbLuc, "
               "lbLc) { LBk%d_%zu(x, y, z, lbLg1, lbLg2, min(lbLc, lbLa), select(lbLc - lbLa, "
               "%.17g, lbLp), select(lbLc - lbLa, %.17g, lbLq), lbLuc) }\n"
               "#declare LBk%d_%zu = function(x, y, z, lbLg1, lbLg2, lbLa, lbLp, lbLq, lbLuc) { "
               "LBh%d_%zu(x, y, z, lbLg1, lbLg2, lbLa, lbLp, lbLq, lbLuc, %s) }\n",
               id, k, id, k + 1, P->p, P->q, id, k, id, k, dist);
        }
        sb(b,
           "#declare LBt%d = function(x, y, z, lbLg1, lbLg2) { LBk%d_0(x, y, z, lbLg1, lbLg2, 1, "
           "0, 0, lb_clean_uc(lbLg1, lbLg2, 0.5, %.17g, %.17g)) }\n",
           id, id, al[0], al[1]);
    }
    if (zero)
        sb(b, "#declare %s%d = function(x, y, z) { %.17g * (1 - LBt%d(x, y, z, %s, %s) / 0.5) }\n",
           name, id, S, id, in1, in2);
    else
        sb(b, "#declare %s%d = function(x, y, z) { max(0, LBt%d(x, y, z, %s, %s)) }\n", name, id,
           id, in1, in2);
    return b->oom ? lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN) : LB_OK;
}

static lb_status emit_node(pctx *c, const lb__node *n, int id);

/* the id n was written under for the world frame F (n's own frame), or -1:
 * a node holding a local_union is written once per frame, others once */
static int written_id(pctx *c, const lb__node *n, const lb__affine *F) {
    const int keyed = has_local(c, n);
    for (size_t i = 0; i < c->ndone; ++i)
        if (c->done[i] == n && (!keyed || memcmp(&c->doneA[i], F, sizeof *F) == 0))
            return c->ids[i];
    return -1;
}

/* the three coordinates y = M x + t as function arguments */
static void affine_args(sbuf *b, const lb__affine *A) {
    for (int r = 0; r < 3; ++r)
        sb(b, "%s%.17g * x + %.17g * y + %.17g * z + %.17g", r ? ", " : "", A->M[3 * r],
           A->M[3 * r + 1], A->M[3 * r + 2], A->t[r]);
}

/* One declaration per node (per node and world frame under a local_union):
 * shared defs stay shared. */
static lb_status emit(pctx *c, const lb__node *n, int *out) {
    const lb__affine saved = c->A;
    lb__affine A = saved;
    if (n->has_transform) lb__affine_compose(&n->to_local, &saved, &A);
    const int known = written_id(c, n, &A);
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
        if ((s = emit(c, n->args[0], &a)) || (s = emit(c, n->args[1], &d))) return s;
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
    if ((s = emit(c, n->args[0], &a))) return s;
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
    if ((s = emit(c, n->args[0], &a)) || (s = emit(c, n->args[1], &d))) return s;
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
                        FN, n->path, n->type, n->o.k, LB_POV_MAX_ARITY);
    if (n->o.k > LB_MAX_ARITY)
        return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %s: a %s node of %zu arguments; allowed in POV-Ray: at most %d (the "
                        "include's functions run every argument at every point); mesh the scene "
                        "instead (blendtool mesh)",
                        FN, n->path, n->type, n->o.k, LB_MAX_ARITY);
    lb_status s = LB_OK;
    if (n->o.family == LB__F_PRIMITIVE) {
        emit_primitive(b, n, id, name);
    } else if (row->pov_form == LB__POV_LOCAL) {
        int a, d;
        if ((s = emit(c, n->args[0], &a)) || (s = emit(c, n->args[1], &d))) return s;
        if ((s = emit_local(c, n, id, name, a, d))) return s;
    } else if (n->o.bulge) {
        if ((s = emit_bulge(c, row, n, id, name))) return s;
    } else if (row->pov_form == LB__POV_MACRO) {
        if ((s = emit_macro(c, row, n, id, name))) return s;
    } else if ((s = emit_inline(c, row, n, id, name))) {
        return s;
    }
    if (n->has_transform) {
        sb(b, "#declare LBn%d = function(x, y, z) { LBl%d(", id, id);
        affine_args(b, &n->to_local);
        sb(b, ") }\n");
    }
    return LB_OK;
}

/* ---- materials: the material rule (scene/material.c) as textures ----
 *
 * A texture per operator where the material is decided: a function
 * pattern that is 0.75 where the first group of arguments (those with the
 * same texture) has the smallest score and 0.25 elsewhere, mapping to that
 * group's texture or to the rest's. The arguments' functions are the ones
 * the field is written with, called in the operator's frame. */

#define LB_POV_MAX_TEXTURES 4096

static void score_expr(pctx *c, const lb__node *n, size_t i, int fid, const lb__affine *A) {
    double sign, off;
    lb__material_score(&n->o, c->sc->convention, i, &sign, &off);
    sb(c->b, "%s%sLBn%d(", off != 0.0 ? "1" : "", sign < 0 ? "-" : off != 0.0 ? "+" : "", fid);
    if (lb__affine_is_identity(A))
        sb(c->b, "x, y, z");
    else
        affine_args(c->b, A);
    sb(c->b, ")");
}

/* the scores of the arguments in group g (their texture is names[g]) */
static void group_expr(pctx *c, const lb__node *n, const int *group, int g, const int *fid,
                       const lb__affine *A) {
    int count = 0;
    for (size_t i = 0; i < n->o.k; ++i) count += group[i] == g;
    if (count > 1) sb(c->b, "min(");
    for (size_t i = 0, w = 0; i < n->o.k; ++i)
        if (group[i] == g) {
            if (w++) sb(c->b, ", ");
            score_expr(c, n, i, fid[i], A);
        }
    if (count > 1) sb(c->b, ")");
}

/* name (at least 24 bytes) receives the texture of n's surface: Ap maps
 * world coordinates to n's parent frame, inh is the inherited material */
static lb_status tex(pctx *c, const lb__node *n, const lb__affine *Ap, size_t inh, char *name) {
    const size_t eff = n->mat ? n->mat : inh;
    if (!n->mat_below) {
        snprintf(name, 24, "LBmat%zu", eff);
        return LB_OK;
    }
    lb__affine A = *Ap;
    if (n->has_transform) lb__affine_compose(&n->to_local, Ap, &A);
    if (n->o.k == 1) return tex(c, n->args[0], &A, eff, name);
    const size_t k = n->o.k;
    char(*sub)[24] = malloc(k * sizeof *sub);
    int *fid = malloc(2 * k * sizeof *fid), *group = fid ? fid + k : NULL;
    lb_status s = sub && fid ? LB_OK : lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    int G = 0;
    for (size_t i = 0; i < k && !s; ++i) {
        if ((s = tex(c, n->args[i], &A, eff, sub[i]))) break;
        lb__affine F = A;
        if (n->args[i]->has_transform) lb__affine_compose(&n->args[i]->to_local, &A, &F);
        fid[i] = written_id(c, n->args[i], &F);
        if (fid[i] < 0) {
            s = lb__fail(c->err, LB_ERR_INTERNAL, "%s: %s: argument %zu was not written", FN,
                         n->path, i);
            break;
        }
        group[i] = -1;
        for (size_t j = 0; j < i && group[i] < 0; ++j)
            if (strcmp(sub[j], sub[i]) == 0) group[i] = group[j];
        if (group[i] < 0) group[i] = G++;
    }
    if (!s && G == 1) memcpy(name, sub[0], 24);
    /* the chain: group g against the groups after it, from the last pair up */
    char rest[24] = "";
    for (int g = G - 2; g >= 0 && !s; --g) {
        if (++c->ntex > LB_POV_MAX_TEXTURES) {
            s = lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                         "%s: %s: more than %d material textures (a def with materials used "
                         "under many parents); allowed: at most %d",
                         FN, n->path, LB_POV_MAX_TEXTURES, LB_POV_MAX_TEXTURES);
            break;
        }
        if (g == G - 2)
            for (size_t i = 0; i < k; ++i)
                if (group[i] == G - 1) memcpy(rest, sub[i], 24);
        const char *mine = NULL;
        for (size_t i = 0; i < k && !mine; ++i)
            if (group[i] == g) mine = sub[i];
        const int t = c->ntex;
        sb(c->b, "#declare LBq%d = function(x, y, z) { select(", t);
        group_expr(c, n, group, g, fid, &A);
        sb(c->b, " - %s", G - g > 2 ? "min(" : "");
        for (int h = g + 1; h < G; ++h) {
            if (h > g + 1) sb(c->b, ", ");
            group_expr(c, n, group, h, fid, &A);
        }
        sb(c->b, "%s, 0.75, 0.25) }\n", G - g > 2 ? ")" : "");
        sb(c->b,
           "#declare LBt%d = texture { function { LBq%d(x, y, z) } texture_map { [0.5 %s] [0.5 "
           "%s] } }\n",
           t, t, rest, mine);
        snprintf(rest, sizeof rest, "LBt%d", t);
    }
    if (!s && G > 1) memcpy(name, rest, 24);
    free(sub);
    free(fid);
    return s;
}

static void material_texture(sbuf *b, const lb_material *m) {
    sb(b,
       "texture { pigment { rgb <%.17g, %.17g, %.17g> } finish { ambient %.17g diffuse %.17g "
       "specular %.17g } }",
       m->color[0], m->color[1], m->color[2], m->ambient, m->diffuse, m->specular);
}

void lb_pov_camera(const lb_scene *scene, double aspect, double loc[3], double at[3], double up[3],
                   double *angle) {
    (void)aspect;
    if (!scene || !loc || !at || !up || !angle) return; /* nothing to write to, or from */
    const lb_render *R = &scene->render;
    *angle = R->has_camera ? R->angle : 40.0;
    memcpy(up, R->up, 3 * sizeof *up);
    if (R->has_camera) {
        memcpy(loc, R->location, 3 * sizeof *loc);
        memcpy(at, R->look_at, 3 * sizeof *at);
        return;
    }
    /* frame the bounding sphere from the front (-y), a little above (+z)
     * and to the right (+x) */
    double diag = 0.0, ctr[3];
    for (int d = 0; d < 3; ++d) {
        diag += (scene->bmax[d] - scene->bmin[d]) * (scene->bmax[d] - scene->bmin[d]);
        ctr[d] = 0.5 * (scene->bmin[d] + scene->bmax[d]);
    }
    diag = sqrt(diag);
    const double dir[3] = {0.45, -1.0, 0.5}, dl = sqrt(0.45 * 0.45 + 1.0 + 0.25);
    const double dist = 0.5 * diag / sin(0.5 * *angle * M_PI / 180.0) * 1.05;
    for (int d = 0; d < 3; ++d) {
        at[d] = ctr[d];
        loc[d] = ctr[d] + dir[d] / dl * dist;
    }
}

/* Every number in b (outside // comments) in its shortest form that reads
 * back as the same double: the writer prints 17 significant digits, which
 * always round-trip, and this keeps the fewest that still do (0.3, not
 * 0.29999999999999999). Identifiers' digits (LBn12) are left alone. */
static void shorten_numbers(sbuf *b) {
    if (!b->s) return;
    size_t r = 0, w = 0;
    while (r < b->n) {
        const char ch = b->s[r];
        if (ch == '/' && r + 1 < b->n && b->s[r + 1] == '/') { /* a comment: copied as is */
            while (r < b->n && b->s[r] != '\n') b->s[w++] = b->s[r++];
            continue;
        }
        const char prev = w ? b->s[w - 1] : ' ';
        const int starts = (ch >= '0' && ch <= '9') ||
                           (ch == '.' && r + 1 < b->n && b->s[r + 1] >= '0' && b->s[r + 1] <= '9');
        const int word = (prev >= 'a' && prev <= 'z') || (prev >= 'A' && prev <= 'Z') ||
                         (prev >= '0' && prev <= '9') || prev == '_' || prev == '.';
        if (!starts || word) {
            b->s[w++] = b->s[r++];
            continue;
        }
        size_t e = r;
        while (e < b->n && b->s[e] >= '0' && b->s[e] <= '9') ++e;
        if (e < b->n && b->s[e] == '.') {
            ++e;
            while (e < b->n && b->s[e] >= '0' && b->s[e] <= '9') ++e;
        }
        if (e + 1 < b->n && (b->s[e] == 'e' || b->s[e] == 'E')) {
            size_t f = e + 1;
            if (f < b->n && (b->s[f] == '+' || b->s[f] == '-')) ++f;
            if (f < b->n && b->s[f] >= '0' && b->s[f] <= '9') {
                while (f < b->n && b->s[f] >= '0' && b->s[f] <= '9') ++f;
                e = f;
            }
        }
        char tok[64], best[64];
        const size_t len = e - r;
        if (len >= sizeof tok) { /* not a number the writer made: copied as is */
            while (r < e) b->s[w++] = b->s[r++];
            continue;
        }
        memcpy(tok, b->s + r, len);
        tok[len] = 0;
        const double v = strtod(tok, NULL);
        size_t blen = len;
        memcpy(best, tok, len + 1);
        for (int p = 1; p <= 17; ++p) {
            char t[64];
            const int n = snprintf(t, sizeof t, "%.*g", p, v);
            if (n > 0 && (size_t)n < blen && strtod(t, NULL) == v) {
                memcpy(best, t, (size_t)n + 1);
                blen = (size_t)n;
                break;
            }
        }
        memcpy(b->s + w, best, blen); /* never longer than what it replaces */
        w += blen;
        r = e;
    }
    b->n = w;
    b->s[w] = 0;
}

/* The floor's height along up: the lowest point of a coarse mesh of the
 * surface (48 cells), or of the bounds when there is no surface. */
/* the largest |grad f| on a grid over the box */
static lb_status max_gradient(const lb_evaluator *ev, const double lo[3], const double hi[3],
                              int threads, double *g, lb_error *err) {
    const size_t N = LB_POV_GRADIENT_SAMPLES, n = N * N * N;
    double *mem = malloc(7 * n * sizeof *mem);
    if (!mem) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    double *x = mem, *y = x + n, *z = y + n, *v = z + n, *gx = v + n, *gy = gx + n, *gz = gy + n;
    for (size_t i = 0; i < n; ++i) {
        const size_t a = i % N, bq = i / N % N, cq = i / N / N;
        x[i] = lo[0] + (hi[0] - lo[0]) * (double)a / (double)(N - 1);
        y[i] = lo[1] + (hi[1] - lo[1]) * (double)bq / (double)(N - 1);
        z[i] = lo[2] + (hi[2] - lo[2]) * (double)cq / (double)(N - 1);
    }
    lb_status s = lb_evaluator_eval(ev, n, x, y, z, v, gx, gy, gz, threads, err);
    /* Only where the surface may be matters: POV-Ray's root search splits an
     * interval of a ray only while the function could reach the threshold
     * in it, so a steep field far from the surface never misleads it. A
     * sample counts when, to first order, the surface lies within two grid
     * diagonals of it: |f - threshold| <= 2 d |grad f|. */
    double d2 = 0.0;
    for (int d = 0; d < 3; ++d)
        d2 += (hi[d] - lo[d]) * (hi[d] - lo[d]) / ((double)(N - 1) * (double)(N - 1));
    const double band = 2.0 * sqrt(d2), level = ev->conv == LB_CONVENTION_SOFT ? 0.5 : 0.0;
    double m = 0.0, mall = 0.0;
    for (size_t i = 0; i < n && !s; ++i) {
        const double l = sqrt(gx[i] * gx[i] + gy[i] * gy[i] + gz[i] * gz[i]);
        if (l > mall) mall = l;
        if (l > m && fabs(v[i] - level) <= band * l) m = l;
    }
    free(mem);
    if (!(m > 0.0)) m = mall; /* no surface seen: the whole box's */
    *g = m * LB_POV_GRADIENT_SAFETY;
    if (!(*g > 0.0)) *g = 1.0;
    return s;
}

/* The whole .pov text into b (freed by the caller). */
static lb_status pov_text(const lb_scene *scene, const lb_evaluator *ev, const lb_pov_options *opt,
                          sbuf *out, double *out_gradient, lb_error *err) {
    lb_pov_options o = {0, 0, 0.0, 0.0, 0};
    if (opt) o = *opt;
    if (!scene->has_bounds)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the scene has no bounds; allowed: a scene with \"bounds\" (the "
                        "isosurface's contained_by box)",
                        FN);
    const double *lo = scene->bmin, *hi = scene->bmax;
    double diag = 0.0;
    for (int d = 0; d < 3; ++d) diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    diag = sqrt(diag);
    sbuf b = {NULL, 0, 0, 0};
    pctx c = {&b,   scene, NULL, NULL, 0, 0,   0, 1e-5 * diag, ev, {{0}, {0}},
              NULL, NULL,  NULL, 0,    0, err, 0};
    lb__affine_identity(&c.A);
    sb(&b, "// written by libblend %d.%d.%d (blendtool pov)\n", LB_VERSION_MAJOR, LB_VERSION_MINOR,
       LB_VERSION_PATCH);
    sb_comment(&b, "scene", scene->name);
    sb(&b, "#version 3.7;\n#include \"libblend.inc\"\n\n");
    int root = 0;
    lb_status s = emit(&c, scene->root, &root);
    double g = o.max_gradient;
    if (!s) {
        sb(&b, "#declare LB_Field = LBn%d;\n", root);
        if (!(g > 0.0)) s = max_gradient(ev, lo, hi, o.threads, &g, err);
    }
    if (!s && !o.include_only) {
        const lb_render *R = &scene->render;
        const double aspect = o.aspect > 0.0 ? o.aspect : 4.0 / 3.0;
        double loc[3], at[3], up[3], angle;
        lb_pov_camera(scene, aspect, loc, at, up, &angle);
        /* the camera's distance to its target (the key light's size) */
        const double F[3] = {at[0] - loc[0], at[1] - loc[1], at[2] - loc[2]};
        const double L = sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2]);
        const double *bg = R->background;
        /* POV-Ray is left-handed: a negated right vector makes the image the
         * right-handed view; sky is the scene's up (the look_at keeps both) */
        sb(&b,
           "\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb <%.17g, %.17g, %.17g> }\n"
           "camera { perspective location <%.17g, %.17g, %.17g> sky <%.17g, %.17g, %.17g> up y "
           "right -x * %.17g angle %.17g look_at <%.17g, %.17g, %.17g> }\n",
           o.silhouette ? 0.0 : bg[0], o.silhouette ? 0.0 : bg[1], o.silhouette ? 0.0 : bg[2],
           loc[0], loc[1], loc[2], up[0], up[1], up[2], aspect, angle, at[0], at[1], at[2]);
        if (o.silhouette) {
            /* no lights: the object is its ambient white */
        } else if (R->light_count) {
            for (size_t i = 0; i < R->light_count; ++i)
                sb(&b, "light_source { <%.17g, %.17g, %.17g> rgb <%.17g, %.17g, %.17g> }\n",
                   R->lights[i].location[0], R->lights[i].location[1], R->lights[i].location[2],
                   R->lights[i].color[0], R->lights[i].color[1], R->lights[i].color[2]);
        } else {
            /* three-point lighting around the camera: a key light above and
             * to the left with soft shadows, a dim fill from the right and a
             * rim light from behind, both without shadows. The key's area
             * light is 3 x 3, not adaptive: every shadow sample is an
             * isosurface intersection, and a soft-object scene took 7x a
             * hard shadow's time at 5 x 5 adaptive (4x at 3 x 3). */
            lb_render_light key[3];
            lb_render_three_point(loc, at, up, key);
            for (int k = 0; k < 3; ++k) {
                const double *X = key[k].location;
                if (k == 0)
                    sb(&b,
                       "light_source { <%.17g, %.17g, %.17g> rgb %.17g area_light <%.17g, 0, 0>, "
                       "<0, %.17g, 0>, 3, 3 adaptive 0 jitter circular orient }\n",
                       X[0], X[1], X[2], key[k].color[0], 0.2 * L, 0.2 * L);
                else
                    sb(&b, "light_source { <%.17g, %.17g, %.17g> rgb %.17g shadowless }\n", X[0],
                       X[1], X[2], key[k].color[0]);
            }
        }
        if (R->floor && !o.silhouette) {
            double h = 0.0;
            lb_render_floor_height(ev, scene->bmin, scene->bmax, up, o.threads, &h, NULL);
            sb(&b,
               "plane { <%.17g, %.17g, %.17g>, %.17g pigment { rgb <%.17g, %.17g, %.17g> } "
               "finish { ambient 0.15 diffuse 0.75 } }\n",
               up[0], up[1], up[2], h, R->floor_color[0], R->floor_color[1], R->floor_color[2]);
        }
        const int soft = scene->convention == LB_CONVENTION_SOFT;
        char texname[24] = "";
        if (!o.silhouette && lb_scene_material_count(scene) > 1) {
            sb(&b, "\n");
            for (size_t i = 0; i < lb_scene_material_count(scene); ++i) {
                lb_material m;
                lb_scene_material(scene, i, &m);
                sb(&b, "#declare LBmat%zu = ", i);
                material_texture(&b, &m);
                sb(&b, "\n");
            }
            lb__affine id;
            lb__affine_identity(&id);
            s = tex(&c, scene->root, &id, 0, texname);
        }
        if (s) goto out;
        sb(&b,
           "isosurface {\n  function { %sLB_Field(x, y, z) }\n  threshold %s\n"
           "  contained_by { box { <%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g> } }\n"
           "  max_gradient %.17g\n  accuracy %.17g\n  ",
           soft ? "-" : "", soft ? "-0.5" : "0", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], g,
           1e-4 * diag);
        if (texname[0]) {
            sb(&b, "texture { %s }", texname);
        } else {
            /* one material (the silhouette: its ambient white) */
            const lb_material white = {{1.0, 1.0, 1.0}, 1.0, 0.0, 0.0};
            lb_material m0;
            lb_scene_material(scene, 0, &m0);
            material_texture(&b, o.silhouette ? &white : &m0);
        }
        sb(&b, "\n}\n");
    }
out:
    free(c.done);
    free(c.ids);
    free(c.doneA);
    free(c.lnodes);
    free(c.lflag);
    if (!s && b.oom) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    if (s) {
        free(b.s);
        return s;
    }
    shorten_numbers(&b);
    *out = b;
    if (out_gradient) *out_gradient = g;
    return LB_OK;
}

lb_status lb_scene_write_pov_stream(const lb_scene *scene, const lb_evaluator *ev,
                                    const lb_pov_options *opt, FILE *stream, double *out_gradient,
                                    lb_error *err) {
    if (!scene || !ev || !stream)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_scene_write_pov_stream: scene, ev and stream must be given");
    sbuf b = {NULL, 0, 0, 0};
    double g = 0.0;
    lb_status s = pov_text(scene, ev, opt, &b, &g, err);
    if (s) return s;
    if (fwrite(b.s, 1, b.n, stream) != b.n || fflush(stream) != 0)
        s = lb__fail(err, LB_ERR_IO, "lb_scene_write_pov_stream: writing failed (%s)",
                     strerror(errno));
    free(b.s);
    if (!s && out_gradient) *out_gradient = g;
    return s;
}

lb_status lb_scene_write_pov(const lb_scene *scene, const lb_evaluator *ev,
                             const lb_pov_options *opt, const char *path, double *out_gradient,
                             lb_error *err) {
    if (!scene || !ev || !path || !*path)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: scene, ev and path must be given", FN);
    sbuf b = {NULL, 0, 0, 0};
    double g = 0.0;
    lb_status s = pov_text(scene, ev, opt, &b, &g, err);
    if (!s) s = lb_output_write_file(path, b.s, b.n, err);
    free(b.s);
    if (!s && out_gradient) *out_gradient = g;
    return s;
}
