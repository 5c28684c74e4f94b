/* A program built against libblend inside the Debian 11 root (glibc 2.31)
 * and run there against the libblend.so built on this machine
 * (tests/portability/test_portable_so.sh): what an artist or a farm node on
 * an older Linux does first. It touches the parts of the library whose glibc
 * symbols were bound to old versions (src/common/glibc_compat.h): the math
 * functions, threads, fstat (lb_scene_load) and lstat (lb_mesh_write).
 *   old_glibc_consumer SCENE.json OUT_DIR */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int fail(const char *what, const lb_error *e) {
    fprintf(stderr, "old_glibc_consumer: %s: %s\n", what, e ? e->message : "");
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 3) return fail("usage: old_glibc_consumer SCENE.json OUT_DIR", NULL);
    lb_error e;

    /* a sphere of radius 0.75 at (0.5, -0.25, 0): in the zero convention its
     * field is |X - c| / r - 1 (docs/scene-format.md), on two threads */
    static const char sphere[] =
        "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\","
        " \"bounds\": {\"min\": [-2, -2, -2], \"max\": [2, 2, 2]},"
        " \"root\": {\"type\": \"sphere\", \"center\": [0.5, -0.25, 0], \"radius\": 0.75}}";
    lb_scene *s = NULL;
    lb_evaluator *ev = NULL;
    if (lb_scene_parse(sphere, strlen(sphere), "sphere", &s, &e) != LB_OK) return fail("parse", &e);
    if (lb_evaluator_create(s, &ev, &e) != LB_OK) return fail("compile", &e);
    enum { N = 4096 };
    static double x[N], y[N], z[N], v[N];
    for (int i = 0; i < N; ++i) {
        x[i] = -1.9 + 3.8 * (i % 16) / 15.0;
        y[i] = -1.9 + 3.8 * ((i / 16) % 16) / 15.0;
        z[i] = -1.9 + 3.8 * (i / 256) / 15.0;
    }
    if (lb_evaluator_eval(ev, N, x, y, z, v, NULL, NULL, NULL, 2, &e) != LB_OK)
        return fail("eval", &e);
    double worst = 0;
    for (int i = 0; i < N; ++i) {
        const double dx = x[i] - 0.5, dy = y[i] + 0.25, dz = z[i];
        const double d = fabs(v[i] - (sqrt(dx * dx + dy * dy + dz * dz) / 0.75 - 1.0));
        if (d > worst) worst = d;
    }
    if (!(worst < 1e-12)) {
        fprintf(stderr, "old_glibc_consumer: sphere field off by %g\n", worst);
        return 1;
    }
    lb_evaluator_free(ev);
    lb_scene_free(s);

    /* the default scene from its file, meshed on two threads, closed, and
     * written through an atomic output */
    if (lb_scene_load(argv[1], &s, &e) != LB_OK) return fail("load", &e);
    if (lb_evaluator_create(s, &ev, &e) != LB_OK) return fail("compile", &e);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    lb_scene_bounds(s, o.bmin, o.bmax);
    o.resolution = 48;
    o.threads = 2;
    lb_mesh *m = NULL;
    if (lb_mesh_create(ev, &o, &m, &e) != LB_OK) return fail("mesh", &e);
    uint32_t *edges = malloc(sizeof *edges * 6 * (m->ntriangles + 1));
    uint32_t *corner = malloc(sizeof *corner * 3 * (m->ntriangles + 1));
    size_t nedges = 0;
    if (!edges || !corner) return fail("out of memory", NULL);
    if (lb_mesh_edges(m, edges, corner, &nedges, &e) != LB_OK) return fail("edges", &e);
    /* closed: every edge is shared by exactly two triangles */
    if (m->ntriangles == 0 || 2 * nedges != 3 * m->ntriangles) {
        fprintf(stderr, "old_glibc_consumer: %zu triangles, %zu edges: not closed\n", m->ntriangles,
                nedges);
        return 1;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/default.ply", argv[2]);
    if (lb_mesh_write(m, path, LB_MESH_FORMAT_AUTO, &e) != LB_OK) return fail("write", &e);
    struct stat st;
    if (stat(path, &st) != 0 || (long long)st.st_size < (long long)(12 * m->ntriangles))
        return fail("the written mesh is missing or short", NULL);
    printf("libblend %d on this system: sphere within %.1e, default scene %zu vertices, "
           "%zu triangles (closed), %s written\n",
           lb_version(), worst, m->nvertices, m->ntriangles, path);
    free(edges);
    free(corner);
    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(s);
    return 0;
}
