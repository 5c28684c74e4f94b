/* Rendering through POV-Ray, shared by blendtool render and batch images:
 * the private render folder (made, cleaned up after a
 * signal, stale ones of dead processes removed), running povray on it with
 * its paths in an INI file, and the output format of an image name. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* Render folders are "blendtool-render-PID-XXXXXX" in $TMPDIR (or /tmp);
 * those of processes that are gone (killed with SIGKILL) are removed. */
static const char *tmp_root(void) {
    const char *t = getenv("TMPDIR");
    return t && *t ? t : "/tmp";
}

/* what a render folder holds: the scene, the image, and the state file
 * povray writes when it is stopped mid-render */
static const char *const RENDER_FILES[BT_RENDER_FILES] = {
    "scene.pov",  "image.png",  "image.pov-state", "povray.log",
    "render.ini", "scene.json", "before.json",     "after.json"};

static void remove_stale_renders(void) {
    DIR *d = opendir(tmp_root());
    if (!d) return;
    static const char prefix[] = "blendtool-render-";
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, prefix, sizeof prefix - 1) != 0) continue;
        char *end = NULL;
        const long pid = strtol(e->d_name + sizeof prefix - 1, &end, 10);
        if (pid <= 0 || !end || *end != '-') continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
        char path[4096];
        for (size_t i = 0; i < BT_RENDER_FILES; ++i) {
            snprintf(path, sizeof path, "%s/%s/%s", tmp_root(), e->d_name, RENDER_FILES[i]);
            unlink(path);
        }
        snprintf(path, sizeof path, "%s/%s", tmp_root(), e->d_name);
        rmdir(path);
    }
    closedir(d);
}

void bt_render_settings(char *out, size_t len, const bt_pov_run *P, int silhouette, int mesh) {
    char m[32] = "";
    if (mesh) snprintf(m, sizeof m, " mesh %d", mesh);
    snprintf(out, len, "%dx%d quality %d%s%s%s", P->width, P->height, P->quality,
             silhouette ? " silhouette" : "", P->antialias ? " antialias" : "", m);
}

