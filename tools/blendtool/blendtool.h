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
#include <stdint.h>
#include <stdio.h>

#include <sys/types.h>

#define BT_STR2(x) #x
#define BT_STR(x) BT_STR2(x)
/* libblend's version as text, e.g. "0.1.0" */
#define BT_VERSION                                                                                 \
    BT_STR(LB_VERSION_MAJOR) "." BT_STR(LB_VERSION_MINOR) "." BT_STR(LB_VERSION_PATCH)

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

/* The text of the last bt_error message ("" before any). */
const char *bt_last_error(void);

/* Option parsing shared by the subcommands: `--name VALUE` or
 * `--name=VALUE`. Returns 1 and sets *value when argv[*i] is that option
 * (advancing *i past the value), 0 when it is not, -1 (after printing an
 * error) when the value is missing. */
int bt_option(const char *cmd, int argc, char **argv, int *i, const char *name, const char **value);
/* An argument that is no known option: an unknown option ("-x", "--y"; "-"
 * is a name) or the scene, which may be given once. Returns 0 with *scene
 * set, or -1 after printing which. */
int bt_scene_arg(const char *cmd, const char *arg, const char **scene);

/* Parse the value of an integer option: the whole text a decimal integer in
 * [lo, hi]. Returns 0 and sets *out, or prints "OPTION TEXT: expected WHAT,
 * LO to HI" and returns -1. */
int bt_parse_long(const char *cmd, const char *option, const char *text, long lo, long hi,
                  const char *what, long *out);

/* Parse a thread count (0 = all CPUs). Returns 0 or prints an error and
 * returns -1. The last count parsed (or set: a job's threads) is also the
 * image module's (bt_threads_asked: 0 when none was given). */
int bt_parse_threads(const char *cmd, const char *text, int *threads);
void bt_threads_set(int n);
int bt_threads_asked(void);

/* The folder of the running executable (from /proc/self/exe) into out;
 * -1 when unknown or longer than n. */
int bt_self_dir(char *out, size_t n);

/* The folder holding libblend.inc into out: $LIBBLEND_POVRAY_INCLUDE, else
 * the installed layout's share/libblend/povray relative to the executable
 * (the build tree mirrors it). 0, or -1 after a message naming the file
 * looked for and the fix. */
int bt_povray_include(const char *cmd, char *out, size_t n);

/* Load a scene, printing the library's message on failure. Returns the exit
 * code (0 on success). */
int bt_load_scene(const char *cmd, const char *path, lb_scene **scene);

/* ---- scene overrides (overrides.c) ---- */

#define BT_MAX_SETS 64

/* One `--set PATH=VALUE`: the path (plen bytes of it) and a JSON value. */
typedef struct bt_set {
    const char *path; /* PATH=VALUE as given (the path is its first plen bytes) */
    size_t plen;
    const char *value; /* JSON text */
} bt_set;

/* A whole file, NUL-terminated (malloc'd; *len without the NUL), or NULL
 * with why (strerror, or "larger than max bytes"). */
char *bt_read_file(const char *path, size_t max, size_t *len, char *why, size_t whylen);

/* Parse "PATH=VALUE" (VALUE must be JSON). Returns 0, or -1 after printing
 * an error naming the argument. */
int bt_set_parse(const char *cmd, const char *arg, bt_set *out);
/* One more --set (arg) into sets[*nsets], at most max in all; 0, or -1 after
 * printing why. */
int bt_set_arg(const char *cmd, const char *arg, bt_set *sets, size_t *nsets, size_t max);

/* Load a scene with overrides applied in order: a path that does not exist
 * and a scene the overrides make invalid are bad input (exit 2) with the
 * scene's own message and the overrides named. hash (may be NULL) receives
 * the 128-bit XXH3 hash of the resolved scene text. Returns an exit code. */
int bt_load_scene_set(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                      lb_scene **scene, uint64_t hash[2]);

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
/* Compile a loaded scene into *ev: an exit code, after the message naming
 * scene_path when the scene cannot be compiled (*ev is then NULL). */
int bt_compile(const char *cmd, const char *scene_path, const lb_scene *sc, lb_evaluator **ev);
/* Warn on stderr (a warning: the exit status stays 0) about every m that can
 * change nothing in the scene (lb_scene_unused_m): the first few paths, the
 * count of the rest, and the fix. Returns how many there are. */
size_t bt_warn_unused_m(const char *cmd, const char *scene_path, const lb_scene *sc);

/* signals.c: SIGINT / SIGTERM / SIGHUP end the command with 128 + N, after
 * ending the child, removing the registered temporary files and folder. */
void bt_signals_install(void);
int bt_signals_temp(const char *path); /* returns a slot for bt_signals_untemp, or -1 */
void bt_signals_untemp(int slot);
void bt_signals_temp_dir(const char *dir); /* NULL: none */
void bt_signals_child(pid_t pid);          /* 0: none */
void bt_signals_worker(pid_t pid);         /* a second child (the Blender worker); 0: none */
void bt_signals_commit(void);              /* hold the signals from here to exit */
/* batch: the signals open again after each output (bt_signals_reopen, which
 * bt_output_commit calls), and a signal that came during the commit ends the
 * run there, the output complete */
