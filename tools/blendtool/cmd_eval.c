/* blendtool eval: field values and gradients at points. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest batch one run accepts (7 doubles per point in memory). */
#define MAX_POINTS 20000000u

typedef struct points {
    double *x, *y, *z;
    size_t n, cap;
} points;

static int grow(points *p) {
    const size_t cap = p->cap ? 2 * p->cap : 4096;
    double *x = realloc(p->x, cap * sizeof *x);
    if (x) p->x = x;
    double *y = realloc(p->y, cap * sizeof *y);
    if (y) p->y = y;
    double *z = realloc(p->z, cap * sizeof *z);
    if (z) p->z = z;
    if (!x || !y || !z) return -1;
    p->cap = cap;
    return 0;
}

/* The longest input line accepted, in bytes (three %.17g numbers need 75). */
#define MAX_LINE 4096

/* strtod, taking underflow (1e-400 is a valid input: it rounds to 0 or a
 * subnormal) but not overflow */
static int number(const char *s, char **end, double *v) {
    errno = 0;
    *v = strtod(s, end);
    if (*end == s) return 0;
    return !(errno == ERANGE && fabs(*v) > 1.0);
}

/* Reads "x y z" lines; blank lines, lines starting with # and a # comment
 * after the numbers are skipped. Lines are read into a fixed buffer, so an
 * endless line (/dev/zero) fails at MAX_LINE bytes instead of growing. */
/* One line into buf (NUL-terminated, newline kept): 1 read, 0 at the end
 * of input, -1 longer than MAX_LINE. *len counts every byte, NULs too. */
static int read_line(FILE *f, char *buf, size_t *len) {
    size_t n = 0;
    int c = EOF;
    while (n <= MAX_LINE && (c = getc_unlocked(f)) != EOF) {
        buf[n++] = (char)c;
        if (c == '\n') break;
    }
    buf[n] = '\0';
    *len = n;
    if (n > MAX_LINE) return -1;
    return n > 0 || c != EOF;
}

