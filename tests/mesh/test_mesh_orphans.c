/* The orphan path of the extraction (libblend/src/meshing/extract.c): a
 * crossing edge whose owner block did not cut it stays with every block that
 * cuts it, and the merge shares it by its grid edge key. Real fields almost
 * never take that path, so this program is built twice: against the library
 * (test_mesh_orphans_ref) and against a build of it in which every third
 * edge on a block's near face is an orphan of all the blocks that hold it
 * (test_mesh_orphans, LB__FORCE_ORPHANS). For every scene, plain and with
 * sharp features (LB_MESH_FEATURES), it meshes on 1 and 3 threads, checks that both meshes are the
 * same bytes and closed (each directed edge once, with its reverse), and prints the vertex and
 * triangle counts and a hash of the triangles as position triples (each rotated to start at its
 * smallest vertex, then sorted): tests/CMakeLists.txt compares the two builds' lines, which must be
 * equal, since an orphan's vertex is refined exactly as its owner's would be.
 *
 * Usage: test_mesh_orphans SCENE... (exit 1 on a failed check) */
#include <libblend/libblend.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct tri {
    double p[9];
} tri;

static int cmp_tri(const void *a, const void *b) {
    return memcmp(a, b, sizeof(tri)); /* any fixed order of the bytes will do */
}

static int cmp_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Each directed edge once, with its reverse present. */
static int closed(const lb_mesh *m) {
    const size_t n = 3 * m->ntriangles;
    uint64_t *e = malloc((n ? n : 1) * sizeof *e), *r = malloc((n ? n : 1) * sizeof *r);
    if (!e || !r) {
        free(e);
        free(r);
        return 0;
    }
    for (size_t t = 0; t < m->ntriangles; ++t)
        for (int c = 0; c < 3; ++c) {
            const uint64_t a = m->triangles[3 * t + c], b = m->triangles[3 * t + (c + 1) % 3];
            e[3 * t + c] = a << 32 | b;
            r[3 * t + c] = b << 32 | a;
        }
    qsort(e, n, sizeof *e, cmp_u64);
    qsort(r, n, sizeof *r, cmp_u64);
    int ok = 1;
    for (size_t i = 0; i < n && ok; ++i) ok = e[i] == r[i] && (i == 0 || e[i] != e[i - 1]);
    free(e);
    free(r);
    return ok;
}

static int same(const lb_mesh *a, const lb_mesh *b) {
    return a->nvertices == b->nvertices && a->ntriangles == b->ntriangles &&
           !memcmp(a->positions, b->positions, 3 * a->nvertices * sizeof(double)) &&
           !memcmp(a->normals, b->normals, 3 * a->nvertices * sizeof(double)) &&
           !memcmp(a->triangles, b->triangles, 3 * a->ntriangles * sizeof(uint32_t));
}

/* FNV-1a over the sorted canonical triangles. */
static uint64_t fingerprint(const lb_mesh *m) {
    tri *T = malloc((m->ntriangles ? m->ntriangles : 1) * sizeof *T);
    if (!T) return 0;
    for (size_t t = 0; t < m->ntriangles; ++t) {
        const double *v[3];
        for (int c = 0; c < 3; ++c) v[c] = m->positions + 3 * m->triangles[3 * t + c];
        int s = 0; /* the rotation that starts at the smallest vertex keeps the orientation */
        for (int c = 1; c < 3; ++c)
            if (memcmp(v[c], v[s], 3 * sizeof(double)) < 0) s = c;
        for (int c = 0; c < 3; ++c) memcpy(T[t].p + 3 * c, v[(s + c) % 3], 3 * sizeof(double));
    }
    qsort(T, m->ntriangles, sizeof *T, cmp_tri);
    uint64_t h = 1469598103934665603ull;
    const unsigned char *p = (const unsigned char *)T;
    for (size_t i = 0; i < m->ntriangles * sizeof *T; ++i) h = (h ^ p[i]) * 1099511628211ull;
    free(T);
    return h;
}

int main(int argc, char **argv) {
    int failed = 0;
    for (int a = 1; a < argc; ++a) {
        lb_error e = {LB_OK, ""};
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        if (lb_scene_load(argv[a], &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
            fprintf(stderr, "test_mesh_orphans: %s\n", e.message);
            return 1;
        }
        /* plain, and with sharp features (their points and fans moved
         * past the orphans) */
        for (int fl = 0; fl < 2; ++fl) {
            lb_mesh_options o;
            lb_mesh_options_init(&o);
            o.resolution = 40; /* five blocks along the longest side */
            o.flags = fl ? LB_MESH_FEATURES : 0;
            lb_scene_bounds(sc, o.bmin, o.bmax);
            lb_mesh *m[2] = {NULL, NULL};
            for (int k = 0; k < 2; ++k) {
                o.threads = k ? 3 : 1;
                if (lb_mesh_create(ev, &o, &m[k], &e)) {
                    fprintf(stderr, "test_mesh_orphans: %s: %s\n", argv[a], e.message);
                    return 1;
                }
            }
            const char *name = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
            if (!same(m[0], m[1])) {
                fprintf(stderr, "FAIL %s: 1 and 3 threads give different meshes\n", name);
                failed = 1;
            }
            if (!closed(m[0])) {
                fprintf(stderr,
                        "FAIL %s: not closed (a directed edge twice or without its reverse)\n",
                        name);
                failed = 1;
            }
            printf("%s%s %zu %zu %016llx\n", name, fl ? "+features" : "", m[0]->nvertices,
                   m[0]->ntriangles, (unsigned long long)fingerprint(m[0]));
            lb_mesh_free(m[0]);
            lb_mesh_free(m[1]);
        }
        lb_evaluator_free(ev);
        lb_scene_free(sc);
    }
    return failed;
}
