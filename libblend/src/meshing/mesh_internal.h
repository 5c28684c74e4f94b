/* Meshing internals (mesh.h is the contract; docs/meshing.md the method).
 *
 * Naming: the field meshed is phi, with phi < 0 inside in both conventions
 * (zero: phi = f; soft: phi = 0.5 - f), and, for a closed mesh, phi is
 * intersected with the region box: phi_c = max(phi, g), g the box's
 * distance-like function (negative inside). Grid nodes are (gx, gy, gz)
 * with linear index (gz * N[1] + gy) * N[0] + gx; a grid edge runs from a
 * node to the node + d, d a non-zero 0/1 offset given as a bit mask
 * (bit 0 = x, 1 = y, 2 = z), and its key is node index * 8 + mask. */
#ifndef LIBBLEND_MESH_INTERNAL_H
#define LIBBLEND_MESH_INTERNAL_H

#include "../common/internal.h"
#include "../evaluation/tape.h"

#include <libblend/mesh.h>

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define LB__MB 8      /* cells per block side */
#define LB__MAXPOLY 7 /* most vertices of one cell polygon (cubes: 7, tetrahedra: 4) */
/* with sharp features, a local union's blending volume of radius below this
 * many cells is meshed as the clean union (mesher.c) */
#define LB__SHARP_BLEND 0.25
/* nodes of the largest block */
#define LB__SLAB_NODES ((size_t)(LB__MB + 1) * (LB__MB + 1) * (LB__MB + 1))
/* crossing edges a block can have: one per node and axis mask (every
 * local edge id is distinct) */
#define LB__EMAP_SIZE (LB__SLAB_NODES * 8)
/* mark()'s levels that cut boxes: a block, then its 4^3 boxes (their
 * children, 2^3, are marked or not) */
#define LB__MARK_DEPTH 2

/* The cube cases (cubes.c): for each of the 256 inside/outside patterns of
 * a cell's corners (bit o set: corner o inside; corner bits 1 = +x, 2 = +y,
 * 4 = +z), the surface polygons as loops of cube edges (0..11), oriented
 * counter-clockwise seen from outside. Built once per lb_mesh_create. */
typedef struct lb__mccase {
    uint8_t nloop;
    uint8_t len[4];
    uint8_t e[12];
    /* per loop, the vertex pairs a < b a triangle may join (bit
     * LB__PAIR(a, b)): the loop's sides, and the diagonals whose two cube
     * edges lie on no common face of the cell */
    uint64_t ok[4];
} lb__mccase;

/* The bit of vertex pair (a, b), a < b, of a polygon (lb__mccase.ok). */
#define LB__PAIR(a, b) ((a)*LB__MAXPOLY + (b))
/* Every pair allowed (a tetrahedron's polygons). */
#define LB__ALL_PAIRS (~(uint64_t)0)

typedef struct lb__mctable {
    lb__mccase c[256];
    uint16_t share[12]; /* bit b of share[a]: cube edges a and b lie on a common face */
} lb__mctable;

typedef struct lb__grid {
    double origin[3]; /* node (0,0,0) */
    double h[3];      /* cell size per axis */
    uint32_t cells[3];
    uint32_t N[3]; /* nodes per axis = cells + 1 */
    int closed;    /* phi_c = max(phi, box) */
    double bmin[3], bmax[3];
    int soft;
    int tetrahedra; /* LB_MESH_TETRAHEDRA: the Kuhn split instead of cube polygons */
    int features;   /* LB_MESH_FEATURES: a vertex on the crease or corner of a cell (features.c) */
    /* LB_MESH_COARSE_FIRST: the tolerance in cells (0: off), for the
     * blocks lb__two_level_block picks (extract.c) */
    double coarse;
    lb__mctable mc;
} lb__grid;

/* A vertex a block owns on one of its near faces (local coordinate 0 on an
 * axis its edge does not run along), for the block before it on that axis:
 * its index in the block and its position. */
typedef struct lb__fent {
    uint32_t idx, pad;
    double pos[3];
    double nrm[3]; /* its unit normal (for the sharp features' test) */
} lb__fent;

/* Entries of a block's near-face table: per near face (axis d), per node of
 * the face (the other two local coordinates, 0..LB__MB each) and per edge
 * direction in the face (the three non-zero masks without bit d). */
