/* Local blending (Bernhardt, Barthe, Cani, Wyvill 2010): a local_union
 * blends its two children only inside blending volumes around the curves
 * where their surfaces intersect; everywhere else it is the clean union UC.
 *
 * At compile time (lb__local_prepare, per instruction, in world space):
 * 1. cells: an octree over the scene's bounds, 64 cells along the longest
 *    side, keeps the cells where both children's interval bounds contain
 *    the iso value C (lb__bounds_pass_list over each child's cone);
 * 2. segments: each kept cell is split into the six Kuhn tetrahedra the
 *    mesher uses; on a tetrahedron both children are linear, so their
 *    surfaces meet in a segment whose ends lie on two of its faces. A face's
 *    point is computed from the face's three nodes in a canonical order, so
 *    the tetrahedra sharing a face share the point exactly;
 * 3. chains: segments sharing a face point are chained into polylines, one
 *    per intersection component (closed, or open where the region cuts);
 * 4. refinement: every vertex is moved onto both surfaces by the
 *    simultaneous Newton step p += a grad g1 + b grad g2 (the 2x2 Gram
 *    system) until |g_i - C| / |grad g_i| <= 1e-10 of the scene size; a
 *    segment whose projected midpoint strays more than 1e-5 of the scene
 *    size from the chord gets that point inserted (4 passes at most);
 * 5. parameters per component: feature sizes d_i (user, else half the
 *    local radius of curvature 2 / |div n_i| averaged over the vertices,
 *    capped at the scene size), limits v1 = g2(P - d1 n2), v2 = g1(P - d2 n1)
 *    averaged (user values override), the support R (user; else
 *    support_factor x the curve's diameter, or 2 min(d1, d2));
 * 6. a bounding-volume hierarchy over all segments.
 * At a point: v = W(d / R) (Wyvill's kernel of the distance to the nearest
 * curve, the component with the smallest d / R), UC and UB = Barthe's blend
 * with q = v1 / C, p = v2 / C, and U = (1 - v^n) UC + v^n UB. Outside every
 * volume U = UC exactly.
 *
 * This file finds the curves and the volumes' parameters (steps 1-5) and
 * describes them; local_bvh.c builds and queries step 6's hierarchy,
 * local_eval.c evaluates at points, local_bounds.c over boxes. */
#include "local_internal.h"
#include "records.h"
#include "../common/boxtree.h"
#include "../common/kuhn.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GRID 64           /* cells along the longest side of the region */
#define REFINE_STEPS 40   /* Newton steps at most per vertex */
#define ON_SURFACE 1e-10  /* of the scene size */
#define MIDPOINT_TOL 1e-5 /* of the scene size */
#define SUBDIVIDE_PASSES 4
/* a cone shorter than this runs as it stands (reducing costs an interval
 * pass over it per chunk) */
#define REDUCE_FROM 24
#define REDUCE_GROUP 16 /* chunks per group (children_at) */
/* octree levels with cones of their own (a 64-cell grid halves its longest
 * side 18 times) */
#define OCTREE_DEPTH 24

void lb__curves_free(struct lb__curves *c) {
    if (!c) return;
    free(c->pts);
    free(c->comp);
    free(c->seg);
    free(c->segc);
    free(c->bvh);
    free(c);
}

/* ---- child evaluation at compile time ---- */

typedef struct child_eval {
    const lb_evaluator *ev;
    const lb__instr *in;
    double *regs;
    lb_error *err;
    double wcone[2];  /* instruction runs of each child's cone per point */
    double *work;     /* the evaluator's compile cost so far */
    lb__cone fold[2]; /* each child's cone reduced over the box (fc, fr) of the
                         fold's kept cells (zeroed, so not reduced, until
                         fold_cones runs) */
    double fc[3], fr[3];
    int gfold[2];                  /* the current group's cone was reduced from fold[] */
    lb__cone grp[2];               /* each child's cone reduced over the current group of chunks */
    lb__cone sub[2];               /* and over the current chunk */
    lb__cone oc[2 * OCTREE_DEPTH]; /* each child's cone reduced over the octree's cells */
    int noreduce[2];               /* the child's cone holds bulge elimination */
    lb__iv *ivs;                   /* interval registers of a reduced cone */
    size_t nivs;
    double *subregs; /* their register file */
    size_t nsubregs;
} child_eval;

/* The refusal once the compile cost passes its limit (scene.h). */
static lb_status over_cost(const lb__instr *in, lb_error *err) {
    return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                    "%s: finding the local unions' intersection curves takes more than %.3g "
                    "instruction runs (the compile-cost limit); allowed: fewer children within "
                    "reach of each other under one local union (each fold evaluates every "
                    "earlier child whose field reaches its curves: a smaller zero_scale, or "
                    "kernels of finite support, keep them apart), or clean_union or min where "
                    "no local blend is needed",
                    in->op->path, LB_SCENE_MAX_COMPILE_COST);
}

/* Counts runs of the children's cones, and refuses once the compile cost
 * passes its limit: no valid scene may make compiling explode. */
static lb_status charge(child_eval *E, double runs) {
    *E->work += runs;
    return *E->work <= LB_SCENE_MAX_COMPILE_COST ? LB_OK : over_cost(E->in, E->err);
}

/* instruction runs of one evaluation of a cone */
static double cone_weight(const lb_evaluator *ev, const uint32_t *cone, size_t n) {
    double w = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const lb__instr *q = &ev->ins[cone[i]];
        w +=
            q->code == LB__I_OP && (lb__op_flags(q->op) & LB__R_CURVES) ? LB_LOCAL_RUN_WEIGHT : 1.0;
    }
    return w;
}

/* is the box (c, r) inside the box (C, R)? */
static int box_inside(const double c[3], const double r[3], const double C[3], const double R[3]) {
    for (int d = 0; d < 3; ++d)
        if (!(c[d] - r[d] >= C[d] - R[d] && c[d] + r[d] <= C[d] + R[d])) return 0;
    return 1;
}

