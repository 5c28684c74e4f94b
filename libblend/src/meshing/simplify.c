/* Adaptive simplification (mesh.h: lb_mesh_options.simplify).
 *
 * The grid gives a flat face as many triangles as a curved one. This pass
 * removes vertices by half-edge collapses (vertex u moves onto a neighbour
 * v, u's triangles follow, the two triangles on edge u-v go) wherever the
 * result stays within the tolerance of the field itself:
 *
 * 1. Kinds. An edge is sharp when its two triangles' normals differ by more
 *    than the feature threshold (LB__FEATURE_COS, 26 degrees), as on the
 *    creases that LB_MESH_FEATURES keeps. A vertex with no sharp edge is
 *    smooth and may move onto any neighbour; one with exactly two is on a
 *    crease and may move only along it, onto one of those two neighbours;
 *    any other vertex (a corner: one or three sharp edges or more; the end
 *    of an open boundary; a vertex of a degenerate triangle) never moves.
 *    When a crease vertex moves, its two crease neighbours become each
 *    other's, so a crease stays a chain of sharp edges: never collapsed
 *    across.
 * 2. Order. Each movable vertex's cheapest move by the quadric error of
 *    Garland and Heckbert (the summed squared distances to the planes of the
 *    triangles merged into the two vertices, area weighted) is kept in a
 *    heap (one per region in a parallel pass: passes below); the cheapest
 *    move is tried first, ties broken by vertex index.
 *    On a flat face every move costs nothing: a small weight on the edge's
 *    squared length makes the short edges go first there, so triangles grow
 *    evenly and each part of a face is sampled a few times, not once per
 *    move (the cube at 128 cells: 16 million samples in index order).
 * 3. Checks, cheapest first; a move that fails one is not made:
 *    - topology: the two vertices share exactly the two neighbours opposite
 *      their edge (the link condition: the mesh stays a closed 2-manifold),
 *      those two keep at least three triangles, v at least three neighbours;
 *    - shape: every moved triangle keeps its orientation (its normal turns
 *      by at most 60 degrees), is not a sliver (area at least 1e-4 of its
 *      longest edge squared) and faces along the field's normal at each of
 *      its vertices whose normal is the field's gradient (not feature
 *      points, whose normal is a mean over a crease);
 *    - both ways: u's own point, on the surface, must lie within the
 *      tolerance of the moved triangles (exact point-triangle distance), so
 *      a part thinner than the tolerance is not cut off at its base by
 *      triangles that pass near its sides;
 *    - flat: when u and its neighbours lie within 1e-6 cells of one plane,
 *      the moved triangles cover exactly the old ones' polygon (same plane,
 *      none turned over), whose points were checked when they were made:
 *      nothing more to check;
 *    - the field: every moved triangle is sampled at most a cell apart, on
 *      a barycentric lattice or, a thin one, in rows along its longest edge
 *      (triangle_samples; at most 64 steps along an edge or a row and 64
 *      rows, so a triangle longer than 64 cells is sampled more coarsely),
 *      a coarse pass of 3 steps first, and each sample's distance estimate
 *      |phi_c| / |grad phi_c| must be within the tolerance; phi_c includes
 *      the region's cap. The samples are evaluated under the plan of a
 *      window (a box of 8 cells a side, one every 4 cells on each axis,
 *      made by one interval pass and kept) narrowed to the triangles' box,
 *      when they fit in one; otherwise under their own box's plan.
 *    A move that failed its shape or field check is not checked again while
 *    u's ring is unchanged (those checks see nothing else). A vertex whose
 *    every move fails waits until a neighbour moves; when every move failed
 *    those checks, until its own ring changes.
 * 4. The survivors keep their positions and normals (every vertex is still
 *    a point of the original mesh, on the surface) and their order; the
 *    triangles keep theirs.
 *
 * On up to the caller's thread count, in passes over regions of the grid
 * that depend on the grid alone (passes below), each region's moves in a
 * fixed order, so the output does not depend on the thread count. The cost
 * grows with the number of moves tried times the samples of their
 * triangles: bounded by the 64-step caps per triangle edge, rows and
 * row. */
#include "mesh_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define NONE UINT32_MAX
#define SMOOTH 0
#define CREASE 1
#define FIXED 2
#define GONE 3
#define MAXSTEPS 64     /* samples' steps along a triangle's edge, rows or a row at most */
#define ROWS 0.5        /* the rows' spacing (triangle_samples), in h */
#define TURN_COS 0.5    /* a moved triangle's normal turns by at most 60 degrees */
#define SLIVER 1e-4     /* a moved triangle's area over its longest edge squared, at least */
#define CHECK_EVERY 256 /* vertices tried between looks at the cancel flag */
/* bytes the pass needs at most per triangle (corner lists, the edges before
 * and after sorting and the facings of the setup) and per vertex (lists'
 * ends, kind, crease neighbours, quadric, stamps, marks, failed moves, the
 * sort's counts, its heap entry's cost and target, its region, lock and
 * place in a pass's lists, and its heap entries: one, then about ten per
 * move nearby), for the memory cap (and per worker WSLOTS window plans,
 * each at most the tape's size) */
#define TRI_BYTES 144
#define VERTEX_BYTES 322
#define FLAT 1e-6 /* cells: a ring this close to one plane is flat */
#define TIE 1e-4  /* the edge length's weight in a move's cost (h^2 len^2) */
/* The plans of windows: boxes of 2 WSTEP cells a side, WSTEP cells apart on
 * each axis, so that any box up to WSTEP cells a side lies in one of them;
 * WSLOTS of them kept (a direct-mapped cache) */
#define WSTEP 4
#define WSLOTS 4096

typedef struct hent {
    double cost;
    uint32_t v, stamp;
} hent;

typedef struct vec32 {
    uint32_t *a;
    size_t n, cap;
} vec32;

typedef struct simp {
    const lb_evaluator *ev;
    const lb__grid *g;
    lb_mesh *M;
    const uint8_t *feat;
    double tol, h;
    uint32_t *next;        /* per corner: the next corner of its vertex (NONE: the last) */
    uint32_t *head, *tail; /* per vertex: its corner list */
    uint8_t *tdead;        /* per triangle */
    uint8_t *kind;         /* per vertex: SMOOTH, CREASE, FIXED, GONE */
    uint32_t *sn;          /* 2 per vertex: a crease vertex's neighbours along the crease */
    double *Q;             /* 10 per vertex: the quadric */
    uint32_t *stamp;       /* per vertex: heap entries with another stamp are stale */
    hent *heap;
    size_t nh, hcap;
    vec32 ru, rv, nu, nv, tmp; /* scratch: rings and neighbour sets */
    double *s;                 /* samples: 7 arrays of scap */
    size_t scap;
    lb_status est; /* the evaluator's failure */
    /* the evaluation of a move's samples: lb__eval_few's registers and
     * plans, allocated once (lb_evaluator_eval's own for every move, the
     * same bits, were 12 % of the simplification's instructions on S2 at
     * 128 cells); few: both allocated */
    lb__boxeval E;
    lb__plan outer;
    int few;
    uint64_t *mark; /* per vertex (fresh) */
    uint64_t tok;   /* 64 bits: never wraps */
    /* a parallel pass (passes below): the region of each vertex, whether a
     * vertex has a neighbour in another region (locked), the region this
     * worker is on; region NULL: the whole mesh, one thread */
    const uint32_t *region;
    const uint8_t *lock;
    uint32_t own;
    vec32 cand;   /* the moves of the vertex tried, in order of cost */
    double *cost; /* and their costs */
    size_t ccap;
    /* per vertex: the moves onto its neighbours (bit i: the i-th of its
     * ring's neighbours, in ring order) that failed a check of shape or
     * field; kept while its ring is unchanged, since those checks see
     * nothing else: tried again, they would fail again */
    uint32_t *failed;
    uint8_t *stuck; /* per vertex: every move failed so (not queued again) */
    double *hcost;  /* per vertex: the cost of its entry in the heap (NAN: none) */
    uint32_t *htgt; /* per vertex with an entry: a move of that cost (its target) */
    /* window plans: slot k holds the window wkey[k] (UINT64_MAX: none) */
    uint64_t *wkey;
    lb__cplan *wplan;
    double sbox[6]; /* the moved triangles' box (near_surface): min, max */
} simp;

