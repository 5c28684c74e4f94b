/* Two-level cells (libblend/src/meshing/transition.c): random grids of
 * coarse cells (two fine cells a side), some of them meshed as their eight
 * fine cells by the cube cases, the others by lb__tcell_loops with their
 * edges split where a fine cell is around them and their faces quartered
 * where the cell across is fine. Whatever the levels and the signs, the
 * assembled mesh must be closed, oriented and 2-manifold (every directed
 * edge once, its reverse once, every vertex's triangles one disk), with
 * outward orientation on unions of balls; the library's triangulations must
 * keep their diagonals off the cell's faces; and without splits the cell
 * must give the cube cases' loops. Everything here is computed by the test
 * from the grid: the neighbour rule, the vertex identities (fine-grid node
 * pairs), the fans, the checks. */
#include "testlib.h"

#include <stdlib.h>

#include "../libblend/src/common/splitmix.h"
#include "../libblend/src/meshing/mesh_internal.h"

enum { C = 4, G = 2 * C, NN = G + 1, NNN = NN * NN * NN };

typedef struct grid {
    double v[NNN]; /* node values, > 0 outside (every boundary node) */
    int fine[C * C * C];
    /* the mesh: vertices by fine-node pair (stamp), positions, triangles */
    int *vid;
    unsigned *vstamp, stamp;
    double (*pos)[3];
    int nv, capv;
    uint32_t (*tri)[3];
    int nt, capt;
    /* what was exercised */
    long quartered, split, fans, library_tris, loops;
} grid;

static int node(int x, int y, int z) {
    return (z * NN + y) * NN + x;
}

static void node_xyz(int n, double p[3]) {
    p[0] = n % NN;
    p[1] = n / NN % NN;
    p[2] = n / (NN * NN);
}

static int add_vertex(grid *g, const double p[3]) {
    if (g->nv == g->capv) {
        g->capv = g->capv ? 2 * g->capv : 1024;
        g->pos = realloc(g->pos, sizeof *g->pos * (size_t)g->capv);
        assert_non_null(g->pos);
    }
    for (int d = 0; d < 3; ++d) g->pos[g->nv][d] = p[d];
    return g->nv++;
}

/* the vertex on the crossing between fine nodes a and b (any distance) */
static int vertex(grid *g, int a, int b) {
    assert_true((g->v[a] < 0) != (g->v[b] < 0)); /* only crossings get vertices */
    const size_t key = (size_t)(a < b ? a : b) * NNN + (size_t)(a < b ? b : a);
    if (g->vstamp[key] == g->stamp) return g->vid[key];
    double pa[3], pb[3], p[3];
    node_xyz(a, pa);
    node_xyz(b, pb);
    const double t = g->v[a] / (g->v[a] - g->v[b]);
    for (int d = 0; d < 3; ++d) p[d] = pa[d] + t * (pb[d] - pa[d]);
    g->vstamp[key] = g->stamp;
    return g->vid[key] = add_vertex(g, p);
}

static void add_tri(grid *g, int a, int b, int c) {
    if (g->nt == g->capt) {
        g->capt = g->capt ? 2 * g->capt : 2048;
        g->tri = realloc(g->tri, sizeof *g->tri * (size_t)g->capt);
        assert_non_null(g->tri);
    }
    g->tri[g->nt][0] = (uint32_t)a;
    g->tri[g->nt][1] = (uint32_t)b;
    g->tri[g->nt][2] = (uint32_t)c;
    ++g->nt;
}

/* a loop of n vertices fanned around its mean (a new vertex) */
static void fan(grid *g, const int *v, int n) {
    double m[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) m[d] += g->pos[v[i]][d] / n;
    const int c = add_vertex(g, m);
    for (int i = 0; i < n; ++i) add_tri(g, v[i], v[(i + 1) % n], c);
}

static int fine_at(const grid *g, int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= C || y >= C || z >= C) return 0;
    return g->fine[(z * C + y) * C + x];
}

/* a fine cell by the cube cases; its loops fanned (the test's own
 * triangulation: only the loops' sides are shared with other cells) */
