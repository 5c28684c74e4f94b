/* The one safeguarded root solver every root-solved operator uses.
 *
 * Contract: T is continuous and non-decreasing on [lo, hi] with
 * T(lo) <= 0 <= T(hi). The solver starts at `start` (clamped into the
 * bracket), takes Newton steps while they stay strictly inside the current
 * bracket and at least halve the step before last, and bisects otherwise
 * (rtsafe). Every evaluation narrows the bracket, so the result never leaves
 * [lo, hi].
 * Stopping: with tol = LB_ROOT_RTOL * |h| + LB_ROOT_WTOL * (width of the
 * original bracket),
 * it stops when the bracket is narrower than tol, when T is exactly 0, or
 * when a Newton step is below tol AND a probe one tol beyond the new point
 * shows the sign change (so a step that is small only because convergence
 * has turned slow near a kink is never mistaken for convergence). After
 * LB_ROOT_MAX_ITER evaluations it returns the best point found.
 *
 * It is a static inline function so each operator gets a copy specialised
 * to its own T (the compiler inlines the callback). */
#ifndef LIBBLEND_SOLVER_ROOT_H
#define LIBBLEND_SOLVER_ROOT_H

#include <math.h>

#define LB_ROOT_RTOL 1e-15
#define LB_ROOT_WTOL 1e-16
#define LB_ROOT_MAX_ITER 200

/* Evaluate T and dT/dh at h. */
typedef void (*lb__root_fn)(double h, const void *ctx, double *T, double *dT);

static inline double lb__root_solve(lb__root_fn fn, const void *ctx, double lo, double hi,
                                    double start) {
    if (!(hi > lo)) return lo;
    const double width0 = hi - lo;
    double h = start;
    if (!(h >= lo)) h = lo;
    if (!(h <= hi)) h = hi;
    double dx_old = width0, dx = width0;
    for (int it = 0; it < LB_ROOT_MAX_ITER; ++it) {
        double T, dT;
        fn(h, ctx, &T, &dT);
        if (T == 0.0) return h;
        if (T < 0.0)
            lo = h;
        else
            hi = h;
        const double tol = LB_ROOT_RTOL * fabs(h) + LB_ROOT_WTOL * width0;
        if (hi - lo <= tol) return h;
        double next = h - T / dT;
        if (!(dT > 0.0) || !(next > lo && next < hi) || fabs(2.0 * (h - next)) > fabs(dx_old)) {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            next = lo + dx;
        } else {
            dx_old = dx;
            dx = h - next;
            if (fabs(dx) <= tol) {
                /* confirm: the root must lie within tol of next, on the far side */
                const double probe = T > 0.0 ? next - tol : next + tol;
                if (!(probe > lo && probe < hi)) return next;
                double Tp, dTp;
                fn(probe, ctx, &Tp, &dTp);
                if (T > 0.0 ? Tp <= 0.0 : Tp >= 0.0) return next;
                if (Tp < 0.0)
                    lo = probe;
                else
                    hi = probe;
                next = probe;
            }
        }
        h = next;
    }
    return h;
}

#endif
