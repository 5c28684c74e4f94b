/* bench_eval: points per second of the compiled evaluator against the naive
 * recursive tree walk (lb_scene_eval_reference: one point at a time, the
 * public per-family functions at every node), on the 64-sphere scene (S2)
 * and the hsu2006 Fig. 7 scene, 1 and 2 threads. The walk and the compiled
 * evaluator are timed alternately in the same process (wall clock, since
 * threads are involved) and the median per-round ratio is reported.
 *
 * Usage: bench_eval [--quick] SCENE_DIR [SCENE.json...] (default: the five below) */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static uint64_t rs = 987654321;
static double urand(void) {
    rs = rs * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rs >> 11) * 0x1.0p-53;
}

static int cmp(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void bench(const char *dir, const char *file, size_t n, int rounds, int grid) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    lb_scene *sc;
    lb_evaluator *ev;
    lb_error e = {LB_OK, ""};
    if (lb_scene_load(path, &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "bench_eval: %s\n", e.message);
        exit(1);
    }
    double lo[3], hi[3];
    lb_scene_bounds(sc, lo, hi);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *z = malloc(n * sizeof *z);
    double *v = malloc(n * sizeof *v), *gx = malloc(n * sizeof *gx), *gy = malloc(n * sizeof *gy),
           *gz = malloc(n * sizeof *gz);
    if (grid) {
        /* a regular grid over the bounds in scan order (x fastest): how a
         * mesher or a renderer asks */
        size_t g = 1;
        while ((g + 1) * (g + 1) * (g + 1) <= n) ++g;
        n = g * g * g;
        for (size_t i = 0; i < n; ++i) {
            x[i] = lo[0] + (hi[0] - lo[0]) * ((double)(i % g) + 0.5) / (double)g;
            y[i] = lo[1] + (hi[1] - lo[1]) * ((double)(i / g % g) + 0.5) / (double)g;
            z[i] = lo[2] + (hi[2] - lo[2]) * ((double)(i / g / g) + 0.5) / (double)g;
        }
    } else {
        /* random points in the scene's bounds, in random order */
        for (size_t i = 0; i < n; ++i) {
            x[i] = lo[0] + (hi[0] - lo[0]) * urand();
            y[i] = lo[1] + (hi[1] - lo[1]) * urand();
            z[i] = lo[2] + (hi[2] - lo[2]) * urand();
        }
    }
    double r1[64], r2[64], naive_pps[64], c1_pps[64], c2_pps[64];
    double checksum = 0.0;
    for (int r = 0; r < rounds; ++r) {
        double t0 = now();
        for (size_t i = 0; i < n; ++i) {
            const double X[3] = {x[i], y[i], z[i]};
            double g[3], val;
            lb_scene_eval_reference(sc, X, &val, g, NULL);
            checksum += val;
        }
        double t1 = now();
        lb_evaluator_eval(ev, n, x, y, z, v, gx, gy, gz, 1, NULL);
        double t2 = now();
        lb_evaluator_eval(ev, n, x, y, z, v, gx, gy, gz, 2, NULL);
        double t3 = now();
        checksum += v[n / 2];
        naive_pps[r] = (double)n / (t1 - t0);
        c1_pps[r] = (double)n / (t2 - t1);
        c2_pps[r] = (double)n / (t3 - t2);
        r1[r] = (t1 - t0) / (t2 - t1);
        r2[r] = (t1 - t0) / (t3 - t2);
    }
    qsort(r1, (size_t)rounds, sizeof *r1, cmp);
    qsort(r2, (size_t)rounds, sizeof *r2, cmp);
    qsort(naive_pps, (size_t)rounds, sizeof(double), cmp);
    qsort(c1_pps, (size_t)rounds, sizeof(double), cmp);
    qsort(c2_pps, (size_t)rounds, sizeof(double), cmp);
    const int m = rounds / 2;
    printf("%-6s %-28s %4zu instr | naive %9.0f pts/s | compiled 1 thread %10.0f pts/s (%5.2fx) | "
           "2 threads %10.0f pts/s (%5.2fx)   [checksum %.3g]\n",
           grid ? "grid" : "random", file, lb_evaluator_size(ev), naive_pps[m], c1_pps[m], r1[m],
           c2_pps[m], r2[m], checksum);
    free(x);
    free(y);
    free(z);
    free(v);
    free(gx);
    free(gy);
    free(gz);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
}

int main(int argc, char **argv) {
    int quick = 0;
    const char *dir = NULL;
    const char *chosen[32];
    size_t nchosen = 0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (!dir)
            dir = argv[i];
        else if (nchosen < 32)
            chosen[nchosen++] = argv[i];
    }
    if (!dir) {
        fprintf(stderr, "usage: bench_eval [--quick] SCENE_DIR [SCENE.json...]\n");
        return 2;
    }
    const size_t n = quick ? 4096 : 100000;
    const int rounds = quick ? 3 : 9;
    printf("bench_eval: %zu points in the scene bounds (random order, then a grid in scan order), "
           "median of %d alternating rounds; ratio = compiled speed / naive walk speed\n",
           n, rounds);
    static const char *const defaults[] = {
        "bench-s2-64-spheres.json", "hsu2006-fig7-m0.6.json", "bench-s1-three-spheres.json",
        "hsu-bounded-fig7-stool.json", "hsu-nonuniform-fig6-m0.65.json"};
    const char *const *scenes = nchosen ? chosen : defaults;
    const size_t nscenes = nchosen ? nchosen : sizeof defaults / sizeof defaults[0];
    for (int grid = 0; grid < 2; ++grid)
        for (size_t i = 0; i < nscenes; ++i) bench(dir, scenes[i], n, rounds, grid);
    return 0;
}