static void fine_cell(grid *g, const lb__mctable *t, int x, int y, int z) {
    int cfg = 0, nodes[8];
    for (int o = 0; o < 8; ++o) {
        nodes[o] = node(x + (o & 1), y + ((o >> 1) & 1), z + ((o >> 2) & 1));
        if (g->v[nodes[o]] < 0) cfg |= 1 << o;
    }
    const lb__mccase *cs = &t->c[cfg];
    int off = 0;
    for (int l = 0; l < cs->nloop; ++l) {
        int v[12];
        for (int q = 0; q < cs->len[l]; ++q) {
            int p, r;
            lb__cube_edge(cs->e[off + q], &p, &r);
            v[q] = vertex(g, nodes[p], nodes[r]);
        }
        fan(g, v, cs->len[l]);
        off += cs->len[l];
    }
}

/* lattice node n of coarse cell (cx, cy, cz): its fine-grid node */
static int lattice_node(int cx, int cy, int cz, int n) {
    return node(2 * cx + n % 3, 2 * cy + n / 3 % 3, 2 * cz + n / 9);
}

/* the face planes (bit 2 d + side) holding lattice nodes a and b, from
 * their coordinates */
static unsigned common_planes(int a, int b) {
    unsigned m = 0;
    const int ca[3] = {a % 3, a / 3 % 3, a / 9}, cb[3] = {b % 3, b / 3 % 3, b / 9};
    for (int d = 0; d < 3; ++d)
        if (ca[d] == cb[d] && ca[d] != 1) m |= 1u << (2 * d + ca[d] / 2);
    return m;
}

static void coarse_cell(grid *g, int cx, int cy, int cz) {
    const int cc[3] = {cx, cy, cz};
    lb__tcell c = {0, 0, 0};
    for (int e = 0; e < 12; ++e) {
        int p, q;
        lb__cube_edge(e, &p, &q);
        const int a = p ^ q; /* the edge's axis bit */
        /* the four coarse cells around the edge */
        int any = 0;
        for (int k = 0; k < 4; ++k) {
            int n[3], j = 0;
            for (int d = 0; d < 3; ++d) {
                n[d] = cc[d];
                if ((1 << d) == a) continue;
                n[d] = cc[d] + ((p >> d) & 1) - ((k >> j++) & 1);
            }
            any |= fine_at(g, n[0], n[1], n[2]);
        }
        if (any) c.split |= (uint16_t)(1u << e);
    }
    for (int f = 0; f < 6; ++f) { /* face f: axis f / 2, side f % 2 */
        int n[3] = {cx, cy, cz};
        n[f / 2] += f % 2 ? 1 : -1;
        if (fine_at(g, n[0], n[1], n[2])) c.quarter |= (uint8_t)(1u << f);
    }
    for (int n = 0; n < LB__TNODES; ++n)
        if (g->v[lattice_node(cx, cy, cz, n)] < 0) c.inside |= 1u << n;
    g->quartered += __builtin_popcount(c.quarter);
    g->split += __builtin_popcount(c.split);
    uint16_t sub[LB__TMAX];
    uint8_t len[LB__TMAX / 3], tri[3 * LB__TMAX];
    int nloop = -1;
    const int total = lb__tcell_loops(&c, sub, len, &nloop);
    assert_true(total >= 0);
    /* every sub-edge a crossing, none twice, none through the body centre */
    for (int s = 0; s < total; ++s) {
        const int a = sub[s] / LB__TNODES, b = sub[s] % LB__TNODES;
        assert_true(a < b && a != 13 && b != 13);
        assert_true(((c.inside >> a) & 1) != ((c.inside >> b) & 1));
        for (int k = 0; k < s; ++k) assert_true(sub[k] != sub[s]);
    }
    for (int l = 0, off = 0; l < nloop; off += len[l++]) {
        const int n = len[l];
        assert_true(n >= 3);
        ++g->loops;
        int v[LB__TMAX];
        for (int i = 0; i < n; ++i)
            v[i] = vertex(g, lattice_node(cx, cy, cz, sub[off + i] / LB__TNODES),
                          lattice_node(cx, cy, cz, sub[off + i] % LB__TNODES));
        double lp[3 * LB__TMAX];
        for (int i = 0; i < n; ++i)
            for (int d = 0; d < 3; ++d) lp[3 * i + d] = g->pos[v[i]][d];
        const int nt = lb__tloop_triangles(sub + off, lp, n, tri);
        if (nt == 0) {
            ++g->fans;
            fan(g, v, n);
            continue;
        }
        assert_int_equal(nt, n - 2);
        const int first = g->nt;
        for (int i = 0; i < nt; ++i) {
            for (int k = 0; k < 3; ++k) {
                const int s = tri[3 * i + k], t = tri[3 * i + (k + 1) % 3];
                assert_true(s < n && t < n);
                const int lo = s < t ? s : t, hi = s < t ? t : s;
                if (hi == lo + 1 || (lo == 0 && hi == n - 1)) continue; /* a side */
                const uint16_t u = sub[off + s], w = sub[off + t];
                const unsigned pu = common_planes(u / LB__TNODES, u % LB__TNODES),
                               pw = common_planes(w / LB__TNODES, w % LB__TNODES);
                assert_int_equal(pu & pw, 0); /* a diagonal off the faces */
            }
            add_tri(g, v[tri[3 * i]], v[tri[3 * i + 1]], v[tri[3 * i + 2]]);
        }
        g->library_tris += nt;
        /* no two triangles of the loop cross (a fold of the triangulation) */
        for (int i = first; i < g->nt; ++i)
            for (int j = i + 1; j < g->nt; ++j)
                assert_false(tris_cross(&g->pos[0][0], g->tri[i], g->tri[j]));
    }
}

