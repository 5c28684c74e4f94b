/* Internal declarations shared by libblend's source files. Not installed.
 * Kernels named lb__* skip validation: the public wrappers validate first. */
#ifndef LIBBLEND_INTERNAL_H
#define LIBBLEND_INTERNAL_H

#include "libblend/operators.h"
#include "libblend/primitives.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) && defined(_WIN32)
/* a DLL exports only what is marked dllexport (LB_API); printf is mingw-w64's
 * own C99 one (__USE_MINGW_ANSI_STDIO, set by the build), hence gnu_printf */
#define LB_INTERNAL
#define LB_PRINTF(a, b) __attribute__((format(gnu_printf, a, b)))
#define LB_NOINLINE __attribute__((noinline))
#elif defined(__GNUC__)
#define LB_INTERNAL __attribute__((visibility("hidden")))
#define LB_PRINTF(a, b) __attribute__((format(printf, a, b)))
#define LB_NOINLINE __attribute__((noinline))
#else
#define LB_INTERNAL
#define LB_PRINTF(a, b)
#define LB_NOINLINE
#endif
/* A hot vector kernel also compiled for AVX2, chosen at load time by the
 * CPU (GCC's function multi-versioning, x86-64 Linux): twice the doubles
 * per instruction, and the same bits as the baseline SSE2 code, since the
 * kernels only add, multiply, divide and take square roots element-wise
 * (AVX2 does not bring FMA, and ISO C mode does not contract a * b + c).
 * S2 at 256 cells: 0.964x the time (bench_mesh, 2026-12-02); the 51
 * reference meshes are the same bytes. */
/* Not under the sanitizers: their runtimes are not up yet when the loader
 * runs the clones' resolvers (ThreadSanitizer crashes there); those builds
 * test the baseline clone, the same source. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) &&       \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define LB_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LB_VECTOR_CLONES
#endif

/* Tells GCC that a kernel reads only the first k (parameter n) elements of
 * array parameter ptr, so stack scratch arrays of LB_MAX_ARITY that are
 * filled up to k are not reported as maybe-uninitialised. */
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 10
#define LB_READS(ptr, n) __attribute__((access(read_only, ptr, n)))
#else
#define LB_READS(ptr, n)
#endif

/* ---- local blending's kernels (operators/local.c), unchecked: the
 * compiled evaluator's inner loop; f finite, C > 0, alpha in [0, 1),
 * 0 <= p, q <= LB_BARTHE_MAX_PQ; g receives the two partial derivatives ---- */
LB_INTERNAL double lb__clean_eval(lb_clean_kind kind, const double f[2], double C,
                                  const double alpha[2], double g[2]);
LB_INTERNAL double lb__barthe_eval(const double xy[2], double p, double q, double g[2]);

/* ---- errors and validation (common/error.c) ---- */
LB_INTERNAL lb_status lb__fail(lb_error *err, lb_status status, const char *fmt, ...)
    LB_PRINTF(3, 4);
/* Text into a caller's buffer, snprintf-style: len grows by what the whole
 * text needs, buf (size bytes, may be NULL with size 0) holds what fits,
 * NUL-terminated. The describers' writer (scene, local blends). */
typedef struct lb__text {
    char *buf;
    size_t size, len;
} lb__text;
LB_INTERNAL void lb__text_put(lb__text *b, const char *fmt, ...) LB_PRINTF(2, 3);
LB_INTERNAL lb_status lb__check_k(const char *fn, size_t k, size_t kmin, size_t kmax,
                                  lb_error *err);
LB_INTERNAL lb_status lb__check_finite(const char *fn, const char *name, size_t n, const double *v,
                                       lb_error *err);
/* Each v[i] in the range; bounds are open (strict) unless *_closed is set.
 * Use -INFINITY / INFINITY for no bound. `what` is the human text of the
 * range, e.g. "r > 0". NULL v is an error naming the parameter. */
LB_INTERNAL lb_status lb__check_range(const char *fn, const char *name, size_t n, const double *v,
                                      double lo, int lo_closed, double hi, int hi_closed,
                                      const char *what, lb_error *err);
/* r_i in [LB_MIN_RANGE, min(rmax, LB_MAX_RANGE)] and m_i (m may be NULL) in
 * [mmin, mmax], with messages naming the range. */
LB_INTERNAL lb_status lb__check_r_m(const char *fn, const char *rname, const char *mname, size_t k,
                                    const double *r, const double *m, double rmax, double mmin,
                                    double mmax, lb_error *err);
