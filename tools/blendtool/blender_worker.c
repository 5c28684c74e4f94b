/* The Blender worker of `blendtool batch` (outputs.image.renderer
 * "blender"): one background Blender (factory settings, the add-on from
 * the build tree or the installed share/libblend/blender_addon) that takes
 * tasks one after another, so Blender's start-up (about 3 s) is paid once
 * per batch process, not once per image.
 *
 * Protocol: Blender inherits two pipes, fd 3 (one JSON request per line:
 * the task's resolved scene file, image size, engine, samples, seed,
 * threads, mesh resolution, motion blur) and fd 4 (one JSON reply per
 * line: {"ok": true} or {"error": "..."}); its first reply says hello with
 * its version. Its own stdout and stderr (Cycles' progress, Python
 * tracebacks) go to an unnamed temporary file, shown when it fails and
 * gone with blendtool. Blender dies with blendtool (PR_SET_PDEATHSIG, and
 * the signal handler ends it); a worker that dies mid-task fails that task
 * only: the next task starts a new worker. Nothing a user supplies reaches a
 * shell: Blender is started with an argument vector, and paths travel
 * inside JSON strings. */
#define _GNU_SOURCE
#include "blendtool.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef LIBBLEND_ADDON_REL
#define LIBBLEND_ADDON_REL "../share/libblend/blender_addon"
#endif

const char *bt_blender_exe(const char *option) {
    if (option && *option) return option;
    const char *e = getenv("LIBBLEND_BLENDER");
    return e && *e ? e : "blender";
}

/* the folder that holds libblend_blender/farm_worker.py */
static int find_addon(char *out, size_t n) {
    const char *env = getenv("LIBBLEND_BLENDER_ADDON");
    char self[PATH_MAX], p[2 * PATH_MAX + 128];
    struct stat st;
    if (env && *env) {
        snprintf(out, n, "%s", env);
        snprintf(p, sizeof p, "%s/libblend_blender/farm_worker.py", env);
        return stat(p, &st) == 0 ? 0 : -1;
    }
    if (bt_self_dir(self, sizeof self)) return -1;
    /* the build tree (tools/blendtool beside blender_addon/), then installed */
    static const char *const rel[] = {"../blender_addon", LIBBLEND_ADDON_REL};
    for (int k = 0; k < 2; ++k) {
        snprintf(p, sizeof p, "%s/%s/libblend_blender/farm_worker.py", self, rel[k]);
        if (stat(p, &st) == 0) {
            snprintf(out, n, "%s/%s", self, rel[k]);
            return 0;
        }
    }
    snprintf(p, sizeof p, "%s/../blender_addon or %s/%s", self, self, LIBBLEND_ADDON_REL);
    snprintf(out, n, "%.*s", (int)(n - 1), p);
    return -1;
}

/* the last part of the worker's output (at most n - 1 bytes) */
static void log_tail(const bt_blender *B, char *buf, size_t n) {
    buf[0] = '\0';
    if (B->logfd < 0 || n < 2) return;
    const off_t end = lseek(B->logfd, 0, SEEK_END);
    const off_t at = end > (off_t)(n - 1) ? end - (off_t)(n - 1) : 0;
    const ssize_t r = pread(B->logfd, buf, n - 1, at);
    buf[r > 0 ? r : 0] = '\0';
}

int bt_blender_version(const char *exe, char *out, size_t n) {
    int fds[2];
    out[0] = '\0';
    if (pipe2(fds, O_CLOEXEC)) return -1;
    const pid_t pid = fork();
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        dup2(fds[1], STDOUT_FILENO);
        const int nul = open("/dev/null", O_WRONLY);
        if (nul >= 0) dup2(nul, STDERR_FILENO);
        execlp(exe, exe, "--version", (char *)NULL);
        _exit(127);
    }
    close(fds[1]);
    char buf[4096];
    size_t len = 0;
    ssize_t r;
    while (pid > 0 && len + 1 < sizeof buf &&
           ((r = read(fds[0], buf + len, sizeof buf - 1 - len)) > 0 || (r < 0 && errno == EINTR)))
        if (r > 0) len += (size_t)r;
    buf[len] = '\0';
    close(fds[0]);
    int st = 0;
    while (pid > 0 && waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    /* the first line that starts with "Blender " */
    for (char *l = buf; l && *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL)
        if (strncmp(l, "Blender ", 8) == 0) {
            const size_t k = strcspn(l, "\r\n");
            snprintf(out, n, "%.*s", (int)(k < n ? k : n - 1), l);
            break;
        }
    return pid > 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 && out[0] ? 0 : -1;
}

