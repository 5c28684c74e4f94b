/* The mesh cache (lb_mesh_cache, mesh.h): what incremental remeshing keeps
 * of the last mesh, and the rule that decides which blocks it may give back.
 *
 * The rule. A block's work (mesher.c: its node values, mark()'s sub-box
 * passes, the refinement, sharp features, the extraction) runs under its
 * plan alone: the instructions and blend arguments the block selection's
 * interval passes kept for its box, in tape order. An instruction's result
 * is a function of its content (kind, primitive or operator with every
 * parameter, its transform, local unions' curves) and of its arguments'
 * results. So two plans whose instructions have equal contents and equal
 * arguments (recursively, compared byte for byte, never by a hash alone),
 * in the same order with the same blend arguments kept, compute the same
 * bits at every point: the block's node values, vertices and triangles
 * are the same, on the same grid. Registers and instruction indices differ
 * between two evaluators and are not part of a content; arguments are
 * named by the matched instruction of the cached evaluator.
 *
 * A block also reads its next blocks (offsets 1 along some axes): their
 * near-face node values (its far faces take them) and their near-face
 * vertices (their index in the next block, position and normal). A next
 * block's vertex numbering follows its own cells, whose far corners come
 * from the blocks after it: so a block's output depends on the plans of
 * the blocks at offsets 0..2 on each axis, and on which of them are kept.
 * mesher.c takes a block from the cache only when all of those are the
 * same in both meshes.
 *
 * The selection's boxes. The block selection (mesher.c) descends an
 * octree of boxes of blocks, each box's interval pass under its parent's
 * plan. Which boxes and blocks under a box are kept, and their plans, are
 * a function of the box and of its own plan alone (the passes below read
 * nothing else), by the same argument as a block's output. So the cache
 * keeps the boxes down to one depth (about 4 x 4 x 4 blocks) with their
 * plans, and a box whose plan is the cached box's, content for content
 * (lb__cache_same_plan, as for blocks), takes the cached boxes and blocks
 * under it instead of descending: their plans written in the new
 * evaluator's indices through the two boxes' lists, which match place for
 * place (a box's or block's list is a subset of every box's above it).
 * Those blocks then go through the block rule like any other. On the
 * 512-sphere lattice with one sphere moved the descent stops at the
 * largest boxes whose plans leave that sphere out: a few dozen interval
 * passes instead of about a thousand.
 *
 * The records. For each instruction of the evaluator last meshed, its
 * content with arguments as instruction indices of that evaluator (a
 * record), in one buffer, with a hash table over the records for the
 * matching. A new evaluator's instruction is matched by writing its record
 * with its arguments replaced by their matches (no match: no match for it
 * either) and looking that record up. */
#include "mesh_internal.h"

#include <stdlib.h>
#include <string.h>

#include "../common/platform.h"
#include "../evaluation/records.h"

#define NONE LB__RNONE

typedef struct lb__slab lb__slab;

struct lb_mesh_cache {
    int valid;
    /* what the blocks were made for */
    double origin[3], h[3], bmin[3], bmax[3];
    uint32_t cells[3];
    int closed, soft, tetrahedra, features, conv, cullable;
    double coarse; /* the grid's coarse-first tolerance (0: off) */
    /* the records of the evaluator last meshed (with and without
     * arguments), a table over the full ones */
    size_t nins;
    lb__recs full, self;
    uint32_t *tab; /* instruction + 1, 0: empty; tcap (a power of 2) slots */
    size_t tcap;
    lb__cblock *blocks; /* sorted by id */
    size_t nblocks;
    /* the block selection's boxes down to depth node_depth (-1: none) that
     * the surface may cross: depth, id (the box's first block's), plan
     * (with argpos), sorted by depth, then id */
    lb__cblock *nodes;
    size_t nnodes;
    int node_depth;
    size_t counts[2]; /* the merged mesh's vertices and triangles */
    lb_mesh_cache_stats stats;
    /* the slabs the blocks' output lies in (the last one filled next), and
     * their bytes */
    lb__slab **slabs;
    size_t nslabs, slabcap, slab_bytes;
    /* slabs emptied, kept for the next blocks (up to one slab's bytes
     * after a commit): an edit that recomputes every block then writes
     * into memory mapped already, and nothing is unmapped */
    lb__slab **idle;
    size_t nidle, idlecap;
    /* a mesh given back (lb_mesh_cache_recycle): its arrays, with room for
     * nv vertices (positions and normals) and nt triangles; NULL: none */
    double *spare_pos, *spare_nrm;
    uint32_t *spare_tri;
    size_t spare_nv, spare_nt;
    /* the arrays a run needs only while it runs, one per use (its slot),
     * kept for the next run (lb__cache_run_take, lb__cache_run_keep) */
    struct {
        void *p;
        size_t bytes;
    } run[LB__RUN_SLOTS];
    /* the threads' coarse-first scratch, kept for the next run
     * (lb__cache_tl_take, lb__cache_tl_keep) */
    void *tl[LB__TL_KEEP];
    size_t ntl, tl_bytes; /* how many, and their lb__tl_bytes */
};

