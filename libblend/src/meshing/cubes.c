/* Cube polygons: the default cell method. Vertices sit on the cell's 12
 * edges only (never on face or body diagonals), about a third of the
 * triangles of the Kuhn split (tetra.c) on the same grid.
 *
 * The cases are built, not typed in: for each of the 256 corner patterns,
 * each of the cell's 6 faces is walked counter-clockwise as seen from
 * outside the cell. Along that walk a crossing edge is an entry (outside ->
 * inside) or an exit; each entry is joined to the next crossing, which is an
 * exit, by one segment across the face. On a face with one crossing pair
 * that is the only choice; on an ambiguous face (its inside corners on a
 * diagonal) it cuts each inside corner off on its own: inside corners that
 * touch only across a face diagonal are separate. The segments of the six
 * faces chain into closed loops (every crossing edge is the exit of one face
 * and the entry of the other face it lies on); each loop is one polygon.
 *
 * Why the mesh is a closed, oriented 2-manifold. A face's segments depend
 * only on the signs of its four corners, so the two cells sharing a face draw
 * the same segments on it, traversed in opposite directions (each walks the
 * face counter-clockwise from its own outside). Every segment is a polygon
 * edge in each of the two cells and in no other polygon: two triangles per
 * face segment, one on each side, with opposite orientations. A polygon is
 * cut into triangles only along diagonals through the cell's interior, never
 * along a segment of a face (lb__mctable_check, run by the tests, proves
 * that every loop of every case has such a triangulation: all do, with at
 * most 7 vertices), so
 * an interior edge belongs to two triangles of one polygon. Around a vertex
 * (a crossing grid edge, shared by four cells) each of the four cells' loops
 * passes through it once, joining the segments on the two faces of that cell
 * that contain the edge: the four fans close into one disk. Where the grid
 * ends the closed mesh is outside on every side (mesher.c's margin). Nodes
 * with phi exactly 0 count as outside, as everywhere in the mesher.
 *
 * Orientation: a segment runs from its entry to its exit, which puts the
 * inside corners on its right as seen from outside the cell, so each loop
 * turns counter-clockwise around the outward normal of the surface. */
#include "mesh_internal.h"

#include <string.h>

/* the faces, corners counter-clockwise as seen from outside the cell */
static const uint8_t FACE[6][4] = {{4, 6, 2, 0}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                   {6, 7, 3, 2}, {2, 3, 1, 0}, {4, 5, 7, 6}};

static int on_face(int e, int f) {
    int hits = 0;
    int p, r;
    lb__cube_edge(e, &p, &r);
    for (int q = 0; q < 4; ++q) hits += FACE[f][q] == p || FACE[f][q] == r;
    return hits == 2;
}

/* Whether loop e[0..n-1] can be cut into triangles along diagonals whose
 * two cube edges share no face (dynamic programming over sub-polygons). */
static int triangulable(const lb__mctable *t, const uint8_t *e, int n) {
    uint8_t ok[LB__MAXPOLY][LB__MAXPOLY];
    memset(ok, 0, sizeof ok);
    for (int len = 1; len < n; ++len)
        for (int a = 0; a + len < n; ++a) {
            const int b = a + len;
            const int edge = len == 1 || (a == 0 && b == n - 1);
            if (!edge && ((t->share[e[a]] >> e[b]) & 1)) continue;
            if (len == 1) {
                ok[a][b] = 1;
                continue;
            }
            for (int k = a + 1; k < b && !ok[a][b]; ++k) ok[a][b] = ok[a][k] && ok[k][b];
        }
    return n == 3 || ok[0][n - 1];
}

void lb__mctable_init(lb__mctable *t) {
    memset(t, 0, sizeof *t);
    for (int a = 0; a < 12; ++a)
        for (int b = 0; b < 12; ++b)
            for (int f = 0; f < 6; ++f)
                if (on_face(a, f) && on_face(b, f)) t->share[a] |= (uint16_t)(1u << b);
    for (int cfg = 0; cfg < 256; ++cfg) {
        int next[12];
        for (int e = 0; e < 12; ++e) next[e] = -1;
        for (int f = 0; f < 6; ++f) {
            int ce[4], entry[4], n = 0;
            for (int q = 0; q < 4; ++q) {
                const int p = FACE[f][q], r = FACE[f][(q + 1) & 3];
                const int pin = (cfg >> p) & 1, rin = (cfg >> r) & 1;
                if (pin == rin) continue;
                ce[n] = LB__CUBE_EDGE_BETWEEN(p, r);
                entry[n++] = !pin;
            }
            for (int q = 0; q < n; ++q)
                if (entry[q]) next[ce[q]] = ce[(q + 1) % n]; /* the next crossing is an exit */
        }
        lb__mccase *c = &t->c[cfg];
        int used = 0, nv = 0;
        for (int s0 = 0; s0 < 12; ++s0) {
            if (next[s0] < 0 || ((used >> s0) & 1)) continue;
            int len = 0;
            for (int e = s0; !((used >> e) & 1) && nv + len < 12; e = next[e]) {
                used |= 1 << e;
                c->e[nv + len++] = (uint8_t)e;
            }
            if (c->nloop < 4) c->len[c->nloop++] = (uint8_t)len; /* at most 4: checked */
            nv += len;
        }
        for (int l = 0, off = 0; l < c->nloop; off += c->len[l++]) {
            const int n = c->len[l];
            for (int a = 0; a < n && n <= LB__MAXPOLY; ++a)
                for (int b = a + 1; b < n; ++b) {
                    const int side = b == a + 1 || (a == 0 && b == n - 1);
                    if (side || !((t->share[c->e[off + a]] >> c->e[off + b]) & 1))
                        c->ok[l] |= (uint64_t)1 << LB__PAIR(a, b);
                }
        }
    }
}

/* Every loop of every case fits a polygon and has a triangulation that keeps
 * off the cell's faces (what the manifold argument above needs); the tests
 * call it (tests/unit/test_mesh.c). */
int lb__mctable_check(const lb__mctable *t) {
    for (int cfg = 0; cfg < 256; ++cfg) {
        const lb__mccase *c = &t->c[cfg];
        int off = 0;
        for (int l = 0; l < c->nloop; ++l) {
            if (c->len[l] < 3 || c->len[l] > LB__MAXPOLY) return 0;
            if (!triangulable(t, c->e + off, c->len[l])) return 0;
            off += c->len[l];
        }
        if ((cfg == 0 || cfg == 255) != (c->nloop == 0)) return 0;
    }
    return 1;
}

int lb__cube_cell(lb__bctx *C, uint32_t i, uint32_t j, uint32_t k, const double *c, int cfg) {
    const lb__mccase *cs = &lb__cell_grid(C)->mc.c[cfg];
    int off = 0;
    for (int l = 0; l < cs->nloop; ++l) {
        const int n = cs->len[l];
        uint32_t v[LB__MAXPOLY];
        for (int q = 0; q < n; ++q) {
            const int e = cs->e[off + q];
            int p, q1;
            lb__cube_edge(e, &p, &q1);
            const int64_t id = lb__cell_edge(C, i, j, k, p, q1, c);
            if (id < 0) return 0;
            v[q] = (uint32_t)id;
        }
        if (!lb__cell_polygon(C, v, cs->ok[l], (uint32_t)n)) return 0;
        off += n;
    }
    return 1;
}