static void reap(bt_blender *B, int *status) {
    int st = 0;
    if (B->pid > 0)
        while (waitpid(B->pid, &st, 0) < 0 && errno == EINTR) {
        }
    bt_signals_worker(0);
    B->pid = 0;
    if (status) *status = st;
    if (B->req) fclose(B->req);
    if (B->rep) fclose(B->rep);
    B->req = B->rep = NULL;
}

static int read_reply(bt_blender *B, cJSON **reply) {
    char *line = NULL;
    size_t cap = 0;
    const ssize_t r = getline(&line, &cap, B->rep);
    *reply = r > 0 ? cJSON_Parse(line) : NULL;
    free(line);
    return *reply ? 0 : -1;
}

/* "exit status 3" or "signal 9" of a finished worker, and its last output */
static void died(bt_blender *B, const char *when, char *err, size_t errlen) {
    char tail[1536];
    log_tail(B, tail, sizeof tail);
    int st = 0;
    if (B->req) { /* no more requests: a worker still running ends */
        fclose(B->req);
        B->req = NULL;
    }
    if (B->pid > 0) kill(B->pid, SIGKILL);
    reap(B, &st);
    snprintf(err, errlen, "the Blender worker (%s) died %s (%s %d); its last output:\n%s", B->exe,
             when, WIFSIGNALED(st) ? "signal" : "exit status",
             WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st), tail);
}

int bt_blender_start(bt_blender *B, char *err, size_t errlen) {
    char addon[2 * PATH_MAX + 128], script[2 * PATH_MAX + 200];
    if (find_addon(addon, sizeof addon)) {
        snprintf(err, errlen,
                 "cannot find the Blender add-on's farm worker (looked in %s); allowed: set "
                 "LIBBLEND_BLENDER_ADDON to the folder that holds libblend_blender/",
                 addon);
        return -1;
    }
    snprintf(script, sizeof script, "%s/libblend_blender/farm_worker.py", addon);
    int rq[2], rp[2];
    if (pipe2(rq, O_CLOEXEC) || pipe2(rp, O_CLOEXEC)) {
        snprintf(err, errlen, "cannot start the Blender worker: %s", strerror(errno));
        return -1;
    }
    if (B->logfd < 0) {
        const char *t = getenv("TMPDIR");
        B->logfd = open(t && *t ? t : "/tmp", O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    }
    const pid_t pid = fork();
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() == 1) _exit(127);
        /* fd 3: requests, fd 4: replies (moved out of the way first) */
        int in = fcntl(rq[0], F_DUPFD, 10), out = fcntl(rp[1], F_DUPFD, 10);
        if (in < 0 || out < 0 || dup2(in, 3) < 0 || dup2(out, 4) < 0) _exit(127);
        const int nul = open("/dev/null", O_RDONLY);
        if (nul >= 0) dup2(nul, STDIN_FILENO);
        /* Blender's messages never reach blendtool's own output (--log-json) */
        const int lf = B->logfd >= 0 ? B->logfd : open("/dev/null", O_WRONLY);
        if (lf < 0 || dup2(lf, STDOUT_FILENO) < 0 || dup2(lf, STDERR_FILENO) < 0) _exit(127);
        setenv("PYTHONDONTWRITEBYTECODE", "1", 1);
        execlp(B->exe, B->exe, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
               script, (char *)NULL);
        fprintf(stderr, "cannot run %s: %s\n", B->exe, strerror(errno));
        _exit(127);
    }
    close(rq[0]);
    close(rp[1]);
    if (pid < 0) {
        close(rq[1]);
        close(rp[0]);
        snprintf(err, errlen, "cannot start the Blender worker: %s", strerror(errno));
        return -1;
    }
    B->pid = pid;
    bt_signals_worker(pid);
    B->req = fdopen(rq[1], "w");
    B->rep = fdopen(rp[0], "r");
    cJSON *hello = NULL;
    if (!B->req || !B->rep || read_reply(B, &hello)) {
        cJSON_Delete(hello);
        died(B, "while starting", err, errlen);
        if (strstr(err, "exit status 127"))
            snprintf(err + strlen(err), errlen - strlen(err),
                     "\nallowed: install Blender (Debian package blender), or name it with "
                     "--blender PATH or LIBBLEND_BLENDER");
        return -1;
    }
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(hello, "blender");
    snprintf(B->running, sizeof B->running, "%s", cJSON_IsString(v) ? v->valuestring : "?");
    cJSON_Delete(hello);
    return 0;
}