/* The matching of an evaluator against the cache (mesher.c's rule):
 * deep[i], the cached instruction with the same record with arguments
 * (UINT32_MAX: none); own records (arguments by place) written through
 * deep for the comparison (cmp) and as they are for the next cache (self,
 * deep records in full); same[i], the cached instruction whose own record
 * was found equal (a memo); pos and stamp, a plan's places. */
struct lb__cmatch {
    const lb_evaluator *ev;
    int usable;
    uint32_t *deep, *same, *pos, *stamp, round;
    lb__recs cmp, self, full;
    /* a box taken (lb__cache_carry_from): each cached instruction of its
     * list -> the new one at the same place (NONE elsewhere; nmap entries,
     * the cache's instruction count) */
    uint32_t *map;
    size_t nmap;
};

void lb__cmatch_free(lb__cmatch *M) {
    if (!M) return;
    free(M->deep);
    free(M->same);
    free(M->pos);
    free(M->stamp);
    free(M->map);
    lb__recs_free(&M->cmp);
    lb__recs_free(&M->self);
    lb__recs_free(&M->full);
    free(M);
}

lb_status lb__cmatch_new(const lb_mesh_cache *C, const lb_evaluator *ev, int usable,
                         lb__cmatch **out, lb_error *err) {
    *out = NULL;
    lb__cmatch *M = calloc(1, sizeof *M);
    const size_t n = ev->n ? ev->n : 1;
    int ok = M != NULL;
    if (ok) {
        M->ev = ev;
        M->usable = usable;
        M->deep = malloc(n * sizeof *M->deep);
        M->same = malloc(n * sizeof *M->same);
        M->pos = malloc(n * sizeof *M->pos);
        M->stamp = calloc(n, sizeof *M->stamp);
        M->nmap = usable ? C->nins : 0;
        M->map = malloc((M->nmap ? M->nmap : 1) * sizeof *M->map);
        for (size_t i = 0; M->map && i < M->nmap; ++i) M->map[i] = NONE;
        ok = M->deep && M->same && M->pos && M->stamp && M->map &&
             lb__recs_make(ev, NULL, 1, 1, &M->full) && lb__recs_make(ev, NULL, 0, 1, &M->self);
    }
    if (ok && usable) {
        /* deep matches in tape order: an instruction's arguments come first */
        lb__rbuf b = {NULL, 0, 0, 0};
        for (size_t i = 0; i < ev->n && !b.oom; ++i) {
            M->deep[i] = M->same[i] = NONE;
            b.n = 0;
            if (!lb__record(ev, (uint32_t)i, M->deep, 1, 1, &b) || b.oom) continue;
            M->deep[i] = lb__recs_find(&C->full, C->tab, C->tcap, b.p, b.n);
        }
        ok = !b.oom;
        free(b.p);
        ok = ok && lb__recs_make(ev, M->deep, 0, 1, &M->cmp);
    }
    if (!ok) {
        lb__cmatch_free(M);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create_cached: out of memory");
    }
    *out = M;
    return LB_OK;
}

/* ---- slabs ----
 * A block's output (the merge's source: vertices, triangles, references,
 * near-face tables) is copied, when the cache takes it, into a slab: one
 * large allocation, advised onto huge pages, holding many blocks' arrays
 * back to back. An incremental run reads all of it (about 200 MB for a
 * 3-million-triangle mesh); as some 150,000 small blocks of the C
 * runtime's heap it spans 50,000 pages, and on a machine whose hypervisor
 * keeps shadow page tables (measured on this project's build machine, a
 * PVM guest) a page touched after any unmapping in the process can cost
 * a fault in the host, which tripled some runs (docs/meshing.md).
 * A slab counts its entries; a slab with none goes idle at the next
 * commit and takes that commit's new blocks (the rest freed, down to one
 * slab's bytes), and when the slabs hold more than twice the live bytes
 * (many edits leave holes) the live entries are moved into new ones. */
struct lb__slab {
    size_t live, liveb; /* entries and their bytes */
    size_t used, cap;   /* bytes of data */
    size_t touched;     /* the most bytes ever used (written before) */
    double *data;       /* the bytes (aligned for every array type) */
};

/* S's bytes after its used ones, up to its end when fresh (pages not
 * written yet allowed), else up to the most it ever used. */
static size_t slab_room(const lb__slab *S, int fresh) {
    const size_t end = fresh ? S->cap : S->touched;
    return end > S->used ? end - S->used : 0;
}

