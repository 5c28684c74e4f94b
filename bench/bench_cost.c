/* The cost model measured: time per point of scenes with k sibling
 * bulge-eliminated blends (a min of k scale differences of two spheres) and
 * of k transformed copies of one shared def holding such a blend, k = 1 to
 * 256, compiled evaluator, one thread, value + gradient. Reported per row:
 * the model's cost (instruction runs per point), the time per point, and the
 * time per point divided by k against k = 1 in the same run: a flat last
 * column is linear growth (before the cost model, 12 siblings took 23 s for
 * one point and each sibling multiplied the time by about 4.5).
 * usage: bench_cost */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static size_t pair(char *b, size_t n, double x) {
    return (size_t)snprintf(b, n,
                            "{\"type\":\"scale\",\"op\":\"difference\",\"r\":0.3,\"p\":2,"
                            "\"bulge\":{\"range\":true},\"args\":[{\"type\":\"sphere\",\"center\":"
                            "[%g,0,0],\"radius\":0.4},{\"type\":\"sphere\",\"center\":[%g,0,0],"
                            "\"radius\":0.3}]}",
                            x, x + 0.2);
}

static char *scene(int shared, int k) {
    const size_t cap = 512 + (size_t)k * 320;
    char *b = malloc(cap);
    if (!b) return NULL;
    size_t n = (size_t)snprintf(b, cap,
                                "{\"format\":\"libblend-scene\",\"version\":1,"
                                "\"convention\":\"zero\",");
    if (shared) {
        n += (size_t)snprintf(b + n, cap - n, "\"defs\":{\"b\":");
        n += pair(b + n, cap - n, 0.0);
        n += (size_t)snprintf(b + n, cap - n, "},");
    }
    n += (size_t)snprintf(b + n, cap - n, "\"root\":{\"type\":\"min\",\"args\":[");
    for (int i = 0; i < k; ++i) {
        if (i) b[n++] = ',';
        if (shared)
            n +=
                (size_t)snprintf(b + n, cap - n, "{\"ref\":\"b\",\"translate\":[%g,0,0]}", 0.5 * i);
        else
            n += pair(b + n, cap - n, 0.5 * i);
    }
    snprintf(b + n, cap - n, "]}}");
    return b;
}

/* seconds per point, median of 5 rounds over npts points spread along the row */
static double per_point(const lb_evaluator *ev, int k, size_t npts) {
    double *x = malloc(7 * npts * sizeof *x), *y = x + npts, *z = y + npts, *v = z + npts;
    double *gx = v + npts, *gy = gx + npts, *gz = gy + npts;
    for (size_t i = 0; i < npts; ++i) {
        x[i] = -0.5 + (0.5 * k) * (double)i / (double)npts;
        y[i] = 0.3 * (double)(i % 7) / 7.0;
        z[i] = 0.2 * (double)(i % 5) / 5.0;
    }
    double t[5];
    lb_error e = {LB_OK, ""};
    for (int r = 0; r < 5; ++r) {
        const double t0 = now();
        if (lb_evaluator_eval(ev, npts, x, y, z, v, gx, gy, gz, 1, &e)) {
            fprintf(stderr, "%s\n", e.message);
            exit(1);
        }
        t[r] = (now() - t0) / (double)npts;
    }
    free(x);
    for (int i = 0; i < 5; ++i)
        for (int j = i + 1; j < 5; ++j)
            if (t[j] < t[i]) {
                const double s = t[i];
                t[i] = t[j];
                t[j] = s;
            }
    return t[2];
}

int main(void) {
    static const int ks[] = {1, 2, 4, 8, 12, 16, 32, 64, 128, 256};
    printf("| scene | k | instructions | cost (runs/point) | us/point | (us/point)/k vs k = 1 |\n"
           "|---|---|---|---|---|---|\n");
    for (int shared = 0; shared < 2; ++shared) {
        double base = 0.0;
        for (size_t i = 0; i < sizeof ks / sizeof ks[0]; ++i) {
            char *text = scene(shared, ks[i]);
            lb_scene *sc = NULL;
            lb_evaluator *ev = NULL;
            lb_error e = {LB_OK, ""};
            if (!text || lb_scene_parse(text, strlen(text), "bench.json", &sc, &e) ||
                lb_evaluator_create(sc, &ev, &e)) {
                fprintf(stderr, "%s\n", e.message);
                return 1;
            }
            const double t = per_point(ev, ks[i], 20000);
            if (i == 0) base = t;
            printf("| %s | %d | %zu | %.0f | %.2f | %.2f |\n",
                   shared ? "shared def, k copies" : "k siblings", ks[i], lb_evaluator_size(ev),
                   lb_evaluator_cost(ev), 1e6 * t, t / ks[i] / base);
            lb_evaluator_free(ev);
            lb_scene_free(sc);
            free(text);
        }
    }
    return 0;
}
