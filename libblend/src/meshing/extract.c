/* Surface extraction over one block, shared by the two cell methods
 * (cubes.c, the default, and tetra.c): the crossing grid edges (each once,
 * keyed by node and axis mask), their vertices (lb__refine_edges), and the
 * triangulation of each cell polygon once its vertices are placed.
 *
 * Every crossing edge has one owner, the only block that refines its
 * vertex: of the blocks that hold the edge (up to four, when it lies on
 * block faces), the last, in which the edge is off the far faces. The
 * blocks are done from the last to the first (mesher.c), so an owner is
 * done before the blocks that hold its edges on their far faces: it keeps
 * its vertices on its near faces in a table in its node slot (position and
 * index), and they take them from there, as references (block, index). A
 * vertex is the same for every block that uses it, and the mesh needs no
 * search to share it. An edge whose owner is not kept or did not cut it
 * (the owner's interval passes proved its cells there do not cross, and a
 * value near 0 fell the other way in the evaluators' last bit) stays with
 * each block that cuts it, as an orphan keyed by its edge, and the merge
 * shares it by key.
 *
 * A cell method adds polygons (up to LB__MAXPOLY vertices, oriented
 * counter-clockwise seen from outside the solid) through lb__cell_edge and
 * lb__cell_polygon. A polygon is cut into the triangles whose smallest
 * angle is largest, among the diagonals it allows: a cube polygon never
 * uses a diagonal that lies in a face of its cell (where the neighbouring
 * cell might place one too), a tetrahedron's quadrilateral may use either. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct face {
    uint32_t e[LB__MAXPOLY];
    uint64_t ok; /* the vertex pairs a triangle may join (LB__PAIR bits) */
    uint32_t n;
    uint32_t cell; /* its cell: local i | j << 4 | k << 8 */
    uint32_t feat; /* a fan around this local vertex (features.c); NOFEAT: none */
} face;

#define NOFEAT UINT32_MAX

/* One thread's extraction state, reused block after block (lb__bctx_new):
 * the arrays are sized once for the largest block, and the edge map is
 * reset by a stamp instead of a clear. A block has at most EMAP_SIZE
 * crossing edges (one per node and axis mask: every local edge id is
 * distinct) and FACE_MAX polygons (six tetrahedra per cell, or at most
 * four cube loops), so nothing grows in the cell loop. */
#define EMAP_SIZE LB__EMAP_SIZE
#define FACE_MAX ((size_t)6 * LB__MB * LB__MB * LB__MB)

#ifndef LB__FORCE_ORPHANS
#define LB__FORCE_ORPHANS 0
#endif

/* A vertex index in a polygon while the block is extracted: an own edge's
 * index, or REF | a reference's index. */
#define REF 0x80000000u

struct lb__bctx {
    lb__bctx_head h; /* first: the edge map (mesh_internal.h) */
    const lb__grid *g;
    lb__block *B;
    const lb__block *blocks; /* the run's blocks, B's next blocks (index + 1) */
    const uint32_t *nbr;
    int gnext;                 /* bit d: the grid has a block after B along d */
    size_t ne;                 /* own crossing edges so far (< EMAP_SIZE) */
    double *ea, *eb, *pa, *pb; /* inside end, outside end, their phi */
    double *ga, *gb;           /* and their gradients */
    uint32_t *eloc;            /* local node (4 bits per axis) and mask (bits 12-14) */
    uint8_t *orph;             /* 1: an orphan */
    uint64_t *key;             /* an orphan's grid edge key */
    size_t norph;
    size_t nref;   /* references so far */
    uint32_t *ref; /* block and index, 2 per reference */
    double *rpos;  /* their positions */
    double *rnrm;  /* and normals */
    uint32_t cell; /* the cell being cut (face.cell) */
    /* sharp features: candidates (FACE_MAX): their face, position, value
     * and gradient, the polygon's normal sums and the QEF's point */
    uint32_t *cface;
    double *cx, *cy, *cz, *cv, *cgx, *cgy, *cgz, *cn, *cq, *cw;
    uint32_t *perm; /* own edge -> vertex index, when there are orphans */
    face *faces;
    size_t nf; /* polygons so far (< FACE_MAX) */
    lb__mscratch S;
    struct tlscratch *tl; /* two-level blocks' scratch, made on first use */
};
typedef lb__bctx bctx;

/* eloc's flag for a whole edge of a two-level block's coarse cell: never on
 * a block face, so never published */
#define COARSE_EDGE (1u << 15)
static void tl_free(struct tlscratch *T);

/* The near-face table entry of local node l's edge along mask, on the near
 * face of axis d (l[d] = 0, mask without bit d). */
static inline size_t face_entry(int d, const uint32_t l[3], int mask) {
    const int d1 = d == 0 ? 1 : 0, d2 = d == 2 ? 1 : 2;
    const int m = (((mask >> d1) & 1) | ((mask >> d2) & 1) << 1) - 1;
    return ((size_t)d * LB__FACE_NODES + l[d1] * (LB__MB + 1) + l[d2]) * 3 + (size_t)m;
}

/* A new own edge of block C->B from local node (li, lj, lk) along mask,
 * step nodes long (1: a grid edge; 2: a whole coarse edge of a two-level
 * block), vp and vq its end values: its ends, values and gradients into the
 * refinement batch, not an orphan. Returns its index. */
static size_t own_edge(bctx *C, uint32_t li, uint32_t lj, uint32_t lk, int mask, uint32_t step,
                       double vp, double vq) {
    const lb__block *B = C->B;
    const uint32_t D0 = C->h.D0, D1 = C->h.D1;
    const uint64_t gx = (uint64_t)B->b[0] * LB__MB + li, gy = (uint64_t)B->b[1] * LB__MB + lj,
                   gz = (uint64_t)B->b[2] * LB__MB + lk;
    const uint32_t sx = step * (uint32_t)(mask & 1), sy = step * (uint32_t)((mask >> 1) & 1),
                   sz = step * (uint32_t)((mask >> 2) & 1);
    double P[3], Q[3];
    lb__node_pos(C->g, gx, gy, gz, P);
    lb__node_pos(C->g, gx + sx, gy + sy, gz + sz, Q);
    const size_t e = C->ne++;
    const int pin = vp < 0.0;
    memcpy(C->ea + 3 * e, pin ? P : Q, sizeof P);
    memcpy(C->eb + 3 * e, pin ? Q : P, sizeof P);
    C->pa[e] = pin ? vp : vq;
    C->pb[e] = pin ? vq : vp;
    const size_t np = ((size_t)lk * D1 + lj) * D0 + li;
    const size_t nq = ((size_t)(lk + sz) * D1 + (lj + sy)) * D0 + (li + sx);
    memcpy(C->ga + 3 * e, B->grads + 3 * (pin ? np : nq), 3 * sizeof(double));
    memcpy(C->gb + 3 * e, B->grads + 3 * (pin ? nq : np), 3 * sizeof(double));
    C->eloc[e] = li | lj << 4 | lk << 8 | (uint32_t)mask << 12;
    C->orph[e] = 0;
    return e;
}

int64_t lb__cell_edge_new(lb__bctx *C, size_t lid, uint32_t i, uint32_t j, uint32_t k, int op,
                          int oq, const double *c) {
    const lb__block *B = C->B;
    const uint32_t li = i + (op & 1), lj = j + ((op >> 1) & 1), lk = k + ((op >> 2) & 1);
    const int mask = op ^ oq;
    lb__emap_entry *em = &C->h.emap[lid];
    em->stamp = C->h.stamp;
    /* on B's far face along the axes in far (and a next block exists
     * there): the next block at offset far owns the edge */
    const uint32_t loc[3] = {li, lj, lk};
    int far = 0;
    for (int d = 0; d < 3; ++d)
        far |= (!((mask >> d) & 1) && loc[d] == B->nc[d] && ((C->gnext >> d) & 1)) << d;
    int orphan = 0;
    if (far) {
        const uint32_t o = C->nbr[far];
        if (o) {
            const lb__block *O = &C->blocks[o - 1];
            const int d = far & 1 ? 0 : far & 2 ? 1 : 2;
            const uint32_t ol[3] = {far & 1 ? 0 : li, far & 2 ? 0 : lj, far & 4 ? 0 : lk};
            const size_t fe = face_entry(d, ol, mask);
            if ((O->fvalid[fe >> 3] >> (fe & 7)) & 1) {
                const size_t r = C->nref++;
                C->ref[2 * r] = o - 1;
                C->ref[2 * r + 1] = O->ftab[fe].idx;
                memcpy(C->rpos + 3 * r, O->ftab[fe].pos, 3 * sizeof(double));
                memcpy(C->rnrm + 3 * r, O->ftab[fe].nrm, 3 * sizeof(double));
                em->e = REF | (uint32_t)r;
                return (int64_t)(REF | (uint32_t)r);
            }
        }
        orphan = 1; /* not kept, or it did not cut this edge */
    }
    const lb__grid *g = C->g;
    const uint64_t gx = (uint64_t)B->b[0] * LB__MB + li, gy = (uint64_t)B->b[1] * LB__MB + lj,
                   gz = (uint64_t)B->b[2] * LB__MB + lk;
#if LB__FORCE_ORPHANS
    /* the orphan test's build (tests/mesh/test_mesh_orphans.c): every third
     * edge on a near face is an orphan of all the blocks that hold it */
    for (int d = 0; d < 3 && !orphan; ++d)
        if (!((mask >> d) & 1) && !loc[d] && B->b[d] &&
            (lb__node_index(g, gx, gy, gz) * 8u + (uint64_t)mask) % 3 == 0)
            orphan = 1;
#endif
    const size_t e = own_edge(C, li, lj, lk, mask, 1, c[op], c[oq]);
    C->orph[e] = (uint8_t)orphan;
    if (orphan) {
        C->key[e] = lb__node_index(g, gx, gy, gz) * 8u + (uint64_t)mask;
        ++C->norph;
    }
    em->e = (uint32_t)e;
    return (int64_t)e;
}

const lb__grid *lb__cell_grid(const lb__bctx *C) {
    return C->g;
}

int lb__cell_polygon(lb__bctx *C, const uint32_t *e, uint64_t ok, uint32_t n) {
    if (C->nf >= FACE_MAX) return 0; /* cannot happen (FACE_MAX above) */
    face *f = &C->faces[C->nf++];
    f->n = n;
    f->ok = ok;
    f->cell = C->cell;
    f->feat = NOFEAT;
    memcpy(f->e, e, n * sizeof *e);
    return 1;
}

/* The cosine of a triangle's smallest angle (1 for a degenerate one), from
 * its squared side lengths: the smallest angle is the one opposite the
 * shortest side s, between the other two sides u and v, and by the law of
 * cosines its cosine is (u + v - s) / (2 sqrt(u v)). */
static inline double worst_cos(double l0, double l1, double l2) {
    double s, u, v;
    if (l0 <= l1 && l0 <= l2) {
        s = l0, u = l1, v = l2;
    } else if (l1 <= l2) {
        s = l1, u = l0, v = l2;
    } else {
        s = l2, u = l0, v = l1;
    }
    const double den = sqrt(u * v);
    return den > 0.0 ? (u + v - s) / (2.0 * den) : 1.0;
}