static int cmp_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int find(int *p, int i) {
    while (p[i] != i) i = p[i] = p[p[i]];
    return i;
}

/* closed, oriented, 2-manifold; with outward, every component's volume > 0 */
static void check_mesh(const grid *g, int outward) {
    const size_t ne = (size_t)g->nt * 3;
    uint64_t *de = malloc(sizeof *de * (ne ? ne : 1));
    int *next = malloc(sizeof *next * (ne ? ne : 1));
    assert_true(de && next);
    for (int t = 0; t < g->nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = g->tri[t][k], b = g->tri[t][(k + 1) % 3];
            assert_true(a != b);
            de[3 * t + k] = (uint64_t)a << 32 | (uint64_t)b;
        }
    qsort(de, ne, sizeof *de, cmp_u64);
    for (size_t i = 0; i < ne; ++i) {
        if (i) assert_true(de[i] != de[i - 1]); /* each directed edge once */
        const uint64_t r = de[i] << 32 | de[i] >> 32;
        assert_non_null(bsearch(&r, de, ne, sizeof *de, cmp_u64)); /* and its reverse */
    }
    /* each vertex's triangles one disk: following b -> c around vertex a
     * (triangle a, b, c) from any start visits all of them */
    int *count = calloc((size_t)g->nv, sizeof *count), *first = malloc(sizeof *first * g->nv);
    assert_true(count && first);
    for (int v = 0; v < g->nv; ++v) first[v] = -1;
    for (int t = 0; t < g->nt; ++t)
        for (int k = 0; k < 3; ++k) ++count[g->tri[t][k]];
    /* the corner i = (t, k) at vertex a = tri[t][k]: the next corner around
     * a is the one whose outgoing edge is a -> c (c: t's vertex before a) */
    uint64_t *pairs = malloc(sizeof *pairs * (ne ? ne : 1) * 2);
    assert_non_null(pairs);
    for (size_t i = 0; i < ne; ++i) {
        pairs[2 * i] = (uint64_t)g->tri[i / 3][i % 3] << 32 | (uint64_t)g->tri[i / 3][(i + 1) % 3];
        pairs[2 * i + 1] = i;
    }
    qsort(pairs, ne, 2 * sizeof *pairs, cmp_u64); /* by the first word: the edge */
    for (size_t i = 0; i < ne; ++i) {
        const uint32_t a = g->tri[i / 3][i % 3], c = g->tri[i / 3][(i + 2) % 3];
        const uint64_t want = (uint64_t)a << 32 | (uint64_t)c;
        size_t lo = 0, hi = ne;
        while (lo < hi) {
            const size_t m = (lo + hi) / 2;
            if (pairs[2 * m] < want)
                lo = m + 1;
            else
                hi = m;
        }
        assert_true(lo < ne && pairs[2 * lo] == want);
        next[i] = (int)pairs[2 * lo + 1];
    }
    free(pairs);
    for (size_t i = 0; i < ne; ++i) {
        const int a = g->tri[i / 3][i % 3];
        if (first[a] >= 0) continue;
        first[a] = (int)i;
        int steps = 0;
        size_t j = i;
        do {
            j = (size_t)next[j];
            ++steps;
            assert_true(steps <= count[a]);
        } while (j != i);
        assert_int_equal(steps, count[a]); /* one cycle through all of a's triangles */
    }
    if (outward) {
        int *p = malloc(sizeof *p * (g->nv ? g->nv : 1));
        double *vol = calloc((size_t)(g->nv ? g->nv : 1), sizeof *vol);
        assert_true(p && vol);
        for (int v = 0; v < g->nv; ++v) p[v] = v;
        for (int t = 0; t < g->nt; ++t)
            for (int k = 1; k < 3; ++k) p[find(p, (int)g->tri[t][k])] = find(p, (int)g->tri[t][0]);
        for (int t = 0; t < g->nt; ++t) {
            const double *a = g->pos[g->tri[t][0]], *b = g->pos[g->tri[t][1]],
                         *c = g->pos[g->tri[t][2]];
            vol[find(p, g->tri[t][0])] +=
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                 a[2] * (b[0] * c[1] - b[1] * c[0])) /
                6;
        }
        for (int v = 0; v < g->nv; ++v)
            if (find(p, v) == v && count[v]) assert_true(vol[v] > 0);
        free(p);
        free(vol);
    }
    free(de);
    free(next);
    free(count);
    free(first);
}

