/* Flat regions merged (mesh.h: LB_MESH_MERGE_FLAT; also the first step of
 * the adaptive simplification, simplify.c).
 *
 * A flat face of the solid (a slab's side, a box's, a cylinder's cap: with
 * LB_MESH_FEATURES its creases are mesh edges) is cut by the grid into as
 * many triangles as a curved part. Where the surface is a plane no vertex
 * inside the face carries any shape, so the face's triangles can be
 * replaced by a triangulation of its outline without moving the surface at
 * all:
 *
 * 1. Regions. Triangles are joined across their edges into regions whose
 *    vertices all lie within FLAT_TOL cells of one plane (through a grid-edge
 *    vertex of the region's first triangle, normal to the field's gradient
 *    there), whose grid-edge vertices' normals (the field's own gradients)
 *    are that plane's normal to within NORMAL_COS, and whose triangles face
 *    the same way. Feature points (a crease's or a corner's, whose normal is
 *    a mean over the crease) take part by their position only.
 * 2. Disks. Only a region that is a disk is merged: one outline loop that
 *    passes each of its vertices once, and Euler's V - E + F = 1.
 * 3. Outlines. A vertex inside a region goes. A vertex on an outline goes
 *    too when every triangle around it lies in two merged regions and it is
 *    on the straight segment between its two outline neighbours (within
 *    FLAT_TOL cells): the edge between two flat faces is one straight
 *    crease, dropped from both sides at once, so the two outlines keep the
 *    same vertices and the mesh stays closed. Any other outline vertex (a
 *    corner, or a vertex shared with a curved part) stays.
 * 4. Triangulation. Each outline is cut into triangles by ear clipping in the
 *    region's plane (an ear: a convex vertex whose triangle holds no other
 *    outline vertex, not even on its edges), at most MAX_LOOP vertices. A
 *    region that cannot be cut (an outline folded within rounding) is left
 *    as it was, and the outline vertices it shares are kept on both sides:
 *    the decisions are made again until every region either merges or
 *    stays (MAX_ROUNDS rounds at most; then nothing is merged).
 * 5. Check. Every directed edge of the result must have exactly one
 *    opposite: a closed 2-manifold still. Where it would not be (an outline
 *    diagonal that is also an edge elsewhere), the pass leaves the mesh as
 *    it was.
 *
 * The new triangles cover exactly the polygons the old ones covered, in the
 * same planes: every point of the surface stays where it was, every kept
 * vertex is a vertex of the input (on the surface, its normal the field's),
 * and no triangle crosses another. One thread, in triangle order: the same
 * bytes for every thread count. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NONE UINT32_MAX
#define FLAT_TOL 1e-6           /* cells: a vertex this close to the plane is on it */
#define NORMAL_COS (1.0 - 1e-9) /* grid-edge normals this close to the plane's */
#define MAX_LOOP 4096           /* outline vertices of a region at most (ear clipping) */
#define MAX_ROUNDS 8            /* rounds of decisions after failed outlines, at most */

typedef struct {
    const lb_mesh *M;
    const uint8_t *feat;
    double tol;            /* FLAT_TOL in scene units */
    uint32_t *vstart, *vt; /* vertex -> its triangles (CSR) */
    uint32_t *adj;         /* 3 t + k -> the triangle across t's edge k (NONE: none) */
    uint32_t *rid;         /* triangle -> region (NONE: in none) */
    double *rplane;        /* region -> unit normal, offset */
    uint8_t *rstate;       /* region: 0 not a disk, 1 merged, 2 left as it was */
    uint32_t nr;
} flat;

static inline const double *pos(const lb_mesh *M, uint32_t v) {
    return M->positions + 3 * (size_t)v;
}

/* the triangle of t across its edge a -> b (the one holding b -> a), or NONE;
 * and that edge's place in it (*ko) */