#define LB__FACE_NODES ((size_t)(LB__MB + 1) * (LB__MB + 1))
#define LB__FACE_ENTRIES (3 * LB__FACE_NODES * 3)

/* One block of LB__MB^3 cells (fewer at the far end of the grid). */
typedef struct lb__block {
    uint32_t b[3];  /* block coordinates */
    uint32_t nc[3]; /* cells per axis in this block */
    uint64_t id;    /* linear block index (sort key) */
    double *vals;   /* (nc+1)^3 node values of phi_c, x fastest */
    double *grads;  /* their gradients, 3 per node */
    uint8_t *nmask; /* nodes evaluated (corners of cells that may cross) */
    uint8_t *cmask; /* cells that may cross the surface, nc[0] * nc[1] * nc[2] */
    lb__cplan plan; /* the block box's plan, from the block selection's descent */
    /* its octants' plans (octant o: bit d set, the upper half along axis d),
     * from mark()'s passes, for the refinement; octmem holds them (NULL:
     * none, the refinement narrows for itself) */
    lb__cplan oct[8];
    void *octmem;
    /* in the block's node slot: its near-face vertices, for the blocks
     * before it (extract.c) */
    lb__fent *ftab;
    uint8_t *fvalid; /* bit e: ftab[e] is written */
    /* output (extract.c): nv vertices of its own in vpos and vnrm, of which
     * the first np are its alone and the rest are orphans (okey: their grid
     * edge keys, nv - np of them); nref vertices of next blocks (rref: their
     * block and index there, 2 per vertex), whose positions follow the own
     * ones in vpos; nt triangles over local vertex indices (own ones, then
     * the references) */
    size_t nv, np, nref, nt;
    size_t nfeat; /* of the np, the last nfeat are feature points (features.c) */
    uint64_t *okey;
    uint32_t *rref;
    double *vpos, *vnrm;
    uint32_t *tri;
    /* incremental remeshing (cache.c): the output above is the cache's
     * (not freed by the merge; rref's blocks are offset codes, as in
     * lb__cblock) */
    int borrowed;
    /* taken with its plan from the cache by the selection (a box of the
     * same plan above it): its own plan is the cached block's; plan_of,
     * when the two evaluators number that plan's instructions alike: the
     * cached entry whose plan memory plan is (not B's to free: mesher.c's
     * commit moves it to the new entry) */
    int carried;
    const struct lb__cblock *plan_of;
} lb__block;

/* ---- incremental remeshing (cache.c; lb_mesh_cache in mesh.h) ----
 * A cached block: its plan in the cached evaluator's instruction indices
 * with its argument places, its output (rref's first entry is the offset
 * code c of the next block referred to, 1..7, not a block index), and what
 * the blocks before it read of it: its near-face nodes that were evaluated
 * (local node index, then value and gradient) and its near-face vertex
 * table's written entries. */
typedef struct lb__cblock {
    uint64_t id;
    lb__cplan plan;
    uint32_t *argpos;
    size_t nargpos;
    size_t nv, np, nref, nt, nfeat;
    uint64_t *okey;
    uint32_t *rref;
    double *vpos, *vnrm;
    uint32_t *tri;
    uint32_t nnode, nface;
    uint32_t depth; /* a selection box's depth (boxes only; cache.c) */
    uint16_t *node;
    double *ndata; /* 4 per node */
    uint16_t *fe;
    lb__fent *fent;
    /* the arrays above from okey on lie in this slab of the cache (cache.c;
     * sbytes of it), or (NULL) are blocks of their own */
    struct lb__slab *slab;
    size_t sbytes;
} lb__cblock;

/* Frees what E holds (not E). */
LB_INTERNAL void lb__cblock_free(lb__cblock *E);
/* The id of a cached entry whose content a new run's entry took over
 * (mesher.c, before lb__cache_commit): it holds nothing of its own. */
#define LB__CBLOCK_MOVED UINT64_MAX
/* The cache's blocks are usable for ev on grid g: made for the same grid,
 * convention and culling. */