/* The tape that computes child a at a chunk of points in box (bc, br): the
 * run, the register of the child's value and the charge per point. A long
 * cone is reduced over the chunk's group of chunks (box (gc, gr), at its
 * first chunk: new_group) and then over the chunk (cone.c): a group's cone
 * that is short already runs as it is; one that kept nearly everything is
 * reduced per chunk from the whole cone. A local union whose blending
 * volumes reach the chunk queries its curves at every point: that costs
 * LB_LOCAL_NEAR_WEIGHT runs more. */
static lb_status chunk_tape(child_eval *E, int a, int new_group, const double gc[3],
                            const double gr[3], const double bc[3], const double br[3],
                            const lb_evaluator **run, uint32_t *reg, double *weight) {
    const lb__instr *in = E->in;
    const uint32_t *cone = in->cone + (a ? in->ncone[0] : 0);
    const lb_evaluator *run_ev = E->ev;
    uint32_t r = in->src[a];
    double w = E->wcone[a];
    lb_status st;
    if (in->ncone[a] >= REDUCE_FROM) {
        lb__cone *Gc = &E->grp[a], *S = &E->sub[a];
        const lb__cone *F = &E->fold[a];
        /* the group's base: the fold's reduced cone when the group's box
         * lies in the fold's box, else the whole cone */
        if (new_group) E->gfold[a] = F->reduced && F->copied && box_inside(gc, gr, E->fc, E->fr);
        const lb_evaluator *bev = E->gfold[a] ? &F->ev : E->ev;
        const uint32_t *blist = E->gfold[a] ? NULL : cone;
        const size_t bn = E->gfold[a] ? F->ev.n : in->ncone[a];
        const double bw = E->gfold[a] ? F->weight : E->wcone[a];
        /* a reduction is an interval pass over what it reduces: charged as
         * one run of that */
        if (new_group &&
            ((st = charge(E, bw)) || (st = lb__cone_reduce(bev, blist, bn, gc, gr, Gc, E->err))))
            return st;
        const int grouped = Gc->reduced && Gc->copied;
        const int chunked = Gc->reduced && (!grouped || Gc->ev.n >= REDUCE_FROM);
        if (chunked && ((st = charge(E, grouped ? Gc->weight : bw)) ||
                        (st = grouped ? lb__cone_reduce(&Gc->ev, NULL, Gc->ev.n, bc, br, S, E->err)
                                      : lb__cone_reduce(bev, blist, bn, bc, br, S, E->err))))
            return st;
        if (grouped && (!chunked || !S->copied)) S = Gc;
        if (Gc->reduced && S->reduced && S->copied) {
            run_ev = &S->ev;
            r = S->out;
            w = S->weight;
        } else if (E->gfold[a]) {
            run_ev = &F->ev;
            r = F->out;
            w = F->weight;
        }
    }
    const size_t nr = run_ev != E->ev ? run_ev->n : in->ncone[a];
    size_t near = 0;
    for (size_t q = 0; q < nr; ++q) {
        const lb__instr *c = run_ev != E->ev ? &run_ev->ins[q] : &E->ev->ins[cone[q]];
        near += c->code == LB__I_OP && (lb__op_flags(c->op) & LB__R_CURVES) &&
                lb__local_reaches(c->curves, bc, br);
    }
    *run = run_ev;
    *reg = r;
    *weight = w + (double)near * LB_LOCAL_NEAR_WEIGHT;
    return LB_OK;
}

/* g (soft form) of both children and their gradients at n points. A long
 * cone is reduced over each chunk's bounding box (cone.c): the points come
 * in spatial order (cell by cell, or along a curve), so a chunk's box is
 * small and most links of a fold's chain drop out. */
static lb_status children_at(child_eval *E, size_t n, const double *x, const double *y,
                             const double *z, double *g, double *grad) {
    const lb__instr *in = E->in;
    double gc[3] = {0.0, 0.0, 0.0}, gr[3] = {0.0, 0.0, 0.0};
    for (size_t s = 0; s < n; s += LB__CHUNK) {
        const size_t m = n - s < LB__CHUNK ? n - s : LB__CHUNK;
        double bc[3], br[3];
        /* a group of REDUCE_GROUP chunks is reduced from the whole cone,
         * each chunk from its group's cone (chunk_tape) */
        const int new_group = s % (REDUCE_GROUP * LB__CHUNK) == 0;
        if (new_group) {
            const size_t gm = n - s < REDUCE_GROUP * LB__CHUNK ? n - s : REDUCE_GROUP * LB__CHUNK;
            lb__points_box(x + s, y + s, z + s, gm, gc, gr);
        }
        lb__points_box(x + s, y + s, z + s, m, bc, br);
        for (int a = 0; a < 2; ++a) {
            const uint32_t *cone = in->cone + (a ? in->ncone[0] : 0);
            const lb_evaluator *run_ev;
            uint32_t r;
            double w;
            lb_status st = chunk_tape(E, a, new_group, gc, gr, bc, br, &run_ev, &r, &w);
            if (st) return st;
            if ((st = charge(E, (double)m * w))) return st;
            if (run_ev != E->ev) {
                if (lb__grow((void **)&E->subregs, &E->nsubregs, lb__regs_len(run_ev),
                             sizeof *E->subregs))
                    return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
                st = lb__tape_run_counted(run_ev, m, x + s, y + s, z + s, E->subregs, NULL, E->err);
            } else {
                st = lb__tape_run_list(E->ev, cone, in->ncone[a], m, x + s, y + s, z + s, E->regs,
                                       E->err);
            }
            if (st) return st;
            double *regs = run_ev != E->ev ? E->subregs : E->regs;
            const double k =
                E->ev->conv == LB_CONVENTION_ZERO ? -LB__LOCAL_ISO / in->op->lp.zero_scale : 1.0;
            for (size_t j = 0; j < m; ++j) {
                const double f = lb__reg(regs, r, 0)[j];
                double fv[2] = {f, f}, gv[2];
                lb__local_in(in->op, E->ev->conv, fv, gv);
                g[2 * (s + j) + a] = gv[0];
                if (grad)
                    for (int d = 0; d < 3; ++d)
                        grad[6 * (s + j) + 3 * a + d] = k * lb__reg(regs, r, 1 + d)[j];
            }
        }
    }
    return LB_OK;
}

/* ---- hash map of 64-bit keys (node ids, face triples) ---- */