static uint32_t find_across(const flat *F, uint32_t t, uint32_t a, uint32_t b, int *ko) {
    const uint32_t *T = F->M->triangles;
    uint32_t found = NONE;
    for (uint32_t i = F->vstart[b]; i < F->vstart[b + 1]; ++i) {
        const uint32_t u = F->vt[i];
        if (u == t) continue;
        for (int k = 0; k < 3; ++k)
            if (T[3 * (size_t)u + k] == b && T[3 * (size_t)u + (k + 1) % 3] == a) {
                if (found != NONE) return NONE; /* not a 2-manifold edge */
                found = u;
                *ko = k;
            }
    }
    return found;
}

/* the triangle across t's edge a -> b (a = t's corner k) */
static inline uint32_t across_k(const flat *F, uint32_t t, int k) {
    return F->adj[3 * (size_t)t + k];
}

/* whether triangle t lies on the plane P (normal, offset) facing its way */
static int on_plane(const flat *F, uint32_t t, const double *P) {
    const lb_mesh *M = F->M;
    const uint32_t *T = M->triangles + 3 * (size_t)t;
    const double *a = pos(M, T[0]), *b = pos(M, T[1]), *c = pos(M, T[2]);
    for (int k = 0; k < 3; ++k) {
        const double *p = pos(M, T[k]);
        if (!(fabs(P[0] * p[0] + P[1] * p[1] + P[2] * p[2] + P[3]) <= F->tol)) return 0;
        if (F->feat && F->feat[T[k]]) continue;
        const double *n = M->normals + 3 * (size_t)T[k];
        if (!(n[0] * P[0] + n[1] * P[1] + n[2] * P[2] >= NORMAL_COS)) return 0;
    }
    double n[3];
    lb__facing(a, b, c, n);
    return n[0] * P[0] + n[1] * P[1] + n[2] * P[2] > 0.0;
}

static int seed_plane(const flat *F, size_t t, double P[4]);

/* Regions (step 1), grown from each triangle in order that has a grid-edge
 * vertex; queue: scratch of nt entries. */
static int regions(flat *F, uint32_t *queue) {
    const lb_mesh *M = F->M;
    const size_t nt = M->ntriangles;
    size_t cap = 0;
    for (size_t t = 0; t < nt; ++t) F->rid[t] = NONE;
    F->nr = 0;
    for (size_t s = 0; s < nt; ++s) {
        if (F->rid[s] != NONE) continue;
        double P[4];
        if (!seed_plane(F, s, P) || !on_plane(F, (uint32_t)s, P)) continue;
        if (F->nr == cap) {
            cap = cap ? 2 * cap : 64;
            double *rp = realloc(F->rplane, 4 * cap * sizeof *rp);
            if (rp) F->rplane = rp;
            uint8_t *rs = realloc(F->rstate, cap);
            if (rs) F->rstate = rs;
            if (!rp || !rs) return 0;
        }
        const uint32_t r = F->nr++;
        memcpy(F->rplane + 4 * r, P, sizeof P);
        F->rstate[r] = 0;
        size_t qa = 0, qb = 0;
        queue[qb++] = (uint32_t)s;
        F->rid[s] = r;
        while (qa < qb) {
            const uint32_t t = queue[qa++];
            for (int e = 0; e < 3; ++e) {
                const uint32_t o = across_k(F, t, e);
                if (o == NONE || F->rid[o] != NONE || !on_plane(F, o, P)) continue;
                F->rid[o] = r;
                queue[qb++] = o;
            }
        }
    }
    return 1;
}

