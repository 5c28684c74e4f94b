/* bench_parse: how long lb_scene_parse takes (public API only).
 *
 * For every scene file given: the text is read once, then parsed (and the
 * scene freed) until half a second has passed; prints the microseconds per
 * parse. Then the limit case: a scene of LB_SCENE_MAX_BYTES bytes
 * (a min of 65535 spheres whose numbers carry 17 digits, the rest of the
 * file spaces between them), parsed three times; prints the shortest time.
 * Peak memory is measured around the program (bench/run_parse_bench.sh).
 *   bench_parse [--limit-only] SCENE...
 * Output lines: "parse NAME MICROSECONDS" and "limit BYTES SECONDS". */
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

static char *read_all(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap);
    for (size_t r; b && (r = fread(b + n, 1, cap - n, f)) > 0;) {
        n += r;
        if (n == cap) {
            char *q = realloc(b, cap *= 2);
            if (!q) {
                free(b);
                b = NULL;
            }
            b = q;
        }
    }
    fclose(f);
    *len = n;
    return b;
}

static int parse_once(const char *text, size_t len, const char *name) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(text, len, name, &sc, &e)) {
        fprintf(stderr, "bench_parse: %s\n", e.message);
        return 1;
    }
    lb_scene_free(sc);
    return 0;
}

/* the limit case: LB_SCENE_MAX_BYTES of a valid scene */
static char *limit_scene(size_t *len) {
    const size_t cap = LB_SCENE_MAX_BYTES;
    char *t = malloc(cap + 1);
    if (!t) return NULL;
    size_t n = (size_t)snprintf(t, cap,
                                "{\"format\": \"libblend-scene\", \"version\": 1, "
                                "\"convention\": \"zero\", \"root\": {\"type\": \"min\", "
                                "\"args\": [");
    const int k = 65535;
    const size_t tail = 4, per = (cap - n - tail) / (size_t)k; /* bytes per sphere */
    for (int i = 0; i < k; ++i) {
        const size_t start = n;
        n += (size_t)snprintf(t + n, cap - n,
                              "%s{\"type\": \"sphere\", \"center\": [%.17g, %.17g, %.17g], "
                              "\"radius\": %.17g}",
                              i ? ", " : "", 1.0 + i * 1e-3, 0.1234567890123456789,
                              -0.98765432109876543, 0.5 + 1e-6 * i);
        while (n - start < per) t[n++] = ' ';
    }
    while (n < cap - tail) t[n++] = ' ';
    memcpy(t + n, "]}}\n", tail);
    n += tail;
    *len = n;
    return t;
}

int main(int argc, char **argv) {
    int limit_only = 0, rc = 0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--limit-only") == 0) {
            limit_only = 1;
            continue;
        }
        if (limit_only) continue;
        size_t len = 0;
        char *text = read_all(argv[i], &len);
        if (!text) {
            fprintf(stderr, "bench_parse: cannot read %s\n", argv[i]);
            return 1;
        }
        const char *name = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
        size_t runs = 0;
        const double t0 = now();
        double t1 = t0;
        while (t1 - t0 < 0.5 && !rc) {
            rc = parse_once(text, len, name);
            ++runs;
            t1 = now();
        }
        printf("parse %s %.1f\n", name, 1e6 * (t1 - t0) / (double)runs);
        free(text);
    }
    size_t len = 0;
    char *t = limit_scene(&len);
    if (!t) return 1;
    double best = 1e30;
    for (int r = 0; r < 3 && !rc; ++r) {
        const double t0 = now();
        rc = parse_once(t, len, "limit.json");
        const double dt = now() - t0;
        if (dt < best) best = dt;
    }
    printf("limit %zu %.3f\n", len, best);
    free(t);
    return rc;
}