LB_INTERNAL int lb__cache_usable(const lb_mesh_cache *C, const lb_evaluator *ev, const lb__grid *g);
/* ev's instructions matched against the cache's (usable: lb__cache_usable;
 * else only ev's records are made, for the commit). */
typedef struct lb__cmatch lb__cmatch;
LB_INTERNAL lb_status lb__cmatch_new(const lb_mesh_cache *C, const lb_evaluator *ev, int usable,
                                     lb__cmatch **out, lb_error *err);
LB_INTERNAL void lb__cmatch_free(lb__cmatch *M);
/* uint32_t entries of the scratch lb__cache_same_plan needs. */
LB_INTERNAL size_t lb__cmatch_scratch(const lb__cmatch *M);
/* The cache's blocks, sorted by id (*n of them). */
LB_INTERNAL const lb__cblock *lb__cache_blocks(const lb_mesh_cache *C, size_t *n);
/* Is plan P (M's evaluator) the cached block's plan, content for content?
 * (M's memo is written: one thread.) */
LB_INTERNAL int lb__cache_same_plan(const lb_mesh_cache *C, lb__cmatch *M, const lb__cblock *E,
                                    const lb__cplan *P, uint32_t *scratch);
/* E's node and face records from block B (done: its node data final and
 * its near-face table published). 0 when out of memory. */
LB_INTERNAL int lb__cache_export(const lb__block *B, lb__cblock *E);
/* The records of E into B's node data (B's vals, grads, nmask, ftab and
 * fvalid set up for the block's size, nmask and fvalid cleared). */
LB_INTERNAL void lb__cache_import(const lb__cblock *E, lb__block *B);
/* The cache becomes this run's: n blocks (sorted by id, plans in M's
 * evaluator's indices; moved in, the array too) on grid g, M consumed;
 * reused counts the ones taken from it, counts are the merged mesh's
 * vertices and triangles. On failure the cache is emptied. */
LB_INTERNAL lb_status lb__cache_commit(lb_mesh_cache *C, lb__cmatch *M, const lb__grid *g,
                                       lb__cblock *blocks, size_t n, size_t reused,
                                       const size_t counts[2], lb__cblock *nodes, size_t nnodes,
                                       int node_depth, lb_error *err);
/* The incremental block selection (mesher.c's select_visit; cache.c states
 * the rule): the selection's boxes down to one depth are kept with their
 * plans (nodes, each with its depth and its first block's id, moved into
 * the cache by the commit, with n of them; freed by lb__cnodes_free
 * otherwise). A box whose plan is the cached box's, content for content,
 * has the cached box's blocks and boxes under it with the same plans:
 * lb__cache_node finds the cached box (NULL: none, or deeper than the
 * cache keeps), lb__cache_node_from the first at (depth, id) or after it
 * (NULL: none), lb__cache_nodes gives them all (sorted by depth, then id),
 * lb__cache_block_from the first cached block with id >= a given one, and
 * lb__cache_carry writes a cached block's or box's plan in the new
 * evaluator's indices through the taken box's list (lb__cache_carry_from,
 * on, before, the cached box E and its plan now in the new evaluator's
 * indices, equal place for place; off after); 0 when an instruction is
 * missing from the box's list or memory is short. */
LB_INTERNAL void lb__cnodes_free(lb__cblock *nodes, size_t n);
LB_INTERNAL const lb__cblock *lb__cache_node(const lb_mesh_cache *C, int depth, uint64_t id);
LB_INTERNAL const lb__cblock *lb__cache_node_from(const lb_mesh_cache *C, int depth, uint64_t id);
LB_INTERNAL const lb__cblock *lb__cache_nodes(const lb_mesh_cache *C, size_t *n);
LB_INTERNAL size_t lb__cache_block_from(const lb_mesh_cache *C, uint64_t id);
LB_INTERNAL void lb__cache_carry_from(lb__cmatch *M, const lb__cblock *E, const lb__cplan *now,
                                      int on);
LB_INTERNAL int lb__cache_carry(const lb__cmatch *M, const lb__cplan *leaf, lb__cplan *out);
/* The vertices and triangles of the cached mesh once merged (before the
 * passes after it). */
LB_INTERNAL void lb__cache_counts(const lb_mesh_cache *C, size_t *nv, size_t *nt);
/* The arrays of a mesh given back (lb_mesh_cache_recycle), if any, moved
 * into M (empty) with their room (vertices, triangles) in vcap and tcap. */
