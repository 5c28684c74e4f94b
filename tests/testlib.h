/* Shared helpers for libblend's tests: a seeded RNG, parameter samplers,
 * long-double bisection for independent references, and a central-difference
 * gradient check whose tolerance is estimated from the data (Richardson:
 * two step sizes) so it stays meaningful from r = 1e-3 to |x| = 1e6.
 * Every test counts how many cases were checked tightly and asserts a floor,
 * so a check cannot quietly degrade into checking nothing. */
#ifndef LIBBLEND_TESTLIB_H
#define LIBBLEND_TESTLIB_H

#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include <libblend/libblend.h>

#include "../libblend/src/common/splitmix.h"

typedef lb__splitmix rng_t;

static inline uint64_t rng_u64(rng_t *r) {
    return lb__splitmix_next(r);
}
static inline double rng_unit(rng_t *r) {
    return lb__splitmix_unit(r);
}
static inline double rng_range(rng_t *r, double a, double b) {
    return a + (b - a) * rng_unit(r);
}
static inline double rng_log(rng_t *r, double a, double b) {
    return exp(rng_range(r, log(a), log(b)));
}
static inline size_t rng_int(rng_t *r, size_t a, size_t b) { /* inclusive */
    return a + (size_t)(rng_u64(r) % (uint64_t)(b - a + 1));
}
/* p in [1.05, 64]: a third general, a third integer, a third exactly 2 */
static inline double rng_p(rng_t *r) {
    const double u = rng_unit(r);
    if (u < 1.0 / 3.0) return rng_log(r, 1.05, 64.0);
    if (u < 2.0 / 3.0) return (double)rng_int(r, 2, 64);
    return 2.0;
}

/* Failure accounting: print the first few failures, count all. */
typedef struct {
    const char *name;
    long checked, failed, tight;
} tally_t;

/* Count a failure; print the first 8 as "[name] <label><suffix>". */
static inline void tally_vfail(tally_t *t, const char *suffix, const char *fmt, va_list ap) {
    t->failed++;
    if (t->failed > 8) return;
    fprintf(stderr, "  [%s] ", t->name);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "%s\n", suffix);
}
static inline void tally_check(tally_t *t, int ok, const char *fmt, ...) {
    t->checked++;
    if (ok) return;
    va_list ap;
    va_start(ap, fmt);
    tally_vfail(t, "", fmt, ap);
    va_end(ap);
}
static inline void tally_end(const tally_t *t, long min_checked) {
    fprintf(stderr, "  %-44s checked %8ld  failed %ld\n", t->name, t->checked, t->failed);
    assert_true(t->checked >= min_checked);
    assert_int_equal(t->failed, 0);
}

/* A scalar function of n arguments (for gradient checks). */
typedef double (*fn_t)(const double *x, const void *ctx);

/* Base relative tolerance of the central-difference check. Numerical
 * derivatives are only trustworthy on moderate scales, so the tests run this
 * check on moderate parameters and check gradients over the full ranges
 * (r from 1e-3 to 1e3, p up to 64, |x| up to 1e6) against the implicit
 * function theorem evaluated in long double at a long-double root. */
#ifndef GRAD_RTOL
#define GRAD_RTOL 1e-2
#endif

/* Central-difference check of g = grad f at x. step[i] is the perturbation
 * scale of argument i (a length over which f is smooth). For each argument
 * the step is swept over four decades below step[i]; the step whose two
 * estimates fd(h), fd(h/2) agree best is used, and their difference (the
 * Richardson error estimate) sets the tolerance. A wrong analytic gradient
 * fails wherever the function is smooth enough to be differentiated
 * numerically; *tight reports whether every component was checked to 1e-3
 * relative (so callers can assert that most cases were).. */
