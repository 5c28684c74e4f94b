/* Sharp features (LB_MESH_FEATURES): a vertex on the crease or corner that
 * a cell's surface bends around, and the flips that join those vertices
 * along the crease. extract.c places the points; this file holds the
 * least-squares fit and the flips.
 *
 * A cell polygon's vertices lie on the cell's edges, each with the unit
 * normal of the field there. Where two of them differ by more than
 * LB__FEATURE_COS, the surface bends sharply inside the cell and the
 * polygon's own triangles would cut the bend off (a bevel of up to half a
 * cell). Each vertex and normal says the surface passes through p_i with
 * tangent plane n_i . (x - p_i) = 0; the point that best satisfies all of
 * them in the least-squares sense (the quadric error function, QEF, of
 * dual contouring) lies on the crease of two planes, or at the corner of
 * three. It is found with the small directions of the 3x3 normal matrix cut
 * off (what those directions cannot decide, the polygon's mass point does),
 * within a box (the cell, grown by half a cell: extract.c says why), by the
 * box's faces, edges and corners when the free minimum lies outside. The
 * polygon becomes a fan around that point: the same boundary segments on
 * the cell faces, so the mesh stays closed and manifold.
 *
 * A fan's triangle runs from the feature point to a segment on a cell
 * face; the neighbouring cell's fan has the same segment. When both cells
 * have a feature point, the segment crosses the crease between them: it is
 * flipped into the edge between the two points (lb__feature_flips), so the
 * crease is an edge of the mesh.
 *
 * A fan whose point lies beyond the cell face holding one of its segments
 * (the crease passes just outside the cell) faces against the surface
 * there until that segment is flipped. Where the neighbour has no point to
 * flip with, the fold stays and may cross the neighbours' triangles: such a
 * point is moved to the mean of its ring and put back on the surface
 * (lb__feature_unfold), a plain vertex in place of a crease point. Fans
 * are therefore made wherever a point is found and repaired afterwards, not
 * refused beforehand: refusing every fan that folds before the flips (the
 * first rule) also refused the many that the flips set right, and left the
 * crease of a cylinder cut by a slab 0.03 to 0.06 cells off at 32 to 128
 * cells where it is now as close as the flat triangles' own chord error. */
#include "../common/platform.h"
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Eigenvalues w and eigenvectors (columns of V) of the symmetric k x k
 * matrix A (k <= 3, row-major in a 3x3 array), by cyclic Jacobi rotations:
 * a fixed sequence of operations, so the same input gives the same bits.
 * Each rotation zeroes A[p][q] with t = tan of its angle, the smaller root
 * of t^2 + 2 theta t - 1 = 0, theta = (A[q][q] - A[p][p]) / (2 A[p][q]),
 * computed as sign(d) 2 A[p][q] / (|d| + sqrt(d^2 + 4 A[p][q]^2)), d =
 * A[q][q] - A[p][p] (one division fewer than through theta); the diagonal
 * moves by t A[p][q] and only the third row and column turn. A pair already
 * below rounding against its diagonal (|A[p][q]| <= 1e-16 (|A[p][p]| +
 * |A[q][q]|)) is not turned: a sixth of the rotations on S2's fillets,
 * which would change nothing but the last bits; the sweeps still end, as
 * such pairs alone meet the convergence test. */
static inline void sym_eigen(double A[3][3], int k, double w[3], double V[3][3]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) V[i][j] = i == j;
    for (int sweep = 0; sweep < 32; ++sweep) {
        double off = 0.0;
        for (int p = 0; p < k; ++p)
            for (int q = p + 1; q < k; ++q) off += A[p][q] * A[p][q];
        double diag = 1e-300; /* converged: off-diagonal tiny against the diagonal */
        for (int p = 0; p < k; ++p) diag += A[p][p] * A[p][p];
        if (off <= 1e-30 * diag) break;
        for (int p = 0; p < k; ++p)
            for (int q = p + 1; q < k; ++q) {
                const double apq = A[p][q], app = A[p][p], aqq = A[q][q];
                if (!(fabs(apq) > 1e-16 * (fabs(app) + fabs(aqq)))) continue;
                const double d = aqq - app, e = 2.0 * apq;
                const double t =
                    d == 0.0 ? 1.0 : (d > 0.0 ? e : -e) / (fabs(d) + sqrt(d * d + e * e));
                const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                A[p][p] = app - t * apq;
                A[q][q] = aqq + t * apq;
                A[p][q] = A[q][p] = 0.0;
                for (int r = 0; r < k; ++r) {
                    if (r == p || r == q) continue;
                    const double arp = A[r][p], arq = A[r][q];
                    A[r][p] = A[p][r] = c * arp - s * arq;
                    A[r][q] = A[q][r] = s * arp + c * arq;
                }
                for (int r = 0; r < k; ++r) {
                    const double vrp = V[r][p], vrq = V[r][q];
                    V[r][p] = c * vrp - s * vrq;
                    V[r][q] = s * vrp + c * vrq;
                }
            }
    }
    for (int i = 0; i < k; ++i) w[i] = A[i][i];
}