LB_INTERNAL void lb__cache_take_spare(lb_mesh_cache *C, lb_mesh *M, size_t *vcap, size_t *tcap);
/* The arrays a cached run needs only while it runs (the sorted blocks,
 * the next-block table, the readers' counts, the matching's candidates),
 * kept by the cache from one run to the next, one per slot (mesher.c's
 * uses): under jemalloc (Blender's allocator) the pages of arrays freed
 * and allocated again mostly came back from the system, a fault per 4 KiB
 * (docs/meshing.md, Incremental remeshing). lb__cache_run_take hands out
 * the slot's array if it holds at least bytes (its size in *got), else
 * NULL (a smaller one is freed); lb__cache_run_keep takes p (malloc'd,
 * bytes long; NULL: none) into the slot. Counted in the cache's bytes. */
#define LB__RUN_SLOTS 16
LB_INTERNAL void *lb__cache_run_take(lb_mesh_cache *C, int slot, size_t bytes, size_t *got);
LB_INTERNAL void lb__cache_run_keep(lb_mesh_cache *C, int slot, void *p, size_t bytes);
/* The coarse-first decisions' scratch of a thread (extract.c: a few MiB of
 * tables, most of them found by stamps, and the loops' answers by pattern),
 * kept by the cache from one run to the next as the arrays above are: made
 * afresh, it was the larger part of a live update's coarse-first cost at
 * 64 cells (its pages mapped and zeroed every run; docs/meshing.md, Coarse
 * first). lb__cache_tl_take hands out one kept scratch (NULL: none);
 * lb__cache_tl_keep takes one back (freed beyond LB__TL_KEEP). Counted in
 * the cache's bytes. lb__bctx_tl_swap puts tl into a thread's context and
 * returns the one it had (the context frees the one it holds at the end);
 * lb__tl_free frees one (NULL is fine), lb__tl_bytes is one's size. */
#define LB__TL_KEEP 64
LB_INTERNAL void *lb__cache_tl_take(lb_mesh_cache *C);
LB_INTERNAL void lb__cache_tl_keep(lb_mesh_cache *C, void *tl);
LB_INTERNAL void lb__tl_free(void *tl);
LB_INTERNAL size_t lb__tl_bytes(const void *tl);

/* The facing of triangle (a, b, c): (b - a) x (c - a), not normalised
 * (features.c's flips and folds, corners.c). */
static inline void lb__facing(const double a[3], const double b[3], const double c[3],
                              double n[3]) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

/* A block's id: its place in x-fastest order on a grid of nb blocks per
 * axis (blocks, the cache's entries and the selection's boxes, which take
 * their first block's, are sorted by it). */
static inline uint64_t lb__block_id(const uint32_t nb[3], uint32_t x, uint32_t y, uint32_t z) {
    return ((uint64_t)z * nb[1] + y) * nb[0] + x;
}

/* The first of n records stride bytes apart, sorted by the uint64_t id at
 * byte off of each, whose id is >= key (n: none). */
static inline size_t lb__lower_id(const void *base, size_t n, size_t stride, size_t off,
                                  uint64_t key) {
    const unsigned char *p = (const unsigned char *)base + off;
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t m = lo + (hi - lo) / 2;
        uint64_t id;
        memcpy(&id, p + m * stride, sizeof id);
        if (id < key)
            lo = m + 1;
        else
            hi = m;
    }
    return lo;
}

static inline uint64_t lb__node_index(const lb__grid *g, uint64_t x, uint64_t y, uint64_t z) {
    return (z * g->N[1] + y) * g->N[0] + x;
}

static inline void lb__node_pos(const lb__grid *g, uint64_t x, uint64_t y, uint64_t z,
                                double X[3]) {
    X[0] = g->origin[0] + (double)x * g->h[0];
    X[1] = g->origin[1] + (double)y * g->h[1];
    X[2] = g->origin[2] + (double)z * g->h[2];
}

/* A block whose plan runs fewer primitives per point is evaluated under
 * that one plan, not octant by octant (mesher.c, refine.c): measured in
 * instructions, the octant passes and grouping cost more than they save on
 * three spheres and pay off from four (bench scenes S1, S2, 2026-12-01). */
