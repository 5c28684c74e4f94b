/* bench_platform: the same work through libblend's public API, built for
 * Linux (libblend.so) and for Windows (libblend.dll, run under Wine), so
 * that bench/run_wine_bench.sh can set the two side by side on one machine.
 *
 * Each row is a fixed amount of work timed by the wall clock (the
 * platform's monotonic clock: clock_gettime on POSIX, QueryPerformanceCounter
 * on Windows; Wine's process CPU clock ticks in 15.6 ms steps), repeated
 * REPS times; the row prints its shortest time, the least disturbed by
 * other load. The operator rows call one family's function on fixed
 * pseudo-random arguments near the blend (the same numbers on both
 * systems); the scene rows evaluate and mesh the scene file given, on one
 * thread and on two.
 *
 * usage: bench_platform SCENE.json [--quick]
 * prints: one line per row, "NAME SECONDS CHECKSUM" (the checksum makes the
 * compiler keep the work, and shows both systems computed the same) */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L
#endif
#include <libblend/libblend.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
static double now(void) {
    LARGE_INTEGER f, t;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&t);
    return (double)t.QuadPart / (double)f.QuadPart;
}
#else
#include <time.h>
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#endif

#define NV 2048 /* argument vectors per pass */

static uint64_t rs = 12345;
static double urand(void) {
    rs = rs * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rs >> 11) * 0x1.0p-53;
}

static double X[NV][6], R[6], P[6], M[6];

static void make(size_t k, double p) {
    for (size_t i = 0; i < k; ++i) {
        R[i] = 0.5 + 0.5 * urand();
        P[i] = p;
        M[i] = 0.7 + 0.6 * urand();
    }
    for (int n = 0; n < NV; ++n) {
        const double h0 = 4.0 * urand() - 2.0;
        for (size_t i = 0; i < k; ++i) X[n][i] = M[i] * h0 + (1.3 * urand() - 0.2) * R[i];
    }
}

typedef enum { DISP, CONIC, SCALE, SOFT } family;

/* one pass over the NV vectors; returns the sum of the values */
static double pass(family f, size_t k) {
    double s = 0.0, v, g[6];
    lb_error e;
    for (int n = 0; n < NV; ++n) {
        lb_status st = LB_OK;
        switch (f) {
        case DISP:
            st = lb_displacement(LB_UNION, k, X[n], R, P, M, &v, g, &e);
            break;
        case CONIC:
            st = lb_conic(LB_UNION, X[n], R, 0.1, M, &v, g, &e);
            break;
        case SCALE:
            st = lb_scale(LB_UNION, k, X[n], R, P, &v, g, &e);
            break;
        case SOFT: {
            double x[6], r[6];
            for (size_t i = 0; i < k; ++i) { /* Max-like: 0 < r <= 1, values near 0.5 */
                x[i] = 0.5 + 0.25 * X[n][i];
                r[i] = 0.5 * R[i];
            }
            st = lb_soft_hyper(LB_UNION, k, x, r, P, M, &v, g, &e);
            break;
        }
        }
        if (st != LB_OK) {
            fprintf(stderr, "bench_platform: %s\n", e.message);
            exit(1);
        }
        s += v;
    }
    return s;
}

static int REPS = 5;

/* the C runtime alone: pow() and exp() over the same numbers (msvcrt's under
 * Wine, glibc's on Linux), and plain arithmetic beside them */
static void row_libm(const char *name, int which, int passes) {
    make(2, 2.0);
    double best = INFINITY, sum = 0.0;
    for (int r = 0; r < REPS; ++r) {
        sum = 0.0;
        const double t0 = now();
        for (int i = 0; i < passes; ++i)
            for (int n = 0; n < NV; ++n) {
                const double a = fabs(X[n][0]) + 0.5, b = X[n][1] + 0.001 * i;
                sum += which == 0 ? pow(a, b) : which == 1 ? exp(b) : a * b + a / (b + 3.0);
            }
        const double t = now() - t0;
        if (t < best) best = t;
    }
    printf("%s %.6f %.17g\n", name, best, sum);
}