static lb_status nomem(lb_error *err) {
    return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
}

static int push32(vec32 *v, uint32_t x) {
    if (v->n == v->cap) {
        const size_t c = v->cap ? 2 * v->cap : 32;
        uint32_t *a = realloc(v->a, c * sizeof *a);
        if (!a) return 0;
        v->a = a;
        v->cap = c;
    }
    v->a[v->n++] = x;
    return 1;
}

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double *a) {
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static const double *P(const simp *S, uint32_t v) {
    return S->M->positions + 3 * (size_t)v;
}

/* ---- heap of (cost, vertex), the cheapest first, ties by vertex index */

static int hless(const hent *a, const hent *b) {
    return a->cost < b->cost || (a->cost == b->cost && a->v < b->v);
}

static int hpush(simp *S, double cost, uint32_t v) {
    if (S->nh == S->hcap) {
        const size_t c = S->hcap ? 2 * S->hcap : 1024;
        hent *h = realloc(S->heap, c * sizeof *h);
        if (!h) return 0;
        S->heap = h;
        S->hcap = c;
    }
    size_t i = S->nh++;
    const hent e = {cost, v, S->stamp[v]};
    while (i > 0) {
        const size_t p = (i - 1) / 2;
        if (!hless(&e, &S->heap[p])) break;
        S->heap[i] = S->heap[p];
        i = p;
    }
    S->heap[i] = e;
    return 1;
}

static hent hpop(simp *S) {
    const hent top = S->heap[0], e = S->heap[--S->nh];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= S->nh) break;
        if (c + 1 < S->nh && hless(&S->heap[c + 1], &S->heap[c])) ++c;
        if (!hless(&S->heap[c], &e)) break;
        S->heap[i] = S->heap[c];
        i = c;
    }
    if (S->nh) S->heap[i] = e;
    return top;
}

/* ---- rings */

/* The live triangles at u into r (dead ones leave u's list on the way). */
static int ring(simp *S, uint32_t u, vec32 *r) {
    r->n = 0;
    uint32_t prev = NONE;
    for (uint32_t c = S->head[u]; c != NONE;) {
        const uint32_t nx = S->next[c];
        if (S->tdead[c / 3]) {
            if (prev == NONE)
                S->head[u] = nx;
            else
                S->next[prev] = nx;
            if (S->tail[u] == c) S->tail[u] = prev;
        } else {
            if (!push32(r, c / 3)) return 0;
            prev = c;
        }
        c = nx;
    }
    return 1;
}

/* A fresh mark: vertices w with mark[w] == the result are marked. */
static uint64_t fresh(simp *S) {
    return ++S->tok;
}

/* Whether w is this worker's to read and write (its region's, in a
 * parallel pass): what other workers touch is never read, so a pass's
 * result does not depend on their progress. */
static int mine(const simp *S, uint32_t w) {
    return !S->region || S->region[w] == S->own;
}

/* Whether w may move in this pass: its own and every neighbour in its
 * region. */
static int movable_here(const simp *S, uint32_t w) {
    return !S->region || (S->region[w] == S->own && !S->lock[w]);
}

/* The distinct vertices other than u of the triangles r, in ring order. */
static int neighbours(simp *S, uint32_t u, const vec32 *r, vec32 *n) {
    n->n = 0;
    const uint64_t m = fresh(S);
    for (size_t i = 0; i < r->n; ++i)
        for (int k = 0; k < 3; ++k) {
            const uint32_t w = S->M->triangles[3 * (size_t)r->a[i] + k];
            if (w == u) continue;
            if (mine(S, w)) {
                if (S->mark[w] == m) continue;
                S->mark[w] = m;
            } else { /* another region's (a locked vertex's few): by search */
                size_t j = 0;
                while (j < n->n && n->a[j] != w) ++j;
                if (j < n->n) continue;
            }
            if (!push32(n, w)) return 0;
        }
    return 1;
}

/* Mark the vertices of n that are this worker's (with a fresh mark,
 * returned): only those are ever looked up. */
static uint64_t mark_all(simp *S, const vec32 *n) {
    const uint64_t m = fresh(S);
    for (size_t i = 0; i < n->n; ++i)
        if (mine(S, n->a[i])) S->mark[n->a[i]] = m;
    return m;
}

/* ---- costs */

static double qcost(const double *Q, const double *x) {
    return Q[0] * x[0] * x[0] + 2 * Q[1] * x[0] * x[1] + 2 * Q[2] * x[0] * x[2] + 2 * Q[3] * x[0] +
           Q[4] * x[1] * x[1] + 2 * Q[5] * x[1] * x[2] + 2 * Q[6] * x[1] + Q[7] * x[2] * x[2] +
           2 * Q[8] * x[2] + Q[9];
}

/* u moved onto v by the quadrics of both. */
static double move_cost(const simp *S, uint32_t u, uint32_t v) {
    double Q[10];
    for (int i = 0; i < 10; ++i) Q[i] = S->Q[10 * (size_t)u + i] + S->Q[10 * (size_t)v + i];
    const double c = qcost(Q, P(S, v));
    const double *a = P(S, u), *b = P(S, v);
    const double e2 = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                      (a[2] - b[2]) * (a[2] - b[2]);
    /* ties (flat regions: no quadric error) go to the shorter edge, so the
     * triangles grow evenly and each region is sampled few times over */
    return (c > 0.0 ? c : 0.0) + TIE * S->h * S->h * e2;
}

/* u's moves (its crease neighbours, or every neighbour of a smooth vertex)
 * into t, the cheapest one's cost and target (the first of that cost); 0
 * when u cannot move (or memory). */
static int moves(simp *S, uint32_t u, vec32 *t, double *best, uint32_t *target) {
    t->n = 0;
    if (S->kind[u] == CREASE) {
        if (!push32(t, S->sn[2 * (size_t)u]) || !push32(t, S->sn[2 * (size_t)u + 1])) return 0;
    } else if (S->kind[u] == SMOOTH) {
        if (!ring(S, u, &S->ru) || !neighbours(S, u, &S->ru, t)) return 0;
    } else {
        return 0;
    }
    *best = INFINITY;
    for (size_t i = 0; i < t->n; ++i) {
        const double c = move_cost(S, u, t->a[i]);
        if (c < *best) {
            *best = c;
            *target = t->a[i];
        }
    }
    return t->n > 0;
}

/* u's heap entry at cost c (target x): an entry of the same cost stands
 * (the same place in the heap's order as a new one would take). */
static int enqueue(simp *S, uint32_t u, double c, uint32_t x) {
    S->htgt[u] = x;
    if (S->hcost[u] == c) return 1;
    ++S->stamp[u];
    S->hcost[u] = c;
    return hpush(S, c, u);
}

static int requeue(simp *S, uint32_t u) {
    double c;
    uint32_t x = NONE;
    if (!movable_here(S, u) || S->stuck[u] || !moves(S, u, &S->tmp, &c, &x)) {
        ++S->stamp[u]; /* its entry goes */
        S->hcost[u] = NAN;
        return 1;
    }
    return enqueue(S, u, c, x);
}

