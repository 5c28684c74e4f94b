/* Surface extraction over one block, shared by the two cell methods
 * (cubes.c, the default, and tetra.c): the crossing grid edges (each once,
 * keyed by node and axis mask), their vertices (lb__refine_edges), and the
 * triangulation of each cell polygon once its vertices are placed.
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
    uint8_t ce[LB__MAXPOLY]; /* cube edge of each vertex (cubes.c), 0xff: any diagonal */
    uint32_t n;
} face;

/* One thread's extraction state, reused block after block (lb__bctx_new):
 * the arrays are sized once for the largest block, and the edge map is
 * reset by a stamp instead of a clear. A block has at most EMAP_SIZE
 * crossing edges (one per node and axis mask: every local edge id is
 * distinct) and FACE_MAX polygons (six tetrahedra per cell, or at most
 * four cube loops), so nothing grows in the cell loop. */
#define EMAP_SIZE LB__EMAP_SIZE
#define FACE_MAX ((size_t)6 * LB__MB * LB__MB * LB__MB)

struct lb__bctx {
    const lb__grid *g;
    lb__block *B;
    /* local edge id -> crossing edge index (e), valid where the entry's
     * stamp is the block's: side by side, one cache line per lookup */
    struct emap {
        uint32_t stamp;
        int32_t e;
    } * emap;
    uint32_t stamp;
    size_t ne;                 /* crossing edges so far (< EMAP_SIZE) */
    double *ea, *eb, *pa, *pb; /* inside end, outside end, their phi */
    double *ga, *gb;           /* and their gradients */
    uint64_t *key;
    face *faces;
    size_t nf; /* polygons so far (< FACE_MAX) */
    lb__mscratch S;
};
typedef lb__bctx bctx;

static inline int corner_in(const double *c, int o) {
    return c[o] < 0.0;
}

int64_t lb__cell_edge(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, int op, int oq,
                      const double *c) {
    const lb__block *B = C->B;
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    const uint32_t li = i + (op & 1), lj = j + ((op >> 1) & 1), lk = k + ((op >> 2) & 1);
    const int mask = op ^ oq;
    const size_t lid = ((size_t)(lk * D1 + lj) * D0 + li) * 8 + (size_t)mask;
    if (C->emap[lid].stamp == C->stamp) return C->emap[lid].e;
    const lb__grid *g = C->g;
    const uint64_t gx = (uint64_t)B->b[0] * LB__MB + li, gy = (uint64_t)B->b[1] * LB__MB + lj,
                   gz = (uint64_t)B->b[2] * LB__MB + lk;
    double P[3], Q[3];
    lb__node_pos(g, gx, gy, gz, P);
    lb__node_pos(g, gx + (mask & 1), gy + ((mask >> 1) & 1), gz + ((mask >> 2) & 1), Q);
    const size_t e = C->ne++;
    const int pin = corner_in(c, op);
    memcpy(C->ea + 3 * e, pin ? P : Q, sizeof P);
    memcpy(C->eb + 3 * e, pin ? Q : P, sizeof P);
    C->pa[e] = pin ? c[op] : c[oq];
    C->pb[e] = pin ? c[oq] : c[op];
    const uint32_t D0n = B->nc[0] + 1, D1n = B->nc[1] + 1;
    const size_t np = ((size_t)lk * D1n + lj) * D0n + li;
    const size_t nq = ((size_t)(lk + ((mask >> 2) & 1)) * D1n + (lj + ((mask >> 1) & 1))) * D0n +
                      (li + (mask & 1));
    memcpy(C->ga + 3 * e, B->grads + 3 * (pin ? np : nq), 3 * sizeof(double));
    memcpy(C->gb + 3 * e, B->grads + 3 * (pin ? nq : np), 3 * sizeof(double));
    /* on a block face (some axis the edge does not run along at 0 or nc):
     * other blocks may cut it too, and the merge must find their copies */
    const uint32_t loc[3] = {li, lj, lk};
    int shared = 0;
    for (int d = 0; d < 3; ++d) shared |= !((mask >> d) & 1) && (loc[d] == 0 || loc[d] == B->nc[d]);
    C->key[e] = (lb__node_index(g, gx, gy, gz) * 8u + (uint64_t)mask) | (uint64_t)shared << 63;
    C->emap[lid].e = (int32_t)e;
    C->emap[lid].stamp = C->stamp;
    return (int64_t)e;
}

const lb__grid *lb__cell_grid(const lb__bctx *C) {
    return C->g;
}