/* 2D orientation of (a, b, c): twice the signed area */
static inline double orient(const double *a, const double *b, const double *c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Ear clipping of the outline L (n vertices, counter-clockwise in xy, 2 per
 * vertex) into out (3 per triangle, indices into L's vertices, n - 2 of
 * them); eps: the smallest twice-area of a convex corner. idx, prev, next:
 * scratch of n. 0 when no ear is left before the end. */
static int clip(const double *xy, uint32_t n, double eps, uint32_t *prev, uint32_t *next,
                uint32_t *out) {
    for (uint32_t i = 0; i < n; ++i) {
        prev[i] = i ? i - 1 : n - 1;
        next[i] = i + 1 < n ? i + 1 : 0;
    }
    uint32_t left = n, i = 0, m = 0, miss = 0;
    while (left > 3) {
        const uint32_t p = prev[i], q = next[i];
        const double *A = xy + 2 * p, *B = xy + 2 * i, *C = xy + 2 * q;
        int ear = orient(A, B, C) > eps;
        for (uint32_t r = next[q]; ear && r != p; r = next[r]) {
            const double *R = xy + 2 * r;
            /* inside or on the edges: a vertex there would be a T-junction */
            if (orient(A, B, R) >= -eps && orient(B, C, R) >= -eps && orient(C, A, R) >= -eps)
                ear = 0;
        }
        if (!ear) {
            if (++miss > left) return 0;
            i = q;
            continue;
        }
        out[3 * m] = p;
        out[3 * m + 1] = i;
        out[3 * m + 2] = q;
        ++m;
        next[p] = q;
        prev[q] = p;
        --left;
        miss = 0;
        i = q;
    }
    const uint32_t p = prev[i], q = next[i];
    if (!(orient(xy + 2 * p, xy + 2 * i, xy + 2 * q) > eps)) return 0;
    out[3 * m] = p;
    out[3 * m + 1] = i;
    out[3 * m + 2] = q;
    return 1;
}

/* the seed plane of triangle t: through its first grid-edge vertex, normal
 * to the field's gradient there; 0 when it has none */
static int seed_plane(const flat *F, size_t t, double P[4]) {
    const lb_mesh *M = F->M;
    const uint32_t *T = M->triangles + 3 * t;
    int k = 0;
    while (k < 3 && F->feat && F->feat[T[k]]) ++k;
    if (k == 3) return 0;
    memcpy(P, M->normals + 3 * (size_t)T[k], 3 * sizeof *P);
    const double *p = pos(M, T[k]);
    P[3] = -(P[0] * p[0] + P[1] * p[1] + P[2] * p[2]);
    return 1;
}

/* the vertices after v on the outlines of the two regions around it: a on
 * r0's (the region of v's first triangle), b on the other's; 0 when v is
 * not on exactly such an outline (an edge without an opposite, or more
 * regions) */
static int outline_pair(const flat *F, uint32_t v, uint32_t *a, uint32_t *b) {
    const uint32_t *T = F->M->triangles;
    const uint32_t r0 = F->rid[F->vt[F->vstart[v]]];
    *a = *b = NONE;
    for (uint32_t i = F->vstart[v]; i < F->vstart[v + 1]; ++i) {
        const uint32_t t = F->vt[i];
        for (int k = 0; k < 3; ++k) {
            if (T[3 * (size_t)t + k] != v) continue;
            const uint32_t w = T[3 * (size_t)t + (k + 1) % 3];
            const uint32_t o = across_k(F, t, k);
            if (o == NONE) return 0;
            if (F->rid[o] == F->rid[t]) continue;
            uint32_t *slot = F->rid[t] == r0 ? a : b;
            if (*slot != NONE) return 0;
            *slot = w;
        }
    }
    return 1;
}

lb_status lb__merge_flat(const lb__grid *g, lb_mesh *M, uint8_t *feat, lb_error *err) {
    const size_t nv = M->nvertices, nt = M->ntriangles;
    if (nt < 2 || nv >= NONE || 3 * nt >= NONE) return LB_OK;
    flat F;
    memset(&F, 0, sizeof F);
    F.M = M;
    F.feat = feat;
    const double h = fmin(g->h[0], fmin(g->h[1], g->h[2]));
    F.tol = FLAT_TOL * h;
    /* a curved mesh has no flat triangle of grid-edge vertices and a tenth
     * of a cell's area or more (tinier ones pass on_plane on S1 and S2, their
     * normals and vertices too close to differ): then nothing to set up */
    size_t nflat = 0;
    for (size_t t = 0; t < nt && nflat < 3; ++t) {
        const uint32_t *U = M->triangles + 3 * t;
        if (feat && (feat[U[0]] | feat[U[1]] | feat[U[2]])) continue;
        const double *n0 = M->normals + 3 * (size_t)U[0], *n1 = M->normals + 3 * (size_t)U[1],
                     *n2 = M->normals + 3 * (size_t)U[2];
        if (!(n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] >= NORMAL_COS) ||
            !(n0[0] * n2[0] + n0[1] * n2[1] + n0[2] * n2[2] >= NORMAL_COS))
            continue; /* the quick test first: most triangles bend */
        double n[3];
        lb__facing(pos(M, U[0]), pos(M, U[1]), pos(M, U[2]), n);
        if (!(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] >= 0.04 * h * h * h * h)) continue;
        double P[4];
        nflat += seed_plane(&F, t, P) && on_plane(&F, (uint32_t)t, P);
    }
    if (nflat < 3) return LB_OK;
    lb_status s = LB_OK;
    const uint32_t *T = M->triangles;
    F.vstart = calloc(nv + 1, sizeof *F.vstart);
    F.vt = malloc(3 * nt * sizeof *F.vt);
    F.adj = malloc(3 * nt * sizeof *F.adj);
    F.rid = malloc(nt * sizeof *F.rid);
    uint32_t *queue = malloc((nt + 1) * sizeof *queue); /* BFS, then regions' triangles */
    uint32_t *rlist = malloc(nt * sizeof *rlist);
    uint32_t *vnext = malloc(nv * sizeof *vnext);   /* outline successor */
    uint32_t *vmark = malloc(nv * sizeof *vmark);   /* outline stamp, then new index */
    uint32_t *vseen = malloc(nv * sizeof *vseen);   /* vertex-count stamp */
    uint8_t *vgo = malloc(nv);                      /* 1: the vertex goes */
    uint32_t *tris = malloc(3 * nt * sizeof *tris); /* the output */
    uint32_t *rstart = NULL, *lp = NULL, *lprev = NULL, *lnext = NULL, *lout = NULL;
    double *lxy = NULL;
    size_t m = 0;
    if (!F.vstart || !F.vt || !F.adj || !F.rid || !queue || !rlist || !vnext || !vmark || !vseen ||
        !vgo || !tris)
        goto nomem;
    for (size_t t = 0; t < 3 * nt; ++t) ++F.vstart[T[t] + 1];
    for (size_t v = 0; v < nv; ++v) F.vstart[v + 1] += F.vstart[v];
    memcpy(vnext, F.vstart, nv * sizeof *vnext); /* the next slot per vertex */
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) F.vt[vnext[T[3 * t + k]]++] = (uint32_t)t;
    /* each edge's opposite, found once for both */
    for (size_t i = 0; i < 3 * nt; ++i) F.adj[i] = NONE - 1; /* not looked for yet */
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            if (F.adj[3 * t + k] != NONE - 1) continue;
            int ko = 0;
            const uint32_t o =
                find_across(&F, (uint32_t)t, T[3 * t + k], T[3 * t + (k + 1) % 3], &ko);
            F.adj[3 * t + k] = o;
            if (o != NONE) F.adj[3 * (size_t)o + ko] = (uint32_t)t;
        }
    if (!regions(&F, queue)) goto nomem;
    if (!F.nr) goto done;
    /* each region's triangles, in order (rstart: CSR) */
    if (!(rstart = calloc((size_t)F.nr + 1, sizeof *rstart))) goto nomem;
    for (size_t t = 0; t < nt; ++t)
        if (F.rid[t] != NONE) ++rstart[F.rid[t] + 1];
    for (uint32_t r = 0; r < F.nr; ++r) rstart[r + 1] += rstart[r];
    memcpy(queue, rstart, ((size_t)F.nr + 1) * sizeof *queue);
    for (size_t t = 0; t < nt; ++t)
        if (F.rid[t] != NONE) rlist[queue[F.rid[t]]++] = (uint32_t)t;
    /* disks (step 2): one outline through each vertex once, V - E + F = 1 */
    for (size_t v = 0; v < nv; ++v) vmark[v] = vseen[v] = NONE;
    for (uint32_t r = 0; r < F.nr; ++r) {
        const uint32_t nf = rstart[r + 1] - rstart[r];
        if (nf < 3) continue; /* nothing to gain */
        size_t nb = 0, nvr = 0;
        int ok = 1;
        uint32_t start = NONE;
        for (uint32_t i = rstart[r]; ok && i < rstart[r + 1]; ++i) {
            const uint32_t t = rlist[i];
            for (int k = 0; k < 3; ++k) {
                const uint32_t a = T[3 * (size_t)t + k], b = T[3 * (size_t)t + (k + 1) % 3];
                if (vseen[a] != r) {
                    vseen[a] = r;
                    ++nvr;
                }
                const uint32_t o = across_k(&F, t, k);
                if (o != NONE && F.rid[o] == r) continue;
                if (vmark[a] == r) ok = 0; /* a second outline edge from a */
                vmark[a] = r;
                vnext[a] = b;
                if (start == NONE) start = a;
                ++nb;
            }
        }
        if (!ok || start == NONE || nb > MAX_LOOP) continue;
        size_t walk = 0;
        uint32_t v = start;
        do {
            ++walk;
            v = vmark[v] == r ? vnext[v] : start;
        } while (v != start && walk <= nb);
        const long euler = (long)nvr - (long)((3 * (size_t)nf + nb) / 2) + (long)nf;
        if (walk == nb && euler == 1) F.rstate[r] = 1;
    }
    lp = malloc(MAX_LOOP * sizeof *lp);
    lprev = malloc(MAX_LOOP * sizeof *lprev);
    lnext = malloc(MAX_LOOP * sizeof *lnext);
    lout = malloc(3 * MAX_LOOP * sizeof *lout);
    lxy = malloc(2 * MAX_LOOP * sizeof *lxy);
    if (!lp || !lprev || !lnext || !lout || !lxy) goto nomem;
    /* steps 3 and 4, until no merged region fails */
    for (int pass = 0;; ++pass) {
        for (size_t v = 0; v < nv; ++v) {
            uint32_t r0 = NONE, r1 = NONE;
            int go = F.vstart[v] < F.vstart[v + 1];
            for (uint32_t i = F.vstart[v]; go && i < F.vstart[v + 1]; ++i) {
                const uint32_t r = F.rid[F.vt[i]];
                if (r == NONE || F.rstate[r] != 1)
                    go = 0;
                else if (r0 == NONE || r0 == r)
                    r0 = r;
                else if (r1 == NONE || r1 == r)
                    r1 = r;
                else
                    go = 0;
            }
            uint32_t a, b;
            if (go && !outline_pair(&F, (uint32_t)v, &a, &b)) go = 0;
            if (go && r1 == NONE && a != NONE) go = 0; /* an open outline */
            if (go && r1 != NONE) {
                if (a == NONE || b == NONE) {
                    go = 0;
                } else { /* v on the segment a - b */
                    const double *pa = pos(M, a), *pb = pos(M, b), *pv = pos(M, (uint32_t)v);
                    const double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]},
                                 e[3] = {pv[0] - pa[0], pv[1] - pa[1], pv[2] - pa[2]};
                    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    const double tp = (d[0] * e[0] + d[1] * e[1] + d[2] * e[2]) / dd;
                    double off = 0.0;
                    for (int k = 0; k < 3; ++k) off += (e[k] - tp * d[k]) * (e[k] - tp * d[k]);
                    if (!(dd > 0.0) || !(tp > 0.0 && tp < 1.0) || !(off <= F.tol * F.tol)) go = 0;
                }
            }
            vgo[v] = (uint8_t)go;
        }
        /* each merged region's outline without the vertices that go, cut
         * into triangles, in place of its triangles at its first one's */
        int failed = 0;
        m = 0;
        for (size_t t = 0; t < nt; ++t) {
            const uint32_t r = F.rid[t];
            if (r == NONE || F.rstate[r] != 1) {
                memcpy(tris + 3 * m++, T + 3 * t, 3 * sizeof *T);
                continue;
            }
            if (rlist[rstart[r]] != t) continue;
            uint32_t start = NONE;
            for (uint32_t i = rstart[r]; i < rstart[r + 1]; ++i) {
                const uint32_t u = rlist[i];
                for (int k = 0; k < 3; ++k) {
                    const uint32_t a = T[3 * (size_t)u + k], b = T[3 * (size_t)u + (k + 1) % 3];
                    const uint32_t o = across_k(&F, u, k);
                    if (o != NONE && F.rid[o] == r) continue;
                    vnext[a] = b; /* again: regions share outline vertices */
                    if (start == NONE) start = a;
                }
            }
            uint32_t n = 0, v = start;
            do {
                if (!vgo[v]) lp[n++] = v;
                v = vnext[v];
            } while (v != start && n < MAX_LOOP);
            const double *P = F.rplane + 4 * r;
            int drop = 0;
            if (fabs(P[1]) > fabs(P[drop])) drop = 1;
            if (fabs(P[2]) > fabs(P[drop])) drop = 2;
            const int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
            const double sgn = P[drop] > 0.0 ? 1.0 : -1.0;
            for (uint32_t i = 0; i < n; ++i) {
                const double *p = pos(M, lp[i]);
                lxy[2 * i] = p[ax];
                lxy[2 * i + 1] = sgn * p[ay];
            }
            if (v != start || n < 3 || !clip(lxy, n, 1e-12 * h * h, lprev, lnext, lout)) {
                F.rstate[r] = 2; /* left as it was; the decisions again */
                failed = 1;
                continue;
            }
            for (uint32_t i = 0; i < 3 * (n - 2); ++i) tris[3 * m + i] = lp[lout[i]];
            m += n - 2;
        }
        if (!failed) break;
        /* every region that failed this round is out; one that kept an
         * outline vertex for such a neighbour can fail in the next. A few
         * rounds at most, so no mesh costs more than a few passes: then the
         * mesh stays as it was */
        if (pass == MAX_ROUNDS - 1) goto done;
    }
    if (m == nt) goto done; /* nothing merged */
    /* step 5: every directed edge once, with one opposite (the output's
     * edges by their first vertex, in vstart / vt) */
    memset(F.vstart, 0, (nv + 1) * sizeof *F.vstart);
    for (size_t i = 0; i < 3 * m; ++i) ++F.vstart[tris[i] + 1];
    for (size_t v = 0; v < nv; ++v) F.vstart[v + 1] += F.vstart[v];
    memcpy(vnext, F.vstart, nv * sizeof *vnext);
    for (size_t t = 0; t < m; ++t)
        for (int k = 0; k < 3; ++k) F.vt[vnext[tris[3 * t + k]]++] = tris[3 * t + (k + 1) % 3];
    for (size_t a = 0; a < nv; ++a)
        for (uint32_t i = F.vstart[a]; i < F.vstart[a + 1]; ++i) {
            const uint32_t b = F.vt[i];
            int same = 0, back = 0;
            for (uint32_t j = F.vstart[a]; j < F.vstart[a + 1]; ++j) same += F.vt[j] == b;
            for (uint32_t j = F.vstart[b]; j < F.vstart[b + 1]; ++j) back += F.vt[j] == a;
            if (same != 1 || back != 1) goto done; /* left as it was */
        }
    /* the kept vertices in their order (vmark: the new index) */
    for (size_t v = 0; v < nv; ++v) vmark[v] = F.vstart[v] == F.vstart[v + 1] ? NONE : 0;
    lb__keep_vertices(M, feat, vmark);
    for (size_t i = 0; i < 3 * m; ++i) M->triangles[i] = vmark[tris[i]];
    M->ntriangles = m;
    goto done;
nomem:
    s = lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
done:
    free(F.vstart);
    free(F.vt);
    free(F.adj);
    free(F.rid);
    free(F.rplane);
    free(F.rstate);
    free(queue);
    free(rlist);
    free(vnext);
    free(vmark);
    free(vseen);
    free(vgo);
    free(tris);
    free(rstart);
    free(lp);
    free(lprev);
    free(lnext);
    free(lout);
    free(lxy);
    return s;
}