/* A new slab's bytes: an eighth of the blocks' output, from 64 KiB to
 * 8 MiB (a small cache in small slabs, so that its holes are moved out
 * too; a large one on huge pages). */
static size_t slab_size(size_t live) {
    const size_t s = live / 8;
    return s < ((size_t)64 << 10) ? (size_t)64 << 10 : s > ((size_t)8 << 20) ? (size_t)8 << 20 : s;
}
#define SLAB_ALIGN(n) (((n) + 15) & ~(size_t)15)

/* The byte sizes of an entry's output arrays, in the order of
 * entry_arrays (okey, rref, vpos, vnrm, tri, node, ndata, fe, fent). */
#define NARRAYS 9
static void entry_sizes(const lb__cblock *E, size_t bytes[NARRAYS]) {
    const size_t b[NARRAYS] = {(E->nv - E->np) * sizeof(uint64_t),
                               2 * E->nref * sizeof(uint32_t),
                               3 * (E->nv + E->nref) * sizeof(double),
                               3 * E->nv * sizeof(double),
                               3 * E->nt * sizeof(uint32_t),
                               E->nnode * sizeof(uint16_t),
                               4 * (size_t)E->nnode * sizeof(double),
                               E->nface * sizeof(uint16_t),
                               E->nface * sizeof(lb__fent)};
    memcpy(bytes, b, sizeof b);
}

/* The arrays of an entry: pointer places and byte sizes. */
static void entry_arrays(lb__cblock *E, void **ptr[NARRAYS], size_t bytes[NARRAYS]) {
    void **p[NARRAYS] = {(void **)&E->okey,  (void **)&E->rref, (void **)&E->vpos,
                         (void **)&E->vnrm,  (void **)&E->tri,  (void **)&E->node,
                         (void **)&E->ndata, (void **)&E->fe,   (void **)&E->fent};
    memcpy(ptr, p, sizeof p);
    entry_sizes(E, bytes);
}

static void slab_release(lb__cblock *E) {
    E->slab->live--;
    E->slab->liveb -= E->sbytes;
    E->slab = NULL;
}

/* The bytes E's arrays take in a slab. */
static size_t entry_bytes(lb__cblock *E) {
    void **ptr[NARRAYS];
    size_t bytes[NARRAYS], total = 0;
    entry_arrays(E, ptr, bytes);
    for (size_t i = 0; i < NARRAYS; ++i)
        if (*ptr[i]) total += SLAB_ALIGN(bytes[i] ? bytes[i] : 1);
    return total;
}

/* E's arrays copied into the cache's last slab (an idle one or, when
 * fresh, a new one of at least slab bytes when it is full; when not fresh
 * only into bytes written before), their old memory freed (or released,
 * from another slab). 0: no such room when not fresh, or out of memory;
 * E as it was. */
static int slab_put(lb_mesh_cache *C, lb__cblock *E, size_t slab, int fresh) {
    void **ptr[NARRAYS];
    size_t bytes[NARRAYS];
    entry_arrays(E, ptr, bytes);
    const size_t total = entry_bytes(E);
    lb__slab *S = C->nslabs ? C->slabs[C->nslabs - 1] : NULL;
    if (!S || slab_room(S, fresh) < total) {
        if (C->nslabs == C->slabcap) {
            const size_t nc = C->slabcap ? 2 * C->slabcap : 16;
            lb__slab **q = realloc(C->slabs, nc * sizeof *q);
            if (!q) return 0;
            C->slabs = q;
            C->slabcap = nc;
        }
        for (size_t i = C->nidle; i-- > 0;) /* an idle slab large enough */
            if ((fresh ? C->idle[i]->cap : C->idle[i]->touched) >= total) {
                S = C->idle[i];
                C->idle[i] = C->idle[--C->nidle];
                S->live = S->liveb = S->used = 0;
                C->slabs[C->nslabs++] = S;
                break;
            }
    }
    if (!S || slab_room(S, fresh) < total) {
        if (!fresh) return 0;
        S = malloc(sizeof *S);
        const size_t cap = total > slab ? total : slab;
        if (S) S->data = lb__huge_alloc(cap);
        if (!S || !S->data) {
            free(S);
            return 0;
        }
        S->live = S->liveb = S->used = S->touched = 0;
        S->cap = cap;
        C->slabs[C->nslabs++] = S;
        C->slab_bytes += cap;
    }
    unsigned char *at = (unsigned char *)S->data + S->used;
    for (size_t i = 0; i < NARRAYS; ++i) {
        if (!*ptr[i]) continue;
        memcpy(at, *ptr[i], bytes[i]);
        if (!E->slab) free(*ptr[i]);
        *ptr[i] = at;
        at += SLAB_ALIGN(bytes[i] ? bytes[i] : 1);
    }
    if (E->slab) slab_release(E);
    S->used += total;
    if (S->used > S->touched) S->touched = S->used;
    S->live++;
    S->liveb += total;
    E->slab = S;
    E->sbytes = total;
    return 1;
}

