/* Corner normals at sharp features (mesh.h: lb_mesh.corner_normals).
 *
 * A feature point (features.c) sits on a crease or a corner, where the
 * surface has no single normal: its vertex normal is only the mean of its
 * cell's. For shading, each triangle corner at such a point gets the normal
 * of the side of the crease its triangle lies on.
 *
 * 1. Sides. A corner's side is told by its triangle's other vertices that
 *    lie on grid edges: their normals are the field's exact gradients, taken
 *    where the triangle meets the surface. Their mean is the corner's
 *    candidate when it agrees with the triangle's own facing (within the
 *    feature threshold, LB__FEATURE_COS: 26 degrees); a corner without one
 *    (its triangle's vertices all feature points, or a vertex near the
 *    crease that took the other side's gradient) takes the unit gradient at
 *    a probe a quarter of a cell from the point towards its triangle's
 *    centroid instead.
 * 2. Groups. A point's corners are grouped in triangle order: a corner
 *    joins the first group whose mean candidate is within the threshold,
 *    else starts one. One group: no crease the shading needs, the corners
 *    keep the vertex normal.
 * 3. Normals. With two groups or more, each group's normal is the unit
 *    gradient of phi_c (so the region's cap counts as a side) at one probe
 *    a quarter of a cell from the point towards the mean of the group's
 *    triangle centroids: the side's normal next to the crease, not a cell
 *    away where the grid-edge vertices are (a probe whose gradient
 *    disagrees with the group's candidates, having crossed the crease,
 *    leaves the candidates' mean). Groups whose normals now agree within
 *    the threshold are one side: a smooth surface that turns by more than
 *    26 degrees between grid-edge vertices a cell apart, but not between
 *    two probes half a cell apart, has no crease. With two sides or more
 *    the sides' normals are appended after the vertex normals; with one the
 *    point keeps its vertex normal.
 *
 * Why a quarter of a cell: near enough that a smooth but tightly curved
 * surface (a fillet a cell or two wide) turns by less than the threshold
 * across a point, far enough that a point a few hundredths of a cell off a
 * curved crease still has its probes on the right sides. One probe per side,
 * not per corner: the evaluations are the cost here (S2's fillets have
 * creases at one polygon in ten). Deterministic: every step runs in triangle
 * order on the merged mesh, and probes are evaluated point by point. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PROBE 0.25 /* cells from the point towards the centroid */
#define MAXG 8     /* groups per point (a corner of a box has 3) */

static lb_status nomem(lb_error *err) {
    return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
}

