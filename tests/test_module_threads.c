/* blendtool's C++ modules keep to the command's thread count. `--threads 1`
 * promises one thread, and a farm slot of one core counts on it, but the
 * libraries behind the modules keep pools of their own, one thread per CPU
 * unless told: OpenVDB's flood fill runs on TBB's workers
 * (tools/vdb/lbvdb.h: the count passed to lbv_level_set_file), OpenImageIO
 * and OpenEXR on theirs (tools/imageio/lbimageio.h: lbi_set_threads). Each
 * module is loaded as blendtool loads it (dlopen), in a child process of its
 * own per count (the pools are the process's); the threads of the process
 * are listed (/proc/self/task) after the load and after the work. 1: no
 * thread alive that the work made; 2 (on 2 CPUs or more): at least one. The
 * bytes are the same for both counts.
 *
 * usage: test_module_threads VDB_MODULE IMAGE_MODULE SCENE */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include "lbimageio.h"
#include "lbvdb.h"

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

typedef int (*vdb_fn)(const lb_level_set *, double, const lbv_meta *, size_t, const char *,
                      unsigned, unsigned char **, size_t *, char *, size_t);
typedef void (*threads_fn)(int);
typedef int (*pixels_fn)(const float *, int, int, const lbi_text *, size_t, lbi_format,
                         const lbi_meta *, size_t, unsigned char **, size_t *, char *, size_t);

static const char *vdb_module, *image_module, *scene;
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

/* In a child: load the module, do the work with `threads`, write the bytes
 * to fd and exit with 100 + the number of threads the work left alive
 * (below 100: a failure, said on stderr). */
static void child_vdb(unsigned threads, int fd) {
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_level_set *ls = NULL;
    lb_level_set_options o;
    lb_level_set_options_init(&o);
    o.resolution = 160;
    o.threads = 1; /* libblend's own threads are not the question here */
    if (lb_scene_load(scene, &sc, &e) || lb_evaluator_create(sc, &ev, &e) ||
        !lb_scene_bounds(sc, o.bmin, o.bmax) || lb_level_set_create(ev, &o, &ls, &e)) {
        fprintf(stderr, "%s: %s\n", scene, e.message);
        _exit(1);
    }
    void *h = dlopen(vdb_module, RTLD_NOW | RTLD_LOCAL);
    vdb_fn file = h ? (vdb_fn)dlsym(h, "lbv_level_set_file") : NULL;
    if (!file) {
        fprintf(stderr, "%s: %s\n", vdb_module, dlerror());
        _exit(2);
    }
    long t0[256], t1[256];
    const size_t m0 = threads_now(t0, 256);
    const lbv_meta meta[1] = {{"libblend:test", "threads"}};
    char err[512] = "";
    unsigned char *b = NULL;
    size_t n = 0;
    if (file(ls, 0.0, meta, 1, "0123456789abcdef0123456789abcdef", threads, &b, &n, err,
             sizeof err)) {
        fprintf(stderr, "%s: %s\n", vdb_module, err);
        _exit(3);
    }
    const size_t m1 = threads_now(t1, 256);
    if (write(fd, b, n) != (ssize_t)n) _exit(4);
    _exit(100 + (int)new_threads(t0, m0, t1, m1));
}

static void child_image(unsigned threads, int fd) {
    void *h = dlopen(image_module, RTLD_NOW | RTLD_LOCAL);
    threads_fn set = h ? (threads_fn)dlsym(h, "lbi_set_threads") : NULL;
    pixels_fn pixels = h ? (pixels_fn)dlsym(h, "lbi_write_pixels") : NULL;
    if (!set || !pixels) {
        fprintf(stderr, "%s: %s\n", image_module, dlerror());
        _exit(2);
    }
    long t0[256], t1[256];
    const size_t m0 = threads_now(t0, 256);
    set((int)threads);
    /* an image large enough for OpenImageIO's copy and OpenEXR's zip to
     * split their work */
    const int w = 1024, hh = 768;
    float *rgb = malloc(sizeof(float) * 3 * (size_t)w * (size_t)hh);
    if (!rgb) _exit(5);
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)hh; ++i)
        rgb[i] = (float)((i * 2654435761u) % 1000u) / 1000.0f;
    char err[512] = "";
    for (int f = 0; f < 2; ++f) {
        unsigned char *b = NULL;
        size_t n = 0;
        if (pixels(rgb, w, hh, NULL, 0, f ? LBI_EXR_HALF : LBI_PNG16, NULL, 0, &b, &n, err,
                   sizeof err)) {
            fprintf(stderr, "%s: %s\n", image_module, err);
            _exit(3);
        }
        if (write(fd, b, n) != (ssize_t)n) _exit(4);
        free(b);
    }
    const size_t m1 = threads_now(t1, 256);
    _exit(100 + (int)new_threads(t0, m0, t1, m1));
}

/* runs one child; returns the threads the work left (-1: failed), the bytes in *out */
static int run(void (*fn)(unsigned, int), unsigned threads, char **out, size_t *len) {
    char path[] = "/tmp/lb-module-threads-XXXXXX";
    const int fd = mkstemp(path);
    if (fd < 0) return -1;
    unlink(path);
    fflush(NULL);
    const pid_t pid = fork();
    if (pid == 0) fn(threads, fd);
    int st = 0;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    const off_t n = lseek(fd, 0, SEEK_END);
    *len = n > 0 ? (size_t)n : 0;
    *out = malloc(*len + 1);
    if (!*out || pread(fd, *out, *len, 0) != (ssize_t)*len) *len = 0;
    close(fd);
    return WIFEXITED(st) && WEXITSTATUS(st) >= 100 ? WEXITSTATUS(st) - 100 : -1;
}

static void module_case(const char *name, void (*fn)(unsigned, int)) {
    char *b1 = NULL, *b2 = NULL;
    size_t n1 = 0, n2 = 0;
    const int made1 = run(fn, 1, &b1, &n1), made2 = run(fn, 2, &b2, &n2);
    const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    char what[200];
    snprintf(what, sizeof what, "%s, 1 thread: %d threads left by the work (want 0)", name, made1);
    check(made1 == 0, what);
    snprintf(what, sizeof what, "%s, 2 threads on %ld CPUs: %d threads left by the work (want %s)",
             name, cpus, made2, cpus >= 2 ? ">= 1" : "0");
    check(cpus >= 2 ? made2 >= 1 : made2 == 0, what);
    snprintf(what, sizeof what, "%s: the same %zu bytes for 1 and 2 threads", name, n1);
    check(n1 > 0 && n1 == n2 && memcmp(b1, b2, n1) == 0, what);
    free(b1);
    free(b2);
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: test_module_threads VDB_MODULE IMAGE_MODULE SCENE\n");
        return 2;
    }
    vdb_module = argv[1];
    image_module = argv[2];
    scene = argv[3];
    module_case("OpenVDB module (S2's level set)", child_vdb);
    module_case("image module (a PNG and an EXR)", child_image);
    printf("%s\n", failures ? "FAILED" : "all checks passed");
    return failures ? 1 : 0;
}