static inline double dist2(const double *A, const double *B) {
    const double d[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* triangulate's dynamic programme for a quadrilateral, written out: the
 * same choice (the later split on a tie) and the same triangle order. */
static uint32_t *triangulate4(const face *f, const double *pos, uint32_t *T) {
    const uint32_t *e = f->e;
    const double *P0 = pos + 3 * e[0], *P1 = pos + 3 * e[1], *P2 = pos + 3 * e[2],
                 *P3 = pos + 3 * e[3];
    const double L01 = dist2(P0, P1), L12 = dist2(P1, P2), L23 = dist2(P2, P3), L03 = dist2(P0, P3);
    double best = INFINITY;
    int k = 1;
    if ((f->ok >> LB__PAIR(0, 2)) & 1) { /* triangles 0 2 3 and 0 1 2 */
        const double L02 = dist2(P0, P2);
        double w = worst_cos(L02, L23, L03);
        const double w2 = worst_cos(L01, L12, L02);
        if (w2 > w) w = w2;
        if (w < best) {
            best = w;
            k = 2;
        }
    }
    if ((f->ok >> LB__PAIR(1, 3)) & 1) { /* triangles 0 1 3 and 1 2 3 */
        const double L13 = dist2(P1, P3);
        double w = worst_cos(L01, L13, L03);
        const double w2 = worst_cos(L12, L23, L13);
        if (w2 > w) w = w2;
        if (w < best) k = 1;
    }
    const uint32_t t2[6] = {e[0], e[2], e[3], e[0], e[1], e[2]},
                   t1[6] = {e[0], e[1], e[3], e[1], e[2], e[3]};
    memcpy(T, k == 2 ? t2 : t1, sizeof t2);
    return T + 6;
}

/* Cut polygon f (vertices placed in pos) into f->n - 2 triangles along the
 * allowed diagonals, choosing the triangulation whose smallest angle is
 * largest (dynamic programming over sub-polygons on the cosine of the
 * smallest angle; ties keep the later split). Every polygon a cell method
 * emits has an allowed triangulation (cubes.c checks its table); a
 * tetrahedron's quadrilateral allows both diagonals. */
static uint32_t *triangulate(const face *f, const double *pos, uint32_t *T) {
    const uint32_t n = f->n;
    if (n == 3) {
        T[0] = f->e[0];
        T[1] = f->e[1];
        T[2] = f->e[2];
        return T + 3;
    }
    if (n == 4) return triangulate4(f, pos, T);
    /* squared lengths of the sides and the allowed diagonals */
    double W[LB__MAXPOLY][LB__MAXPOLY], L[LB__MAXPOLY][LB__MAXPOLY];
    uint8_t ok[LB__MAXPOLY][LB__MAXPOLY], K[LB__MAXPOLY][LB__MAXPOLY];
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t b = a + 1; b < n; ++b) {
            ok[a][b] = (uint8_t)((f->ok >> LB__PAIR(a, b)) & 1);
            if (!ok[a][b]) continue;
            L[a][b] = dist2(pos + 3 * f->e[a], pos + 3 * f->e[b]);
        }
    for (uint32_t len = 2; len < n; ++len)
        for (uint32_t a = 0; a + len < n; ++a) {
            const uint32_t b = a + len;
            if (!ok[a][b]) continue; /* never a side of a triangle: W, K unused */
            double best = INFINITY;  /* the largest smallest-angle cosine: lower is better */
            uint8_t bk = (uint8_t)(a + 1);
            for (uint32_t k = b - 1; k > a; --k) {
                if (!ok[a][k] || !ok[k][b]) continue;
                double w = worst_cos(L[a][k], L[k][b], L[a][b]);
                if (k - a >= 2 && W[a][k] > w) w = W[a][k];
                if (b - k >= 2 && W[k][b] > w) w = W[k][b];
                if (w < best) {
                    best = w;
                    bk = (uint8_t)k;
                }
            }
            W[a][b] = best;
            K[a][b] = bk;
        }
    /* emit: an explicit stack of sub-polygons (a, b) */
    uint8_t st[2 * LB__MAXPOLY];
    int sp = 0;
    st[sp++] = 0;
    st[sp++] = (uint8_t)(n - 1);
    while (sp) {
        const uint8_t b = st[--sp], a = st[--sp];
        if (b - a < 2) continue;
        const uint8_t k = K[a][b];
        T[0] = f->e[a];
        T[1] = f->e[k];
        T[2] = f->e[b];
        T += 3;
        st[sp++] = a;
        st[sp++] = k;
        st[sp++] = k;
        st[sp++] = b;
    }
    return T;
}

/* A feature candidate's crease data (C->cw, CW doubles each; used by
 * place_features): the other side's plane (W[0..2] . x + W[3]; W[3] NAN:
 * not on a crease), the point a probe stepped from (4..6), where the
 * plane came from (7), the point the probe is evaluated at (8..10; the
 * polygon's vertex on that side until then). */
#define CW 11
#define W_POLYGON 0.0 /* the polygon's vertex's tangent plane */
#define W_SEEN 1.0    /* evaluated on that side (or that side is flat) */
#define W_PROBE 2.0   /* a probe is being evaluated */
#define W_PROBED 3.0  /* from a probe: the point it left (4..6) is kept if no better */

lb__bctx *lb__bctx_new(const lb_evaluator *ev) {
    lb__bctx *C = calloc(1, sizeof *C);
    if (!C) return NULL;
    C->h.emap = calloc(EMAP_SIZE, sizeof *C->h.emap);
    C->ea = malloc(3 * EMAP_SIZE * sizeof *C->ea);
    C->eb = malloc(3 * EMAP_SIZE * sizeof *C->eb);
    C->ga = malloc(3 * EMAP_SIZE * sizeof *C->ga);
    C->gb = malloc(3 * EMAP_SIZE * sizeof *C->gb);
    C->pa = malloc(EMAP_SIZE * sizeof *C->pa);
    C->pb = malloc(EMAP_SIZE * sizeof *C->pb);
    C->key = malloc(EMAP_SIZE * sizeof *C->key);
    C->eloc = malloc(EMAP_SIZE * sizeof *C->eloc);
    C->orph = malloc(EMAP_SIZE * sizeof *C->orph);
    C->ref = malloc(2 * EMAP_SIZE * sizeof *C->ref);
    C->rpos = malloc(3 * EMAP_SIZE * sizeof *C->rpos);
    C->rnrm = malloc(3 * EMAP_SIZE * sizeof *C->rnrm);
    C->cface = malloc(FACE_MAX * sizeof *C->cface);
    double **cd[10] = {&C->cx,  &C->cy,  &C->cz, &C->cv, &C->cgx,
                       &C->cgy, &C->cgz, &C->cn, &C->cq, &C->cw};
    int cok = 1;
    for (int q = 0; q < 10; ++q) {
        *cd[q] = malloc((q == 9 ? CW : q >= 7 ? 3 : 1) * FACE_MAX * sizeof(double));
        cok = cok && *cd[q];
    }
    C->perm = malloc(EMAP_SIZE * sizeof *C->perm);
    C->faces = malloc(FACE_MAX * sizeof *C->faces);
    lb__mscratch *S = &C->S;
    int ok =
        lb__boxeval_alloc(ev, &S->E, NULL) == LB_OK && lb__plan_alloc(ev, &S->outer, NULL) == LB_OK;
    for (int d = 0; d < LB__MARK_DEPTH; ++d)
        ok = ok && lb__plan_alloc(ev, &S->pool[d], NULL) == LB_OK;
    for (int o = 0; o < 8; ++o) ok = ok && lb__plan_alloc(ev, &S->oct[o], NULL) == LB_OK;
    S->nodes = malloc(7 * LB__SLAB_NODES * sizeof *S->nodes);
    S->nidx = malloc(LB__SLAB_NODES * sizeof *S->nidx);
    S->edges = malloc(10 * EMAP_SIZE * sizeof *S->edges);
    S->eact = malloc(EMAP_SIZE * sizeof *S->eact);
    if (!ok || !C->h.emap || !C->ea || !C->eb || !C->ga || !C->gb || !C->pa || !C->pb || !C->key ||
        !C->eloc || !C->orph || !C->ref || !C->rpos || !C->rnrm || !C->cface || !cok || !C->perm ||
        !C->faces || !S->nodes || !S->nidx || !S->edges || !S->eact) {
        lb__bctx_free(C);
        return NULL;
    }
    return C;
}

void lb__bctx_free(lb__bctx *C) {
    if (!C) return;
    free(C->h.emap);
    free(C->ea);
    free(C->eb);
    free(C->pa);
    free(C->pb);
    free(C->ga);
    free(C->gb);
    free(C->key);
    free(C->eloc);
    free(C->orph);
    free(C->ref);
    free(C->rpos);
    free(C->rnrm);
    free(C->cface);
    free(C->cx);
    free(C->cy);
    free(C->cz);
    free(C->cv);
    free(C->cgx);
    free(C->cgy);
    free(C->cgz);
    free(C->cn);
    free(C->cq);
    free(C->cw);
    free(C->perm);
    free(C->faces);
    tl_free(C->tl);
    lb__mscratch *S = &C->S;
    lb__boxeval_free(&S->E);
    lb__plan_free(&S->outer);
    for (int d = 0; d < LB__MARK_DEPTH; ++d) lb__plan_free(&S->pool[d]);
    for (int o = 0; o < 8; ++o) lb__plan_free(&S->oct[o]);
    free(S->nodes);
    free(S->nidx);
    free(S->edges);
    free(S->eact);
    free(C);
}

lb__mscratch *lb__bctx_scratch(lb__bctx *C) {
    return &C->S;
}

/* Own edges' vertices, in place: those of the block alone first, then the
 * orphans (both in the order found), so that a next block's reference and
 * the merge can count on the first np. perm maps old to new indices. */
static void orphans_last(lb__bctx *C) {
    const size_t n = C->ne, np = n - C->norph;
    size_t a = 0, b = np;
    for (size_t e = 0; e < n; ++e) C->perm[e] = (uint32_t)(C->orph[e] ? b++ : a++);
    /* apply the permutation through the refinement batch (free until the
     * refinement) as a copy */
    double *tmp = C->S.edges;
    double *arr3[4] = {C->ea, C->eb, C->ga, C->gb};
    for (int q = 0; q < 4; ++q) {
        for (size_t e = 0; e < n; ++e) memcpy(tmp + 3 * C->perm[e], arr3[q] + 3 * e, 24);
        memcpy(arr3[q], tmp, 3 * n * sizeof(double));
    }
    double *arr1[2] = {C->pa, C->pb};
    for (int q = 0; q < 2; ++q) {
        for (size_t e = 0; e < n; ++e) tmp[C->perm[e]] = arr1[q][e];
        memcpy(arr1[q], tmp, n * sizeof(double));
    }
    uint64_t *kt = (uint64_t *)(void *)tmp;
    for (size_t e = 0; e < n; ++e) kt[C->perm[e]] = C->key[e];
    memcpy(C->key, kt, n * sizeof *kt);
    uint32_t *lt = (uint32_t *)(void *)tmp;
    for (size_t e = 0; e < n; ++e) lt[C->perm[e]] = C->eloc[e];
    memcpy(C->eloc, lt, n * sizeof *lt);
}

/* The block's own vertices on its near faces into its table (for the
 * blocks before it; only those of the block alone: np). */
static void publish(lb__bctx *C) {
    lb__block *B = C->B;
    const size_t np = C->ne - C->norph;
    for (size_t e = 0; e < np; ++e) {
        const uint32_t w = C->eloc[e];
        if (w & COARSE_EDGE) continue; /* inside the block (two-level blocks) */
        const uint32_t l[3] = {w & 15, (w >> 4) & 15, (w >> 8) & 15};
        const int mask = (int)(w >> 12);
        for (int d = 0; d < 3; ++d) {
            if (l[d] || ((mask >> d) & 1) || !B->b[d]) continue;
            const size_t fe = face_entry(d, l, mask);
            B->ftab[fe].idx = (uint32_t)e;
            memcpy(B->ftab[fe].pos, B->vpos + 3 * e, 3 * sizeof(double));
            memcpy(B->ftab[fe].nrm, B->vnrm + 3 * e, 3 * sizeof(double));
            B->fvalid[fe >> 3] |= (uint8_t)(1u << (fe & 7));
        }
    }
}

/* Sharp features (features.c): each polygon alone in its cell whose
 * vertex normals disagree gets a candidate point (the QEF's, within the
 * cell), moved onto the surface by Newton steps along the gradient there
 * (a point on a crease or corner is on it already; on a curved crease it
 * moves by the crease's deviation from its tangent planes, onto both
 * sides at once: crease_side, probe). A candidate that reaches the surface
 * (|phi| <= 1e-7 h |grad phi|) within FEAT_ITER evaluations (a crease's
 * CREASE_EVALS more) becomes a vertex of the block, after its own vertices alone
 * and before its orphans, and its polygon a fan around it. Vertex indices
 * in the faces are local (own, then references) on entry and stay so. */
#define FEAT_ITER 6
/* How far outside its cell (in cells) a feature point may lie. Where a
 * crease passes just outside a cell, near one of its edges, the surface
 * crosses that edge twice (no sign change, so no vertex) and the cell's
 * polygon joins a vertex on one side of the crease to one on the other
 * across a sliver of solid the grid cannot see. The crease point just
 * outside the cell, joined by the flips to its neighbours', puts the sliver
 * back: on a cube turned off the axes the largest error went from 0.25
 * cells (points kept in their cells) to 2e-6 cells with half a cell of
 * reach, at 32, 64 and 128 cells; a whole cell changed nothing more. */
#define FEAT_REACH 0.5

/* The unit normal of a polygon's local vertex v: an own vertex's, or a
 * reference's (from the owner's near-face table). */
static inline const double *vertex_normal(const lb__block *B, const bctx *C, uint32_t v) {
    return v < C->ne ? B->vnrm + 3 * v : C->rnrm + 3 * (v - C->ne);
}

/* The corners of B's cell (its 12-bit local index, as faces hold it). */
static void cell_box(const lb__grid *g, const lb__block *B, uint32_t cell, double lo[3],
                     double hi[3]) {
    const uint64_t gx = (uint64_t)B->b[0] * LB__MB + (cell & 15),
                   gy = (uint64_t)B->b[1] * LB__MB + ((cell >> 4) & 15),
                   gz = (uint64_t)B->b[2] * LB__MB + ((cell >> 8) & 15);
    lb__node_pos(g, gx, gy, gz, lo);
    lb__node_pos(g, gx + 1, gy + 1, gz + 1, hi);
}

/* A point on a crease may lie anywhere along it; the step's own choice
 * (the least move onto both planes) can leave it beyond a face of its
 * cell that the crease crosses, next to the neighbour's point or past it,
 * and then the fans of the two cannot be flipped into a crease edge (the
 * two new triangles face opposite ways) and the point is unfolded off the
 * crease (features.c): 6 of the 242 points of the clean union of two
 * spheres at 128 cells. So the step also slides the point along the
 * crease's direction t (on both planes still) into its cell, a twentieth
 * of a cell from its faces where the crease's piece in the cell allows
 * (else into the cell itself, else not at all). Only the faces the crease
 * crosses steeply (|t_d| >= 0.1) count: a crease passing just outside the
 * cell, nearly along a face, is where a point beyond the cell belongs
 * (FEAT_REACH). */
static void along_crease(const lb__grid *g, const lb__block *B, uint32_t cell, const double *n1,
                         const double *n2, const double *X, double dx[3]) {
    double t[3] = {n1[1] * n2[2] - n1[2] * n2[1], n1[2] * n2[0] - n1[0] * n2[2],
                   n1[0] * n2[1] - n1[1] * n2[0]};
    const double tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (!(tl > 0.0) || !isfinite(tl)) return;
    for (int d = 0; d < 3; ++d) t[d] /= tl;
    double lo[3], hi[3];
    cell_box(g, B, cell, lo, hi);
    for (int pass = 0; pass < 2; ++pass) {
        double a = -INFINITY, b = INFINITY;
        for (int d = 0; d < 3; ++d) {
            if (!(fabs(t[d]) >= 0.1)) continue;
            const double m = pass ? 0.0 : 0.05 * g->h[d], y = X[d] + dx[d];
            double l0 = (lo[d] + m - y) / t[d], l1 = (hi[d] - m - y) / t[d];
            if (l0 > l1) {
                const double q = l0;
                l0 = l1;
                l1 = q;
            }
            a = fmax(a, l0);
            b = fmin(b, l1);
        }
        if (!(a <= b)) continue;
        const double lam = a > 0.0 ? a : b < 0.0 ? b : 0.0;
        for (int d = 0; d < 3; ++d) dx[d] += lam * t[d];
        return;
    }
}

/* The candidates Newton could not settle (state 2), where the surface near
 * the crease is a fillet far below a cell (a local union's blending
 * volume: its gradient turns within a fraction of a cell, and the distance
 * to the curve's polyline has kinks, so the steps go on alternating):
 * the root of phi along the polygon's mean normal through the QEF's point,
 * bracketed within half a cell either way and halved to the same tolerance
 * (|phi| <= tol |grad phi|). Where no sign change is bracketed the
 * candidate stays rejected. Evaluated in batches (E holds the block's
 * plan). */
#define BISECT_ITER 40
static lb_status settle_by_bisection(const lb_evaluator *ev, const lb__grid *g, bctx *C, size_t nc,
                                     uint8_t *state, double tol, double hmin, double boxmax,
                                     lb_error *err) {
    lb__boxeval *E = &C->S.E;
    /* cv, cgx, cgy: the bracket's ends (t along the unit normal) and phi's
     * sign at its lower end; cgz: the unit normal's length (0: none) */
    size_t nb = 0;
    for (size_t c = 0; c < nc; ++c) {
        if (state[c] != 2) continue;
        const double *n = C->cn + 3 * c;
        const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        C->cgz[c] = l > 0.0 && isfinite(l) ? l : 0.0;
        if (C->cgz[c] > 0.0) {
            state[c] = 3; /* bracketing */
            ++nb;
        }
    }
    if (!nb) return LB_OK;
    /* 21 doubles a candidate, at most one candidate a cell (a cell with two
     * loops has none): 512 x 21 fit the 10 x EMAP_SIZE of the scratch */
    double *x = C->S.edges, *y = x + 3 * nb, *z = y + 3 * nb, *v = z + 3 * nb, *gx = v + 3 * nb,
           *gy = gx + 3 * nb, *gz = gy + 3 * nb;
    /* phi at t = -h/2, 0, h/2 */
    size_t j = 0;
    for (size_t c = 0; c < nc; ++c) {
        if (state[c] != 3) continue;
        const double *n = C->cn + 3 * c, *q = C->cq + 3 * c, l = C->cgz[c];
        for (int k = -1; k <= 1; ++k, ++j) {
            const double t = 0.5 * k * hmin / l;
            x[j] = q[0] + t * n[0];
            y[j] = q[1] + t * n[1];
            z[j] = q[2] + t * n[2];
        }
    }
    lb_status s = lb__boxeval_run(ev, E, j, x, y, z, v, gx, gy, gz, err);
    if (s) return s;
    j = 0;
    for (size_t c = 0; c < nc; ++c) {
        if (state[c] != 3) continue;
        double ph[3];
        for (int k = 0; k < 3; ++k, ++j) {
            const double X[3] = {x[j], y[j], z[j]}, gf[3] = {gx[j], gy[j], gz[j]};
            double gp[3];
            ph[k] = lb__mesh_phi_in(g, boxmax, X, v[j], gf, gp);
        }
        const double h2 = 0.5 * hmin;
        if (!isfinite(ph[0]) || !isfinite(ph[1]) || !isfinite(ph[2])) {
            state[c] = 2;
        } else if ((ph[0] < 0.0) != (ph[1] < 0.0)) {
            C->cv[c] = -h2, C->cgx[c] = 0.0, C->cgy[c] = ph[0] < 0.0 ? -1.0 : 1.0;
        } else if ((ph[1] < 0.0) != (ph[2] < 0.0)) {
            C->cv[c] = 0.0, C->cgx[c] = h2, C->cgy[c] = ph[1] < 0.0 ? -1.0 : 1.0;
        } else {
            state[c] = 2; /* no surface crossed within half a cell */
        }
    }
    for (int it = 0; it < BISECT_ITER; ++it) {
        j = 0;
        for (size_t c = 0; c < nc; ++c) {
            if (state[c] != 3) continue;
            const double *n = C->cn + 3 * c, *q = C->cq + 3 * c, l = C->cgz[c];
            const double t = 0.5 * (C->cv[c] + C->cgx[c]) / l;
            x[j] = q[0] + t * n[0];
            y[j] = q[1] + t * n[1];
            z[j] = q[2] + t * n[2];
            ++j;
        }
        if (!j) break;
        if ((s = lb__boxeval_run(ev, E, j, x, y, z, v, gx, gy, gz, err))) return s;
        j = 0;
        for (size_t c = 0; c < nc; ++c) {
            if (state[c] != 3) continue;
            const double X[3] = {x[j], y[j], z[j]}, gf[3] = {gx[j], gy[j], gz[j]};
            double gp[3];
            const double ph = lb__mesh_phi_in(g, boxmax, X, v[j], gf, gp);
            ++j;
            const double gl = sqrt(gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2]);
            const double mid = 0.5 * (C->cv[c] + C->cgx[c]);
            if (!isfinite(ph)) {
                state[c] = 2;
            } else if (gl > 0.0 && isfinite(gl) && fabs(ph) <= tol * gl) {
                state[c] = 1;
                C->cx[c] = X[0];
                C->cy[c] = X[1];
                C->cz[c] = X[2];
            } else if ((ph < 0.0) == (C->cgy[c] < 0.0)) {
                C->cv[c] = mid;
            } else {
                C->cgx[c] = mid;
            }
        }
    }
    for (size_t c = 0; c < nc; ++c)
        if (state[c] == 3) state[c] = 2;
    return LB_OK;
}