static void row_op(const char *name, family f, size_t k, double p, int passes) {
    make(k, p);
    double best = INFINITY, sum = 0.0;
    for (int r = 0; r < REPS; ++r) {
        sum = 0.0;
        const double t0 = now();
        for (int i = 0; i < passes; ++i) sum += pass(f, k);
        const double t = now() - t0;
        if (t < best) best = t;
    }
    printf("%s %.6f %.17g\n", name, best, sum);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: bench_platform SCENE.json [--quick]\n");
        return 2;
    }
    const int quick = argc > 2 && strcmp(argv[2], "--quick") == 0;
    if (quick) REPS = 2;
    const int ops = quick ? 20 : 500;
    row_op("displacement_k2_p2", DISP, 2, 2.0, ops);
    row_op("displacement_k6_p2.5", DISP, 6, 2.5, ops / 4);
    row_op("conic_k2", CONIC, 2, 2.0, ops);
    row_op("scale_k4_p3", SCALE, 4, 3.0, ops / 2);
    row_op("soft_hyper_k2", SOFT, 2, 2.5, ops / 4);
    row_libm("crt_pow", 0, ops);
    row_libm("crt_exp", 1, ops);
    row_libm("arithmetic", 2, ops);

    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_error e;
    if (lb_scene_load(argv[1], &sc, &e) != LB_OK || lb_evaluator_create(sc, &ev, &e) != LB_OK) {
        fprintf(stderr, "bench_platform: %s: %s\n", argv[1], e.message);
        return 1;
    }
    double bmin[3], bmax[3];
    lb_scene_bounds(sc, bmin, bmax);
    const size_t n = quick ? 20000 : 500000;
    double *buf = malloc(4 * n * sizeof *buf);
    if (!buf) return 1;
    double *x = buf, *y = buf + n, *z = buf + 2 * n, *v = buf + 3 * n;
    for (size_t i = 0; i < n; ++i) {
        x[i] = bmin[0] + (bmax[0] - bmin[0]) * urand();
        y[i] = bmin[1] + (bmax[1] - bmin[1]) * urand();
        z[i] = bmin[2] + (bmax[2] - bmin[2]) * urand();
    }
    for (int threads = 1; threads <= 2; ++threads) {
        double best = INFINITY, sum = 0.0;
        for (int r = 0; r < REPS; ++r) {
            const double t0 = now();
            if (lb_evaluator_eval(ev, n, x, y, z, v, NULL, NULL, NULL, threads, &e) != LB_OK) {
                fprintf(stderr, "bench_platform: eval: %s\n", e.message);
                return 1;
            }
            const double t = now() - t0;
            if (t < best) best = t;
            sum = 0.0;
            for (size_t i = 0; i < n; ++i) sum += v[i];
        }
        printf("scene_eval_%dthread %.6f %.17g\n", threads, best, sum);
    }
    for (int threads = 1; threads <= 2; ++threads) {
        lb_mesh_options o;
        lb_mesh_options_init(&o);
        memcpy(o.bmin, bmin, sizeof bmin);
        memcpy(o.bmax, bmax, sizeof bmax);
        o.resolution = quick ? 32 : 128;
        o.threads = threads;
        double best = INFINITY;
        size_t tris = 0;
        for (int r = 0; r < REPS; ++r) {
            lb_mesh *m = NULL;
            const double t0 = now();
            if (lb_mesh_create(ev, &o, &m, &e) != LB_OK) {
                fprintf(stderr, "bench_platform: mesh: %s\n", e.message);
                return 1;
            }
            const double t = now() - t0;
            if (t < best) best = t;
            tris = m->ntriangles;
            lb_mesh_free(m);
        }
        printf("mesh_%u_%dthread %.6f %zu\n", o.resolution, threads, best, tris);
    }
    free(buf);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return 0;
}
