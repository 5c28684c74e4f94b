/* The one safeguarded root solver every root-solved operator uses.
 *
 * Contract: T is continuous and non-decreasing on [lo, hi] with
 * T(lo) <= 0 <= T(hi). The solver starts at `start` (clamped into the
 * bracket), takes Newton (or Halley) steps while they stay strictly inside the current
 * bracket and at least halve the step before last, and bisects otherwise
 * (rtsafe). Every evaluation narrows the bracket, so the result never leaves
 * [lo, hi].
 * Stopping: when |T| <= LB_ROOT_TNOISE (T is zero to its own rounding) and
 * |T|/T' <= 10 LB_ROOT_RTOL |h| (so h is that close to the root), or with tol = LB_ROOT_RTOL * |h|
 * + LB_ROOT_WTOL * (width of the original bracket), it stops when the bracket is narrower than tol,
 * when T is exactly 0, or when a Newton step is below tol AND a probe one tol beyond the new point
 * shows the sign change (so a step that is small only because convergence
 * has turned slow near a kink is never mistaken for convergence). After
 * LB_ROOT_MAX_ITER evaluations it returns the best point found. In the
 * asymptotic regime (a step at most 1/100 of the one before) the error after
 * a step is predicted from the convergence order (3 for Halley, 2 for
 * Newton); when it is below tol/100 the step is accepted without a further
 * evaluation, so the returned point may differ from the last one passed to fn
 * by that one step.
 *
 * It is a static inline function so each operator gets a copy specialised
 * to its own T (the compiler inlines the callback). */
#ifndef LIBBLEND_SOLVER_ROOT_H
#define LIBBLEND_SOLVER_ROOT_H

#include <math.h>

#define LB_ROOT_RTOL 2e-15
#define LB_ROOT_WTOL 1e-16
#define LB_ROOT_MAX_ITER 200

/* Evaluate T, dT/dh and (optionally, else 0) d2T/dh2 at h: with the second
 * derivative the step is Halley's (cubic convergence), otherwise Newton's.
 * *smooth (optionally, else 0) is a radius around h within which T is
 * analytic (no kink); only then is a step accepted without evaluating it. T must be scaled so that
 * its rounding error is a few LB_ROOT_TNOISE: |T| <= LB_ROOT_TNOISE counts as T = 0 (the root is
 * then resolved as far as T itself is). */
typedef void (*lb__root_fn)(double h, const void *ctx, double *T, double *dT, double *d2T,
                            double *smooth);
#define LB_ROOT_TNOISE 1e-14

#if defined(__GNUC__)
#define LB__ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define LB__ALWAYS_INLINE inline
#endif

/* habs > 0 replaces |h| in the tolerance (for a variable such as ln h whose
 * absolute, not relative, error matters). */
static LB__ALWAYS_INLINE double lb__root_solve_scaled(lb__root_fn fn, const void *ctx, double lo,
                                                      double hi, double start, double habs) {
    if (!(hi > lo)) return lo;
    const double width0 = hi - lo;
    double h = start;
    if (!(h >= lo)) h = lo;
    if (!(h <= hi)) h = hi;
    double dx_old = width0, dx = width0;
    double prev_step = 0.0; /* last Newton/Halley step, 0 after a bisection */
    for (int it = 0; it < LB_ROOT_MAX_ITER; ++it) {
        double T, dT, d2T = 0.0, smooth = 0.0;
        fn(h, ctx, &T, &dT, &d2T, &smooth);
        const double hsz = habs > 0.0 ? habs : fabs(h);
        const double tol = LB_ROOT_RTOL * hsz + LB_ROOT_WTOL * width0;
        /* T at its rounding floor, and the root within 10 LB_ROOT_RTOL |h| of h */
        if (T == 0.0 || (fabs(T) <= LB_ROOT_TNOISE && fabs(T) <= 10.0 * LB_ROOT_RTOL * hsz * dT))
            return h;
        if (T < 0.0)
            lo = h;
        else
            hi = h;
        if (hi - lo <= tol) return h;
        const double den = 2.0 * dT * dT - T * d2T;
        const int halley = d2T != 0.0 && den > 0.0;
        double next = halley ? h - 2.0 * T * dT / den : h - T / dT;
        if (!(dT > 0.0) || !(next > lo && next < hi) || fabs(2.0 * (h - next)) > fabs(dx_old)) {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            next = lo + dx;
            prev_step = 0.0;
        } else {
            dx_old = dx;
            dx = h - next;
            /* asymptotic regime: the error after this step is about
             * |dx|^3/|prev|^2 * |dx| (Halley, cubic) or |dx|^2/|prev| (Newton);
             * when that is far below tol, accept next without evaluating it */
            const double a = fabs(dx), b = fabs(prev_step);
            /* no kink within the last step nor this one: both inside the radius */
            if (b > 0.0 && a <= 1e-2 * b && b < smooth) {
                const double q = a / b;
                const double predicted = halley ? a * q * q * q : a * q;
                if (predicted <= 0.01 * tol) return next;
            }
            prev_step = dx;
            if (fabs(dx) <= tol) {
                /* confirm: the root must lie within tol of next, on the far side */
                const double probe = T > 0.0 ? next - tol : next + tol;
                if (!(probe > lo && probe < hi)) return next;
                double Tp, dTp, d2Tp = 0.0, sp = 0.0;
                fn(probe, ctx, &Tp, &dTp, &d2Tp, &sp);
                /* the root lies between probe and next: return the probe, the
                 * last point evaluated, so callers may reuse what fn computed */
                if (T > 0.0 ? Tp <= 0.0 : Tp >= 0.0) return probe;
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

static LB__ALWAYS_INLINE double lb__root_solve(lb__root_fn fn, const void *ctx, double lo,
                                               double hi, double start) {
    return lb__root_solve_scaled(fn, ctx, lo, hi, start, 0.0);
}

#endif