static void slab_drop(lb_mesh_cache *C, lb__slab *S) {
    C->slab_bytes -= S->cap;
    lb__huge_free(S->data, S->cap);
    free(S);
}

/* The slabs with no entry made idle (the last one stays while it has
 * room), then idle ones freed down to keep bytes. */
static void slab_sweep(lb_mesh_cache *C, size_t keep) {
    size_t w = 0, idle = 0;
    for (size_t i = 0; i < C->nslabs; ++i) {
        lb__slab *S = C->slabs[i];
        if (S->live || (i + 1 == C->nslabs && S->used < S->cap)) {
            C->slabs[w++] = S;
            continue;
        }
        if (C->nidle == C->idlecap) {
            const size_t nc = C->idlecap ? 2 * C->idlecap : 16;
            lb__slab **q = realloc(C->idle, nc * sizeof *q);
            if (!q) {
                slab_drop(C, S);
                continue;
            }
            C->idle = q;
            C->idlecap = nc;
        }
        C->idle[C->nidle++] = S;
    }
    C->nslabs = w;
    for (size_t i = 0; i < C->nidle; ++i) idle += C->idle[i]->cap;
    while (C->nidle && idle > keep) {
        lb__slab *S = C->idle[--C->nidle];
        idle -= S->cap;
        slab_drop(C, S);
    }
}

/* The blocks' output into slabs: the new ones (into slab bytes written
 * before, in the last slab or an idle one; into pages not written yet only
 * once the blocks outside slabs hold a slab's bytes), then, when the slabs
 * hold more than twice the live bytes, all of them into new slabs (the old
 * ones freed). Pages written the first time are costly (3.6 ms for the
 * 3 MB of a one-sphere edit of the 512-sphere lattice at 256 cells, on
 * this project's build machine), so a small edit's blocks stay in the
 * heap, at most about a slab's bytes of them. Out of memory leaves blocks
 * as they are (still correct). */
static void slab_settle(lb_mesh_cache *C) {
    size_t live = 0, loose = 0;
    for (size_t i = 0; i < C->nblocks; ++i) {
        const lb__cblock *E = &C->blocks[i];
        const size_t b = E->slab ? E->sbytes : entry_bytes(&C->blocks[i]);
        live += b;
        loose += E->slab ? 0 : b;
    }
    const size_t slab = slab_size(live);
    slab_sweep(C, SIZE_MAX); /* the slabs the last commit emptied, for the new blocks */
    for (size_t i = 0; i < C->nblocks; ++i)
        if (!C->blocks[i].slab && !slab_put(C, &C->blocks[i], slab, loose >= slab)) break;
    slab_sweep(C, slab);
    if (C->slab_bytes <= 2 * live + 2 * slab) return;
    const size_t old = C->nslabs;
    /* a new slab first, so that nothing is copied into an old one */
    if (old) C->slabs[old - 1]->used = C->slabs[old - 1]->cap;
    for (size_t i = 0; i < C->nblocks; ++i)
        if (!slab_put(C, &C->blocks[i], slab, 1)) break;
    slab_sweep(C, slab);
}

static void slabs_free(lb_mesh_cache *C) {
    for (size_t i = 0; i < C->nslabs; ++i) slab_drop(C, C->slabs[i]);
    for (size_t i = 0; i < C->nidle; ++i) slab_drop(C, C->idle[i]);
    free(C->slabs);
    free(C->idle);
    C->slabs = C->idle = NULL;
    C->nslabs = C->slabcap = C->nidle = C->idlecap = 0;
}

/* ---- blocks ---- */

void lb__cblock_free(lb__cblock *E) {
    lb__cplan_free(&E->plan);
    if (E->slab) {
        slab_release(E);
    } else {
        free(E->okey);
        free(E->rref);
        free(E->vpos);
        free(E->vnrm);
        free(E->tri);
        free(E->node);
        free(E->ndata);
        free(E->fe);
        free(E->fent);
    }
    free(E->argpos);
    memset(E, 0, sizeof *E);
}

static void blocks_free(lb_mesh_cache *C) {
    for (size_t i = 0; i < C->nblocks; ++i)
        if (C->blocks[i].id != LB__CBLOCK_MOVED) lb__cblock_free(&C->blocks[i]);
    free(C->blocks);
    C->blocks = NULL;
    C->nblocks = 0;
    lb__cnodes_free(C->nodes, C->nnodes);
    C->nodes = NULL;
    C->nnodes = 0;
    C->node_depth = -1;
}

void lb__cnodes_free(lb__cblock *nodes, size_t n) {
    for (size_t i = 0; i < n; ++i) lb__cblock_free(&nodes[i]);
    free(nodes);
}

