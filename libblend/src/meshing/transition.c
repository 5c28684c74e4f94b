/* Two-level cells: the polygons of a cell twice the grid's cell size whose
 * edges may be split at their midpoints and whose faces may be cut into
 * quarters. This is the cell a coarse-first mesher needs where a coarse cell
 * meets fine ones (docs/meshing.md, Adaptive simplification): a coarse edge
 * is split where any cell around it is fine, a coarse face is quartered
 * where the cell across it is fine, and the samples at midpoints and face
 * centres are the fine grid's nodes.
 *
 * The rule is cubes.c's, applied to the subdivided faces on the fly: each
 * face, or each quarter of a quartered face, is walked counter-clockwise as
 * seen from outside the cell through its corners and the midpoints of its
 * split edges; along the walk a crossing sub-edge (two neighbouring samples
 * on opposite sides) is an entry (outside -> inside) or an exit, and each
 * entry is joined to the next crossing, an exit. The segments chain into
 * loops: every crossing sub-edge lies on exactly two of the cell's (quarter)
 * faces, which walk it in opposite directions, so it is the entry of one and
 * the exit of the other.
 *
 * Why two cells sharing a face draw the same segments on it, whatever their
 * levels: the face's subdivision is the same from both sides (a split edge
 * is split for all four cells around it; a quartered face is each fine
 * cell's whole face on the other side), and walking a face backwards
 * reverses the entries and exits, so "each entry to the next crossing" read
 * from the other side joins the same pairs, in the opposite direction. The
 * closed, oriented 2-manifold argument of cubes.c then carries over; the
 * tests assemble random two-level grids and check it
 * (tests/test_transition.c).
 *
 * A loop of two sub-edges (the two halves of a split edge crossing, their
 * midpoint on the other side of both ends) has no area: it is dropped, and
 * the cells across the two faces holding the edge share the segment. A loop
 * is cut into triangles only along diagonals whose two sub-edges lie on no
 * common face plane of the cell (such a diagonal could be a segment another
 * cell draws on that face), and of those triangulations the one whose worst
 * triangle faces closest to the loop's mean normal (the first one found
 * folded loops over unions of balls); where there is none, or the best one
 * still has a triangle facing backwards, the caller fans the loop around a
 * point inside the cell. Nodes with phi exactly 0 count as outside, as
 * everywhere in the mesher. */
#include "mesh_internal.h"

#include <math.h>
#include <string.h>

/* The corners of the faces counter-clockwise seen from outside (cubes.c's
 * order); corner o is lattice node (2 (o & 1), 2 (o >> 1 & 1), 2 (o >> 2)).
 * From them, as constants: each face's corner nodes, the midpoint nodes of
 * its edges (corner q to q + 1) and those edges' cube numbers. */
#define FACES(X)                                                                                   \
    { X(4, 6, 2, 0), X(1, 3, 7, 5), X(0, 1, 5, 4), X(6, 7, 3, 2), X(2, 3, 1, 0), X(4, 5, 7, 6) }
#define CN(o) LB__TCORNER(o)
#define MID(p, q) ((CN(p) + CN(q)) / 2)
#define EB(p, q) LB__CUBE_EDGE_BETWEEN(p, q)
#define ROW_NODE(a, b, c, d)                                                                       \
    { CN(a), CN(b), CN(c), CN(d) }
#define ROW_MID(a, b, c, d)                                                                        \
    { MID(a, b), MID(b, c), MID(c, d), MID(d, a) }
#define ROW_EDGE(a, b, c, d)                                                                       \
    { EB(a, b), EB(b, c), EB(c, d), EB(d, a) }
static const uint8_t FNODE[6][4] = FACES(ROW_NODE);
static const uint8_t FMID[6][4] = FACES(ROW_MID);
static const uint8_t FEDGE[6][4] = FACES(ROW_EDGE);

static uint16_t sub_key(int a, int b) {
    return (uint16_t)(a < b ? a * LB__TNODES + b : b * LB__TNODES + a);
}

/* The segments found so far: entry sub-edge ein[i] joined to exit eout[i]
 * (every crossing sub-edge is the entry of exactly one (quarter) face). */
typedef struct segs {
    uint16_t ein[LB__TMAX], eout[LB__TMAX];
    int n;
} segs;

/* One (quarter) face walked through nodes w[0..n-1]: its segments. 0 when
 * there are more than a cell can have (cannot happen). */
