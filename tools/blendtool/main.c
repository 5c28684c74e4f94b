/* blendtool entry point: the subcommand table and shared helpers. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const bt_command *const COMMANDS[] = {&bt_cmd_validate, &bt_cmd_info, &bt_cmd_eval,
                                             &bt_cmd_mesh,     &bt_cmd_pov,  &bt_cmd_render};
#define NCOMMANDS (sizeof COMMANDS / sizeof COMMANDS[0])

int bt_exit_for(lb_status s) {
    return s == LB_ERR_INVALID_ARGUMENT || s == LB_ERR_NOT_FINITE ? BT_EXIT_BAD_INPUT
                                                                  : BT_EXIT_INTERNAL;
}

void bt_error(const char *cmd, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "blendtool %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
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

int bt_parse_threads(const char *cmd, const char *text, int *threads) {
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno || !end || *end || end == text || v < 0 || v > 1024) {
        bt_error(cmd, "--threads %s: expected an integer from 0 (one per CPU) to 1024", text);
        return -1;
    }
    *threads = (int)v;
    return 0;
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

int bt_write_file(const char *cmd, const char *path, const char *data, size_t len) {
    if (strcmp(path, "-") == 0) {
        if (fwrite(data, 1, len, stdout) != len || fflush(stdout) != 0) {
            bt_error(cmd, "writing to standard output failed: %s", strerror(errno));
            return BT_EXIT_INTERNAL;
        }
        return BT_EXIT_OK;
    }
    const size_t pl = strlen(path);
    char *tmp = malloc(pl + 32);
    if (!tmp) {
        bt_error(cmd, "out of memory");
        return BT_EXIT_INTERNAL;
    }
    snprintf(tmp, pl + 32, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        bt_error(cmd,
                 "%s: cannot create the output file (%s); allowed: a path in a writable "
                 "directory",
                 path, strerror(errno));
        free(tmp);
        return BT_EXIT_BAD_INPUT;
    }
    int ok = fwrite(data, 1, len, f) == len;
    ok &= fflush(f) == 0;
    ok &= fclose(f) == 0;
    if (!ok || rename(tmp, path) != 0) {
        bt_error(cmd, "%s: writing the output failed (%s); nothing was written", path,
                 strerror(errno));
        remove(tmp);
        free(tmp);
        return BT_EXIT_INTERNAL;
    }
    free(tmp);
    return BT_EXIT_OK;
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
                 "Exit status: 0 success, 2 bad input, 1 internal failure.\n");
}

int main(int argc, char **argv) {
    if (argc < 2) {
        usage(stderr);
        return BT_EXIT_BAD_INPUT;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return BT_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("blendtool (libblend) %d.%d.%d\n", LB_VERSION_MAJOR, LB_VERSION_MINOR,
               LB_VERSION_PATCH);
        return BT_EXIT_OK;
    }
    for (size_t i = 0; i < NCOMMANDS; ++i) {
        if (strcmp(argv[1], COMMANDS[i]->name) != 0) continue;
        if (bt_wants_help(argc - 1, argv + 1)) {
            fputs(COMMANDS[i]->usage, stdout);
            return BT_EXIT_OK;
        }
        return COMMANDS[i]->run(argc - 1, argv + 1);
    }
    fprintf(stderr, "blendtool: unknown command \"%s\"; allowed:", argv[1]);
    for (size_t i = 0; i < NCOMMANDS; ++i) fprintf(stderr, " %s", COMMANDS[i]->name);
    fprintf(stderr, " (see blendtool --help)\n");
    return BT_EXIT_BAD_INPUT;
}
