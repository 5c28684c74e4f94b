/* The POV-Ray writer's local_union: its blending volumes as data, the
 * distance to the curves unrolled over the segment hierarchy. */
#include "pov_internal.h"

/* The blending volumes as data, distances unrolled.
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

lb_status lb__pov_local(pctx *c, const lb__node *n, int id, const char *name, int a, int d) {
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
                        FN, n->o.path);
    const struct lb__curves *C = ins ? ins->curves : NULL;
    if ((lb__op_flags(&n->o) & LB__R_CURVES))
        sb(b, "// %s: local union, %zu blending volume%s\n", n->o.path[0] ? n->o.path : "root",
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
                            n->o.path);
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