/* A crease, as against a smooth bend sharper than the threshold: the
 * gradient at the QEF's point matches one of the polygon's normals to
 * within 10 degrees (one side's, turned by the side's own curvature over
 * a cell) while another differs by more than the threshold (the other
 * side's). Measured at the QEF's points: min, max, clean unions and the
 * cylinder cut by a slab within 4 degrees on nearly every candidate; S2's
 * fillets at 128 cells none within 15 degrees (a fifth within 10 at 64 and
 * 256 cells, which the check at the next point sends back to plain steps
 * where the gradient there matches neither side). */
#define CREASE_COS 0.98480775301220806 /* cos(10 degrees) */
/* and the QEF's point, on both sides' tangent planes, lies on the surface
 * to within the sides' own curvature over a cell (at most 0.047 cells on
 * the clean union of two spheres at 32 cells, 0.022 on the cylinder cut by
 * a slab); a fillet far below a cell leaves it farther (0.19 cells in the
 * median on the local union with R = 0.005 at 128 cells), and there the
 * sides' planes do not meet on the surface */
#define CREASE_NEAR 0.1

static inline double cos_to(const double *g, double gl, const double *p) {
    const double pl = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]) / (gl * pl);
}

/* evaluations a crease candidate may take beyond FEAT_ITER: the probe and
 * the steps from its plane (quadratic: two, and one to spare) */
#define CREASE_EVALS 3
/* two gradients this close (cos 5.7 degrees) are one side's */
#define SIDES_COS 0.99498743710661997

/* W: the other side's plane (unit normal, offset) at the polygon vertex
 * whose normal differs most from the gradient g at the QEF's point, when
 * that point is on a crease (above); NAN offset otherwise. The plane is
 * exact (W_SEEN) when that side is flat across the polygon: every vertex
 * whose normal is within CREASE_COS of that one has the same normal and
 * lies on the plane. */
static void crease_side(const lb__block *B, const bctx *C, uint32_t f, const double *g, double gl,
                        double tol, double W[CW]) {
    const face *F = &C->faces[f];
    W[7] = W_POLYGON;
    double ca = -2.0, cb = 2.0;
    uint32_t vb = 0;
    for (uint32_t q = 0; q < F->n; ++q) {
        const double *n = vertex_normal(B, C, F->e[q]);
        const double cs = (n[0] * g[0] + n[1] * g[1] + n[2] * g[2]) / gl;
        if (cs > ca) ca = cs;
        if (cs < cb) cb = cs, vb = F->e[q];
    }
    W[3] = NAN;
    if (!(ca >= CREASE_COS && cb < LB__FEATURE_COS)) return;
    const double *n = vertex_normal(B, C, vb), *p = B->vpos + 3 * (size_t)vb;
    memcpy(W, n, 3 * sizeof *n);
    W[3] = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]);
    memcpy(W + 8, p, 3 * sizeof *p);
    W[7] = W_SEEN;
    for (uint32_t q = 0; q < F->n; ++q) {
        const double *m = vertex_normal(B, C, F->e[q]), *r = B->vpos + 3 * (size_t)F->e[q];
        const double cs = m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
        if (cs < CREASE_COS) continue;
        if (!(cs >= 1.0 - 1e-12) || !(fabs(n[0] * r[0] + n[1] * r[1] + n[2] * r[2] + W[3]) <= tol))
            W[7] = W_POLYGON;
    }
}

/* A candidate that failed after a probe keeps the point the probe left
 * (on the surface, on the polygon's plane of the other side): state 1;
 * any other is rejected (2) */
static uint8_t settle_at_probe(bctx *C, size_t c, const double *W) {
    if (W[7] != W_PROBED) return 2;
    C->cx[c] = W[4];
    C->cy[c] = W[5];
    C->cz[c] = W[6];
    return 1;
}

