/* Marching tetrahedra on the Kuhn (Freudenthal) triangulation: the cell
 * method of LB_MESH_TETRAHEDRA (cubes.c is the default).
 *
 * Every cell is split into the six tetrahedra 0 -> e_a -> e_a + e_b -> 7
 * along its main diagonal (corner bits: 1 = +x, 2 = +y, 4 = +z). Every cell
 * uses the same split, so the two cells sharing a face cut it along the same
 * diagonal, and the triangles on both sides meet edge to edge. A node is
 * inside when phi < 0 and outside otherwise (phi = 0 counts as outside), so
 * each tetrahedron has one of three cases: one vertex apart (one triangle),
 * two and two (a quadrilateral, cut along its shorter diagonal after the
 * vertices are placed: extract.c), or no crossing. The linear interpolant on
 * a tetrahedron has no ambiguous case: the surface is the zero set of a
 * piecewise-linear function, a closed 2-manifold.
 *
 * Orientation is decided combinatorially, in exact integers: with the
 * vertices at the edge midpoints (doubled lattice coordinates), the
 * triangle's normal must point from the inside corners towards the outside
 * ones. Moving a vertex along its edge never flips a one-apart triangle
 * (its volume with the apart corner scales by the three edge fractions). */
#include "mesh_internal.h"
#include "../common/kuhn.h"

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

int lb__tetra_cell(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, const double *c, int cfg) {
    for (int t = 0; t < 6; ++t) {
        const uint8_t *tv = LB__KUHN[t];
        int in[4], nin = 0;
        for (int q = 0; q < 4; ++q) nin += in[q] = (cfg >> tv[q]) & 1;
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
            const int64_t id = lb__cell_edge(C, i, j, k, ep[q], eq[q], c);
            if (id < 0) return 0;
            e[q] = (uint32_t)id;
        }
        if (!lb__cell_polygon(C, e, LB__ALL_PAIRS, (uint32_t)ne)) return 0;
    }
    return 1;
}