/* w's entry after u moved onto v, w a neighbour of either: of w's moves
 * only the one onto u went and the one onto v is new or costs more (v's
 * quadric took u's); the others cost what they did (their quadrics and
 * points are unchanged). So when w's entry stands and its move is onto
 * neither, its cheapest move is that one or the one onto v: the same
 * minimum as requeue() finds walking w's ring. Otherwise requeue(). */
static int requeue_near(simp *S, uint32_t w, uint32_t u, uint32_t v) {
    if (!movable_here(S, w) || S->stuck[w] || isnan(S->hcost[w]) || S->htgt[w] == u ||
        S->htgt[w] == v)
        return requeue(S, w);
    if (S->kind[w] == CREASE) { /* moves along the crease only */
        const uint32_t *s = S->sn + 2 * (size_t)w;
        if (s[0] != v && s[1] != v) return 1; /* neither changed */
    } else if (S->kind[w] != SMOOTH) {
        return requeue(S, w);
    }
    /* a smooth w is a neighbour of v now: it shares a live triangle with v
     * (a triangle of u's that had no v, or one of v's that had no u) */
    const double c = move_cost(S, w, v);
    return c < S->hcost[w] ? enqueue(S, w, c, v) : 1;
}

/* ---- checks */

static int samples_room(simp *S, size_t n) {
    if (n <= S->scap) return 1;
    free(S->s);
    S->s = malloc(7 * n * sizeof *S->s);
    S->scap = S->s ? n : 0;
    return S->s != NULL;
}

/* Steps of length at most h over length l: 2 to maxn (*coarser set when h
 * apart would need more). */
static int steps(double l, double h, int maxn, int *coarser) {
    const double n = ceil(l / h);
    if (!(n <= maxn)) {
        *coarser = 1;
        return maxn;
    }
    return n >= 2.0 ? (int)n : 2;
}

/* The samples of triangle q: a barycentric lattice of n steps along each
 * edge, n the longest edge over h (every point of the triangle within
 * h / sqrt(3), 0.58 h, of a sample: its small triangles' sides are at most
 * h); or, for a thin triangle (its m rows fewer than half n), rows
 * parallel to its longest edge AB, from AB towards the opposite corner C,
 * at most ROWS h apart (C's height over AB divided into m steps), each
 * divided into steps of at most ROWS h. Angles A and B are acute (AB is
 * the longest side), so each row lies over the next: every point is at
 * most ROWS h above a row and ROWS h / 2 along it from a sample, within
 * 0.56 h, no farther than on the lattice; and a long thin triangle costs
 * samples in proportion to its area, where the lattice would take its
 * longest edge's length squared. At most maxn steps along an edge, rows or
 * along a row (*coarser set when the layout taken needed more). The
 * corners are left out (points of the mesh, on the surface). Into x, y, z
 * unless x is NULL; returns how many. */
static size_t triangle_samples(const double *const q[3], double h, int maxn, int *coarser,
                               double *x, double *y, double *z) {
    int k = 0;
    double L2 = -1.0;
    for (int i = 0; i < 3; ++i) {
        const double *a = q[i], *b = q[(i + 1) % 3];
        const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2 = dot3(e, e);
        if (e2 > L2) {
            L2 = e2;
            k = i;
        }
    }
    const double *A = q[k], *B = q[(k + 1) % 3], *C = q[(k + 2) % 3];
    const double L = sqrt(L2), hr = ROWS * h;
    int lc = 0, rc = 0; /* each layout's coarser */
    const int n = steps(L, h, maxn, &lc);
    int m = n; /* at least 2 rows: never fewer than half of n <= 4 */
    if (n > 4) {
        double cr[3];
        lb__facing(A, B, C, cr);
        m = steps(norm3(cr) / L, hr, maxn, &rc);
    }
    size_t c = 0;
    if (2 * m >= n) { /* not thin: the lattice */
        if (lc) *coarser = 1;
        for (int a = 0; a <= n; ++a)
            for (int b = 0; a + b <= n; ++b) {
                if ((a == 0 && b == 0) || a == n || b == n) continue;
                if (x) {
                    const double wb = (double)a / n, wc = (double)b / n, wa = 1.0 - wb - wc;
                    x[c] = wa * q[0][0] + wb * q[1][0] + wc * q[2][0];
                    y[c] = wa * q[0][1] + wb * q[1][1] + wc * q[2][1];
                    z[c] = wa * q[0][2] + wb * q[1][2] + wc * q[2][2];
                }
                ++c;
            }
        return c;
    }
    for (int j = 0; j < m; ++j) { /* row m is C alone */
        const double t = (double)j / m;
        const int nr = steps((1.0 - t) * L, hr, maxn, &rc);
        for (int i = 0; i <= nr; ++i) {
            if (j == 0 && (i == 0 || i == nr)) continue; /* A, B */
            if (x) {
                const double s = (double)i / nr;
                double p[3];
                for (int d = 0; d < 3; ++d) {
                    const double l = A[d] + t * (C[d] - A[d]), r = B[d] + t * (C[d] - B[d]);
                    p[d] = l + s * (r - l);
                }
                x[c] = p[0];
                y[c] = p[1];
                z[c] = p[2];
            }
            ++c;
        }
    }
    if (rc) *coarser = 1;
    return c;
}

/* The plan of the window holding the box S->sbox (the moved triangles'),
 * made once for the window and kept in its slot (an interval pass over the
 * window instead of one over the samples' box for every move: the same
 * values, since a plan only leaves out what provably changes nothing in
 * its box); NULL when the box spans more than WSTEP cells on an axis or
 * when memory is short (S->est set then: LB_ERR_NO_MEMORY). */
static const lb__cplan *window_plan(simp *S, lb_error *err) {
    uint64_t key = 0;
    double bmin[3], bmax[3];
    for (int d = 0; d < 3; ++d) {
        const double lo = S->sbox[d], hi = S->sbox[3 + d];
        const double step = WSTEP * S->g->h[d], pad = 1e-9 * S->g->h[d];
        double w = floor((lo - S->g->origin[d]) / step);
        /* the window from w: [w, w + 2) steps, the box inside it by a
         * margin (one step lower where rounding put lo at its edge), within
         * 2^20 windows of the origin (the grid has at most 8192 cells a
         * side) */
        if (!(S->g->origin[d] + w * step <= lo - pad)) w -= 1.0;
        if (!(w >= -1.0 && w < 1048575.0)) return NULL;
        bmin[d] = S->g->origin[d] + w * step;
        bmax[d] = bmin[d] + 2.0 * step;
        if (!(bmin[d] <= lo - pad && hi <= bmax[d] - pad)) return NULL;
        key |= (uint64_t)(w + 1.0) << (21 * d);
    }
    const size_t k = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 52) % WSLOTS;
    if (S->wkey[k] == key) return &S->wplan[k];
    if (S->wkey[k] != UINT64_MAX) lb__cplan_free(&S->wplan[k]);
    S->wkey[k] = UINT64_MAX;
    double bc[3], br[3];
    lb__box_centre(bmin, bmax, bc, br);
    lb__bounds_pass(S->ev, bc, br, S->E.iv, &S->outer);
    if ((S->est = lb__cplan_make(S->ev, &S->outer, &S->wplan[k], err))) return NULL;
    S->wkey[k] = key;
    return &S->wplan[k];
}

/* The triangles of u's ring (S->ru) that u's move onto v keeps, with v for
 * u: every sample of theirs (triangle_samples, at most maxn steps a row and
 * rows a triangle) within the tolerance of the surface, by one evaluation:
 * 1, else 0; -1 when out of memory, -2 when the evaluator fails (err set).
 * *coarser: some triangle needed more than maxn. */