static inline int grad_ok(fn_t f, const void *ctx, size_t n, const double *x, const double *g,
                          const double *step, int *tight, double *worst) {
    double xp[64];
    int ok = 1, all_tight = 1;
    double w = 0.0, gmax = 0.0;
    memcpy(xp, x, n * sizeof *x);
    for (size_t i = 0; i < n; ++i) gmax = fmax(gmax, fabs(g[i]));
    const double floor_ = 1e-5 * gmax + 1e-300; /* components this small compare absolutely */
    /* rounding noise of f: its own size plus the size of what was summed or
     * cancelled to get it (x_j g_j terms), and the root solvers' 1e-14 */
    double fsize = fabs(f(x, ctx));
    for (size_t j = 0; j < n; ++j) fsize += fabs(x[j] * g[j]);
    for (size_t i = 0; i < n; ++i) {
        double best_fd = NAN, best_est = INFINITY, best_h = 0.0;
        double h = fmax(step[i], 0x1.0p-40 * fabs(x[i]));
        for (int j = 0; j < 4; ++j, h *= 0.1) {
            double fd[2];
            for (int s = 0; s < 2; ++s) {
                volatile double hp = x[i] + h / (1 + s), hm = x[i] - h / (1 + s);
                xp[i] = hp;
                const double a = f(xp, ctx);
                xp[i] = hm;
                const double b = f(xp, ctx);
                xp[i] = x[i];
                fd[s] = hp > hm ? (a - b) / (hp - hm) : NAN;
            }
            const double est = fabs(fd[0] - fd[1]);
            if (est < best_est) {
                best_est = est;
                best_fd = fd[1];
                best_h = h;
            }
        }
        const double scale = fabs(g[i]) + floor_;
        const double noise = 64.0 * DBL_EPSILON * (fsize + fabs(x[i]) * gmax) / best_h;
        const double tol = GRAD_RTOL * scale + 4.0 * best_est + noise;
        const double err = fabs(g[i] - best_fd);
        if (!(4.0 * best_est + noise <= 1e-3 * scale)) all_tight = 0;
        if (!(err <= tol)) ok = 0;
        if (err / scale > w) w = err / scale;
    }
    if (tight) *tight = all_tight;
    if (worst) *worst = w;
    return ok;
}

/* One gradient check counted in a tally: runs grad_ok, counts tightly checked
 * cases in t->tight and reports a failure with the case's printf-style label
 * and the worst relative error. */
static inline void tally_grad(tally_t *t, fn_t f, const void *ctx, size_t n, const double *x,
                              const double *g, const double *step, const char *fmt, ...) {
    int tight = 0;
    double worst = 0.0;
    const int ok = grad_ok(f, ctx, n, x, g, step, &tight, &worst);
    t->checked++;
    t->tight += tight;
    if (ok) return;
    char suffix[64];
    snprintf(suffix, sizeof suffix, ": worst relative error %g", worst);
    va_list ap;
    va_start(ap, fmt);
    tally_vfail(t, suffix, fmt, ap);
    va_end(ap);
}

/* Long-double bisection of an increasing function on [lo, hi] to the last bit. */
typedef long double (*ldfn_t)(long double h, const void *ctx);
static inline long double ld_bisect(ldfn_t T, const void *ctx, long double lo, long double hi) {
    for (int it = 0; it < 400; ++it) {
        const long double mid = 0.5L * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        if (T(mid, ctx) < 0.0L)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5L * (lo + hi);
}

/* ---- self-intersections (test_mesh.c, test_transition.c) ---- */

static inline int seg_tri(const double *p, const double *q, const double *a, const double *b,
                          const double *c) {
    /* proper intersection of segment pq with triangle abc (Moller-Trumbore) */
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const double h[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                         d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    const double scale = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) *
                         sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]) *
                         sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (fabs(det) <= 1e-12 * scale) return 0; /* parallel: not a proper crossing */
    const double inv = 1.0 / det;
    const double s[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) * inv;
    const double qv[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                          s[0] * e1[1] - s[1] * e1[0]};
    const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
    const double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
    const double eps = 1e-9;
    return u > eps && v > eps && u + v < 1.0 - eps && t > eps && t < 1.0 - eps;
}

/* Whether triangles A and B (vertex indices into P, 3 doubles per vertex)
 * cross: an edge of one properly through the other; neighbours across an
 * edge never do, and at a shared vertex only the edges away from it count. */
static inline int tris_cross(const double *P, const uint32_t *A, const uint32_t *B) {
    int shared = 0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) shared += A[a] == B[b];
    if (shared >= 2) return 0; /* neighbours across an edge */
    for (int k = 0; k < 3; ++k) {
        const uint32_t p = A[k], q = A[(k + 1) % 3];
        if (shared && (p == B[0] || p == B[1] || p == B[2] || q == B[0] || q == B[1] || q == B[2]))
            continue; /* an edge through the shared vertex touches there */
        if (seg_tri(P + 3 * p, P + 3 * q, P + 3 * B[0], P + 3 * B[1], P + 3 * B[2])) return 1;
        const uint32_t r = B[k], s = B[(k + 1) % 3];
        if (shared && (r == A[0] || r == A[1] || r == A[2] || s == A[0] || s == A[1] || s == A[2]))
            continue;
        if (seg_tri(P + 3 * r, P + 3 * s, P + 3 * A[0], P + 3 * A[1], P + 3 * A[2])) return 1;
    }
    return 0;
}

static inline int all_finite(size_t n, const double *v) {
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

#endif