/* no two triangles of the mesh cross (bounding boxes first) */
static void check_crossings(const grid *g) {
    for (int i = 0; i < g->nt; ++i) {
        double lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            lo[d] = hi[d] = g->pos[g->tri[i][0]][d];
            for (int k = 1; k < 3; ++k) {
                lo[d] = fmin(lo[d], g->pos[g->tri[i][k]][d]);
                hi[d] = fmax(hi[d], g->pos[g->tri[i][k]][d]);
            }
        }
        for (int j = i + 1; j < g->nt; ++j) {
            int apart = 0;
            for (int d = 0; d < 3 && !apart; ++d) {
                const double a = g->pos[g->tri[j][0]][d], b = g->pos[g->tri[j][1]][d],
                             c = g->pos[g->tri[j][2]][d];
                apart = fmax(a, fmax(b, c)) < lo[d] || fmin(a, fmin(b, c)) > hi[d];
            }
            if (!apart) assert_false(tris_cross(&g->pos[0][0], g->tri[i], g->tri[j]));
        }
    }
}

static void fill(grid *g, lb__splitmix *r, int balls) {
    double ctr[4][3], rad[4];
    const int nb = 1 + (int)(lb__splitmix_next(r) % 4);
    for (int b = 0; b < nb; ++b) {
        for (int d = 0; d < 3; ++d) ctr[b][d] = 1 + (G - 2) * lb__splitmix_unit(r);
        rad[b] = 0.4 + 2.5 * lb__splitmix_unit(r);
    }
    const double bias = lb__splitmix_unit(r);
    for (int z = 0; z < NN; ++z)
        for (int y = 0; y < NN; ++y)
            for (int x = 0; x < NN; ++x) {
                double v;
                if (balls) {
                    v = 1e30;
                    for (int b = 0; b < nb; ++b) {
                        const double dx = x - ctr[b][0], dy = y - ctr[b][1], dz = z - ctr[b][2];
                        const double s = sqrt(dx * dx + dy * dy + dz * dz) - rad[b];
                        if (s < v) v = s;
                    }
                    if (v == 0) v = 1e-3; /* zero counts as outside: keep it off the nodes */
                } else {
                    v = lb__splitmix_unit(r) - bias;
                    if (v == 0) v = 0.5;
                }
                if (!x || !y || !z || x == G || y == G || z == G) v = 1; /* closed */
                g->v[node(x, y, z)] = v;
            }
}

