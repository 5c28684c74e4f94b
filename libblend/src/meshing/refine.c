/* Vertices on the surface: a safeguarded root solve of phi_c along grid
 * edges, batched so that each iteration is one evaluator call over all the
 * edges still unconverged.
 *
 * Per edge: start at the linear interpolation of the end values; Newton on
 * t (phi's derivative along the edge is grad phi . (b - a)) while the step
 * stays strictly inside the bracket, bisection otherwise and every eighth
 * step. Stops when
 * |phi| <= 1e-7 h |grad phi| (the vertex is within 1e-7 cell sizes of the
 * surface to first order) or when the bracket is below 1e-12 of the edge.
 * The vertex is the last evaluated point, so its normal is the gradient
 * there. */
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

#define MAX_ITER 64

lb_status lb__refine_edges(const lb_evaluator *ev, const lb__grid *g, size_t n, const double *a,
                           const double *b, const double *pa, const double *pb, double *pos,
                           double *nrm, lb_error *err) {
    if (n == 0) return LB_OK;
    double hmin = g->h[0];
    if (g->h[1] < hmin) hmin = g->h[1];
    if (g->h[2] < hmin) hmin = g->h[2];
    const double tol = 1e-7 * hmin;
    double *mem = malloc(n * (10 * sizeof(double) + sizeof(size_t)));
    if (!mem) return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    double *t = mem, *lo = t + n, *hi = lo + n, *x = hi + n, *y = x + n, *z = y + n, *v = z + n,
           *gx = v + n, *gy = gx + n, *gz = gy + n;
    size_t *act = (size_t *)(mem + 10 * n);
    size_t na = n;
    for (size_t i = 0; i < n; ++i) {
        act[i] = i;
        lo[i] = 0.0;
        hi[i] = 1.0;
        double t0 = pa[i] / (pa[i] - pb[i]);
        if (!(t0 > 1e-9)) t0 = 1e-9;
        if (!(t0 < 1.0 - 1e-9)) t0 = 1.0 - 1e-9;
        t[i] = t0;
    }
    lb_status s = LB_OK;
    for (int it = 0; it < MAX_ITER && na > 0 && !s; ++it) {
        for (size_t j = 0; j < na; ++j) {
            const size_t i = act[j];
            const double *A = a + 3 * i, *Bp = b + 3 * i;
            x[j] = A[0] + t[i] * (Bp[0] - A[0]);
            y[j] = A[1] + t[i] * (Bp[1] - A[1]);
            z[j] = A[2] + t[i] * (Bp[2] - A[2]);
        }
        s = lb_evaluator_eval(ev, na, x, y, z, v, gx, gy, gz, 1, err);
        if (s) break;
        size_t keep = 0;
        const int last = it == MAX_ITER - 1;
        for (size_t j = 0; j < na; ++j) {
            const size_t i = act[j];
            const double *A = a + 3 * i, *Bp = b + 3 * i;
            const double X[3] = {x[j], y[j], z[j]}, gf[3] = {gx[j], gy[j], gz[j]};
            double gp[3];
            const double ph = lb__mesh_phi(g, X, v[j], gf, gp);
            const double e[3] = {Bp[0] - A[0], Bp[1] - A[1], Bp[2] - A[2]};
            const double L = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            const double gl = sqrt(gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2]);
            if (ph < 0.0)
                lo[i] = t[i];
            else
                hi[i] = t[i];
            const int done = fabs(ph) <= tol * gl || (hi[i] - lo[i]) <= 1e-12 || last;
            if (done) {
                for (int d = 0; d < 3; ++d) {
                    pos[3 * i + d] = X[d];
                    nrm[3 * i + d] = gl > 0.0 ? gp[d] / gl : e[d] / L;
                }
                continue;
            }
            const double dt = gp[0] * e[0] + gp[1] * e[1] + gp[2] * e[2];
            const double tn = dt != 0.0 ? t[i] - ph / dt : NAN;
            /* every eighth step bisects, so slow Newton (a kink) still ends */
            t[i] = tn > lo[i] && tn < hi[i] && it % 8 != 7 ? tn : 0.5 * (lo[i] + hi[i]);
            act[keep++] = i;
        }
        na = keep;
    }
    free(mem);
    return s;
}
