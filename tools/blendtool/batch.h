/* blendtool batch, shared between its files: the job (docs/batch.md), the
 * task list it expands into, the log, and the functions each file offers
 * the others. cmd_batch.c is the command; batch_job.c reads the job file;
 * batch_tasks.c expands tasks and keeps manifests and the log;
 * batch_run.c runs a task and makes the contact sheet; batch_slurm.c writes
 * the Slurm array script. */
#ifndef BT_BATCH_H
#define BT_BATCH_H

#include "blendtool.h"

#include "../../libblend/src/common/json_check.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <xxhash.h>

#define CMD "batch"
#define MAX_TASKS 100000
#define MAX_AXES 16

typedef struct axis {
    char *path; /* JSON path into the scene */
    size_t n;
    char **values;  /* JSON text per step (sweeps) or per frame (animation) */
    char label[33]; /* the contact sheet's name for it ("m2"); empty: the path's last part */
    cJSON *keys;    /* an animated path's [frame, value] keys (sub-frames: motion blur) */
    char interp[8]; /* and their interpolation */
} axis;

typedef struct job {
    const char *file;
    char dir[4096]; /* the job file's folder: relative paths start there */
    char name[256]; /* output base name */
    char pattern[256];
    char outdir[4096];
    size_t nscenes;
    char **scenes; /* resolved paths */
    char **scene_stems;
    size_t nfixed;
    bt_set fixed[BT_MAX_SETS];
    char **fixed_text;
    size_t naxes;
    axis axes[MAX_AXES];
    int has_frames;
    long first, last;
    size_t nanim;
    axis anim[MAX_AXES];
    /* outputs */
    int mesh, mesh_res;
    lb_mesh_format mesh_fmt;
    int mesh_features;    /* LB_MESH_FEATURES (and corner normals in OBJ / GLB) */
    double mesh_simplify; /* lb_mesh_options.simplify, cells; 0 = off */
    int mesh_merge_flat;  /* LB_MESH_MERGE_FLAT */
    int pov, pov_w, pov_h;
    /* outputs.vdb: a narrow-band level set (voxel size, or voxels along the
     * longest side; band in voxels; LB_LEVEL_SET_* extra grids) */
    int vdb, vdb_res;
    double vdb_voxel, vdb_band;
    unsigned vdb_grids;
    int vdb_blender; /* voxel_centres "blender" */
    int image, img_w, img_h, img_quality, img_alpha, img_fmt, img_antialias, img_mesh;
    /* the Blender renderer (blender: 1): engine, samples, seed, render threads (0: the
     * job's), motion blur shutter in frames (0: none) */
    int blender;
    char engine[8];
    int samples, seed, blender_threads;
    double shutter;
    int fps;                  /* frames.fps (motion blur's velocities per second) */
    bt_blender *worker;       /* the process's Blender worker (cmd_batch.c owns it) */
    char blender_version[64]; /* "Blender 3.4.1": in every manifest's identity */
    int sheet, sheet_cols, sheet_w, sheet_h;
    bt_image_plan img_plan; /* how the images are made on this machine */
    int threads;
    uint64_t spec_hash[2]; /* of the outputs section: a change redoes every task */
} job;

typedef struct task {
    size_t id, scene, combo;
    long frame;
    char name[512];
    size_t nsets;
    bt_set sets[BT_MAX_SETS];
    char *set_text[BT_MAX_SETS];
    char label[1024];
} task;

typedef struct logger {
    FILE *f;    /* JSON lines, or NULL */
    int bar;    /* progress on a terminal */
    int failed; /* a line could not be written (errno in err) */
    int err;
} logger;

/* ---- batch_job.c: the job file ---- */
/* a malloc'd copy of s (NULL when out of memory) */
char *batch_dupstr(const char *s);
/* read and check the job file (exit 2 with the JSON path on a bad one); an exit code */
int batch_parse_job(job *J, const char *file);
/* a bad job file: prints the file, the JSON path and what is allowed; returns exit 2 */
int batch_bad(const job *J, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* an animated axis's value at a (fractional) frame, as JSON number text (malloc'd) */
char *batch_anim_value(const axis *X, double frame);
/* free what batch_parse_job allocated */
void batch_job_free(job *J);

/* ---- batch_tasks.c: the task list, outputs, manifests and the log ---- */
/* the most outputs one task writes */
#define BATCH_MAX_OUTPUTS 4
/* the output file names of task T (mesh, pov, vdb, image, in that order: the
 * image last, for the contact sheet); their count */
size_t batch_outputs_of(const job *J, const task *T, char out[BATCH_MAX_OUTPUTS][600]);
/* a JSON-lines log event of kind_ (about T, or the job when T is NULL) */
cJSON *batch_event(const char *kind_, const task *T);
/* write e as one JSON line (when logging) and free it */
void batch_log_event(logger *L, cJSON *e);
/* the manifest file of task T */
void batch_manifest_path(const job *J, const task *T, char *out, size_t len);
/* task id of the job expanded (scene, sweep values, frame, name); an exit code */
int batch_make_task(const job *J, size_t id, task *T);
/* free what batch_make_task allocated */
void batch_task_free(task *T);
/* the number of tasks of the job */
size_t batch_ntasks_of(const job *J);
/* seconds on the monotonic clock */
double batch_now(void);
/* the manifest's identity of task T: scene hash and stem, overridden paths, libblend's
 * version, the outputs section's hash; malloc'd JSON text */
char *batch_identity(const job *J, const task *T, const uint64_t scene[2]);
/* whether task T is complete: its manifest has identity ident and every output its hash */
int batch_task_done(const job *J, const task *T, const char *ident);

/* ---- batch_run.c: running one task, the contact sheet ---- */
/* write len bytes to path through bt_write_file (atomic; an exit code) */
int batch_write_bytes(const char *path, const void *data, size_t len);
/* make path and its parents (0, or -1 with errno) */
int batch_mkdirs(const char *path);
/* the job's contact sheet (OUT/NAME_sheet.png) from every task's image; an exit code */
int batch_contact_sheet(const job *J, size_t ntasks, logger *L);
/* take task T's lock, a byte of OUT/.libblend-manifest/tasks.lock chosen by its name
 * (wait: block until it is free): the descriptor holding it, -1 when another
 * process holds it, -2 on any other failure (errno) */
int batch_task_lock(const job *J, const task *T, int wait);
/* run task T (its outputs, then its manifest); an exit code */
int batch_run_task(const job *J, const task *T, const char *ident, const uint64_t scene_hash[2],
                   lb_scene *sc, logger *L, int threads);

/* ---- batch_slurm.c: the Slurm array script ---- */
/* whether p can be a Slurm partition name */
int batch_partition_ok(const char *p);
/* write the job's sbatch script (OUT/NAME.sbatch, its path into out) running ntasks as
 * an array of `array` shards (with --blender BLENDER when not NULL), every value in it
 * quoted; an exit code */
int batch_slurm_script(const job *J, size_t ntasks, int array, const char *partition, long time_min,
                       long mem_mb, const char *self, const char *blender, char *out,
                       size_t outlen);

#endif