/* Directions whose eigenvalue is below this fraction of the largest are
 * left to the mass point: for the normals of two planes at angle t the
 * small eigenvalue is about sin^2 t of the large one, so creases sharper
 * than about 8 degrees are resolved, and nearly parallel normals (a gently
 * curved surface) do not throw the point far along its tangent plane. */
#define EIG_CUT 0.02

/* The least-squares step y over the k free coordinates idx (their values
 * x0 so far): y = pinv(A_F^T A_F) A_F^T r with r_i = n_i . (p_i - x0).
 * Inline, and called with k (and for k = 3 the coordinates) as constants,
 * so that the compiler unrolls the 3 x 3 work: the same operations in the
 * same order, so the same bits as a loop over k, in less time (15 % fewer
 * samples in the fit on S2 with features at 128 cells, where the fit was a
 * quarter of the features' cost). */
static inline void qef_step(const double *p, const double *n, int m, const int idx[3], int k,
                            const double x0[3], double y[3]) {
    double A[3][3] = {{0}}, b[3] = {0};
    for (int i = 0; i < m; ++i) {
        const double *ni = n + 3 * i, *pi = p + 3 * i;
        const double r =
            ni[0] * (pi[0] - x0[0]) + ni[1] * (pi[1] - x0[1]) + ni[2] * (pi[2] - x0[2]);
        for (int a = 0; a < k; ++a) {
            b[a] += ni[idx[a]] * r;
            for (int q = 0; q < k; ++q) A[a][q] += ni[idx[a]] * ni[idx[q]];
        }
    }
    double w[3], V[3][3];
    sym_eigen(A, k, w, V);
    double wmax = 0.0;
    for (int a = 0; a < k; ++a) wmax = fmax(wmax, w[a]);
    for (int a = 0; a < k; ++a) {
        if (!(w[a] > EIG_CUT * wmax) || !(wmax > 0.0)) continue;
        double vb = 0.0;
        for (int q = 0; q < k; ++q) vb += V[q][a] * b[q];
        for (int q = 0; q < k; ++q) y[q] += V[q][a] * vb / w[a];
    }
}

/* Rows a and b of the symmetric S, crossed: a vector S's rows are all
 * orthogonal to (S's null direction) when a and b are independent. */
static inline void row_cross(const double S[3][3], int a, int b, double c[3]) {
    c[0] = S[a][1] * S[b][2] - S[a][2] * S[b][1];
    c[1] = S[a][2] * S[b][0] - S[a][0] * S[b][2];
    c[2] = S[a][0] * S[b][1] - S[a][1] * S[b][0];
}

/* The unit vector v with (A - w I) v = 0 for an eigenvalue w of the
 * symmetric A that is a distance of at least 1e-6 wmax from the others
 * (the largest cross product of two rows of A - w I; its length is the
 * product of the other two eigenvalues' distances to w): 0 when none is. */
static int eigvec(const double A[3][3], double w, double wmax, double v[3]) {
    double S[3][3];
    memcpy(S, A, sizeof S);
    for (int d = 0; d < 3; ++d) S[d][d] -= w;
    double c[3][3], best = 0.0;
    int k = 0;
    row_cross(S, 0, 1, c[0]);
    row_cross(S, 0, 2, c[1]);
    row_cross(S, 1, 2, c[2]);
    for (int i = 0; i < 3; ++i) {
        const double l = c[i][0] * c[i][0] + c[i][1] * c[i][1] + c[i][2] * c[i][2];
        if (l > best) best = l, k = i;
    }
    if (!(best > 1e-12 * wmax * wmax * wmax * wmax)) return 0;
    const double il = 1.0 / sqrt(best);
    for (int d = 0; d < 3; ++d) v[d] = c[k][d] * il;
    return 1;
}