/* The probe for a point X on the surface and on the other side's plane
 * as the polygon gave it (W): the point a step d along that plane towards
 * the polygon's vertex on that side (W[8..10]), to be evaluated in place
 * of X (saved in W[4..6]); 0 when that vertex is no farther than rounding
 * along the plane. The true crease lies off the polygon's plane by that
 * side's curvature over the distance to the vertex (up to 0.06 cells on
 * the clean union of two spheres at 32 cells); an eighth of a cell
 * crosses it there, and the plane taken at the probe is off at X by the
 * curvature over an eighth of a cell (1e-3 cells at 32 cells). */
static int probe(double W[CW], const double *X, double d) {
    double u[3] = {W[8] - X[0], W[9] - X[1], W[10] - X[2]};
    const double un = u[0] * W[0] + u[1] * W[1] + u[2] * W[2];
    for (int k = 0; k < 3; ++k) u[k] -= un * W[k];
    const double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(ul > 1e-9 * d)) return 0;
    memcpy(W + 4, X, 3 * sizeof *X);
    for (int k = 0; k < 3; ++k) W[8 + k] = X[k] + fmin(d, ul) * u[k] / ul;
    W[7] = W_PROBE;
    return 1;
}

/* cos(acos(LB__FEATURE_COS) / 2) = sqrt((1 + 0.9) / 2) = 0.974679..., a
 * little above: two normals each within this of a third (unit to an ulp or
 * two, as the edge refinement leaves them) are within LB__FEATURE_COS of
 * each other with room for rounding (25.838 against 25.842 degrees) */
#define NEAR_COS 0.9747 /* to be derived again if LB__FEATURE_COS changes */

static lb_status place_features(const lb_evaluator *ev, const lb__grid *g, lb__block *B, bctx *C,
                                lb_error *err) {
    const size_t ne = C->ne, nref = C->nref, np0 = ne - C->norph;
    size_t nc = 0;
    for (size_t f = 0; f < C->nf; ++f) {
        face *F = &C->faces[f];
        if ((f > 0 && C->faces[f - 1].cell == F->cell) ||
            (f + 1 < C->nf && C->faces[f + 1].cell == F->cell))
            continue; /* two loops in one cell: their fans could cross */
        /* most polygons bend little: all their normals within half the
         * threshold's angle of the first (cos >= NEAR_COS) keeps every pair
         * within it (angles add), so the pairs need no test */
        const double *n0 = vertex_normal(B, C, F->e[0]);
        uint32_t q0 = 1;
        for (; q0 < F->n; ++q0) {
            const double *nq = vertex_normal(B, C, F->e[q0]);
            if (!(n0[0] * nq[0] + n0[1] * nq[1] + n0[2] * nq[2] >= NEAR_COS)) break;
        }
        if (q0 == F->n) continue;
        double P[3 * LB__MAXPOLY], N[3 * LB__MAXPOLY], ns[3] = {0, 0, 0};
        double mincos = 1.0;
        for (uint32_t q = 0; q < F->n; ++q) {
            const uint32_t v = F->e[q];
            memcpy(P + 3 * q, B->vpos + 3 * v, 3 * sizeof(double));
            memcpy(N + 3 * q, vertex_normal(B, C, v), 3 * sizeof(double));
            for (int d = 0; d < 3; ++d) ns[d] += N[3 * q + d];
            for (uint32_t r = 0; r < q; ++r) {
                const double cs =
                    N[3 * q] * N[3 * r] + N[3 * q + 1] * N[3 * r + 1] + N[3 * q + 2] * N[3 * r + 2];
                if (cs < mincos) mincos = cs;
            }
        }
        if (!(mincos < LB__FEATURE_COS)) continue;
        double lo[3], hi[3], X[3];
        cell_box(g, B, F->cell, lo, hi);
        for (int d = 0; d < 3; ++d) {
            lo[d] -= FEAT_REACH * g->h[d];
            hi[d] += FEAT_REACH * g->h[d];
        }
        if (!lb__feature_qef(P, N, (int)F->n, lo, hi, X)) continue;
        C->cface[nc] = (uint32_t)f;
        C->cx[nc] = X[0];
        C->cy[nc] = X[1];
        C->cz[nc] = X[2];
        memcpy(C->cn + 3 * nc, ns, sizeof ns);
        memcpy(C->cq + 3 * nc, X, sizeof X);
        C->cv[nc] = NAN;          /* no earlier point (the crease step, below) */
        C->cw[CW * nc + 3] = NAN; /* no other side yet (crease_side, below) */
        C->cw[CW * nc + 7] = W_POLYGON;
        ++nc;
    }
    if (!nc) return LB_OK;
    double hmin = fmin(g->h[0], fmin(g->h[1], g->h[2]));
    const double tol = 1e-7 * hmin, boxmax = lb__block_boxmax(g, B);
    lb__boxeval *E = &C->S.E;
    /* the octant plans where the block has them (mesher.c, block_nodes:
     * a point inside an octant's box is evaluated under that octant's
     * plan, about half the block's arguments on S2; any other point, in
     * the block or within a cell or so of it, under the block's) */
    double obox[8][6];
    const int octs = B->octmem != NULL;
    for (int o = 0; octs && o < 8; ++o) {
        uint32_t l0[3], l1[3];
        lb__octant_nodes(B, o, l0, l1);
        lb__node_box(g, B, l0, l1, obox[o], obox[o] + 3);
    }
    /* each candidate's state; cv, cgx..cgz hold the tangent plane of its
     * last point (cv NAN: none yet) for the crease step, cw its crease data
     * (CW: the other side's plane, the probe). The scratch's first bytes
     * (eact): the states, each moving candidate's plan group, and the
     * candidates in the order evaluated (nc <= 512) */
    uint8_t *state = (uint8_t *)C->S.eact, *grp = state + 512;
    uint32_t *ord = (uint32_t *)(void *)(state + 1024);
    memset(state, 0, nc);
    for (int it = 0; it < FEAT_ITER + CREASE_EVALS; ++it) {
        /* the moving ones, packed at the scratch's start, by plan group:
         * octant o (0..7), the block (8) */
        size_t start[10] = {0};
        for (size_t c = 0; c < nc; ++c) {
            if (state[c]) continue;
            int o = 8;
            const double X[3] = {C->cx[c], C->cy[c], C->cz[c]};
            for (int q = 0; octs && q < 8 && o == 8; ++q)
                if (X[0] >= obox[q][0] && X[0] <= obox[q][3] && X[1] >= obox[q][1] &&
                    X[1] <= obox[q][4] && X[2] >= obox[q][2] && X[2] <= obox[q][5])
                    o = q;
            grp[c] = (uint8_t)o;
            ++start[o + 1];
        }
        for (int q = 0; q < 9; ++q) start[q + 1] += start[q];
        const size_t na = start[9];
        if (!na) break;
        double *x = C->S.edges, *y = x + na, *z = y + na, *v = z + na, *gxx = v + na,
               *gyy = gxx + na, *gzz = gyy + na;
        size_t fill[9];
        memcpy(fill, start, sizeof fill);
        for (size_t c = 0; c < nc; ++c)
            if (!state[c]) {
                const size_t j = fill[grp[c]]++;
                x[j] = C->cx[c];
                y[j] = C->cy[c];
                z[j] = C->cz[c];
                ord[j] = (uint32_t)c;
            }
        for (int q = 0; q < 9; ++q) {
            const size_t a = start[q], n = start[q + 1] - a;
            if (!n) continue;
            lb__boxeval_load(ev, q < 8 ? &B->oct[q] : &B->plan, E);
            lb_status s = lb__boxeval_run(ev, E, n, x + a, y + a, z + a, v + a, gxx + a, gyy + a,
                                          gzz + a, err);
            if (s) return s;
        }
        for (size_t j = 0; j < na; ++j) {
            const size_t c = ord[j];
            double Xc[3] = {x[j], y[j], z[j]};
            const double gf[3] = {gxx[j], gyy[j], gzz[j]};
            double gp[3];
            double ph = lb__mesh_phi_in(g, boxmax, Xc, v[j], gf, gp);
            double gl2 = gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2];
            const int valid = isfinite(ph) && gl2 > 0.0 && isfinite(gl2);
            double *W = C->cw + CW * c;
            double last[4] = {C->cgx[c], C->cgy[c], C->cgz[c], C->cv[c]};
            const double *other = NULL;
            int swapped = 0;
            if (W[7] == W_PROBE) {
                /* the probe beyond the crease: where its gradient is the
                 * other side's (within CREASE_COS of the polygon's normal
                 * there), its plane replaces the polygon's and the point
                 * steps again from where it was; otherwise (a fillet
                 * between the sides, or the same side) the point stays
                 * where it was */
                const double gl = sqrt(gl2);
                memcpy(Xc, W + 4, sizeof Xc);
                if (!valid || !(cos_to(gp, gl, W) >= CREASE_COS) ||
                    cos_to(gp, gl, last) >= SIDES_COS) {
                    C->cx[c] = Xc[0];
                    C->cy[c] = Xc[1];
                    C->cz[c] = Xc[2];
                    state[c] = 1;
                    continue;
                }
                memcpy(W, gp, sizeof gp);
                W[3] = ph - (gp[0] * W[8] + gp[1] * W[9] + gp[2] * W[10]);
                W[7] = W_PROBED;
                memcpy(gp, last, sizeof gp);
                gl2 = gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2];
                ph = gp[0] * Xc[0] + gp[1] * Xc[1] + gp[2] * Xc[2] + last[3];
                other = W;
            } else {
                if (!valid) {
                    state[c] = settle_at_probe(C, c, W);
                    continue;
                }
                if (it == 0 && fabs(ph) <= CREASE_NEAR * hmin * sqrt(gl2))
                    crease_side(B, C, C->cface[c], gp, sqrt(gl2), tol, W);
                if (fabs(ph) <= tol * sqrt(gl2)) {
                    if (isfinite(W[3]) && W[7] == W_POLYGON && it < FEAT_ITER &&
                        probe(W, Xc, 0.125 * hmin)) {
                        /* on the surface, and on the other side's plane
                         * as the polygon gave it: that side's own plane
                         * comes from a point just beyond the crease */
                        C->cgx[c] = gp[0];
                        C->cgy[c] = gp[1];
                        C->cgz[c] = gp[2];
                        C->cv[c] = ph - (gp[0] * Xc[0] + gp[1] * Xc[1] + gp[2] * Xc[2]);
                        C->cx[c] = W[8];
                        C->cy[c] = W[9];
                        C->cz[c] = W[10];
                        continue;
                    }
                    state[c] = 1;
                    continue;
                }
                /* the step from the probe's plane landed off the surface by
                 * more than a sharp crease allows (CREASE_NEAR): the sides
                 * meet in a fillet, whose field there is not theirs */
                if (W[7] == W_PROBED && isfinite(W[3]) &&
                    !(fabs(ph) <= CREASE_NEAR * hmin * sqrt(gl2))) {
                    state[c] = settle_at_probe(C, c, W);
                    continue;
                }
                if (it >= FEAT_ITER - 1 + (W[7] != W_POLYGON ? CREASE_EVALS : 0)) {
                    state[c] = settle_at_probe(C, c, W);
                    continue;
                }
                if (isfinite(W[3])) {
                    if (!isfinite(last[3])) {
                        other = W;
                    } else {
                        /* which side this point is on: the one whose last
                         * plane its gradient matches; neither (a smooth
                         * bend after all): plain steps from here on */
                        const double gl = sqrt(gl2), cl = cos_to(gp, gl, last),
                                     cw = cos_to(gp, gl, W);
                        if (!(fmax(cl, cw) >= CREASE_COS)) {
                            if (W[7] == W_PROBED) { /* back to where the probe left */
                                state[c] = settle_at_probe(C, c, W);
                                continue;
                            }
                            W[3] = NAN;
                            other = last;
                        } else if (cw > cl) {
                            other = last; /* crossed to the other side */
                            swapped = 1;
                        } else {
                            other = W;
                        }
                    }
                } else if (isfinite(last[3])) {
                    other = last;
                }
            }
            /* the step: onto the tangent plane here, and where the last
             * point saw another side of the crease, onto that side's
             * tangent plane too (the shortest step onto both: a Newton step
             * for the crease, which plain steps, alternating between its
             * sides, approach only linearly). On a crease the other side's
             * plane is the last one seen on that side. */
            double dx[3] = {-ph * gp[0] / gl2, -ph * gp[1] / gl2, -ph * gp[2] / gl2};
            if (other) {
                const double h2[3] = {other[0], other[1], other[2]};
                const double r2 = h2[0] * Xc[0] + h2[1] * Xc[1] + h2[2] * Xc[2] + other[3];
                const double a11 = gl2, a22 = h2[0] * h2[0] + h2[1] * h2[1] + h2[2] * h2[2],
                             a12 = gp[0] * h2[0] + gp[1] * h2[1] + gp[2] * h2[2];
                const double det = a11 * a22 - a12 * a12;
                if (det > 1e-2 * a11 * a22) { /* the two sides differ by > 5.7 degrees */
                    const double l1 = (-ph * a22 + r2 * a12) / det,
                                 l2 = (-r2 * a11 + ph * a12) / det;
                    for (int d = 0; d < 3; ++d) dx[d] = l1 * gp[d] + l2 * h2[d];
                    along_crease(g, B, C->faces[C->cface[c]].cell, gp, h2, Xc, dx);
                }
            }
            /* a step longer than a cell: not a crease this point can reach
             * (a vanishing gradient, or sides that barely differ) */
            if (!(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2] <= hmin * hmin)) {
                state[c] = settle_at_probe(C, c, W);
                continue;
            }
            if (swapped) { /* the plane left behind is the other side's now */
                memcpy(W, last, sizeof last);
                if (W[7] == W_POLYGON) W[7] = W_SEEN;
            }
            C->cgx[c] = gp[0];
            C->cgy[c] = gp[1];
            C->cgz[c] = gp[2];
            C->cv[c] = ph - (gp[0] * Xc[0] + gp[1] * Xc[1] + gp[2] * Xc[2]);
            C->cx[c] = Xc[0] + dx[0];
            C->cy[c] = Xc[1] + dx[1];
            C->cz[c] = Xc[2] + dx[2];
        }
    }
    lb__boxeval_load(ev, &B->plan, E); /* the bisection's points: the block's plan */
    lb_status s = settle_by_bisection(ev, g, C, nc, state, tol, hmin, boxmax, err);
    if (s) return s;
    size_t nfeat = 0;
    for (size_t c = 0; c < nc; ++c) nfeat += state[c] == 1;
    if (!nfeat) return LB_OK;
    double *vp = realloc(B->vpos, 3 * (ne + nfeat + nref) * sizeof *vp);
    if (vp) B->vpos = vp;
    double *vn = realloc(B->vnrm, 3 * (ne + nfeat) * sizeof *vn);
    if (vn) B->vnrm = vn;
    if (!vp || !vn) return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    /* make room after the vertices of the block alone: orphans and
     * references move up by nfeat */
    memmove(B->vpos + 3 * (np0 + nfeat), B->vpos + 3 * np0, 3 * (ne - np0 + nref) * sizeof(double));
    memmove(B->vnrm + 3 * (np0 + nfeat), B->vnrm + 3 * np0, 3 * (ne - np0) * sizeof(double));
    for (size_t f = 0; f < C->nf; ++f) {
        face *F = &C->faces[f];
        for (uint32_t q = 0; q < F->n; ++q)
            if (F->e[q] >= np0) F->e[q] += (uint32_t)nfeat;
    }
    size_t k = np0;
    for (size_t c = 0; c < nc; ++c) {
        if (state[c] != 1) continue;
        double *P = B->vpos + 3 * k, *Nn = B->vnrm + 3 * k;
        P[0] = C->cx[c];
        P[1] = C->cy[c];
        P[2] = C->cz[c];
        /* the vertex normal: the mean of its polygon's (a crease's sides
         * averaged; per-corner normals are the renderer's business) */
        const double *ns = C->cn + 3 * c;
        const double l = sqrt(ns[0] * ns[0] + ns[1] * ns[1] + ns[2] * ns[2]);
        for (int d = 0; d < 3; ++d) Nn[d] = l > 0.0 ? ns[d] / l : (d == 2);
        C->faces[C->cface[c]].feat = (uint32_t)k;
        ++k;
    }
    B->nfeat = nfeat;
    B->np = np0 + nfeat;
    B->nv = ne + nfeat;
    return LB_OK;
}