static int near_surface(simp *S, uint32_t u, uint32_t v, int maxn, int *coarser, lb_error *err) {
    *coarser = 0;
    const uint32_t *T = S->M->triangles;
    size_t total = 0;
    for (int d = 0; d < 3; ++d) {
        S->sbox[d] = INFINITY;
        S->sbox[3 + d] = -INFINITY;
    }
    for (int pass = 0; pass < 2; ++pass) {
        size_t m = 0;
        for (size_t i = 0; i < S->ru.n; ++i) {
            const uint32_t *t = T + 3 * (size_t)S->ru.a[i];
            if (t[0] == v || t[1] == v || t[2] == v) continue;
            const double *q[3];
            for (int k = 0; k < 3; ++k) q[k] = P(S, t[k] == u ? v : t[k]);
            if (pass == 0) {
                total += triangle_samples(q, S->h, maxn, coarser, NULL, NULL, NULL);
                for (int k = 0; k < 3; ++k) /* points are finite: no fmin's NaN rule, a call */
                    for (int d = 0; d < 3; ++d) {
                        if (q[k][d] < S->sbox[d]) S->sbox[d] = q[k][d];
                        if (q[k][d] > S->sbox[3 + d]) S->sbox[3 + d] = q[k][d];
                    }
                continue;
            }
            double *x = S->s, *y = x + S->scap, *z = y + S->scap;
            m += triangle_samples(q, S->h, maxn, coarser, x + m, y + m, z + m);
        }
        if (pass == 0 && !samples_room(S, total)) return -1;
    }
    double *x = S->s, *y = x + S->scap, *z = y + S->scap, *f = z + S->scap, *gx = f + S->scap,
           *gy = gx + S->scap, *gz = gy + S->scap;
    S->est = LB_OK;
    const lb__cplan *C = S->few ? window_plan(S, err) : NULL;
    if (S->est) return -2;
    if (C) { /* the window's plan narrowed to the triangles' box */
        lb__boxeval_load(S->ev, C, &S->E);
        lb__plan_load(S->ev, &S->E.plan, &S->outer);
        lb__boxeval_narrow(S->ev, &S->E, &S->outer, S->sbox, S->sbox + 3);
        S->est = lb__boxeval_run(S->ev, &S->E, total, x, y, z, f, gx, gy, gz, err);
    } else {
        S->est = S->few && total <= LB__FEW
                     ? lb__eval_few(S->ev, &S->E, &S->outer, total, x, y, z, f, gx, gy, gz, err)
                     : lb_evaluator_eval(S->ev, total, x, y, z, f, gx, gy, gz, 1, err);
    }
    if (S->est != LB_OK) return -2;
    for (size_t i = 0; i < total; ++i) {
        const double X[3] = {x[i], y[i], z[i]}, gf[3] = {gx[i], gy[i], gz[i]};
        double gp[3];
        const double ph = lb__mesh_phi(S->g, X, f[i], gf, gp);
        const double gl = norm3(gp);
        if (!isfinite(ph) || !(gl > 0.0) || !isfinite(gl) || !(fabs(ph) <= S->tol * gl)) return 0;
    }
    return 1;
}

/* The squared distance from x to triangle (a, b, c): the nearest point by
 * the region of the triangle's plane x projects into (a corner, an edge or
 * the inside), from the barycentric signs. */
static double point_triangle2(const double *x, const double *a, const double *b, const double *c) {
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
                 ax[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
    double w[3]; /* weights of a, b, c of the nearest point */
    const double d1 = dot3(ab, ax), d2 = dot3(ac, ax);
    const double bx[3] = {x[0] - b[0], x[1] - b[1], x[2] - b[2]},
                 cx[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    const double d3 = dot3(ab, bx), d4 = dot3(ac, bx), d5 = dot3(ab, cx), d6 = dot3(ac, cx);
    const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0 && d2 <= 0) { /* corner a */
        w[0] = 1, w[1] = 0, w[2] = 0;
    } else if (d3 >= 0 && d4 <= d3) { /* corner b */
        w[0] = 0, w[1] = 1, w[2] = 0;
    } else if (d6 >= 0 && d5 <= d6) { /* corner c */
        w[0] = 0, w[1] = 0, w[2] = 1;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) { /* edge ab */
        const double t = d1 / (d1 - d3);
        w[0] = 1 - t, w[1] = t, w[2] = 0;
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) { /* edge ac */
        const double t = d2 / (d2 - d6);
        w[0] = 1 - t, w[1] = 0, w[2] = t;
    } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) { /* edge bc */
        const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[0] = 0, w[1] = 1 - t, w[2] = t;
    } else { /* inside */
        const double den = va + vb + vc;
        w[1] = vb / den, w[2] = vc / den, w[0] = 1 - w[1] - w[2];
    }
    double d = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double y = w[0] * a[k] + w[1] * b[k] + w[2] * c[k] - x[k];
        d += y * y;
    }
    return d;
}

/* u and its neighbours (S->nu) within FLAT cells of one plane, that of u's
 * largest triangle (S->ru). */
static int flat_ring(const simp *S, uint32_t u) {
    double n[3] = {0, 0, 0}, best = 0.0;
    for (size_t i = 0; i < S->ru.n; ++i) {
        const uint32_t *t = S->M->triangles + 3 * (size_t)S->ru.a[i];
        double f[3];
        lb__facing(P(S, t[0]), P(S, t[1]), P(S, t[2]), f);
        const double l = norm3(f);
        if (l > best) {
            best = l;
            for (int d = 0; d < 3; ++d) n[d] = f[d] / l;
        }
    }
    if (!(best > 0.0)) return 0;
    const double *o = P(S, u), eps = FLAT * S->h;
    for (size_t i = 0; i < S->nu.n; ++i) {
        const double *q = P(S, S->nu.a[i]);
        const double d = n[0] * (q[0] - o[0]) + n[1] * (q[1] - o[1]) + n[2] * (q[2] - o[2]);
        if (!(fabs(d) <= eps)) return 0;
    }
    return 1;
}

/* Whether the mesh stays a closed 2-manifold when u moves onto v: 1 yes, 0
 * no, -1 out of memory. S->ru and S->nu hold u's ring and neighbours (the
 * same for every move of u tried); v's go into S->rv and S->nv. */
static int keeps_topology(simp *S, uint32_t u, uint32_t v) {
    const uint32_t *T = S->M->triangles;
    if (!ring(S, v, &S->rv) || !neighbours(S, v, &S->rv, &S->nv)) return -1;
    /* topology: the edge's two triangles and their far vertices */
    uint32_t opp[2];
    int no = 0;
    for (size_t i = 0; i < S->ru.n; ++i) {
        const uint32_t *t = T + 3 * (size_t)S->ru.a[i];
        if (t[0] != v && t[1] != v && t[2] != v) continue;
        if (no == 2) return 0;
        for (int k = 0; k < 3; ++k)
            if (t[k] != u && t[k] != v) opp[no] = t[k];
        ++no;
    }
    if (no != 2 || opp[0] == opp[1]) return 0;
    size_t common = 0;
    const uint64_t m = mark_all(S, &S->nv); /* u's neighbours and opp are this worker's */
    for (size_t i = 0; i < S->nu.n; ++i)
        if (S->mark[S->nu.a[i]] == m) ++common;
    if (common != 2 || S->mark[opp[0]] != m || S->mark[opp[1]] != m) return 0;
    if (S->nu.n + S->nv.n < 4 + 3) return 0;
    for (int k = 0; k < 2; ++k) {
        if (!ring(S, opp[k], &S->tmp)) return -1;
        if (S->tmp.n < 4) return 0;
    }
    return 1;
}

/* Whether the triangles of u's ring (S->ru; neighbours S->nu) moved with u
 * onto v keep their shape and stay within the tolerance of the field: 1
 * yes, 0 no, -1 out of memory, -2 the evaluator failed. Sees only u's ring
 * and v's point and normal. */