/* y = A^-1 b for the symmetric A (by its cofactors); 0 when A's
 * determinant is not positive. */
static int solve3(const double A[3][3], const double b[3], double y[3]) {
    const double c00 = A[1][1] * A[2][2] - A[1][2] * A[1][2],
                 c01 = A[0][2] * A[1][2] - A[0][1] * A[2][2],
                 c02 = A[0][1] * A[1][2] - A[0][2] * A[1][1],
                 c11 = A[0][0] * A[2][2] - A[0][2] * A[0][2],
                 c12 = A[0][1] * A[0][2] - A[0][0] * A[1][2],
                 c22 = A[0][0] * A[1][1] - A[0][1] * A[0][1];
    const double det = A[0][0] * c00 + A[0][1] * c01 + A[0][2] * c02;
    if (!(det > 0.0) || !isfinite(det)) return 0;
    const double id = 1.0 / det;
    y[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) * id;
    y[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) * id;
    y[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) * id;
    return 1;
}

/* qef_step over all three coordinates, with the eigenvalues of the 3 x 3
 * matrix in closed form (the trigonometric solution of its characteristic
 * cubic) rather than by Jacobi rotations, whose square roots and divisions
 * were most of the fit's time (a fifth of the features' cost on S2): with
 * no eigenvalue under the cut, y = A^-1 b; with the smallest under it,
 * the same solve with that eigenvalue raised to the largest and b's part
 * along its vector taken out (which leaves y with no part along it); with
 * two under it, y along the largest's vector alone. The same y as the
 * rotations' up to rounding. 0 (y untouched) where that is not well
 * determined: a matrix nearly a multiple of the identity, an eigenvalue
 * within 1e-6 of another whose vector is needed; the rotations then. */
static int qef_step3(const double *p, const double *n, int m, const double x0[3], double y[3]) {
    double A[3][3] = {{0}}, b[3] = {0};
    for (int i = 0; i < m; ++i) {
        const double *ni = n + 3 * i, *pi = p + 3 * i;
        const double r =
            ni[0] * (pi[0] - x0[0]) + ni[1] * (pi[1] - x0[1]) + ni[2] * (pi[2] - x0[2]);
        for (int a = 0; a < 3; ++a) {
            b[a] += ni[a] * r;
            for (int q = a; q < 3; ++q) A[a][q] += ni[a] * ni[q];
        }
    }
    A[1][0] = A[0][1];
    A[2][0] = A[0][2];
    A[2][1] = A[1][2];
    const double q = (A[0][0] + A[1][1] + A[2][2]) / 3.0;
    const double d0 = A[0][0] - q, d1 = A[1][1] - q, d2 = A[2][2] - q;
    const double off = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    const double p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off;
    if (!(q > 0.0) || !(p2 > 1e-20 * q * q) || !isfinite(p2)) return 0;
    const double pp = sqrt(p2 / 6.0);
    /* det(A - q I) / (2 pp^3), in [-1, 1] up to rounding */
    const double det = d0 * (d1 * d2 - A[1][2] * A[1][2]) -
                       A[0][1] * (A[0][1] * d2 - A[1][2] * A[0][2]) +
                       A[0][2] * (A[0][1] * A[1][2] - d1 * A[0][2]);
    const double r = fmin(1.0, fmax(-1.0, det / (2.0 * pp * pp * pp)));
    const double phi = acos(r) / 3.0;
    const double w1 = q + 2.0 * pp * cos(phi), w3 = q + 2.0 * pp * cos(phi + 2.0943951023931954923),
                 w2 = 3.0 * q - w1 - w3;
    if (!(w1 > 0.0)) return 0;
    const double cut = EIG_CUT * w1;
    double v[3], z[3];
    if (w3 > cut) return solve3(A, b, y);
    if (w2 > cut) {
        if (!eigvec(A, w3, w1, v)) return 0;
        const double vb = v[0] * b[0] + v[1] * b[1] + v[2] * b[2], up = w1 - w3;
        double B[3][3], c[3];
        for (int a = 0; a < 3; ++a) {
            c[a] = b[a] - vb * v[a];
            for (int e = 0; e < 3; ++e) B[a][e] = A[a][e] + up * v[a] * v[e];
        }
        if (!solve3(B, c, z)) return 0;
        memcpy(y, z, sizeof z);
        return 1;
    }
    if (!eigvec(A, w1, w1, v)) return 0;
    const double vb = (v[0] * b[0] + v[1] * b[1] + v[2] * b[2]) / w1;
    for (int a = 0; a < 3; ++a) y[a] = v[a] * vb;
    return 1;
}