/* The render's progress from the worker's output, the last such line
 * Blender printed: "Rendered T/N Tiles, Sample A/B" (Cycles with tiles, as
 * the worker renders: (T + A/B) / N), "Sample A/B" (Cycles in one tile) or
 * "Rendering A / B samples" (EEVEE); -1 when there is none yet. */
static double progress_of(const bt_blender *B) {
    char tail[2048];
    log_tail(B, tail, sizeof tail);
    double best = -1;
    for (const char *p = tail; (p = strpbrk(p, "SR")) != NULL; ++p) {
        int t = 0, n = 0, a = 0, b = 0;
        if (sscanf(p, "Rendered %d/%d Tiles, Sample %d/%d", &t, &n, &a, &b) == 4 && n > 0 &&
            b > 0 && t >= 0 && t < n && a >= 0 && a <= b)
            best = (t + (double)a / b) / n;
        else if ((sscanf(p, "Sample %d/%d", &a, &b) == 2 ||
                  sscanf(p, "Rendering %d / %d samples", &a, &b) == 2) &&
                 b > 0 && a >= 0 && a <= b && (p - tail < 2 || (p[-1] != ',' && p[-2] != ',')))
            best = (double)a / b;
    }
    return best;
}

int bt_blender_task(bt_blender *B, const char *request, char *err, size_t errlen,
                    void (*progress)(void *ctx, double fraction), void *ctx, double *seconds) {
    if (B->pid <= 0 && bt_blender_start(B, err, errlen)) return 2;
    if (lseek(B->logfd, 0, SEEK_SET) == 0 && ftruncate(B->logfd, 0) != 0) {
        /* the log keeps the older output; only its tail is shown */
    }
    /* a worker that died while idle: the write fails with EPIPE, and the
     * SIGPIPE it raises is held and taken back, so that blendtool goes on */
    sigset_t pipe_set, old;
    sigemptyset(&pipe_set);
    sigaddset(&pipe_set, SIGPIPE);
    sigprocmask(SIG_BLOCK, &pipe_set, &old);
    const int bad = fprintf(B->req, "%s\n", request) < 0 || fflush(B->req) != 0;
    sigset_t pending;
    if (sigpending(&pending) == 0 && sigismember(&pending, SIGPIPE)) {
        const struct timespec zero = {0, 0};
        sigtimedwait(&pipe_set, NULL, &zero);
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    if (bad) {
        died(B, "before the task", err, errlen);
        return 2;
    }
    /* while it renders: its progress every half second, reported in steps
     * of a tenth */
    int step = 0;
    struct pollfd pf = {fileno(B->rep), POLLIN, 0};
    for (;;) {
        const int r = poll(&pf, 1, 500);
        if (r > 0 || (r < 0 && errno != EINTR)) break;
        const double f = progress ? progress_of(B) : -1;
        if (f >= 0 && (int)(f * 10) > step) {
            step = (int)(f * 10);
            progress(ctx, f);
        }
    }
    cJSON *reply = NULL;
    if (read_reply(B, &reply)) {
        died(B, "during the task", err, errlen);
        return 2;
    }
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(reply, "error");
    for (int i = 0; i < 2 && seconds; ++i) {
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(reply, i ? "seconds" : "render_seconds");
        seconds[i] = cJSON_IsNumber(t) ? t->valuedouble : -1;
    }
    int rc = 0;
    if (cJSON_IsString(e)) {
        snprintf(err, errlen, "%s", e->valuestring);
        rc = 1;
    }
    cJSON_Delete(reply);
    return rc;
}

void bt_blender_stop(bt_blender *B) {
    if (B->pid > 0) {
        fclose(B->req); /* end of requests: the worker quits */
        B->req = NULL;
        reap(B, NULL);
    }
    if (B->logfd >= 0) close(B->logfd);
    B->logfd = -1;
}
