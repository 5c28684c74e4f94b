/* How cheap could an edge-collapse simplifier be at all? meshoptimizer's
 * meshopt_simplify (quadric-ordered collapses, no field to check, a
 * production library's speed) against libblend's meshing and libblend's
 * field-checked simplification of the same mesh, in the same process with
 * the runs alternating (docs/meshing.md, Adaptive simplification): the
 * floor any collapse simplifier sits on, to weigh against what Blender
 * saves on the triangles removed. And the floor of any simplification
 * checked against the field, collapses or not: one evaluation of the field
 * (lb_evaluator_eval, one thread and two) at points a cell apart over the
 * simplified mesh's triangles (each triangle's barycentric lattice of n
 * steps, n its longest edge in cells rounded up, its corners left out:
 * the simplifier's own lattice). Not a test; meshoptimizer is a benchmark
 * dependency only (Debian's libmeshoptimizer-dev).
 *
 * Usage: bench_meshopt SCENE RESOLUTION TOLERANCE [ROUNDS]
 * (one thread; TOLERANCE in cells; prints one JSON line: best-of-ROUNDS
 * seconds of each, triangle counts, meshoptimizer's own error in cells,
 * and the check's points and seconds on one thread and on two) */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>
#include <meshoptimizer.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Points a cell apart over m's triangles into x, y, z (NULL: count only). */
static size_t lattice(const lb_mesh *m, double h, double *x, double *y, double *z) {
    size_t c = 0;
    for (size_t t = 0; t < m->ntriangles; ++t) {
        const double *q[3];
        double L = 0.0;
        for (int k = 0; k < 3; ++k) q[k] = m->positions + 3 * (size_t)m->triangles[3 * t + k];
        for (int k = 0; k < 3; ++k) {
            const double *a = q[k], *b = q[(k + 1) % 3];
            const double d = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                                  (b[2] - a[2]) * (b[2] - a[2]));
            if (d > L) L = d;
        }
        const int n = (int)fmax(1.0, ceil(L / h));
        for (int a = 0; a <= n; ++a)
            for (int b = 0; a + b <= n; ++b) {
                if ((a == 0 && b == 0) || a == n || b == n) continue;
                if (x) {
                    const double wb = (double)a / n, wc = (double)b / n, wa = 1.0 - wb - wc;
                    x[c] = wa * q[0][0] + wb * q[1][0] + wc * q[2][0];
                    y[c] = wa * q[0][1] + wb * q[1][1] + wc * q[2][1];
                    z[c] = wa * q[0][2] + wb * q[1][2] + wc * q[2][2];
                }
                ++c;
            }
    }
    return c;
}

static lb_mesh *mesh(lb_evaluator *ev, const lb_mesh_options *o, double *best) {
    lb_error e = {LB_OK, ""};
    lb_mesh *m = NULL;
    const double t0 = now();
    if (lb_mesh_create(ev, o, &m, &e)) {
        fprintf(stderr, "bench_meshopt: %s\n", e.message);
        exit(1);
    }
    const double t = now() - t0;
    if (t < *best) *best = t;
    return m;
}

int main(int argc, char **argv) {
    if (argc != 4 && argc != 5) {
        fprintf(stderr, "usage: bench_meshopt SCENE RESOLUTION TOLERANCE [ROUNDS]\n");
        return 2;
    }
    const double tol = atof(argv[3]);
    const int rounds = argc == 5 ? atoi(argv[4]) : 5;
    if (rounds < 1) {
        fprintf(stderr, "bench_meshopt: ROUNDS %s: allowed: 1 or more\n", argv[4]);
        return 2;
    }
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    if (lb_scene_load(argv[1], &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "bench_meshopt: %s\n", e.message);
        return 2;
    }
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    o.resolution = (unsigned)atoi(argv[2]);
    o.threads = 1;
    lb_scene_bounds(sc, o.bmin, o.bmax);
    double side = 0.0; /* the region's longest side: resolution cells */
    for (int d = 0; d < 3; ++d)
        if (o.bmax[d] - o.bmin[d] > side) side = o.bmax[d] - o.bmin[d];
    const double h = side / o.resolution;
    lb_mesh_options os = o;
    os.simplify = tol;

    double t_mesh = 1e30, t_simp = 1e30, t_opt = 1e30;
    lb_mesh *m = NULL, *ms = NULL;
    float *pos = NULL;
    unsigned *idx = NULL, *out = NULL;
    size_t nout = 0;
    float opt_err = 0.0f, target = 0.0f, scale = 0.0f;
    for (int r = 0; r < rounds; ++r) {
        lb_mesh_free(m);
        lb_mesh_free(ms);
        m = mesh(ev, &o, &t_mesh);
        ms = mesh(ev, &os, &t_simp);
        if (!pos) { /* the unsimplified mesh as meshoptimizer takes it */
            pos = malloc(sizeof *pos * 3 * m->nvertices);
            idx = malloc(sizeof *idx * 3 * m->ntriangles);
            out = malloc(sizeof *out * 3 * m->ntriangles);
            if (!pos || !idx || !out) return 1;
            for (size_t i = 0; i < 3 * m->nvertices; ++i) pos[i] = (float)m->positions[i];
            for (size_t i = 0; i < 3 * m->ntriangles; ++i) idx[i] = m->triangles[i];
            scale = meshopt_simplifyScale(pos, m->nvertices, 3 * sizeof(float));
            target = (float)(tol * h / scale); /* relative to the mesh's extent */
        }
        const double t0 = now();
        nout = meshopt_simplify(out, idx, 3 * m->ntriangles, pos, m->nvertices, 3 * sizeof(float),
                                0, target, 0, &opt_err);
        const double t = now() - t0;
        if (t < t_opt) t_opt = t;
    }
    /* the field once at the simplified mesh's points, as a check of it would */
    const size_t np = lattice(ms, h, NULL, NULL, NULL);
    double *buf = malloc(sizeof *buf * 7 * (np ? np : 1)), t_check[2] = {1e30, 1e30};
    if (!buf) return 1;
    lattice(ms, h, buf, buf + np, buf + 2 * np);
    for (int r = 0; r < rounds; ++r)
        for (int th = 1; th <= 2; ++th) {
            const double t0 = now();
            if (lb_evaluator_eval(ev, np, buf, buf + np, buf + 2 * np, buf + 3 * np, buf + 4 * np,
                                  buf + 5 * np, buf + 6 * np, th, &e)) {
                fprintf(stderr, "bench_meshopt: %s\n", e.message);
                return 1;
            }
            const double t = now() - t0;
            if (t < t_check[th - 1]) t_check[th - 1] = t;
        }
    free(buf);
    printf("{\"resolution\": %u, \"tolerance_cells\": %g, \"triangles\": %zu, "
           "\"mesh_s\": %.6f, \"libblend_simplify_s\": %.6f, \"libblend_triangles\": %zu, "
           "\"meshopt_s\": %.6f, \"meshopt_triangles\": %zu, \"meshopt_error_cells\": %.4f, "
           "\"check_points\": %zu, \"check_s\": %.6f, \"check_2_threads_s\": %.6f}\n",
           o.resolution, tol, m->ntriangles, t_mesh, t_simp - t_mesh, ms->ntriangles, t_opt,
           nout / 3, opt_err * scale / h, np, t_check[0], t_check[1]);
    free(pos);
    free(idx);
    free(out);
    lb_mesh_free(m);
    lb_mesh_free(ms);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return 0;
}