static void test_transition_cells(void **state) {
    (void)state;
    lb__mctable t;
    lb__mctable_init(&t);
    grid *g = calloc(1, sizeof *g);
    assert_non_null(g);
    g->vid = malloc(sizeof *g->vid * (size_t)NNN * NNN);
    g->vstamp = calloc((size_t)NNN * NNN, sizeof *g->vstamp);
    assert_true(g->vid && g->vstamp);
    lb__splitmix r = {20261206};
    long tris = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const int balls = trial % 2;
        fill(g, &r, balls);
        const double pf = trial % 7 == 0 ? 0.0 : trial % 7 == 1 ? 1.0 : lb__splitmix_unit(&r);
        for (int i = 0; i < C * C * C; ++i) g->fine[i] = lb__splitmix_unit(&r) < pf;
        ++g->stamp;
        g->nv = g->nt = 0;
        for (int cz = 0; cz < C; ++cz)
            for (int cy = 0; cy < C; ++cy)
                for (int cx = 0; cx < C; ++cx) {
                    if (!fine_at(g, cx, cy, cz)) {
                        coarse_cell(g, cx, cy, cz);
                        continue;
                    }
                    for (int o = 0; o < 8; ++o)
                        fine_cell(g, &t, 2 * cx + (o & 1), 2 * cy + ((o >> 1) & 1),
                                  2 * cz + ((o >> 2) & 1));
                }
        check_mesh(g, balls);
        if (balls) check_crossings(g); /* random signs can cross loops of one cell */
        tris += g->nt;
    }
    /* the cases that matter were met, many times over */
    assert_true(g->quartered > 10000 && g->split > 10000 && g->loops > 10000);
    assert_true(g->library_tris > 10000 && tris > 100000);
    print_message("two-level grids: %ld triangles, %ld coarse loops (%ld by the library's "
                  "triangulation, %ld fans), %ld split edges, %ld quartered faces\n",
                  tris, g->loops, g->library_tris, g->fans, g->split, g->quartered);
    free(g->vid);
    free(g->vstamp);
    free(g->pos);
    free(g->tri);
    free(g);
}

/* Without splits a coarse cell is a cube cell: the same loops as the cube
 * cases (as cyclic sequences), for all 256 corner patterns; and a quartered
 * face without its edges split is refused. */
static void test_transition_unsplit(void **state) {
    (void)state;
    lb__mctable t;
    lb__mctable_init(&t);
    for (int cfg = 0; cfg < 256; ++cfg) {
        lb__tcell c = {0, 0, 0};
        for (int o = 0; o < 8; ++o)
            if ((cfg >> o) & 1)
                c.inside |= 1u << (2 * (o & 1) + 6 * ((o >> 1) & 1) + 18 * (o >> 2));
        uint16_t sub[LB__TMAX];
        uint8_t len[LB__TMAX / 3];
        int nloop;
        const int total = lb__tcell_loops(&c, sub, len, &nloop);
        const lb__mccase *cs = &t.c[cfg];
        assert_int_equal(nloop, cs->nloop);
        int off = 0, want_total = 0;
        for (int l = 0; l < cs->nloop; ++l) want_total += cs->len[l];
        assert_int_equal(total, want_total);
        for (int l = 0; l < cs->nloop; ++l) {
            /* the table's loop l as sub-edges */
            uint16_t w[12];
            for (int q = 0; q < cs->len[l]; ++q) {
                int p, r;
                lb__cube_edge(cs->e[off + q], &p, &r);
                const int a = 2 * (p & 1) + 6 * ((p >> 1) & 1) + 18 * (p >> 2),
                          b = 2 * (r & 1) + 6 * ((r >> 1) & 1) + 18 * (r >> 2);
                w[q] = (uint16_t)(a < b ? a * LB__TNODES + b : b * LB__TNODES + a);
            }
            /* find it among the cell's loops, as a rotation */
            int found = 0;
            for (int m = 0, mo = 0; m < nloop && !found; mo += len[m++]) {
                if (len[m] != cs->len[l]) continue;
                for (int rot = 0; rot < len[m] && !found; ++rot) {
                    int same = 1;
                    for (int q = 0; q < len[m]; ++q) same &= sub[mo + (rot + q) % len[m]] == w[q];
                    found = same;
                }
            }
            assert_true(found);
            off += cs->len[l];
        }
    }
    lb__tcell bad = {0, 1, 0};
    uint16_t sub[LB__TMAX];
    uint8_t len[LB__TMAX / 3];
    int nloop;
    assert_int_equal(lb__tcell_loops(&bad, sub, len, &nloop), -1);
}

int main(void) {
    const struct CMUnitTest all[] = {
        cmocka_unit_test(test_transition_unsplit),
        cmocka_unit_test(test_transition_cells),
    };
    return cmocka_run_group_tests(all, NULL, NULL);
}
