/* Marching tetrahedra on the Kuhn (Freudenthal) triangulation of a block.
 *
 * Every cell is split into the six tetrahedra 0 -> e_a -> e_a + e_b -> 7
 * along its main diagonal (corner bits: 1 = +x, 2 = +y, 4 = +z). Every cell
 * uses the same split, so the two cells sharing a face cut it along the same
 * diagonal, and the triangles on both sides meet edge to edge. A node is
 * inside when phi < 0 and outside otherwise (phi = 0 counts as outside), so
 * each tetrahedron has one of three cases: one vertex apart (one triangle),
 * two and two (a quadrilateral, cut along its shorter diagonal after the
 * vertices are placed), or no crossing. The linear interpolant on a
 * tetrahedron has no ambiguous case: the surface is the zero set of a
 * piecewise-linear function, a closed 2-manifold.
 *
 * Orientation is decided combinatorially, in exact integers: with the
 * vertices at the edge midpoints (doubled lattice coordinates), the
 * triangle's normal must point from the inside corners towards the outside
 * ones. Moving a vertex along its edge never flips a one-apart triangle
 * (its volume with the apart corner scales by the three edge fractions). */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const uint8_t KUHN[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                   {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

typedef struct face {
    uint32_t e[4];
    uint32_t n; /* 3 or 4 */
} face;

typedef struct bctx {
    const lb__grid *g;
    lb__block *B;
    int32_t *emap; /* local edge id -> crossing edge index */
    size_t ne, cap;
    double *ea, *eb, *pa, *pb; /* inside end, outside end, their phi */
    double *ga, *gb;           /* and their gradients */
    uint64_t *key;
    face *faces;
    size_t nf, fcap;
} bctx;

static int grow(void **p, size_t *cap, size_t need, size_t elem) {
    if (need <= *cap) return 1;
    size_t nc = *cap ? 2 * *cap : 64;
    while (nc < need) nc *= 2;
    void *q = realloc(*p, nc * elem);
    if (!q) return 0;
    *p = q;
    *cap = nc;
    return 1;
}

static inline int corner_in(const double *c, int o) {
    return c[o] < 0.0;
}

/* The crossing edge between corners op < oq (op is a subset of oq) of cell
 * (i, j, k): its index, created on first use. Returns -1 on out of memory. */
static int64_t edge_of(bctx *C, uint32_t i, uint32_t j, uint32_t k, int op, int oq,
                       const double *c) {
    const lb__block *B = C->B;
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1;
    const uint32_t li = i + (op & 1), lj = j + ((op >> 1) & 1), lk = k + ((op >> 2) & 1);
    const int mask = op ^ oq;
    const size_t lid = ((size_t)(lk * D1 + lj) * D0 + li) * 8 + (size_t)mask;
    if (C->emap[lid] >= 0) return C->emap[lid];
    size_t cap = C->cap;
    if (C->ne + 1 > cap) {
        size_t nc = cap ? 2 * cap : 256;
        double *ea = realloc(C->ea, 3 * nc * sizeof *ea);
        if (ea) C->ea = ea;
        double *eb = realloc(C->eb, 3 * nc * sizeof *eb);
        if (eb) C->eb = eb;
        double *pa = realloc(C->pa, nc * sizeof *pa);
        if (pa) C->pa = pa;
        double *pb = realloc(C->pb, nc * sizeof *pb);
        if (pb) C->pb = pb;
        uint64_t *key = realloc(C->key, nc * sizeof *key);
        if (key) C->key = key;
        double *ga = realloc(C->ga, 3 * nc * sizeof *ga);
        if (ga) C->ga = ga;
        double *gb = realloc(C->gb, 3 * nc * sizeof *gb);
        if (gb) C->gb = gb;
        if (!ea || !eb || !pa || !pb || !key || !ga || !gb) return -1;
        C->cap = nc;
    }
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
    C->key[e] = lb__node_index(g, gx, gy, gz) * 8u + (uint64_t)mask;
    C->emap[lid] = (int32_t)e;
    return (int64_t)e;
}

/* Doubled lattice midpoint of corners p, q. */
static void mid2(int p, int q, int m[3]) {
    for (int d = 0; d < 3; ++d) m[d] = ((p >> d) & 1) + ((q >> d) & 1);
}

/* Whether the polygon through the midpoints of edges (ep[i], eq[i]) must be
 * reversed so its normal points from the inside corners to the outside
 * ones. */
static int reverse(const int ep[], const int eq[], const uint8_t *tv, const int *in) {
    int m0[3], m1[3], m2[3];
    mid2(ep[0], eq[0], m0);
    mid2(ep[1], eq[1], m1);
    mid2(ep[2], eq[2], m2);
    const int u[3] = {m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]};
    const int v[3] = {m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
    const int n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                      u[0] * v[1] - u[1] * v[0]};
    int nin = 0, sin[3] = {0, 0, 0}, sout[3] = {0, 0, 0};
    for (int t = 0; t < 4; ++t) {
        int *s = in[t] ? sin : sout;
        nin += in[t];
        for (int d = 0; d < 3; ++d) s[d] += (tv[t] >> d) & 1;
    }
    const int nout = 4 - nin;
    long dot = 0;
    for (int d = 0; d < 3; ++d) dot += (long)n[d] * (long)(nin * sout[d] - nout * sin[d]);
    return dot < 0;
}

static int add_face(bctx *C, const uint32_t *e, uint32_t n) {
    if (!grow((void **)&C->faces, &C->fcap, C->nf + 1, sizeof *C->faces)) return 0;
    face *f = &C->faces[C->nf++];
    f->n = n;
    memcpy(f->e, e, n * sizeof *e);
    return 1;
}

static int do_cell(bctx *C, uint32_t i, uint32_t j, uint32_t k, const double *c) {
    for (int t = 0; t < 6; ++t) {
        const uint8_t *tv = KUHN[t];
        int in[4], nin = 0;
        for (int q = 0; q < 4; ++q) nin += in[q] = corner_in(c, tv[q]);
        if (nin == 0 || nin == 4) continue;
        int ep[4], eq[4], ne = 0;
        if (nin == 1 || nin == 3) {
            int apart = 0;
            for (int q = 0; q < 4; ++q)
                if (in[q] == (nin == 1)) apart = q;
            for (int q = 0; q < 4; ++q) {
                if (q == apart) continue;
                const int lo = q < apart ? q : apart, hi = q < apart ? apart : q;
                ep[ne] = tv[lo];
                eq[ne] = tv[hi];
                ++ne;
            }
        } else {
            int a[2], b[2], na = 0, nb = 0;
            for (int q = 0; q < 4; ++q) {
                if (in[q])
                    a[na++] = q;
                else
                    b[nb++] = q;
            }
            /* cycle a0b0 -> a0b1 -> a1b1 -> a1b0 */
            const int pairs[4][2] = {{a[0], b[0]}, {a[0], b[1]}, {a[1], b[1]}, {a[1], b[0]}};
            for (int q = 0; q < 4; ++q) {
                const int x = pairs[q][0], y = pairs[q][1];
                ep[q] = tv[x < y ? x : y];
                eq[q] = tv[x < y ? y : x];
            }
            ne = 4;
        }
        if (reverse(ep, eq, tv, in)) {
            for (int q = 0; q < ne / 2; ++q) {
                int s = ep[q];
                ep[q] = ep[ne - 1 - q];
                ep[ne - 1 - q] = s;
                s = eq[q];
                eq[q] = eq[ne - 1 - q];
                eq[ne - 1 - q] = s;
            }
        }
        uint32_t e[4];
        for (int q = 0; q < ne; ++q) {
            const int64_t id = edge_of(C, i, j, k, ep[q], eq[q], c);
            if (id < 0) return 0;
            e[q] = (uint32_t)id;
        }
        if (!add_face(C, e, (uint32_t)ne)) return 0;
    }
    return 1;
}

static double dist2(const double *p, const double *q) {
    const double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

lb_status lb__mesh_block(const lb_evaluator *ev, const lb__grid *g, lb__block *B, lb_error *err) {
    bctx C;
    memset(&C, 0, sizeof C);
    C.g = g;
    C.B = B;
    const uint32_t D0 = B->nc[0] + 1, D1 = B->nc[1] + 1, D2 = B->nc[2] + 1;
    const size_t nid = (size_t)D0 * D1 * D2 * 8;
    C.emap = malloc(nid * sizeof *C.emap);
    lb_status s = LB_OK;
    if (!C.emap) {
        s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
        goto done;
    }
    memset(C.emap, 0xff, nid * sizeof *C.emap);
    for (uint32_t k = 0; k < B->nc[2]; ++k)
        for (uint32_t j = 0; j < B->nc[1]; ++j)
            for (uint32_t i = 0; i < B->nc[0]; ++i) {
                if (!B->cmask[((size_t)k * B->nc[1] + j) * B->nc[0] + i]) continue;
                double c[8];
                int nin = 0;
                for (int o = 0; o < 8; ++o) {
                    const size_t idx =
                        ((size_t)(k + ((o >> 2) & 1)) * D1 + (j + ((o >> 1) & 1))) * D0 +
                        (i + (o & 1));
                    c[o] = B->vals[idx];
                    nin += c[o] < 0.0;
                }
                if (nin == 0 || nin == 8) continue;
                if (!do_cell(&C, i, j, k, c)) {
                    s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
                    goto done;
                }
            }
    B->nv = C.ne;
    if (C.ne) {
        B->vkey = C.key;
        C.key = NULL;
        B->vpos = malloc(3 * C.ne * sizeof *B->vpos);
        B->vnrm = malloc(3 * C.ne * sizeof *B->vnrm);
        size_t nt = 0;
        for (size_t f = 0; f < C.nf; ++f) nt += C.faces[f].n - 2;
        B->tri = malloc(3 * (nt ? nt : 1) * sizeof *B->tri);
        if (!B->vpos || !B->vnrm || !B->tri) {
            s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
            goto done;
        }
        s = lb__refine_edges(ev, g, B, C.ne, C.ea, C.eb, C.pa, C.pb, C.ga, C.gb, B->vpos, B->vnrm,
                             err);
        if (s) goto done;
        uint32_t *T = B->tri;
        for (size_t f = 0; f < C.nf; ++f) {
            const uint32_t *e = C.faces[f].e;
            if (C.faces[f].n == 3) {
                T[0] = e[0];
                T[1] = e[1];
                T[2] = e[2];
                T += 3;
            } else {
                const double d02 = dist2(B->vpos + 3 * e[0], B->vpos + 3 * e[2]);
                const double d13 = dist2(B->vpos + 3 * e[1], B->vpos + 3 * e[3]);
                const uint32_t q[6] = {e[0], e[1], e[2], e[0], e[2], e[3]};
                const uint32_t r[6] = {e[0], e[1], e[3], e[1], e[2], e[3]};
                memcpy(T, d02 <= d13 ? q : r, sizeof q);
                T += 6;
            }
        }
        B->nt = nt;
    }
done:
    free(C.emap);
    free(C.ea);
    free(C.eb);
    free(C.pa);
    free(C.pb);
    free(C.ga);
    free(C.gb);
    free(C.key);
    free(C.faces);
    return s;
}
