/* Meshing benchmark, one configuration per process (so peak memory is this
 * run's): loads a scene, meshes it over a region at a resolution with a
 * thread count, and prints one JSON line: wall time of lb_mesh_create
 * (best of ROUNDS), triangles, vertices, peak RSS and RSS before meshing.
 * bench/mesh/run_mesh_bench.py runs it next to the anchors.
 *
 * Usage: bench_mesh SCENE RESOLUTION THREADS [x0 y0 z0 x1 y1 z1]
 *                   [--features | --corner-normals] [--simplify TOL]
 * (--features: LB_MESH_FEATURES, sharp creases and corners; --corner-normals:
 * also LB_MESH_CORNER_NORMALS; --simplify: lb_mesh_options.simplify, cells;
 * the options come last) */
#define _POSIX_C_SOURCE 200809L
#include "bench_args.h"

#include <libblend/libblend.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static long rss_kb(void) { /* current resident set, from /proc */
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2) res = 0;
        fclose(f);
    }
    return res * 4;
}

int main(int argc, char **argv) {
    unsigned flags = 0;
    double simplify = 0.0;
    bench_mesh_args(&argc, argv, &flags, &simplify);
    if (argc != 4 && argc != 10) {
        fprintf(stderr, "usage: bench_mesh SCENE RESOLUTION THREADS [x0 y0 z0 x1 y1 z1] "
                        "[--features | --corner-normals] [--simplify TOL] [--coarse-first]\n");
        return 2;
    }
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    if (lb_scene_load(argv[1], &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "bench_mesh: %s\n", e.message);
        return 2;
    }
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    o.resolution = (unsigned)atoi(argv[2]);
    o.threads = atoi(argv[3]);
    o.flags = flags;
    o.simplify = simplify;
    if (argc == 10)
        for (int d = 0; d < 3; ++d) {
            o.bmin[d] = atof(argv[4 + d]);
            o.bmax[d] = atof(argv[7 + d]);
        }
    else
        lb_scene_bounds(sc, o.bmin, o.bmax);
    const long before = rss_kb();
    double best = 1e30;
    lb_mesh *m = NULL;
    for (int r = 0; r < 3; ++r) {
        lb_mesh_free(m);
        m = NULL;
        const double t0 = now();
        if (lb_mesh_create(ev, &o, &m, &e)) {
            fprintf(stderr, "bench_mesh: %s\n", e.message);
            return 1;
        }
        const double t = now() - t0;
        if (t < best) best = t;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("{\"tool\": \"libblend\", \"threads\": %d, \"resolution\": %u, \"seconds\": %.6f, "
           "\"triangles\": %zu, \"vertices\": %zu, \"peak_rss_kb\": %ld, \"rss_before_kb\": %ld}\n",
           o.threads, o.resolution, best, m->ntriangles, m->nvertices, ru.ru_maxrss, before);
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return 0;
}