#define LB__NARROW_MIN_PRIMS 4

/* Octant o of block B as local nodes [l0, l1] (bit d of o set: the upper
 * half along axis d, from the middle node nc / 2 on). */
static inline void lb__octant_nodes(const lb__block *B, int o, uint32_t l0[3], uint32_t l1[3]) {
    for (int d = 0; d < 3; ++d) {
        const uint32_t half = B->nc[d] / 2;
        l0[d] = (o >> d) & 1 ? half : 0;
        l1[d] = (o >> d) & 1 ? B->nc[d] : half;
    }
}

/* E's plan narrowed (lb__boxeval_narrow) from outer, the block's plan, to
 * octant o of B (lb__octant_nodes). */
LB_INTERNAL void lb__octant_narrow(const lb_evaluator *ev, const lb__grid *g, const lb__block *B,
                                   int o, const lb__plan *outer, lb__boxeval *E);
/* E's plan for octant o of B: mark()'s plan of that octant where the block
 * kept them (B->octmem), else narrowed from outer (the block's plan, which
 * the caller copied there before its first octant). The refinement and the
 * two-level blocks' decisions evaluate octant by octant through it. */
LB_INTERNAL void lb__octant_plan(const lb_evaluator *ev, const lb__grid *g, const lb__block *B,
                                 int o, const lb__plan *outer, lb__boxeval *E);
/* The box of the block's local nodes [l0, l1] (padded by 1e-9 of a cell). */
LB_INTERNAL void lb__node_box(const lb__grid *g, const lb__block *B, const uint32_t l0[3],
                              const uint32_t l1[3], double bmin[3], double bmax[3]);

/* phi_c and its gradient from the field's value and gradient at X. */
LB_INTERNAL double lb__mesh_phi(const lb__grid *g, const double X[3], double f, const double gf[3],
                                double gphi[3]);

/* The largest region-box term of phi_c over block B's nodes (-inf for an
 * open mesh): wherever phi is at least this, phi_c = phi. */
LB_INTERNAL double lb__block_boxmax(const lb__grid *g, const lb__block *B);

/* lb__mesh_phi at a point of a block whose lb__block_boxmax is boxmax,
 * without the per-axis tests where they cannot change phi (the same bits). */
static inline double lb__mesh_phi_in(const lb__grid *g, double boxmax, const double X[3], double f,
                                     const double gf[3], double gphi[3]) {
    const double ph = g->soft ? 0.5 - f : f;
    if (!(ph >= boxmax)) return lb__mesh_phi(g, X, f, gf, gphi);
    const double s = g->soft ? -1.0 : 1.0;
    for (int d = 0; d < 3; ++d) gphi[d] = s * gf[d];
    return ph;
}

/* A thread's evaluation scratch, made once per run and reused block after
 * block (so a block allocates only what it outputs): the evaluator state a
 * block's runs share, the block's plan kept while that state's is narrowed
 * octant by octant, mark()'s plans by depth and its octant plans, and the
 * batches of node values (7 doubles per node) and of refinement (10
 * doubles and an index per edge). */
typedef struct lb__mscratch {
    lb__boxeval E;
    lb__plan outer;
    lb__plan pool[LB__MARK_DEPTH];
    lb__plan oct[8]; /* the block's octant plans, from mark()'s passes */
    double *nodes;
    size_t *nidx;
    double *edges;
    size_t *eact;
} lb__mscratch;

/* A block meshed coarse first (extract.c, two-level blocks): with a
 * tolerance, cube cells, no sharp features, and a whole block (LB__MB
 * cells a side, so that mark()'s smallest boxes are its coarse cells). Its
 * other blocks are meshed as without it: every block's boundary faces are
 * fine on both sides either way. */
static inline int lb__two_level_block(const lb__grid *g, const lb__block *B) {
    return g->coarse > 0.0 && !g->tetrahedra && !g->features && B->nc[0] == LB__MB &&
           B->nc[1] == LB__MB && B->nc[2] == LB__MB;
}

