/* The OpenVDB module's thread count (tools/vdb/lbvdb.h): `blendtool vdb
 * --threads 1` promises one thread, and a farm slot of one core counts on
 * it, but OpenVDB's flood fill runs on TBB's workers, one per CPU unless the
 * module limits them. The module, loaded as blendtool loads it (dlopen),
 * writes S2's level set with 1 and with 2 threads; the threads of the
 * process are listed (/proc/self/task) after the load and after each call.
 * 1: no thread made by the call; 2 (on a machine of 2 CPUs or more): a
 * worker made. The bytes are the same.
 *
 * usage: test_vdb_threads MODULE SCENE */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include "lbvdb.h"

#include <dirent.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef int (*file_fn)(const lb_level_set *, double, const lbv_meta *, size_t, const char *,
                       unsigned, unsigned char **, size_t *, char *, size_t);

static int failures;

static void check(int ok, const char *what) {
    printf("%s: %s\n", ok ? "ok" : "FAIL", what);
    if (!ok) ++failures;
}

/* the ids of this process's threads, in tids[0..n) (n returned, at most cap) */
static size_t threads_now(long *tids, size_t cap) {
    DIR *d = opendir("/proc/self/task");
    size_t n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.' && n < cap) tids[n++] = atol(e->d_name);
    if (d) closedir(d);
    return n;
}

static size_t new_threads(const long *before, size_t nb, const long *after, size_t na) {
    size_t k = 0;
    for (size_t i = 0; i < na; ++i) {
        int seen = 0;
        for (size_t j = 0; j < nb && !seen; ++j) seen = after[i] == before[j];
        k += !seen;
    }
    return k;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: test_vdb_threads MODULE SCENE\n");
        return 2;
    }
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_level_set *ls = NULL;
    lb_level_set_options o;
    lb_level_set_options_init(&o);
    o.resolution = 160;
    o.threads = 1; /* libblend's own threads are not the question here */
    if (lb_scene_load(argv[2], &sc, &e) || lb_evaluator_create(sc, &ev, &e) ||
        !lb_scene_bounds(sc, o.bmin, o.bmax) || lb_level_set_create(ev, &o, &ls, &e)) {
        fprintf(stderr, "%s: %s\n", argv[2], e.message);
        return 2;
    }
    void *h = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    file_fn file = h ? (file_fn)dlsym(h, "lbv_level_set_file") : NULL;
    if (!file) {
        fprintf(stderr, "%s: %s\n", argv[1], dlerror());
        return 2;
    }
    const lbv_meta meta[1] = {{"libblend:test", "threads"}};
    const char *seed = "0123456789abcdef0123456789abcdef";
    char err[512] = "";
    unsigned char *b1 = NULL, *b2 = NULL;
    size_t n1 = 0, n2 = 0;
    long t0[256], t1[256], t2[256];
    const size_t m0 = threads_now(t0, 256);
    const int r1 = file(ls, 0.0, meta, 1, seed, 1, &b1, &n1, err, sizeof err);
    const size_t m1 = threads_now(t1, 256);
    const size_t made1 = new_threads(t0, m0, t1, m1);
    char what[160];
    snprintf(what, sizeof what, "1 thread: written (%s), %zu threads made by the call (want 0)",
             r1 ? err : "ok", made1);
    check(r1 == 0 && made1 == 0, what);
    const int r2 = file(ls, 0.0, meta, 1, seed, 2, &b2, &n2, err, sizeof err);
    const size_t m2 = threads_now(t2, 256);
    const size_t made2 = new_threads(t1, m1, t2, m2);
    const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    snprintf(what, sizeof what, "2 threads on %ld CPUs: written (%s), %zu threads made (want %s)",
             cpus, r2 ? err : "ok", made2, cpus >= 2 ? "1" : "0");
    check(r2 == 0 && made2 == (cpus >= 2 ? 1u : 0u), what);
    check(r1 == 0 && r2 == 0 && n1 == n2 && memcmp(b1, b2, n1) == 0,
          "the same bytes for 1 and 2 threads");
    free(b1);
    free(b2);
    lb_level_set_free(ls);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    printf("%s\n", failures ? "FAILED" : "all checks passed");
    return failures ? 1 : 0;
}