static double norm3(const double *a) {
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* The centroid of triangle t minus P, and the triangle's (unnormalised)
 * facing. */
static void centroid_from(const lb_mesh *M, size_t t, const double *P, double C[3], double fn[3]) {
    const double *a = M->positions + 3 * (size_t)M->triangles[3 * t];
    const double *b = M->positions + 3 * (size_t)M->triangles[3 * t + 1];
    const double *c = M->positions + 3 * (size_t)M->triangles[3 * t + 2];
    for (int d = 0; d < 3; ++d) C[d] = (a[d] + b[d] + c[d]) / 3.0 - P[d];
    lb__facing(a, b, c, fn);
}

/* A probe PROBE cells (hmin) from P along D (or at P + D when nearer). */
static void probe_at(const double *P, const double *D, double hmin, double *x, double *y,
                     double *z) {
    const double len = norm3(D);
    const double s = len > PROBE * hmin ? PROBE * hmin / len : 1.0;
    *x = P[0] + s * D[0];
    *y = P[1] + s * D[1];
    *z = P[2] + s * D[2];
}

/* The unit normal of phi_c from the field's value and gradient at a probe;
 * 0 when the gradient vanishes or is not finite. */
static int probe_normal(const lb__grid *g, double x, double y, double z, double f, double gx,
                        double gy, double gz, double n[3]) {
    const double X[3] = {x, y, z}, gf[3] = {gx, gy, gz};
    lb__mesh_phi(g, X, f, gf, n);
    const double l = norm3(n);
    if (!(l > 0.0) || !isfinite(l)) return 0;
    for (int d = 0; d < 3; ++d) n[d] /= l;
    return 1;
}

typedef struct group {
    uint32_t v;    /* its point */
    double sum[3]; /* of its corners' candidates */
    double dir[3]; /* of its triangles' centroids minus the point */
} group;

typedef struct work {
    uint32_t *start, *corner; /* the corners at each point (counting sort) */
    double *cand;             /* per listed corner: its candidate (0 0 0: none) */
    uint32_t *gid;            /* per listed corner: its group, UINT32_MAX: the vertex normal */
    group *G;
    size_t ng, gcap;
    double *w; /* probe coordinates and results, 7 per probe */
    size_t wcap;
} work;

static void work_free(work *W) {
    free(W->start);
    free(W->corner);
    free(W->cand);
    free(W->gid);
    free(W->G);
    free(W->w);
}

static int probes_room(work *W, size_t n) {
    if (n <= W->wcap) return 1;
    free(W->w);
    W->w = malloc(7 * n * sizeof *W->w);
    W->wcap = W->w ? n : 0;
    return W->w != NULL;
}

/* Step 1: each listed corner's candidate, probing the corners that have
 * none from their grid-edge neighbours. */
static lb_status candidates(const lb_evaluator *ev, const lb__grid *g, const lb_mesh *M,
                            const uint8_t *feat, work *W, double hmin, int threads, lb_error *err) {
    const size_t n = W->start[M->nvertices];
    size_t np = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t t = W->corner[i] / 3;
        double *c = W->cand + 3 * i, C[3], fn[3];
        c[0] = c[1] = c[2] = 0.0;
        for (int k = 0; k < 3; ++k) {
            const uint32_t u = M->triangles[3 * t + k];
            if (!feat[u])
                for (int d = 0; d < 3; ++d) c[d] += M->normals[3 * (size_t)u + d];
        }
        const double l = norm3(c);
        centroid_from(M, t, M->positions + 3 * (size_t)M->triangles[W->corner[i]], C, fn);
        const double fl = norm3(fn);
        if (l > 0.0 && (!(fl > 0.0) ||
                        c[0] * fn[0] + c[1] * fn[1] + c[2] * fn[2] >= LB__FEATURE_COS * l * fl)) {
            for (int d = 0; d < 3; ++d) c[d] /= l;
        } else {
            c[0] = c[1] = c[2] = 0.0;
            ++np;
        }
    }
    if (!np) return LB_OK;
    if (!probes_room(W, np)) return nomem(err);
    double *x = W->w, *y = x + np, *z = y + np, *f = z + np, *gx = f + np, *gy = gx + np,
           *gz = gy + np;
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *c = W->cand + 3 * i;
        if (c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0) continue;
        const double *P = M->positions + 3 * (size_t)M->triangles[W->corner[i]];
        double C[3], fn[3];
        centroid_from(M, W->corner[i] / 3, P, C, fn);
        probe_at(P, C, hmin, x + k, y + k, z + k);
        ++k;
    }
    const lb_status s = lb_evaluator_eval(ev, np, x, y, z, f, gx, gy, gz, threads, err);
    if (s) return s;
    k = 0;
    for (size_t i = 0; i < n; ++i) {
        double *c = W->cand + 3 * i;
        if (c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0) continue;
        if (!probe_normal(g, x[k], y[k], z[k], f[k], gx[k], gy[k], gz[k], c))
            c[0] = c[1] = c[2] = 0.0; /* none: the corner keeps the vertex normal */
        ++k;
    }
    return LB_OK;
}

