/* lb_mesh_create: grid, sparse block selection, parallel phases, merge.
 *
 * 1. The region is cut into cells (resolution along the longest side); for
 *    a closed mesh the grid gets half a cell of margin on every side, so
 *    every outermost node lies outside the region box and the surface of
 *    max(phi, box) closes on the region's faces.
 * 2. Blocks of 8^3 cells: an octree over block ranges keeps the blocks whose
 *    interval bound of phi_c (lb_evaluator_bounds) contains 0.
 * 3. In parallel, each kept block finds, by intervals again, its sub-boxes
 *    of 2^3 cells that may cross (mark) and evaluates only their nodes,
 *    octant by octant, each octant under the plan of its own interval pass
 *    (fewer arguments survive culling over a smaller box).
 * 4. Nodes on a block's far faces are also nodes of the next block: they
 *    take that block's value and gradient, so both sides see the same signs
 *    (the evaluator's per-batch culling may differ in the last bit). Blocks
 *    are taken from the last to the first, so a block's next blocks are
 *    done first (one still at work on another thread keeps the block
 *    waiting in its thread's short list: work()).
 * 5. Right after, while its node data is in cache: the vertices of the
 *    crossing edges the block owns (refine.c, octant by octant as in 3),
 *    the vertices on its far faces taken from the next blocks that own
 *    them, and its cells' polygons (extract.c with cubes.c, or tetra.c with
 *    LB_MESH_TETRAHEDRA): every vertex is refined once.
 * 6. The blocks are merged from the last to the first as they are done, so
 *    the output is the same for every thread count.
 * Threads take blocks from a shared counter; the calling thread works too
 * and is the only one that calls the progress callback. */
#include "mesh_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "../common/boxtree.h"
#include "../common/platform.h"

static const char FN[] = "lb_mesh_create";

void lb_mesh_options_init(lb_mesh_options *opt) {
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->resolution = LB_MESH_DEFAULT_RESOLUTION;
}

void lb_mesh_free(lb_mesh *mesh) {
    if (!mesh) return;
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->triangles);
    free(mesh->corner_normals);
    free(mesh);
}

/* ---- the grid ---- */

static lb_status make_grid(const lb_evaluator *ev, const lb_mesh_options *o, lb__grid *g,
                           lb_error *err) {
    memset(g, 0, sizeof *g);
    double ext[3], longest = 0.0;
    for (int d = 0; d < 3; ++d) {
        if (!isfinite(o->bmin[d]) || !isfinite(o->bmax[d]) ||
            fabs(o->bmin[d]) > LB_SCENE_MAX_COORD || fabs(o->bmax[d]) > LB_SCENE_MAX_COORD)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: region %s[%d] = %g; allowed: finite, |value| <= %g", FN,
                            !isfinite(o->bmin[d]) || fabs(o->bmin[d]) > LB_SCENE_MAX_COORD ? "bmin"
                                                                                           : "bmax",
                            d, !isfinite(o->bmin[d]) ? o->bmin[d] : o->bmax[d], LB_SCENE_MAX_COORD);
        if (!(o->bmin[d] < o->bmax[d]))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: region min[%d] = %g is not below max[%d] = %g; allowed: "
                            "min < max on every axis",
                            FN, d, o->bmin[d], d, o->bmax[d]);
        ext[d] = o->bmax[d] - o->bmin[d];
        if (ext[d] > longest) longest = ext[d];
    }
    double h;
    if (o->cell_size != 0.0) {
        if (!(o->cell_size > 0.0) || !isfinite(o->cell_size))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: cell_size = %g; allowed: a positive number (or 0 to use the "
                            "resolution)",
                            FN, o->cell_size);
        h = o->cell_size;
    } else {
        if (o->resolution < 1 || o->resolution > LB_MESH_MAX_CELLS_PER_AXIS)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: resolution = %u; allowed: 1 to %d cells along the longest side",
                            FN, o->resolution, LB_MESH_MAX_CELLS_PER_AXIS);
        h = longest / o->resolution;
    }
    g->closed = !(o->flags & LB_MESH_OPEN_BOUNDARY);
    g->tetrahedra = (o->flags & LB_MESH_TETRAHEDRA) != 0;
    g->features = (o->flags & LB_MESH_FEATURES) != 0;
    g->coarse =
        (o->flags & LB_MESH_COARSE_FIRST) && !g->tetrahedra && !g->features ? o->simplify : 0.0;
    g->soft = lb_evaluator_convention(ev) == LB_CONVENTION_SOFT;
    for (int d = 0; d < 3; ++d) {
        const double nf = ceil(ext[d] / h - 1e-9);
        if (!(nf <= LB_MESH_MAX_CELLS_PER_AXIS))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: %.0f cells along axis %d (cell size %g); allowed: at most %d "
                            "cells per axis (a cell size of at least %g)",
                            FN, nf, d, h, LB_MESH_MAX_CELLS_PER_AXIS,
                            longest / LB_MESH_MAX_CELLS_PER_AXIS);
        const uint32_t n = nf < 1.0 ? 1u : (uint32_t)nf;
        g->h[d] = ext[d] / n;
        g->bmin[d] = o->bmin[d];
        g->bmax[d] = o->bmax[d];
        g->cells[d] = n + (g->closed ? 1u : 0u);
        g->N[d] = g->cells[d] + 1;
        g->origin[d] = o->bmin[d] - (g->closed ? 0.5 * g->h[d] : 0.0);
    }
    return LB_OK;
}

/* phi_c's interval on the box [bl, bh] from the field's interval [flo, fhi]:
 * phi = f or 0.5 - f, and for a closed mesh the max with the region box's
 * terms bmin - X and X - bmax (each linear, so exact on the box). */
static void phi_interval(const lb__grid *g, const double bl[3], const double bh[3], double flo,
                         double fhi, double *lo, double *hi) {
    double plo = g->soft ? 0.5 - fhi : flo, phi = g->soft ? 0.5 - flo : fhi;
    if (g->closed)
        for (int d = 0; d < 3; ++d) {
            const double l1 = g->bmin[d] - bh[d], h1 = g->bmin[d] - bl[d];
            const double l2 = bl[d] - g->bmax[d], h2 = bh[d] - g->bmax[d];
            if (l1 > plo) plo = l1;
            if (l2 > plo) plo = l2;
            if (h1 > phi) phi = h1;
            if (h2 > phi) phi = h2;
        }
    *lo = plo;
    *hi = phi;
}

/* ---- block selection (octree over block ranges) ----
 * Each box's interval pass runs under its parent box's plan (the root's
 * over the whole tape), so a box looks only at the blend arguments that
 * can reach its parent: the octree is the spatial index over the
 * arguments, and a kept block leaves with its own plan (kept small, in
 * lb__block.plan) for its node values and refinement. */

typedef struct blist {
    lb__block *b;
    size_t n, cap;
} blist;

/* The incremental selection (cache.c states the rule): the boxes down to
 * depth `depth` that the surface may cross, with their plans, for the next
 * cache (nodes); with a usable match M, a box whose plan is the cached
 * box's takes the cached boxes and blocks under it instead of its
 * descent. */
typedef struct incsel {
    lb_mesh_cache *cache;
    lb__cmatch *M; /* NULL: record the boxes only */
    uint32_t *scratch;
    int depth; /* the deepest boxes kept; -1: none */
    lb__cblock *nodes;
    size_t n, cap;
    size_t carried; /* blocks carried over */
} incsel;

/* Halvings above the blocks for the deepest boxes the incremental
 * selection keeps: boxes of about 4 x 4 x 4 blocks. */
#define INC_LEVELS 6

typedef struct sel {
    const lb_evaluator *ev;
    const lb__grid *g;
    const uint32_t *nb;
    blist *L;
    size_t max_blocks;
    lb__plan *pool; /* one plan per depth */
    lb__iv *R;
    int keep;    /* store each block's plan */
    incsel *inc; /* NULL: a plain selection */
    lb_error *err;
} sel;

/* *p (room for cap elements of size sz, the first used of them in use)
 * given room for c elements when c > cap. */
static int grow(void **p, size_t cap, size_t c, size_t used, size_t sz) {
    if (c <= cap) return 1;
    /* a new array, on huge pages from its first byte (lb__array_alloc)
     * before the used part is copied in: realloc would move the pages
     * (mremap) to an address whose 2 MiB alignment differs, which splits
     * the huge pages into small ones for good, and on this project's build
     * machine (a PVM guest) a small page can cost a fault in the host each
     * time it is touched after any unmapping (docs/meshing.md, Incremental
     * remeshing) */
    void *q = lb__array_alloc(c * sz);
    if (!q) return 0;
    if (*p) memcpy(q, *p, used * sz);
    free(*p);
    *p = q;
    return 1;
}

/* Room for element n (of sz bytes) in *p, which has room for *cap: doubled
 * from first when full. 0 when out of memory (*p as it was). Grown as the
 * output arrays are (grow): under jemalloc (Blender's allocator) the block
 * list's pages came fresh from the system every run, a fault per 4 KiB. */
static int room_for(void **p, size_t *cap, size_t n, size_t sz, size_t first) {
    if (n < *cap) return 1;
    const size_t nc = *cap ? 2 * *cap : first;
    if (!grow(p, *cap, nc, n, sz)) return 0;
    *cap = nc;
    return 1;
}