/* Surface extraction over one block whose node values are final (extract.c):
 * finds the crossing edges cell by cell (cubes.c, or tetra.c with
 * g->tetrahedra), refines a vertex on each edge the block owns
 * (lb__refine_edges), takes the others from their owners' near-face tables,
 * triangulates the cell polygons and writes the block's vertices and
 * triangles. blocks and nbr (B's next blocks by offset c, as index + 1; 0:
 * none kept) give the owners, which must be done; bit d of gnext: the grid
 * has a block after B along axis d. */
typedef struct lb__bctx lb__bctx;
LB_INTERNAL lb_status lb__mesh_block(const lb_evaluator *ev, const lb__grid *g, lb__block *B,
                                     const lb__block *blocks, const uint32_t nbr[8], int gnext,
                                     lb__bctx *C, lb_error *err);

/* A thread's extraction state for lb__mesh_block, with its evaluation
 * scratch, reused across blocks (NULL when out of memory); freed by
 * lb__bctx_free (NULL is fine). */
LB_INTERNAL lb__bctx *lb__bctx_new(const lb_evaluator *ev);
LB_INTERNAL void lb__bctx_free(lb__bctx *C);
/* (lb__cache_tl_take) */
LB_INTERNAL void *lb__bctx_tl_swap(lb__bctx *C, void *tl);
LB_INTERNAL lb__mscratch *lb__bctx_scratch(lb__bctx *C);

/* Safeguarded, batched root solve of phi_c along n grid edges: a[i] inside
 * (phi < 0), b[i] outside, pa/pb their values and ga/gb their gradients
 * (3 per edge), all inside block B; writes the surface points and unit
 * normals. An edge's result depends on its own inputs alone, whatever the
 * batch. known (NULL: none): the edges whose pos and nrm the caller has
 * already written (solved before from the same inputs), left as they are. */
LB_INTERNAL lb_status lb__refine_edges(const lb_evaluator *ev, const lb__grid *g,
                                       const lb__block *B, size_t n, const double *a,
                                       const double *b, const double *pa, const double *pb,
                                       const double *ga, const double *gb, const uint8_t *known,
                                       double *pos, double *nrm, lb__mscratch *S, lb_error *err);

/* ---- the cell methods' side of extract.c */

/* The head of a thread's extraction state (lb__bctx's first member,
 * extract.c), read inline by the cell methods: the block's edge map (local
 * edge id -> vertex index, valid where the entry's stamp is the block's;
 * side by side, one cache line per lookup) and its node strides. */
typedef struct lb__emap_entry {
    uint32_t stamp, e;
} lb__emap_entry;

typedef struct lb__bctx_head {
    lb__emap_entry *emap;
    uint32_t stamp;
    uint32_t D0, D1; /* the block's nodes along x, along y */
} lb__bctx_head;

/* The edge's vertex when the edge map has it, else lb__cell_edge_new's. */
LB_INTERNAL int64_t lb__cell_edge_new(lb__bctx *C, size_t lid, uint32_t i, uint32_t j, uint32_t k,
                                      int op, int oq, const double *c);

/* The vertex on the crossing edge between corners op and oq (op a subset of
 * oq) of cell (i, j, k) of the block, c its 8 corner values: its index in the
 * block, created on first use (lb__cell_edge_new); -1 when out of memory. */
static inline int64_t lb__cell_edge(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, int op, int oq,
                                    const double *c) {
    const lb__bctx_head *H = (const lb__bctx_head *)(const void *)C;
    const uint32_t li = i + (op & 1), lj = j + ((op >> 1) & 1), lk = k + ((op >> 2) & 1);
    const size_t lid = ((size_t)(lk * H->D1 + lj) * H->D0 + li) * 8 + (size_t)(op ^ oq);
    if (H->emap[lid].stamp == H->stamp) return H->emap[lid].e;
    return lb__cell_edge_new(C, lid, i, j, k, op, oq, c);
}

/* Add a polygon of n (3..LB__MAXPOLY) vertices (indices from lb__cell_edge),
 * counter-clockwise seen from outside; ok holds the vertex pairs its
 * triangles may join (LB__PAIR bits; LB__ALL_PAIRS: any diagonal). 0 when
 * out of memory. */
LB_INTERNAL int lb__cell_polygon(lb__bctx *C, const uint32_t *e, uint64_t ok, uint32_t n);