typedef struct hmap {
    uint64_t *k1, *k2; /* a face is (k1, k2) = packed sorted node ids */
    uint32_t *val;
    size_t cap, n;
} hmap;

static uint64_t mix64(uint64_t a, uint64_t b) {
    uint64_t h = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull + (a << 6) + (a >> 2));
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    return h ^ (h >> 29);
}

static int hmap_init(hmap *m, size_t want) {
    m->cap = 64;
    while (m->cap < 2 * want) m->cap *= 2;
    m->n = 0;
    m->k1 = malloc(m->cap * sizeof *m->k1);
    m->k2 = malloc(m->cap * sizeof *m->k2);
    m->val = malloc(m->cap * sizeof *m->val);
    if (!m->k1 || !m->k2 || !m->val) return -1;
    for (size_t i = 0; i < m->cap; ++i) m->val[i] = UINT32_MAX;
    return 0;
}

static void hmap_free(hmap *m) {
    free(m->k1);
    free(m->k2);
    free(m->val);
}

/* slot of (a, b): found (val != UINT32_MAX) or empty */
static size_t hmap_slot(const hmap *m, uint64_t a, uint64_t b) {
    size_t i = (size_t)mix64(a, b) & (m->cap - 1);
    while (m->val[i] != UINT32_MAX && (m->k1[i] != a || m->k2[i] != b)) i = (i + 1) & (m->cap - 1);
    return i;
}

/* ---- step 1: cells ---- */

typedef struct grid {
    double origin[3], h;
    uint32_t cells[3];
} grid;

typedef struct cellset {
    uint32_t *c; /* 3 per cell */
    size_t n, cap;
} cellset;

/* The descent's context: what each depth's halves start from. */
#define CELL_DEPTH 64 /* > 3 log2(GRID) + 1 */
typedef struct cell_walk {
    child_eval *E;
    const grid *G;
    lb__iv *R;
    cellset *S;
    const lb__cone *next[CELL_DEPTH][2]; /* each child's cone, reduced over the box at depth */
} cell_walk;

/* Cells where both children can cross C (a visit of lb__box_descend). A
 * long cone is reduced cell by cell (cone.c), each cell's from its
 * parent's (E->oc[depth]), so a cell costs what its parent's reduced cone
 * holds, not the whole cone. */
static lb_status cell_visit(void *ctx, const uint32_t lo[3], const uint32_t hi[3], int depth,
                            int cell, int *split) {
    cell_walk *W = ctx;
    child_eval *E = W->E;
    const grid *G = W->G;
    lb__iv *R = W->R;
    cellset *S = W->S;
    static const lb__cone *const whole[2] = {NULL, NULL};
    if (depth >= CELL_DEPTH)
        return lb__fail(E->err, LB_ERR_INTERNAL, "%s: cell octree deeper than %d", E->in->op->path,
                        CELL_DEPTH);
    const lb__cone *const *cur = depth ? W->next[depth - 1] : whole;
    double bmin[3], bmax[3], bc[3], br[3];
    for (int d = 0; d < 3; ++d) {
        bmin[d] = G->origin[d] + G->h * lo[d];
        bmax[d] = G->origin[d] + G->h * hi[d];
    }
    lb__box_centre(bmin, bmax, bc, br);
    const lb__instr *in = E->in;
    const lb__cone **next = W->next[depth];
    next[0] = cur[0];
    next[1] = cur[1];
    /* the cheaper child first: most cells are pruned by it alone */
    const int first = E->wcone[1] < E->wcone[0];
    for (int t = 0; t < 2; ++t) {
        const int a = t ? 1 - first : first;
        const uint32_t *cone = in->cone + (a ? in->ncone[0] : 0);
        const lb__cone *P = cur[a]; /* NULL: the whole cone */
        lb__iv f;
        lb_status cs;
        const size_t np = P ? P->ev.n : in->ncone[a];
        int done = 0;
        if (np >= REDUCE_FROM && depth < OCTREE_DEPTH && !E->noreduce[a]) {
            lb__cone *C = &E->oc[2 * depth + a];
            if ((cs = charge(E, P ? P->weight : E->wcone[a])) ||
                (cs = lb__cone_reduce(P ? &P->ev : E->ev, P ? NULL : cone, np, bc, br, C, E->err)))
                return cs;
            if (C->reduced) {
                f = C->root;
                if (C->copied) next[a] = C;
                done = 1;
            } else {
                E->noreduce[a] = 1; /* bulge elimination inside: the whole cone from here */
            }
        }
        if (done) {
        } else if (P) { /* short enough: its interval pass as it stands */
            if ((cs = charge(E, P->weight))) return cs;
            if (lb__grow((void **)&E->ivs, &E->nivs, lb__ivs_len(&P->ev), sizeof *E->ivs))
                return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
            lb__bounds_pass(&P->ev, bc, br, E->ivs, NULL);
            f = E->ivs[P->out];
        } else {
            if ((cs = charge(E, E->wcone[a]))) return cs;
            lb__bounds_pass_list(E->ev, cone, in->ncone[a], bc, br, R);
            f = R[in->src[a]];
        }
        double fl[2] = {f.lo, f.hi}, gl[2];
        lb__local_in(in->op, E->ev->conv, fl, gl);
        const double glo = gl[0] < gl[1] ? gl[0] : gl[1], ghi = gl[0] < gl[1] ? gl[1] : gl[0];
        if (!(glo <= LB__LOCAL_ISO && ghi >= LB__LOCAL_ISO)) return LB_OK; /* pruned */
    }
    if (cell) {
        if (lb__grow((void **)&S->c, &S->cap, S->n + 1, 3 * sizeof *S->c))
            return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        memcpy(S->c + 3 * S->n++, lo, 3 * sizeof *lo);
        return LB_OK;
    }
    *split = 1;
    return LB_OK;
}

/* ---- step 2: segments on the Kuhn tetrahedra ---- */

static uint64_t node_id(const grid *G, uint32_t i, uint32_t j, uint32_t k) {
    return (uint64_t)i +
           (uint64_t)(G->cells[0] + 1) * ((uint64_t)j + (uint64_t)(G->cells[1] + 1) * k);
}