static int keeps_shape(simp *S, uint32_t u, uint32_t v, lb_error *err) {
    const uint32_t *T = S->M->triangles;
    /* shape */
    const double *pv = P(S, v);
    for (size_t i = 0; i < S->ru.n; ++i) {
        const uint32_t *t = T + 3 * (size_t)S->ru.a[i];
        if (t[0] == v || t[1] == v || t[2] == v) continue;
        const double *o[3], *q[3];
        for (int k = 0; k < 3; ++k) {
            o[k] = P(S, t[k]);
            q[k] = t[k] == u ? pv : o[k];
        }
        double n0[3], n1[3];
        lb__facing(o[0], o[1], o[2], n0);
        lb__facing(q[0], q[1], q[2], n1);
        const double l0 = norm3(n0), l1 = norm3(n1);
        double L2 = 0.0;
        for (int k = 0; k < 3; ++k) {
            const double *x = q[k], *y = q[(k + 1) % 3];
            const double e2 = (y[0] - x[0]) * (y[0] - x[0]) + (y[1] - x[1]) * (y[1] - x[1]) +
                              (y[2] - x[2]) * (y[2] - x[2]);
            if (e2 > L2) L2 = e2;
        }
        if (!(l1 >= 2.0 * SLIVER * L2) || !(l0 > 0.0)) return 0;
        if ((n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2]) < TURN_COS * l0 * l1) return 0;
        for (int k = 0; k < 3; ++k) {
            const uint32_t w = t[k] == u ? v : t[k];
            if (S->feat && S->feat[w]) continue;
            const double *N = S->M->normals + 3 * (size_t)w;
            if (!(N[0] * n1[0] + N[1] * n1[1] + N[2] * n1[2] > 0.0)) return 0;
        }
    }
    /* both ways: u's point (on the surface) within the tolerance of the
     * moved triangles, so no thin part is cut off by triangles that pass
     * near its base (and most moves that fail are refused before sampling) */
    double d2 = INFINITY;
    for (size_t i = 0; i < S->ru.n && d2 > S->tol * S->tol; ++i) {
        const uint32_t *t = T + 3 * (size_t)S->ru.a[i];
        if (t[0] == v || t[1] == v || t[2] == v) continue;
        const double *q[3];
        for (int k = 0; k < 3; ++k) q[k] = t[k] == u ? pv : P(S, t[k]);
        const double e = point_triangle2(P(S, u), q[0], q[1], q[2]);
        if (e < d2) d2 = e;
    }
    if (!(d2 <= S->tol * S->tol)) return 0;
    /* a flat ring: the moved triangles cover the old ones' polygon exactly
     * (same plane, none turned over), whose points were checked when they
     * were made: nothing new to sample */
    if (flat_ring(S, u)) return 1;
    /* the field: a coarse lattice first (most moves that fail, fail there),
     * then the full one where that was coarser */
    int coarser;
    const int r = near_surface(S, u, v, 3, &coarser, err);
    if (r != 1 || !coarser) return r;
    return near_surface(S, u, v, MAXSTEPS, &coarser, err);
}

/* Move u onto v (can_move said yes; S->ru is u's ring, S->nu and S->nv the
 * two neighbour sets) and requeue the vertices around. */
static int do_move(simp *S, uint32_t u, uint32_t v) {
    uint32_t *T = S->M->triangles;
    for (size_t i = 0; i < S->ru.n; ++i) {
        uint32_t *t = T + 3 * (size_t)S->ru.a[i];
        for (int k = 0; k < 3; ++k) { /* its ring changes: its moves are new */
            S->failed[t[k]] = 0;
            S->stuck[t[k]] = 0;
        }
        if (t[0] == v || t[1] == v || t[2] == v)
            S->tdead[S->ru.a[i]] = 1;
        else
            for (int k = 0; k < 3; ++k)
                if (t[k] == u) t[k] = v;
    }
    /* u's corners join v's list (its dead ones are dropped by later walks) */
    if (S->head[u] != NONE) {
        if (S->head[v] == NONE)
            S->head[v] = S->head[u];
        else
            S->next[S->tail[v]] = S->head[u];
        S->tail[v] = S->tail[u];
    }
    S->head[u] = S->tail[u] = NONE;
    for (int i = 0; i < 10; ++i) S->Q[10 * (size_t)v + i] += S->Q[10 * (size_t)u + i];
    if (S->kind[u] == CREASE) {
        uint32_t *su = S->sn + 2 * (size_t)u;
        const uint32_t w = su[0] == v ? su[1] : su[0];
        if (S->kind[v] == CREASE) {
            uint32_t *s = S->sn + 2 * (size_t)v;
            if (s[0] == u) s[0] = w;
            if (s[1] == u) s[1] = w;
            if (s[0] == s[1]) S->kind[v] = FIXED; /* a crease closed into a loop of two */
        }
        if (S->kind[w] == CREASE) {
            uint32_t *s = S->sn + 2 * (size_t)w;
            if (s[0] == u) s[0] = v;
            if (s[1] == u) s[1] = v;
            if (s[0] == s[1]) S->kind[w] = FIXED;
        }
    }
    S->kind[u] = GONE;
    ++S->stamp[u];
    /* requeue v and every neighbour of either (copied: requeue reuses ru) */
    vec32 around = {NULL, 0, 0};
    int ok = push32(&around, v);
    for (size_t i = 0; ok && i < S->nu.n; ++i)
        if (S->nu.a[i] != v) ok = push32(&around, S->nu.a[i]);
    const uint64_t m = mark_all(S, &S->nu);
    for (size_t i = 0; ok && i < S->nv.n; ++i) /* another region's: left to a later pass */
        if (S->nv.a[i] != u && mine(S, S->nv.a[i]) && S->mark[S->nv.a[i]] != m)
            ok = push32(&around, S->nv.a[i]);
    for (size_t i = 0; ok && i < around.n; ++i)
        ok = i == 0 ? requeue(S, v) : requeue_near(S, around.a[i], u, v);
    free(around.a);
    return ok;
}

/* ---- setup */

typedef struct hedge {
    uint64_t key; /* smaller vertex << 32 | larger */
    uint32_t t;
} hedge;

