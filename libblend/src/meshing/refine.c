/* Vertices on the surface: a safeguarded root solve of phi_c along grid
 * edges, batched so that each iteration is one evaluator call over all the
 * edges still unconverged.
 *
 * Per edge: start at the root of the cubic Hermite interpolant of the end
 * values and gradients (hermite_root, to about 1e-8 of the edge); Newton on
 * t (phi's derivative along the edge is grad phi . (b - a)) while the step
 * stays strictly inside the bracket, bisection otherwise and every eighth
 * step. Stops when
 * |phi| <= 1e-7 h |grad phi| (the vertex is within 1e-7 cell sizes of the
 * surface to first order) or when the bracket is below 1e-12 of the edge;
 * or takes one last Newton step unevaluated when bounds on the curvature
 * (from the normals) and on the change of the slope along the edge (from
 * the end slopes) make its error below 1e-9 h (see the loop). The normal is the
 * gradient at the last evaluated point. The edges are refined octant by
 * octant of the block (by their midpoints), each under the culling plan of
 * an interval pass over that octant. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>

double lb__mesh_phi(const lb__grid *g, const double X[3], double f, const double gf[3],
                    double gphi[3]) {
    const double s = g->soft ? -1.0 : 1.0;
    double phi = g->soft ? 0.5 - f : f;
    for (int d = 0; d < 3; ++d) gphi[d] = s * gf[d];
    if (g->closed) {
        for (int d = 0; d < 3; ++d) {
            const double lo = g->bmin[d] - X[d], hi = X[d] - g->bmax[d];
            if (lo > phi) {
                phi = lo;
                gphi[0] = gphi[1] = gphi[2] = 0.0;
                gphi[d] = -1.0;
            }
            if (hi > phi) {
                phi = hi;
                gphi[0] = gphi[1] = gphi[2] = 0.0;
                gphi[d] = 1.0;
            }
        }
    }
    return phi;
}

double lb__block_boxmax(const lb__grid *g, const lb__block *B) {
    double boxmax = -INFINITY;
    if (!g->closed) return boxmax;
    const uint32_t zero[3] = {0, 0, 0};
    double bl[3], bh[3];
    lb__node_box(g, B, zero, B->nc, bl, bh);
    for (int d = 0; d < 3; ++d) {
        boxmax = fmax(boxmax, g->bmin[d] - bl[d]);
        boxmax = fmax(boxmax, bh[d] - g->bmax[d]);
    }
    return boxmax;
}

#define MAX_ITER 64

/* The root in (0, 1) of the cubic Hermite interpolant of phi along an edge
 * (end values f0 < 0 <= f1, end slopes d0, d1): a start that is usually
 * within rounding of the surface, so one evaluation confirms it. Newton on
 * the cubic inside its bracket, bisection when a step leaves it. */
static double hermite_root(double f0, double f1, double d0, double d1) {
    /* H(t) = f0 + d0 t + c2 t^2 + c3 t^3 */
    const double c2 = 3.0 * (f1 - f0) - 2.0 * d0 - d1, c3 = 2.0 * (f0 - f1) + d0 + d1;
    double lo = 0.0, hi = 1.0, t = f0 / (f0 - f1);
    for (int it = 0; it < 16; ++it) {
        const double H = f0 + t * (d0 + t * (c2 + t * c3));
        const double dH = d0 + t * (2.0 * c2 + 3.0 * t * c3);
        if (H < 0.0)
            lo = t;
        else
            hi = t;
        const double tn = dH > 0.0 ? t - H / dH : NAN;
        const int newton = tn > lo && tn < hi;
        const double next = newton ? tn : 0.5 * (lo + hi);
        /* after a Newton step of 1e-4 the next iterate is within about
         * 1e-8 of the cubic's root (quadratic convergence), below the
         * cubic's own error: as good a start (S2 at 256 cells: the same
         * evaluations), a step or two sooner; a bisection step must be
         * tiny itself */
        if (fabs(next - t) <= (newton ? 1e-4 : 1e-7)) return next;
        t = next;
    }
    return t;
}

void lb__node_box(const lb__grid *g, const lb__block *B, const uint32_t l0[3], const uint32_t l1[3],
                  double bmin[3], double bmax[3]) {
    const uint64_t n0[3] = {(uint64_t)B->b[0] * LB__MB, (uint64_t)B->b[1] * LB__MB,
                            (uint64_t)B->b[2] * LB__MB};
    lb__node_pos(g, n0[0] + l0[0], n0[1] + l0[1], n0[2] + l0[2], bmin);
    lb__node_pos(g, n0[0] + l1[0], n0[1] + l1[1], n0[2] + l1[2], bmax);
    for (int d = 0; d < 3; ++d) {
        const double pad = 1e-9 * g->h[d];
        bmin[d] -= pad;
        bmax[d] += pad;
    }
}

void lb__octant_narrow(const lb_evaluator *ev, const lb__grid *g, const lb__block *B, int o,
                       const lb__plan *outer, lb__boxeval *E) {
    uint32_t l0[3], l1[3];
    lb__octant_nodes(B, o, l0, l1);
    double omin[3], omax[3];
    lb__node_box(g, B, l0, l1, omin, omax);
    lb__boxeval_narrow(ev, E, outer, omin, omax);
}