static void node_pos(const grid *G, uint64_t id, double p[3]) {
    const uint64_t nx = G->cells[0] + 1, ny = G->cells[1] + 1;
    p[0] = G->origin[0] + G->h * (double)(id % nx);
    p[1] = G->origin[1] + G->h * (double)(id / nx % ny);
    p[2] = G->origin[2] + G->h * (double)(id / nx / ny);
}

typedef struct builder {
    const grid *G;
    hmap nodes;   /* node id -> index into nv (values) */
    double *nval; /* 2 per node: g1 - C, g2 - C */
    hmap faces;   /* face -> index into fpts */
    double *fpts; /* 3 per face point */
    size_t nf, fcap;
    uint32_t *seg; /* 2 face indices per segment */
    size_t ns, scap;
} builder;

static int face_point(builder *B, const uint64_t v[3], uint32_t *out) {
    uint64_t s[3] = {v[0], v[1], v[2]};
    for (int a = 0; a < 2; ++a) /* sort the three ids: the face's canonical order */
        for (int b = 0; b < 2 - a; ++b)
            if (s[b] > s[b + 1]) {
                const uint64_t t = s[b];
                s[b] = s[b + 1];
                s[b + 1] = t;
            }
    /* node ids are below 65^3 < 2^21: three fit in one word */
    const uint64_t k1 = s[0] | s[1] << 21 | s[2] << 42, k2 = 1;
    size_t slot = hmap_slot(&B->faces, k1, k2);
    if (B->faces.val[slot] != UINT32_MAX) {
        *out = B->faces.val[slot];
        return *out != UINT32_MAX - 1;
    }
    double h1[3], h2[3], P[3][3];
    for (int i = 0; i < 3; ++i) {
        const size_t ni = B->nodes.val[hmap_slot(&B->nodes, s[i], 0)];
        h1[i] = B->nval[2 * ni];
        h2[i] = B->nval[2 * ni + 1];
        node_pos(B->G, s[i], P[i]);
    }
    /* barycentric weights where both linear functions vanish: h1 x h2 */
    const double l[3] = {h1[1] * h2[2] - h1[2] * h2[1], h1[2] * h2[0] - h1[0] * h2[2],
                         h1[0] * h2[1] - h1[1] * h2[0]};
    const int pos = l[0] > 0.0 && l[1] > 0.0 && l[2] > 0.0;
    const int neg = l[0] < 0.0 && l[1] < 0.0 && l[2] < 0.0;
    B->faces.k1[slot] = k1;
    B->faces.k2[slot] = k2;
    B->faces.n++;
    if (!pos && !neg) {
        B->faces.val[slot] = UINT32_MAX - 1; /* no point on this face */
        return 0;
    }
    if (lb__grow((void **)&B->fpts, &B->fcap, B->nf + 1, 3 * sizeof *B->fpts)) return -1;
    const double sum = l[0] + l[1] + l[2];
    for (int d = 0; d < 3; ++d)
        B->fpts[3 * B->nf + d] = (l[0] * P[0][d] + l[1] * P[1][d] + l[2] * P[2][d]) / sum;
    B->faces.val[slot] = (uint32_t)B->nf;
    *out = (uint32_t)B->nf++;
    return 1;
}