static int cmp_hedge(const void *a, const void *b) {
    const hedge *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

/* in[0..n) (in triangle order) into out in order of key, then triangle: a
 * counting sort by the smaller vertex, which keeps the triangle order, then
 * each vertex's few edges by the larger one (qsort of all of them was 7 %
 * of the simplification's instructions on S2 at 128 cells). start: nv + 1
 * zeros. */
static void sort_hedges(const hedge *in, hedge *out, size_t n, uint32_t *start, size_t nv) {
    for (size_t i = 0; i < n; ++i) ++start[(in[i].key >> 32) + 1];
    for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    for (size_t i = 0; i < n; ++i) out[start[in[i].key >> 32]++] = in[i];
    /* start[v] is now the end of v's edges, which begin at start[v - 1] */
    size_t b = 0;
    for (size_t v = 0; v < nv; ++v) {
        const size_t e = start[v];
        if (e - b > 32) { /* a vertex of many triangles (a merged flat face's fan) */
            qsort(out + b, e - b, sizeof *out, cmp_hedge);
        } else {
            for (size_t i = b + 1; i < e; ++i) {
                const hedge x = out[i];
                size_t j = i;
                for (; j > b && out[j - 1].key > x.key; --j) out[j] = out[j - 1];
                out[j] = x;
            }
        }
        b = e;
    }
}

static void add_sharp(simp *S, uint32_t *count, uint32_t a, uint32_t b) {
    if (count[a] < 2) S->sn[2 * (size_t)a + count[a]] = b;
    ++count[a];
}

/* Kinds, crease neighbours, quadrics and corner lists. */
static lb_status setup(simp *S, lb_error *err) {
    const lb_mesh *M = S->M;
    const size_t nv = M->nvertices, nt = M->ntriangles;
    hedge *E = malloc(3 * nt * sizeof *E), *F = malloc(3 * nt * sizeof *F);
    double *un = malloc(3 * nt * sizeof *un); /* unit facings, 0 0 0: degenerate */
    uint32_t *count = calloc(nv + 1, sizeof *count);
    if (!E || !F || !un || !count) {
        free(E);
        free(F);
        free(un);
        free(count);
        return nomem(err);
    }
    for (size_t t = 0; t < nt; ++t) {
        const uint32_t *tv = M->triangles + 3 * t;
        const double *a = P(S, tv[0]), *b = P(S, tv[1]), *c = P(S, tv[2]);
        double *n = un + 3 * t;
        lb__facing(a, b, c, n);
        const double l = norm3(n);
        if (l > 0.0 && isfinite(l)) {
            for (int d = 0; d < 3; ++d) n[d] /= l;
            /* the plane n . x + dd = 0, weighted by the area */
            const double dd = -(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]), w = 0.5 * l;
            const double q[10] = {n[0] * n[0], n[0] * n[1], n[0] * n[2], n[0] * dd, n[1] * n[1],
                                  n[1] * n[2], n[1] * dd,   n[2] * n[2], n[2] * dd, dd * dd};
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < 10; ++i) S->Q[10 * (size_t)tv[k] + i] += w * q[i];
        } else {
            n[0] = n[1] = n[2] = 0.0;
            for (int k = 0; k < 3; ++k) S->kind[tv[k]] = FIXED;
        }
        for (int k = 0; k < 3; ++k) {
            const uint32_t x = tv[k], y = tv[(k + 1) % 3];
            const uint32_t lo = x < y ? x : y, hi = x < y ? y : x;
            E[3 * t + k].key = (uint64_t)lo << 32 | hi;
            E[3 * t + k].t = (uint32_t)t;
        }
    }
    sort_hedges(E, F, 3 * nt, count, nv);
    free(E);
    E = F;
    memset(count, 0, nv * sizeof *count);
    for (size_t i = 0; i < 3 * nt;) {
        size_t j = i + 1;
        while (j < 3 * nt && E[j].key == E[i].key) ++j;
        const uint32_t a = (uint32_t)(E[i].key >> 32), b = (uint32_t)E[i].key;
        if (j - i != 2) { /* an open boundary (or worse): its ends stay */
            S->kind[a] = S->kind[b] = FIXED;
        } else {
            const double *n = un + 3 * (size_t)E[i].t, *m = un + 3 * (size_t)E[i + 1].t;
            if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < LB__FEATURE_COS) {
                add_sharp(S, count, a, b);
                add_sharp(S, count, b, a);
            }
        }
        i = j;
    }
    for (size_t v = 0; v < nv; ++v)
        if (S->kind[v] != FIXED)
            S->kind[v] = count[v] == 0 ? SMOOTH : count[v] == 2 ? CREASE : FIXED;
    free(E);
    free(un);
    free(count);
    /* corner lists, each in corner order */
    for (size_t v = 0; v < nv; ++v) S->head[v] = S->tail[v] = NONE;
    for (size_t c = 0; c < 3 * nt; ++c) {
        const uint32_t v = M->triangles[c];
        S->next[c] = NONE;
        if (S->head[v] == NONE)
            S->head[v] = (uint32_t)c;
        else
            S->next[S->tail[v]] = (uint32_t)c;
        S->tail[v] = (uint32_t)c;
    }
    return LB_OK;
}

void lb__keep_vertices(lb_mesh *M, uint8_t *feat, uint32_t *to) {
    size_t n = 0;
    for (size_t v = 0; v < M->nvertices; ++v) {
        if (to[v] == NONE) continue;
        to[v] = (uint32_t)n;
        if (n != v) {
            memcpy(M->positions + 3 * n, M->positions + 3 * v, 3 * sizeof *M->positions);
            memcpy(M->normals + 3 * n, M->normals + 3 * v, 3 * sizeof *M->normals);
            if (feat) feat[n] = feat[v];
        }
        ++n;
    }
    M->nvertices = n;
}

/* Drop the moved vertices and the dead triangles, keeping both orders. */
static void compact(simp *S, uint8_t *feat) {
    lb_mesh *M = S->M;
    uint32_t *to = S->stamp; /* reused: new index per vertex */
    for (size_t v = 0; v < M->nvertices; ++v) to[v] = S->kind[v] == GONE ? NONE : 0;
    lb__keep_vertices(M, feat, to);
    size_t m = 0;
    for (size_t t = 0; t < M->ntriangles; ++t) {
        if (S->tdead[t]) continue;
        for (int k = 0; k < 3; ++k) M->triangles[3 * m + k] = to[M->triangles[3 * t + k]];
        ++m;
    }
    M->ntriangles = m;
}

/* ---- collapses, cheapest first */

/* What a run of collapses looks up from its work: the caller's cancel
 * flag, a pass's stop flag (a worker failed or saw the cancel), and on the
 * calling thread only the progress callback. */
typedef struct watch {
    const volatile int *cancel;
    atomic_int *stop;             /* NULL: no pass */
    lb_mesh_progress_fn progress; /* NULL on other threads */
    void *user;
    double base, weight, shown; /* the fraction reported: base + weight * shown */
    atomic_size_t *done;        /* a pass: regions done of nreg, the fraction shown */
    size_t nreg;
} watch;

static int stopped(watch *wt, size_t tried, size_t left) {
    if (wt->stop && atomic_load_explicit(wt->stop, memory_order_relaxed)) return 1;
    if (wt->cancel && *wt->cancel) return 1;
    if (!wt->progress) return 0;
    const double f = wt->done ? (double)atomic_load(wt->done) / (double)wt->nreg
                              : (double)tried / (double)(tried + left);
    if (f > wt->shown) wt->shown = f;
    return wt->progress(wt->base + wt->weight * wt->shown, wt->user) != 0;
}

/* The moves of verts[0..n) (every vertex when verts is NULL) and, after
 * each move made, of the vertices around it, cheapest first, until none is
 * left. */