/* Room for one more block in L (over max_blocks: LB_ERR_NO_MEMORY too). */
static lb_status blist_room(sel *S) {
    blist *L = S->L;
    if (L->n >= S->max_blocks)
        return lb__fail(S->err, LB_ERR_NO_MEMORY, "%s: more than %zu blocks", FN, S->max_blocks);
    if (!room_for((void **)&L->b, &L->cap, L->n, sizeof *L->b, 256))
        return lb__fail(S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    return LB_OK;
}

/* B's plan freed, unless it is a cached entry's (plan_of). */
static void plan_drop(lb__block *B) {
    if (B->plan_of)
        memset(&B->plan, 0, sizeof B->plan);
    else
        lb__cplan_free(&B->plan);
}

/* A block of the list at block coordinates b (its cells clipped to the
 * grid), with plan. */
static void block_at(sel *S, const uint32_t b[3], const lb__cplan *plan) {
    lb__block *B = &S->L->b[S->L->n++];
    memset(B, 0, sizeof *B);
    if (plan) B->plan = *plan;
    for (int d = 0; d < 3; ++d) {
        const uint64_t n0 = (uint64_t)b[d] * LB__MB;
        uint64_t n1 = n0 + LB__MB;
        if (n1 > S->g->cells[d]) n1 = S->g->cells[d];
        B->b[d] = b[d];
        B->nc[d] = (uint32_t)(n1 - n0);
    }
    B->id = lb__block_id(S->nb, b[0], b[1], b[2]);
}

/* Room for one more box in I (out of memory: LB_ERR_NO_MEMORY). */
static lb_status node_room(sel *S) {
    incsel *I = S->inc;
    if (!room_for((void **)&I->nodes, &I->cap, I->n, sizeof *I->nodes, 64))
        return lb__fail(S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    return LB_OK;
}

/* Is block coordinate b (of a block or box's first block, by id) inside
 * the box [r0, r1)? */
static int in_box(const uint32_t nb[3], uint64_t id, const uint32_t r0[3], const uint32_t r1[3]) {
    const uint32_t b[3] = {(uint32_t)(id % nb[0]), (uint32_t)(id / nb[0] % nb[1]),
                           (uint32_t)(id / nb[0] / nb[1])};
    return b[0] >= r0[0] && b[0] < r1[0] && b[1] >= r0[1] && b[1] < r1[1] && b[2] >= r0[2] &&
           b[2] < r1[2];
}

/* The cached boxes and blocks under box [r0, r1) (the cached box E, its
 * plan now in the new evaluator's indices) taken, their plans carried over
 * (*taken = 1); when some plan cannot be, nothing is taken (the box is
 * descended). A failure's status (out of memory, over max_blocks) is
 * returned. */
static lb_status take_under(sel *S, const lb__cblock *E, const lb__cplan *now, int depth,
                            const uint32_t r0[3], const uint32_t r1[3], int *taken) {
    incsel *I = S->inc;
    const size_t first = S->L->n, nfirst = I->n;
    const uint64_t N0 = lb__block_id(S->nb, r0[0], r0[1], r0[2]);
    lb_status s = LB_OK;
    int ok = 1;
    lb__cache_carry_from(I->M, E, now, 1);
    /* the boxes below it that the cache keeps (sorted by depth, then id):
     * at each depth those with ids from the box's first block's to its
     * last one's, inside it */
    size_t nold = 0;
    const lb__cblock *on = lb__cache_nodes(I->cache, &nold);
    const uint64_t last = lb__block_id(S->nb, r1[0] - 1, r1[1] - 1, r1[2] - 1);
    for (size_t j = 0; j < nold && ok && !s; ++j) {
        if (on[j].depth <= (uint32_t)depth) continue;
        if (on[j].id < N0) { /* the next depth's first one inside */
            const lb__cblock *F = lb__cache_node_from(I->cache, on[j].depth, N0);
            if (!F) break;
            j = (size_t)(F - on) - 1;
            continue;
        }
        if (on[j].id > last) { /* the next depth's */
            const lb__cblock *F = lb__cache_node_from(I->cache, on[j].depth + 1, 0);
            if (!F) break;
            j = (size_t)(F - on) - 1;
            continue;
        }
        if (!in_box(S->nb, on[j].id, r0, r1)) continue;
        if ((s = node_room(S))) break;
        lb__cblock *N = &I->nodes[I->n];
        memset(N, 0, sizeof *N);
        if (!(ok = lb__cache_carry(I->M, &on[j].plan, &N->plan))) break;
        N->id = on[j].id;
        N->depth = on[j].depth;
        ++I->n;
    }
    /* the two boxes' lists number their instructions alike (an edit of
     * parameters only): a block's plan is the cached one's, shared */
    const int alike = E->plan.nlist == now->nlist &&
                      !memcmp(E->plan.list, now->list, now->nlist * sizeof *now->list);
    const lb__cblock *old = lb__cache_blocks(I->cache, &nold);
    for (uint32_t z = r0[2]; z < r1[2] && ok && !s; ++z)
        for (uint32_t y = r0[1]; y < r1[1] && ok && !s; ++y) {
            const uint64_t row = lb__block_id(S->nb, 0, y, z);
            for (size_t j = lb__cache_block_from(I->cache, row + r0[0]);
                 j < nold && old[j].id < row + r1[0]; ++j) {
                lb__cplan p = old[j].plan;
                if ((s = blist_room(S))) break;
                if (!alike && !(ok = lb__cache_carry(I->M, &old[j].plan, &p))) break;
                const uint32_t b[3] = {(uint32_t)(old[j].id % S->nb[0]), y, z};
                block_at(S, b, &p);
                S->L->b[S->L->n - 1].carried = 1;
                S->L->b[S->L->n - 1].plan_of = alike ? &old[j] : NULL;
            }
        }
    lb__cache_carry_from(I->M, E, now, 0);
    if (s || !ok) { /* nothing taken: the box is descended (or the run fails) */
        for (size_t k = first; k < S->L->n; ++k) plan_drop(&S->L->b[k]);
        S->L->n = first;
        for (size_t k = nfirst; k < I->n; ++k) lb__cplan_free(&I->nodes[k].plan);
        I->n = nfirst;
        return s;
    }
    I->carried += S->L->n - first;
    *taken = 1;
    return LB_OK;
}

/* Box [r0, r1) at depth (at most the incremental depth), its plan own:
 * recorded for the next cache; *taken when the cached boxes and blocks
 * under it were taken instead of its descent. */
static lb_status inc_box(sel *S, const uint32_t r0[3], const uint32_t r1[3], int depth,
                         const lb__plan *own, int *taken) {
    incsel *I = S->inc;
    *taken = 0;
    lb_status s = node_room(S);
    if (s) return s;
    lb__cblock *N = &I->nodes[I->n];
    memset(N, 0, sizeof *N);
    s = lb__cplan_make(S->ev, own, &N->plan, S->err);
    if (s) return s;
    N->id = lb__block_id(S->nb, r0[0], r0[1], r0[2]);
    N->depth = (uint32_t)depth;
    ++I->n;
    const lb__cblock *E = I->M ? lb__cache_node(I->cache, depth, N->id) : NULL;
    if (!E || !lb__cache_same_plan(I->cache, I->M, E, &N->plan, I->scratch)) return LB_OK;
    const lb__cplan now = N->plan; /* I->nodes may move */
    return take_under(S, E, &now, depth, r0, r1, taken);
}

/* One box of blocks [r0, r1) (a visit of lb__box_descend): kept when the
 * surface may cross it, a kept single block into the list with its plan. */
static lb_status select_visit(void *ctx, const uint32_t r0[3], const uint32_t r1[3], int depth,
                              int cell, int *split) {
    sel *S = ctx;
    lb_error *err = S->err;
    const lb__plan *parent = depth ? &S->pool[depth - 1] : NULL;
    const lb__grid *g = S->g;
    uint64_t n0[3], n1[3];
    for (int d = 0; d < 3; ++d) {
        n0[d] = (uint64_t)r0[d] * LB__MB;
        n1[d] = (uint64_t)r1[d] * LB__MB;
        if (n1[d] > g->cells[d]) n1[d] = g->cells[d];
    }
    double bl[3], bh[3], bc[3], br[3];
    lb__node_pos(g, n0[0], n0[1], n0[2], bl);
    lb__node_pos(g, n1[0], n1[1], n1[2], bh);
    lb__box_centre(bl, bh, bc, br);
    lb__plan *own = &S->pool[depth];
    if (parent)
        lb__bounds_pass_sub(S->ev, parent, bc, br, S->R, own);
    else
        lb__bounds_pass(S->ev, bc, br, S->R, own);
    double lo, hi;
    phi_interval(g, bl, bh, S->R[S->ev->out].lo, S->R[S->ev->out].hi, &lo, &hi);
    if (lo >= 0.0 || hi < 0.0) return LB_OK; /* all outside, or all inside */
    if (cell) {
        lb_status s = blist_room(S);
        lb__cplan p;
        if (!s && S->keep) s = lb__cplan_make(S->ev, own, &p, err);
        if (s) return s;
        block_at(S, r0, S->keep ? &p : NULL);
        return LB_OK;
    }
    if (S->inc && depth <= S->inc->depth) {
        int taken;
        const lb_status s = inc_box(S, r0, r1, depth, own, &taken);
        if (s || taken) return s;
    }
    *split = 1;
    return LB_OK;
}

static void blist_free(blist *L) {
    for (size_t i = 0; i < L->n; ++i) plan_drop(&L->b[i]);
    free(L->b);
    L->b = NULL;
    L->n = L->cap = 0;
}

/* The blocks of grid g (nb per axis) that the surface may cross, into L
 * (with their plans when keep; through inc, when not NULL, incrementally). */
static lb_status select_all(const lb_evaluator *ev, const lb__grid *g, const uint32_t nb[3],
                            blist *L, size_t max_blocks, int keep, incsel *inc, lb_error *err) {
    const int depth = lb__box_depths(nb);
    sel S = {ev,
             g,
             nb,
             L,
             max_blocks,
             calloc((size_t)depth, sizeof(lb__plan)),
             malloc(lb__ivs_len(ev) * sizeof(lb__iv)),
             keep,
             inc,
             err};
    lb_status s = S.pool && S.R ? LB_OK : lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    for (int d = 0; d < depth && !s && S.pool; ++d) s = lb__plan_alloc(ev, &S.pool[d], err);
    const uint32_t zero[3] = {0, 0, 0};
    if (!s) s = lb__box_descend(&S, select_visit, zero, nb, 0);
    for (int d = 0; d < depth && S.pool; ++d) lb__plan_free(&S.pool[d]);
    free(S.pool);
    free(S.R);
    return s;
}

typedef struct bkey {
    uint64_t id;
    size_t at;
} bkey;

static int cmp_bkey(const void *a, const void *b) {
    const uint64_t x = ((const bkey *)a)->id, y = ((const bkey *)b)->id;
    return x < y ? -1 : x > y;
}

/* ---- the blocks' work, in parallel ----
 * Blocks are taken from the last to the first. A block's node values come
 * first; then, once the next blocks (+x, +y, +z and their combinations:
 * taken earlier) are done, its far-face nodes take their values
 * (block_share) and its surface is extracted at once, while its own node
 * data is still in cache. A block's node data, with its near-face vertex
 * table, lives in a slot until the last block that reads it is done
 * (refs), and the slot is reused. */

/* The mesh being merged (merge_block): its arrays' capacities, the table of
 * orphan vertices (grid edge key, mesh vertex), a block's local-to-mesh
 * vertex map (xt, room for xcap), each merged block's first mesh vertex,
 * and the first failure. */
typedef struct mkv {
    uint64_t key, v;
} mkv;

typedef struct mstate {
    lb_mesh *M;
    size_t vcap, tcap;
    mkv *tab;
    size_t cap, used;
    uint32_t *xt;
    size_t xcap;
    uint32_t *base;
    /* the feature points' vertex ranges (first, count), for the flips */
    size_t *fr;
    size_t nfr, frcap;
    /* the triangle ranges (first, count) of the blocks with feature
     * points, ascending: the fans, which the flips and the unfolding look
     * at, are among them */
    size_t *ftr;
    size_t nftr, ftrcap;
    /* with a cache: each block's entry, which takes its output once merged
     * (its references as offset codes, by nbr) */
    lb__cblock *keep;
    uint32_t (*nbr)[8];
    size_t vhint, thint; /* first capacities: the cached mesh's counts, a sixteenth more */
    lb_status s;
    lb_error err;
} mstate;

typedef struct run {
    const lb_evaluator *ev;
    const lb__grid *g;
    lb__block *blocks;
    size_t nblocks;
    uint32_t nb[3];
    atomic_size_t next, done;
    atomic_int stop;
    const volatile int *cancel;
    pthread_mutex_t lock; /* the first error and the free slots */
    size_t err_block;
    lb_error err;
    lb__bctx **ctx; /* one extraction state per thread (index 0: the calling thread) */
    size_t nctx;
    /* per block: its next blocks by offset c (bit d: +1 along axis d), as
     * index + 1 (0: none kept); whether its node values are done; how many
     * of itself and the blocks before it still read its node data */
    uint32_t (*nbr)[8];
    atomic_int *ready;
    atomic_uint *refs;
    /* node data slots (NODE_BYTES each, their own heap blocks): all made so
     * far, and the free ones (at most one per block) */
    unsigned char **all, **free;
    size_t nall, nfree;
    /* waiting for a next block to be done: gen counts the wake-ups (a
     * block done, a stop) */
    pthread_mutex_t wm;
    pthread_cond_t wc;
    atomic_ulong gen;
    /* the merge: blocks whose output is done (fin), how many are merged
     * (from the last block down), under mlock */
    atomic_int *fin;
    pthread_mutex_t mlock;
    size_t mnext;
    mstate ms;
    /* incremental remeshing (cache.c): the cache, the cached entry each
     * block is taken from (NULL: computed), whether a block taken from the
     * cache is read by a computed one (its shared faces are loaded) */
    lb_mesh_cache *cache;
    lb__cmatch *match;
    const lb__cblock **from;
    uint8_t *want;
    size_t nreused;
    /* the run's own arrays (run_alloc): the cache they go back to (NULL:
     * none, plain malloc and free), and each slot's array out now */
    lb_mesh_cache *keeper;
    struct {
        void *p;
        size_t bytes;
    } out[LB__RUN_SLOTS];
} run;

/* the uses of run_alloc's arrays, one slot each */
enum {
    RS_KEYS,
    RS_SORTED,
    RS_CAND,
    RS_CHANGED,
    RS_SCRATCH,
    RS_FROM,
    RS_WANT,
    RS_NBR,
    RS_READY,
    RS_REFS,
    RS_FIN,
    RS_BASE,
    RS_ALL,
    RS_FREE,
    RS_IDS,
    RS_COUNT
};
_Static_assert(RS_COUNT <= LB__RUN_SLOTS, "a slot for each use");

/* An array of bytes (zeroed when zero) for one use (slot) in this run:
 * with a cache, the one it kept from the last run when large enough, else
 * a new one; run_free gives it back. NULL when out of memory. */
static void *run_alloc(run *R, int slot, size_t bytes, int zero) {
    if (!bytes) bytes = 1;
    if (!R->keeper) return zero ? calloc(1, bytes) : malloc(bytes);
    size_t got = 0;
    void *p = lb__cache_run_take(R->keeper, slot, bytes, &got);
    if (p) {
        if (zero) memset(p, 0, bytes);
    } else {
        if (!(p = zero ? calloc(1, bytes) : malloc(bytes))) return NULL;
        lb__huge_pages(p, bytes);
        got = bytes;
    }
    R->out[slot].p = p;
    R->out[slot].bytes = got;
    return p;
}

/* The slot's array (from run_alloc, or NULL) back to the cache, or freed. */
static void run_free(run *R, int slot, void *p) {
    if (!p) return;
    if (R->keeper && R->out[slot].p == p) {
        lb__cache_run_keep(R->keeper, slot, p, R->out[slot].bytes);
        R->out[slot].p = NULL;
    } else {
        free(p);
    }
}

/* L's blocks in order of id (the descent leaves them in octree order):
 * their keys sorted, then each block moved once (qsort over the blocks
 * themselves, 392 bytes each, was 4 % of an incremental run of 28,664
 * blocks; this is 1 %). 0 when out of memory (L unchanged). */
static int sort_blocks(run *R, blist *L) {
    if (L->n < 2) return 1;
    bkey *k = run_alloc(R, RS_KEYS, L->n * sizeof *k, 0);
    lb__block *b = run_alloc(R, RS_SORTED, L->n * sizeof *b, 0);
    if (!k || !b) {
        run_free(R, RS_KEYS, k);
        run_free(R, RS_SORTED, b);
        return 0;
    }
    if (!R->keeper) { /* else run_alloc advised them when new */
        lb__huge_pages(k, L->n * sizeof *k);
        lb__huge_pages(b, L->n * sizeof *b);
    }
    for (size_t i = 0; i < L->n; ++i) {
        k[i].id = L->b[i].id;
        k[i].at = i;
    }
    qsort(k, L->n, sizeof *k, cmp_bkey);
    for (size_t i = 0; i < L->n; ++i) b[i] = L->b[k[i].at];
    run_free(R, RS_KEYS, k);
    free(L->b);
    L->b = b;
    L->cap = L->n;
    return 1;
}

static lb__block *find_block(run *R, const uint32_t b[3]) {
    const uint64_t id = lb__block_id(R->nb, b[0], b[1], b[2]);
    const size_t lo =
        lb__lower_id(R->blocks, R->nblocks, sizeof *R->blocks, offsetof(lb__block, id), id);
    return lo < R->nblocks && R->blocks[lo].id == id ? &R->blocks[lo] : NULL;
}

/* phi_c's interval over nodes [n0, n1] with phi from an interval pass
 * restricted by the enclosing box's plan (lb__bounds_pass_sub); child (may
 * be NULL) receives this box's own plan. */
static void sub_phi(const lb_evaluator *ev, const lb__grid *g, const lb__plan *plan, lb__iv *R,
                    const uint64_t n0[3], const uint64_t n1[3], lb__plan *child, double *lo,
                    double *hi) {
    double bl[3], bh[3], bc[3], br[3];
    lb__node_pos(g, n0[0], n0[1], n0[2], bl);
    lb__node_pos(g, n1[0], n1[1], n1[2], bh);
    lb__box_centre(bl, bh, bc, br);
    lb__bounds_pass_sub(ev, plan, bc, br, R, child);
    phi_interval(g, bl, bh, R[ev->out].lo, R[ev->out].hi, lo, hi);
}

/* Inside a kept block, the sub-boxes of at most 2^3 cells whose interval
 * may contain 0: their cells and corner nodes are marked; nothing else of
 * the block is evaluated (no cell outside them can cross the surface). A box
 * is cut into up to eight (every side over 2 cells halved at once: 8^3,
 * 4^3, 2^3). Cutting one side at a time pruned too little at each level to
 * pay for its passes (75-90 % of the boxes went on, S2 at 256 cells;
 * 151,000 passes per mesh against 110,000). A box that is cut hands its own
 * plan (pool[depth]) to its children, so deeper passes look only at the
 * arguments that survived above them (pool NULL: every box under the
 * block's plan). */
static void mark(run *R, lb__block *B, const lb__plan *plan, lb__iv *IV, const uint32_t s0[3],
                 const uint32_t s1[3], lb__plan *pool, int depth, lb__plan *given) {
    const lb__grid *g = R->g;
    uint64_t n0[3], n1[3];
    for (int d = 0; d < 3; ++d) {
        n0[d] = (uint64_t)B->b[d] * LB__MB + s0[d];
        n1[d] = (uint64_t)B->b[d] * LB__MB + s1[d];
    }
    /* every side over 2 cells is halved at once: up to 8 children */
    int split = 0;
    uint32_t mid[3];
    for (int d = 0; d < 3; ++d) {
        mid[d] = s0[d] + (s1[d] - s0[d]) / 2;
        if (s1[d] - s0[d] > 2) split |= 1 << d;
    }
    /* given: this box's plan is kept by the caller (an octant's) */
    lb__plan *own = !split                           ? NULL
                    : given                          ? given
                    : pool && depth < LB__MARK_DEPTH ? &pool[depth]
                                                     : NULL;
    double lo, hi;
    sub_phi(R->ev, g, plan, IV, n0, n1, own, &lo, &hi);
    if (lo >= 0.0 || hi < 0.0) return;
    if (split) {
        const lb__plan *next = own ? own : plan;
        for (int c = 0; c < 8; ++c) {
            if (c & ~split) continue;
            uint32_t c0[3], c1[3];
            for (int d = 0; d < 3; ++d) {
                const int cut = (split >> d) & 1, up = (c >> d) & 1;
                c0[d] = cut && up ? mid[d] : s0[d];
                c1[d] = cut && !up ? mid[d] : s1[d];
            }
            mark(R, B, next, IV, c0, c1, pool, depth + 1, NULL);
        }
        return;
    }
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    for (uint32_t k = s0[2]; k <= s1[2]; ++k)
        for (uint32_t j = s0[1]; j <= s1[1]; ++j)
            for (uint32_t i = s0[0]; i <= s1[0]; ++i) {
                B->nmask[((size_t)k * D1 + j) * D0 + i] = 1;
                if (i < s1[0] && j < s1[1] && k < s1[2])
                    B->cmask[((size_t)k * B->nc[1] + j) * B->nc[0] + i] = 1;
            }
}

/* One block's node data in its slot: values, gradients, the near-face
 * table (extract.c), node and cell marks and the table's written bits, for
 * the largest block (LB__MB^3 cells). */
#define SLAB_NODES LB__SLAB_NODES
#define FTAB_OFFSET (SLAB_NODES * 4 * sizeof(double))
#define MASK_OFFSET (FTAB_OFFSET + LB__FACE_ENTRIES * sizeof(lb__fent))
#define FVALID_BYTES ((LB__FACE_ENTRIES + 7) / 8)
#define NODE_BYTES                                                                                 \
    ((MASK_OFFSET + SLAB_NODES + LB__MB * LB__MB * LB__MB + FVALID_BYTES + 63) / 64 * 64)

/* A free slot (the most recently freed: still warm), or a new one; NULL
 * when out of memory. */
static unsigned char *slot_get(run *R) {
    unsigned char *p = NULL;
    pthread_mutex_lock(&R->lock);
    if (R->nfree) p = R->free[--R->nfree];
    pthread_mutex_unlock(&R->lock);
    if (p || !(p = malloc(NODE_BYTES))) return p;
    pthread_mutex_lock(&R->lock);
    R->all[R->nall++] = p; /* at most one slot per block was ever made */
    pthread_mutex_unlock(&R->lock);
    return p;
}

/* One reader of block i's node data is done; the last one frees its slot. */
static void slot_release(run *R, size_t i) {
    if (atomic_fetch_sub(&R->refs[i], 1) != 1) return;
    lb__block *B = &R->blocks[i];
    unsigned char *p = (unsigned char *)(void *)B->vals;
    B->vals = B->grads = NULL;
    B->nmask = B->cmask = B->fvalid = NULL;
    B->ftab = NULL;
    if (!p) return;
    pthread_mutex_lock(&R->lock);
    R->free[R->nfree++] = p;
    pthread_mutex_unlock(&R->lock);
}

/* Block B's node data in slot base: marks and the table's written bits
 * cleared. */
static void slot_setup(lb__block *B, unsigned char *base) {
    const size_t n = (size_t)(B->nc[0] + 1) * (B->nc[1] + 1) * (B->nc[2] + 1);
    B->vals = (double *)(void *)base;
    B->grads = B->vals + SLAB_NODES;
    B->ftab = (lb__fent *)(void *)(base + FTAB_OFFSET);
    B->nmask = base + MASK_OFFSET;
    B->cmask = B->nmask + SLAB_NODES;
    B->fvalid = B->cmask + LB__MB * LB__MB * LB__MB;
    memset(B->nmask, 0, n);
    memset(B->cmask, 0, (size_t)B->nc[0] * B->nc[1] * B->nc[2]);
    memset(B->fvalid, 0, FVALID_BYTES);
}

/* The node values of a block: its plan (from the block selection's
 * descent), mark() with sub-box passes under that plan, then the marked
 * nodes evaluated octant by octant under the octants' plans (or the block's
 * own, for few primitives). */
static lb_status block_nodes(run *R, lb__block *B, lb__mscratch *S, lb_error *err) {
    const lb__grid *g = R->g;
    const lb_evaluator *ev = R->ev;
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1, D2 = B->nc[2] + 1;
    const size_t n = (size_t)D0 * D1 * D2;
    unsigned char *base = slot_get(R);
    if (!base) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    /* a reused slot was last written about a layer of blocks ago (out of
     * the core's cache): fetch it for writing while mark() runs, instead of
     * stalling on the scattered stores of the node values below */
    for (size_t off = 0; off < FTAB_OFFSET; off += 64) __builtin_prefetch(base + off, 1, 3);
    slot_setup(B, base);
    lb__boxeval *E = &S->E;
    lb__boxeval_load(ev, &B->plan, E);
    const uint32_t zero[3] = {0, 0, 0};
    /* few primitives: no narrower plans (LB__NARROW_MIN_PRIMS), here or below;
     * each split box's pass fills its depth's plan whole (no copy needed) */
    const int narrow = lb__plan_prims(ev, &E->plan) >= LB__NARROW_MIN_PRIMS;
    /* a block of at least 6 cells a side starts at its octants (the block
     * passed its interval test in the selection): their passes' plans are
     * the octant plans of the node values and the refinement, so no octant
     * is passed twice */
    const uint32_t half[3] = {B->nc[0] / 2, B->nc[1] / 2, B->nc[2] / 2};
    const int octs = narrow && B->nc[0] >= 6 && B->nc[1] >= 6 && B->nc[2] >= 6;
    if (octs) {
        for (int o = 0; o < 8; ++o) {
            uint32_t l0[3], l1[3];
            lb__octant_nodes(B, o, l0, l1);
            mark(R, B, &E->plan, E->iv, l0, l1, S->pool, 1, &S->oct[o]);
        }
        if (!(B->octmem = lb__cplan_pack(ev, S->oct, 8, B->oct)))
            return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    } else {
        mark(R, B, &E->plan, E->iv, zero, B->nc, narrow ? S->pool : NULL, 0, NULL);
    }
    if (lb__two_level_block(g, B)) {
        /* coarse first (extract.c): now only the coarse cells' corners and
         * the nodes on the block's boundary planes (what block_share and
         * the cache read); the others marked are left for the extraction
         * (2: marked, not yet evaluated) */
        for (uint32_t k = 0; k < D2; ++k)
            for (uint32_t j = 0; j < D1; ++j)
                for (uint32_t i = 0; i < D0; ++i) {
                    const size_t q = ((size_t)k * D1 + j) * D0 + i;
                    const int even = !(i & 1) && !(j & 1) && !(k & 1);
                    const int plane =
                        !i || !j || !k || i == B->nc[0] || j == B->nc[1] || k == B->nc[2];
                    if (B->nmask[q] && !even && !plane) B->nmask[q] = 2;
                }
    }
    size_t m = 0;
    for (size_t q = 0; q < n; ++q) m += B->nmask[q] == 1;
    if (m == 0) return LB_OK;
    /* m <= LB__SLAB_NODES: the thread's scratch holds the batch */
    double *x = S->nodes, *y = x + m, *z = y + m, *v = z + m, *gx = v + m, *gy = gx + m,
           *gz = gy + m;
    size_t *idx = S->nidx;
    lb_status s = LB_OK;
    /* the nodes by octant (nodes up to the middle one in the low half), each
     * octant evaluated under its own, tighter plan: a block's interval pass
     * keeps every argument that may matter somewhere in the block, an
     * octant's about half as many on a lattice of spheres. A plan that runs
     * few primitives gains too little to pay for eight more passes: then
     * the block is one group under its own plan. */
    const int ngroups = narrow ? 8 : 1;
    size_t start[9] = {0}, w = 0;
    for (int o = 0; o < ngroups; ++o) {
        uint32_t r0[3], r1[3]; /* the group's node range, inclusive */
        for (int d = 0; d < 3; ++d) {
            r0[d] = narrow && (o >> d) & 1 ? half[d] + 1 : 0;
            r1[d] = narrow && !((o >> d) & 1) ? half[d] : B->nc[d];
        }
        start[o] = w;
        for (uint32_t k = r0[2]; k <= r1[2]; ++k)
            for (uint32_t j = r0[1]; j <= r1[1]; ++j)
                for (uint32_t i = r0[0]; i <= r1[0]; ++i) {
                    const size_t q = ((size_t)k * D1 + j) * D0 + i;
                    if (B->nmask[q] != 1) continue;
                    double X[3];
                    lb__node_pos(g, (uint64_t)B->b[0] * LB__MB + i, (uint64_t)B->b[1] * LB__MB + j,
                                 (uint64_t)B->b[2] * LB__MB + k, X);
                    x[w] = X[0];
                    y[w] = X[1];
                    z[w] = X[2];
                    idx[w++] = q;
                }
    }
    start[ngroups] = w;
    if (narrow && !octs) lb__plan_load(ev, &E->plan, &S->outer);
    for (int o = 0; o < ngroups && !s; ++o) {
        const size_t c = start[o + 1] - start[o];
        if (!c) continue;
        if (octs)
            lb__plan_load(ev, &S->oct[o], &E->plan);
        else if (narrow)
            lb__octant_narrow(ev, g, B, o, &S->outer, E);
        const size_t a = start[o];
        s = lb__boxeval_run(ev, E, c, x + a, y + a, z + a, v + a, gx + a, gy + a, gz + a, err);
    }
    const double boxmax = lb__block_boxmax(g, B);
    for (size_t i = 0; i < m && !s; ++i) {
        const double X[3] = {x[i], y[i], z[i]}, gf[3] = {gx[i], gy[i], gz[i]};
        B->vals[idx[i]] = lb__mesh_phi_in(g, boxmax, X, v[i], gf, B->grads + 3 * idx[i]);
    }
    return s;
}

/* Far-face nodes take the value and gradient of the block that owns them
 * (block i's next blocks, whose node values are done). They read only
 * nodes that their owner never overwrites: every axis on which such a node
 * is on the owner's far face is one without a next block. */
static void block_share(run *R, size_t bi) {
    lb__block *B = &R->blocks[bi];
    const lb__block *next[8] = {NULL};
    for (int c = 1; c < 8; ++c) next[c] = R->nbr[bi][c] ? &R->blocks[R->nbr[bi][c] - 1] : NULL;
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    /* node l takes next[c]'s node where c holds the axes on which l is on the
     * far face and a next block exists in the grid: the region of c is
     * l[d] = LB__MB on c's axes and below it (or up to nc where the grid
     * ends) on the others */
    for (int c = 1; c < 8; ++c) {
        const lb__block *O = next[c];
        if (!O) continue;
        uint32_t lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            const int far = B->b[d] + 1 < R->nb[d];
            lo[d] = (c >> d) & 1 ? LB__MB : 0;
            hi[d] = (c >> d) & 1 ? LB__MB : far ? LB__MB - 1 : B->nc[d];
        }
        const uint32_t E0 = O->nc[0] + 1, E1 = O->nc[1] + 1;
        for (uint32_t k = lo[2]; k <= hi[2]; ++k)
            for (uint32_t j = lo[1]; j <= hi[1]; ++j)
                for (uint32_t i = lo[0]; i <= hi[0]; ++i) {
                    const uint32_t oi = c & 1 ? 0 : i, oj = c & 2 ? 0 : j, ok = c & 4 ? 0 : k;
                    const size_t mine = ((size_t)k * D1 + j) * D0 + i,
                                 theirs = ((size_t)ok * E1 + oj) * E0 + oi;
                    /* a node only one side evaluated is used only by that
                     * side: the other side's interval proved its cells there
                     * do not cross */
                    if (!B->nmask[mine] || !O->nmask[theirs]) continue;
                    B->vals[mine] = O->vals[theirs];
                    memcpy(B->grads + 3 * mine, O->grads + 3 * theirs, 3 * sizeof(double));
                }
    }
}

/* Wake the threads waiting for a next block to be done (or for stop): a new
 * generation, under the lock the waiters check it with. */
static void wake(run *R) {
    pthread_mutex_lock(&R->wm);
    atomic_fetch_add(&R->gen, 1);
    pthread_cond_broadcast(&R->wc);
    pthread_mutex_unlock(&R->wm);
}

/* ---- merge ----
 * Blocks are merged from the last to the first, each as soon as it and
 * every block after it is done: its output is still in cache, and its
 * memory serves the blocks after it instead of fresh pages. A block's own
 * vertices are appended; a reference (extract.c) names a vertex of a next
 * block, merged before it, by that block's first mesh vertex plus its
 * index; orphans are shared by their grid edge key through a hash table
 * (the first block merged keeps its copy). The order is fixed, so the
 * output is the same for every thread count. Whoever finishes a block
 * merges what is ready (try_merge, never waiting for the lock); the calling
 * thread merges the rest after the workers are joined. */

/* n and a sixteenth more: the room a mesh made through a cache starts with
 * (the cached mesh's counts) and keeps (lb_mesh_cache_recycle gives it
 * back), so that the next run's output mostly fits without growing. */
static size_t with_room(size_t n) {
    return n + n / 16;
}

/* The mesh arrays' first capacity, in bytes: glibc serves an allocation
 * this large by mmap whatever its dynamic threshold (at most 32 MiB on
 * 64-bit systems), so the pages not written cost no memory and the final
 * shrink is in place. Growing from small sizes copied (and faulted in) the
 * arrays about twice: 4.5 % of S2's time at 256 cells. */
#define FIRST_BYTES ((size_t)32 << 20)

/* A capacity (elements of sz bytes) of at least need, doubling cap; the
 * first one at least hint (the cached mesh's size: a mesh through a cache
 * mostly fits without growing). */
static size_t doubled(size_t cap, size_t need, size_t sz, size_t hint) {
    size_t c = cap ? cap : FIRST_BYTES / sz > hint ? FIRST_BYTES / sz : hint;
    while (c < need) c *= 2;
    return c;
}

/* The home slot of an orphan's key in a table of cap (a power of 2) slots;
 * collisions go on to the next slots. */
static size_t tab_slot(uint64_t key, size_t cap) {
    return (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (cap - 1);
}

/* A table of cap (a power of 2) slots for at least n keys, half full at most:
 * the old entries moved over. */
static int tab_fit(mstate *S, size_t n) {
    if (2 * n <= S->cap) return 1;
    size_t cap = S->cap ? S->cap : 1024;
    while (cap < 2 * n) cap *= 2;
    mkv *t = calloc(cap, sizeof *t);
    if (!t) return 0;
    for (size_t i = 0; i < S->cap; ++i) {
        if (!S->tab[i].key) continue;
        size_t h = tab_slot(S->tab[i].key, cap);
        while (t[h].key) h = (h + 1) & (cap - 1);
        t[h] = S->tab[i];
    }
    free(S->tab);
    S->tab = t;
    S->cap = cap;
    return 1;
}

/* Block B's output arrays, unless the cache's (pointers left as they are). */
static void output_free(lb__block *B) {
    if (B->borrowed) return;
    free(B->okey);
    free(B->rref);
    free(B->vpos);
    free(B->vnrm);
    free(B->tri);
}

/* Block bi's output appended to the mesh, then freed. 0 on failure (S->s). */
static int merge_block(mstate *S, lb__block *B, size_t bi) {
    lb_mesh *M = S->M;
    const size_t no = B->nv - B->np; /* orphans */
    if (M->nvertices + B->nv > UINT32_MAX) {
        S->s = lb__fail(&S->err, LB_ERR_NO_MEMORY,
                        "%s: more than %u vertices; allowed: fewer (a coarser resolution)", FN,
                        UINT32_MAX);
        return 0;
    }
    const size_t vc = doubled(S->vcap, M->nvertices + B->nv, 3 * sizeof(double), S->vhint),
                 tc = doubled(S->tcap, M->ntriangles + B->nt, 3 * sizeof(uint32_t), S->thint);
    /* written page by page once: huge pages fault far less (grow) */
    const int ok = grow((void **)&M->positions, S->vcap, vc, M->nvertices, 3 * sizeof(double)) &&
                   grow((void **)&M->normals, S->vcap, vc, M->nvertices, 3 * sizeof(double)) &&
                   grow((void **)&M->triangles, S->tcap, tc, M->ntriangles, 3 * sizeof(uint32_t));
    if (M->positions && M->normals) S->vcap = vc; /* both grown (or neither needed to) */
    if (ok) S->tcap = tc;
    if (ok && B->nv + B->nref > S->xcap) {
        const size_t c = 2 * (B->nv + B->nref);
        uint32_t *q = malloc(c * sizeof *q);
        if (q) {
            free(S->xt);
            S->xt = q;
            S->xcap = c;
        }
    }
    if (!ok || B->nv + B->nref > S->xcap || (no && !tab_fit(S, S->used + no))) {
        S->s = lb__fail(&S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        return 0;
    }
    /* the block's own vertices are the mesh's next ones */
    const size_t base = M->nvertices;
    S->base[bi] = (uint32_t)base;
    if (B->nfeat) {
        if (!room_for((void **)&S->fr, &S->frcap, S->nfr, 2 * sizeof *S->fr, 64)) {
            S->s = lb__fail(&S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
            return 0;
        }
        S->fr[2 * S->nfr] = base + B->np - B->nfeat;
        S->fr[2 * S->nfr + 1] = B->nfeat;
        ++S->nfr;
        if (!room_for((void **)&S->ftr, &S->ftrcap, S->nftr, 2 * sizeof *S->ftr, 64)) {
            S->s = lb__fail(&S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
            return 0;
        }
        S->ftr[2 * S->nftr] = M->ntriangles;
        S->ftr[2 * S->nftr + 1] = B->nt;
        ++S->nftr;
    }
    if (B->np) { /* a block may have no vertex (and no arrays) */
        memcpy(M->positions + 3 * base, B->vpos, 3 * B->np * sizeof(double));
        memcpy(M->normals + 3 * base, B->vnrm, 3 * B->np * sizeof(double));
    }
    /* each local vertex u's mesh vertex (xt): own (u < np) the mesh's next
     * ones, an orphan through the table, a reference (u >= nown) a vertex of
     * a block merged before this one; then every triangle index through xt
     * (one load each from a table in the core's cache: the three cases in
     * one loop were mispredicted often) */
    uint32_t *xt = S->xt;
    const uint32_t np = (uint32_t)B->np, nown = (uint32_t)B->nv, b32 = (uint32_t)base;
    for (uint32_t u = 0; u < np; ++u) xt[u] = b32 + u;
    size_t nv = base + B->np;
    for (size_t i = 0; i < no; ++i) {
        const uint64_t key = B->okey[i];
        const size_t cap = S->cap;
        size_t h = tab_slot(key, cap);
        while (S->tab[h].key && S->tab[h].key != key) h = (h + 1) & (cap - 1);
        if (!S->tab[h].key) {
            S->tab[h].key = key;
            S->tab[h].v = nv;
            ++S->used;
            memcpy(M->positions + 3 * nv, B->vpos + 3 * (B->np + i), 3 * sizeof(double));
            memcpy(M->normals + 3 * nv, B->vnrm + 3 * (B->np + i), 3 * sizeof(double));
            ++nv;
        }
        xt[np + i] = (uint32_t)S->tab[h].v;
    }
    for (size_t r = 0; r < B->nref; ++r) {
        const uint32_t *q = B->rref + 2 * r;
        /* a cached block names the next block by its offset code */
        xt[nown + r] = S->base[B->borrowed ? S->nbr[bi][q[0]] - 1 : q[0]] + q[1];
    }
    uint32_t *T = M->triangles + 3 * M->ntriangles;
    const uint32_t *src = B->tri;
    const size_t ni = 3 * B->nt;
    for (size_t t = 0; t < ni; ++t) T[t] = xt[src[t]];
    M->ntriangles += B->nt;
    M->nvertices = nv;
    if (S->keep && !B->borrowed) { /* the cache takes the output */
        lb__cblock *E = &S->keep[bi];
        for (size_t r = 0; r < B->nref; ++r)
            for (int c = 1; c < 8; ++c)
                if (S->nbr[bi][c] == B->rref[2 * r] + 1) {
                    B->rref[2 * r] = (uint32_t)c;
                    break;
                }
        E->nv = B->nv;
        E->np = B->np;
        E->nref = B->nref;
        E->nt = B->nt;
        E->nfeat = B->nfeat;
        E->okey = B->okey;
        E->rref = B->rref;
        E->vpos = B->vpos;
        E->vnrm = B->vnrm;
        E->tri = B->tri;
        B->okey = NULL;
        B->rref = NULL;
        B->vpos = B->vnrm = NULL;
        B->tri = NULL;
        return 1;
    }
    /* merged: the block's copy goes (its memory serves the next blocks);
     * one taken from the cache stays there */
    output_free(B);
    B->okey = NULL;
    B->rref = NULL;
    B->vpos = B->vnrm = NULL;
    B->tri = NULL;
    return 1;
}

/* Merge the blocks that are next in order and done, unless another thread
 * is merging (it will see them, or the final sweep will). */
static void try_merge(run *R) {
    mstate *S = &R->ms;
    for (;;) {
        if (pthread_mutex_trylock(&R->mlock)) return;
        while (R->mnext < R->nblocks && !S->s) {
            const size_t i = R->nblocks - 1 - R->mnext;
            if (!atomic_load(&R->fin[i])) break;
            if (!merge_block(S, &R->blocks[i], i)) {
                atomic_store(&R->stop, 1);
                wake(R);
                break;
            }
            ++R->mnext;
        }
        const int again =
            !S->s && R->mnext < R->nblocks && atomic_load(&R->fin[R->nblocks - 1 - R->mnext]);
        pthread_mutex_unlock(&R->mlock);
        if (!again) return;
    }
}

static void fail_block(run *R, size_t i, const lb_error *e) {
    pthread_mutex_lock(&R->lock);
    if (i < R->err_block) {
        R->err_block = i;
        R->err = *e;
    }
    pthread_mutex_unlock(&R->lock);
    atomic_store(&R->stop, 1);
    wake(R);
}

/* Block i's node values; 0 when they failed (the run stops). Its next
 * blocks' values may not be done yet: finish_block waits for them. */
static int start_block(run *R, size_t i, size_t t) {
    lb_error e = {LB_OK, ""};
    if (R->from && R->from[i]) { /* from the cache: what the blocks before it read */
        lb__block *B = &R->blocks[i];
        lb_status s = LB_OK;
        if (R->want[i]) {
            unsigned char *base = slot_get(R);
            if (!base) {
                s = lb__fail(&e, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
                fail_block(R, i, &e);
            } else {
                slot_setup(B, base);
                lb__cache_import(R->from[i], B);
            }
        }
        atomic_store(&R->ready[i], 1);
        wake(R);
        return !s;
    }
    /* the +z block's near face, read by block_share right after this block's
     * node values, was computed about a layer of blocks ago: fetch it now
     * (its node data is readable once it is ready) */
    const uint32_t up = R->nbr[i][4];
    if (up && atomic_load(&R->ready[up - 1])) {
        const lb__block *O = &R->blocks[up - 1];
        const size_t face = (size_t)(O->nc[0] + 1) * (O->nc[1] + 1);
        if (O->vals) {
            for (size_t off = 0; off < face * sizeof(double); off += 64)
                __builtin_prefetch((const char *)O->vals + off, 0, 3);
            for (size_t off = 0; off < 3 * face * sizeof(double); off += 64)
                __builtin_prefetch((const char *)O->grads + off, 0, 3);
            for (size_t off = 0; off < face; off += 64) __builtin_prefetch(O->nmask + off, 0, 3);
        }
    }
    const lb_status s = block_nodes(R, &R->blocks[i], lb__bctx_scratch(R->ctx[t]), &e);
    if (s) fail_block(R, i, &e); /* stop is set before ready: a waiter sees both */
    atomic_store(&R->ready[i], 1);
    wake(R);
    return !s;
}

/* May block i hold a node slot? Not when it comes from the cache and no
 * computed block reads it (start_block gives it none: its reader count is
 * never needed). */
static int has_slot(const run *R, size_t i) {
    return !(R->from && R->from[i] && !R->want[i]);
}

/* Block i's output from its cached entry (the arrays borrowed; its
 * references name next blocks by offset code, which the merge reads
 * through nbr: the rule checked that those blocks are kept). */
static void take_cached(run *R, size_t i) {
    lb__block *B = &R->blocks[i];
    const lb__cblock *E = R->from[i];
    B->nv = E->nv;
    B->np = E->np;
    B->nref = E->nref;
    B->nt = E->nt;
    B->nfeat = E->nfeat;
    B->okey = E->okey;
    B->vpos = E->vpos;
    B->vnrm = E->vnrm;
    B->tri = E->tri;
    B->rref = E->rref;
    B->borrowed = 1;
}

/* Are block i's next blocks done (their output and near-face tables)? */
static int next_done(run *R, size_t i) {
    for (int c = 1; c < 8; ++c)
        if (R->nbr[i][c] && !atomic_load(&R->fin[R->nbr[i][c] - 1])) return 0;
    return 1;
}

/* Block i on thread t, once its next blocks are done: its far-face nodes,
 * then its extraction while its node data is in cache (taking the next
 * blocks' vertices on its far faces from their tables), then the merge of
 * what is ready. */
static void finish_block(run *R, size_t i, size_t t) {
    lb_error e = {LB_OK, ""};
    lb__block *B = &R->blocks[i];
    int ok = 1;
    if (R->from && R->from[i]) {
        take_cached(R, i);
    } else {
        block_share(R, i);
        int gnext = 0;
        for (int d = 0; d < 3; ++d) gnext |= (B->b[d] + 1 < R->nb[d]) << d;
        ok = !lb__mesh_block(R->ev, R->g, B, R->blocks, R->nbr[i], gnext, R->ctx[t], &e);
        /* the cache keeps what the blocks before it read */
        if (ok && R->cache && !lb__cache_export(B, &R->ms.keep[i]))
            ok = !lb__fail(&e, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    if (!ok) fail_block(R, i, &e);
    for (int c = 1; c < 8; ++c)
        if (R->nbr[i][c] && has_slot(R, R->nbr[i][c] - 1)) slot_release(R, R->nbr[i][c] - 1);
    if (has_slot(R, i)) slot_release(R, i);
    if (R->cache) { /* the cache keeps the plan */
        R->ms.keep[i].plan = B->plan;
        memset(&B->plan, 0, sizeof B->plan);
    }
    plan_drop(B);
    free(B->octmem);
    B->octmem = NULL;
    atomic_fetch_add(&R->done, 1);
    if (!ok) return;
    atomic_store(&R->fin[i], 1);
    /* a thread waiting for a next block of its own may go on */
    wake(R);
    try_merge(R);
}

static int stopped(run *R) {
    if (atomic_load(&R->stop)) return 1;
    if (R->cancel && *R->cancel) {
        atomic_store(&R->stop, 1);
        wake(R);
        return 1;
    }
    return 0;
}

typedef struct progress {
    lb_mesh_progress_fn fn;
    void *user;
    double base, weight;
    int cancelled;
} progress;

/* The next block to take, from the last to the first; SIZE_MAX when none. */
static size_t take(run *R) {
    const size_t k = atomic_fetch_add(&R->next, 1);
    return k < R->nblocks ? R->nblocks - 1 - k : SIZE_MAX;
}

/* Blocks whose node values are done, waiting for their next blocks to be
 * done (at most this many per thread: each holds a slot). */
#define PENDING_MAX 4

/* One thread's share of the blocks: take a block and compute its node
 * values; finish every taken block whose next blocks are done. A thread
 * waits only when PENDING_MAX blocks (or, at the end, all it has left)
 * wait for other threads' blocks. Nothing waits in a cycle: a block waits
 * only on blocks after it, which were taken before it; the last block not
 * done has every block after it done, and its thread (which took it, and
 * computed its node values before waiting) finishes it at its next look,
 * which the gen count guarantees. P (the calling thread's only) reports
 * progress and may cancel. */
static void work(run *R, size_t t, progress *P) {
    size_t pend[PENDING_MAX];
    size_t np = 0;
    int more = 1;
    const double all = (double)(R->nblocks ? R->nblocks : 1);
    while (!stopped(R)) {
        if (P && P->fn) {
            /* the fraction first: weight * 1.0 is weight, so the last report
             * is the base the next stage starts from, not an ulp above it */
            const double f = P->base + P->weight * ((double)atomic_load(&R->done) / all);
            if (P->fn(f, P->user)) {
                P->cancelled = 1;
                atomic_store(&R->stop, 1);
                wake(R);
                break;
            }
        }
        const unsigned long gen = atomic_load(&R->gen); /* before looking */
        size_t k = 0;
        for (size_t q = 0; q < np; ++q) {
            if (next_done(R, pend[q]))
                finish_block(R, pend[q], t);
            else
                pend[k++] = pend[q];
        }
        np = k;
        if (more && np < PENDING_MAX) {
            const size_t i = take(R);
            if (i == SIZE_MAX)
                more = 0;
            else if (start_block(R, i, t))
                pend[np++] = i;
            continue;
        }
        if (!np) break;
        /* every pending block waits on other threads: wait until a block is
         * done (or the run stops), then look again */
        pthread_mutex_lock(&R->wm);
        while (atomic_load(&R->gen) == gen && !atomic_load(&R->stop))
            pthread_cond_wait(&R->wc, &R->wm);
        pthread_mutex_unlock(&R->wm);
    }
}

typedef struct wctx {
    run *R;
    size_t t;
} wctx;

static void *worker(void *arg) {
    const wctx *W = arg;
    work(W->R, W->t, NULL);
    return NULL;
}

/* Which blocks the cache gives (cache.c states the rule): block i when its
 * plan and those of the blocks at offsets 0..2 on each axis are the cached
 * ones, content for content, and the same of those blocks are kept; and
 * which of them computed blocks read (want). The two block lists are both
 * sorted by id: one walk pairs them, and each changed place (a block kept
 * in one mesh only, or with another plan) rules out the blocks up to two
 * before it on each axis. 0 when out of memory. */
static int decide(run *R) {
    const size_t n = R->nblocks;
    size_t nold = 0;
    const lb__cblock *old = lb__cache_blocks(R->cache, &nold);
    const lb__cblock **cand = run_alloc(R, RS_CAND, n * sizeof *cand, 1);
    uint64_t *changed = run_alloc(R, RS_CHANGED, (n + nold) * sizeof *changed, 0);
    uint32_t *scratch = run_alloc(R, RS_SCRATCH, lb__cmatch_scratch(R->match) * sizeof *scratch, 0);
    R->from = run_alloc(R, RS_FROM, n * sizeof *R->from, 1);
    R->want = run_alloc(R, RS_WANT, n, 1);
    if (!cand || !changed || !scratch || !R->from || !R->want) {
        run_free(R, RS_CAND, (void *)cand);
        run_free(R, RS_CHANGED, changed);
        run_free(R, RS_SCRATCH, scratch);
        return 0;
    }
    size_t nch = 0, j = 0;
    for (size_t i = 0; i < n; ++i) {
        const uint64_t id = R->blocks[i].id;
        while (j < nold && old[j].id < id) changed[nch++] = old[j++].id; /* old only */
        if (j < nold && old[j].id == id) cand[i] = &old[j++];
        /* a block carried by the selection has the cached plan (cache.c) */
        if (cand[i] && (R->blocks[i].carried || lb__cache_same_plan(R->cache, R->match, cand[i],
                                                                    &R->blocks[i].plan, scratch)))
            R->from[i] = cand[i];
        else
            changed[nch++] = id;
    }
    while (j < nold) changed[nch++] = old[j++].id;
    run_free(R, RS_SCRATCH, scratch);
    for (size_t q = 0; q < nch; ++q) {
        const uint64_t id = changed[q];
        const uint32_t p[3] = {(uint32_t)(id % R->nb[0]), (uint32_t)(id / R->nb[0] % R->nb[1]),
                               (uint32_t)(id / R->nb[0] / R->nb[1])};
        for (int c = 0; c < 27; ++c) {
            uint32_t b[3];
            int in = 1;
            for (int d = 0, w = c; d < 3; ++d, w /= 3) {
                in &= p[d] >= (uint32_t)(w % 3);
                b[d] = p[d] - (uint32_t)(w % 3);
            }
            const lb__block *O = in ? find_block(R, b) : NULL;
            if (O) R->from[O - R->blocks] = NULL;
        }
    }
    run_free(R, RS_CHANGED, changed);
    run_free(R, RS_CAND, (void *)cand);
    for (size_t i = 0; i < n; ++i) {
        if (R->from[i]) {
            ++R->nreused;
            continue;
        }
        for (int c = 1; c < 8; ++c)
            if (R->nbr[i][c]) R->want[R->nbr[i][c] - 1] = 1;
    }
    return 1;
}

/* Every block on nt threads (nt - 1 workers, fewer if the system refuses
 * threads: the calling thread works too and is the only one that reports
 * progress, between its own blocks). Nothing waits on a block taken later,
 * so the order of taking cannot deadlock. */
static lb_status blocks_run(run *R, size_t nt, progress *P) {
    if (nt > R->nctx) nt = R->nctx;
    const size_t nbk = R->nblocks;
    R->nbr = run_alloc(R, RS_NBR, nbk * sizeof *R->nbr, 1);
    R->ready = run_alloc(R, RS_READY, nbk * sizeof *R->ready, 1);
    R->refs = run_alloc(R, RS_REFS, nbk * sizeof *R->refs, 1);
    R->fin = run_alloc(R, RS_FIN, nbk * sizeof *R->fin, 1);
    R->ms.base = run_alloc(R, RS_BASE, nbk * sizeof *R->ms.base, 0);
    R->all = run_alloc(R, RS_ALL, nbk * sizeof *R->all, 0);
    R->free = run_alloc(R, RS_FREE, nbk * sizeof *R->free, 0);
    if (!R->nbr || !R->ready || !R->refs || !R->fin || !R->ms.base || !R->all || !R->free) {
        R->err_block = 0;
        return lb__fail(&R->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    for (size_t i = 0; i < nbk; ++i) {
        atomic_init(&R->ready[i], 0);
        atomic_init(&R->refs[i], 1);
        atomic_init(&R->fin[i], 0);
    }
    atomic_init(&R->gen, 0);
    /* the next blocks: for each offset c, the wanted ids grow with i (the
     * blocks are sorted by id), so one cursor per offset walks the ids
     * once, copied out of the 400-byte blocks (a binary search per block
     * and offset was 9 % of an incremental run of 28,664 blocks) */
    uint64_t *ids = run_alloc(R, RS_IDS, nbk * sizeof *ids, 0);
    if (!ids) {
        R->err_block = 0;
        return lb__fail(&R->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    for (size_t i = 0; i < nbk; ++i) ids[i] = R->blocks[i].id;
    size_t cur[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < nbk; ++i)
        for (int c = 1; c < 8; ++c) {
            int ok = 1;
            for (int d = 0; d < 3; ++d) ok &= R->blocks[i].b[d] + ((c >> d) & 1) < R->nb[d];
            if (!ok) continue;
            /* ids are linear in the coordinates: the offset's id added */
            const uint64_t id = ids[i] + lb__block_id(R->nb, c & 1, (c >> 1) & 1, c >> 2);
            size_t j = cur[c];
            while (j < nbk && ids[j] < id) ++j;
            cur[c] = j;
            if (j == nbk || ids[j] != id) continue;
            R->nbr[i][c] = (uint32_t)(j + 1);
            /* no other thread yet: a plain increment, not a locked one */
            atomic_store_explicit(&R->refs[j],
                                  atomic_load_explicit(&R->refs[j], memory_order_relaxed) + 1,
                                  memory_order_relaxed);
        }
    run_free(R, RS_IDS, ids);
    R->ms.nbr = R->nbr;
    if (R->match && !decide(R)) {
        R->err_block = 0;
        return lb__fail(&R->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    pthread_mutex_init(&R->wm, NULL);
    pthread_cond_init(&R->wc, NULL);
    pthread_t tid[256];
    wctx W[256];
    size_t nw = 0;
    for (size_t t = 1; t < nt && t < 256; ++t) {
        W[nw].R = R;
        W[nw].t = t;
        if (pthread_create(&tid[nw], NULL, worker, &W[nw]) != 0) break;
        ++nw;
    }
    work(R, 0, P);
    for (size_t t = 0; t < nw; ++t) pthread_join(tid[t], NULL);
    pthread_cond_destroy(&R->wc);
    pthread_mutex_destroy(&R->wm);
    P->base += P->weight;
    if (R->cancel && *R->cancel) P->cancelled = 1;
    return R->err_block != SIZE_MAX ? R->err.status : LB_OK;
}

/* Estimated bytes per kept block (node values, crossing edges, output). */
#define BLOCK_BYTES ((size_t)128 * 1024)

/* Does the surface at this resolution stay within max_blocks? (The block
 * selection alone: interval passes, stopped as soon as it is over.) */
static int fits(const lb_evaluator *ev, const lb_mesh_options *opt, unsigned res,
                size_t max_blocks) {
    lb_mesh_options o = *opt;
    o.resolution = res;
    o.cell_size = 0.0;
    lb__grid g;
    if (make_grid(ev, &o, &g, NULL)) return 0;
    uint32_t nb[3];
    for (int d = 0; d < 3; ++d) nb[d] = (g.cells[d] + LB__MB - 1) / LB__MB;
    blist L = {NULL, 0, 0};
    const lb_status s = select_all(ev, &g, nb, &L, max_blocks, 0, NULL, NULL);
    blist_free(&L);
    return s == LB_OK;
}

/* The largest resolution whose surface fits the memory cap, by bisection
 * on the block selection (about 13 selections, each stopped at the cap);
 * then confirmed upward, since the count is not strictly monotone. 0 when
 * even resolution 1 does not fit. */
static unsigned largest_fit(const lb_evaluator *ev, const lb_mesh_options *opt, size_t max_blocks) {
    if (!fits(ev, opt, 1, max_blocks)) return 0;
    unsigned lo = 1, hi = LB_MESH_MAX_CELLS_PER_AXIS; /* fits(lo); hi is the bound */
    while (lo < hi) {
        const unsigned mid = lo + (hi - lo + 1) / 2;
        if (fits(ev, opt, mid, max_blocks))
            lo = mid;
        else
            hi = mid - 1;
    }
    for (unsigned r = lo + 1; r <= lo + 8 && r <= LB_MESH_MAX_CELLS_PER_AXIS; ++r)
        if (fits(ev, opt, r, max_blocks)) lo = r;
    return lo;
}

lb_status lb_mesh_create(const lb_evaluator *ev, const lb_mesh_options *opt, lb_mesh **out,
                         lb_error *err) {
    return lb_mesh_create_cached(ev, opt, NULL, out, err);
}

lb_status lb_mesh_create_cached(const lb_evaluator *ev, const lb_mesh_options *opt,
                                lb_mesh_cache *cache, lb_mesh **out, lb_error *err) {
    if (out) *out = NULL;
    if (!ev || !opt || !out)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: ev, opt and out must be non-NULL", FN);
    if (opt->threads < 0)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: threads = %d; allowed: 0 (one per CPU) or a positive count", FN,
                        opt->threads);
    if (opt->flags &
        ~(unsigned)(LB_MESH_OPEN_BOUNDARY | LB_MESH_TETRAHEDRA | LB_MESH_FEATURES |
                    LB_MESH_CORNER_NORMALS | LB_MESH_MERGE_FLAT | LB_MESH_COARSE_FIRST))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: flags = %#x; allowed: 0 or LB_MESH_OPEN_BOUNDARY | "
                        "LB_MESH_TETRAHEDRA | LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS | "
                        "LB_MESH_MERGE_FLAT | LB_MESH_COARSE_FIRST",
                        FN, opt->flags);
    if (!(opt->simplify >= 0.0 && opt->simplify <= LB_MESH_MAX_SIMPLIFY))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: simplify = %g cells; allowed: 0 (off) to %g cells", FN, opt->simplify,
                        LB_MESH_MAX_SIMPLIFY);
    if ((opt->flags & LB_MESH_COARSE_FIRST) && !(opt->simplify > 0.0))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: LB_MESH_COARSE_FIRST with simplify = 0; allowed: a tolerance "
                        "above 0 (up to %g cells), which it meshes to",
                        FN, LB_MESH_MAX_SIMPLIFY);
    lb__grid g;
    lb_status s = make_grid(ev, opt, &g, err);
    if (s) return s;
    lb__mctable_init(&g.mc); /* extraction only: not in make_grid, which fits() calls */
    /* with sharp features, a local union's blending volume narrower than
     * LB__SHARP_BLEND cells is meshed as the sharp union it rounds: the
     * evaluator's copy for this mesh says so (docs/meshing.md, "Blends
     * below a cell") */
    lb_evaluator sharp;
    if (g.features && !g.tetrahedra) {
        sharp = *ev;
        sharp.sharp_below = LB__SHARP_BLEND * fmin(g.h[0], fmin(g.h[1], g.h[2]));
        ev = &sharp;
    }
    const size_t max_memory = opt->max_memory ? opt->max_memory : LB_MESH_DEFAULT_MAX_MEMORY;
    const size_t max_blocks = max_memory / BLOCK_BYTES;
    run R;
    memset(&R, 0, sizeof R);
    R.ev = ev;
    R.g = &g;
    R.cancel = opt->cancel;
    R.err_block = SIZE_MAX;
    for (int d = 0; d < 3; ++d) R.nb[d] = (g.cells[d] + LB__MB - 1) / LB__MB;
    progress P = {opt->progress, opt->user, 0.0, 0.05, 0};
    blist L = {NULL, 0, 0};
    /* with a cache: the matching of ev against it (cache.c), which the
     * selection uses for its boxes and the blocks for theirs */
    lb__cmatch *match = NULL;
    incsel inc = {cache, NULL, NULL, -1, NULL, 0, 0, 0};
    const int usable = cache && lb__cache_usable(cache, ev, &g);
    if (cache) {
        s = lb__cmatch_new(cache, ev, usable, &match, err);
        if (s) return s;
        inc.M = usable ? match : NULL;
        inc.depth = lb__box_depths(R.nb) - 1 - INC_LEVELS;
        if (inc.depth < 1) inc.depth = -1;
        inc.scratch = malloc(lb__cmatch_scratch(match) * sizeof *inc.scratch);
        if (!inc.scratch) {
            lb__cmatch_free(match);
            return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        }
    }
    s = select_all(ev, &g, R.nb, &L, max_blocks, 1, cache ? &inc : NULL, err);
    if (s == LB_ERR_NO_MEMORY && L.n >= max_blocks) {
        const unsigned fit = largest_fit(ev, opt, max_blocks);
        if (fit)
            s = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                         "%s: the surface crosses more than %zu blocks of %d^3 cells at %u x %u x "
                         "%u cells, over the memory cap of %zu MiB; allowed: a resolution of at "
                         "most %u (cells along the longest side; computed) or a larger max_memory",
                         FN, max_blocks, LB__MB, g.cells[0], g.cells[1], g.cells[2],
                         max_memory >> 20, fit);
        else
            s = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                         "%s: the surface crosses more than %zu blocks of %d^3 cells at %u x %u x "
                         "%u cells, over the memory cap of %zu MiB; allowed: a larger max_memory "
                         "(no resolution fits)",
                         FN, max_blocks, LB__MB, g.cells[0], g.cells[1], g.cells[2],
                         max_memory >> 20);
    }
    R.keeper = cache;
    if (!s && !sort_blocks(&R, &L)) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    size_t merged[2] = {0, 0}; /* the merged mesh's vertices and triangles, for the cache */
    if (!s && cache) {         /* each block's entry for the cache */
        R.cache = cache;
        R.ms.keep = calloc(L.n ? L.n : 1, sizeof *R.ms.keep);
        if (!R.ms.keep)
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        else
            lb__huge_pages(R.ms.keep, L.n * sizeof *R.ms.keep);
        if (usable) {
            lb__cache_counts(cache, &R.ms.vhint, &R.ms.thint);
            R.ms.vhint = with_room(R.ms.vhint);
            R.ms.thint = with_room(R.ms.thint);
            R.match = match;
        }
    }
    if (s) {
        free(R.ms.keep);
        blist_free(&L);
        lb__cmatch_free(match);
        lb__cnodes_free(inc.nodes, inc.n);
        free(inc.scratch);
        return s;
    }
    R.blocks = L.b;
    R.nblocks = L.n;
    pthread_mutex_init(&R.lock, NULL);
    pthread_mutex_init(&R.mlock, NULL);
    size_t nt = opt->threads == 0 ? lb__cpu_count() : (size_t)opt->threads;
    if (nt < 1) nt = 1;
    if (nt > R.nblocks) nt = R.nblocks ? R.nblocks : 1;
    if (P.fn && P.fn(0.05, P.user)) P.cancelled = 1;
    P.base = 0.05;
    lb_mesh *M = calloc(1, sizeof *M);
    R.ms.M = M;
    if (M && cache) /* a mesh given back: its mapped arrays take the output */
        lb__cache_take_spare(cache, M, &R.ms.vcap, &R.ms.tcap);
    if (nt > 256) nt = 256;
    R.ctx = calloc(nt, sizeof *R.ctx);
    if (R.ctx)
        for (R.nctx = 0; R.nctx < nt; ++R.nctx)
            if (!(R.ctx[R.nctx] = lb__bctx_new(ev))) break;
    if (!M || !R.ctx || R.nctx < nt) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    if (cache && g.coarse > 0.0) /* the decisions' scratch the last run kept */
        for (size_t t = 0; t < R.nctx; ++t) lb__bctx_tl_swap(R.ctx[t], lb__cache_tl_take(cache));
    /* with simplification, the blocks take the first half of the bar and
     * the simplification (often several times the meshing) the second */
    P.weight = opt->simplify > 0.0 && !(g.coarse > 0.0) ? 0.45 : 0.90;
    if (!s && !P.cancelled) s = blocks_run(&R, nt, &P);
    if (s && R.err_block != SIZE_MAX && err) *err = R.err;
    if (!s && !P.cancelled) {
        try_merge(&R); /* the blocks no worker merged */
        merged[0] = M->nvertices;
        merged[1] = M->ntriangles;
        s = R.ms.s;
        if (s && err) *err = R.ms.err;
        if (!s && R.mnext != R.nblocks) /* cannot happen: every block is done */
            s = lb__fail(err, LB_ERR_INTERNAL, "%s: %zu blocks not merged", FN,
                         R.nblocks - R.mnext);
    }
    uint8_t *feat = NULL; /* the feature points (features.c), for the flips and corners.c */
    if (!s && !P.cancelled && R.ms.nfr) { /* sharp features: join them (features.c) */
        feat = calloc(M->nvertices, 1);
        if (!feat) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        } else {
            for (size_t i = 0; i < R.ms.nfr; ++i)
                memset(feat + R.ms.fr[2 * i], 1, R.ms.fr[2 * i + 1]);
            s = lb__feature_flips(M, feat, R.ms.ftr, R.ms.nftr, err);
            if (!s)
                s = lb__feature_unfold(ev, &g, M, feat, R.ms.ftr, R.ms.nftr, (int)nt,
                                       lb__bctx_scratch(R.ctx[0]), err);
        }
    }
    if (!s && !P.cancelled && ((opt->flags & LB_MESH_MERGE_FLAT) || opt->simplify > 0.0) &&
        M->ntriangles) /* flat.c */
        s = lb__merge_flat(&g, M, feat, err);
    if (!s && !P.cancelled && opt->simplify > 0.0 && !(g.coarse > 0.0) &&
        M->ntriangles) /* simplify.c; coarse first: the blocks did it */
        s = lb__simplify(ev, &g, M, feat, opt->simplify, max_memory, (int)nt, opt->cancel, P.fn,
                         P.user, P.base, 0.95 - P.base, err);
    if (!s && !M->positions) { /* an empty mesh: valid, with (empty) arrays */
        M->positions = malloc(3 * sizeof *M->positions);
        M->normals = malloc(3 * sizeof *M->normals);
        M->triangles = malloc(3 * sizeof *M->triangles);
        if (!M->positions || !M->normals || !M->triangles)
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    if (!s) { /* the arrays' spare capacity goes, but through a cache
               * with_room's stays: given back (lb_mesh_cache_recycle) they
               * then take the next run's output without growing (grow) */
        /* never to 0 bytes: realloc(p, 0) may free p and return NULL */
        size_t nv = M->nvertices ? M->nvertices : 1, nt = M->ntriangles ? M->ntriangles : 1;
        if (cache) {
            nv = with_room(nv);
            nt = with_room(nt);
        }
        if (!cache || nv < R.ms.vcap) { /* only ever shrunk here */
            double *p = realloc(M->positions, 3 * nv * sizeof *p);
            if (p) M->positions = p;
            double *q = realloc(M->normals, 3 * nv * sizeof *q);
            if (q) M->normals = q;
        }
        if (!cache || nt < R.ms.tcap) {
            uint32_t *r = realloc(M->triangles, 3 * nt * sizeof *r);
            if (r) M->triangles = r;
        }
    }
    M->nnormals = M->nvertices;
    if (!s && !P.cancelled && feat && (opt->flags & LB_MESH_CORNER_NORMALS))
        s = lb__corner_normals(ev, &g, M, feat, (int)nt, err); /* shading per corner */
    free(feat);
    if (!s && P.cancelled) s = lb__fail(err, LB_ERR_CANCELLED, "%s: cancelled by the caller", FN);
    if (!s && cache) { /* the cache becomes this mesh's */
        for (size_t i = 0; i < R.nblocks; ++i) {
            lb__cblock *E = &R.ms.keep[i];
            const lb__cblock *of = R.blocks[i].plan_of; /* E's plan is its plan */
            if (R.from && R.from[i]) { /* moved over from the cached entry, with the new plan */
                lb__cblock *old = (lb__cblock *)(uintptr_t)R.from[i];
                const lb__cplan plan = E->plan;
                if (!of) lb__cplan_free(&old->plan); /* else of is old: the same memory */
                *E = *old;
                E->plan = plan;
                old->id = LB__CBLOCK_MOVED; /* what it held is E's */
            } else if (of) {                /* the plan's memory taken from the cached entry */
                memset(&((lb__cblock *)(uintptr_t)of)->plan, 0, sizeof of->plan);
            }
            E->id = R.blocks[i].id;
        }
        lb_error ce;
        const lb_status cs = lb__cache_commit(cache, match, &g, R.ms.keep, R.nblocks, R.nreused,
                                              merged, inc.nodes, inc.n, inc.depth, &ce);
        match = NULL;
        inc.nodes = NULL;
        inc.n = 0;
        if (cs) {
            /* out of memory for the records: the cache is emptied (the next
             * run meshes everything), the mesh is still good */
        }
        R.ms.keep = NULL;
    }
    if (!s && P.fn && P.fn(1.0, P.user)) {
        /* cancelling at 100 % is too late to matter: the mesh is done */
    }
    if (R.ms.keep) /* a failed run: the cache stays as it was (its plans too) */
        for (size_t i = 0; i < R.nblocks; ++i) {
            if (R.blocks[i].plan_of) memset(&R.ms.keep[i].plan, 0, sizeof R.ms.keep[i].plan);
            lb__cblock_free(&R.ms.keep[i]);
        }
    free(R.ms.keep);
    lb__cmatch_free(match);
    lb__cnodes_free(inc.nodes, inc.n);
    free(inc.scratch);
    run_free(&R, RS_FROM, (void *)R.from);
    run_free(&R, RS_WANT, R.want);
    for (size_t i = 0; i < R.nblocks; ++i) {
        lb__block *B = &R.blocks[i];
        output_free(B);
        free(B->octmem);
        plan_drop(B);
    }
    run_free(&R, RS_SORTED, R.blocks);
    for (size_t t = 0; t < R.nctx; ++t) {
        if (cache) lb__cache_tl_keep(cache, lb__bctx_tl_swap(R.ctx[t], NULL));
        lb__bctx_free(R.ctx[t]);
    }
    free(R.ctx);
    for (size_t i = 0; i < R.nall; ++i) free(R.all[i]);
    run_free(&R, RS_ALL, R.all);
    run_free(&R, RS_FREE, R.free);
    run_free(&R, RS_NBR, R.nbr);
    run_free(&R, RS_READY, (void *)R.ready);
    run_free(&R, RS_REFS, (void *)R.refs);
    run_free(&R, RS_FIN, (void *)R.fin);
    free(R.ms.tab);
    free(R.ms.fr);
    free(R.ms.ftr);
    run_free(&R, RS_BASE, R.ms.base);
    free(R.ms.xt);
    pthread_mutex_destroy(&R.lock);
    pthread_mutex_destroy(&R.mlock);
    if (s) {
        lb_mesh_free(M);
        return s;
    }
    for (int d = 0; d < 3; ++d) {
        M->origin[d] = g.origin[d];
        M->cell[d] = g.h[d];
        M->cells[d] = g.cells[d];
    }
    *out = M;
    return LB_OK;
}
