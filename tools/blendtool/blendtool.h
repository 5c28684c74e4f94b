/* blendtool: the command line render farms and scripts call.
 *
 * One subcommand per file (cmd_*.c), registered in main.c's table. Every
 * subcommand follows the same contract (docs/blendtool.md, "Exit status"):
 * - `blendtool CMD --help` prints its usage to stdout and exits 0;
 * - exit 0 on success; 2 on bad input or arguments (scene, options, points,
 *   an output path that cannot take a file, a documented limit); 1 on an
 *   internal failure or an I/O failure while writing output (disk full,
 *   standard output closed); 128 + N when ended by signal N (SIGINT 130,
 *   SIGHUP 129, SIGTERM 143; signals.c);
 * - one message on stderr naming the file, the place and the fix;
 * - output files go through lb_output (libblend/output.h), so a failed or
 *   interrupted run never leaves partial output. */
#ifndef BLENDTOOL_H
#define BLENDTOOL_H

#include <libblend/libblend.h>

#include <stddef.h>
#include <stdio.h>

#include <sys/types.h>

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

/* An output being written: an lb_output, or standard output for "-". */
typedef struct bt_out {
    lb_output *o;
    FILE *f;
    int slot; /* signals.c registry slot of a named temporary file, or -1 */
    const char *path;
} bt_out;

/* Open path for output ("-": standard output). Returns an exit code (2 with
 * a message naming the path when it cannot take a file). */
int bt_output_open(const char *cmd, const char *path, bt_out *out);
/* Put the output in place (signals held from here on). Returns an exit code
 * (1 with a message when writing failed; nothing is left at the path). */
int bt_output_commit(const char *cmd, bt_out *out);
void bt_output_discard(bt_out *out);

/* Is path "-", or (after symbolic links) a device or FIFO? Those take any
 * name, so the format cannot come from an extension. */
int bt_is_stream(const char *path);

/* Write len bytes to path through bt_output_*. Returns an exit code. */
int bt_write_file(const char *cmd, const char *path, const char *data, size_t len);

/* The exit code and message for a library failure on a scene: the message
 * is printed with the scene's path in front unless it already starts with
 * it; LB_ERR_INVALID_ARGUMENT and LB_ERR_NOT_FINITE give 2, the rest 1. */
int bt_fail(const char *cmd, const char *scene_path, lb_status s, const lb_error *e);

/* signals.c: SIGINT / SIGTERM / SIGHUP end the command with 128 + N, after
 * ending the child, removing the registered temporary files and folder. */
void bt_signals_install(void);
int bt_signals_temp(const char *path); /* returns a slot for bt_signals_untemp, or -1 */
void bt_signals_untemp(int slot);
void bt_signals_temp_dir(const char *dir); /* NULL: none */
void bt_signals_child(pid_t pid);          /* 0: none */
void bt_signals_commit(void);              /* hold the signals from here to exit */

/* Is help requested anywhere in argv? */
int bt_wants_help(int argc, char **argv);

extern const bt_command bt_cmd_validate, bt_cmd_info, bt_cmd_eval, bt_cmd_mesh, bt_cmd_pov,
    bt_cmd_render;

#endif