/* One cell (i, j, k) of block B whose corner values are final: its
 * polygons by the grid's cell method. 0 when out of memory. */
static inline int cut_cell(bctx *C, const lb__grid *g, const lb__block *B, uint32_t i, uint32_t j,
                           uint32_t k) {
    const uint32_t D0 = C->h.D0, D1 = C->h.D1;
    double c[8];
    int cfg = 0; /* bit o: corner o inside */
    for (int o = 0; o < 8; ++o) {
        const size_t idx =
            ((size_t)(k + ((o >> 2) & 1)) * D1 + (j + ((o >> 1) & 1))) * D0 + (i + (o & 1));
        c[o] = B->vals[idx];
        cfg |= (c[o] < 0.0) << o;
    }
    if (cfg == 0 || cfg == 255) return 1;
    C->cell = i | j << 4 | k << 8;
    return (g->tetrahedra ? lb__tetra_cell : lb__cube_cell)(C, i, j, k, c, cfg);
}

/* ---- two-level blocks (LB_MESH_COARSE_FIRST; docs/meshing.md, "How it
 * fits the block mesher") ----
 * The block's 4^3 coarse cells (mark()'s smallest boxes: a coarse cell is
 * marked whole or not at all) are decided in rounds. A round takes every
 * marked coarse cell not yet decided, or decided coarse but whose pattern
 * (lb__tcell: its edges split on the block's boundary planes and where a
 * fine cell is around them, its faces quartered on those planes and where
 * the cell across is fine) has changed, evaluates the samples its pattern
 * reads, and makes it fine when
 * - its samples show no crossing but one of its other nodes is on the other
 *   side (the corners miss a part of the surface that mark()'s interval
 *   did not rule out), or
 * - a loop has no triangulation that keeps off its faces and does not fold
 *   (lb__tloop_triangles), or
 * - a triangle bows out by more than the tolerance: its centroid's or an
 *   edge midpoint's |phi| / |grad phi|, or an edge of length L whose end
 *   normals turn by an angle a (a circular arc: L a / 8), over the
 *   tolerance in cells of the smallest side.
 * Cells only ever turn fine, so the rounds end (at most one per cell); the
 * result depends on the block's node values and plan alone. Then the fine
 * cells' nodes are evaluated and their cells cut by the cube cases, and the
 * coarse cells' loops give triangles through the block's own vertex
 * sharing: every sub-edge of a coarse cell that is a grid edge is one
 * (lb__cell_edge: shared with the fine cells and, on the block's faces,
 * with the next blocks as now); a whole coarse edge, never on a boundary
 * plane, is the block's own (tl_coarse_edge). The decisions solve each
 * sub-edge's vertex once for the block (tlroot); the refinement after the
 * cells takes those and solves only the rest (the same inputs would give
 * the same positions). */
#define TL_SIDE (LB__MB / 2)
#define TL_CELLS (TL_SIDE * TL_SIDE * TL_SIDE)
#define TL_EDGES ((size_t)TL_CELLS * LB__TMAX)
/* check points: under LB__TMAX triangles a cell, 4 points each */
#define TL_POINTS ((size_t)TL_CELLS * LB__TMAX * 4)
#define TL_NODES ((size_t)TL_CELLS * LB__TNODES)
#define TL_D ((size_t)LB__MB + 1) /* a whole block's nodes a side */
#define TL_CHKS_BITS 13           /* the block's check points by their roots (tl_check) */
#define TL_CHKS (1u << TL_CHKS_BITS)

enum { TL_OFF, TL_TODO, TL_OK, TL_FINE };

typedef struct tlcell {
    lb__tcell t; /* the pattern it was decided with */
    uint16_t sub[LB__TMAX];
    uint16_t key[LB__TMAX]; /* its sub-edges' roots (tlroot) */
    uint8_t len[LB__TMAX / 3];
    uint8_t tri[3 * LB__TMAX]; /* the loops' triangles, as positions in sub */
    uint8_t nloop, ntri, state;
} tlcell;

/* The root on a sub-edge, solved once per block: a sub-edge is in the loops
 * of up to four coarse cells, and its root depends only on its two nodes,
 * so the rounds share it, and the block's refinement takes it as it is
 * (the same inputs to lb__refine_edges, the same bytes). Keyed by the
 * sub-edge's lower node, axis and length (tl_key). */
typedef struct tlroot {
    double pos[3], nrm[3];
} tlroot;
#define TL_KEYS (TL_D * TL_D * TL_D * 6)

/* A coarse cell's fixed surroundings in its block (made once, tl_new) */
typedef struct tlgeom {
    uint16_t plane_split;  /* its edges on the block's boundary planes */
    uint8_t plane_quarter; /* its faces on them */
    uint8_t fnbr[6];       /* the cell across each face (0xff: none) */
    uint8_t enbr[12][3];   /* the other cells around each edge (0xff: none) */
} tlgeom;

/* lb__tcell_loops' answers by pattern (tl_loops): patterns repeat across
 * cells, blocks and rounds (key + 1; 0: empty) */
#define TL_LCACHE 4096u
typedef struct tlloops {
    int16_t total;
    uint8_t nloop;
    uint8_t len[LB__TMAX / 3];
    uint16_t sub[LB__TMAX];
} tlloops;

struct tlscratch {
    tlcell cell[TL_CELLS];
    uint64_t lkey[TL_LCACHE]; /* apart from the answers: most lookups miss */
    tlloops lcache[TL_LCACHE];
    tlgeom geom[TL_CELLS];
    uint8_t elat[12][3]; /* cube edge e's lattice nodes: its ends, its midpoint */
    tlroot root[TL_KEYS];
    /* T->rstamp: the root is solved in this block (apart from root: the
     * decisions test these far more often than they read a root) */
    uint32_t rdone[TL_KEYS];
    uint32_t rstamp;
    uint16_t bkey[TL_EDGES]; /* the round's batch: each sub-edge's key */
    uint8_t *known;          /* the block's own edges solved in the decisions */
    /* a cell's pattern may have changed: a cell around it turned fine in
     * the last round (seen: its turn has been passed on) */
    uint8_t dirty[TL_CELLS], seen[TL_CELLS];
    size_t *q;                                       /* nodes to evaluate (TL_NODES) */
    double *ea, *eb, *pa, *pb, *ga, *gb, *pos, *nrm; /* the round's sub-edges (TL_EDGES) */
    double *x, *y, *z, *v, *gx, *gy, *gz;            /* points to evaluate (TL_POINTS) */
    double *sx;      /* the same, grouped by octant (7 TL_POINTS; tl_eval) */
    uint8_t *poct;   /* a point's octant of the block (its plan) */
    size_t *pord;    /* tl_eval's grouping */
    uint8_t *pcell;  /* a check point's cell */
    uint8_t *pcell2; /* and the other cell whose triangles hold that edge (0xff: none) */
    uint32_t *pslot; /* a check point's entry in chk (TL_NOSLOT: none) */
    /* the block's check points by the roots they are made of (tl_check):
     * this round's (info: TL_PENDING | index), the earlier rounds' results
     * (TL_PASS, TL_FAIL) */
    struct tlchk {
        uint64_t key;
        uint32_t stamp, info;
    } chk[TL_CHKS];
    uint32_t nchk; /* entries made in this block (at most TL_CHKS / 2) */
    size_t bytes;  /* all of it, as tl_new allocated it (lb__tl_bytes) */
};
typedef struct tlscratch tlscratch;

static void tl_free(tlscratch *T) {
    if (!T) return;
    free(T->q);
    free(T->ea);
    free(T->x);
    free(T->pcell);
    free(T->pcell2);
    free(T->pslot);
    free(T->poct);
    free(T->pord);
    free(T->known);
    free(T);
}

void *lb__bctx_tl_swap(lb__bctx *C, void *tl) {
    void *had = C->tl;
    C->tl = tl;
    return had;
}

void lb__tl_free(void *tl) {
    tl_free(tl);
}

size_t lb__tl_bytes(const void *tl) {
    return ((const tlscratch *)tl)->bytes;
}

/* malloc(n), n added to *sum */
static void *tl_alloc(size_t n, size_t *sum) {
    *sum += n;
    return malloc(n);
}