void bt_signals_going_on(void);
void bt_signals_reopen(void); /* nothing unless bt_signals_going_on was called */

/* ---- rendering (cmd_pov.c) ---- */

/* A private render folder in $TMPDIR (or /tmp): the scene, povray's image
 * and its state file, all registered with the signal handler (removed on
 * SIGINT / SIGTERM / SIGHUP; a folder of a killed run is removed by the
 * next render). */
enum { BT_RENDER_FILES = 8 };
typedef struct bt_render_dir {
    char dir[4096];
    /* the folder's files (cmd_pov.c's RENDER_FILES, in that order) */
    char pov[4200], png[4200], state[4200], log[4200], ini[4200];
    /* a Blender task's resolved scene, and the scenes a frame before and after it */
    char json[4200], before[4200], after[4200];
    int slot[BT_RENDER_FILES];
} bt_render_dir;
int bt_render_dir_open(bt_render_dir *r); /* exit code */
void bt_render_dir_close(bt_render_dir *r);

/* How povray renders: image size, threads (0: one per CPU), quality 0..11,
 * a PNG of 16 bits per channel (else 8) with an alpha channel (else RGB);
 * quiet: its messages go to the render folder's log and are shown only when
 * it fails (else they stream to stderr); antialias: adaptive antialiasing,
 * without jitter (the same bytes run to run at one thread). */
typedef struct bt_pov_run {
    int width, height, threads, quality, bits16, alpha, quiet, antialias;
} bt_pov_run;
/* povray on R's scene into R's image as P says, through R's INI file.
 * Returns an exit code, after printing a message naming scene_name on
 * failure. */
int bt_povray(const char *scene_name, const bt_render_dir *R, const bt_pov_run *P);
/* The image's libblend:render metadata for P's size, quality and
 * antialiasing, a silhouette and a mesh resolution (0: the isosurface):
 * "640x480 quality 9[ silhouette][ antialias][ mesh N]", the same words for
 * `render` and `batch`. */
void bt_render_settings(char *out, size_t len, const bt_pov_run *P, int silhouette, int mesh);

/* The scene file's text with sets applied (malloc'd, its length in len),
 * the same document bt_load_scene_set parses; NULL after printing why. */
char *bt_scene_text_set(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                        size_t *len);

/* ---- the Blender worker (blender_worker.c) ---- */

/* One background Blender that renders batch tasks one after another (pid 0:
 * not running; it starts on the first task and again after a crash). */
typedef struct bt_blender {
    const char *exe; /* bt_blender_exe() */
    pid_t pid;
    FILE *req, *rep;  /* its fd 3 (requests) and fd 4 (replies) */
    int logfd;        /* its stdout and stderr: an unnamed temporary file, or -1 */
    char running[64]; /* the version the running worker reported */
} bt_blender;
/* the Blender to run: option (--blender), else $LIBBLEND_BLENDER, else "blender" on PATH */
const char *bt_blender_exe(const char *option);
/* "Blender 3.4.1" from exe --version into out; 0, or -1 when it cannot run */
int bt_blender_version(const char *exe, char *out, size_t n);
/* start the worker; 0, or -1 with the reason in err */
int bt_blender_start(bt_blender *B, char *err, size_t errlen);
/* send one request (a JSON object on one line) and wait for its reply: 0 done,
 * 1 the task failed inside Blender (err says why; the worker goes on), 2 the
 * worker died or could not start (err: how, and its last output; the next
 * task starts a new one). While Blender renders, progress (may be NULL) is
 * called with the fraction of samples done, each time it passes a tenth.
 * seconds (may be NULL): [0] Blender's render, [1] the whole task in Blender
 * (import, mesh, render, save), -1 when not reported. */
int bt_blender_task(bt_blender *B, const char *request, char *err, size_t errlen,
                    void (*progress)(void *ctx, double fraction), void *ctx, double *seconds);
/* end the worker (if running) and close its log */
void bt_blender_stop(bt_blender *B);

/* The lbi_format for an image name (.png: --bits 8|16, .exr: --pixel
 * half|float; 0 / NULL: the defaults), or -1 after printing why. */
int bt_image_format(const char *cmd, const char *out, int bits, const char *pixel);
/* 32 hex digits of a 128-bit hash */
void bt_hash_hex(const uint64_t h[2], char out[33]);

/* ---- images (imageio_load.c): OpenImageIO, loaded on first use ---- */

#include "lbimageio.h"

