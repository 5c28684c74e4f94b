/* What a coarse-first mesher built from the two-level cell (transition.c)
 * would output, counted on a real scene (docs/meshing.md, Adaptive
 * simplification): not a mesher and not timed, a measurement for its
 * design.
 *
 *     two_level_counts SCENE RES TOL...
 *
 * The scene is meshed once by lb_mesh_create at RES cells (for its grid and
 * its triangle count). Every node of that grid is evaluated (phi_c: the
 * field, intersected with the region's box; the outermost nodes outside),
 * and the uniform cube cells' triangles are counted the way the mesher
 * makes them (n - 2 per loop), a check against the library's count. Then,
 * for each tolerance (cells of RES): the grid of twice the cell size is
 * polygonised (its cells' unsplit loops, vertices on coarse edges by
 * regula falsi on the field), every coarse triangle is checked at points
 * at most a fine cell apart (|phi| / |grad phi|, in fine cells), and the
 * coarse cells with a triangle over the tolerance become fine (their eight
 * fine cells by the cube cases). The rest are two-level cells: edges split
 * where a fine cell is around them, faces quartered where the cell across
 * is fine ("exact seams"), or in addition every face and edge lying on a
 * block's boundary plane (blocks of 8 fine cells, mesher.c's) quartered and
 * split whatever is across ("block seams": a block then needs nothing from
 * its neighbours' decisions). Printed per tolerance and seam rule: the
 * triangles, the fine cells' share, the loops fanned, and the fine
 * crossings a coarse cell cannot see (fine edges crossing inside coarse
 * cells that draw no loop: surface the coarse grid misses). */
#include "../../libblend/src/meshing/mesh_internal.h"

#include <libblend/libblend.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct run {
    const lb_evaluator *ev;
    int soft;
    double bmin[3], bmax[3], origin[3], h[3];
    unsigned N[3]; /* nodes per axis */
    unsigned C[3]; /* coarse cells per axis */
    double *phi;   /* every node */
    uint8_t *fine; /* per coarse cell */
} run;

static size_t nid(const run *R, unsigned x, unsigned y, unsigned z) {
    return ((size_t)z * R->N[1] + y) * R->N[0] + x;
}

static int phi_many(const run *R, size_t n, const double *X, double *v, double *g) {
    if (!n) return 0;
    double *x = calloc(n * 7, sizeof *x);
    if (!x) return 1;
    double *y = x + n, *z = y + n, *f = z + n, *gx = f + n, *gy = gx + n, *gz = gy + n;
    for (size_t i = 0; i < n; ++i) {
        x[i] = X[3 * i];
        y[i] = X[3 * i + 1];
        z[i] = X[3 * i + 2];
    }
    lb_error e;
    if (lb_evaluator_eval(R->ev, n, x, y, z, f, gx, gy, gz, 0, &e)) {
        fprintf(stderr, "two_level_counts: %s\n", e.message);
        free(x);
        return 1;
    }
    for (size_t i = 0; i < n; ++i) {
        const double s = R->soft ? -1 : 1;
        double p = R->soft ? 0.5 - f[i] : f[i];
        double gg[3] = {s * gx[i], s * gy[i], s * gz[i]};
        for (int d = 0; d < 3; ++d) { /* the region's box: max(phi, box) */
            const double c = X[3 * i + d];
            const double lo = R->bmin[d] - c, hi = c - R->bmax[d];
            if (lo > p) {
                p = lo;
                memset(gg, 0, sizeof gg);
                gg[d] = -1;
            }
            if (hi > p) {
                p = hi;
                memset(gg, 0, sizeof gg);
                gg[d] = 1;
            }
        }
        v[i] = p;
        if (g) memcpy(g + 3 * i, gg, sizeof gg);
    }
    free(x);
    return 0;
}

static void node_at(const run *R, size_t n, double X[3]) {
    const size_t x = n % R->N[0], y = n / R->N[0] % R->N[1], z = n / ((size_t)R->N[0] * R->N[1]);
    X[0] = R->origin[0] + (double)x * R->h[0];
    X[1] = R->origin[1] + (double)y * R->h[1];
    X[2] = R->origin[2] + (double)z * R->h[2];
}

static int inside(const run *R, size_t n) {
    return R->phi[n] < 0;
}

/* the coarse cells' own loops and their vertices: root between nodes a, b */
typedef struct ctri {
    size_t cell;
    double p[3][3];
} ctri;