/* The QEF's least-squares point over the free coordinates (free bit d set:
 * x[d] free; the others stay as given in x), starting from the mass point
 * c: x_F = c_F + y (qef_step), x0 = x with c in the free coordinates. */
static void qef_free(const double *p, const double *n, int m, const double c[3], int freem,
                     double x[3]) {
    int idx[3], k = 0;
    for (int d = 0; d < 3; ++d)
        if ((freem >> d) & 1) idx[k++] = d;
    double x0[3];
    for (int d = 0; d < 3; ++d) x0[d] = (freem >> d) & 1 ? c[d] : x[d];
    double y[3] = {0, 0, 0};
    if (k == 3) {
        static const int all[3] = {0, 1, 2};
        if (!qef_step3(p, n, m, x0, y)) qef_step(p, n, m, all, 3, x0, y);
    } else if (k == 2) {
        qef_step(p, n, m, idx, 2, x0, y);
    } else if (k == 1) {
        qef_step(p, n, m, idx, 1, x0, y);
    }
    memcpy(x, x0, sizeof x0);
    for (int a = 0; a < k; ++a) x[idx[a]] += y[a];
}

static double qef_err(const double *p, const double *n, int m, const double x[3]) {
    double e = 0.0;
    for (int i = 0; i < m; ++i) {
        const double *ni = n + 3 * i, *pi = p + 3 * i;
        const double r = ni[0] * (x[0] - pi[0]) + ni[1] * (x[1] - pi[1]) + ni[2] * (x[2] - pi[2]);
        e += r * r;
    }
    return e;
}

int lb__feature_qef(const double *p, const double *n, int m, const double lo[3], const double hi[3],
                    double x[3]) {
    if (m < 2) return 0;
    double c[3] = {0, 0, 0};
    for (int i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) c[d] += p[3 * i + d];
    for (int d = 0; d < 3; ++d) c[d] /= m;
    /* slack: a point on the box within rounding counts as inside */
    double tol[3];
    for (int d = 0; d < 3; ++d) tol[d] = 1e-9 * (hi[d] - lo[d]);
    /* the free minimum inside the box is the global one (most fits) */
    double best[3] = {c[0], c[1], c[2]}, beste = INFINITY;
    qef_free(p, n, m, c, 7, best);
    int in_box = 1;
    for (int d = 0; d < 3; ++d) in_box &= best[d] >= lo[d] - tol[d] && best[d] <= hi[d] + tol[d];
    if (in_box) {
        for (int d = 0; d < 3; ++d) x[d] = fmin(fmax(best[d], lo[d]), hi[d]);
        return 1;
    }
    /* else every face (one coordinate fixed), edge (two) and corner (three)
     * of the box; the first feasible one with the least error wins (a fixed
     * order: deterministic) */
    memcpy(best, c, sizeof best);
    for (int nfix = 1; nfix <= 3; ++nfix) {
        for (int fixm = 0; fixm < 8; ++fixm) {
            const int cnt = (fixm & 1) + ((fixm >> 1) & 1) + ((fixm >> 2) & 1);
            if (cnt != nfix) continue;
            for (int side = 0; side < 8; ++side) {
                if (side & ~fixm) continue; /* side bits only on fixed axes */
                double x2[3];
                for (int d = 0; d < 3; ++d)
                    x2[d] = (fixm >> d) & 1 ? ((side >> d) & 1 ? hi[d] : lo[d]) : c[d];
                qef_free(p, n, m, c, 7 & ~fixm, x2);
                int inside = 1;
                for (int d = 0; d < 3; ++d)
                    inside &= x2[d] >= lo[d] - tol[d] && x2[d] <= hi[d] + tol[d];
                if (!inside) continue;
                const double e = qef_err(p, n, m, x2);
                if (e < beste * (1.0 - 1e-12)) {
                    beste = e;
                    memcpy(best, x2, sizeof best);
                }
            }
        }
    }
    for (int d = 0; d < 3; ++d) x[d] = fmin(fmax(best[d], lo[d]), hi[d]);
    return 1;
}