static int walk(const uint8_t *w, int n, uint32_t inside, segs *S) {
    uint16_t cross[8];
    uint8_t entry[8];
    int m = 0;
    for (int q = 0; q < n; ++q) {
        const int p = w[q], r = w[(q + 1) % n];
        const int pin = (inside >> p) & 1, rin = (inside >> r) & 1;
        if (pin == rin) continue;
        cross[m] = sub_key(p, r);
        entry[m++] = (uint8_t)!pin;
    }
    for (int q = 0; q < m; ++q)
        if (entry[q]) {
            if (S->n == LB__TMAX) return 0;
            S->ein[S->n] = cross[q];
            S->eout[S->n++] = cross[(q + 1) % m];
        }
    return 1;
}

int lb__tcell_loops(const lb__tcell *c, uint16_t *sub, uint8_t *len, int *nloop) {
    segs S;
    S.n = 0;
    *nloop = 0;
    for (int f = 0; f < 6; ++f) {
        uint8_t mid[4];
        for (int q = 0; q < 4; ++q) mid[q] = (c->split >> FEDGE[f][q]) & 1 ? FMID[f][q] : 0xff;
        if ((c->quarter >> f) & 1) {
            const int centre = (FNODE[f][0] + FNODE[f][2]) / 2;
            for (int q = 0; q < 4; ++q)
                if (mid[q] == 0xff) return -1; /* a quartered face needs its edges split */
            for (int q = 0; q < 4; ++q) {
                const uint8_t w[4] = {FNODE[f][q], mid[q], (uint8_t)centre, mid[(q + 3) & 3]};
                if (!walk(w, 4, c->inside, &S)) return -1;
            }
        } else {
            uint8_t w[8];
            int n = 0;
            for (int q = 0; q < 4; ++q) {
                w[n++] = FNODE[f][q];
                if (mid[q] != 0xff) w[n++] = mid[q];
            }
            if (!walk(w, n, c->inside, &S)) return -1;
        }
    }
    /* the segments by entry, ascending (insertion sort: at most 48), so a
     * cell's loops come out the same way every time and each exit's own
     * segment is found by bisection */
    for (int i = 1; i < S.n; ++i)
        for (int j = i; j > 0 && S.ein[j - 1] > S.ein[j]; --j) {
            const uint16_t a = S.ein[j], b = S.eout[j];
            S.ein[j] = S.ein[j - 1];
            S.eout[j] = S.eout[j - 1];
            S.ein[j - 1] = a;
            S.eout[j - 1] = b;
        }
    uint8_t used[LB__TMAX] = {0};
    int total = 0;
    for (int i0 = 0; i0 < S.n; ++i0) {
        if (used[i0]) continue;
        int n = 0, i = i0;
        for (;;) {
            if (used[i] || total + n >= LB__TMAX) return -1; /* cannot happen: tested */
            used[i] = 1;
            sub[total + n++] = S.ein[i];
            const uint16_t next = S.eout[i];
            if (next == S.ein[i0]) break;
            int lo = 0, hi = S.n; /* the segment whose entry is next */
            while (lo < hi) {
                const int m = (lo + hi) / 2;
                if (S.ein[m] < next)
                    lo = m + 1;
                else
                    hi = m;
            }
            if (lo == S.n || S.ein[lo] != next) return -1; /* nor this: every exit enters */
            i = lo;
        }
        if (n < 3) continue; /* two halves of a split edge: no area */
        len[(*nloop)++] = (uint8_t)n;
        total += n;
    }
    return total;
}

/* bit 2 d + side: sub-edge s lies on the face plane of axis d at 0 (side 0)
 * or at 2 (side 1) */
static unsigned planes(uint16_t s) {
    const int a = s / LB__TNODES, b = s % LB__TNODES;
    unsigned m = 0;
    for (int d = 0, div = 1; d < 3; ++d, div *= 3) {
        const int ca = a / div % 3, cb = b / div % 3;
        if (ca == cb && ca != 1) m |= 1u << (2 * d + (ca == 2));
    }
    return m;
}

/* the cosine between triangle (a, k, b)'s normal and N (its length nl), as
 * the search below compares it (-1 for a triangle without area) */
static float tri_cos(const double *pos, int a, int k, int b, const double N[3], double nl) {
    double t[3];
    lb__facing(pos + 3 * a, pos + 3 * k, pos + 3 * b, t);
    const double tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    return tl > 0 ? (float)((t[0] * N[0] + t[1] * N[1] + t[2] * N[2]) / (tl * nl)) : -1.0f;
}