/* The first of the n entries of E (sorted by id) with id >= key. */
static size_t lower_id(const lb__cblock *E, size_t n, uint64_t key) {
    return lb__lower_id(E, n, sizeof *E, offsetof(lb__cblock, id), key);
}

/* Boxes by depth, then id. */
static int cmp_node(const void *a, const void *b) {
    const lb__cblock *x = a, *y = b;
    if (x->depth != y->depth) return x->depth < y->depth ? -1 : 1;
    return x->id < y->id ? -1 : x->id > y->id;
}

const lb__cblock *lb__cache_node(const lb_mesh_cache *C, int depth, uint64_t id) {
    const lb__cblock *F = lb__cache_node_from(C, depth, id);
    return F && F->depth == (uint32_t)depth && F->id == id ? F : NULL;
}

const lb__cblock *lb__cache_node_from(const lb_mesh_cache *C, int depth, uint64_t id) {
    if (!C->valid || depth < 0) return NULL;
    size_t lo = 0, hi = C->nnodes;
    const lb__cblock key = {.id = id, .depth = (uint32_t)depth};
    while (lo < hi) {
        const size_t m = lo + (hi - lo) / 2;
        if (cmp_node(&C->nodes[m], &key) < 0)
            lo = m + 1;
        else
            hi = m;
    }
    return lo < C->nnodes ? &C->nodes[lo] : NULL;
}

const lb__cblock *lb__cache_nodes(const lb_mesh_cache *C, size_t *n) {
    *n = C->valid ? C->nnodes : 0;
    return C->nodes;
}

size_t lb__cache_block_from(const lb_mesh_cache *C, uint64_t id) {
    return lower_id(C->blocks, C->nblocks, id);
}

void lb__cache_carry_from(lb__cmatch *M, const lb__cblock *E, const lb__cplan *now, int on) {
    for (uint32_t q = 0; q < E->plan.nlist; ++q) M->map[E->plan.list[q]] = on ? now->list[q] : NONE;
}

int lb__cache_carry(const lb__cmatch *M, const lb__cplan *leaf, lb__cplan *out) {
    const uint32_t nl = leaf->nlist, na = leaf->nact_total;
    memset(out, 0, sizeof *out);
    uint32_t *list = malloc((nl ? nl : 1) * sizeof *list + (na ? na : 1) * sizeof *out->act);
    if (!list) return 0;
    for (uint32_t t = 0; t < nl; ++t) /* the leaf's list is a subset of the box's */
        if ((list[t] = M->map[leaf->list[t]]) == NONE) {
            free(list);
            return 0;
        }
    out->list = list;
    out->act = (uint16_t *)(void *)(list + (nl ? nl : 1));
    if (na) memcpy(out->act, leaf->act, na * sizeof *out->act);
    out->nlist = nl;
    out->nact_total = na;
    return 1;
}

static void spare_free(lb_mesh_cache *C) {
    free(C->spare_pos);
    free(C->spare_nrm);
    free(C->spare_tri);
    C->spare_pos = C->spare_nrm = NULL;
    C->spare_tri = NULL;
    C->spare_nv = C->spare_nt = 0;
}

static size_t spare_bytes(const lb_mesh_cache *C) {
    return C->spare_pos ? 6 * C->spare_nv * sizeof(double) + 3 * C->spare_nt * sizeof(uint32_t) : 0;
}

static size_t run_bytes(const lb_mesh_cache *C) {
    size_t bytes = 0;
    for (int i = 0; i < LB__RUN_SLOTS; ++i) bytes += C->run[i].bytes;
    return bytes;
}

const lb__cblock *lb__cache_blocks(const lb_mesh_cache *C, size_t *n) {
    *n = C->nblocks;
    return C->blocks;
}

/* P's argument places into out (at most ev->total_k entries), returning
 * how many: per listed operator, the place in P->list of each argument it
 * reads (a fast kernel's kept ones, another operator's all k:
 * eval_points.c), UINT32_MAX where that argument is not listed. */
static size_t arg_places(lb__cmatch *M, const lb__cplan *P, uint32_t *out) {
    const lb_evaluator *ev = M->ev;
    if (++M->round == 0) {
        memset(M->stamp, 0, (ev->n ? ev->n : 1) * sizeof *M->stamp);
        M->round = 1;
    }
    for (uint32_t q = 0; q < P->nlist; ++q) {
        M->pos[P->list[q]] = q;
        M->stamp[P->list[q]] = M->round;
    }
    size_t w = 0;
    const uint16_t *act = P->act;
    for (uint32_t q = 0; q < P->nlist; ++q) {
        const lb__instr *in = &ev->ins[P->list[q]];
        if (in->code != LB__I_OP) continue;
        const uint16_t na = *act++;
        const size_t k = in->fast ? na : in->op->k;
        for (size_t t = 0; t < k; ++t) {
            const uint32_t a = in->srci[in->fast ? act[t] : t];
            out[w++] = M->stamp[a] == M->round ? M->pos[a] : NONE;
        }
        act += na;
    }
    return w;
}

