/* Incremental remeshing benchmark (lb_mesh_cache), one configuration per
 * process: scene BEFORE is meshed through a cache, then scene AFTER (an
 * edit of it) is meshed through that cache (incremental) and without it
 * (full), alternating, best of ROUNDS each. The incremental run is
 * timed twice: with the previous mesh given back to the cache
 * (lb_mesh_cache_recycle, as the Blender add-on's live update does: the
 * output goes into memory already mapped) and with it freed. Prints one
 * JSON line: the times and the ratio of the first to the full time, the blocks and how many came
 * from the cache, the cache's memory, the evaluator's compile time (a live update pays it too)
 * fresh and against the previous evaluator (lb_evaluator_create_reusing:
 * local unions above the edit only), and whether both meshes are the same
 * bytes.
 * bench/incremental/run_incremental_bench.py runs it.
 *
 * Usage: bench_incremental BEFORE AFTER RESOLUTION THREADS
 *                          [--features | --corner-normals] [--simplify TOL [--coarse-first]] */
#define _POSIX_C_SOURCE 200809L
#include "bench_args.h"

#include <libblend/libblend.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define ROUNDS 5

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int same(const lb_mesh *a, const lb_mesh *b) {
    return a->nvertices == b->nvertices && a->ntriangles == b->ntriangles &&
           !memcmp(a->positions, b->positions, 3 * a->nvertices * sizeof(double)) &&
           !memcmp(a->normals, b->normals, 3 * a->nvertices * sizeof(double)) &&
           !memcmp(a->triangles, b->triangles, 3 * a->ntriangles * sizeof(uint32_t));
}

int main(int argc, char **argv) {
    unsigned flags = 0;
    double simplify = 0.0;
    bench_mesh_args(&argc, argv, &flags, &simplify);
    if (argc != 5) {
        fprintf(stderr, "usage: bench_incremental BEFORE AFTER RESOLUTION THREADS "
                        "[--features | --corner-normals] [--simplify TOL [--coarse-first]]\n");
        return 2;
    }
    lb_error e = {LB_OK, ""};
    lb_scene *s0 = NULL, *s1 = NULL;
    lb_evaluator *e0 = NULL, *e1 = NULL;
    if (lb_scene_load(argv[1], &s0, &e) || lb_evaluator_create(s0, &e0, &e) ||
        lb_scene_load(argv[2], &s1, &e)) {
        fprintf(stderr, "bench_incremental: %s\n", e.message);
        return 2;
    }
    double compile = 1e30;
    for (int r = 0; r < ROUNDS; ++r) {
        lb_evaluator_free(e1);
        e1 = NULL;
        const double t = now();
        if (lb_evaluator_create(s1, &e1, &e)) {
            fprintf(stderr, "bench_incremental: %s\n", e.message);
            return 2;
        }
        if (now() - t < compile) compile = now() - t;
    }
    /* the same evaluator compiled against the previous one (local unions
     * whose children did not change copy their curves) */
    double recompile = 1e30;
    size_t recopied = 0;
    for (int r = 0; r < ROUNDS; ++r) {
        lb_evaluator *er = NULL;
        const double t = now();
        if (lb_evaluator_create_reusing(s1, e0, &er, &recopied, &e)) {
            fprintf(stderr, "bench_incremental: %s\n", e.message);
            return 2;
        }
        if (now() - t < recompile) recompile = now() - t;
        lb_evaluator_free(er);
    }
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    lb_scene_bounds(s0, o.bmin, o.bmax);
    o.resolution = (unsigned)atoi(argv[3]);
    o.threads = atoi(argv[4]);
    o.flags = flags;
    o.simplify = simplify;
    double full = 1e30, inc = 1e30, fresh = 1e30;
    lb_mesh *mf = NULL, *mi = NULL, *mn = NULL;
    lb_mesh_cache_stats st = {0, 0, 0, 0};
    for (int r = 0; r < ROUNDS; ++r) {
        lb_mesh_free(mf);
        lb_mesh_free(mi);
        lb_mesh_free(mn);
        mf = mi = mn = NULL;
        for (int give = 1; give >= 0; --give) {
            lb_mesh_cache *cache = NULL;
            lb_mesh *m0 = NULL, *m1 = NULL;
            if (lb_mesh_cache_create(&cache, &e) || lb_mesh_create_cached(e0, &o, cache, &m0, &e)) {
                fprintf(stderr, "bench_incremental: %s\n", e.message);
                return 2;
            }
            if (give)
                lb_mesh_cache_recycle(cache, m0);
            else
                lb_mesh_free(m0);
            const double t = now();
            if (lb_mesh_create_cached(e1, &o, cache, &m1, &e)) {
                fprintf(stderr, "bench_incremental: %s\n", e.message);
                return 2;
            }
            const double dt = now() - t;
            if (give) {
                inc = dt < inc ? dt : inc;
                mi = m1;
                lb_mesh_cache_stats_get(cache, &st);
            } else {
                fresh = dt < fresh ? dt : fresh;
                mn = m1;
            }
            lb_mesh_cache_free(cache);
        }
        const double t = now();
        if (lb_mesh_create(e1, &o, &mf, &e)) {
            fprintf(stderr, "bench_incremental: %s\n", e.message);
            return 2;
        }
        if (now() - t < full) full = now() - t;
    }
    printf("{\"full_s\": %.6f, \"incremental_s\": %.6f, \"ratio\": %.4f, "
           "\"incremental_freed_s\": %.6f, \"ratio_freed\": %.4f, \"blocks\": %zu, "
           "\"reused\": %zu, \"cache_mib\": %.2f, \"compile_s\": %.6f, \"compile_reusing_s\": "
           "%.6f, \"curves_copied\": %zu, \"triangles\": %zu, \"same\": %s}\n",
           full, inc, inc / full, fresh, fresh / full, st.blocks, st.reused,
           (double)st.bytes / 1048576.0, compile, recompile, recopied, mf->ntriangles,
           same(mf, mi) && same(mf, mn) ? "true" : "false");
    lb_mesh_free(mf);
    lb_mesh_free(mi);
    lb_mesh_free(mn);
    lb_evaluator_free(e0);
    lb_evaluator_free(e1);
    lb_scene_free(s0);
    lb_scene_free(s1);
    return 0;
}