int bt_povray(const char *scene_name, const bt_render_dir *R, const bt_pov_run *P) {
    char outw[64], outh[64], th[64], q[32], dir[4096];
    if (bt_povray_include("render", dir, sizeof dir)) return BT_EXIT_INTERNAL;
    /* POV-Ray splits its command line at spaces, even inside one argument
     * (+L/a b fails): the paths go into an INI file as quoted strings, and
     * povray runs in the render folder, given the INI file by its bare name */
    const char *const log = P->quiet ? R->log : NULL;
    const char *const paths[3] = {R->pov, R->png, dir};
    for (int i = 0; i < 3; ++i)
        if (strpbrk(paths[i], "\"\n\r")) {
            bt_error("render",
                     "%s: POV-Ray cannot take a path with a double quote or a line break; "
                     "allowed: another folder (set TMPDIR, or LIBBLEND_POVRAY_INCLUDE)",
                     paths[i]);
            return BT_EXIT_INTERNAL;
        }
    FILE *fi = fopen(R->ini, "w");
    if (!fi ||
        fprintf(fi, "Input_File_Name=\"%s\"\nOutput_File_Name=\"%s\"\nLibrary_Path=\"%s\"\n",
                R->pov, R->png, dir) < 0 ||
        fclose(fi) != 0) {
        bt_error("render", "%s: cannot write: %s", R->ini, strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    snprintf(outw, sizeof outw, "+W%d", P->width);
    snprintf(outh, sizeof outh, "+H%d", P->height);
    snprintf(th, sizeof th, "+WT%d",
             P->threads > 0 ? P->threads : (int)sysconf(_SC_NPROCESSORS_ONLN));
    snprintf(q, sizeof q, "+Q%d", P->quality);
    const char *const ini_name = R->ini + strlen(R->dir) + 1; /* run in R->dir */
    const pid_t pid = fork();
    if (pid == 0) {
        /* povray ends with blendtool, even when blendtool is killed */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() == 1) _exit(127);
        /* povray's own progress goes to stderr: the user sees it stream;
         * or into log (batch), shown when povray fails */
        if (log) {
            FILE *lf = fopen(log, "w");
            if (lf) {
                dup2(fileno(lf), STDERR_FILENO);
                dup2(fileno(lf), STDOUT_FILENO);
            }
        }
        if (chdir(R->dir) != 0) _exit(127);
        /* antialiasing: adaptive (method 2, 3 levels) where neighbours
         * differ by more than 0.3, no jitter */
        execlp("povray", "povray", ini_name, outw, outh, th, q, "-D", P->bits16 ? "+FN16" : "+FN8",
               P->alpha ? "+UA" : "-UA", "-V", P->antialias ? "+A0.3" : "-A", "+AM2", "+R3", "-J",
               (char *)NULL);
        fprintf(stderr,
                "blendtool render: cannot run povray (%s); allowed: install POV-Ray 3.7 (Debian "
                "package povray)\n",
                strerror(errno));
        _exit(127);
    }
    if (pid > 0) bt_signals_child(pid);
    int status = 0;
    pid_t w = -1;
    if (pid > 0)
        while ((w = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
        }
    bt_signals_child(0);
    if (pid < 0 || w < 0) {
        bt_error("render", "cannot start povray: %s", strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        FILE *lf = log ? fopen(log, "r") : NULL;
        if (lf) { /* its last lines */
            char buf[8192];
            const long at = fseek(lf, 0, SEEK_END) == 0 ? ftell(lf) : 0;
            fseek(lf, at > (long)sizeof buf - 1 ? at - (long)sizeof buf + 1 : 0, SEEK_SET);
            const size_t n = fread(buf, 1, sizeof buf - 1, lf);
            buf[n] = '\0';
            fclose(lf);
            fprintf(stderr, "%s", buf);
        }
        if (!(WIFEXITED(status) && WEXITSTATUS(status) == 127))
            bt_error("render", "povray failed (%s %d) on %s; its messages are above",
                     WIFEXITED(status) ? "exit status" : "signal",
                     WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), scene_name);
        return BT_EXIT_INTERNAL;
    }
    return BT_EXIT_OK;
}

int bt_render_dir_open(bt_render_dir *r) {
    remove_stale_renders();
    snprintf(r->dir, sizeof r->dir, "%s/blendtool-render-%ld-XXXXXX", tmp_root(), (long)getpid());
    if (!mkdtemp(r->dir)) {
        bt_error("render", "%s: cannot create a temporary folder: %s", tmp_root(), strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    /* registered before they exist: the handler removes what is there */
    char *const files[BT_RENDER_FILES] = {r->pov, r->png,  r->state,  r->log,
                                          r->ini, r->json, r->before, r->after};
    for (size_t i = 0; i < BT_RENDER_FILES; ++i) {
        snprintf(files[i], sizeof r->pov, "%s/%s", r->dir, RENDER_FILES[i]);
        r->slot[i] = bt_signals_temp(files[i]);
    }
    bt_signals_temp_dir(r->dir);
    return BT_EXIT_OK;
}

void bt_render_dir_close(bt_render_dir *r) {
    const char *const files[BT_RENDER_FILES] = {r->pov, r->png,  r->state,  r->log,
                                                r->ini, r->json, r->before, r->after};
    for (size_t i = 0; i < BT_RENDER_FILES; ++i) remove(files[i]);
    rmdir(r->dir);
    for (size_t i = 0; i < BT_RENDER_FILES; ++i) bt_signals_untemp(r->slot[i]);
    bt_signals_temp_dir(NULL);
}

int bt_image_format(const char *cmd, const char *out, int bits, const char *pixel) {
    const size_t ol = strlen(out);
    const int exr = ol > 4 && strcmp(out + ol - 4, ".exr") == 0;
    const int png = ol > 4 && strcmp(out + ol - 4, ".png") == 0;
    if (!exr && !png && !bt_is_stream(out)) {
        bt_error(cmd,
                 "%s: allowed: an image name ending in .png or .exr (or a device or FIFO, "
                 "written as PNG)",
                 out);
        return -1;
    }
    if (exr && bits) {
        bt_error(cmd, "%s: --bits is for PNG; allowed for EXR: --pixel half|float", out);
        return -1;
    }
    if (!exr && pixel) {
        bt_error(cmd, "%s: --pixel is for EXR; allowed for PNG: --bits 8|16", out);
        return -1;
    }
    if (exr) return pixel && strcmp(pixel, "float") == 0 ? LBI_EXR_FLOAT : LBI_EXR_HALF;
    return bits == 16 ? LBI_PNG16 : LBI_PNG8;
}

void bt_hash_hex(const uint64_t h[2], char out[33]) {
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)h[0], (unsigned long long)h[1]);
}