void lb__octant_plan(const lb_evaluator *ev, const lb__grid *g, const lb__block *B, int o,
                     const lb__plan *outer, lb__boxeval *E) {
    if (B->octmem) /* mark()'s plan of this octant */
        lb__boxeval_load(ev, &B->oct[o], E);
    else
        lb__octant_narrow(ev, g, B, o, outer, E);
}

static lb_status refine_some(const lb_evaluator *ev, const lb__grid *g, lb__boxeval *E, size_t *act,
                             size_t na, const double *a, const double *b, const double *ga,
                             const double *gb, double tol, double *t, double *lo, double *hi,
                             double *x, double *y, double *z, double *v, double *gx, double *gy,
                             double *gz, double *pos, double *nrm, double boxmax, lb_error *err);

lb_status lb__refine_edges(const lb_evaluator *ev, const lb__grid *g, const lb__block *B, size_t n,
                           const double *a, const double *b, const double *pa, const double *pb,
                           const double *ga, const double *gb, const uint8_t *known, double *pos,
                           double *nrm, lb__mscratch *S, lb_error *err) {
    if (n == 0) return LB_OK;
    double hmin = g->h[0];
    if (g->h[1] < hmin) hmin = g->h[1];
    if (g->h[2] < hmin) hmin = g->h[2];
    const double tol = 1e-7 * hmin;
    /* n <= LB__EMAP_SIZE: the thread's scratch holds every batch */
    double *t = S->edges, *lo = t + n, *hi = lo + n, *x = hi + n, *y = x + n, *z = y + n,
           *v = z + n, *gx = v + n, *gy = gx + n, *gz = gy + n;
    size_t *act = S->eact;
    for (size_t i = 0; i < n; ++i) {
        lo[i] = 0.0;
        hi[i] = 1.0;
        const double e[3] = {b[3 * i] - a[3 * i], b[3 * i + 1] - a[3 * i + 1],
                             b[3 * i + 2] - a[3 * i + 2]};
        const double d0 = ga[3 * i] * e[0] + ga[3 * i + 1] * e[1] + ga[3 * i + 2] * e[2];
        const double d1 = gb[3 * i] * e[0] + gb[3 * i + 1] * e[1] + gb[3 * i + 2] * e[2];
        double t0 = hermite_root(pa[i], pb[i], d0, d1);
        if (!(t0 > 1e-9)) t0 = 1e-9;
        if (!(t0 < 1.0 - 1e-9)) t0 = 1.0 - 1e-9;
        t[i] = t0;
    }
    lb__boxeval *E = &S->E;
    lb__boxeval_load(ev, &B->plan, E);
    lb_status s = LB_OK;
    /* the edges by octant of the block (as the node values, mesher.c), each
     * octant refined under its own plan: the edge's midpoint decides. A plan
     * with few primitives keeps all the edges in one group. */
    const int narrow = lb__plan_prims(ev, &E->plan) >= LB__NARROW_MIN_PRIMS;
    const int ngroups = narrow ? 8 : 1;
    size_t start[9] = {0};
    const uint32_t half[3] = {B->nc[0] / 2, B->nc[1] / 2, B->nc[2] / 2};
    if (narrow) {
        if (!B->octmem) lb__plan_load(ev, &E->plan, &S->outer);
        double mid[3];
        lb__node_pos(g, (uint64_t)B->b[0] * LB__MB + half[0], (uint64_t)B->b[1] * LB__MB + half[1],
                     (uint64_t)B->b[2] * LB__MB + half[2], mid);
        for (int pass = 0; pass < 2; ++pass) {
            size_t fill[8];
            for (int o = 0; o < 8; ++o) fill[o] = start[o];
            for (size_t i = 0; i < n; ++i) {
                if (known && known[i]) continue;
                int o = 0;
                for (int d = 0; d < 3; ++d)
                    o |= (0.5 * (a[3 * i + d] + b[3 * i + d]) >= mid[d]) << d;
                if (pass)
                    act[fill[o]++] = i;
                else
                    start[o + 1]++;
            }
            if (!pass)
                for (int o = 0; o < 8; ++o) start[o + 1] += start[o];
        }
    } else {
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if (!known || !known[i]) act[m++] = i;
        start[1] = m;
    }
    const double boxmax = lb__block_boxmax(g, B);
    for (int o = 0; o < ngroups && !s; ++o) {
        const size_t na = start[o + 1] - start[o];
        if (!na) continue;
        if (narrow) lb__octant_plan(ev, g, B, o, &S->outer, E);
        s = refine_some(ev, g, E, act + start[o], na, a, b, ga, gb, tol, t, lo, hi, x, y, z, v, gx,
                        gy, gz, pos, nrm, boxmax, err);
    }
    return s;
}

/* The safeguarded iteration for edges act[0..na) (act is reordered as
 * edges converge; the other arrays are indexed by edge). */