static lb_status collapse(simp *S, const uint32_t *verts, size_t n, watch *wt, lb_error *err) {
    S->nh = 0;
    for (size_t i = 0; i < n; ++i)
        if (!requeue(S, verts ? verts[i] : (uint32_t)i)) return nomem(err);
    lb_status s = LB_OK;
    size_t tried = 0;
    while (!s && S->nh) {
        const hent e = hpop(S);
        const uint32_t u = e.v;
        if (e.stamp != S->stamp[u] || S->kind[u] == GONE) continue;
        S->hcost[u] = NAN;
        if (++tried % CHECK_EVERY == 0 && stopped(wt, tried, S->nh)) {
            s = lb__fail(err, LB_ERR_CANCELLED, "lb_mesh_create: cancelled by the caller");
            break;
        }
        if (S->kind[u] != SMOOTH && S->kind[u] != CREASE) continue;
        /* u's ring and neighbours, once for its moves and their checks */
        if (!ring(S, u, &S->ru) || !neighbours(S, u, &S->ru, &S->nu)) {
            s = nomem(err);
            break;
        }
        /* its moves (as moves() finds them) in order of cost, each cost
         * computed once (stable: ties in ring order) */
        vec32 *cand = &S->cand;
        cand->n = 0;
        int room = 1;
        if (S->kind[u] == CREASE)
            room = push32(cand, S->sn[2 * (size_t)u]) && push32(cand, S->sn[2 * (size_t)u + 1]);
        else
            for (size_t i = 0; room && i < S->nu.n; ++i) room = push32(cand, S->nu.a[i]);
        if (room && cand->n > S->ccap) {
            free(S->cost);
            S->ccap = cand->cap;
            room = (S->cost = malloc(S->ccap * sizeof *S->cost)) != NULL;
        }
        if (!room) {
            s = nomem(err);
            break;
        }
        if (!cand->n) continue;
        double *cost = S->cost;
        for (size_t i = 0; i < cand->n; ++i) {
            const uint32_t x = cand->a[i];
            const double c = move_cost(S, u, x);
            size_t j = i;
            for (; j > 0 && c < cost[j - 1]; --j) {
                cost[j] = cost[j - 1];
                cand->a[j] = cand->a[j - 1];
            }
            cost[j] = c;
            cand->a[j] = x;
        }
        /* in cost order, the first that passes every check is made; a move
         * that failed its shape or field check before, with u's ring as it
         * is, is not checked again */
        int moved = 0, stuck = 1; /* stuck: every move tried failed so */
        for (size_t i = 0; i < cand->n && !moved; ++i) {
            size_t bit = 0; /* the move's bit in S->failed[u] (none from 32 on) */
            while (bit < S->nu.n && S->nu.a[bit] != cand->a[i]) ++bit;
            const uint32_t mask = bit < 32 ? (uint32_t)1 << bit : 0;
            if (S->failed[u] & mask) continue;
            int r = keeps_topology(S, u, cand->a[i]);
            if (r == 1) {
                r = keeps_shape(S, u, cand->a[i], err);
                if (r == 0) S->failed[u] |= mask;
            }
            if (r == -1) s = nomem(err);
            if (r == -2) s = S->est;
            if (s) break;
            if (r == 1) {
                if (!do_move(S, u, cand->a[i])) s = nomem(err);
                moved = 1;
            } else if (!(S->failed[u] & mask)) {
                stuck = 0; /* the topology, which v's ring can change */
            }
        }
        /* then every move fails whatever u's neighbours do, until u's ring
         * changes (do_move clears this): u is not queued again till then */
        if (!s && !moved && stuck) S->stuck[u] = 1;
    }
    return s;
}

/* ---- parallel passes
 *
 * The grid is cut into regions, cubes of RMIN cells a side or more (at
 * most RMAXN along an axis: the regions depend on the grid alone, never on
 * the thread count). In a pass each region's vertices whose neighbours all
 * lie in the region move as in one thread, the regions on as many threads
 * as the caller allows. Such a move changes only the region's vertices
 * (their lists, quadrics, kinds, triangles) and reads, of others, only
 * what no other worker changes: triangles of a locked vertex (one with a
 * neighbour in another region), which no move of another region touches,
 * since a vertex moves only when all its neighbours are its region's. A
 * locked vertex therefore stays locked through the pass, and a region's
 * result does not depend on the others' progress or on which thread takes
 * it. The second pass shifts the regions by half a side, so the vertices
 * locked in the first lie inside its regions; a last pass on one thread
 * takes every vertex that can still move (the few locked in both, and
 * those whose neighbours moved). Every pass applies the same checks to
 * every move, so the guarantees are those of one thread. */
#define RMIN 32
#define RMAXN 16

typedef struct pass {
    simp *W; /* the workers' (W[0]: the calling thread's) */
    const uint32_t *verts, *ids;
    const size_t *start; /* region ids[r]'s movable vertices: verts[start[r] .. start[r + 1]) */
    /* the regions in the order taken, most vertices first (the last ones
     * taken are short, so the threads finish together): r in the low 32 bits */
    const uint64_t *load;
    size_t nreg;
    atomic_size_t next, done;
    atomic_int stop;
    watch w0; /* the calling thread's */
    lb_status *st;
    lb_error *errs;
} pass;

typedef struct pworker {
    pass *P;
    size_t t;
} pworker;

static void pass_work(pass *P, size_t t) {
    simp *W = &P->W[t];
    watch other = {P->w0.cancel, &P->stop, NULL, NULL, 0.0, 0.0, 0.0, NULL, 0};
    watch *wt = t == 0 ? &P->w0 : &other;
    for (;;) {
        /* a cancel, another worker's failure, and the progress between regions */
        if (stopped(wt, 0, 0)) {
            P->st[t] =
                lb__fail(&P->errs[t], LB_ERR_CANCELLED, "lb_mesh_create: cancelled by the caller");
            atomic_store(&P->stop, 1);
            break;
        }
        const size_t k = atomic_fetch_add(&P->next, 1);
        if (k >= P->nreg) break;
        const size_t r = (uint32_t)P->load[k];
        W->own = P->ids[r];
        const lb_status s =
            collapse(W, P->verts + P->start[r], P->start[r + 1] - P->start[r], wt, &P->errs[t]);
        if (s) {
            P->st[t] = s;
            atomic_store(&P->stop, 1);
            break;
        }
        atomic_fetch_add(&P->done, 1);
    }
}

/* The most vertices first, then by region. */
static int cmp_load(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static void *pass_thread(void *a) {
    const pworker *pw = a;
    pass_work(pw->P, pw->t);
    return NULL;
}

/* One pass on nw workers W (their tok the same on entry, and on return the
 * largest), regions shifted by half a side when shift; rg and lock: a
 * vertex's room. */
static lb_status run_pass(simp *W, size_t nw, int shift, uint32_t *rg, uint8_t *lock, watch *w0,
                          lb_error *err) {
    const lb_mesh *M = W->M;
    const lb__grid *g = W->g;
    const size_t nv = M->nvertices, ntri = M->ntriangles;
    uint32_t longest = 0;
    for (int d = 0; d < 3; ++d)
        if (g->cells[d] > longest) longest = g->cells[d];
    const uint32_t side = longest > RMIN * RMAXN ? (longest + RMAXN - 1) / RMAXN : RMIN;
    size_t nr[3], nall = 1;
    for (int d = 0; d < 3; ++d) nall *= nr[d] = g->cells[d] / side + 3;
    for (size_t v = 0; v < nv; ++v) {
        size_t id = 0;
        for (int d = 0; d < 3; ++d) {
            double c = floor((M->positions[3 * v + d] - g->origin[d]) / (side * g->h[d]) +
                             (shift ? 0.5 : 0.0)) +
                       1.0;
            if (!(c >= 0.0)) c = 0.0; /* NaN too */
            if (c > (double)(nr[d] - 1)) c = (double)(nr[d] - 1);
            id = id * nr[d] + (size_t)c;
        }
        rg[v] = (uint32_t)id;
    }
    memset(lock, 0, nv);
    for (size_t t = 0; t < ntri; ++t) {
        if (W->tdead[t]) continue;
        const uint32_t *tv = M->triangles + 3 * t;
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = tv[k], b = tv[(k + 1) % 3];
            if (rg[a] != rg[b]) lock[a] = lock[b] = 1;
        }
    }
    size_t *pos = calloc(nall, sizeof *pos), *start = malloc((nall + 1) * sizeof *start);
    uint32_t *ids = malloc(nall * sizeof *ids), *verts = malloc(nv * sizeof *verts);
    uint64_t *load = malloc(nall * sizeof *load);
    lb_status *st = calloc(nw, sizeof *st);
    lb_error *errs = calloc(nw, sizeof *errs);
    pthread_t *tid = malloc(nw * sizeof *tid);
    pworker *pw = malloc(nw * sizeof *pw);
    pass *P = malloc(sizeof *P);
    lb_status s = LB_OK;
    if (!pos || !start || !ids || !verts || !load || !st || !errs || !tid || !pw || !P)
        s = nomem(err);
    size_t nids = 0;
    if (!s) {
#define ELIGIBLE(v) ((W->kind[v] == SMOOTH || W->kind[v] == CREASE) && !lock[v] && !W->stuck[v])
        for (size_t v = 0; v < nv; ++v)
            if (ELIGIBLE(v)) ++pos[rg[v]];
        size_t total = 0;
        for (size_t r = 0; r < nall; ++r) {
            if (!pos[r]) continue;
            ids[nids] = (uint32_t)r;
            start[nids++] = total;
            total += pos[r];
            pos[r] = start[nids - 1];
        }
        start[nids] = total;
        for (size_t v = 0; v < nv; ++v)
            if (ELIGIBLE(v)) verts[pos[rg[v]]++] = (uint32_t)v;
#undef ELIGIBLE
        /* key: the vertices' complement (most first), then the index */
        for (size_t r = 0; r < nids; ++r)
            load[r] = (uint64_t)(UINT32_MAX - (start[r + 1] - start[r])) << 32 | r;
        qsort(load, nids, sizeof *load, cmp_load);
        for (size_t v = 0; v < nv; ++v) W->hcost[v] = NAN;
        P->W = W;
        P->verts = verts;
        P->ids = ids;
        P->start = start;
        P->load = load;
        P->nreg = nids;
        atomic_init(&P->next, 0);
        atomic_init(&P->done, 0);
        atomic_init(&P->stop, 0);
        P->w0 = *w0;
        P->w0.stop = &P->stop;
        P->w0.done = &P->done;
        P->w0.nreg = nids ? nids : 1;
        P->w0.shown = 0.0;
        P->st = st;
        P->errs = errs;
        for (size_t t = 0; t < nw; ++t) {
            W[t].region = rg;
            W[t].lock = lock;
        }
        size_t nthr = 0; /* the other threads started (fewer when refused: the same result) */
        for (size_t t = 1; t < nw && t < nids; ++t) {
            pw[t].P = P;
            pw[t].t = t;
            if (pthread_create(&tid[t], NULL, pass_thread, &pw[t]) != 0) break;
            ++nthr;
        }
        pass_work(P, 0);
        for (size_t t = 1; t <= nthr; ++t) pthread_join(tid[t], NULL);
        uint64_t tok = 0;
        for (size_t t = 0; t < nw; ++t) {
            if (W[t].tok > tok) tok = W[t].tok;
            W[t].region = NULL;
            W[t].lock = NULL;
        }
        for (size_t t = 0; t < nw; ++t) W[t].tok = tok;
        size_t who = nw; /* a failure first, else a cancel */
        for (size_t t = 0; t < nw && who == nw; ++t)
            if (st[t] && st[t] != LB_ERR_CANCELLED) who = t;
        for (size_t t = 0; t < nw && who == nw; ++t)
            if (st[t]) who = t;
        if (who < nw) {
            s = st[who];
            if (err) *err = errs[who];
        }
    }
    free(pos);
    free(start);
    free(ids);
    free(verts);
    free(load);
    free(st);
    free(errs);
    free(tid);
    free(pw);
    free(P);
    return s;
}