int lb__cell_polygon(lb__bctx *C, const uint32_t *e, const uint8_t *ce, uint32_t n) {
    if (C->nf >= FACE_MAX) return 0; /* cannot happen (FACE_MAX above) */
    face *f = &C->faces[C->nf++];
    f->n = n;
    memcpy(f->e, e, n * sizeof *e);
    if (ce)
        memcpy(f->ce, ce, n);
    else
        memset(f->ce, 0xff, n);
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

/* Cut polygon f (vertices placed in pos) into f->n - 2 triangles along the
 * allowed diagonals, choosing the triangulation whose smallest angle is
 * largest (dynamic programming over sub-polygons on the cosine of the
 * smallest angle; ties keep the later split). Every polygon a cell method
 * emits has an allowed triangulation (cubes.c checks its table); a
 * tetrahedron's quadrilateral allows both diagonals. */
static uint32_t *triangulate(const face *f, const double *pos, const lb__grid *g, uint32_t *T) {
    const uint32_t n = f->n;
    if (n == 3) {
        T[0] = f->e[0];
        T[1] = f->e[1];
        T[2] = f->e[2];
        return T + 3;
    }
    double W[LB__MAXPOLY][LB__MAXPOLY], L[LB__MAXPOLY][LB__MAXPOLY];
    uint8_t ok[LB__MAXPOLY][LB__MAXPOLY], K[LB__MAXPOLY][LB__MAXPOLY];
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t b = a + 1; b < n; ++b) {
            const int edge = b == a + 1 || (a == 0 && b == n - 1);
            ok[a][b] = (uint8_t)(edge || f->ce[a] == 0xff ||
                                 !lb__cube_edges_share_face(g, f->ce[a], f->ce[b]));
            /* squared lengths of the sides and diagonals a triangle may use */
            const double *A = pos + 3 * f->e[a], *B = pos + 3 * f->e[b];
            const double d[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
            L[a][b] = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        }
    for (uint32_t len = 2; len < n; ++len)
        for (uint32_t a = 0; a + len < n; ++a) {
            const uint32_t b = a + len;
            double best = INFINITY; /* the largest smallest-angle cosine: lower is better */
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

lb__bctx *lb__bctx_new(const lb_evaluator *ev) {
    lb__bctx *C = calloc(1, sizeof *C);
    if (!C) return NULL;
    C->emap = calloc(EMAP_SIZE, sizeof *C->emap);
    C->ea = malloc(3 * EMAP_SIZE * sizeof *C->ea);
    C->eb = malloc(3 * EMAP_SIZE * sizeof *C->eb);
    C->ga = malloc(3 * EMAP_SIZE * sizeof *C->ga);
    C->gb = malloc(3 * EMAP_SIZE * sizeof *C->gb);
    C->pa = malloc(EMAP_SIZE * sizeof *C->pa);
    C->pb = malloc(EMAP_SIZE * sizeof *C->pb);
    C->key = malloc(EMAP_SIZE * sizeof *C->key);
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
    if (!ok || !C->emap || !C->ea || !C->eb || !C->ga || !C->gb || !C->pa || !C->pb || !C->key ||
        !C->faces || !S->nodes || !S->nidx || !S->edges || !S->eact) {
        lb__bctx_free(C);
        return NULL;
    }
    return C;
}

void lb__bctx_free(lb__bctx *C) {
    if (!C) return;
    free(C->emap);
    free(C->ea);
    free(C->eb);
    free(C->pa);
    free(C->pb);
    free(C->ga);
    free(C->gb);
    free(C->key);
    free(C->faces);
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

lb_status lb__mesh_block(const lb_evaluator *ev, const lb__grid *g, lb__block *B, lb__bctx *C,
                         lb_error *err) {
    C->g = g;
    C->B = B;
    C->ne = C->nf = 0;
    if (++C->stamp == 0) { /* wrapped: clear the stamps once */
        memset(C->emap, 0, EMAP_SIZE * sizeof *C->emap);
        C->stamp = 1;
    }
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    lb_status s = LB_OK;
    for (uint32_t k = 0; k < B->nc[2]; ++k)
        for (uint32_t j = 0; j < B->nc[1]; ++j) {
            const uint8_t *row = B->cmask + ((size_t)k * B->nc[1] + j) * B->nc[0];
            if (B->nc[0] == sizeof(uint64_t)) { /* most rows of most blocks: no marked cell */
                uint64_t w;
                memcpy(&w, row, sizeof w);
                if (!w) continue;
            }
            for (uint32_t i = 0; i < B->nc[0]; ++i) {
                if (!row[i]) continue;
                double c[8];
                int cfg = 0; /* bit o: corner o inside */
                for (int o = 0; o < 8; ++o) {
                    const size_t idx =
                        ((size_t)(k + ((o >> 2) & 1)) * D1 + (j + ((o >> 1) & 1))) * D0 +
                        (i + (o & 1));
                    c[o] = B->vals[idx];
                    cfg |= (c[o] < 0.0) << o;
                }
                if (cfg == 0 || cfg == 255) continue;
                if (!(g->tetrahedra ? lb__tetra_cell : lb__cube_cell)(C, i, j, k, c, cfg)) {
                    s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
                    goto done;
                }
            }
        }
    B->nv = C->ne;
    if (C->ne) {
        B->vkey = malloc(C->ne * sizeof *B->vkey);
        B->vpos = malloc(3 * C->ne * sizeof *B->vpos);
        B->vnrm = malloc(3 * C->ne * sizeof *B->vnrm);
        size_t nt = 0;
        for (size_t f = 0; f < C->nf; ++f) nt += C->faces[f].n - 2;
        B->tri = malloc(3 * (nt ? nt : 1) * sizeof *B->tri);
        if (!B->vkey || !B->vpos || !B->vnrm || !B->tri) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            goto done;
        }
        memcpy(B->vkey, C->key, C->ne * sizeof *B->vkey);
        s = lb__refine_edges(ev, g, B, C->ne, C->ea, C->eb, C->pa, C->pb, C->ga, C->gb, B->vpos,
                             B->vnrm, &C->S, err);
        if (s) goto done;
        uint32_t *T = B->tri;
        for (size_t f = 0; f < C->nf; ++f) T = triangulate(&C->faces[f], B->vpos, g, T);
        B->nt = nt;
    }
done:
    return s;
}