/* Sharp features (features.c). A polygon whose vertex normals include two
 * with a cosine below LB__FEATURE_COS gets a feature point. */
#define LB__FEATURE_COS 0.9
/* The point of the box [lo, hi] that minimises sum_i (n_i . (x - p_i))^2
 * over the m points p and unit normals n (3 per point), small eigen-
 * directions left to the mass point; 0 when m < 2. */
LB_INTERNAL int lb__feature_qef(const double *p, const double *n, int m, const double lo[3],
                                const double hi[3], double x[3]);
/* Flip every cell-face segment between two fans around feature points
 * (feat[v] = 1) into the edge joining the two points, where that keeps
 * both triangles' orientation and makes no edge twice. tr holds ntr
 * ascending ranges of M's triangles (first, count): every triangle with a
 * feature point lies in one, before and after. */
LB_INTERNAL lb_status lb__feature_flips(lb_mesh *M, const uint8_t *feat, const size_t *tr,
                                        size_t ntr, lb_error *err);
/* After the flips: a feature point with a triangle that faces against the
 * surface at each of its grid-edge vertices (a fold: a fan whose segment
 * found no neighbour to flip with) moves to the mean of its ring, put on
 * the surface by Newton steps; where those fail it stays (feat is scratch:
 * 2 marks such points while it runs, 1 again when done). */
LB_INTERNAL lb_status lb__feature_unfold(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M,
                                         uint8_t *feat, const size_t *tr, size_t ntr, int threads,
                                         lb__mscratch *S, lb_error *err);
/* M's corner_normals and nnormals (corners.c): the identity without
 * feature points (feat NULL), else split normals where a feature point's
 * triangles lie on sides of a crease. Evaluates ev with threads. */
LB_INTERNAL lb_status lb__corner_normals(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M,
                                         const uint8_t *feat, int threads, lb_error *err);

/* Adaptive simplification (simplify.c): half-edge collapses wherever every
 * moved triangle stays within tolerance cells (of the smallest cell side)
 * of phi_c, never across a crease; closed and manifold kept; feat (may be
 * NULL) is compacted with the vertices. On up to threads threads (the
 * calling one among them), the same result for every count. Fails before
 * allocating when its scratch would exceed max_memory; checks *cancel (may
 * be NULL) and calls progress (may be NULL; non-zero cancels; on the
 * calling thread only) with fractions rising from base by at most
 * weight. */
LB_INTERNAL lb_status lb__simplify(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M,
                                   uint8_t *feat, double tolerance, size_t max_memory, int threads,
                                   const volatile int *cancel, lb_mesh_progress_fn progress,
                                   void *user, double base, double weight, lb_error *err);

/* Keep the vertices whose to[v] is not UINT32_MAX, in their order (their
 * positions, normals and feat, which may be NULL), and set to[v] to each
 * one's new index; M->nvertices becomes their count (simplify.c). The
 * triangles are the caller's to renumber. */
LB_INTERNAL void lb__keep_vertices(lb_mesh *M, uint8_t *feat, uint32_t *to);

/* Flat regions merged (flat.c): where triangles lie in one plane with the
 * field's gradient its normal, the region's outline (without the vertices
 * inside it, or on a straight crease between two such regions) is cut into
 * as few triangles as it needs; the surface does not move, the mesh stays a
 * closed 2-manifold (else the pass leaves it as it was); feat (may be
 * NULL) is compacted with the vertices. */
LB_INTERNAL lb_status lb__merge_flat(const lb__grid *g, lb_mesh *M, uint8_t *feat, lb_error *err);

/* One cell (i, j, k) with corner values c (some inside, some outside; bit o
 * of cfg set: corner o inside): its polygons, by the cube cases or by the
 * Kuhn split. 0 when out of memory. */
LB_INTERNAL int lb__cube_cell(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, const double *c,
                              int cfg);
LB_INTERNAL int lb__tetra_cell(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, const double *c,
                               int cfg);

/* The grid of the block being extracted (cell methods read the cube cases). */
LB_INTERNAL const lb__grid *lb__cell_grid(const lb__bctx *C);

