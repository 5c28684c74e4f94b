/* blendtool: the command line render farms and scripts call.
 *
 * One subcommand per file (cmd_*.c), registered in main.c's table. Every
 * subcommand follows the same contract:
 * - `blendtool CMD --help` prints its usage to stdout and exits 0;
 * - exit 0 on success, 2 on bad input (scene, options, points), 1 on an
 *   internal failure (out of memory, I/O errors writing output);
 * - one message on stderr naming the file, the place and the fix;
 * - output files are written to a temporary file and renamed, so a failed
 *   run never leaves partial output. */
#ifndef BLENDTOOL_H
#define BLENDTOOL_H

#include <libblend/libblend.h>

#include <stddef.h>
#include <stdio.h>

enum { BT_EXIT_OK = 0, BT_EXIT_INTERNAL = 1, BT_EXIT_BAD_INPUT = 2 };

typedef struct bt_command {
    const char *name;
    const char *summary;
    const char *usage; /* full --help text */
    int (*run)(int argc, char **argv);
} bt_command;

/* Exit code for a library status: invalid input -> 2, the rest -> 1. */
int bt_exit_for(lb_status s);

/* Print "blendtool CMD: message" to stderr. */
void bt_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Option parsing shared by the subcommands: `--name VALUE` or
 * `--name=VALUE`. Returns 1 and sets *value when argv[*i] is that option
 * (advancing *i past the value), 0 when it is not, -1 (after printing an
 * error) when the value is missing. */
int bt_option(const char *cmd, int argc, char **argv, int *i, const char *name, const char **value);

/* Parse a thread count (0 = all CPUs). Returns 0 or prints an error and
 * returns -1. */
int bt_parse_threads(const char *cmd, const char *text, int *threads);

/* Load a scene, printing the library's message on failure. Returns the exit
 * code (0 on success). */
int bt_load_scene(const char *cmd, const char *path, lb_scene **scene);

/* Write len bytes to path atomically (temporary file in the same directory,
 * then rename). "-" writes to stdout. Returns an exit code. */
int bt_write_file(const char *cmd, const char *path, const char *data, size_t len);

/* Is help requested anywhere in argv? */
int bt_wants_help(int argc, char **argv);

extern const bt_command bt_cmd_validate, bt_cmd_info, bt_cmd_eval, bt_cmd_mesh, bt_cmd_pov,
    bt_cmd_render;

#endif