typedef struct bt_imageio {
    int (*convert)(const char *in, lbi_format format, int alpha, const lbi_meta *meta, size_t nmeta,
                   unsigned char **data, size_t *size, char *err, size_t errlen);
    int (*contact_sheet)(const char *const *images, const char *const *labels, size_t n,
                         int columns, int cell_w, int cell_h, lbi_format format,
                         const lbi_meta *meta, size_t nmeta, unsigned char **data, size_t *size,
                         char *err, size_t errlen);
    int (*compare)(const char *a, const char *b, double fail, double *max_error, double *mean_error,
                   double *fail_percent, char *err, size_t errlen);
    int (*write_pixels)(const float *rgb, int w, int h, const lbi_text *texts, size_t ntexts,
                        lbi_format format, const lbi_meta *meta, size_t nmeta, unsigned char **data,
                        size_t *size, char *err, size_t errlen);
    void (*set_threads)(int n);
} bt_imageio;

/* A module of blendtool's (a C++ library behind a C interface, file
 * "liblbNAME.so"): $env_var when set, else next to the executable (the build
 * tree), else in the installed libdir relative to it. The dlopen handle, or
 * NULL with "cannot load the WHAT (tried ...): why" in why (room: 3 paths
 * and a message). */
void *bt_module_open(const char *env_var, const char *file, const char *what, char *why,
                     size_t whylen);

/* The image functions, or NULL after printing why they cannot be loaded. */
const bt_imageio *bt_imageio_get(const char *cmd);
/* The same, silently: NULL with the reason in why. */
const bt_imageio *bt_imageio_try(char *why, size_t whylen);

/* How a rendered image becomes OUT. With the image module (OpenImageIO),
 * POV-Ray writes a 16-bit RGBA PNG and the module converts it to any
 * format. Without it (a farm node that has POV-Ray but not OpenImageIO),
 * POV-Ray writes the final PNG itself, at the asked depth and channels, and
 * bt_png_direct finishes it; OpenEXR then fails. */
typedef struct bt_image_plan {
    const bt_imageio *io; /* NULL: POV-Ray's own PNG */
    int bits16, alpha;    /* what POV-Ray writes */
    int out_alpha;        /* OUT has an alpha channel */
} bt_image_plan;
/* Plan OUT (format fmt, alpha channel or not); an exit code, after printing
 * why when OUT cannot be written on this machine. Without the module, a note
 * says so once per process. */
int bt_image_plan_for(const char *cmd, const char *out, int fmt, int alpha, bt_image_plan *p);
/* OUT's bytes from POV-Ray's png, with meta (0, or -1 with err) */
int bt_image_finish(const bt_image_plan *p, const char *png, int fmt, const lbi_meta *meta,
                    size_t nmeta, unsigned char **data, size_t *size, char *err, size_t errlen);
/* png_direct.c: POV-Ray's PNG at in, its time stamp and text chunks
 * replaced by meta (text chunks before the image data), every chunk's CRC
 * checked; the bytes in a malloc'd buffer the caller frees. 0, or -1 with a
 * message in err. */
int bt_png_direct(const char *in, const lbi_meta *meta, size_t nmeta, unsigned char **data,
                  size_t *size, char *err, size_t errlen);

/* Is help requested anywhere in argv? */
int bt_wants_help(int argc, char **argv);

/* ---- OpenVDB files (cmd_vdb.c): the lbvdb module, loaded on first use ---- */

#include "lbvdb.h"

typedef struct bt_vdb {
    int (*level_set_file)(const lb_level_set *ls, double shift, const lbv_meta *meta, size_t nmeta,
                          const char *uuid_seed, unsigned threads, unsigned char **data,
                          size_t *size, char *err, size_t errlen);
} bt_vdb;
/* The OpenVDB functions, or NULL after printing why they cannot be loaded. */
const bt_vdb *bt_vdb_get(const char *cmd);
/* The .vdb file of a level set (malloc'd bytes in *data), its grids carrying
 * the scene's hash, libblend's version, the voxel size, band and voxel
 * centres and the --set paths; blender: voxel centres placed for Blender
 * (the transform moved by half a voxel down each axis); threads: OpenVDB's
 * threads (the command's --threads: 0 one per CPU). An exit code, after
 * printing why. */
int bt_vdb_bytes(const char *cmd, const char *scene_path, const lb_level_set *ls, int blender,
                 const uint64_t hash[2], const bt_set *sets, size_t nsets, unsigned threads,
                 unsigned char **data, size_t *size);
/* --bounds "x0,y0,z0,x1,y1,z1" (commas or spaces) into bmin, bmax: 0, or
 * BT_EXIT_BAD_INPUT after saying what is expected */
int bt_bounds_arg(const char *cmd, const char *text, double bmin[3], double bmax[3]);
/* The scene with its --set values, and its region: the --bounds given
 * (have_bounds) or the scene's own; an exit code, after printing why (a
 * scene without bounds and no --bounds among them). hash as
 * bt_load_scene_set. */
int bt_load_scene_region(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                         int have_bounds, double bmin[3], double bmax[3], lb_scene **scene,
                         uint64_t hash[2]);

extern const bt_command bt_cmd_validate, bt_cmd_info, bt_cmd_eval, bt_cmd_mesh, bt_cmd_pov,
    bt_cmd_render, bt_cmd_batch, bt_cmd_compare, bt_cmd_section, bt_cmd_vdb;

#endif