/* roots of phi on segments (a inside, b outside), regula falsi (Illinois) */
static int roots(const run *R, size_t n, const size_t *a, const size_t *b, double *P) {
    double *A = malloc(sizeof *A * n * 8);
    if (!A) return 1;
    double *B = A + 3 * n, *fa = B + 3 * n, *fb = fa + n;
    for (size_t i = 0; i < n; ++i) {
        node_at(R, a[i], A + 3 * i);
        node_at(R, b[i], B + 3 * i);
        fa[i] = R->phi[a[i]];
        fb[i] = R->phi[b[i]];
    }
    double *v = malloc(sizeof *v * n);
    if (!v) return 1;
    for (int it = 0; it < 30; ++it) {
        for (size_t i = 0; i < n; ++i) {
            const double t = fa[i] / (fa[i] - fb[i]);
            for (int d = 0; d < 3; ++d)
                P[3 * i + d] = A[3 * i + d] + t * (B[3 * i + d] - A[3 * i + d]);
        }
        if (it == 29) break;
        if (phi_many(R, n, P, v, NULL)) return 1;
        for (size_t i = 0; i < n; ++i) {
            if (v[i] < 0) {
                memcpy(A + 3 * i, P + 3 * i, 3 * sizeof *P);
                fa[i] = v[i];
                fb[i] *= 0.5;
            } else {
                memcpy(B + 3 * i, P + 3 * i, 3 * sizeof *P);
                fb[i] = v[i];
                fa[i] *= 0.5;
            }
        }
    }
    free(v);
    free(A);
    return 0;
}

/* lattice node l (x + 3 y + 9 z) of coarse cell (cx, cy, cz) */
static size_t lat(const run *R, unsigned cx, unsigned cy, unsigned cz, int l) {
    return nid(R, 2 * cx + (unsigned)(l % 3), 2 * cy + (unsigned)(l / 3 % 3),
               2 * cz + (unsigned)(l / 9));
}

static int fine_at(const run *R, long x, long y, long z) {
    if (x < 0 || y < 0 || z < 0 || x >= R->C[0] || y >= R->C[1] || z >= R->C[2]) return 0;
    return R->fine[((size_t)z * R->C[1] + (size_t)y) * R->C[0] + (size_t)x];
}

/* the two-level cell of coarse cell c under the seam rule (blockseams: the
 * block boundary planes quartered too) */
static lb__tcell tcell_of(const run *R, const unsigned c[3], int blockseams) {
    lb__tcell t = {0, 0, 0};
    for (int e = 0; e < 12; ++e) {
        int p, q;
        lb__cube_edge(e, &p, &q);
        const int a = p ^ q;
        int any = 0, onblock = 0, planes = 0;
        for (int d = 0; d < 3; ++d) {
            if ((1 << d) == a) continue;
            const unsigned pos = c[d] + (unsigned)((p >> d) & 1); /* the edge's coarse node */
            if (pos % 4 == 0) ++planes;
        }
        onblock = planes > 0;
        for (int k = 0; k < 4; ++k) {
            long n[3];
            int j = 0;
            for (int d = 0; d < 3; ++d) {
                n[d] = c[d];
                if ((1 << d) == a) continue;
                n[d] = (long)c[d] + ((p >> d) & 1) - ((k >> j++) & 1);
            }
            any |= fine_at(R, n[0], n[1], n[2]);
        }
        if (any || (blockseams && onblock)) t.split |= (uint16_t)(1u << e);
    }
    for (int f = 0; f < 6; ++f) {
        long n[3] = {c[0], c[1], c[2]};
        n[f / 2] += f % 2 ? 1 : -1;
        const unsigned plane = c[f / 2] + (unsigned)(f % 2);
        if (fine_at(R, n[0], n[1], n[2]) || (blockseams && plane % 4 == 0))
            t.quarter |= (uint8_t)(1u << f);
    }
    /* a quartered face needs its four edges split (block seams: they lie on
     * the plane, so they are) */
    for (int l = 0; l < LB__TNODES; ++l)
        if (l != 13 && inside(R, lat(R, c[0], c[1], c[2], l))) t.inside |= 1u << l;
    return t;
}

