/* Local blending's parts shared by its files (evaluation/local_*.c):
 * local_curves.c finds the intersection curves and the blending volumes'
 * parameters, local_bvh.c the segment hierarchy and its queries,
 * local_eval.c the values at points, local_bounds.c the intervals over
 * boxes. Not installed. */
#ifndef LIBBLEND_LOCAL_INTERNAL_H
#define LIBBLEND_LOCAL_INTERNAL_H

#include "tape.h"

/* the hierarchy over C's segments (C->seg, C->segc, C->bvh from the
 * components); LB_ERR_NO_MEMORY naming path when memory is short */
LB_INTERNAL lb_status lb__local_bvh(struct lb__curves *C, const char *path, lb_error *err);

/* the component with the smallest d / R near X (a < 1), the distance and
 * the closest point; returns a = d / R (>= 1: outside every volume) */
LB_INTERNAL double lb__local_nearest(const struct lb__curves *C, const double X[3], uint32_t *comp,
                                     double Q[3], double *dist);

/* Wyvill's kernel W(a) = 1 - 4/9 a^6 + 17/9 a^4 - 22/9 a^2 on [0, 1] */
static inline double lb__wyvill(double a, double *dw) {
    const double a2 = a * a;
    *dw = a * (-24.0 / 9.0 * a2 * a2 + 68.0 / 9.0 * a2 - 44.0 / 9.0);
    return 1.0 + a2 * (-4.0 / 9.0 * a2 * a2 + 17.0 / 9.0 * a2 - 22.0 / 9.0);
}

/* the bounding box (centre, half-size) of n >= 1 points */
static inline void lb__points_box(const double *x, const double *y, const double *z, size_t n,
                                  double bc[3], double br[3]) {
    double bmin[3] = {x[0], y[0], z[0]}, bmax[3] = {x[0], y[0], z[0]};
    for (size_t j = 1; j < n; ++j) {
        const double P[3] = {x[j], y[j], z[j]};
        for (int d = 0; d < 3; ++d) {
            if (P[d] < bmin[d]) bmin[d] = P[d];
            if (P[d] > bmax[d]) bmax[d] = P[d];
        }
    }
    lb__box_centre(bmin, bmax, bc, br);
}

#endif