static int read_points(const char *cmd, FILE *f, const char *name, points *p) {
    char line[MAX_LINE + 2];
    size_t lineno = 0, len = 0;
    int rc = 0, got;
    while ((got = read_line(f, line, &len)) != 0) {
        ++lineno;
        if (got < 0) {
            bt_error(cmd,
                     "%s:%zu: line longer than %d bytes; allowed: one point \"x y z\" per line",
                     name, lineno, MAX_LINE);
            rc = BT_EXIT_BAD_INPUT;
            break;
        }
        if (strlen(line) != len) {
            bt_error(cmd, "%s:%zu: a NUL byte; allowed: text lines \"x y z\"", name, lineno);
            rc = BT_EXIT_BAD_INPUT;
            break;
        }
        char *s = line;
        while (*s == ' ' || *s == '\t') ++s;
        if (*s == '\n' || *s == '\r' || *s == '\0' || *s == '#') continue;
        double v[3];
        char *end = s;
        int ok = 1;
        for (int d = 0; d < 3 && ok; ++d) {
            char *e2;
            ok = number(end, &e2, &v[d]);
            end = e2;
        }
        while (ok && (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n')) ++end;
        if (ok && *end == '#') end += strlen(end);
        if (!ok || *end) {
            char shown[48];
            size_t k = 0;
            for (; s[k] && s[k] != '\n' && k < sizeof shown - 1; ++k)
                shown[k] = (unsigned char)s[k] < 32 || (unsigned char)s[k] > 126 ? '?' : s[k];
            shown[k] = '\0';
            bt_error(cmd, "%s:%zu: expected three numbers \"x y z\", found \"%s\"", name, lineno,
                     shown);
            rc = BT_EXIT_BAD_INPUT;
            break;
        }
        for (int d = 0; d < 3; ++d)
            if (!(v[d] >= -LB_SCENE_MAX_COORD && v[d] <= LB_SCENE_MAX_COORD)) {
                bt_error(cmd, "%s:%zu: %c = %g; allowed: finite, |coordinate| <= %g", name, lineno,
                         "xyz"[d], v[d], LB_SCENE_MAX_COORD);
                rc = BT_EXIT_BAD_INPUT;
            }
        if (rc) break;
        if (p->n >= MAX_POINTS) {
            bt_error(cmd,
                     "%s:%zu: more than %u points; allowed: at most %u per run (split the "
                     "input)",
                     name, lineno, MAX_POINTS, MAX_POINTS);
            rc = BT_EXIT_BAD_INPUT;
            break;
        }
        if (p->n == p->cap && grow(p)) {
            bt_error(cmd, "out of memory reading points");
            rc = BT_EXIT_INTERNAL;
            break;
        }
        p->x[p->n] = v[0];
        p->y[p->n] = v[1];
        p->z[p->n] = v[2];
        p->n++;
    }
    if (!rc && ferror(f)) {
        bt_error(cmd, "%s: read error: %s", name, strerror(errno));
        rc = BT_EXIT_BAD_INPUT;
    }
    return rc;
}

static int run_eval(int argc, char **argv) {
    const char *cmd = "eval";
    const char *scene_path = NULL, *points_path = NULL, *out_path = "-", *v;
    int threads = 0;
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option(cmd, argc, argv, &i, "--points", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            points_path = v;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--threads", &v))) {
            if (r < 0 || bt_parse_threads(cmd, v, &threads)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--output", &v)) ||
                   (r = bt_option(cmd, argc, argv, &i, "-o", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            out_path = v;
        } else if (bt_scene_arg(cmd, argv[i], &scene_path)) {
            return BT_EXIT_BAD_INPUT;
        }
    }
    if (!scene_path) {
        bt_error(cmd, "no scene given; usage: blendtool eval [--points FILE] SCENE < points");
        return BT_EXIT_BAD_INPUT;
    }
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    points P = {0};
    double *val = NULL, *gx = NULL, *gy = NULL, *gz = NULL;
    char *out = NULL;
    int rc = bt_load_scene(cmd, scene_path, &sc);
    if (rc || (rc = bt_compile(cmd, scene_path, sc, &ev))) goto done;
    lb_error e = {LB_OK, ""};
    lb_status s = LB_OK;
    if (points_path) {
        FILE *f = fopen(points_path, "rb");
        if (!f) {
            bt_error(cmd, "%s: cannot open the points file (%s)", points_path, strerror(errno));
            rc = BT_EXIT_BAD_INPUT;
            goto done;
        }
        rc = read_points(cmd, f, points_path, &P);
        fclose(f);
    } else {
        rc = read_points(cmd, stdin, "<stdin>", &P);
    }
    if (rc) goto done;
    const size_t n = P.n ? P.n : 1;
    val = malloc(n * sizeof *val);
    gx = malloc(n * sizeof *gx);
    gy = malloc(n * sizeof *gy);
    gz = malloc(n * sizeof *gz);
    /* 4 numbers of at most 24 characters, 3 spaces and a newline */
    out = malloc(n * 104 + 1);
    if (!val || !gx || !gy || !gz || !out) {
        bt_error(cmd, "out of memory for %zu points", P.n);
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    s = lb_evaluator_eval(ev, P.n, P.x, P.y, P.z, val, gx, gy, gz, threads, &e);
    if (s) {
        rc = bt_fail(cmd, scene_path, s, &e);
        goto done;
    }
    size_t len = 0;
    for (size_t i = 0; i < P.n; ++i)
        len += (size_t)snprintf(out + len, 104, "%.17g %.17g %.17g %.17g\n", val[i], gx[i], gy[i],
                                gz[i]);
    rc = bt_write_file(cmd, out_path, out, len);
done:
    free(P.x);
    free(P.y);
    free(P.z);
    free(val);
    free(gx);
    free(gy);
    free(gz);
    free(out);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return rc;
}

const bt_command bt_cmd_eval = {
    "eval", "field value and gradient at points",
    "usage: blendtool eval [--points FILE] [--threads N] [-o OUT] SCENE\n\n"
    "Reads points \"x y z\" (one per line; blank lines, # comment lines and a #\n"
    "comment after the numbers skipped; lines of at most 4096 bytes)\n"
    "from FILE or standard input and prints \"value gx gy gz\" per point with\n"
    "%.17g, in input order. All points are read and evaluated before anything is\n"
    "written, so bad input produces no output.\n"
    "  --points FILE   read points from FILE instead of standard input\n"
    "  --threads N     0 = one per CPU (default), 1 = single-threaded\n"
    "  -o, --output F  write to F (atomically) instead of standard output\n"
    "Limits: at most 20,000,000 points per run, lines of at most 4096 bytes, |coordinate|\n"
    "<= 1e9 (checked while reading: an endless input fails at the limit). A FIFO or\n"
    "device as FILE is read to its end.\n"
    "Exit status: 0 success, 2 bad scene or points, 1 internal failure or failure writing\n"
    "the output, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP (nothing written).\n",
    run_eval};