static int cmp_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static int cmp_ctri(const void *a, const void *b) {
    const size_t x = ((const ctri *)a)->cell, y = ((const ctri *)b)->cell;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: two_level_counts SCENE RES TOL...\n");
        return 2;
    }
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    if (lb_scene_load(argv[1], &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "two_level_counts: %s\n", e.message);
        return 2;
    }
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    o.resolution = (unsigned)atoi(argv[2]);
    lb_scene_bounds(sc, o.bmin, o.bmax);
    lb_mesh *m = NULL;
    if (lb_mesh_create(ev, &o, &m, &e)) {
        fprintf(stderr, "two_level_counts: %s\n", e.message);
        return 1;
    }
    run R = {.ev = ev, .soft = lb_evaluator_convention(ev) == LB_CONVENTION_SOFT};
    for (int d = 0; d < 3; ++d) {
        R.bmin[d] = o.bmin[d];
        R.bmax[d] = o.bmax[d];
        R.origin[d] = m->origin[d];
        R.h[d] = m->cell[d];
        R.C[d] = (m->cells[d] + 1) / 2;
        R.N[d] = 2 * R.C[d] + 1; /* an odd cell count gets one more, outside */
    }
    const size_t nn = (size_t)R.N[0] * R.N[1] * R.N[2];
    R.phi = malloc(sizeof *R.phi * nn);
    double *X = malloc(sizeof *X * 3 * nn);
    if (!R.phi || !X) return 1;
    for (size_t n = 0; n < nn; ++n) node_at(&R, n, X + 3 * n);
    if (phi_many(&R, nn, X, R.phi, NULL)) return 1;
    free(X);
    for (unsigned z = 0; z < R.N[2]; ++z)
        for (unsigned y = 0; y < R.N[1]; ++y)
            for (unsigned x = 0; x < R.N[0]; ++x)
                if (!x || !y || !z || x == R.N[0] - 1 || y == R.N[1] - 1 || z == R.N[2] - 1)
                    R.phi[nid(&R, x, y, z)] = 1;
    lb__mctable *mc = malloc(sizeof *mc);
    if (!mc) return 1;
    lb__mctable_init(mc);
    /* the uniform count */
    size_t uniform = 0;
    for (unsigned z = 0; z + 1 < R.N[2]; ++z)
        for (unsigned y = 0; y + 1 < R.N[1]; ++y)
            for (unsigned x = 0; x + 1 < R.N[0]; ++x) {
                int cfg = 0;
                for (int c = 0; c < 8; ++c)
                    if (inside(&R, nid(&R, x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1))))
                        cfg |= 1 << c;
                for (int l = 0; l < mc->c[cfg].nloop; ++l) uniform += mc->c[cfg].len[l] - 2u;
            }
    printf("%s at %u cells: lb_mesh_create %zu triangles, the grid's cube cells %zu\n", argv[1],
           o.resolution, m->ntriangles, uniform);
    /* the coarse cells' unsplit loops, their vertices and triangles */
    const size_t ncc = (size_t)R.C[0] * R.C[1] * R.C[2];
    size_t cap = 1024, nct = 0, nv = 0, vcap = 1024;
    ctri *T = malloc(sizeof *T * cap);
    size_t *va = malloc(sizeof *va * vcap), *vb = malloc(sizeof *vb * vcap);
    R.fine = calloc(ncc, 1);
    if (!T || !va || !vb || !R.fine) return 1;
    /* pass 1: vertices (one per loop sub-edge; shared ones solved twice) */
    typedef struct pending {
        size_t cell, v0;
        int n;
    } pending;
    size_t pcap = 1024, np = 0;
    pending *P = malloc(sizeof *P * pcap);
    if (!P) return 1;
    for (unsigned cz = 0; cz < R.C[2]; ++cz)
        for (unsigned cy = 0; cy < R.C[1]; ++cy)
            for (unsigned cx = 0; cx < R.C[0]; ++cx) {
                lb__tcell t = {0, 0, 0};
                for (int o8 = 0; o8 < 8; ++o8) {
                    const int l = 2 * (o8 & 1) + 6 * ((o8 >> 1) & 1) + 18 * (o8 >> 2);
                    if (inside(&R, lat(&R, cx, cy, cz, l))) t.inside |= 1u << l;
                }
                uint16_t sub[LB__TMAX];
                uint8_t len[LB__TMAX / 3];
                int nloop;
                if (lb__tcell_loops(&t, sub, len, &nloop) < 0) return 1;
                for (int l = 0, off = 0; l < nloop; off += len[l++]) {
                    if (np == pcap) P = realloc(P, sizeof *P * (pcap *= 2));
                    while (nv + len[l] > vcap) {
                        vcap *= 2;
                        va = realloc(va, sizeof *va * vcap);
                        vb = realloc(vb, sizeof *vb * vcap);
                    }
                    if (!P || !va || !vb) return 1;
                    P[np].cell = ((size_t)cz * R.C[1] + cy) * R.C[0] + cx;
                    P[np].v0 = nv;
                    P[np].n = len[l];
                    for (int i = 0; i < len[l]; ++i) {
                        size_t a = lat(&R, cx, cy, cz, sub[off + i] / LB__TNODES),
                               b = lat(&R, cx, cy, cz, sub[off + i] % LB__TNODES);
                        if (!inside(&R, a)) {
                            const size_t s = a;
                            a = b;
                            b = s;
                        }
                        va[nv] = a;
                        vb[nv++] = b;
                    }
                    ++np;
                }
            }
    double *V = malloc(sizeof *V * 3 * (nv ? nv : 1));
    if (!V || roots(&R, nv, va, vb, V)) return 1;
    /* the coarse triangles: fans would be the mesher's choice where the
     * loop folds; for the check, the loop's triangulation by lb__tloop_triangles
     * on the unsplit cell (or a fan around the loop's mean) */
    for (size_t i = 0; i < np; ++i) {
        const size_t cell = P[i].cell;
        const unsigned cx = (unsigned)(cell % R.C[0]), cy = (unsigned)(cell / R.C[0] % R.C[1]),
                       cz = (unsigned)(cell / ((size_t)R.C[0] * R.C[1]));
        uint16_t sub[LB__TMAX];
        const int n = P[i].n;
        for (int k = 0; k < n; ++k) {
            /* back to lattice nodes for the plane rule */
            int la = -1, lb = -1;
            for (int l = 0; l < LB__TNODES; ++l) {
                if (lat(&R, cx, cy, cz, l) == va[P[i].v0 + k]) la = l;
                if (lat(&R, cx, cy, cz, l) == vb[P[i].v0 + k]) lb = l;
            }
            sub[k] = (uint16_t)(la < lb ? la * LB__TNODES + lb : lb * LB__TNODES + la);
        }
        uint8_t tri[3 * LB__TMAX];
        int nt = lb__tloop_triangles(sub, V + 3 * P[i].v0, n, tri);
        double mean[3] = {0, 0, 0};
        if (!nt)
            for (int k = 0; k < n; ++k)
                for (int d = 0; d < 3; ++d) mean[d] += V[3 * (P[i].v0 + k) + d] / n;
        const int count = nt ? nt : n;
        for (int k = 0; k < count; ++k) {
            if (nct == cap) T = realloc(T, sizeof *T * (cap *= 2));
            if (!T) return 1;
            T[nct].cell = cell;
            for (int q = 0; q < 3; ++q) {
                const double *src;
                if (nt)
                    src = V + 3 * (P[i].v0 + tri[3 * k + q]);
                else
                    src = q == 0   ? V + 3 * (P[i].v0 + k)
                          : q == 1 ? V + 3 * (P[i].v0 + (k + 1) % n)
                                   : mean;
                memcpy(T[nct].p[q], src, 3 * sizeof(double));
            }
            ++nct;
        }
    }
    qsort(T, nct, sizeof *T, cmp_ctri);
    /* the check's points: a barycentric lattice at most a fine cell apart */
    const double hmin = fmin(R.h[0], fmin(R.h[1], R.h[2]));
    size_t npts = 0, pcap2 = 1 << 16;
    double *Q = malloc(sizeof *Q * 3 * pcap2);
    size_t *qt = malloc(sizeof *qt * pcap2);
    if (!Q || !qt) return 1;
    for (size_t t = 0; t < nct; ++t) {
        double L = 0;
        for (int q = 0; q < 3; ++q) {
            const double *a = T[t].p[q], *b = T[t].p[(q + 1) % 3];
            L = fmax(L, sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                             (a[2] - b[2]) * (a[2] - b[2])));
        }
        const int k = (int)ceil(L / hmin);
        for (int i = 0; i <= k; ++i)
            for (int j = 0; i + j <= k; ++j) {
                if (npts == pcap2) {
                    pcap2 *= 2;
                    Q = realloc(Q, sizeof *Q * 3 * pcap2);
                    qt = realloc(qt, sizeof *qt * pcap2);
                    if (!Q || !qt) return 1;
                }
                const double u = k ? (double)i / k : 0, w = k ? (double)j / k : 0;
                for (int d = 0; d < 3; ++d)
                    Q[3 * npts + d] = T[t].p[0][d] + u * (T[t].p[1][d] - T[t].p[0][d]) +
                                      w * (T[t].p[2][d] - T[t].p[0][d]);
                qt[npts++] = t;
            }
    }
    double *qv = malloc(sizeof *qv * npts), *qg = malloc(sizeof *qg * 3 * npts);
    if (!qv || !qg || phi_many(&R, npts, Q, qv, qg)) return 1;
    double *terr = calloc(nct ? nct : 1, sizeof *terr);
    if (!terr) return 1;
    for (size_t i = 0; i < npts; ++i) {
        const double gl = sqrt(qg[3 * i] * qg[3 * i] + qg[3 * i + 1] * qg[3 * i + 1] +
                               qg[3 * i + 2] * qg[3 * i + 2]);
        const double err = gl > 0 ? fabs(qv[i]) / gl / hmin : INFINITY;
        if (err > terr[qt[i]]) terr[qt[i]] = err;
    }
    /* a sparser check: each triangle's centroid and edge midpoints */
    double *S = malloc(sizeof *S * 12 * (nct ? nct : 1)),
           *sv = malloc(sizeof *sv * 4 * (nct ? nct : 1)),
           *sg = malloc(sizeof *sg * 12 * (nct ? nct : 1)),
           *serr = calloc(nct ? nct : 1, sizeof *serr);
    if (!S || !sv || !sg || !serr) return 1;
    for (size_t t = 0; t < nct; ++t)
        for (int d = 0; d < 3; ++d) {
            S[12 * t + d] = (T[t].p[0][d] + T[t].p[1][d] + T[t].p[2][d]) / 3;
            for (int q = 0; q < 3; ++q)
                S[12 * t + 3 * (q + 1) + d] = 0.5 * (T[t].p[q][d] + T[t].p[(q + 1) % 3][d]);
        }
    if (phi_many(&R, 4 * nct, S, sv, sg)) return 1;
    for (size_t i = 0; i < 4 * nct; ++i) {
        const double gl = sqrt(sg[3 * i] * sg[3 * i] + sg[3 * i + 1] * sg[3 * i + 1] +
                               sg[3 * i + 2] * sg[3 * i + 2]);
        const double err = gl > 0 ? fabs(sv[i]) / gl / hmin : INFINITY;
        if (err > serr[i / 4]) serr[i / 4] = err;
    }
    /* a check from the vertices' normals alone (no evaluation beyond the
     * roots' own): a triangle's edge of length L whose end normals turn by
     * an angle a bows out of it by about L a / 8 (a circular arc) */
    double *nerr = calloc(nct ? nct : 1, sizeof *nerr);
    if (!nerr) return 1;
    {
        /* the triangles hold positions only: their corners' normals by
         * evaluating there (the mesher has them from the roots) */
        double *CP = malloc(sizeof *CP * 9 * (nct ? nct : 1)),
               *cv = malloc(sizeof *cv * 3 * (nct ? nct : 1)),
               *cg = malloc(sizeof *cg * 9 * (nct ? nct : 1));
        if (!CP || !cv || !cg) return 1;
        for (size_t t = 0; t < nct; ++t)
            for (int q = 0; q < 3; ++q) memcpy(CP + 9 * t + 3 * q, T[t].p[q], 3 * sizeof(double));
        if (phi_many(&R, 3 * nct, CP, cv, cg)) return 1;
        for (size_t t = 0; t < nct; ++t)
            for (int q = 0; q < 3; ++q) {
                const double *a = CP + 9 * t + 3 * q, *b = CP + 9 * t + 3 * ((q + 1) % 3);
                const double *ga = cg + 9 * t + 3 * q, *gb = cg + 9 * t + 3 * ((q + 1) % 3);
                const double la = sqrt(ga[0] * ga[0] + ga[1] * ga[1] + ga[2] * ga[2]),
                             lb = sqrt(gb[0] * gb[0] + gb[1] * gb[1] + gb[2] * gb[2]);
                double c = (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]) / (la * lb);
                c = c > 1 ? 1 : c < -1 ? -1 : c;
                const double L =
                    sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                         (a[2] - b[2]) * (a[2] - b[2]));
                const double est = L * acos(c) / 8 / hmin;
                if (est > nerr[t]) nerr[t] = est;
            }
        free(CP);
        free(cv);
        free(cg);
    }
    size_t coarse_plain = 0;
    for (size_t t = 0; t < nct; ++t) ++coarse_plain;
    printf("  the grid of twice the cell: %zu triangles, %zu check points\n", coarse_plain, npts);
    /* the coarse cells without a sign change at their corners that the
     * interval bounds cannot clear (their fine nodes must be looked at), and
     * of those the ones with a fine crossing (surface the corners miss) */
    size_t unclear = 0, hidden = 0, quiet = 0;
    for (unsigned cz = 0; cz < R.C[2]; ++cz)
        for (unsigned cy = 0; cy < R.C[1]; ++cy)
            for (unsigned cx = 0; cx < R.C[0]; ++cx) {
                int in = 0;
                for (int o8 = 0; o8 < 8; ++o8)
                    in += inside(&R, lat(&R, cx, cy, cz,
                                         2 * (o8 & 1) + 6 * ((o8 >> 1) & 1) + 18 * (o8 >> 2)));
                if (in != 0 && in != 8) continue;
                ++quiet;
                double lo[3], hi[3], flo, fhi;
                node_at(&R, lat(&R, cx, cy, cz, 0), lo);
                node_at(&R, lat(&R, cx, cy, cz, 26), hi);
                if (lb_evaluator_bounds(ev, lo, hi, &flo, &fhi, &e)) return 1;
                const double level = R.soft ? 0.5 : 0.0;
                if (!(flo <= level && fhi >= level)) continue;
                ++unclear;
                int fine_in = 0;
                for (int l = 0; l < LB__TNODES; ++l) fine_in += inside(&R, lat(&R, cx, cy, cz, l));
                if (fine_in != 0 && fine_in != LB__TNODES) ++hidden;
            }
    printf("  coarse cells without a corner sign change: %zu; the field's interval over the cell "
           "not clear of the surface: %zu (%zu fine nodes to evaluate); of those with a fine "
           "sign change: %zu\n",
           quiet, unclear, 19 * unclear, hidden);
    /* the cells whose interval is not clear of the surface: every coarse
     * cell, and the fine cells inside the coarse ones that are not. The
     * uniform mesher's mark (mesher.c) stops at boxes of two cells a side,
     * the coarse cells: it evaluates the 27 nodes of each such box (under
     * the block plans' intervals, which may be tighter than the whole
     * field's here); the corners of the fine cells alone would be fewer */
    const unsigned F[3] = {2 * R.C[0], 2 * R.C[1], 2 * R.C[2]};
    uint8_t *cstr = calloc(ncc, 1), *fstr = calloc((size_t)F[0] * F[1] * F[2], 1),
            *need = calloc(nn, 1);
    if (!cstr || !fstr || !need) return 1;
    const double level = R.soft ? 0.5 : 0.0;
    for (size_t c = 0; c < ncc; ++c) {
        const unsigned cx = (unsigned)(c % R.C[0]), cy = (unsigned)(c / R.C[0] % R.C[1]),
                       cz = (unsigned)(c / ((size_t)R.C[0] * R.C[1]));
        double lo[3], hi[3], flo, fhi;
        node_at(&R, lat(&R, cx, cy, cz, 0), lo);
        node_at(&R, lat(&R, cx, cy, cz, 26), hi);
        if (lb_evaluator_bounds(ev, lo, hi, &flo, &fhi, &e)) return 1;
        if (!(flo <= level && fhi >= level)) continue;
        cstr[c] = 1;
        for (int o8 = 0; o8 < 8; ++o8) {
            const unsigned x = 2 * cx + (o8 & 1), y = 2 * cy + ((o8 >> 1) & 1),
                           z = 2 * cz + ((o8 >> 2) & 1);
            node_at(&R, nid(&R, x, y, z), lo);
            node_at(&R, nid(&R, x + 1, y + 1, z + 1), hi);
            if (lb_evaluator_bounds(ev, lo, hi, &flo, &fhi, &e)) return 1;
            if (!(flo <= level && fhi >= level)) continue;
            fstr[((size_t)z * F[1] + y) * F[0] + x] = 1;
            for (int k = 0; k < 8; ++k)
                need[nid(&R, x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1))] = 1;
        }
    }
    size_t unodes = 0, mnodes = 0;
    for (size_t n = 0; n < nn; ++n) unodes += need[n];
    for (size_t c = 0; c < ncc; ++c)
        if (cstr[c])
            for (int l = 0; l < LB__TNODES; ++l)
                need[lat(&R, (unsigned)(c % R.C[0]), (unsigned)(c / R.C[0] % R.C[1]),
                         (unsigned)(c / ((size_t)R.C[0] * R.C[1])), l)] = 1;
    for (size_t n = 0; n < nn; ++n) mnodes += need[n];
    printf("  the uniform mesher: %zu vertices (roots), %zu nodes evaluated (boxes of two cells; "
           "%zu at the fine cells' corners)\n",
           m->nvertices, mnodes, unodes);
    size_t kcap = 1 << 16, nk = 0;
    uint64_t *keys = malloc(sizeof *keys * kcap);
    if (!keys) return 1;