size_t lb__cmatch_scratch(const lb__cmatch *M) {
    return M->ev->total_k ? M->ev->total_k : 1;
}

int lb__cache_same_plan(const lb_mesh_cache *C, lb__cmatch *M, const lb__cblock *E,
                        const lb__cplan *P, uint32_t *scratch) {
    if (!M->usable || E->plan.nlist != P->nlist || E->plan.nact_total != P->nact_total || !P->nlist)
        return 0;
    /* the root last in both (its register is the value read) */
    if (P->list[P->nlist - 1] != M->ev->n - 1 || E->plan.list[P->nlist - 1] != C->nins - 1)
        return 0;
    for (uint32_t q = 0; q < P->nlist; ++q) {
        const uint32_t i = P->list[q], j = E->plan.list[q];
        if (M->same[i] == j) continue;
        if (!lb__recs_equal(&M->cmp, i, &C->self, j)) return 0;
        M->same[i] = j;
    }
    if (P->nact_total && memcmp(E->plan.act, P->act, P->nact_total * sizeof *P->act)) return 0;
    const size_t na = arg_places(M, P, scratch);
    if (na != E->nargpos) return 0;
    for (size_t t = 0; t < na; ++t)
        if (scratch[t] == NONE || scratch[t] != E->argpos[t]) return 0;
    return 1;
}

/* E's argument places from its plan (ev's, M's evaluator); 0 when out of
 * memory. */
static int set_places(lb__cmatch *M, lb__cblock *E, uint32_t *scratch) {
    if (E->argpos) return 1; /* a block from the cache: its plan's places, checked equal */
    E->nargpos = arg_places(M, &E->plan, scratch);
    if (!E->nargpos) return 1;
    E->argpos = malloc(E->nargpos * sizeof *E->argpos);
    if (!E->argpos) return 0;
    memcpy(E->argpos, scratch, E->nargpos * sizeof *E->argpos);
    return 1;
}

int lb__cache_usable(const lb_mesh_cache *C, const lb_evaluator *ev, const lb__grid *g) {
    if (!C || !C->valid || C->conv != (int)ev->conv || C->cullable != ev->cullable) return 0;
    if (C->closed != g->closed || C->soft != g->soft || C->tetrahedra != g->tetrahedra ||
        C->features != g->features || C->coarse != g->coarse)
        return 0;
    for (int d = 0; d < 3; ++d)
        if (C->origin[d] != g->origin[d] || C->h[d] != g->h[d] || C->cells[d] != g->cells[d] ||
            (g->closed && (C->bmin[d] != g->bmin[d] || C->bmax[d] != g->bmax[d])))
            return 0;
    return 1;
}

/* A near-face node of block B: local coordinate 0 on some axis. */
static int near_face(const uint32_t l[3]) {
    return !l[0] || !l[1] || !l[2];
}

int lb__cache_export(const lb__block *B, lb__cblock *E) {
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1, D2 = B->nc[2] + 1;
    uint32_t nn = 0, nf = 0;
    if (B->nmask)
        for (uint32_t k = 0; k < D2; ++k)
            for (uint32_t j = 0; j < D1; ++j)
                for (uint32_t i = 0; i < D0; ++i) {
                    const uint32_t l[3] = {i, j, k};
                    nn += near_face(l) && B->nmask[((size_t)k * D1 + j) * D0 + i];
                }
    if (B->fvalid)
        for (size_t e = 0; e < LB__FACE_ENTRIES; ++e) nf += (B->fvalid[e >> 3] >> (e & 7)) & 1;
    E->nnode = nn;
    E->nface = nf;
    E->node = nn ? malloc(nn * sizeof *E->node) : NULL;
    E->ndata = nn ? malloc(4 * nn * sizeof *E->ndata) : NULL;
    E->fe = nf ? malloc(nf * sizeof *E->fe) : NULL;
    E->fent = nf ? malloc(nf * sizeof *E->fent) : NULL;
    if ((nn && (!E->node || !E->ndata)) || (nf && (!E->fe || !E->fent))) return 0;
    uint32_t w = 0;
    for (uint32_t k = 0; k < D2 && nn; ++k)
        for (uint32_t j = 0; j < D1; ++j)
            for (uint32_t i = 0; i < D0; ++i) {
                const uint32_t l[3] = {i, j, k};
                const size_t q = ((size_t)k * D1 + j) * D0 + i;
                if (!near_face(l) || !B->nmask[q]) continue;
                E->node[w] = (uint16_t)q;
                E->ndata[4 * w] = B->vals[q];
                memcpy(E->ndata + 4 * w + 1, B->grads + 3 * q, 3 * sizeof(double));
                ++w;
            }
    w = 0;
    for (size_t e = 0; e < LB__FACE_ENTRIES && nf; ++e)
        if ((B->fvalid[e >> 3] >> (e & 7)) & 1) {
            E->fe[w] = (uint16_t)e;
            E->fent[w++] = B->ftab[e];
        }
    return 1;
}