/* Every triangle t of the ranges tr (ntr pairs: first triangle, count) that
 * the merge recorded for the blocks with feature points, in the mesh's
 * order. */
#define FOR_RANGE_TRIANGLES(t, tr, ntr)                                                            \
    for (size_t r_ = 0; r_ < (ntr); ++r_)                                                          \
        for (size_t t = (tr)[2 * r_]; t < (tr)[2 * r_] + (tr)[2 * r_ + 1]; ++t)

static void tri_normal(const double *P, const uint32_t *t, double nrm[3]) {
    lb__facing(P + 3 * (size_t)t[0], P + 3 * (size_t)t[1], P + 3 * (size_t)t[2], nrm);
}

/* The segments (a, b), a < b, waiting for their second fan triangle,
 * chained by a hash of a; a segment leaves its chain when paired, and its
 * slot takes the next one, so the table holds about the segments between
 * merged blocks and blocks still to come, not all of them (a table of
 * every segment, and two chain heads for every vertex, were 0.8 MB of
 * fresh pages on S2 at 128 cells: a fault each 4 KiB). */
#define NONE UINT32_MAX
typedef struct seg {
    uint32_t a, b; /* its ends, a < b */
    uint32_t next; /* the next segment in the chain, or the next free slot */
    uint32_t t;    /* the fan triangle waiting */
} seg;

static inline uint32_t chain_of(uint32_t v, int shift) {
    return (uint32_t)((v * 0x9E3779B97F4A7C15ull) >> shift);
}

/* Whether the triangles near t (t's fan: a fan's triangles are written one
 * after the other, LB__MAXPOLY at most) join c and d: a flip between
 * their fans leaves a triangle with both in each (the fans' triangles
 * have one feature point each until a flip). */
static int joined(const lb_mesh *M, size_t t, uint32_t c, uint32_t d) {
    const size_t lo = t >= LB__MAXPOLY ? t - LB__MAXPOLY : 0,
                 hi = t + LB__MAXPOLY < M->ntriangles ? t + LB__MAXPOLY : M->ntriangles;
    for (size_t u = lo; u < hi; ++u) {
        const uint32_t *T = M->triangles + 3 * u;
        if ((T[0] == c || T[1] == c || T[2] == c) && (T[0] == d || T[1] == d || T[2] == d))
            return 1;
    }
    return 0;
}

