/* blendtool entry point: the subcommand table and shared helpers. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const bt_command *const COMMANDS[] = {
    &bt_cmd_validate, &bt_cmd_info,  &bt_cmd_eval,    &bt_cmd_mesh,    &bt_cmd_pov,
    &bt_cmd_render,   &bt_cmd_batch, &bt_cmd_compare, &bt_cmd_section, &bt_cmd_vdb};
#define NCOMMANDS (sizeof COMMANDS / sizeof COMMANDS[0])

int bt_exit_for(lb_status s) {
    return s == LB_ERR_INVALID_ARGUMENT || s == LB_ERR_NOT_FINITE ? BT_EXIT_BAD_INPUT
                                                                  : BT_EXIT_INTERNAL;
}

/* One line whatever the arguments hold (file names, option values): control
 * characters are written as \n, \t, \r or \xNN, as the library does. */
/* the last message, for batch's JSON log (one process, one thread) */
static char last_error[4096];

const char *bt_last_error(void) {
    return last_error;
}

void bt_error(const char *cmd, const char *fmt, ...) {
    char raw[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    snprintf(last_error, sizeof last_error, "%s", raw);
    fprintf(stderr, "blendtool %s: ", cmd);
    for (const unsigned char *c = (const unsigned char *)raw; *c; ++c) {
        if (*c == '\n' || *c == '\t' || *c == '\r')
            fprintf(stderr, "\\%c", *c == '\n' ? 'n' : *c == '\t' ? 't' : 'r');
        else if (*c < 0x20 || *c == 0x7f)
            fprintf(stderr, "\\x%02x", *c);
        else
            fputc(*c, stderr);
    }
    fputc('\n', stderr);
}

int bt_option(const char *cmd, int argc, char **argv, int *i, const char *name,
              const char **value) {
    const char *a = argv[*i];
    const size_t n = strlen(name);
    if (strncmp(a, name, n) != 0) return 0;
    if (a[n] == '=') {
        *value = a + n + 1;
        return 1;
    }
    if (a[n] != '\0') return 0;
    if (*i + 1 >= argc) {
        bt_error(cmd, "option %s needs a value; see blendtool %s --help", name, cmd);
        return -1;
    }
    *value = argv[++*i];
    return 1;
}

int bt_scene_arg(const char *cmd, const char *arg, const char **scene) {
    if (arg[0] == '-' && arg[1]) {
        bt_error(cmd, "unknown option %s; see blendtool %s --help", arg, cmd);
        return -1;
    }
    if (*scene) {
        bt_error(cmd, "more than one scene (%s, %s); allowed: one", *scene, arg);
        return -1;
    }
    *scene = arg;
    return 0;
}

int bt_parse_long(const char *cmd, const char *option, const char *text, long lo, long hi,
                  const char *what, long *out) {
    char *end = NULL;
    errno = 0;
    const long v = strtol(text, &end, 10);
    if (errno || !end || *end || end == text || v < lo || v > hi) {
        bt_error(cmd, "%s %s: expected %s, %ld to %ld", option, text, what, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

static int threads_asked; /* the command's --threads (one command a process) */

int bt_parse_threads(const char *cmd, const char *text, int *threads) {
    long v = 0;
    if (bt_parse_long(cmd, "--threads", text, 0, 1024, "an integer (0: one per CPU)", &v))
        return -1;
    *threads = (int)v;
    threads_asked = (int)v;
    return 0;
}

void bt_threads_set(int n) {
    threads_asked = n;
}

int bt_threads_asked(void) {
    return threads_asked;
}

int bt_self_dir(char *out, size_t n) {
    char self[4096];
    const ssize_t l = readlink("/proc/self/exe", self, sizeof self - 1);
    if (l <= 0) return -1;
    self[l] = '\0';
    char *slash = strrchr(self, '/');
    if (!slash) return -1;
    *slash = '\0';
    return (size_t)snprintf(out, n, "%s", self) < n ? 0 : -1;
}

#ifndef LIBBLEND_POVRAY_REL
#define LIBBLEND_POVRAY_REL "../share/libblend/povray"
#endif

int bt_povray_include(const char *cmd, char *out, size_t n) {
    const char *env = getenv("LIBBLEND_POVRAY_INCLUDE");
    char self[4096] = "", tried[8400] = "";
    if (env && *env) {
        snprintf(out, n, "%s", env);
    } else if (bt_self_dir(self, sizeof self) == 0) {
        snprintf(out, n, "%s/%s", self, LIBBLEND_POVRAY_REL);
    } else {
        bt_error(cmd, "cannot find libblend.inc: the executable's folder is unknown "
                      "(/proc/self/exe); allowed: set LIBBLEND_POVRAY_INCLUDE to the folder "
                      "holding libblend.inc");
        return -1;
    }
    snprintf(tried, sizeof tried, "%s/libblend.inc", out);
    if (access(tried, R_OK) == 0) return 0;
    bt_error(cmd,
             "cannot read %s (%s); allowed: set LIBBLEND_POVRAY_INCLUDE to the folder holding "
             "libblend.inc, or install blendtool with its share/libblend/povray folder "
             "(cmake --install)",
             tried, env && *env ? "from $LIBBLEND_POVRAY_INCLUDE" : "beside the executable");
    return -1;
}

int bt_load_scene(const char *cmd, const char *path, lb_scene **scene) {
    lb_error e = {LB_OK, ""};
    lb_status s = lb_scene_load(path, scene, &e);
    if (s) {
        bt_error(cmd, "%s", e.message);
        return bt_exit_for(s);
    }
    return BT_EXIT_OK;
}

int bt_output_open(const char *cmd, const char *path, bt_out *out) {
    memset(out, 0, sizeof *out);
    out->slot = -1;
    out->path = path;
    if (strcmp(path, "-") == 0) {
        out->f = stdout;
        return BT_EXIT_OK;
    }
    lb_error e = {LB_OK, ""};
    if (lb_output_open(path, &out->o, &e)) {
        bt_error(cmd, "%s", e.message);
        return BT_EXIT_BAD_INPUT;
    }
    out->f = lb_output_stream(out->o);
    const char *t = lb_output_temp_name(out->o);
    if (t) out->slot = bt_signals_temp(t);
    return BT_EXIT_OK;
}

static int commit(const char *cmd, bt_out *out) {
    if (!out->o) {
        if (fflush(out->f) != 0 || ferror(out->f)) {
            bt_error(cmd, "writing to standard output failed: %s", strerror(errno));
            return BT_EXIT_INTERNAL;
        }
        return BT_EXIT_OK;
    }
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_output_commit(out->o, &e);
    out->o = NULL;
    bt_signals_untemp(out->slot);
    if (s) {
        bt_error(cmd, "%s", e.message);
        return BT_EXIT_INTERNAL;
    }
    return BT_EXIT_OK;
}

int bt_output_commit(const char *cmd, bt_out *out) {
    bt_signals_commit();
    const int rc = commit(cmd, out);
    bt_signals_reopen(); /* batch: the signals open again, the output in place */
    return rc;
}

void bt_output_discard(bt_out *out) {
    if (!out->o) return;
    lb_output_discard(out->o);
    out->o = NULL;
    bt_signals_untemp(out->slot);
}

int bt_write_file(const char *cmd, const char *path, const char *data, size_t len) {
    bt_out out;
    int rc = bt_output_open(cmd, path, &out);
    if (rc) return rc;
    if (len && fwrite(data, 1, len, out.f) != len) {
        bt_error(cmd, "%s: writing the output failed (%s); nothing was written",
                 strcmp(path, "-") ? path : "standard output", strerror(errno));
        bt_output_discard(&out);
        return BT_EXIT_INTERNAL;
    }
    return bt_output_commit(cmd, &out);
}

int bt_is_stream(const char *path) {
    struct stat st;
    if (strcmp(path, "-") == 0) return 1;
    return stat(path, &st) == 0 &&
           (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) || S_ISFIFO(st.st_mode));
}

int bt_fail(const char *cmd, const char *scene_path, lb_status s, const lb_error *e) {
    const size_t n = scene_path ? strlen(scene_path) : 0;
    if (n && strncmp(e->message, scene_path, n) != 0)
        bt_error(cmd, "%s: %s", scene_path, e->message);
    else
        bt_error(cmd, "%s", e->message);
    return bt_exit_for(s);
}

static int parse_bounds(const char *text, double bmin[3], double bmax[3]) {
    double v[6];
    const char *p = text;
    for (int i = 0; i < 6; ++i) {
        while (*p == ' ' || *p == ',') ++p;
        char *end = NULL;
        errno = 0;
        v[i] = strtod(p, &end);
        if (errno || end == p || !isfinite(v[i])) return -1;
        p = end;
    }
    while (*p == ' ' || *p == ',') ++p;
    if (*p) return -1;
    for (int d = 0; d < 3; ++d) {
        bmin[d] = v[d];
        bmax[d] = v[3 + d];
    }
    return 0;
}

int bt_bounds_arg(const char *cmd, const char *text, double bmin[3], double bmax[3]) {
    if (!parse_bounds(text, bmin, bmax)) return 0;
    bt_error(cmd, "--bounds %s: expected six numbers \"x0,y0,z0,x1,y1,z1\"", text);
    return BT_EXIT_BAD_INPUT;
}

int bt_load_scene_region(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                         int have_bounds, double bmin[3], double bmax[3], lb_scene **scene,
                         uint64_t hash[2]) {
    const int rc = bt_load_scene_set(cmd, path, sets, nsets, scene, hash);
    if (rc || have_bounds || lb_scene_bounds(*scene, bmin, bmax)) return rc;
    bt_error(cmd,
             "%s: the scene has no bounds; allowed: add \"bounds\" to the scene or give "
             "--bounds x0,y0,z0,x1,y1,z1",
             path);
    lb_scene_free(*scene);
    *scene = NULL;
    return BT_EXIT_BAD_INPUT;
}

int bt_compile(const char *cmd, const char *scene_path, const lb_scene *sc, lb_evaluator **ev) {
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_evaluator_create(sc, ev, &e);
    return s ? bt_fail(cmd, scene_path, s, &e) : BT_EXIT_OK;
}

size_t bt_warn_unused_m(const char *cmd, const char *scene_path, const lb_scene *sc) {
    enum { SHOWN = 4 };
    const char *paths[SHOWN];
    const size_t n = lb_scene_unused_m(sc, paths, SHOWN);
    for (size_t i = 0; i < n && i < SHOWN; ++i)
        fprintf(stderr,
                "blendtool %s: warning: %s: %s sets m other than 1, which has no effect there: no "
                "operator above it uses its values (min, max, complement, R-functions and clean "
                "unions do not), so m changes nothing in the surface and only steepens the "
                "field. Fix: leave m at 1, or blend this node with something\n",
                cmd, scene_path, paths[i]);
    if (n > SHOWN)
        fprintf(stderr, "blendtool %s: warning: %s: and %zu more nodes like it\n", cmd, scene_path,
                n - SHOWN);
    return n;
}

int bt_wants_help(int argc, char **argv) {
    for (int i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return 1;
    return 0;
}

static void usage(FILE *out) {
    fprintf(out,
            "usage: blendtool COMMAND [OPTIONS] SCENE\n\n"
            "libblend %d.%d.%d - implicit-surface blends from scene files.\n\ncommands:\n",
            LB_VERSION_MAJOR, LB_VERSION_MINOR, LB_VERSION_PATCH);
    for (size_t i = 0; i < NCOMMANDS; ++i)
        fprintf(out, "  %-10s %s\n", COMMANDS[i]->name, COMMANDS[i]->summary);
    fprintf(out, "\n`blendtool COMMAND --help` describes one command.\n"
                 "Exit status (every command): 0 success; 2 bad input or arguments (the\n"
                 "message names the file, the place and the fix); 1 internal failure or\n"
                 "failure writing output; 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP\n"
                 "(nothing is left at the output path).\n");
}

/* Standard output must have reached its destination (a full disk or a
 * closed pipe is a failure, not success). */
static int finish(int rc) {
    if (fflush(stdout) != 0 || ferror(stdout)) {
        if (rc) return rc; /* the command has said what failed */
        bt_error("output", "writing to standard output failed: %s", strerror(errno));
        return rc ? rc : BT_EXIT_INTERNAL;
    }
    return rc;
}

int main(int argc, char **argv) {
    bt_signals_install();
    if (argc < 2) {
        usage(stderr);
        return BT_EXIT_BAD_INPUT;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return finish(BT_EXIT_OK);
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("blendtool (libblend) %d.%d.%d\n", LB_VERSION_MAJOR, LB_VERSION_MINOR,
               LB_VERSION_PATCH);
        return finish(BT_EXIT_OK);
    }
    for (size_t i = 0; i < NCOMMANDS; ++i) {
        if (strcmp(argv[1], COMMANDS[i]->name) != 0) continue;
        if (bt_wants_help(argc - 1, argv + 1)) {
            fputs(COMMANDS[i]->usage, stdout);
            return finish(BT_EXIT_OK);
        }
        return finish(COMMANDS[i]->run(argc - 1, argv + 1));
    }
    fprintf(stderr, "blendtool: unknown command \"%s\"; allowed:", argv[1]);
    for (size_t i = 0; i < NCOMMANDS; ++i) fprintf(stderr, " %s", COMMANDS[i]->name);
    fprintf(stderr, " (see blendtool --help)\n");
    return BT_EXIT_BAD_INPUT;
}
