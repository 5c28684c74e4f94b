/* Local blending's speed, in one run (issue 13's bars):
 * - compile time of a local_union of two spheres (curves, refinement,
 *   parameters, BVH), and of a five-capsule figure's fold of local unions;
 * - evaluation (value + gradient, compiled evaluator, one thread) of two
 *   spheres under local_union over the scene's bounds, against the same
 *   spheres under clean_union;
 * - meshing the drop scene at 256 cells (one thread) against its clean union.
 * Medians of 7 rounds; candidate and baseline alternate.
 * usage: bench_local */
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

static int cmpd(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, cmpd);
    return v[n / 2];
}

static lb_scene *parse(const char *t) {
    lb_scene *s = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(t, strlen(t), "bench.json", &s, &e)) {
        fprintf(stderr, "%s\n", e.message);
        exit(1);
    }
    return s;
}

static lb_evaluator *compile(const lb_scene *s) {
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_evaluator_create(s, &ev, &e)) {
        fprintf(stderr, "%s\n", e.message);
        exit(1);
    }
    return ev;
}

static const char *TWO =
    "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"soft\","
    "\"bounds\":{\"min\":[-2,-2,-2],\"max\":[3,2,2]},\"root\":{\"type\":\"%s\","
    "\"args\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},"
    "{\"type\":\"sphere\",\"center\":[1.2,0,0],\"radius\":0.8}]}}";

static const char *FIGURE =
    "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"soft\","
    "\"bounds\":{\"min\":[-1.5,-2.5,-1],\"max\":[1.5,1.8,1]},\"root\":{\"type\":\"local_union\","
    "\"args\":[{\"type\":\"capsule\",\"start\":[0,-0.8,0],\"end\":[0,0.8,0],\"radius\":0.35},"
    "{\"type\":\"sphere\",\"center\":[0,1.25,0],\"radius\":0.4},"
    "{\"type\":\"capsule\",\"start\":[-0.2,0.5,0],\"end\":[-1.1,-0.3,0],\"radius\":0.15},"
    "{\"type\":\"capsule\",\"start\":[0.2,0.5,0],\"end\":[1.1,-0.3,0],\"radius\":0.15},"
    "{\"type\":\"capsule\",\"start\":[-0.15,-0.7,0],\"end\":[-0.3,-2.2,0],\"radius\":0.18},"
    "{\"type\":\"capsule\",\"start\":[0.15,-0.7,0],\"end\":[0.3,-2.2,0],\"radius\":0.18}]}}";

static const char *DROP =
    "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"soft\","
    "\"bounds\":{\"min\":[-1.5,-1,-1.5],\"max\":[1.5,1.5,1.5]},\"root\":{"
    "\"type\":\"%s\",\"args\":[{\"type\":\"sphere\",\"center\":[0,0.3,0],"
    "\"radius\":0.5},{\"type\":\"sphere\",\"center\":[0,-5,0],\"radius\":5}]}}";

static double compile_ms(const char *text) {
    lb_scene *s = parse(text);
    double t[7];
    for (int r = 0; r < 7; ++r) {
        const double t0 = now();
        lb_evaluator *ev = compile(s);
        t[r] = 1e3 * (now() - t0);
        lb_evaluator_free(ev);
    }
    lb_scene_free(s);
    return median(t, 7);
}

int main(void) {
    char local[2048], clean[2048];
    snprintf(local, sizeof local, TWO, "local_union");
    snprintf(clean, sizeof clean, TWO, "clean_union");
    printf("compile, two spheres: %.2f ms (bar 10 ms)\n", compile_ms(local));
    printf("compile, five-capsule figure (5 local blends): %.2f ms (bar 100 ms for its largest)\n",
           compile_ms(FIGURE));

    /* evaluation over the bounds */
    const size_t n = 1000000;
    double *x = malloc(7 * n * sizeof *x), *y = x + n, *z = y + n, *v = z + n, *gx = v + n,
           *gy = gx + n, *gz = gy + n;
    srand(1);
    for (size_t i = 0; i < n; ++i) {
        x[i] = -2.0 + 5.0 * rand() / (double)RAND_MAX;
        y[i] = -2.0 + 4.0 * rand() / (double)RAND_MAX;
        z[i] = -2.0 + 4.0 * rand() / (double)RAND_MAX;
    }
    lb_scene *sl = parse(local), *sc = parse(clean);
    lb_evaluator *el = compile(sl), *ec = compile(sc);
    double tl[7], tc[7];
    lb_error e = {LB_OK, ""};
    for (int r = 0; r < 7; ++r) {
        double t0 = now();
        lb_evaluator_eval(el, n, x, y, z, v, gx, gy, gz, 1, &e);
        tl[r] = now() - t0;
        t0 = now();
        lb_evaluator_eval(ec, n, x, y, z, v, gx, gy, gz, 1, &e);
        tc[r] = now() - t0;
    }
    const double ml = median(tl, 7), mc = median(tc, 7);
    printf("evaluate, two spheres, 1 thread: local_union %.3g points/s, clean_union %.3g "
           "points/s: local at %.2fx the clean union's speed (bars 1e7 points/s, 0.5x)\n",
           n / ml, n / mc, mc / ml);
    lb_evaluator_free(el);
    lb_evaluator_free(ec);
    lb_scene_free(sl);
    lb_scene_free(sc);
    free(x);

    /* meshing the drop at 256 cells */
    snprintf(local, sizeof local, DROP, "local_union");
    snprintf(clean, sizeof clean, DROP, "clean_union");
    sl = parse(local);
    sc = parse(clean);
    el = compile(sl);
    ec = compile(sc);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    lb_scene_bounds(sl, o.bmin, o.bmax);
    o.resolution = 256;
    o.threads = 1;
    for (int r = 0; r < 7; ++r) {
        lb_mesh *m = NULL;
        double t0 = now();
        lb_mesh_create(el, &o, &m, &e);
        tl[r] = now() - t0;
        lb_mesh_free(m);
        t0 = now();
        lb_mesh_create(ec, &o, &m, &e);
        tc[r] = now() - t0;
        lb_mesh_free(m);
    }
    printf("mesh the drop at 256 cells, 1 thread: local_union %.3f s, clean_union %.3f s: "
           "%.2fx (bar 2x)\n",
           median(tl, 7), median(tc, 7), median(tl, 7) / median(tc, 7));
    lb_evaluator_free(el);
    lb_evaluator_free(ec);
    lb_scene_free(sl);
    lb_scene_free(sc);
    return 0;
}