static tlscratch *tl_new(void) {
    tlscratch *T = calloc(1, sizeof *T);
    if (!T) return NULL;
    size_t *sum = &T->bytes;
    *sum = sizeof *T;
    T->q = tl_alloc(TL_NODES * sizeof *T->q, sum);
    T->ea = tl_alloc(20 * TL_EDGES * sizeof *T->ea, sum);
    T->x = tl_alloc(14 * TL_POINTS * sizeof *T->x, sum);
    T->pcell = tl_alloc(TL_POINTS * sizeof *T->pcell, sum);
    T->pcell2 = tl_alloc(TL_POINTS * sizeof *T->pcell2, sum);
    T->pslot = tl_alloc(TL_POINTS * sizeof *T->pslot, sum);
    T->poct = tl_alloc(TL_POINTS * sizeof *T->poct, sum);
    T->pord = tl_alloc(TL_POINTS * sizeof *T->pord, sum);
    T->known = tl_alloc(EMAP_SIZE, sum);
    if (!T->q || !T->ea || !T->x || !T->pcell || !T->pcell2 || !T->pslot || !T->poct || !T->pord ||
        !T->known) {
        tl_free(T);
        return NULL;
    }
    T->eb = T->ea + 3 * TL_EDGES;
    T->ga = T->eb + 3 * TL_EDGES;
    T->gb = T->ga + 3 * TL_EDGES;
    T->pos = T->gb + 3 * TL_EDGES;
    T->nrm = T->pos + 3 * TL_EDGES;
    T->pa = T->nrm + 3 * TL_EDGES;
    T->pb = T->pa + TL_EDGES;
    T->y = T->x + TL_POINTS;
    T->z = T->y + TL_POINTS;
    T->v = T->z + TL_POINTS;
    T->gx = T->v + TL_POINTS;
    T->gy = T->gx + TL_POINTS;
    T->gz = T->gy + TL_POINTS;
    T->sx = T->gz + TL_POINTS;
    for (int e = 0; e < 12; ++e) {
        int p, q;
        lb__cube_edge(e, &p, &q);
        T->elat[e][0] = (uint8_t)LB__TCORNER(p);
        T->elat[e][1] = (uint8_t)LB__TCORNER(q);
        T->elat[e][2] = (uint8_t)((LB__TCORNER(p) + LB__TCORNER(q)) / 2);
    }
    for (int ci = 0; ci < TL_CELLS; ++ci) {
        const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
        tlgeom *G = &T->geom[ci];
        memset(G, 0xff, sizeof *G);
        G->plane_split = 0;
        G->plane_quarter = 0;
        for (int e = 0; e < 12; ++e) {
            int p, q, m = 0;
            lb__cube_edge(e, &p, &q);
            const int a = p ^ q;
            for (int d = 0; d < 3; ++d) {
                if ((1 << d) == a) continue;
                const int at = c[d] + ((p >> d) & 1);
                if (at == 0 || at == TL_SIDE) G->plane_split |= (uint16_t)(1u << e);
            }
            for (int k = 0; k < 4; ++k) { /* the four cells around it */
                int n[3], j = 0;
                for (int d = 0; d < 3; ++d) {
                    n[d] = c[d];
                    if ((1 << d) != a) n[d] += ((p >> d) & 1) - ((k >> j++) & 1);
                }
                const int in = n[0] >= 0 && n[1] >= 0 && n[2] >= 0 && n[0] < TL_SIDE &&
                               n[1] < TL_SIDE && n[2] < TL_SIDE;
                const int ni = (n[2] * TL_SIDE + n[1]) * TL_SIDE + n[0];
                if (in && ni != ci) G->enbr[e][m++] = (uint8_t)ni;
            }
        }
        for (int f = 0; f < 6; ++f) { /* face f: axis f / 2, side f % 2 */
            const int d = f / 2, side = f % 2, at = c[d] + side;
            int n[3] = {c[0], c[1], c[2]};
            n[d] += side ? 1 : -1;
            if (at == 0 || at == TL_SIDE)
                G->plane_quarter |= (uint8_t)(1u << f);
            else
                G->fnbr[f] = (uint8_t)((n[2] * TL_SIDE + n[1]) * TL_SIDE + n[0]);
        }
    }
    return T;
}

/* lattice node l (x + 3 y + 9 z, 0..2 each) of coarse cell c, as a local
 * node of its block (a whole block: TL_D nodes a side; the offsets are a table,
 * these indices being the decisions' innermost work) */
#define TL_O(l) ((l) / 9 * TL_D * TL_D + (l) / 3 % 3 * TL_D + (l) % 3)
static const uint16_t TL_LATOFF[LB__TNODES] = {
    TL_O(0),  TL_O(1),  TL_O(2),  TL_O(3),  TL_O(4),  TL_O(5),  TL_O(6),  TL_O(7),  TL_O(8),
    TL_O(9),  TL_O(10), TL_O(11), TL_O(12), TL_O(13), TL_O(14), TL_O(15), TL_O(16), TL_O(17),
    TL_O(18), TL_O(19), TL_O(20), TL_O(21), TL_O(22), TL_O(23), TL_O(24), TL_O(25), TL_O(26)};
static inline size_t tl_lat(const int c[3], int l) {
    return ((size_t)(2 * c[2]) * TL_D + (size_t)(2 * c[1])) * TL_D + (size_t)(2 * c[0]) +
           TL_LATOFF[l];
}

/* the root key of the sub-edge from local node q (its lower end) along
 * axis d, len nodes long */
static inline uint16_t tl_key(size_t q, int d, int len) {
    return (uint16_t)((q * 3 + (size_t)d) * 2 + (size_t)(len - 1));
}

/* the position of block B's local node q */
static void tl_node_pos(const lb__grid *g, const lb__block *B, size_t q, double X[3]) {
    const size_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    lb__node_pos(g, (uint64_t)B->b[0] * LB__MB + q % D0, (uint64_t)B->b[1] * LB__MB + q / D0 % D1,
                 (uint64_t)B->b[2] * LB__MB + q / (D0 * D1), X);
}

_Static_assert(TL_CELLS == 64, "a block's fine cells as one 64-bit mask");

/* whether cell ci (0xff: none) is fine in mask fine (bit ci) */
static inline int tl_is_fine(uint64_t fine, uint8_t ci) {
    return ci != 0xff && (fine >> ci) & 1u;
}

/* coarse cell ci's splits: on the block's boundary planes, and where a fine
 * cell (fine: the cells turned fine, a bit each) is around an edge or
 * across a face */
static void tl_pattern(const tlscratch *T, uint64_t fine, int ci, lb__tcell *t) {
    const tlgeom *G = &T->geom[ci];
    t->split = G->plane_split;
    t->quarter = G->plane_quarter;
    for (int e = 0; e < 12; ++e)
        if (tl_is_fine(fine, G->enbr[e][0]) || tl_is_fine(fine, G->enbr[e][1]) ||
            tl_is_fine(fine, G->enbr[e][2]))
            t->split |= (uint16_t)(1u << e);
    for (int f = 0; f < 6; ++f)
        if (tl_is_fine(fine, G->fnbr[f])) t->quarter |= (uint8_t)(1u << f);
}

/* Whether coarse cell ci (at c) has an edge on the block's boundary planes
 * whose two halves both cross (its midpoint on the other side of its ends).
 * Both unquartered faces holding such an edge would draw the segment
 * between the two halves' vertices, on each side of the plane: four
 * triangles on one edge. A cell with such an edge is fine; the block across
 * the plane, seeing the same three shared nodes, makes its cells there fine
 * too. */
static int tl_plane_pinch(const tlscratch *T, const lb__block *B, int ci, const int c[3]) {
    for (int e = 0; e < 12; ++e) {
        if (!((T->geom[ci].plane_split >> e) & 1)) continue;
        const int ip = B->vals[tl_lat(c, T->elat[e][0])] < 0.0,
                  iq = B->vals[tl_lat(c, T->elat[e][1])] < 0.0,
                  im = B->vals[tl_lat(c, T->elat[e][2])] < 0.0;
        if (ip == iq && im != ip) return 1;
    }
    return 0;
}

/* the lattice nodes pattern t reads: corners, split edges' midpoints,
 * quartered faces' centres (n of them into l) */
static int tl_samples(const tlscratch *T, const lb__tcell *t, int *l) {
    static const uint8_t CORNERS[8] = {LB__TCORNER(0), LB__TCORNER(1), LB__TCORNER(2),
                                       LB__TCORNER(3), LB__TCORNER(4), LB__TCORNER(5),
                                       LB__TCORNER(6), LB__TCORNER(7)},
                         CENTRES[6] = {12, 14, 10, 16, 4, 22};
    int n = 0;
    for (int o = 0; o < 8; ++o) l[n++] = CORNERS[o];
    for (int e = 0; e < 12; ++e)
        if ((t->split >> e) & 1) l[n++] = T->elat[e][2];
    for (int f = 0; f < 6; ++f)
        if ((t->quarter >> f) & 1) l[n++] = CENTRES[f];
    return n;
}

/* phi_c and its gradient at n points (T->x, y, z): where the block's plan
 * is narrowed octant by octant (as for its nodes and roots: mesher.c,
 * refine.c), each point under the plan of its octant T->poct[i] */
static lb_status tl_eval(const lb_evaluator *ev, const lb__grid *g, const lb__block *B, bctx *C,
                         size_t n, lb_error *err) {
    if (!n) return LB_OK;
    tlscratch *T = C->tl;
    lb__boxeval *E = &C->S.E;
    lb__boxeval_load(ev, &B->plan, E);
    lb_status s = LB_OK;
    if (lb__plan_prims(ev, &E->plan) < LB__NARROW_MIN_PRIMS) {
        s = lb__boxeval_run(ev, E, n, T->x, T->y, T->z, T->v, T->gx, T->gy, T->gz, err);
    } else {
        if (!B->octmem) lb__plan_load(ev, &E->plan, &C->S.outer);
        size_t start[9] = {0};
        for (size_t i = 0; i < n; ++i) ++start[T->poct[i] + 1];
        for (int o = 0; o < 8; ++o) start[o + 1] += start[o];
        size_t fill[8];
        memcpy(fill, start, sizeof fill);
        for (size_t i = 0; i < n; ++i) T->pord[fill[T->poct[i]]++] = i;
        double *X = T->sx, *Y = X + n, *Z = Y + n, *V = Z + n, *GX = V + n, *GY = GX + n,
               *GZ = GY + n;
        for (size_t r = 0; r < n; ++r) {
            X[r] = T->x[T->pord[r]];
            Y[r] = T->y[T->pord[r]];
            Z[r] = T->z[T->pord[r]];
        }
        for (int o = 0; o < 8 && !s; ++o) {
            const size_t a = start[o], m = start[o + 1] - a;
            if (!m) continue;
            lb__octant_plan(ev, g, B, o, &C->S.outer, E);
            s = lb__boxeval_run(ev, E, m, X + a, Y + a, Z + a, V + a, GX + a, GY + a, GZ + a, err);
        }
        for (size_t r = 0; r < n && !s; ++r) {
            const size_t i = T->pord[r];
            T->v[i] = V[r];
            T->gx[i] = GX[r];
            T->gy[i] = GY[r];
            T->gz[i] = GZ[r];
        }
    }
    if (s) return s;
    const double boxmax = lb__block_boxmax(g, B);
    for (size_t i = 0; i < n; ++i) {
        const double X[3] = {T->x[i], T->y[i], T->z[i]}, gf[3] = {T->gx[i], T->gy[i], T->gz[i]};
        double gp[3];
        T->v[i] = lb__mesh_phi_in(g, boxmax, X, T->v[i], gf, gp);
        T->gx[i] = gp[0];
        T->gy[i] = gp[1];
        T->gz[i] = gp[2];
    }
    return LB_OK;
}

/* the marked nodes among T->q[0..n-1] not yet evaluated, evaluated */
static lb_status tl_nodes(const lb_evaluator *ev, const lb__grid *g, lb__block *B, bctx *C,
                          size_t n, lb_error *err) {
    tlscratch *T = C->tl;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t q = T->q[i];
        if (B->nmask[q] != 2) continue;
        B->nmask[q] = 3; /* queued: once */
        double X[3];
        tl_node_pos(g, B, q, X);
        /* its octant: nodes up to the middle one in the low half (mesher.c) */
        T->poct[m] = (uint8_t)((q % TL_D > LB__MB / 2) | (q / TL_D % TL_D > LB__MB / 2) << 1 |
                               (q / (TL_D * TL_D) > LB__MB / 2) << 2);
        T->x[m] = X[0];
        T->y[m] = X[1];
        T->z[m] = X[2];
        T->q[m++] = q;
    }
    lb_status s = tl_eval(ev, g, B, C, m, err);
    for (size_t i = 0; i < m && !s; ++i) {
        const size_t q = T->q[i];
        B->vals[q] = T->v[i];
        B->grads[3 * q] = T->gx[i];
        B->grads[3 * q + 1] = T->gy[i];
        B->grads[3 * q + 2] = T->gz[i];
        B->nmask[q] = 1;
    }
    return s;
}