void lb__cache_import(const lb__cblock *E, lb__block *B) {
    for (uint32_t w = 0; w < E->nnode; ++w) {
        const size_t q = E->node[w];
        B->nmask[q] = 1;
        B->vals[q] = E->ndata[4 * w];
        memcpy(B->grads + 3 * q, E->ndata + 4 * w + 1, 3 * sizeof(double));
    }
    for (uint32_t w = 0; w < E->nface; ++w) {
        const size_t e = E->fe[w];
        B->ftab[e] = E->fent[w];
        B->fvalid[e >> 3] |= (uint8_t)(1u << (e & 7));
    }
}

static size_t cblock_bytes(const lb__cblock *E) {
    const size_t own = sizeof *E + E->plan.nlist * sizeof(uint32_t) +
                       E->plan.nact_total * sizeof(uint16_t) + E->nargpos * sizeof(uint32_t);
    if (E->slab) return own; /* the slabs count on their own */
    size_t bytes[NARRAYS], arrays = 0;
    entry_sizes(E, bytes);
    for (size_t i = 0; i < NARRAYS; ++i) arrays += bytes[i];
    return own + arrays;
}

void lb__cache_counts(const lb_mesh_cache *C, size_t *nv, size_t *nt) {
    *nv = C->counts[0];
    *nt = C->counts[1];
}

lb_status lb__cache_commit(lb_mesh_cache *C, lb__cmatch *M, const lb__grid *g, lb__cblock *blocks,
                           size_t n, size_t reused, const size_t counts[2], lb__cblock *nodes,
                           size_t nnodes, int node_depth, lb_error *err) {
    const lb_evaluator *ev = M->ev;
    blocks_free(C);
    C->valid = 0;
    const size_t cap = lb__recs_table_cap(ev->n);
    uint32_t *tab = calloc(cap, sizeof *tab);
    uint32_t *scratch = malloc(lb__cmatch_scratch(M) * sizeof *scratch);
    int ok = tab && scratch;
    for (size_t i = 0; i < n && ok; ++i) ok = set_places(M, &blocks[i], scratch);
    for (size_t i = 0; i < nnodes && ok; ++i) ok = set_places(M, &nodes[i], scratch);
    free(scratch);
    if (!ok) {
        free(tab);
        for (size_t i = 0; i < n; ++i) lb__cblock_free(&blocks[i]);
        free(blocks);
        lb__cnodes_free(nodes, nnodes);
        lb__cmatch_free(M);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create_cached: out of memory");
    }
    lb__recs_free(&C->full);
    lb__recs_free(&C->self);
    free(C->tab);
    C->full = M->full;
    C->self = M->self;
    memset(&M->full, 0, sizeof M->full);
    memset(&M->self, 0, sizeof M->self);
    lb__cmatch_free(M);
    lb__recs_table_fill(&C->full, ev->n, tab, cap);
    C->tab = tab;
    C->tcap = cap;
    C->nins = ev->n;
    C->counts[0] = counts[0];
    C->counts[1] = counts[1];
    C->blocks = blocks;
    C->nblocks = n;
    if (nnodes) qsort(nodes, nnodes, sizeof *nodes, cmp_node); /* made in descent order */
    C->nodes = nodes;
    C->nnodes = nnodes;
    C->node_depth = node_depth;
    C->valid = 1;
    for (int d = 0; d < 3; ++d) {
        C->origin[d] = g->origin[d];
        C->h[d] = g->h[d];
        C->cells[d] = g->cells[d];
        C->bmin[d] = g->bmin[d];
        C->bmax[d] = g->bmax[d];
    }
    C->closed = g->closed;
    C->soft = g->soft;
    C->tetrahedra = g->tetrahedra;
    C->features = g->features;
    C->coarse = g->coarse;
    C->conv = (int)ev->conv;
    C->cullable = ev->cullable;
    size_t bytes = sizeof *C + C->full.off[C->nins] + C->self.off[C->nins] +
                   2 * C->nins * (sizeof(size_t) + sizeof(uint64_t) + 1) +
                   C->tcap * sizeof(uint32_t);
    slab_settle(C);
    for (size_t i = 0; i < n; ++i) bytes += cblock_bytes(&blocks[i]);
    for (size_t i = 0; i < nnodes; ++i) bytes += cblock_bytes(&nodes[i]);
    bytes += spare_bytes(C) + run_bytes(C) + C->tl_bytes + C->slab_bytes +
             (C->slabcap + C->idlecap) * sizeof(lb__slab *) +
             (C->nslabs + C->nidle) * sizeof(lb__slab);
    C->stats.blocks = n;
    C->stats.reused = reused;
    C->stats.recycled += reused > 0;
    C->stats.bytes = bytes;
    return LB_OK;
}