static lb_status refine_some(const lb_evaluator *ev, const lb__grid *g, lb__boxeval *E, size_t *act,
                             size_t na, const double *a, const double *b, const double *ga,
                             const double *gb, double tol, double *t, double *lo, double *hi,
                             double *x, double *y, double *z, double *v, double *gx, double *gy,
                             double *gz, double *pos, double *nrm, double boxmax, lb_error *err) {
    lb_status s = LB_OK;
    for (int it = 0; it < MAX_ITER && na > 0 && !s; ++it) {
        for (size_t j = 0; j < na; ++j) {
            const size_t i = act[j];
            const double *A = a + 3 * i, *Bp = b + 3 * i;
            x[j] = A[0] + t[i] * (Bp[0] - A[0]);
            y[j] = A[1] + t[i] * (Bp[1] - A[1]);
            z[j] = A[2] + t[i] * (Bp[2] - A[2]);
        }
        s = lb__boxeval_run(ev, E, na, x, y, z, v, gx, gy, gz, err);
        if (s) break;
        size_t keep = 0;
        const int last = it == MAX_ITER - 1;
        for (size_t j = 0; j < na; ++j) {
            const size_t i = act[j];
            const double *A = a + 3 * i, *Bp = b + 3 * i;
            const double X[3] = {x[j], y[j], z[j]}, gf[3] = {gx[j], gy[j], gz[j]};
            double gp[3];
            const double ph = lb__mesh_phi_in(g, boxmax, X, v[j], gf, gp);
            const double e[3] = {Bp[0] - A[0], Bp[1] - A[1], Bp[2] - A[2]};
            const double L = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double gl = sqrt(gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2]);
            if (ph < 0.0)
                lo[i] = t[i];
            else
                hi[i] = t[i];
            const int done = fabs(ph) <= tol * gl || (hi[i] - lo[i]) <= 1e-12 || last;
            if (done) {
                /* one division for the normal (and its length within an ulp
                 * or two of 1) */
                const double in = gl > 0.0 ? 1.0 / gl : 1.0 / L;
                const double *src = gl > 0.0 ? gp : e;
                for (int d = 0; d < 3; ++d) {
                    pos[3 * i + d] = X[d];
                    nrm[3 * i + d] = src[d] * in;
                }
                continue;
            }
            const double dt = gp[0] * e[0] + gp[1] * e[1] + gp[2] * e[2];
            const double tn = dt != 0.0 ? t[i] - ph / dt : NAN;
            if (tn > lo[i] && tn < hi[i] && gl > 0.0) {
                /* A last Newton step taken without evaluating its point, when
                 * its error is provably tiny: the unit normals at both ends
                 * and here bound the curvature along the edge (kappa), and
                 * Newton's error is kappa step^2 / 2. Accepted only when that
                 * is below tol / 100 and the normal here is within 1e-6 rad
                 * of the one at the new point; kinks (normals that jump)
                 * never qualify. */
                double kap2 = 0.0; /* the largest squared normal change */
                const double *G[2] = {ga + 3 * i, gb + 3 * i};
                const double igl = 1.0 / gl, iL = 1.0 / L;
                for (int q = 0; q < 2; ++q) {
                    const double l =
                        sqrt(G[q][0] * G[q][0] + G[q][1] * G[q][1] + G[q][2] * G[q][2]);
                    if (!(l > 0.0)) {
                        kap2 = INFINITY;
                        break;
                    }
                    const double il = 1.0 / l;
                    double dn = 0.0;
                    for (int d = 0; d < 3; ++d) {
                        const double u = G[q][d] * il - gp[d] * igl;
                        dn += u * u;
                    }
                    if (dn > kap2) kap2 = dn;
                }
                const double kap = 4.0 * sqrt(kap2) * iL;
                /* the slope along the edge may change too (fields whose
                 * gradient length varies, as blends' do): phi'' from the
                 * end slopes and this one, with the same safety factor */
                const double s0 = (G[0][0] * e[0] + G[0][1] * e[1] + G[0][2] * e[2]) * iL,
                             s1 = (G[1][0] * e[0] + G[1][1] * e[1] + G[1][2] * e[2]) * iL,
                             sh = dt * iL;
                const double M =
                    4.0 * iL * fmax(fabs(sh - s0) / t[i], fabs(s1 - sh) / (1.0 - t[i]));
                const double step = fabs(tn - t[i]) * L;
                if (0.5 * kap * step * step <= 0.01 * tol && kap * step <= 1e-6 &&
                    0.5 * M * step * step <= 0.01 * tol * fabs(sh)) {
                    for (int d = 0; d < 3; ++d) {
                        pos[3 * i + d] = A[d] + tn * e[d];
                        nrm[3 * i + d] = gp[d] * igl;
                    }
                    continue;
                }
            }
            /* every eighth step bisects, so slow Newton (a kink) still ends */
            t[i] = tn > lo[i] && tn < hi[i] && it % 8 != 7 ? tn : 0.5 * (lo[i] + hi[i]);
            act[keep++] = i;
        }
        na = keep;
    }
    return s;
}
