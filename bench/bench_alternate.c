/* Meshing times of several builds and flag sets in one process, alternated
 * round by round: on a shared machine whose speed drifts between runs (and
 * between processes started seconds apart), every configuration meets the
 * same drift. Each configuration names a libblend shared library (loaded
 * with dlopen, its own symbols kept local) and the lb_mesh_options flags to
 * mesh with; the scene is loaded and compiled by each library once, then
 * every round meshes it once per configuration in the order given, on one
 * thread over the scene's bounds. Prints, per configuration, the minimum,
 * lower quartile and median of the rounds' wall times of lb_mesh_create,
 * and each against the first configuration's (min, quartile, median):
 * one JSON line each.
 *
 * Usage: bench_alternate SCENE RESOLUTION ROUNDS LIB[@FLAGS]...
 * (FLAGS: a number, lb_mesh_options.flags; e.g. 4 = LB_MESH_FEATURES).
 * bench/run_features_bench.sh runs it with the mesher before features and
 * the current one. */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include <dlfcn.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef lb_status (*load_fn)(const char *, lb_scene **, lb_error *);
typedef lb_status (*compile_fn)(const lb_scene *, lb_evaluator **, lb_error *);
typedef void (*init_fn)(lb_mesh_options *);
typedef void (*bounds_fn)(const lb_scene *, double *, double *);
typedef lb_status (*mesh_fn)(const lb_evaluator *, const lb_mesh_options *, lb_mesh **, lb_error *);
typedef void (*free_fn)(lb_mesh *);

typedef struct config {
    const char *name;
    lb_evaluator *ev;
    lb_mesh_options o;
    mesh_fn mesh;
    free_fn mesh_free;
} config;

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* a function of the library, by name; exits with a message when missing */
static void *symbol(void *lib, const char *path, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) {
        fprintf(stderr, "bench_alternate: %s has no %s\n", path, name);
        exit(2);
    }
    return f;
}

int main(int argc, char **argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: bench_alternate SCENE RESOLUTION ROUNDS LIB[@FLAGS]...\n");
        return 2;
    }
    const int nc = argc - 4, rounds = atoi(argv[3]);
    const unsigned res = (unsigned)atoi(argv[2]);
    if (rounds < 1 || res < 1) {
        fprintf(stderr, "bench_alternate: RESOLUTION and ROUNDS must be at least 1\n");
        return 2;
    }
    /* glibc raises its mmap threshold to the size of the largest mapped
     * block freed so far, process-wide: a configuration that frees a large
     * array (corner normals) would move the next ones' arrays from fresh
     * mappings to the heap. Fixed at its default, every configuration
     * allocates as it would in a process of its own. */
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    config *C = calloc((size_t)nc, sizeof *C);
    double *t = malloc((size_t)nc * (size_t)rounds * sizeof *t);
    if (!C || !t) return 1;
    for (int i = 0; i < nc; ++i) {
        char path[4096];
        snprintf(path, sizeof path, "%s", argv[4 + i]);
        char *at = strrchr(path, '@');
        unsigned flags = 0;
        if (at) {
            *at = '\0';
            flags = (unsigned)strtoul(at + 1, NULL, 0);
        }
        void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!lib) {
            fprintf(stderr, "bench_alternate: %s\n", dlerror());
            return 2;
        }
        const load_fn load = (load_fn)symbol(lib, path, "lb_scene_load");
        const compile_fn compile = (compile_fn)symbol(lib, path, "lb_evaluator_create");
        const init_fn init = (init_fn)symbol(lib, path, "lb_mesh_options_init");
        const bounds_fn bounds = (bounds_fn)symbol(lib, path, "lb_scene_bounds");
        C[i].name = argv[4 + i];
        C[i].mesh = (mesh_fn)symbol(lib, path, "lb_mesh_create");
        C[i].mesh_free = (free_fn)symbol(lib, path, "lb_mesh_free");
        lb_error e = {LB_OK, ""};
        lb_scene *sc = NULL;
        if (load(argv[1], &sc, &e) || compile(sc, &C[i].ev, &e)) {
            fprintf(stderr, "bench_alternate: %s: %s\n", C[i].name, e.message);
            return 2;
        }
        init(&C[i].o);
        C[i].o.resolution = res;
        C[i].o.threads = 1;
        C[i].o.flags = flags;
        bounds(sc, C[i].o.bmin, C[i].o.bmax);
    }
    for (int r = 0; r < rounds; ++r)
        for (int i = 0; i < nc; ++i) {
            lb_mesh *m = NULL;
            lb_error e = {LB_OK, ""};
            const double t0 = now();
            if (C[i].mesh(C[i].ev, &C[i].o, &m, &e)) {
                fprintf(stderr, "bench_alternate: %s: %s\n", C[i].name, e.message);
                return 1;
            }
            t[(size_t)i * (size_t)rounds + (size_t)r] = now() - t0;
            C[i].mesh_free(m);
        }
    double first[3] = {0, 0, 0};
    for (int i = 0; i < nc; ++i) {
        double *ti = t + (size_t)i * (size_t)rounds;
        qsort(ti, (size_t)rounds, sizeof *ti, by_value);
        const double q[3] = {ti[0], ti[rounds / 4], ti[rounds / 2]};
        if (i == 0) memcpy(first, q, sizeof q);
        printf("{\"config\": \"%s\", \"rounds\": %d, \"min\": %.6f, \"q25\": %.6f, \"median\": "
               "%.6f, \"ratio_min\": %.4f, \"ratio_q25\": %.4f, \"ratio_median\": %.4f}\n",
               C[i].name, rounds, q[0], q[1], q[2], q[0] / first[0], q[1] / first[1],
               q[2] / first[2]);
    }
    return 0;
}