/* A worker: the shared arrays of S, its own scratch (1: allocated). */
static int worker_init(simp *W, const simp *S) {
    *W = *S;
    W->wkey = malloc(WSLOTS * sizeof *W->wkey);
    W->wplan = calloc(WSLOTS, sizeof *W->wplan);
    for (size_t k = 0; W->wkey && k < WSLOTS; ++k) W->wkey[k] = UINT64_MAX;
    /* without them, lb_evaluator_eval's own (the same values) */
    W->few = lb__boxeval_alloc(W->ev, &W->E, NULL) == LB_OK &&
             lb__plan_alloc(W->ev, &W->outer, NULL) == LB_OK;
    return W->wkey && W->wplan;
}

static void worker_free(simp *W) {
    for (size_t k = 0; W->wkey && k < WSLOTS; ++k)
        if (W->wkey[k] != UINT64_MAX) lb__cplan_free(&W->wplan[k]);
    free(W->wkey);
    free(W->wplan);
    free(W->heap);
    free(W->ru.a);
    free(W->rv.a);
    free(W->nu.a);
    free(W->nv.a);
    free(W->tmp.a);
    free(W->cand.a);
    free(W->cost);
    free(W->s);
    lb__boxeval_free(&W->E);
    lb__plan_free(&W->outer);
}

#define MAXWORKERS 64

lb_status lb__simplify(const lb_evaluator *ev, const lb__grid *g, lb_mesh *M, uint8_t *feat,
                       double tolerance, size_t max_memory, int threads, const volatile int *cancel,
                       lb_mesh_progress_fn progress, void *user, double base, double weight,
                       lb_error *err) {
    const size_t nv = M->nvertices, nt = M->ntriangles;
    if (!nt || nv >= NONE || 3 * nt >= NONE) return LB_OK;
    const double need = (double)nt * TRI_BYTES + (double)nv * VERTEX_BYTES;
    if (need > (double)max_memory)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_mesh_create: simplifying %zu triangles needs about %.0f MiB, over the "
                        "memory cap of %zu MiB; allowed: a lower resolution or a larger "
                        "max_memory",
                        nt, need / 1048576.0, max_memory >> 20);
    const size_t nw = threads < 1 ? 1 : threads > MAXWORKERS ? MAXWORKERS : (size_t)threads;
    simp S;
    memset(&S, 0, sizeof S);
    S.ev = ev;
    S.g = g;
    S.M = M;
    S.feat = feat;
    S.h = fmin(g->h[0], fmin(g->h[1], g->h[2]));
    S.tol = tolerance * S.h;
    S.next = malloc(3 * nt * sizeof *S.next);
    S.head = malloc(nv * sizeof *S.head);
    S.tail = malloc(nv * sizeof *S.tail);
    S.tdead = calloc(nt, 1);
    S.kind = calloc(nv, 1);
    S.sn = malloc(2 * nv * sizeof *S.sn);
    S.Q = calloc(10 * nv, sizeof *S.Q);
    S.stamp = calloc(nv, sizeof *S.stamp);
    S.mark = calloc(nv, sizeof *S.mark);
    S.failed = calloc(nv, sizeof *S.failed);
    S.stuck = calloc(nv, 1);
    S.hcost = malloc(nv * sizeof *S.hcost);
    S.htgt = malloc(nv * sizeof *S.htgt); /* hcost: NAN set by each pass */
    uint32_t *rg = malloc(nv * sizeof *rg);
    uint8_t *lock = malloc(nv);
    simp *W = calloc(nw, sizeof *W);
    lb_status s = LB_OK;
    if (!S.next || !S.head || !S.tail || !S.tdead || !S.kind || !S.sn || !S.Q || !S.stamp ||
        !S.mark || !S.failed || !S.stuck || !S.hcost || !S.htgt || !rg || !lock || !W)
        s = nomem(err);
    if (!s) s = setup(&S, err);
    size_t nwi = 0;               /* workers initialised */
    for (; !s && nwi < nw; ++nwi) /* a failed one is freed with the others */
        if (!worker_init(&W[nwi], &S)) s = nomem(err);
    /* two parallel passes (two fifths of the bar each), then one thread */
    watch w0 = {cancel, NULL, progress, user, base, 0.4 * weight, 0.0, NULL, 0};
    if (!s) s = run_pass(W, nw, 0, rg, lock, &w0, err);
    w0.base = base + 0.4 * weight;
    if (!s) s = run_pass(W, nw, 1, rg, lock, &w0, err);
    if (!s) {
        for (size_t v = 0; v < nv; ++v) S.hcost[v] = NAN;
        w0.base = base + 0.8 * weight;
        w0.weight = 0.2 * weight;
        s = collapse(&W[0], NULL, nv, &w0, err);
    }
    if (!s) compact(&S, feat);
    for (size_t t = 0; t < nwi; ++t) worker_free(&W[t]);
    free(W);
    free(rg);
    free(lock);
    free(S.next);
    free(S.head);
    free(S.tail);
    free(S.tdead);
    free(S.kind);
    free(S.sn);
    free(S.Q);
    free(S.stamp);
    free(S.mark);
    free(S.failed);
    free(S.stuck);
    free(S.hcost);
    free(S.htgt);
    return s;
}