#define KEY(a, b) ((a) < (b) ? (uint64_t)(a)*nn + (b) : (uint64_t)(b)*nn + (a))
#define PUSH(k)                                                                                    \
    do {                                                                                           \
        if (nk == kcap) {                                                                          \
            keys = realloc(keys, sizeof *keys * (kcap *= 2));                                      \
            if (!keys) return 1;                                                                   \
        }                                                                                          \
        keys[nk++] = (k);                                                                          \
    } while (0)
    for (int ti = 3; ti < argc; ++ti) {
        const double tol = atof(argv[ti]);
        memset(R.fine, 0, ncc);
        for (size_t t = 0; t < nct; ++t)
            if (terr[t] > tol) R.fine[T[t].cell] = 1;
        size_t nfine = 0, sparse_miss = 0;
        for (size_t c = 0; c < ncc; ++c) nfine += R.fine[c];
        {
            uint8_t *sf = calloc(ncc, 1);
            if (!sf) return 1;
            for (size_t t = 0; t < nct; ++t)
                if (serr[t] > tol) sf[T[t].cell] = 1;
            for (size_t c = 0; c < ncc; ++c) sparse_miss += R.fine[c] && !sf[c];
            free(sf);
        }
        printf("  tolerance %g cells: the sparse check (%zu points) misses %zu of the %zu failing "
               "coarse cells\n",
               tol, 4 * nct, sparse_miss, nfine);
        for (int mode = 0; mode < 2; ++mode) {
            uint8_t *nf = calloc(ncc, 1);
            if (!nf) return 1;
            for (size_t t = 0; t < nct; ++t)
                if (nerr[t] > tol || (mode && serr[t] > tol)) nf[T[t].cell] = 1;
            size_t miss = 0, extra = 0;
            for (size_t c = 0; c < ncc; ++c) {
                miss += R.fine[c] && !nf[c];
                extra += !R.fine[c] && nf[c];
            }
            printf("  tolerance %g cells: the normals' estimate%s misses %zu of the %zu failing "
                   "coarse cells and flags %zu that pass\n",
                   tol, mode ? " with the sparse points" : "", miss, nfine, extra);
            free(nf);
        }
        for (int blockseams = 0; blockseams < 2; ++blockseams) {
            size_t tris = 0, fine_tris = 0, fans = 0, loops = 0, missed = 0;
            memset(need, 0, nn);
            nk = 0;
            for (unsigned cz = 0; cz < R.C[2]; ++cz)
                for (unsigned cy = 0; cy < R.C[1]; ++cy)
                    for (unsigned cx = 0; cx < R.C[0]; ++cx) {
                        const unsigned c[3] = {cx, cy, cz};
                        if (fine_at(&R, cx, cy, cz)) {
                            for (int o8 = 0; o8 < 8; ++o8) {
                                const unsigned x = 2 * cx + (o8 & 1), y = 2 * cy + ((o8 >> 1) & 1),
                                               z = 2 * cz + ((o8 >> 2) & 1);
                                int cfg = 0;
                                for (int k = 0; k < 8; ++k)
                                    if (inside(&R, nid(&R, x + (k & 1), y + ((k >> 1) & 1),
                                                       z + ((k >> 2) & 1))))
                                        cfg |= 1 << k;
                                for (int l = 0, off = 0; l < mc->c[cfg].nloop;
                                     off += mc->c[cfg].len[l++]) {
                                    fine_tris += mc->c[cfg].len[l] - 2u;
                                    for (int q = 0; q < mc->c[cfg].len[l]; ++q) {
                                        int p0, p1;
                                        lb__cube_edge(mc->c[cfg].e[off + q], &p0, &p1);
                                        const size_t a = nid(&R, x + (p0 & 1), y + ((p0 >> 1) & 1),
                                                             z + ((p0 >> 2) & 1)),
                                                     b = nid(&R, x + (p1 & 1), y + ((p1 >> 1) & 1),
                                                             z + ((p1 >> 2) & 1));
                                        PUSH(KEY(a, b));
                                    }
                                }
                                if (cstr[((size_t)cz * R.C[1] + cy) * R.C[0] + cx])
                                    for (int l = 0; l < LB__TNODES; ++l)
                                        need[lat(&R, cx, cy, cz, l)] = 1;
                            }
                            continue;
                        }
                        const lb__tcell t = tcell_of(&R, c, blockseams);
                        const size_t ci = ((size_t)cz * R.C[1] + cy) * R.C[0] + cx;
                        if (cstr[ci]) { /* its samples: corners, split midpoints, quarters */
                            int sampled[LB__TNODES] = {0};
                            for (int o8 = 0; o8 < 8; ++o8)
                                sampled[2 * (o8 & 1) + 6 * ((o8 >> 1) & 1) + 18 * (o8 >> 2)] = 1;
                            for (int ed = 0; ed < 12; ++ed)
                                if ((t.split >> ed) & 1) {
                                    int p0, p1;
                                    lb__cube_edge(ed, &p0, &p1);
                                    sampled[(2 * (p0 & 1) + 6 * ((p0 >> 1) & 1) + 18 * (p0 >> 2) +
                                             2 * (p1 & 1) + 6 * ((p1 >> 1) & 1) + 18 * (p1 >> 2)) /
                                            2] = 1;
                                }
                            for (int f = 0; f < 6; ++f)
                                if ((t.quarter >> f) & 1) {
                                    const int d = f / 2, side = f % 2,
                                              st = d == 0   ? 1
                                                   : d == 1 ? 3
                                                            : 9;
                                    sampled[13 + (side ? st : -st)] = 1;
                                }
                            int in = 0, cnt = 0;
                            for (int l = 0; l < LB__TNODES; ++l)
                                if (sampled[l]) {
                                    ++cnt;
                                    in += inside(&R, lat(&R, cx, cy, cz, l));
                                }
                            const int quiet = in == 0 || in == cnt;
                            for (int l = 0; l < LB__TNODES; ++l)
                                if (sampled[l] || quiet) need[lat(&R, cx, cy, cz, l)] = 1;
                        }
                        uint16_t sub[LB__TMAX];
                        uint8_t len[LB__TMAX / 3];
                        int nloop;
                        if (lb__tcell_loops(&t, sub, len, &nloop) < 0) return 1;
                        if (!nloop) { /* fine crossings it cannot see */
                            for (int a = 0; a < LB__TNODES; ++a)
                                for (int d = 0, step = 1; d < 3; ++d, step *= 3) {
                                    if (a / step % 3 == 2) continue;
                                    if (inside(&R, lat(&R, cx, cy, cz, a)) !=
                                        inside(&R, lat(&R, cx, cy, cz, a + step)))
                                        ++missed;
                                }
                        }
                        /* triangles: positions by linear interpolation of
                         * the samples (counts only; a fan where it folds) */
                        for (int l = 0, off = 0; l < nloop; off += len[l++]) {
                            double pos[3 * LB__TMAX];
                            for (int k = 0; k < len[l]; ++k) {
                                const size_t a = lat(&R, cx, cy, cz, sub[off + k] / LB__TNODES),
                                             b = lat(&R, cx, cy, cz, sub[off + k] % LB__TNODES);
                                double A[3], B[3];
                                node_at(&R, a, A);
                                node_at(&R, b, B);
                                const double s = R.phi[a] / (R.phi[a] - R.phi[b]);
                                for (int d = 0; d < 3; ++d)
                                    pos[3 * k + d] = A[d] + s * (B[d] - A[d]);
                            }
                            for (int k = 0; k < len[l]; ++k)
                                PUSH(KEY(lat(&R, cx, cy, cz, sub[off + k] / LB__TNODES),
                                         lat(&R, cx, cy, cz, sub[off + k] % LB__TNODES)));
                            uint8_t tri[3 * LB__TMAX];
                            const int nt = lb__tloop_triangles(sub + off, pos, len[l], tri);
                            ++loops;
                            if (!nt) ++fans;
                            tris += nt ? (size_t)nt : len[l];
                        }
                    }
            qsort(keys, nk, sizeof *keys, cmp_u64);
            size_t nvert = 0, nodes = 0;
            for (size_t i = 0; i < nk; ++i) nvert += !i || keys[i] != keys[i - 1];
            for (size_t n = 0; n < nn; ++n) nodes += need[n];
            printf("  tolerance %g cells, %s: %zu vertices (roots), %zu nodes evaluated, "
                   "with the check %zu evaluations\n",
                   tol, blockseams ? "block seams" : "exact seams", nvert, nodes, nodes + npts);
            printf("  tolerance %g cells, %s: %zu triangles (%.3f of the uniform; %zu in "
                   "fine cells, %zu of %zu coarse cells fine), %zu of %zu coarse loops fanned, "
                   "%zu fine crossings in coarse cells drawing nothing\n",
                   tol, blockseams ? "block seams" : "exact seams", tris + fine_tris,
                   (double)(tris + fine_tris) / (double)uniform, fine_tris, nfine, ncc, fans, loops,
                   missed);
        }
    }
    free(keys);
    free(cstr);
    free(fstr);
    free(need);
    free(terr);
    free(nerr);
    free(S);
    free(sv);
    free(sg);
    free(serr);
    free(qv);
    free(qg);
    free(Q);
    free(qt);
    free(V);
    free(P);
    free(T);
    free(va);
    free(vb);
    free(mc);
    free(R.fine);
    free(R.phi);
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return 0;
}