/* Step 2: the groups of every point with two or more sides. */
static lb_status grouping(const lb_mesh *M, work *W, lb_error *err) {
    for (size_t v = 0; v < M->nvertices; ++v) {
        const size_t a = W->start[v], b = W->start[v + 1];
        if (b - a < 2) continue;
        const size_t base = W->ng;
        if (W->gcap - base < MAXG) {
            const size_t c2 = W->gcap ? 2 * W->gcap : 256;
            group *p = realloc(W->G, c2 * sizeof *p);
            if (!p) return nomem(err);
            W->G = p;
            W->gcap = c2;
        }
        size_t ng = 0;
        for (size_t i = a; i < b; ++i) {
            const double *c = W->cand + 3 * i;
            if (c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0) continue;
            size_t k = 0;
            for (; k < ng; ++k) {
                const double *s = W->G[base + k].sum;
                if (c[0] * s[0] + c[1] * s[1] + c[2] * s[2] > LB__FEATURE_COS * norm3(s)) break;
            }
            if (k == ng) {
                if (ng == MAXG) continue; /* cannot happen on a fan: the vertex normal */
                group *G = &W->G[base + ng++];
                memset(G, 0, sizeof *G);
                G->v = (uint32_t)v;
            }
            group *G = &W->G[base + k];
            double C[3], fn[3];
            centroid_from(M, W->corner[i] / 3, M->positions + 3 * v, C, fn);
            for (int d = 0; d < 3; ++d) {
                G->sum[d] += c[d];
                G->dir[d] += C[d];
            }
            W->gid[i] = (uint32_t)(base + k);
        }
        if (ng < 2) {
            for (size_t i = a; i < b; ++i) W->gid[i] = UINT32_MAX;
        } else {
            W->ng += ng;
        }
    }
    return LB_OK;
}