lb_status lb__feature_flips(lb_mesh *M, const uint8_t *feat, const size_t *tr, size_t ntr,
                            lb_error *err) {
    if (!ntr) return LB_OK;
    if (M->ntriangles >= NONE)
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    /* chain heads for a sixteenth of the ranges' triangles, counted from
     * the ranges without a pass over the triangles: a chain's length
     * decides how fast a segment is found, never which */
    size_t ntri = 0;
    for (size_t r = 0; r < ntr; ++r) ntri += tr[2 * r + 1];
    int bits = 6;
    while (((size_t)1 << bits) < ntri / 16) ++bits;
    const size_t nh = (size_t)1 << bits;
    const int shift = 64 - bits;
    uint32_t *head = malloc(nh * sizeof *head);
    size_t cap = 1024, nseg = 0;
    seg *segs = malloc(cap * sizeof *segs);
    if (!head || !segs) {
        free(head);
        free(segs);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    }
    memset(head, 0xff, nh * sizeof *head);
    uint32_t freed = NONE; /* the free slots, chained by next */
    /* in the mesh's order: a triangle is changed only when its pair comes,
     * after both were looked at */
    FOR_RANGE_TRIANGLES(t, tr, ntr) {
        uint32_t *T = M->triangles + 3 * t;
        if ((feat[T[0]] + feat[T[1]] + feat[T[2]]) != 1) continue;
        const int k = feat[T[0]] ? 0 : feat[T[1]] ? 1 : 2;
        const uint32_t a = T[(k + 1) % 3], b = T[(k + 2) % 3];
        const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
        const uint32_t h = chain_of(lo, shift);
        uint32_t i = head[h], *link = &head[h];
        while (i != NONE && (segs[i].a != lo || segs[i].b != hi)) {
            link = &segs[i].next;
            i = segs[i].next;
        }
        if (i == NONE) { /* the first fan triangle on this segment: wait */
            if (freed != NONE) {
                i = freed;
                freed = segs[i].next;
            } else {
                if (nseg == cap) {
                    seg *q = realloc(segs, 2 * cap * sizeof *segs);
                    if (!q) {
                        free(head);
                        free(segs);
                        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
                    }
                    segs = q;
                    cap *= 2;
                }
                i = (uint32_t)nseg++;
            }
            segs[i] = (seg){lo, hi, head[h], (uint32_t)t};
            head[h] = i;
            continue;
        }
        /* the other fan on this segment: triangle (d, b, a); the
         * segment is paired (no third triangle pairs with it) */
        uint32_t *U = M->triangles + 3 * (size_t)segs[i].t;
        *link = segs[i].next;
        segs[i].next = freed;
        freed = i;
        const int kk = feat[U[0]] ? 0 : feat[U[1]] ? 1 : 2;
        const uint32_t c = T[k], d = U[kk];
        if (U[(kk + 1) % 3] != b || U[(kk + 2) % 3] != a || c == d) continue;
        if (joined(M, t, c, d)) continue; /* c and d already joined */
        /* flipped: (c, a, d) and (d, b, c); only where both keep their
         * orientation (no fold) */
        const uint32_t T1[3] = {c, a, d}, T2[3] = {d, b, c};
        double m1[3], m2[3];
        tri_normal(M->positions, T1, m1);
        tri_normal(M->positions, T2, m2);
        /* each new triangle faces the way the surface does at its
         * vertex off the crease (a, b: on the grid edges, with the
         * field's normals) */
        const double *na = M->normals + 3 * (size_t)a, *nb = M->normals + 3 * (size_t)b;
        if (!(m1[0] * na[0] + m1[1] * na[1] + m1[2] * na[2] > 0.0) ||
            !(m2[0] * nb[0] + m2[1] * nb[1] + m2[2] * nb[2] > 0.0))
            continue;
        memcpy(T, T1, sizeof T1);
        memcpy(U, T2, sizeof T2);
    }
    free(head);
    free(segs);
    return LB_OK;
}

/* A fan triangle folds when it faces against the surface at every one of
 * its grid-edge vertices (at least one). */
static int folded(const lb_mesh *M, const uint8_t *feat, size_t t) {
    const uint32_t *T = M->triangles + 3 * t;
    double m[3];
    tri_normal(M->positions, T, m);
    int grid = 0;
    for (int k = 0; k < 3; ++k) {
        if (feat[T[k]]) continue;
        ++grid;
        const double *n = M->normals + 3 * (size_t)T[k];
        if (m[0] * n[0] + m[1] * n[1] + m[2] * n[2] > 0.0) return 0;
    }
    return grid > 0;
}