/* a sub-edge's nodes: lattice a < b (a the lower end), its axis and length
 * (1: a grid edge, 2: a whole coarse edge) */
static inline void tl_sub(uint16_t s, int *a, int *b, int *d, int *len) {
    *a = s / LB__TNODES;
    *b = s % LB__TNODES;
    const int diff = *b - *a;
    *d = diff < 3 ? 0 : diff < 9 ? 1 : 2;
    *len = diff == 1 || diff == 3 || diff == 9 ? 1 : 2;
}

/* lb__tcell_loops for cell K's pattern, through the thread's cache */
static int tl_loops(tlscratch *T, tlcell *K) {
    const uint64_t key =
        ((uint64_t)K->t.split | (uint64_t)K->t.quarter << 12 | (uint64_t)K->t.inside << 18) + 1;
    const size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 52);
    tlloops *L = &T->lcache[h];
    if (T->lkey[h] != key) {
        int nloop = 0;
        const int total = lb__tcell_loops(&K->t, L->sub, L->len, &nloop);
        T->lkey[h] = key;
        L->total = (int16_t)total;
        L->nloop = (uint8_t)nloop;
    }
    K->nloop = L->nloop;
    if (L->total > 0) {
        memcpy(K->sub, L->sub, (size_t)L->total * sizeof *K->sub);
        memcpy(K->len, L->len, L->nloop);
    }
    return L->total;
}

#define TL_PENDING 0x40000000u
#define TL_PASS 0x80000000u
#define TL_FAIL 0xc0000000u
#define TL_NOSLOT 0xffffffffu

/* The check point X (a triangle edge's midpoint or a triangle's centroid,
 * made of the roots that key names) for cell ci. A point's place depends on
 * its roots only, so it is checked once per block: a new point at
 * T->x[*np]; or the one this round already has there (the other triangle
 * on a diagonal, or the cell across a face drawing the same segment),
 * then checked for both cells; or an earlier round's result (a cell
 * re-decided with a changed pattern keeps most of its triangles). Returns
 * 0 where an earlier round found the point off the surface: ci is fine. */
static int tl_check(tlscratch *T, uint64_t key, const double X[3], int ci, uint8_t oct,
                    size_t *np) {
    uint32_t h = (uint32_t)((key * 0x9E3779B97F4A7C15ull) >> (64 - TL_CHKS_BITS)), slot = TL_NOSLOT;
    for (;; h = (h + 1) & (TL_CHKS - 1)) {
        struct tlchk *M = &T->chk[h];
        if (M->stamp != T->rstamp) {
            if (T->nchk >= TL_CHKS / 2) break; /* full: checked without an entry */
            ++T->nchk;
            M->stamp = T->rstamp;
            M->key = key;
            M->info = TL_PENDING | (uint32_t)*np;
            slot = h;
            break;
        }
        if (M->key != key) continue;
        if (M->info == TL_PASS) return 1;
        if (M->info == TL_FAIL) return 0;
        const uint32_t i = M->info & ~TL_PENDING;
        if (T->pcell[i] != ci) T->pcell2[i] = (uint8_t)ci;
        return 1;
    }
    const size_t i = (*np)++;
    T->x[i] = X[0];
    T->y[i] = X[1];
    T->z[i] = X[2];
    T->poct[i] = oct;
    T->pcell[i] = (uint8_t)ci;
    T->pcell2[i] = 0xff;
    T->pslot[i] = slot;
    return 1;
}

/* The decisions (above). */
static lb_status tl_decide(const lb_evaluator *ev, const lb__grid *g, lb__block *B, bctx *C,
                           lb_error *err) {
    tlscratch *T = C->tl;
    const double hmin = fmin(g->h[0], fmin(g->h[1], g->h[2])), tol = g->coarse;
    for (int ci = 0; ci < TL_CELLS; ++ci) {
        tlcell *K = &T->cell[ci];
        const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
        K->state = TL_OFF;
        K->t.split = 0xffff; /* no pattern yet */
        int marked = 0;
        for (int o = 0; o < 8; ++o)
            marked |=
                B->cmask[((size_t)(2 * c[2] + (o >> 2)) * B->nc[1] + 2 * c[1] + ((o >> 1) & 1)) *
                             B->nc[0] +
                         2 * c[0] + (o & 1)];
        if (!marked) continue;
        K->state = TL_TODO;
        for (int l = 0; l < LB__TNODES; ++l) /* mark() marks its boxes whole: cannot happen */
            if (!B->nmask[tl_lat(c, l)]) K->state = TL_FINE;
    }
    if (++T->rstamp == 0) { /* wrapped: clear the stamps once */
        for (size_t i = 0; i < TL_KEYS; ++i) T->rdone[i] = 0;
        for (size_t i = 0; i < TL_CHKS; ++i) T->chk[i].stamp = 0;
        T->rstamp = 1;
    }
    T->nchk = 0;
    memset(T->dirty, 1, sizeof T->dirty);
    memset(T->seen, 0, sizeof T->seen);
    for (int round = 0; round <= TL_CELLS; ++round) {
        /* the cells to decide, and the samples their patterns read */
        size_t nq = 0;
        int todo = 0;
        uint64_t fine = 0;
        for (int ci = 0; ci < TL_CELLS; ++ci)
            fine |= (uint64_t)(T->cell[ci].state == TL_FINE) << ci;
        for (int ci = 0; ci < TL_CELLS; ++ci) {
            tlcell *K = &T->cell[ci];
            if ((K->state != TL_TODO && K->state != TL_OK) || !T->dirty[ci]) continue;
            T->dirty[ci] = 0;
            const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
            lb__tcell t;
            tl_pattern(T, fine, ci, &t);
            if (K->state == TL_OK && t.split == K->t.split && t.quarter == K->t.quarter) continue;
            K->state = TL_TODO;
            K->t = t;
            ++todo;
            int l[26];
            const int n = tl_samples(T, &t, l);
            for (int i = 0; i < n; ++i) T->q[nq++] = tl_lat(c, l[i]);
        }
        if (!todo) return LB_OK;
        lb_status s = tl_nodes(ev, g, B, C, nq, err);
        if (s) return s;
        /* their loops; a cell whose samples show no crossing needs all its
         * nodes */
        nq = 0;
        for (int ci = 0; ci < TL_CELLS; ++ci) {
            tlcell *K = &T->cell[ci];
            if (K->state != TL_TODO) continue;
            const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
            if (tl_plane_pinch(T, B, ci, c)) {
                K->state = TL_FINE;
                continue;
            }
            int l[26];
            const int n = tl_samples(T, &K->t, l);
            K->t.inside = 0;
            for (int i = 0; i < n; ++i)
                if (B->vals[tl_lat(c, l[i])] < 0.0) K->t.inside |= 1u << l[i];
            if (tl_loops(T, K) < 0) {
                K->state = TL_FINE; /* cannot happen (transition.c) */
                continue;
            }
            if (!K->nloop)
                for (int i = 0; i < LB__TNODES; ++i) T->q[nq++] = tl_lat(c, i);
        }
        s = tl_nodes(ev, g, B, C, nq, err);
        if (s) return s;
        /* quiet cells: fine where any node is on the other side; the loops'
         * vertices into one batch */
        size_t ne = 0;
        for (int ci = 0; ci < TL_CELLS; ++ci) {
            tlcell *K = &T->cell[ci];
            if (K->state != TL_TODO) continue;
            const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
            if (!K->nloop) {
                const int in0 = B->vals[tl_lat(c, 0)] < 0.0;
                K->state = TL_OK;
                K->ntri = 0;
                for (int i = 1; i < LB__TNODES; ++i)
                    if ((B->vals[tl_lat(c, i)] < 0.0) != in0) K->state = TL_FINE;
                continue;
            }
            int total = 0;
            for (int lp = 0; lp < K->nloop; ++lp) total += K->len[lp];
            for (int i = 0; i < total; ++i) {
                int a, b, d, len;
                tl_sub(K->sub[i], &a, &b, &d, &len);
                const size_t qa = tl_lat(c, a), qb = tl_lat(c, b);
                const uint16_t key = tl_key(qa, d, len);
                K->key[i] = key;
                if (T->rdone[key] == T->rstamp) continue; /* solved, or queued */
                T->rdone[key] = T->rstamp;
                T->bkey[ne] = key;
                const int ain = B->vals[qa] < 0.0;
                const size_t qi = ain ? qa : qb, qo = ain ? qb : qa;
                tl_node_pos(g, B, qi, T->ea + 3 * ne);
                tl_node_pos(g, B, qo, T->eb + 3 * ne);
                T->pa[ne] = B->vals[qi];
                T->pb[ne] = B->vals[qo];
                memcpy(T->ga + 3 * ne, B->grads + 3 * qi, 3 * sizeof(double));
                memcpy(T->gb + 3 * ne, B->grads + 3 * qo, 3 * sizeof(double));
                ++ne;
            }
        }
        s = lb__refine_edges(ev, g, B, ne, T->ea, T->eb, T->pa, T->pb, T->ga, T->gb, NULL, T->pos,
                             T->nrm, &C->S, err);
        if (s) return s;
        for (size_t i = 0; i < ne; ++i) {
            memcpy(T->root[T->bkey[i]].pos, T->pos + 3 * i, 3 * sizeof(double));
            memcpy(T->root[T->bkey[i]].nrm, T->nrm + 3 * i, 3 * sizeof(double));
        }
        /* the triangulations and the bow of their edges; then the check
         * points of the cells that pass */
        size_t np = 0;
        for (int ci = 0; ci < TL_CELLS; ++ci) {
            tlcell *K = &T->cell[ci];
            if (K->state != TL_TODO || !K->nloop) continue;
            K->ntri = 0;
            for (int lp = 0, off = 0; lp < K->nloop && K->state == TL_TODO; off += K->len[lp++]) {
                const int n = K->len[lp];
                double P[3 * LB__TMAX], N[3 * LB__TMAX];
                for (int i = 0; i < n; ++i) {
                    memcpy(P + 3 * i, T->root[K->key[off + i]].pos, 3 * sizeof(double));
                    memcpy(N + 3 * i, T->root[K->key[off + i]].nrm, 3 * sizeof(double));
                }
                uint8_t tri[3 * LB__TMAX];
                const int nt = lb__tloop_triangles(K->sub + off, P, n, tri);
                if (!nt) {
                    K->state = TL_FINE;
                    break;
                }
                for (int t = 0; t < nt && K->state == TL_TODO; ++t) {
                    for (int v = 0; v < 3; ++v) {
                        const int a = tri[3 * t + v], b = tri[3 * t + (v + 1) % 3];
                        K->tri[3 * K->ntri + v] = (uint8_t)(off + a);
                        const double *A = P + 3 * a, *Bp = P + 3 * b;
                        const double L =
                            sqrt((A[0] - Bp[0]) * (A[0] - Bp[0]) + (A[1] - Bp[1]) * (A[1] - Bp[1]) +
                                 (A[2] - Bp[2]) * (A[2] - Bp[2]));
                        double cs = N[3 * a] * N[3 * b] + N[3 * a + 1] * N[3 * b + 1] +
                                    N[3 * a + 2] * N[3 * b + 2];
                        cs = cs > 1.0 ? 1.0 : cs < -1.0 ? -1.0 : cs;
                        /* the arc's bow L a / 8 against the tolerance, acos
                         * only where its bounds by the chord angle
                         * c = sqrt(2 (1 - cs)) <= a <= pi c / 2 do not decide */
                        const double lim = tol * hmin, ch = L * sqrt(2.0 * (1.0 - cs)) / 8.0;
                        if (ch > lim || (1.5707963267948966 * ch > lim && L * acos(cs) / 8.0 > lim))
                            K->state = TL_FINE;
                    }
                    ++K->ntri;
                }
            }
            if (K->state != TL_TODO) continue;
            const int half = TL_SIDE / 2;
            const uint8_t oct =
                (uint8_t)((ci % TL_SIDE >= half) | (ci / TL_SIDE % TL_SIDE >= half) << 1 |
                          (ci / (TL_SIDE * TL_SIDE) >= half) << 2);
            for (int t = 0; t < K->ntri && K->state == TL_TODO; ++t) {
                double mid[3] = {0, 0, 0};
                for (int v = 0; v < 3 && K->state == TL_TODO; ++v) {
                    const uint16_t ka = K->key[K->tri[3 * t + v]],
                                   kb = K->key[K->tri[3 * t + (v + 1) % 3]];
                    const double *A = T->root[ka].pos, *Bp = T->root[kb].pos;
                    const double X[3] = {0.5 * (A[0] + Bp[0]), 0.5 * (A[1] + Bp[1]),
                                         0.5 * (A[2] + Bp[2])};
                    if (!tl_check(T, ka < kb ? (uint64_t)ka << 16 | kb : (uint64_t)kb << 16 | ka, X,
                                  ci, oct, &np))
                        K->state = TL_FINE;
                    for (int d = 0; d < 3; ++d) mid[d] += A[d] / 3.0;
                }
                if (K->state != TL_TODO) break;
                const uint64_t key = 1ull << 63 | (uint64_t)K->key[K->tri[3 * t]] << 32 |
                                     (uint64_t)K->key[K->tri[3 * t + 1]] << 16 |
                                     K->key[K->tri[3 * t + 2]];
                if (!tl_check(T, key, mid, ci, oct, &np)) K->state = TL_FINE;
            }
        }
        s = tl_eval(ev, g, B, C, np, err);
        if (s) return s;
        for (size_t i = 0; i < np; ++i) {
            const double gl = sqrt(T->gx[i] * T->gx[i] + T->gy[i] * T->gy[i] + T->gz[i] * T->gz[i]);
            const int pass = fabs(T->v[i]) <= tol * hmin * gl;
            if (T->pslot[i] != TL_NOSLOT) T->chk[T->pslot[i]].info = pass ? TL_PASS : TL_FAIL;
            if (pass) continue;
            if (T->cell[T->pcell[i]].state == TL_TODO) T->cell[T->pcell[i]].state = TL_FINE;
            if (T->pcell2[i] != 0xff && T->cell[T->pcell2[i]].state == TL_TODO)
                T->cell[T->pcell2[i]].state = TL_FINE;
        }
        for (int ci = 0; ci < TL_CELLS; ++ci) {
            if (T->cell[ci].state == TL_TODO) T->cell[ci].state = TL_OK;
            if (T->cell[ci].state != TL_FINE || T->seen[ci]) continue;
            T->seen[ci] = 1;
            const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
            for (int z = c[2] - 1; z <= c[2] + 1; ++z)
                for (int y = c[1] - 1; y <= c[1] + 1; ++y)
                    for (int x = c[0] - 1; x <= c[0] + 1; ++x)
                        if (x >= 0 && y >= 0 && z >= 0 && x < TL_SIDE && y < TL_SIDE && z < TL_SIDE)
                            T->dirty[(z * TL_SIDE + y) * TL_SIDE + x] = 1;
        }
    }
    return LB_OK;
}