static int tet_segments(builder *B, const uint64_t corner[8]) {
    static const int FACES[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (int t = 0; t < 6; ++t) {
        uint32_t ends[4];
        int ne = 0;
        for (int f = 0; f < 4; ++f) {
            const uint64_t v[3] = {corner[LB__KUHN[t][FACES[f][0]]],
                                   corner[LB__KUHN[t][FACES[f][1]]],
                                   corner[LB__KUHN[t][FACES[f][2]]]};
            uint32_t idx;
            const int r = face_point(B, v, &idx);
            if (r < 0) return -1;
            if (r) ends[ne++] = idx;
        }
        if (ne != 2) continue; /* 0 generically; 1, 3 or 4 only on degenerate ties */
        if (lb__grow((void **)&B->seg, &B->scap, B->ns + 1, 2 * sizeof *B->seg)) return -1;
        B->seg[2 * B->ns] = ends[0];
        B->seg[2 * B->ns + 1] = ends[1];
        B->ns++;
    }
    return 0;
}

/* ---- step 4: refinement ---- */

static lb_status project(child_eval *E, size_t n, double *p, double size) {
    double *x = malloc(3 * n * sizeof *x), *g = malloc(2 * n * sizeof *g);
    double *gr = malloc(6 * n * sizeof *gr);
    lb_status s = LB_OK;
    if (!x || !g || !gr)
        s = lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
    for (int it = 0; it < REFINE_STEPS && !s; ++it) {
        for (size_t i = 0; i < n; ++i)
            for (int d = 0; d < 3; ++d) x[d * n + i] = p[3 * i + d];
        if ((s = children_at(E, n, x, x + n, x + 2 * n, g, gr))) break;
        int moved = 0;
        for (size_t i = 0; i < n; ++i) {
            const double *a = gr + 6 * i, *b = a + 3;
            const double r1 = LB__LOCAL_ISO - g[2 * i], r2 = LB__LOCAL_ISO - g[2 * i + 1];
            const double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
            const double bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
            const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            if (!(aa > 0.0 && bb > 0.0)) continue;
            if (fabs(r1) <= ON_SURFACE * size * sqrt(aa) &&
                fabs(r2) <= ON_SURFACE * size * sqrt(bb))
                continue;
            const double det = aa * bb - ab * ab;
            if (!(det > 1e-12 * aa * bb)) continue; /* tangent surfaces: leave it */
            const double ca = (r1 * bb - r2 * ab) / det, cb = (r2 * aa - r1 * ab) / det;
            double step = 0.0;
            for (int d = 0; d < 3; ++d) {
                const double dd = ca * a[d] + cb * b[d];
                step += dd * dd;
            }
            /* a step of more than a tenth of the scene is no refinement */
            if (!(sqrt(step) <= 0.1 * size)) continue;
            for (int d = 0; d < 3; ++d) p[3 * i + d] += ca * a[d] + cb * b[d];
            moved = 1;
        }
        if (!moved) break;
    }
    free(x);
    free(g);
    free(gr);
    return s;
}

/* ---- the whole preparation of one instruction ---- */

/* Each long cone reduced once over the box of the kept cells (one cell more
 * on every side): the groups of points inside it, nearly all of them, are
 * reduced from that short cone instead of the whole one, so a fold's
 * reductions cost what its box meets and not every child before it. */
static lb_status fold_cones(child_eval *E, const grid *G, const cellset *S) {
    uint32_t lo[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX}, hi[3] = {0, 0, 0};
    for (size_t c = 0; c < S->n; ++c)
        for (int d = 0; d < 3; ++d) {
            const uint32_t v = S->c[3 * c + d];
            if (v < lo[d]) lo[d] = v;
            if (v + 1 > hi[d]) hi[d] = v + 1;
        }
    for (int d = 0; d < 3; ++d) {
        const double a = G->origin[d] + G->h * ((double)lo[d] - 1.0);
        const double b = G->origin[d] + G->h * ((double)hi[d] + 1.0);
        E->fc[d] = 0.5 * (a + b);
        E->fr[d] = 0.5 * (b - a);
    }
    for (int a = 0; a < 2; ++a) {
        const lb__instr *in = E->in;
        if (in->ncone[a] < REDUCE_FROM) continue;
        lb_status st = charge(E, E->wcone[a]);
        if (!st)
            st = lb__cone_reduce(E->ev, in->cone + (a ? in->ncone[0] : 0), in->ncone[a], E->fc,
                                 E->fr, &E->fold[a], E->err);
        if (st) return st;
    }
    return LB_OK;
}

static double dist3(const double *a, const double *b) {
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

/* chains: vertices per component in order, from segments over face points */
static lb_status chain(child_eval *E, const builder *B, struct lb__curves *C) {
    const size_t nf = B->nf, ns = B->ns;
    uint32_t *adj = malloc(2 * (nf ? nf : 1) * sizeof *adj);
    uint8_t *used = calloc(ns ? ns : 1, 1);
    C->pts = malloc(3 * (nf + 1) * sizeof *C->pts);
    C->comp = malloc((ns + 1) * sizeof *C->comp);
    if (!adj || !used || !C->pts || !C->comp) {
        free(adj);
        free(used);
        return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
    }
    for (size_t i = 0; i < 2 * nf; ++i) adj[i] = UINT32_MAX;
    for (size_t s = 0; s < ns; ++s)
        for (int e = 0; e < 2; ++e) {
            const uint32_t f = B->seg[2 * s + e];
            if (adj[2 * f] == UINT32_MAX)
                adj[2 * f] = (uint32_t)s;
            else if (adj[2 * f + 1] == UINT32_MAX)
                adj[2 * f + 1] = (uint32_t)s;
        }
        /* the other segment at face f, not s */
#define OTHER(f, s) (adj[2 * (f)] == (s) ? adj[2 * (f) + 1] : adj[2 * (f)])
    size_t nv = 0;
    C->ncomp = 0;
    /* open chains first (start at a face with one segment), then loops */
    for (int pass = 0; pass < 2; ++pass)
        for (size_t s0 = 0; s0 < ns; ++s0) {
            if (used[s0]) continue;
            uint32_t start = B->seg[2 * s0];
            if (pass == 0) {
                const int open0 = adj[2 * B->seg[2 * s0] + 1] == UINT32_MAX;
                const int open1 = adj[2 * B->seg[2 * s0 + 1] + 1] == UINT32_MAX;
                if (!open0 && !open1) continue;
                start = open0 ? B->seg[2 * s0] : B->seg[2 * s0 + 1];
            }
            lb__component *K = &C->comp[C->ncomp++];
            memset(K, 0, sizeof *K);
            K->first = nv;
            uint32_t f = start, s = (uint32_t)s0;
            memcpy(C->pts + 3 * nv++, B->fpts + 3 * f, 3 * sizeof(double));
            for (;;) {
                used[s] = 1;
                f = B->seg[2 * s] == f ? B->seg[2 * s + 1] : B->seg[2 * s];
                if (f == start) {
                    K->closed = 1;
                    break;
                }
                memcpy(C->pts + 3 * nv++, B->fpts + 3 * f, 3 * sizeof(double));
                const uint32_t next = OTHER(f, s);
                if (next == UINT32_MAX || used[next]) break;
                s = next;
            }
            K->count = nv - K->first;
            if (K->count < 2) --C->ncomp, nv = K->first; /* a lone point is no curve */
        }
#undef OTHER
    C->nv = nv;
    free(adj);
    free(used);
    return LB_OK;
}

/* insert projected midpoints where a segment strays from the curve */
static lb_status subdivide(child_eval *E, struct lb__curves *C, double size) {
    for (int pass = 0; pass < SUBDIVIDE_PASSES; ++pass) {
        /* midpoints of every segment, projected */
        size_t nseg = 0;
        for (size_t c = 0; c < C->ncomp; ++c)
            nseg += C->comp[c].count - (C->comp[c].closed ? 0 : 1);
        if (!nseg) return LB_OK;
        double *mid = malloc(3 * nseg * sizeof *mid);
        if (!mid) return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
        size_t q = 0;
        for (size_t c = 0; c < C->ncomp; ++c) {
            const lb__component *K = &C->comp[c];
            const size_t ne = K->count - (K->closed ? 0 : 1);
            for (size_t i = 0; i < ne; ++i) {
                const double *a = C->pts + 3 * (K->first + i);
                const double *b = C->pts + 3 * (K->first + (i + 1) % K->count);
                for (int d = 0; d < 3; ++d) mid[3 * q + d] = 0.5 * (a[d] + b[d]);
                ++q;
            }
        }
        double *chord = malloc(3 * nseg * sizeof *chord);
        if (!chord) {
            free(mid);
            return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
        }
        memcpy(chord, mid, 3 * nseg * sizeof *mid);
        lb_status s = project(E, nseg, mid, size);
        size_t add = 0;
        for (size_t i = 0; i < nseg && !s; ++i)
            add += dist3(mid + 3 * i, chord + 3 * i) > MIDPOINT_TOL * size;
        if (s || !add) {
            free(mid);
            free(chord);
            return s;
        }
        double *np = malloc(3 * (C->nv + add) * sizeof *np);
        if (!np) {
            free(mid);
            free(chord);
            return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
        }
        size_t nv = 0;
        q = 0;
        for (size_t c = 0; c < C->ncomp; ++c) {
            lb__component *K = &C->comp[c];
            const size_t first = nv;
            for (size_t i = 0; i < K->count; ++i) {
                memcpy(np + 3 * nv++, C->pts + 3 * (K->first + i), 3 * sizeof(double));
                if (i + 1 < K->count || K->closed) {
                    if (dist3(mid + 3 * q, chord + 3 * q) > MIDPOINT_TOL * size)
                        memcpy(np + 3 * nv++, mid + 3 * q, 3 * sizeof(double));
                    ++q;
                }
            }
            K->first = first;
            K->count = nv - first;
        }
        free(C->pts);
        C->pts = np;
        C->nv = nv;
        free(mid);
        free(chord);
    }
    return LB_OK;
}

/* feature sizes, limits and support of each component */
static lb_status parameters(child_eval *E, struct lb__curves *C, double size) {
    const lb__local_params *L = &E->in->op->lp;
    const size_t n = C->nv;
    if (!n) return LB_OK;
    /* gradients at X +- h e_d for the divergence of the unit normals */
    const double h = 1e-4 * size;
    double *x = malloc(3 * 7 * n * sizeof *x), *g = malloc(2 * 7 * n * sizeof *g);
    double *gr = malloc(6 * 7 * n * sizeof *gr);
    if (!x || !g || !gr) {
        free(x);
        free(g);
        free(gr);
        return lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
    }
    const size_t N = 7 * n;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 7; ++k)
            for (int d = 0; d < 3; ++d)
                x[d * N + 7 * i + k] =
                    C->pts[3 * i + d] + (k && (k - 1) / 2 == d ? (k % 2 ? h : -h) : 0.0);
    lb_status s = children_at(E, N, x, x + N, x + 2 * N, g, gr);
    for (size_t c = 0; c < C->ncomp && !s; ++c) {
        lb__component *K = &C->comp[c];
        double rho[2] = {0.0, 0.0};
        K->length = 0.0;
        K->diameter = 0.0;
        const size_t stride = K->count > 3000 ? K->count / 3000 : 1;
        for (size_t i = 0; i < K->count; ++i) {
            const double *P = C->pts + 3 * (K->first + i);
            if (i + 1 < K->count || K->closed)
                K->length += dist3(P, C->pts + 3 * (K->first + (i + 1) % K->count));
            if (i % stride == 0)
                for (size_t j = i + stride; j < K->count; j += stride) {
                    const double dd = dist3(P, C->pts + 3 * (K->first + j));
                    if (dd > K->diameter) K->diameter = dd;
                }
            for (int a = 0; a < 2; ++a) {
                double div = 0.0;
                for (int d = 0; d < 3; ++d) {
                    const double *gp = gr + 6 * (7 * (K->first + i) + 1 + 2 * d) + 3 * a;
                    const double *gm = gr + 6 * (7 * (K->first + i) + 2 + 2 * d) + 3 * a;
                    const double lp = sqrt(gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2]);
                    const double lm = sqrt(gm[0] * gm[0] + gm[1] * gm[1] + gm[2] * gm[2]);
                    if (lp > 0.0 && lm > 0.0) div += (gp[d] / lp - gm[d] / lm) / (2.0 * h);
                }
                const double r = fabs(div) > 2.0 / size ? 2.0 / fabs(div) : size;
                rho[a] += r;
            }
        }
        K->d1 = L->has_feature ? L->feature[0] : 0.5 * rho[0] / (double)K->count;
        K->d2 = L->has_feature ? L->feature[1] : 0.5 * rho[1] / (double)K->count;
        if (L->has_limits) {
            K->v1 = L->limits[0];
            K->v2 = L->limits[1];
        } else {
            /* v1 = g2(P - d1 n2), v2 = g1(P - d2 n1): a second evaluation */
            const size_t m = K->count;
            double *y = malloc(3 * 2 * m * sizeof *y), *gy = malloc(2 * 2 * m * sizeof *gy);
            if (!y || !gy) {
                free(y);
                free(gy);
                s = lb__fail(E->err, LB_ERR_NO_MEMORY, "%s: out of memory", E->in->op->path);
                break;
            }
            for (size_t i = 0; i < m; ++i) {
                const double *P = C->pts + 3 * (K->first + i);
                const double *g0 = gr + 6 * (7 * (K->first + i));
                for (int a = 0; a < 2; ++a) {
                    const double *nn = g0 + 3 * (1 - a); /* the other child's normal */
                    const double ln = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
                    const double dist = a == 0 ? K->d1 : K->d2;
                    for (int d = 0; d < 3; ++d)
                        y[d * 2 * m + 2 * i + a] = P[d] - (ln > 0.0 ? dist * nn[d] / ln : 0.0);
                }
            }
            s = children_at(E, 2 * m, y, y + 2 * m, y + 4 * m, gy, NULL);
            double s1 = 0.0, s2 = 0.0;
            for (size_t i = 0; i < m && !s; ++i) {
                s1 += gy[2 * (2 * i + 0) + 1]; /* g2 at P - d1 n2 */
                s2 += gy[2 * (2 * i + 1) + 0]; /* g1 at P - d2 n1 */
            }
            K->v1 = s1 / (double)m;
            K->v2 = s2 / (double)m;
            free(y);
            free(gy);
        }
        K->q = K->v1 / LB__LOCAL_ISO;
        K->p = K->v2 / LB__LOCAL_ISO;
        if (!(K->q >= 0.0)) K->q = 0.0;
        if (!(K->p >= 0.0)) K->p = 0.0;
        if (K->q > LB_BARTHE_MAX_PQ) K->q = LB_BARTHE_MAX_PQ;
        if (K->p > LB_BARTHE_MAX_PQ) K->p = LB_BARTHE_MAX_PQ;
        K->R = L->radius > 0.0      ? L->radius
               : L->feature_support ? 2.0 * (K->d1 < K->d2 ? K->d1 : K->d2)
                                    : L->support * K->diameter;
        if (!(K->R > 1e-12 * size)) K->R = 1e-12 * size;
        if (K->R > C->rmax) C->rmax = K->R;
    }
    free(x);
    free(g);
    free(gr);
    return s;
}