void lb__cache_take_spare(lb_mesh_cache *C, lb_mesh *M, size_t *vcap, size_t *tcap) {
    if (!C->spare_pos) return;
    C->stats.bytes -= spare_bytes(C);
    M->positions = C->spare_pos;
    M->normals = C->spare_nrm;
    M->triangles = C->spare_tri;
    *vcap = C->spare_nv;
    *tcap = C->spare_nt;
    C->spare_pos = C->spare_nrm = NULL;
    C->spare_tri = NULL;
    C->spare_nv = C->spare_nt = 0;
}

void *lb__cache_run_take(lb_mesh_cache *C, int slot, size_t bytes, size_t *got) {
    void *p = C->run[slot].p;
    const size_t have = C->run[slot].bytes;
    C->run[slot].p = NULL;
    C->run[slot].bytes = 0;
    C->stats.bytes -= have;
    if (p && have < bytes) { /* too small: a new one */
        free(p);
        p = NULL;
    }
    *got = have;
    return p;
}

void lb__cache_run_keep(lb_mesh_cache *C, int slot, void *p, size_t bytes) {
    if (C->run[slot].p) { /* cannot happen: each slot's array is out once */
        C->stats.bytes -= C->run[slot].bytes;
        free(C->run[slot].p);
    }
    C->run[slot].p = p;
    C->run[slot].bytes = p ? bytes : 0;
    C->stats.bytes += C->run[slot].bytes;
}

void *lb__cache_tl_take(lb_mesh_cache *C) {
    if (!C->ntl) return NULL;
    void *tl = C->tl[--C->ntl];
    C->tl_bytes -= lb__tl_bytes(tl);
    C->stats.bytes -= lb__tl_bytes(tl);
    return tl;
}

void lb__cache_tl_keep(lb_mesh_cache *C, void *tl) {
    if (!tl) return;
    if (C->ntl == LB__TL_KEEP) {
        lb__tl_free(tl);
        return;
    }
    C->tl[C->ntl++] = tl;
    C->tl_bytes += lb__tl_bytes(tl);
    C->stats.bytes += lb__tl_bytes(tl);
}

/* ---- the public side ---- */

lb_status lb_mesh_cache_create(lb_mesh_cache **out, lb_error *err) {
    if (!out)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_mesh_cache_create: out must be non-NULL");
    *out = calloc(1, sizeof **out);
    if (!*out) return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_cache_create: out of memory");
    (*out)->node_depth = -1;
    return LB_OK;
}

void lb_mesh_cache_recycle(lb_mesh_cache *C, lb_mesh *mesh) {
    if (!C || !mesh || !mesh->positions || !mesh->normals || !mesh->triangles) {
        lb_mesh_free(mesh);
        return;
    }
    C->stats.bytes -= spare_bytes(C);
    spare_free(C);
    /* room as allocated where the C runtime says (a mesh made through a
     * cache keeps a sixteenth more, mesher.c), else the mesh's counts:
     * every library mesh's arrays hold at least those (normals nnormals
     * >= nvertices) */
    C->spare_pos = mesh->positions;
    C->spare_nrm = mesh->normals;
    C->spare_tri = mesh->triangles;
    const size_t vp = lb__usable_size(mesh->positions) / (3 * sizeof(double)),
                 vn = lb__usable_size(mesh->normals) / (3 * sizeof(double)),
                 vt = lb__usable_size(mesh->triangles) / (3 * sizeof(uint32_t));
    const size_t room = vp < vn ? vp : vn;
    C->spare_nv = room > mesh->nvertices ? room : mesh->nvertices;
    C->spare_nt = vt > mesh->ntriangles ? vt : mesh->ntriangles;
    C->stats.bytes += spare_bytes(C);
    free(mesh->corner_normals);
    free(mesh);
}

void lb_mesh_cache_free(lb_mesh_cache *C) {
    if (!C) return;
    spare_free(C);
    for (int i = 0; i < LB__RUN_SLOTS; ++i) free(C->run[i].p);
    for (size_t i = 0; i < C->ntl; ++i) lb__tl_free(C->tl[i]);
    blocks_free(C);
    slabs_free(C);
    lb__recs_free(&C->full);
    lb__recs_free(&C->self);
    free(C->tab);
    free(C);
}

void lb_mesh_cache_stats_get(const lb_mesh_cache *C, lb_mesh_cache_stats *out) {
    if (!out) return;
    if (!C) {
        memset(out, 0, sizeof *out);
        return;
    }
    *out = C->stats;
}