LB_INTERNAL lb_status lb__check_setop(const char *fn, lb_setop op, lb_error *err);
LB_INTERNAL lb_status lb__check_out(const char *fn, const void *value, lb_error *err);
/* 1 < p_i <= LB_MAX_EXPONENT, with the message naming the range. */
LB_INTERNAL lb_status lb__check_p(const char *fn, size_t k, const double *p, lb_error *err);
/* r in [LB_MIN_RANGE, min(rmax, LB_MAX_RANGE)], 1 < p <= LB_MAX_EXPONENT,
 * m in [LB_MIN_SLOPE, LB_MAX_SLOPE] or NULL. */
LB_INTERNAL lb_status lb__check_blend_params(const char *fn, size_t k, const double *r,
                                             const double *p, const double *m, double rmax,
                                             lb_error *err);
/* x finite, r and m (or NULL) in their accepted ranges, p < r0 r1 (conic shape). */
LB_INTERNAL lb_status lb__check_conic(const char *fn, const double x[2], const double r[2],
                                      double p, const double m[2], const void *value,
                                      lb_error *err);

/* Grow the buffer *p (capacity *cap elements of sz bytes) to hold at least
 * want elements: doubling from 16, contents kept. Returns 0, or -1 when the
 * size overflows or realloc fails (then *p and *cap are unchanged). */
static inline int lb__grow(void **p, size_t *cap, size_t want, size_t sz) {
    if (want <= *cap) return 0;
    size_t c = *cap ? *cap : 16;
    while (c < want) {
        if (c > SIZE_MAX / 2) return -1;
        c *= 2;
    }
    if (sz && c > SIZE_MAX / sz) return -1;
    void *q = realloc(*p, c * sz);
    if (!q) return -1;
    *p = q;
    *cap = c;
    return 0;
}

/* The bits of a double. For doubles >= +0 the bit patterns are ordered like
 * the values, and NaN patterns lie above +inf; negatives have the top bit. */
static inline uint64_t lb__bits(double v) {
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}
/* lo <= v <= hi for 0 < lo <= hi, false for NaN: two integer operations. */
static inline int lb__in_range(double v, double lo, double hi) {
    return lb__bits(v) - lb__bits(lo) <= lb__bits(hi) - lb__bits(lo);
}

/* Cheap validity pre-check for the hot path (no messages): every x_i finite,
 * 0 < r_i <= rmax, 1 < p_i <= LB_MAX_EXPONENT (p may be NULL when the family
 * has none), m_i > 0 finite or m NULL. Callers run the detailed checks only
 * when this fails, to produce the message. */
static inline int lb__fast_ok_n(size_t kmax, size_t k, const double *x, const double *r,
                                const double *p, const double *m, double rmax) {
    if (!x || !r || k == 0 || k > kmax) return 0;
    const double rhi = rmax < LB_MAX_RANGE ? rmax : LB_MAX_RANGE;
    const uint64_t xmax = lb__bits(LB_MAX_ABS_ARG) << 1;
    int ok = 1;
    for (size_t i = 0; i < k; ++i) {
        ok &= lb__bits(x[i]) << 1 <= xmax; /* |x| in range (false for NaN) */
        ok &= lb__in_range(r[i], LB_MIN_RANGE, rhi);
        if (p) ok &= lb__in_range(p[i], 0x1.0000000000001p0, LB_MAX_EXPONENT); /* 1 < p */
        if (m) ok &= lb__in_range(m[i], LB_MIN_SLOPE, LB_MAX_SLOPE);
    }
    return ok;
}
/* The same for operators of at most LB_MAX_ARITY arguments. */
static inline int lb__fast_ok(size_t k, const double *x, const double *r, const double *p,
                              const double *m, double rmax) {
    return lb__fast_ok_n(LB_MAX_ARITY, k, x, r, p, m, rmax);
}

/* How the exponents of one operator call can be evaluated. */
enum { LB__P_GENERAL = 0, LB__P_INTEGER = 1, LB__P_TWO = 2 };

/* The exponent mode of p[0..k-1]: all 2, all integers <= 64, or general.
 * The integer test avoids floor() (a libm call on baseline x86-64); p <= 1000. */
static inline int lb__exponent_mode(size_t k, const double *p) {
    int two = 1, integer = 1;
    for (size_t i = 0; i < k; ++i) {
        two &= p[i] == 2.0;
        integer &= (p[i] <= 64.0) & ((double)(long)p[i] == p[i]);
    }
    return two ? LB__P_TWO : integer ? LB__P_INTEGER : LB__P_GENERAL;
}

/* lb__fast_ok for blend parameters (p required), returning the exponent
 * mode, or -1 when a check fails. */
static inline int lb__fast_mode_n(size_t kmax, size_t k, const double *x, const double *r,
                                  const double *p, const double *m, double rmax) {
    if (!p || !lb__fast_ok_n(kmax, k, x, r, p, m, rmax)) return -1;
    return lb__exponent_mode(k, p);
}