static lb_status prepare_one(const lb_evaluator *ev, lb__instr *in, const double bmin[3],
                             const double bmax[3], double *work, lb_error *err) {
    struct lb__curves *C = calloc(1, sizeof *C);
    double *regs = malloc(lb__regs_len(ev) * sizeof *regs);
    lb__iv *R = malloc(lb__ivs_len(ev) * sizeof *R);
    builder B;
    memset(&B, 0, sizeof B);
    cellset S = {NULL, 0, 0};
    lb_status s = LB_OK;
    if (!C || !regs || !R) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
    child_eval E = {.ev = ev,
                    .in = in,
                    .regs = regs,
                    .err = err,
                    .wcone = {cone_weight(ev, in->cone, in->ncone[0]),
                              cone_weight(ev, in->cone + in->ncone[0], in->ncone[1])},
                    .work = work};
    grid G;
    double size = 0.0;
    if (!s) {
        double longest = 0.0;
        for (int d = 0; d < 3; ++d) {
            const double e = bmax[d] - bmin[d];
            size += e * e;
            if (e > longest) longest = e;
        }
        size = sqrt(size);
        C->scene_size = size;
        G.h = longest / GRID;
        for (int d = 0; d < 3; ++d) {
            G.cells[d] = (uint32_t)ceil((bmax[d] - bmin[d]) / G.h - 1e-9);
            if (G.cells[d] < 1) G.cells[d] = 1;
            /* centre the grid on the region; shifted by a fraction of a cell
             * so that symmetric scenes do not put nodes exactly on surfaces */
            G.origin[d] = 0.5 * (bmin[d] + bmax[d]) - 0.5 * G.h * G.cells[d] + 1e-7 * G.h * (d + 1);
        }
        const uint32_t zero[3] = {0, 0, 0};
        cell_walk *W = malloc(sizeof *W);
        if (!W) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        } else {
            W->E = &E;
            W->G = &G;
            W->R = R;
            W->S = &S;
            s = lb__box_descend(W, cell_visit, zero, G.cells, 0);
            free(W);
        }
    }
    if (!s && S.n) s = fold_cones(&E, &G, &S);
    /* sample the kept cells' nodes */
    if (!s && S.n) {
        if (hmap_init(&B.nodes, 8 * S.n) || hmap_init(&B.faces, 24 * S.n))
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        B.G = &G;
        uint64_t *ids = s ? NULL : malloc(8 * S.n * sizeof *ids);
        if (!s && !ids) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        size_t nn = 0;
        for (size_t c = 0; c < S.n && !s; ++c)
            for (int k = 0; k < 8; ++k) {
                const uint32_t *q = S.c + 3 * c;
                const uint64_t id =
                    node_id(&G, q[0] + (k & 1), q[1] + (k >> 1 & 1), q[2] + (k >> 2));
                const size_t slot = hmap_slot(&B.nodes, id, 0);
                if (B.nodes.val[slot] != UINT32_MAX) continue;
                B.nodes.k1[slot] = id;
                B.nodes.k2[slot] = 0;
                B.nodes.val[slot] = (uint32_t)nn;
                ids[nn++] = id;
            }
        double *x = s ? NULL : malloc(3 * nn * sizeof *x);
        B.nval = s ? NULL : malloc(2 * nn * sizeof *B.nval);
        if (!s && (!x || !B.nval))
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        for (size_t i = 0; i < nn && !s; ++i) {
            double p[3];
            node_pos(&G, ids[i], p);
            for (int d = 0; d < 3; ++d) x[d * nn + i] = p[d];
        }
        if (!s) s = children_at(&E, nn, x, x + nn, x + 2 * nn, B.nval, NULL);
        for (size_t i = 0; i < 2 * nn && !s; ++i) {
            B.nval[i] -= LB__LOCAL_ISO;
            if (B.nval[i] == 0.0) B.nval[i] = DBL_MIN; /* a tie counts as inside */
        }
        free(x);
        free(ids);
        for (size_t c = 0; c < S.n && !s; ++c) {
            const uint32_t *q = S.c + 3 * c;
            uint64_t corner[8];
            for (int k = 0; k < 8; ++k)
                corner[k] = node_id(&G, q[0] + (k & 1), q[1] + (k >> 1 & 1), q[2] + (k >> 2));
            if (tet_segments(&B, corner))
                s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
        }
    }
    if (!s) s = chain(&E, &B, C);
    if (!s && C->nv) s = project(&E, C->nv, C->pts, size);
    if (!s) s = subdivide(&E, C, size);
    if (!s) s = parameters(&E, C, size);
    if (!s) s = lb__local_bvh(C, in->op->path, err);
    for (int q = 0; q < 2; ++q) {
        lb__cone_free(&E.grp[q]);
        lb__cone_free(&E.sub[q]);
    }
    for (int q = 0; q < 2 * OCTREE_DEPTH; ++q) lb__cone_free(&E.oc[q]);
    lb__cone_free(&E.fold[0]);
    lb__cone_free(&E.fold[1]);
    free(E.ivs);
    free(E.subregs);
    hmap_free(&B.nodes);
    hmap_free(&B.faces);
    free(B.nval);
    free(B.fpts);
    free(B.seg);
    free(S.c);
    free(regs);
    free(R);
    if (s) {
        lb__curves_free(C);
        return s;
    }
    in->curves = C;
    return LB_OK;
}