static int by_index(const void *a, const void *b) {
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The place of v in the ascending list pts of n vertices (v is in it). */
static size_t place_of(const uint32_t *pts, size_t n, uint32_t v) {
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (pts[mid] <= v)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

lb_status lb__feature_unfold(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M, uint8_t *feat,
                             const size_t *tr, size_t ntr, int threads, lb__mscratch *S,
                             lb_error *err) {
    /* the points of folded triangles (feat 2), listed as they are marked
     * (twice as many slots: the second half lists the moving ones later) */
    size_t nb = 0, cap = 0;
    uint32_t *pts = NULL;
    FOR_RANGE_TRIANGLES(t, tr, ntr) {
        const uint32_t *T = M->triangles + 3 * t;
        if (!feat[T[0]] && !feat[T[1]] && !feat[T[2]]) continue; /* no point to move */
        if (!folded(M, feat, t)) continue;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = T[k];
            if (feat[v] != 1) continue;
            if (2 * nb + 2 > cap) {
                cap = cap ? 2 * cap : 64;
                uint32_t *q = realloc(pts, cap * sizeof *pts);
                if (!q) {
                    free(pts);
                    return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
                }
                pts = q;
            }
            feat[v] = 2;
            pts[nb++] = v;
        }
    }
    if (!nb) return LB_OK;
    /* in ascending order (their rows in w) */
    qsort(pts, nb, sizeof *pts, by_index);
    uint32_t *mov = pts + nb;
    double *w = calloc(15 * nb, sizeof *w); /* ring sum, count, points, then eval arrays */
    if (!w) {
        free(pts);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    }
    double *sum = w, *cnt = w + 3 * nb, *x = w + 4 * nb, *y = x + nb, *z = y + nb, *ex = z + nb,
           *ey = ex + nb, *ez = ey + nb, *f = ez + nb, *gx = f + nb, *gy = gx + nb, *gz = gy + nb;
    FOR_RANGE_TRIANGLES(t, tr, ntr) {
        const uint32_t *T = M->triangles + 3 * t;
        for (int a = 0; a < 3; ++a) {
            if (feat[T[a]] != 2) continue;
            const size_t i = place_of(pts, nb, T[a]);
            for (int b = 1; b < 3; ++b)
                for (int d = 0; d < 3; ++d)
                    sum[3 * i + d] += M->positions[3 * (size_t)T[(a + b) % 3] + d];
            cnt[i] += 2.0;
        }
    }
    for (size_t i = 0; i < nb; ++i) {
        x[i] = sum[3 * i] / cnt[i];
        y[i] = sum[3 * i + 1] / cnt[i];
        z[i] = sum[3 * i + 2] / cnt[i];
    }
    const double hmin = fmin(g->h[0], fmin(g->h[1], g->h[2])), tol = 1e-7 * hmin;
    uint8_t *done = (uint8_t *)cnt; /* reuse: 0 moving, 1 on the surface, 2 failed */
    memset(done, 0, nb);
    lb_status s = LB_OK;
    for (int it = 0; it < 8 && !s; ++it) {
        /* the points still moving, evaluated together */
        size_t na = 0;
        for (size_t i = 0; i < nb; ++i)
            if (!done[i]) {
                ex[na] = x[i];
                ey[na] = y[i];
                ez[na] = z[i];
                mov[na++] = (uint32_t)i;
            }
        if (!na) break;
        /* few points: the first thread's scratch, warm from the blocks */
        s = na <= LB__FEW ? lb__eval_few(ev, &S->E, &S->outer, na, ex, ey, ez, f, gx, gy, gz, err)
                          : lb_evaluator_eval(ev, na, ex, ey, ez, f, gx, gy, gz, threads, err);
        for (size_t j = 0; !s && j < na; ++j) {
            const size_t i = mov[j];
            const double X[3] = {x[i], y[i], z[i]}, gf[3] = {gx[j], gy[j], gz[j]};
            double gp[3];
            const double ph = lb__mesh_phi(g, X, f[j], gf, gp);
            const double gl2 = gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2];
            if (!isfinite(ph) || !(gl2 > 0.0) || !isfinite(gl2)) {
                done[i] = 2;
            } else if (fabs(ph) <= tol * sqrt(gl2)) {
                done[i] = 1;
                const double l = sqrt(gl2);
                for (int d = 0; d < 3; ++d) sum[3 * i + d] = gp[d] / l; /* its normal */
            } else if (it == 7 || ph * ph > hmin * hmin * gl2) {
                done[i] = 2;
            } else {
                x[i] -= ph * gp[0] / gl2;
                y[i] -= ph * gp[1] / gl2;
                z[i] -= ph * gp[2] / gl2;
            }
        }
    }
    for (size_t i = 0; i < nb; ++i) {
        const uint32_t v = pts[i];
        feat[v] = 1;
        if (s || done[i] != 1) continue;
        M->positions[3 * v] = x[i];
        M->positions[3 * v + 1] = y[i];
        M->positions[3 * v + 2] = z[i];
        memcpy(M->normals + 3 * v, sum + 3 * i, 3 * sizeof(double));
    }
    free(pts);
    free(w);
    return s;
}
