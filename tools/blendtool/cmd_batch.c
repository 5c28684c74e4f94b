/* blendtool batch: a job file (docs/batch.md) expanded into a deterministic
 * task list (scenes x sweep axes x frames), run locally, by task, shard or
 * frame range, resumable through per-task manifests, logged as JSON lines;
 * --slurm writes (and --submit submits) an array job running the shards. */
#define _GNU_SOURCE
#include "batch.h"

/* ---- the command ---- */

static int parse_range(const char *v, long *a, long *b) {
    char *end = NULL;
    *a = strtol(v, &end, 10);
    if (!end || end == v) return -1;
    if (*end == '\0') {
        *b = *a;
        return 0;
    }
    if (*end != '-') return -1;
    const char *s2 = end + 1;
    *b = strtol(s2, &end, 10);
    return !end || end == s2 || *end || *b < *a ? -1 : 0;
}

/* the command line of blendtool batch */
typedef struct batch_opts {
    const char *file, *logpath, *partition, *blender;
    int list, log_json, fail_fast, slurm, submit, array, threads, sheet_only;
    long time_min, mem_mb; /* --time, --mem of --slurm: 0 = measured or default */
    long task_id, shard_i, shard_n, fa, fb;
} batch_opts;

static int parse_options(int argc, char **argv, batch_opts *o) {
    const char *v = NULL;
    *o = (batch_opts){.array = 4, .threads = -1, .task_id = -1, .shard_i = -1, .fa = -1, .fb = -1};
    for (int i = 1; i < argc; ++i) {
        int r;
        if (!strcmp(argv[i], "--list")) {
            o->list = 1;
        } else if (!strcmp(argv[i], "--log-json")) {
            o->log_json = 1;
        } else if (!strcmp(argv[i], "--fail-fast")) {
            o->fail_fast = 1;
        } else if (!strcmp(argv[i], "--slurm")) {
            o->slurm = 1;
        } else if (!strcmp(argv[i], "--submit")) {
            o->submit = o->slurm = 1;
        } else if (!strcmp(argv[i], "--sheet")) {
            o->sheet_only = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--task", &v))) {
            long b;
            if (r < 0 || parse_range(v, &o->task_id, &b) || b != o->task_id || o->task_id < 0) {
                if (r >= 0)
                    bt_error(CMD, "--task %s: expected a task id (a number from --list)", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--shard", &v))) {
            char *end = NULL;
            if (r < 0) return BT_EXIT_BAD_INPUT;
            o->shard_i = strtol(v, &end, 10);
            if (!end || *end != '/' || (o->shard_n = strtol(end + 1, &end, 10)) < 1 || *end ||
                o->shard_i < 0 || o->shard_i >= o->shard_n) {
                bt_error(CMD, "--shard %s: expected I/N with 0 <= I < N", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--frames", &v))) {
            if (r < 0 || parse_range(v, &o->fa, &o->fb) || o->fa < 0) {
                if (r >= 0)
                    bt_error(CMD, "--frames %s: expected A-B (or one frame A) with 0 <= A <= B", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--blender", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            o->blender = v;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--log", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            o->logpath = v;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--threads", &v))) {
            if (r < 0 || bt_parse_threads(CMD, v, &o->threads)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--array-size", &v))) {
            long a = 0;
            if (r < 0 || bt_parse_long(CMD, "--array-size", v, 1, 10000, "an integer", &a))
                return BT_EXIT_BAD_INPUT;
            o->array = (int)a;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--partition", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            if (!batch_partition_ok(v)) {
                bt_error(CMD,
                         "--partition: %zu bytes that Slurm cannot take as a partition list; "
                         "allowed: names of letters, digits, '_', '-', '.', separated by commas",
                         strlen(v));
                return BT_EXIT_BAD_INPUT;
            }
            o->partition = v;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--time", &v))) {
            if (r < 0 ||
                bt_parse_long(CMD, "--time", v, 1, 525600, "minutes per array task", &o->time_min))
                return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--mem", &v))) {
            if (r < 0 || bt_parse_long(CMD, "--mem", v, 16, 16777216, "megabytes per array task",
                                       &o->mem_mb))
                return BT_EXIT_BAD_INPUT;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            bt_error(CMD, "unknown option %s; see blendtool batch --help", argv[i]);
            return BT_EXIT_BAD_INPUT;
        } else if (!o->file) {
            o->file = argv[i];
        } else {
            bt_error(CMD, "more than one job file (%s, %s); allowed: one", o->file, argv[i]);
            return BT_EXIT_BAD_INPUT;
        }
    }
    if (!o->file) {
        bt_error(CMD, "no job file given; usage: blendtool batch JOB.json [--list]");
        return BT_EXIT_BAD_INPUT;
    }
    if ((o->task_id >= 0) + (o->shard_n > 0) > 1) {
        bt_error(CMD, "--task and --shard both given; allowed: one of them");
        return BT_EXIT_BAD_INPUT;
    }
    return BT_EXIT_OK;
}

/* is task T outside the --frames range? */
static int filtered(const batch_opts *o, const task *T) {
    return o->fa >= 0 && (T->frame < o->fa || T->frame > o->fb);
}

/* --slurm: the array script (and with --submit, sbatch --wait on it, then the sheet) */
static int run_slurm(const job *J, const batch_opts *o, size_t nt) {
    char script[8192];
    char self[4096];
    const ssize_t sl = readlink("/proc/self/exe", self, sizeof self - 1);
    self[sl > 0 ? sl : 0] = '\0';
    int rc = batch_slurm_script(J, nt, o->array, o->partition, o->time_min, o->mem_mb, self,
                                o->blender, script, sizeof script);
    if (!rc) printf("%s\n", script);
    if (rc || !o->submit) return rc;
    fflush(stdout);
    const pid_t pid = fork();
    if (pid == 0) {
        execlp("sbatch", "sbatch", "--wait", script, (char *)NULL);
        fprintf(stderr,
                "blendtool batch: cannot run sbatch (%s); allowed: install Slurm "
                "(Debian package slurm-wlm) or submit the script yourself\n",
                strerror(errno));
        _exit(127);
    }
    int st = 0;
    bt_signals_child(pid);
    while (pid > 0 && waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    bt_signals_child(0);
    rc = pid > 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : BT_EXIT_INTERNAL;
    if (rc) {
        bt_error(CMD, "sbatch --wait %s: some array tasks failed (logs in %s/logs)", script,
                 J->outdir);
    } else if (J->sheet) {
        logger L0 = {NULL, 0, 0, 0};
        rc = batch_contact_sheet(J, nt, &L0);
    }
    return rc;
}

/* --list: one line per selected task (id, name, scene hash, outputs, label) */
static int run_list(const job *J, const batch_opts *o, size_t lo, size_t hi) {
    int rc = 0;
    for (size_t i = lo; i < hi && !rc; ++i) {
        task T;
        if ((rc = batch_make_task(J, i, &T))) break;
        if (filtered(o, &T)) {
            batch_task_free(&T);
            continue;
        }
        lb_scene *sc = NULL;
        uint64_t h[2] = {0, 0};
        rc = bt_load_scene_set(CMD, J->scenes[T.scene], T.sets, T.nsets, &sc, h);
        lb_scene_free(sc);
        if (!rc) {
            char hex[33], names[BATCH_MAX_OUTPUTS][600];
            bt_hash_hex(h, hex);
            const size_t n = batch_outputs_of(J, &T, names);
            printf("%zu\t%s\t%s\t", T.id, T.name, hex);
            for (size_t k = 0; k < n; ++k) printf("%s%s", k ? "," : "", names[k]);
            printf("\t%s\n", T.label);
        }
        batch_task_free(&T);
    }
    if (fflush(stdout) != 0) rc = BT_EXIT_INTERNAL;
    return rc;
}

/* Before anything is created: every selected task's scene is read (a job
 * whose scene or overrides are invalid leaves no output folder), and the
 * images can be made on this machine. */
static int check_selection(job *J, const batch_opts *o, size_t lo, size_t hi) {
    int rc = 0;
    for (size_t i = lo; i < hi && !rc; ++i) {
        task T;
        if ((rc = batch_make_task(J, i, &T))) break;
        if (!filtered(o, &T)) {
            lb_scene *sc = NULL;
            uint64_t h[2];
            rc = bt_load_scene_set(CMD, J->scenes[T.scene], T.sets, T.nsets, &sc, h);
            lb_scene_free(sc);
        }
        batch_task_free(&T);
    }
    if (!rc && J->vdb && !bt_vdb_get(CMD)) rc = BT_EXIT_INTERNAL;
    if (!rc && J->image &&
        (rc = bt_image_plan_for(CMD, J->file, J->img_fmt, J->img_alpha, &J->img_plan)) == 0 &&
        J->sheet && !J->img_plan.io) {
        bt_error(CMD,
                 "%s: the contact sheet needs the image module (above); allowed: install "
                 "OpenImageIO 2.4 (Debian package libopenimageio2.4), or drop "
                 "outputs.contact_sheet and make the sheet elsewhere with --sheet",
                 J->file);
        rc = BT_EXIT_INTERNAL;
    }
    return rc;
}

/* the output and manifest folders (mdir: the latter's path), and the log */
static int open_outputs(const job *J, const batch_opts *o, char *mdir, size_t mdirlen, logger *L) {
    if (batch_mkdirs(J->outdir)) {
        bt_error(CMD, "%s: cannot create the output folder (%s)", J->outdir, strerror(errno));
        return BT_EXIT_BAD_INPUT;
    }
    snprintf(mdir, mdirlen, "%s/.libblend-manifest", J->outdir);
    if (batch_mkdirs(mdir)) {
        bt_error(CMD, "%s: cannot create the manifest folder (%s)", mdir, strerror(errno));
        return BT_EXIT_BAD_INPUT;
    }
    *L = (logger){NULL, 0, 0, 0};
    if (o->log_json) L->f = stdout;
    if (o->logpath && !(L->f = fopen(o->logpath, "a"))) {
        bt_error(CMD, "--log %s: %s", o->logpath, strerror(errno));
        return BT_EXIT_BAD_INPUT;
    }
    L->bar = isatty(STDERR_FILENO);
    return BT_EXIT_OK;
}

/* what became of the selected tasks */
typedef struct tally {
    size_t done, skipped, failed;
    int worst; /* the exit code of the failed tasks: 1 when any failed inside */
} tally;

/* One task, locked (lk: its lock's descriptor, or -2 when it could not be
 * taken): skipped when its manifest says it is complete, else run; its
 * task_start and task_end events logged. Returns the task's exit code. */
static int one_task(const job *J, const task *T, int lk, const char *mdir, logger *L, tally *t) {
    const double t0 = batch_now();
    lb_scene *sc = NULL;
    uint64_t h[2] = {0, 0};
    int trc = 0;
    if (lk < 0) {
        bt_error(CMD, "%s: cannot lock the task in %s (%s)", T->name, mdir, strerror(errno));
        trc = BT_EXIT_INTERNAL;
    } else {
        trc = bt_load_scene_set(CMD, J->scenes[T->scene], T->sets, T->nsets, &sc, h);
    }
    char *ident = trc ? NULL : batch_identity(J, T, h);
    const char *status = "done";
    if (!trc && batch_task_done(J, T, ident)) {
        status = "skipped";
        ++t->skipped;
    } else if (!trc) {
        batch_log_event(L, batch_event("task_start", T));
        trc = batch_run_task(J, T, ident, h, sc, L, J->threads);
    }
    if (lk >= 0) close(lk); /* the lock goes with the descriptor */
    if (trc) {
        status = "failed";
        ++t->failed;
        if (trc != BT_EXIT_BAD_INPUT || !t->worst) t->worst = trc;
    } else if (strcmp(status, "skipped")) {
        ++t->done;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    cJSON *e = batch_event("task_end", T);
    cJSON_AddStringToObject(e, "status", status);
    cJSON_AddNumberToObject(e, "seconds", batch_now() - t0);
    cJSON_AddNumberToObject(e, "peak_rss_kb", (double)ru.ru_maxrss);
    if (trc) cJSON_AddStringToObject(e, "error", bt_last_error());
    batch_log_event(L, e);
    free(ident);
    lb_scene_free(sc);
    return trc;
}

/* The tasks [lo, hi) in order. Tasks locked by another process (another run
 * on the same OUT folder) are passed over and taken at the end, waiting for
 * their locks: by then the other process has usually finished them, and
 * they are skipped as complete. Returns an exit code for a failure of the
 * run itself; the tasks' own are in t. */
static int run_tasks(const job *J, const batch_opts *o, size_t lo, size_t hi, const char *mdir,
                     logger *L, tally *t) {
    size_t nbusy = 0;
    size_t *busy = malloc((hi - lo + 1) * sizeof *busy);
    if (!busy) return BT_EXIT_INTERNAL;
    int rc = 0;
    for (size_t q = lo; q < hi + nbusy; ++q) {
        const int second = q >= hi;
        const size_t i = second ? busy[q - hi] : q;
        task T;
        if (batch_make_task(J, i, &T)) {
            rc = BT_EXIT_INTERNAL;
            break;
        }
        if (filtered(o, &T)) {
            batch_task_free(&T);
            continue;
        }
        const int lk = batch_task_lock(J, &T, second);
        if (lk == -1) {
            busy[nbusy++] = i;
            batch_task_free(&T);
            continue;
        }
        if (L->bar) fprintf(stderr, "\r[%zu/%zu] %s ", q - lo + 1, hi - lo, T.name), fflush(stderr);
        const int trc = one_task(J, &T, lk, mdir, L, t);
        batch_task_free(&T);
        if (trc && o->fail_fast) break;
    }
    free(busy);
    if (L->bar) fprintf(stderr, "\n");
    return rc;
}

static int run(int argc, char **argv) {
    bt_signals_going_on(); /* a signal ends the job between outputs, not after the last */
    batch_opts o;
    int rc = parse_options(argc, argv, &o);
    if (rc) return rc;
    job J;
    if ((rc = batch_parse_job(&J, o.file))) goto done;
    if (o.threads >= 0) J.threads = o.threads;
    bt_threads_set(J.threads); /* the image and OpenVDB modules' too */
    const size_t nt = batch_ntasks_of(&J);
    if (nt > MAX_TASKS) {
        rc = batch_bad(&J, "$", "%zu tasks (scenes x sweep values x frames); allowed: at most %d",
                       nt, MAX_TASKS);
        goto done;
    }
    if (o.task_id >= 0 && (size_t)o.task_id >= nt) {
        bt_error(CMD, "--task %ld: the job has tasks 0 to %zu", o.task_id, nt - 1);
        rc = BT_EXIT_BAD_INPUT;
        goto done;
    }
    if (o.fa >= 0 && !J.has_frames) {
        bt_error(CMD, "--frames %ld-%ld: %s has no \"frames\"", o.fa, o.fb, o.file);
        rc = BT_EXIT_BAD_INPUT;
        goto done;
    }
    /* the selection: [lo, hi) of task ids, then the frame filter */
    size_t lo = 0, hi = nt;
    if (o.task_id >= 0) lo = (size_t)o.task_id, hi = lo + 1;
    if (o.shard_n > 0) {
        lo = nt * (size_t)o.shard_i / (size_t)o.shard_n;
        hi = nt * (size_t)(o.shard_i + 1) / (size_t)o.shard_n;
    }
    if (o.slurm) {
        rc = run_slurm(&J, &o, nt);
        goto done;
    }
    if (o.list) {
        rc = run_list(&J, &o, lo, hi);
        goto done;
    }
    if (o.sheet_only && J.image && !J.sheet) { /* the documented defaults */
        J.sheet_cols = 4;
        J.sheet_w = 160;
        J.sheet_h = 120;
    }
    if (o.sheet_only && !J.image) {
        bt_error(CMD,
                 "--sheet: %s has no image outputs to put on a sheet; allowed: a job with "
                 "\"outputs\": {\"image\": {...}}",
                 o.file);
        rc = BT_EXIT_BAD_INPUT;
        goto done;
    }
    if (!o.sheet_only && (rc = check_selection(&J, &o, lo, hi))) goto done;
    bt_blender worker = {.exe = bt_blender_exe(o.blender), .logfd = -1};
    if (!o.sheet_only && J.image && J.blender) {
        /* its version is in every manifest: another Blender re-renders */
        if (bt_blender_version(worker.exe, J.blender_version, sizeof J.blender_version)) {
            bt_error(CMD,
                     "%s: the job renders with Blender, but `%s --version` did not run; "
                     "allowed: install Blender (Debian package blender), or name it with "
                     "--blender PATH or LIBBLEND_BLENDER",
                     o.file, worker.exe);
            rc = BT_EXIT_INTERNAL;
            goto done;
        }
        J.worker = &worker;
    }
    char mdir[8192];
    logger L;
    if ((rc = open_outputs(&J, &o, mdir, sizeof mdir, &L))) goto done;
    if (o.sheet_only) {
        rc = batch_contact_sheet(&J, nt, &L);
        if (L.f && L.f != stdout) fclose(L.f);
        goto done;
    }
    cJSON *je = batch_event("job", NULL);
    cJSON_AddStringToObject(je, "job", J.name);
    cJSON_AddNumberToObject(je, "tasks", (double)nt);
    cJSON_AddNumberToObject(je, "first", (double)lo);
    cJSON_AddNumberToObject(je, "end", (double)hi);
    batch_log_event(&L, je);
    tally t = {0, 0, 0, 0};
    rc = run_tasks(&J, &o, lo, hi, mdir, &L, &t);
    bt_blender_stop(&worker);
    if (!rc && !t.failed && J.sheet && lo == 0 && hi == nt && o.fa < 0)
        rc = batch_contact_sheet(&J, nt, &L);
    cJSON *e = batch_event("job_end", NULL);
    cJSON_AddNumberToObject(e, "done", (double)t.done);
    cJSON_AddNumberToObject(e, "skipped", (double)t.skipped);
    cJSON_AddNumberToObject(e, "failed", (double)t.failed);
    batch_log_event(&L, e);
    if (L.f && L.f != stdout && fclose(L.f) != 0 && !L.failed) {
        L.failed = 1;
        L.err = errno;
    }
    if (L.failed) {
        bt_error(CMD, "%s: writing the log failed (%s); the outputs and manifests are complete",
                 o.logpath ? o.logpath : "standard output", strerror(L.err));
        if (!rc) rc = BT_EXIT_INTERNAL;
    }
    fprintf(stderr, "blendtool batch: %s: %zu done, %zu skipped (complete), %zu failed\n", J.name,
            t.done, t.skipped, t.failed);
    if (!rc && t.failed) rc = t.worst;
done:
    batch_job_free(&J);
    return rc;
}

const bt_command bt_cmd_batch = {
    "batch", "run a job file: sweeps and frames as tasks, resumable, sharded, on Slurm",
    "usage: blendtool batch JOB.json [--list] [--task ID | --shard I/N] [--frames A-B]\n"
    "                       [--threads N] [--log FILE | --log-json] [--fail-fast] [--sheet]\n"
    "       blendtool batch JOB.json --slurm [--array-size N] [--partition P] [--submit]\n\n"
    "Expands the job (docs/batch.md) into tasks: scenes x sweep values x frames, in a\n"
    "fixed order, and runs them: each task's outputs (mesh, POV-Ray scene, image) go\n"
    "into the output folder under temporary names and are renamed when complete; a\n"
    "manifest (scene hash, parameters, libblend version, output hashes) is written\n"
    "last. A task whose manifest and outputs match is skipped, so a rerun after a\n"
    "kill or a failure redoes only what is missing.\n"
    "  --list          print the tasks: id, name, scene hash, outputs, parameters\n"
    "  --task ID       run one task; --shard I/N the I-th of N contiguous chunks\n"
    "  --frames A-B    only the frames A to B\n"
    "  --threads N     threads per task (the job's \"threads\", default 1)\n"
    "  --blender PATH  the Blender that renders outputs.image.renderer \"blender\"\n"
    "                  (default: $LIBBLEND_BLENDER, else blender on PATH)\n"
    "  --log FILE      append one JSON line per event to FILE; --log-json to stdout\n"
    "  --fail-fast     stop at the first failed task (default: run the others)\n"
    "  --sheet         only (re)make the contact sheet from the finished images\n"
    "  --slurm         write OUT/NAME.sbatch, an array job of --array-size shards (4);\n"
    "                  --submit also runs sbatch --wait on it\n"
    "Exit status: 0 every selected task done or complete, 1 a task failed, 2 bad job file\n"
    "or options, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP (the running task\n"
    "leaves no output and no manifest).\n",
    run};