static int has_curves(const lb__instr *in) {
    return in->code == LB__I_OP && (lb__op_flags(in->op) & LB__R_CURVES);
}

static struct lb__curves *curves_copy(const struct lb__curves *c) {
    struct lb__curves *d = malloc(sizeof *d);
    if (!d) return NULL;
    *d = *c;
    d->pts = malloc((c->nv ? 3 * c->nv : 1) * sizeof *d->pts);
    d->comp = malloc((c->ncomp ? c->ncomp : 1) * sizeof *d->comp);
    d->seg = malloc((c->nseg ? 2 * c->nseg : 1) * sizeof *d->seg);
    d->segc = malloc((c->nseg ? c->nseg : 1) * sizeof *d->segc);
    d->bvh = malloc((c->nnodes ? c->nnodes : 1) * sizeof *d->bvh);
    if (!d->pts || !d->comp || !d->seg || !d->segc || !d->bvh) {
        lb__curves_free(d);
        return NULL;
    }
    if (c->nv) memcpy(d->pts, c->pts, 3 * c->nv * sizeof *d->pts);
    if (c->ncomp) memcpy(d->comp, c->comp, c->ncomp * sizeof *d->comp);
    if (c->nseg) {
        memcpy(d->seg, c->seg, 2 * c->nseg * sizeof *d->seg);
        memcpy(d->segc, c->segc, c->nseg * sizeof *d->segc);
    }
    if (c->nnodes) memcpy(d->bvh, c->bvh, c->nnodes * sizeof *d->bvh);
    return d;
}