lb_status lb__corner_normals(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M,
                             const uint8_t *feat, int threads, lb_error *err) {
    const size_t nv = M->nvertices, nt = M->ntriangles;
    M->corner_normals = NULL;
    M->nnormals = nv;
    if (!feat || !nt) return LB_OK;
    work W;
    memset(&W, 0, sizeof W);
    lb_status s = LB_OK;
    if (3 * nt > UINT32_MAX) /* corners are numbered in 32 bits (1.4 G triangles) */
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_mesh_create: corner normals for %zu triangles; allowed: at most "
                        "%u. Fix: a coarser resolution, or no LB_MESH_CORNER_NORMALS",
                        nt, (unsigned)(UINT32_MAX / 3));
    /* the corners at feature points, grouped by point */
    W.start = calloc(nv + 1, sizeof *W.start);
    if (!W.start) return nomem(err);
    for (size_t c = 0; c < 3 * nt; ++c)
        if (feat[M->triangles[c]]) ++W.start[M->triangles[c] + 1];
    for (size_t v = 0; v < nv; ++v) W.start[v + 1] += W.start[v];
    const size_t n = W.start[nv];
    W.corner = malloc((n ? n : 1) * sizeof *W.corner);
    W.cand = malloc(3 * (n ? n : 1) * sizeof *W.cand);
    W.gid = malloc((n ? n : 1) * sizeof *W.gid);
    uint32_t *fill = malloc((nv ? nv : 1) * sizeof *fill);
    if (!W.corner || !W.cand || !W.gid || !fill) {
        free(fill);
        work_free(&W);
        return nomem(err);
    }
    memcpy(fill, W.start, nv * sizeof *fill);
    for (size_t c = 0; c < 3 * nt; ++c)
        if (feat[M->triangles[c]]) W.corner[fill[M->triangles[c]]++] = (uint32_t)c;
    free(fill);
    for (size_t i = 0; i < n; ++i) W.gid[i] = UINT32_MAX;
    const double hmin = fmin(g->h[0], fmin(g->h[1], g->h[2]));
    s = candidates(ev, g, M, feat, &W, hmin, threads, err);
    if (!s) s = grouping(M, &W, err);
    if (!s && W.ng && nv + W.ng > UINT32_MAX)
        s = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                     "lb_mesh_create: more than 2^32 normals; use a coarser resolution");
    /* step 3: one probe per group; groups whose probes agree are one side
     * (a smooth surface that turns across the cells, not a crease) */
    double *gn = NULL;    /* per group: its normal */
    uint32_t *fin = NULL; /* per group: its final normal, past nv; UINT32_MAX: none */
    uint32_t *cn = NULL;
    size_t nfin = 0;
    if (!s && W.ng) {
        gn = malloc(3 * W.ng * sizeof *gn);
        fin = malloc(W.ng * sizeof *fin);
        if (!gn || !fin) s = nomem(err);
    }
    if (!s && W.ng) {
        const size_t m = W.ng;
        for (size_t k = 0; k < m; ++k) { /* the candidates' means */
            const double *sum = W.G[k].sum;
            const double l = norm3(sum);
            for (int d = 0; d < 3; ++d) gn[3 * k + d] = sum[d] / l;
        }
        if (!probes_room(&W, m)) s = nomem(err);
        double *x = W.w, *y = x + m, *z = y + m, *f = z + m, *gx = f + m, *gy = gx + m,
               *gz = gy + m;
        for (size_t k = 0; !s && k < m; ++k)
            probe_at(M->positions + 3 * (size_t)W.G[k].v, W.G[k].dir, hmin, x + k, y + k, z + k);
        if (!s) s = lb_evaluator_eval(ev, m, x, y, z, f, gx, gy, gz, threads, err);
        for (size_t k = 0; !s && k < m; ++k) {
            double *out = gn + 3 * k, nrm[3];
            if (probe_normal(g, x[k], y[k], z[k], f[k], gx[k], gy[k], gz[k], nrm) &&
                nrm[0] * out[0] + nrm[1] * out[1] + nrm[2] * out[2] >= LB__FEATURE_COS)
                memcpy(out, nrm, sizeof nrm);
        }
        /* per point (its groups are consecutive): a group joins the side of
         * the first earlier group whose normal is within the threshold; the
         * sides' normals are moved to the front of gn (side slots never pass
         * the groups still to be read) */
        for (size_t a = 0; !s && a < m;) {
            size_t b = a + 1;
            while (b < m && W.G[b].v == W.G[a].v) ++b;
            uint32_t sides = 0;
            for (size_t k = a; k < b; ++k) {
                const double *r = gn + 3 * k;
                size_t j = a;
                for (; j < k; ++j) {
                    const double *p = gn + 3 * j;
                    if (p[0] * r[0] + p[1] * r[1] + p[2] * r[2] > LB__FEATURE_COS) break;
                }
                fin[k] = j < k ? fin[j] : sides++; /* the side's number */
            }
            if (sides < 2) {
                for (size_t k = a; k < b; ++k) fin[k] = UINT32_MAX;
            } else {
                uint32_t next = 0;
                for (size_t k = a; k < b; ++k) {
                    if (fin[k] == next) { /* the first group of side next */
                        memmove(gn + 3 * (nfin + next), gn + 3 * k, 3 * sizeof *gn);
                        ++next;
                    }
                    fin[k] += (uint32_t)nfin;
                }
                nfin += sides;
            }
            a = b;
        }
    }
    if (!s && nfin) {
        double *q = realloc(M->normals, 3 * (nv + nfin) * sizeof *q);
        if (q) M->normals = q;
        cn = malloc(3 * nt * sizeof *cn);
        if (!q || !cn) s = nomem(err);
    }
    if (!s && nfin) {
        memcpy(M->normals + 3 * nv, gn, 3 * nfin * sizeof *gn);
        memcpy(cn, M->triangles, 3 * nt * sizeof *cn);
        for (size_t i = 0; i < n; ++i)
            if (W.gid[i] != UINT32_MAX && fin[W.gid[i]] != UINT32_MAX)
                cn[W.corner[i]] = (uint32_t)(nv + fin[W.gid[i]]);
        M->corner_normals = cn;
        M->nnormals = nv + nfin;
        cn = NULL;
    }
    free(gn);
    free(fin);
    free(cn);
    work_free(&W);
    return s;
}
