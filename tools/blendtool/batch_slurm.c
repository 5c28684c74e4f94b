/* blendtool batch --slurm: the sbatch script of an array job running the
 * shards, every value in it quoted. */
#define _GNU_SOURCE /* fopencookie */
#include "batch.h"

/* ---- Slurm ---- */

/* Slurm partition lists: names of [A-Za-z0-9_.-] separated by commas */
int batch_partition_ok(const char *p) {
    if (!*p || strlen(p) > 1000 || *p == ',' || p[strlen(p) - 1] == ',') return 0;
    for (const char *c = p; *c; ++c)
        if (!(isalnum((unsigned char)*c) || *c == '_' || *c == '-' || *c == '.' ||
              (*c == ',' && c[1] != ',')))
            return 0;
    return 1;
}

/* text as one shell word: single quotes, each ' as '\'' (no byte can end
 * it: inside single quotes the shell gives no character a meaning) */
static void sh_quote(char *out, size_t len, size_t *o, const char *text) {
    const char *parts[2] = {"'", "'\\''"};
    size_t n = *o;
    if (n + 1 < len) out[n++] = '\'';
    for (const char *c = text; *c && n + 5 < len; ++c) {
        if (*c == '\'')
            for (const char *q = parts[1]; *q; ++q) out[n++] = *q;
        else
            out[n++] = *c;
    }
    if (n + 1 < len) out[n++] = '\'';
    out[n < len ? n : len - 1] = '\0';
    *o = n;
}

/* A value sbatch's #SBATCH parser passes through unchanged inside double
 * quotes, and its file-name patterns leave alone: no '"', '\', '%' (file
 * name patterns), no control character. */
static int directive_ok(const char *v) {
    for (const unsigned char *c = (const unsigned char *)v; *c; ++c)
        if (*c < 32 || *c == 127 || *c == '"' || *c == '\\' || *c == '%') return 0;
    return 1;
}

/* The largest time and peak memory of the job's tasks that the shard logs
 * of earlier runs (OUT/logs/NAME_shard_*.jsonl) record as done (0 when
 * none do). */
static void measured_costs(const job *J, double *sec, double *rss_kb) {
    *sec = *rss_kb = 0.0;
    char logs[8192];
    snprintf(logs, sizeof logs, "%s/logs", J->outdir);
    DIR *d = opendir(logs);
    if (!d) return;
    char prefix[300];
    snprintf(prefix, sizeof prefix, "%s_shard_", J->name);
    for (struct dirent *e; (e = readdir(d));) {
        const size_t nl = strlen(e->d_name), pl = strlen(prefix);
        if (nl <= pl + 6 || strncmp(e->d_name, prefix, pl) || strcmp(e->d_name + nl - 6, ".jsonl"))
            continue;
        char path[8600];
        snprintf(path, sizeof path, "%s/%s", logs, e->d_name);
        FILE *f = fopen(path, "r");
        char line[4096];
        while (f && fgets(line, sizeof line, f)) {
            cJSON *ev = cJSON_Parse(line);
            const cJSON *k = cJSON_GetObjectItemCaseSensitive(ev, "event"),
                        *st = cJSON_GetObjectItemCaseSensitive(ev, "status"),
                        *s2 = cJSON_GetObjectItemCaseSensitive(ev, "seconds"),
                        *r = cJSON_GetObjectItemCaseSensitive(ev, "peak_rss_kb");
            if (cJSON_IsString(k) && !strcmp(k->valuestring, "task_end") && cJSON_IsString(st) &&
                !strcmp(st->valuestring, "done")) {
                if (cJSON_IsNumber(s2) && s2->valuedouble > *sec) *sec = s2->valuedouble;
                if (cJSON_IsNumber(r) && r->valuedouble > *rss_kb) *rss_kb = r->valuedouble;
            }
            cJSON_Delete(ev);
        }
        if (f) fclose(f);
    }
    closedir(d);
}