int lb__tloop_triangles(const uint16_t *s, const double *pos, int n, uint8_t *tri) {
    if (n < 3 || n > LB__TMAX) return 0;
    unsigned pl[LB__TMAX];
    for (int i = 0; i < n; ++i) pl[i] = planes(s[i]);
    /* the loop's mean normal (Newell's sum: twice the vector area) */
    double N[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
        const double *p = pos + 3 * i, *q = pos + 3 * ((i + 1) % n);
        N[0] += (p[1] - q[1]) * (p[2] + q[2]);
        N[1] += (p[2] - q[2]) * (p[0] + q[0]);
        N[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    const double nl = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    if (!(nl > 0)) return 0;
    if (n == 3) { /* the one triangulation: what the search below finds */
        double t[3];
        lb__facing(pos, pos + 3, pos + 6, t);
        if (!(t[0] * N[0] + t[1] * N[1] + t[2] * N[2] > 0)) return 0;
        tri[0] = 0;
        tri[1] = 1;
        tri[2] = 2;
        return 1;
    }
    if (n == 4) { /* the search below on four vertices: diagonal 1-3 or 0-2 */
        const float b02 = pl[0] & pl[2] ? -2.0f : tri_cos(pos, 0, 1, 2, N, nl),
                    b13 = pl[1] & pl[3] ? -2.0f : tri_cos(pos, 1, 2, 3, N, nl);
        float best = -2.0f;
        int at = 0;
        for (int k = 1; k <= 2; ++k) { /* triangle (0, k, 3) and the rest's */
            const float rest = k == 1 ? b13 : b02;
            if (rest < -1.5f) continue;
            float c = tri_cos(pos, 0, k, 3, N, nl);
            if (rest < c) c = rest;
            if (c > best) {
                best = c;
                at = k;
            }
        }
        if (!at || !(best > 0)) return 0;
        static const uint8_t T4[2][6] = {{0, 1, 3, 1, 2, 3}, {0, 2, 3, 0, 1, 2}};
        memcpy(tri, T4[at - 1], 6);
        return 2;
    }
    /* best[a][b]: over the triangulations of the sub-polygon a..b whose
     * diagonals keep off the faces, the largest smallest cosine between a
     * triangle's normal and N (2: a side, nothing to cut); at[a][b]: the
     * apex of the triangle on a-b in the best one */
    static const uint8_t NONE = 0xff;
    float best[LB__TMAX][LB__TMAX];
    uint8_t at[LB__TMAX][LB__TMAX];
    for (int a = 0; a < n; ++a) memset(at[a], NONE, (size_t)n);
    for (int a = 0; a + 1 < n; ++a) best[a][a + 1] = 2.0f;
    for (int len = 2; len < n; ++len)
        for (int a = 0; a + len < n; ++a) {
            const int b = a + len;
            best[a][b] = -2.0f;
            const int side = a == 0 && b == n - 1;
            if (!side && (pl[a] & pl[b])) continue;
            for (int k = a + 1; k < b; ++k) {
                if (best[a][k] < -1.5f || best[k][b] < -1.5f) continue;
                float c = tri_cos(pos, a, k, b, N, nl);
                if (best[a][k] < c) c = best[a][k];
                if (best[k][b] < c) c = best[k][b];
                if (c > best[a][b]) {
                    best[a][b] = c;
                    at[a][b] = (uint8_t)k;
                }
            }
        }
    /* none, or one with a triangle facing against the loop: a fan instead */
    if (at[0][n - 1] == NONE || !(best[0][n - 1] > 0)) return 0;
    /* the sub-polygons, depth first (at most n - 2 on the stack) */
    uint8_t stack[2 * LB__TMAX];
    int sp = 0, nt = 0;
    stack[sp++] = 0;
    stack[sp++] = (uint8_t)(n - 1);
    while (sp) {
        const int b = stack[--sp], a = stack[--sp];
        const int k = at[a][b];
        tri[3 * nt] = (uint8_t)a;
        tri[3 * nt + 1] = (uint8_t)k;
        tri[3 * nt + 2] = (uint8_t)b;
        ++nt;
        if (k > a + 1) {
            stack[sp++] = (uint8_t)a;
            stack[sp++] = (uint8_t)k;
        }
        if (b > k + 1) {
            stack[sp++] = (uint8_t)k;
            stack[sp++] = (uint8_t)b;
        }
    }
    return nt;
}