/* prev's records without curves and a table over them, for the matching */
typedef struct reuse {
    const lb_evaluator *prev;
    lb__recs P;
    uint32_t *tab; /* instruction + 1, 0: empty */
    size_t tcap;
    uint32_t *deep; /* ev's instruction -> prev's with the same record, or LB__RNONE */
    lb__rbuf b;
} reuse;

static void reuse_free(reuse *U) {
    lb__recs_free(&U->P);
    free(U->tab);
    free(U->deep);
    free(U->b.p);
}

/* 0 when out of memory (then nothing is reused) */
static int reuse_init(reuse *U, const lb_evaluator *ev, const lb_evaluator *prev) {
    memset(U, 0, sizeof *U);
    U->prev = prev;
    U->tcap = lb__recs_table_cap(prev->n);
    U->tab = calloc(U->tcap, sizeof *U->tab);
    U->deep = malloc((ev->n ? ev->n : 1) * sizeof *U->deep);
    if (!U->tab || !U->deep || !lb__recs_make(prev, NULL, 1, 0, &U->P)) {
        reuse_free(U);
        return 0;
    }
    lb__recs_table_fill(&U->P, prev->n, U->tab, U->tcap);
    return 1;
}

/* prev's instruction with ev's instruction i's record (curves left out),
 * or LB__RNONE */
static uint32_t reuse_match(reuse *U, const lb_evaluator *ev, size_t i) {
    U->b.n = 0;
    if (!lb__record(ev, (uint32_t)i, U->deep, 1, 0, &U->b) || U->b.oom) return LB__RNONE;
    return lb__recs_find(&U->P, U->tab, U->tcap, U->b.p, U->b.n);
}

lb_status lb__local_prepare(lb_evaluator *ev, const lb_scene *scene, const lb_evaluator *prev,
                            size_t *reused, lb_error *err) {
    if (reused) *reused = 0;
    int any = 0, prev_any = 0;
    for (size_t i = 0; i < ev->n; ++i) any |= has_curves(&ev->ins[i]);
    for (size_t j = 0; prev && j < prev->n; ++j) prev_any |= has_curves(&prev->ins[j]);
    if (!any) return LB_OK;
    reuse U;
    const int use = prev_any && reuse_init(&U, ev, prev);
    lb_status s = LB_OK;
    for (size_t i = 0; i < ev->n && !s; ++i) {
        lb__instr *in = &ev->ins[i];
        uint32_t j = use ? reuse_match(&U, ev, i) : LB__RNONE;
        if (has_curves(in)) {
            double bmin[3], bmax[3];
            if (!lb_scene_bounds(scene, bmin, bmax)) {
                s = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                             "%s: local_union finds its children's intersection curves inside "
                             "the scene's bounds; allowed: a scene with \"bounds\"",
                             in->op->path);
                break;
            }
            const struct lb__curves *old = j != LB__RNONE ? prev->ins[j].curves : NULL;
            if (old && !memcmp(old->bmin, bmin, sizeof bmin) &&
                !memcmp(old->bmax, bmax, sizeof bmax) && (in->curves = curves_copy(old))) {
                /* the cost finding them took, counted as if found again */
                ev->compile_cost += old->cost;
                if (ev->compile_cost > LB_SCENE_MAX_COMPILE_COST) s = over_cost(in, err);
                if (reused) ++*reused;
            } else {
                j = LB__RNONE;
                const double before = ev->compile_cost;
                s = prepare_one(ev, in, bmin, bmax, &ev->compile_cost, err);
                if (!s) {
                    in->curves->cost = ev->compile_cost - before;
                    memcpy(in->curves->bmin, bmin, sizeof bmin);
                    memcpy(in->curves->bmax, bmax, sizeof bmax);
                }
            }
        }
        if (use) U.deep[i] = j;
    }
    if (use) reuse_free(&U);
    return s;
}

/* ---- description (blendtool info) ---- */

size_t lb_evaluator_describe_local(const lb_evaluator *ev, char *buf, size_t size) {
    lb__text b = {buf, buf ? size : 0, 0};
    if (b.size) buf[0] = '\0';
    if (!ev) return 0;
    for (size_t i = 0; i < ev->n; ++i) {
        const lb__instr *in = &ev->ins[i];
        if (in->code != LB__I_OP || !(lb__op_flags(in->op) & LB__R_CURVES) || !in->curves) continue;
        const struct lb__curves *C = in->curves;
        lb__text_put(&b, "%s: %zu intersection curve%s, %zu vertices\n", in->op->path, C->ncomp,
                     C->ncomp == 1 ? "" : "s", C->nv);
        for (size_t c = 0; c < C->ncomp; ++c) {
            const lb__component *K = &C->comp[c];
            lb__text_put(
                &b,
                "  curve %zu: %s, %zu vertices, length %.6g, diameter %.6g, R %.6g, v1 %.6g, "
                "v2 %.6g, d1 %.6g, d2 %.6g\n",
                c, K->closed ? "closed" : "open", K->count, K->length, K->diameter, K->R, K->v1,
                K->v2, K->d1, K->d2);
        }
    }
    if (b.size && b.len >= b.size) buf[b.size - 1] = '\0';
    return b.len;
}

/* ---- inspection (tests) ---- */

const struct lb__curves *lb__local_nth(const lb_evaluator *ev, size_t which) {
    size_t seen = 0;
    for (size_t i = 0; ev && i < ev->n; ++i) {
        const lb__instr *in = &ev->ins[i];
        if (in->code == LB__I_OP && (lb__op_flags(in->op) & LB__R_CURVES) && seen++ == which)
            return in->curves;
    }
    return NULL;
}