int batch_slurm_script(const job *J, size_t ntasks, int array, const char *partition, long time_min,
                       long mem_mb, const char *self, const char *blender, char *out,
                       size_t outlen) {
    if (batch_mkdirs(J->outdir)) {
        bt_error(CMD, "%s: cannot create the output folder (%s)", J->outdir, strerror(errno));
        return BT_EXIT_BAD_INPUT;
    }
    if ((size_t)array > ntasks) array = (int)ntasks;
    char jobabs[8192], dirabs[8192];
    if (!realpath(J->file, jobabs) || !realpath(J->outdir, dirabs)) {
        bt_error(CMD, "%s: %s", J->file, strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    if (snprintf(out, outlen, "%s/%s.sbatch", dirabs, J->name) >= (int)outlen) {
        bt_error(CMD, "%s: the output folder's path is too long", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    /* --time and --mem: given, else measured on the job's tasks in the
     * shard logs of an earlier submission (twice the slowest task per task of the largest shard,
     * plus 5 minutes; twice the largest peak plus 256 MB), else 30 minutes per task of the largest
     * shard and 4096 MB (docs/batch.md) */
    const size_t per_shard = (ntasks + (size_t)array - 1) / (size_t)array;
    double sec = 0.0, rss = 0.0;
    if (!time_min || !mem_mb) measured_costs(J, &sec, &rss);
    if (!time_min) {
        const double t =
            sec > 0.0 ? ceil(2.0 * sec * (double)per_shard / 60.0) + 5.0 : 30.0 * (double)per_shard;
        time_min = t < 10.0 ? 10 : t > 525600.0 ? 525600 : (long)t;
    }
    if (!mem_mb) mem_mb = rss > 0.0 ? (long)ceil(2.0 * rss / 1024.0) + 256 : 4096;
    /* every path is a shell word in single quotes; the log folder goes into
     * a #SBATCH line only where sbatch keeps it as it is */
    char logs[8300], qself[20000], qjob[20000], qlog[20000], qbl[20000] = "";
    size_t o1 = 0, o2 = 0, o3 = 0, o4 = 0;
    if (snprintf(logs, sizeof logs, "%s/logs", dirabs) >= (int)sizeof logs) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    char logfile[8800];
    if (snprintf(logfile, sizeof logfile, "%s/%s_shard_", logs, J->name) >= (int)sizeof logfile) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    sh_quote(qself, sizeof qself, &o1, self);
    sh_quote(qjob, sizeof qjob, &o2, jobabs);
    sh_quote(qlog, sizeof qlog, &o3, logfile);
    if (blender && J->blender && J->image) { /* --blender PATH, as given */
        char abs[8192];
        const char *b = strchr(blender, '/') && realpath(blender, abs) ? abs : blender;
        sh_quote(qbl, sizeof qbl, &o4, "--blender");
        qbl[o4++] = ' ';
        qbl[o4] = '\0';
        sh_quote(qbl, sizeof qbl, &o4, b);
        qbl[o4++] = ' ';
        qbl[o4] = '\0';
    }
    /* a Blender job's render threads are the array task's CPUs */
    const int cpus = J->blender && J->image && J->blender_threads > 0 ? J->blender_threads : 1;
    const int direct = directive_ok(logs);
    char text[80000];
    const int tl = snprintf(
        text, sizeof text,
        "#!/bin/sh\n"
        "# written by blendtool batch --slurm (libblend %s): %zu tasks in %d array tasks.\n"
        "# Submitting it again redoes only what is missing or incomplete.\n"
        "#SBATCH --job-name=%s\n"
        "#SBATCH --array=0-%d\n"
        "%s%s%s"
        "#SBATCH --ntasks=1\n"
        "#SBATCH --cpus-per-task=%d\n"
        "#SBATCH --time=%ld\n"
        "#SBATCH --mem=%ldM\n"
        "%s%s%s"
        "%s%s%s"
        "exec %s batch %s --shard \"$SLURM_ARRAY_TASK_ID/%d\" --threads 1 %s"
        "--log %s\"$SLURM_ARRAY_TASK_ID\"'.jsonl'\n",
        BT_VERSION, ntasks, array, J->name, array - 1, direct ? "#SBATCH --output=\"" : "",
        direct ? logs : "", direct ? "/%x_%A_%a.log\"\n" : "", cpus, time_min, mem_mb,
        partition ? "#SBATCH --partition=" : "", partition ? partition : "", partition ? "\n" : "",
        direct ? ""
               : "# the output folder's path has characters a #SBATCH line cannot carry:\n"
                 "# the shard's messages go to its log from here (Slurm's own to\n"
                 "# slurm-JOB_TASK.out in the folder it was submitted from)\n"
                 "exec >>",
        direct ? "" : qlog, direct ? "" : "\"$SLURM_ARRAY_TASK_ID\"'.log' 2>&1\n", qself, qjob,
        array, qbl, qlog);
    if (tl >= (int)sizeof text || o1 + 1 >= sizeof qself || o2 + 1 >= sizeof qjob ||
        o3 + 1 >= sizeof qlog || o4 + 2 >= sizeof qbl) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    if (batch_mkdirs(logs)) {
        bt_error(CMD, "%s: cannot create the log folder (%s)", logs, strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    int rc = batch_write_bytes(out, text, strlen(text));
    if (!rc) chmod(out, 0755);
    return rc;
}