/* A whole coarse edge's vertex (from local node l along axis d, two cells
 * long): the block's own, created on first use (as lb__cell_edge_new, with
 * an id from the axis masks cube cells leave unused). */
static int64_t tl_coarse_edge(bctx *C, uint32_t li, uint32_t lj, uint32_t lk, int d) {
    const lb__block *B = C->B;
    const uint32_t D0 = C->h.D0, D1 = C->h.D1;
    const int mask = 1 << d;
    const size_t np = ((size_t)lk * D1 + lj) * D0 + li;
    const size_t nq = np + 2 * (d == 0 ? 1 : d == 1 ? (size_t)D0 : (size_t)D0 * D1);
    lb__emap_entry *em = &C->h.emap[np * 8 + (size_t)(7 ^ mask)];
    if (em->stamp == C->h.stamp) return em->e;
    em->stamp = C->h.stamp;
    const size_t e = own_edge(C, li, lj, lk, mask, 2, B->vals[np], B->vals[nq]);
    C->eloc[e] |= COARSE_EDGE;
    em->e = (uint32_t)e;
    return (int64_t)e;
}

/* A two-level block's cells: the decisions, the fine cells' nodes and
 * cells, the coarse cells' triangles. */
static lb_status tl_cells(const lb_evaluator *ev, const lb__grid *g, lb__block *B, bctx *C,
                          lb_error *err) {
    if (!C->tl && !(C->tl = tl_new()))
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    tlscratch *T = C->tl;
    lb_status s = tl_decide(ev, g, B, C, err);
    if (s) return s;
    size_t nq = 0;
    for (int ci = 0; ci < TL_CELLS; ++ci) {
        if (T->cell[ci].state != TL_FINE) continue;
        const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
        for (int l = 0; l < LB__TNODES; ++l) T->q[nq++] = tl_lat(c, l);
    }
    s = tl_nodes(ev, g, B, C, nq, err);
    if (s) return s;
    for (int ci = 0; ci < TL_CELLS; ++ci) {
        const tlcell *K = &T->cell[ci];
        const int c[3] = {ci % TL_SIDE, ci / TL_SIDE % TL_SIDE, ci / (TL_SIDE * TL_SIDE)};
        if (K->state == TL_FINE) {
            for (int o = 0; o < 8; ++o) {
                const uint32_t i = (uint32_t)(2 * c[0] + (o & 1)),
                               j = (uint32_t)(2 * c[1] + ((o >> 1) & 1)),
                               k = (uint32_t)(2 * c[2] + (o >> 2));
                if (B->cmask[((size_t)k * B->nc[1] + j) * B->nc[0] + i] &&
                    !cut_cell(C, g, B, i, j, k))
                    return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            }
            continue;
        }
        if (K->state != TL_OK || !K->ntri) continue;
        C->cell = (uint32_t)(2 * c[0]) | (uint32_t)(2 * c[1]) << 4 | (uint32_t)(2 * c[2]) << 8;
        int total = 0;
        for (int lp = 0; lp < K->nloop; ++lp) total += K->len[lp];
        uint32_t v[LB__TMAX];
        for (int i = 0; i < total; ++i) {
            int a, b, d, len;
            tl_sub(K->sub[i], &a, &b, &d, &len);
            const uint32_t li = (uint32_t)(2 * c[0] + a % 3), lj = (uint32_t)(2 * c[1] + a / 3 % 3),
                           lk = (uint32_t)(2 * c[2] + a / 9);
            int64_t id;
            if (len == 2) {
                id = tl_coarse_edge(C, li, lj, lk, d);
            } else {
                double cv[8] = {0};
                cv[0] = B->vals[tl_lat(c, a)];
                cv[1 << d] = B->vals[tl_lat(c, b)];
                id = lb__cell_edge(C, li, lj, lk, 0, 1 << d, cv);
            }
            if (id < 0) return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            v[i] = (uint32_t)id;
        }
        for (int t = 0; t < K->ntri; ++t) {
            const uint32_t tv[3] = {v[K->tri[3 * t]], v[K->tri[3 * t + 1]], v[K->tri[3 * t + 2]]};
            if (!lb__cell_polygon(C, tv, LB__ALL_PAIRS, 3))
                return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
        }
    }
    return LB_OK;
}

/* A two-level block's own edges (after orphans_last) whose roots its
 * decisions solved: their positions and normals written into B's, and
 * marked in the returned array for lb__refine_edges to leave. */
static const uint8_t *tl_known(bctx *C, lb__block *B) {
    tlscratch *T = C->tl;
    for (size_t e = 0; e < C->ne; ++e) {
        const uint32_t w = C->eloc[e];
        const size_t q = ((size_t)((w >> 8) & 15) * TL_D + ((w >> 4) & 15)) * TL_D + (w & 15);
        const int mask = (int)((w >> 12) & 7);
        const uint16_t key = tl_key(q, mask == 1 ? 0 : mask == 2 ? 1 : 2, w & COARSE_EDGE ? 2 : 1);
        T->known[e] = T->rdone[key] == T->rstamp;
        if (!T->known[e]) continue;
        const tlroot *R = &T->root[key];
        memcpy(B->vpos + 3 * e, R->pos, 3 * sizeof(double));
        memcpy(B->vnrm + 3 * e, R->nrm, 3 * sizeof(double));
    }
    return T->known;
}

lb_status lb__mesh_block(const lb_evaluator *ev, const lb__grid *g, lb__block *B,
                         const lb__block *blocks, const uint32_t nbr[8], int gnext, lb__bctx *C,
                         lb_error *err) {
    C->g = g;
    C->B = B;
    C->blocks = blocks;
    C->nbr = nbr;
    C->gnext = gnext;
    C->ne = C->nf = C->nref = C->norph = 0;
    if (++C->h.stamp == 0) { /* wrapped: clear the stamps once */
        memset(C->h.emap, 0, EMAP_SIZE * sizeof *C->h.emap);
        C->h.stamp = 1;
    }
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    C->h.D0 = D0;
    C->h.D1 = D1;
    lb_status s = LB_OK;
    const int two_level = lb__two_level_block(g, B);
    if (two_level) {
        s = tl_cells(ev, g, B, C, err);
        if (s) goto done;
    } else {
        for (uint32_t k = 0; k < B->nc[2]; ++k)
            for (uint32_t j = 0; j < B->nc[1]; ++j) {
                const uint8_t *row = B->cmask + ((size_t)k * B->nc[1] + j) * B->nc[0];
                if (B->nc[0] == sizeof(uint64_t)) { /* most rows of most blocks: none marked */
                    uint64_t w;
                    memcpy(&w, row, sizeof w);
                    if (!w) continue;
                }
                for (uint32_t i = 0; i < B->nc[0]; ++i) {
                    if (!row[i]) continue;
                    if (!cut_cell(C, g, B, i, j, k)) {
                        s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
                        goto done;
                    }
                }
            }
    }
    const size_t ne = C->ne, nref = C->nref;
    const int feats = g->features && !g->tetrahedra;
    B->nv = ne;
    B->np = ne - C->norph;
    B->nref = nref;
    B->nfeat = 0;
    if (ne + nref) {
        /* sharp features grow vpos and vnrm (place_features) and make
         * fans, so the triangles are counted after them */
        B->vpos = malloc(3 * (ne + nref) * sizeof *B->vpos);
        B->vnrm = malloc(3 * (ne ? ne : 1) * sizeof *B->vnrm);
        B->rref = malloc(2 * (nref ? nref : 1) * sizeof *B->rref);
        B->okey = C->norph ? malloc(C->norph * sizeof *B->okey) : NULL;
        if (!B->vpos || !B->vnrm || !B->rref || (C->norph && !B->okey)) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            goto done;
        }
        if (C->norph) {
            orphans_last(C);
            memcpy(B->okey, C->key + B->np, C->norph * sizeof *B->okey);
        }
        const uint8_t *known = two_level ? tl_known(C, B) : NULL;
        s = lb__refine_edges(ev, g, B, ne, C->ea, C->eb, C->pa, C->pb, C->ga, C->gb, known, B->vpos,
                             B->vnrm, &C->S, err);
        if (s) goto done;
        publish(C);
        memcpy(B->vpos + 3 * ne, C->rpos, 3 * nref * sizeof(double));
        memcpy(B->rref, C->ref, 2 * nref * sizeof *B->rref);
        /* polygon vertices as local indices: own ones, then references */
        for (size_t f = 0; f < C->nf; ++f) {
            face *F = &C->faces[f];
            for (uint32_t q = 0; q < F->n; ++q) {
                const uint32_t v = F->e[q];
                F->e[q] = v & REF ? (uint32_t)ne + (v & ~REF) : C->norph ? C->perm[v] : v;
            }
        }
        if (feats) {
            s = place_features(ev, g, B, C, err);
            if (s) goto done;
        }
        size_t nt = 0;
        for (size_t f = 0; f < C->nf; ++f)
            nt += C->faces[f].n - (C->faces[f].feat == NOFEAT ? 2 : 0);
        B->tri = malloc(3 * (nt ? nt : 1) * sizeof *B->tri);
        if (!B->tri) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            goto done;
        }
        uint32_t *T = B->tri;
        for (size_t f = 0; f < C->nf; ++f) {
            const face *F = &C->faces[f];
            if (F->feat == NOFEAT) {
                T = triangulate(F, B->vpos, T);
                continue;
            }
            for (uint32_t q = 0; q < F->n; ++q, T += 3) {
                T[0] = F->feat;
                T[1] = F->e[q];
                T[2] = F->e[(q + 1) % F->n];
            }
        }
        B->nt = (size_t)(T - B->tri) / 3;
    }
done:
    return s;
}