LB_INTERNAL void lb__mctable_init(lb__mctable *t);
/* Cube edge e (0..11) runs from corner *p to corner *q: edges 0-3 along x,
 * 4-7 along y, 8-11 along z, each group in the order of its lower corner.
 * Inline: the two-level cells (extract.c, transition.c) ask for it in their
 * innermost loops. */
static inline void lb__cube_edge(int e, int *p, int *q) {
    static const uint8_t P[12] = {0, 2, 4, 6, 0, 1, 4, 5, 0, 1, 2, 3};
    *p = P[e];
    *q = P[e] | 1 << (e >> 2);
}
/* The cube edge between corners p and q, which differ in one bit: its axis
 * and the place of its lower corner among that axis's four edges. A
 * constant expression (transition.c's face tables are built from it). */
#define LB__CUBE_AXIS(p, q) (((p) ^ (q)) == 1 ? 0 : ((p) ^ (q)) == 2 ? 1 : 2)
#define LB__CUBE_LO(p, q) ((p) < (q) ? (p) : (q))
#define LB__CUBE_EDGE_BETWEEN(p, q)                                                                \
    (4 * LB__CUBE_AXIS(p, q) + (LB__CUBE_AXIS(p, q) == 0 ? LB__CUBE_LO(p, q) >> 1                  \
                                : LB__CUBE_AXIS(p, q) == 1                                         \
                                    ? (LB__CUBE_LO(p, q) & 1) | (LB__CUBE_LO(p, q) >> 1 & 2)       \
                                    : LB__CUBE_LO(p, q)))
/* 1 when every loop of every case is a polygon of 3..LB__MAXPOLY vertices
 * with a triangulation off the cell's faces (the manifold argument in
 * cubes.c needs it), else 0. */
LB_INTERNAL int lb__mctable_check(const lb__mctable *t);

/* ---- two-level cells (transition.c): a cell of twice the grid's cell
 * size whose edges may be split at their midpoints and whose faces may be
 * quartered, for a mesher that meshes coarse first. Its samples are the
 * 3 x 3 x 3 fine-grid nodes in it, lattice node x + 3 y + 9 z (x, y, z in
 * 0..2; the body centre, 13, is never read). */
#define LB__TNODES 27
/* cube corner o (bit d: the far side along axis d) as a lattice node */
#define LB__TCORNER(o) (2 * ((o)&1) + 6 * (((o) >> 1) & 1) + 18 * (((o) >> 2) & 1))
/* most crossing sub-edges of one cell: 24 edge halves, 24 in the faces */
#define LB__TMAX 48
typedef struct lb__tcell {
    uint16_t split;  /* bit e: cube edge e (cubes.c's numbering) split */
    uint8_t quarter; /* bit f: face f (cubes.c's order) quartered; its four edges must be split */
    uint32_t inside; /* bit n: lattice node n inside (phi < 0) */
} lb__tcell;
/* The cell's surface polygons: loops of crossing sub-edges (lattice nodes
 * a < b, as a * LB__TNODES + b), counter-clockwise seen from outside, one
 * after the other in sub (LB__TMAX room), len[l] each (LB__TMAX / 3 room),
 * *nloop of them; loops of two sub-edges are left out (no area). Returns
 * the sub-edges written, or -1 for a quartered face with an edge not
 * split (or, which the rule rules out, a walk that does not close).
 * Two cells sharing a face draw the same segments on it whatever their
 * levels (transition.c says why). Face f (cubes.c's order) lies at
 * coordinate f % 2 of axis f / 2. */
LB_INTERNAL int lb__tcell_loops(const lb__tcell *c, uint16_t *sub, uint8_t *len, int *nloop);
/* The n - 2 triangles of loop s[0..n-1] (3..LB__TMAX sub-edges of one
 * cell; pos: their vertices, 3 doubles each) along diagonals whose two
 * sub-edges lie on no common face plane of the cell, as loop positions, 3
 * per triangle in the loop's turn, into tri (3 * (LB__TMAX - 2) room): of
 * those triangulations, the one whose worst triangle is closest to facing
 * along the loop's mean normal. 0 when there is none, or when even the best
 * has a triangle facing against that normal (a fold): the loop then needs
 * a fan around a point inside the cell. */
LB_INTERNAL int lb__tloop_triangles(const uint16_t *s, const double *pos, int n, uint8_t *tri);

#endif