/* |v| of a 3-vector without overflow or underflow of the squares. */
static inline double lb__norm3(const double v[3]) {
    const double s = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    if (!(s > 0.0)) return 0.0;
    const double a = v[0] / s, b = v[1] / s, c = v[2] / s;
    return s * sqrt(a * a + b * b + c * c);
}

/* ---- exponent helpers ---- */
/* t^n for small non-negative integer n by repeated squaring. */
static inline double lb__ipow(double t, unsigned n) {
    double r = 1.0;
    while (n) {
        if (n & 1u) r *= t;
        t *= t;
        n >>= 1u;
    }
    return r;
}

/* t^(p-1) for t >= 0, using products when mode says the exponents are integers. */
static inline double lb__pow_m1(double t, double p, int mode) {
    if (mode != LB__P_GENERAL) return lb__ipow(t, (unsigned)p - 1u);
    return pow(t, p - 1.0);
}

/* The conic base curve of hsu2006 Eq. 4 and its partial derivatives. */
static inline double lb__conic_H(double r1, double r2, double p, double u1, double u2, double *H1,
                                 double *H2) {
    *H1 = 2.0 * (r2 * r2 * (u1 - r1) + p * u2);
    *H2 = 2.0 * (r1 * r1 * (u2 - r2) + p * u1);
    return r2 * r2 * u1 * u1 + r1 * r1 * u2 * u2 + r1 * r1 * r2 * r2 - 2.0 * r2 * r2 * r1 * u1 -
           2.0 * r1 * r1 * r2 * u2 + 2.0 * p * u1 * u2;
}

/* A primitive's field from rho in its convention: rho - 1 or a soft kernel
 * (decreasing in rho). df may be NULL. */
LB_INTERNAL double lb__kernel(lb_kernel kernel, double rho, double *df);

/* ---- kernels (unchecked). Gradient outputs may be NULL. ---- */

/* BT_k union (displacement). m must be non-NULL. dx, dr, dm: d/dx_i, d/dr_i, d/dm_i.
 * k <= LB_MAX_ARITY (NAN beyond); lb__bt_union_ws takes any k with 4k
 * doubles of the caller's scratch, and computes the same bits. */
LB_INTERNAL double lb__bt_union_ws(size_t k, const double *x, const double *r, const double *p,
                                   const double *m, int mode, double *dx, double *dr, double *dm,
                                   double *ws);
LB_INTERNAL LB_READS(2, 1) LB_READS(3, 1) LB_READS(4, 1)
    LB_READS(5, 1) double lb__bt_union(size_t k, const double *x, const double *r, const double *p,
                                       const double *m, int mode, double *dx, double *dr,
                                       double *dm);
/* Same, by the generic safeguarded Newton solver only (no closed form): the
 * reference the p = 2 closed form is tested against. */
LB_INTERNAL double lb__bt_union_newton(size_t k, const double *x, const double *r, const double *p,
                                       const double *m, int mode, double *dx, double *dr,
                                       double *dm);

/* Binary conic union, closed form (and root-solved, for tests). */
LB_INTERNAL double lb__conic_union(const double x[2], const double r[2], double p,
                                   const double m[2], double dx[2], double dr[2], double dm[2]);
LB_INTERNAL double lb__conic_union_solved(const double x[2], const double r[2], double p,
                                          const double m[2], double dx[2]);

/* Scale method: B_A (Min-like) and B_S (Max-like, r <= 1) on soft-domain y.
 * dy, dr: derivatives with respect to y_i and r_i. */
LB_INTERNAL LB_READS(2, 1) double lb__scale_ba(size_t k, const double *y, const double *r,
                                               const double *p, int mode, double *dy, double *dr);
LB_INTERNAL LB_READS(2, 1) double lb__scale_bs(size_t k, const double *y, const double *r,
                                               const double *p, int mode, double *dy, double *dr);
/* Zero-convention B_U / B_I / B_D from them. */
LB_INTERNAL LB_READS(3, 2)
    LB_READS(4, 2) double lb__scale_setop(lb_setop op, size_t k, const double *x, const double *r,
                                          const double *p, int mode, double *dx, double *dr);

/* Zero-convention duality: intersection(x) = -union(-x), difference(x) =
 * -union(-x_0, x_1, ...). Writes x'_i = sign_i x_i; the result is
 * (op == LB_UNION ? 1 : -1) * union(x'), and d/dx_i = sign_i * (that sign) * du/dx'_i. */
LB_INTERNAL void lb__dual_args(lb_setop op, size_t k, const double *x, double *xt, double *sign);

#endif
