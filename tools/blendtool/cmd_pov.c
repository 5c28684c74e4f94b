/* blendtool pov: a scene as a POV-Ray file; blendtool render: the same,
 * rendered by povray into a PNG. */
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

#ifndef LIBBLEND_POVRAY_DIR
#define LIBBLEND_POVRAY_DIR "/usr/local/share/libblend/povray"
#endif

/* where libblend.inc is: $LIBBLEND_POVRAY_INCLUDE, else the built-in path */
static const char *include_dir(void) {
    const char *e = getenv("LIBBLEND_POVRAY_INCLUDE");
    return e && *e ? e : LIBBLEND_POVRAY_DIR;
}

static int parse_int(const char *cmd, const char *opt, const char *v, long lo, long hi, int *out) {
    char *end = NULL;
    errno = 0;
    const long n = strtol(v, &end, 10);
    if (errno || !end || *end || end == v || n < lo || n > hi) {
        bt_error(cmd, "%s %s: expected an integer from %ld to %ld", opt, v, lo, hi);
        return -1;
    }
    *out = (int)n;
    return 0;
}

typedef struct povargs {
    const char *scene, *out;
    int include_only, width, height, threads, quality, silhouette;
} povargs;

static int parse(const char *cmd, int argc, char **argv, povargs *a, int render) {
    const char *v = NULL;
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option(cmd, argc, argv, &i, "-o", &v)) ||
            (r = bt_option(cmd, argc, argv, &i, "--output", &v))) {
            if (r < 0) return -1;
            a->out = v;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--width", &v))) {
            if (r < 0 || parse_int(cmd, "--width", v, 1, 16384, &a->width)) return -1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--height", &v))) {
            if (r < 0 || parse_int(cmd, "--height", v, 1, 16384, &a->height)) return -1;
        } else if (render && (r = bt_option(cmd, argc, argv, &i, "--threads", &v))) {
            if (r < 0 || bt_parse_threads(cmd, v, &a->threads)) return -1;
        } else if (render && (r = bt_option(cmd, argc, argv, &i, "--quality", &v))) {
            if (r < 0 || parse_int(cmd, "--quality", v, 0, 11, &a->quality)) return -1;
        } else if (!render && strcmp(argv[i], "--include-only") == 0) {
            a->include_only = 1;
        } else if (strcmp(argv[i], "--silhouette") == 0) {
            a->silhouette = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            bt_error(cmd, "unknown option %s; see blendtool %s --help", argv[i], cmd);
            return -1;
        } else if (!a->scene) {
            a->scene = argv[i];
        } else {
            bt_error(cmd, "more than one scene (%s, %s); allowed: one", a->scene, argv[i]);
            return -1;
        }
    }
    if (!a->scene || !a->out) {
        bt_error(cmd, "%s; see blendtool %s --help",
                 !a->scene ? "no scene given" : "no output (-o)", cmd);
        return -1;
    }
    return 0;
}

/* load, compile, write the .pov to an open output */
static int export(const char *cmd, const povargs *a, FILE *f, const char *out_name) {
    lb_scene *sc = NULL;
    int rc = bt_load_scene(cmd, a->scene, &sc);
    if (rc) return rc;
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_status s = lb_evaluator_create(sc, &ev, &e);
    if (!s) {
        lb_pov_options o = {a->include_only, a->silhouette, (double)a->width / (double)a->height,
                            0.0, a->threads};
        s = lb_scene_write_pov_stream(sc, ev, &o, f, NULL, &e);
    }
    if (s == LB_ERR_IO) {
        bt_error(cmd, "%s: writing the POV-Ray scene failed (%s); nothing was written", out_name,
                 strerror(errno));
        rc = BT_EXIT_INTERNAL;
    } else if (s) {
        rc = bt_fail(cmd, a->scene, s, &e);
    }
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return rc;
}

static int run_pov(int argc, char **argv) {
    povargs a = {NULL, NULL, 0, 640, 480, 0, 9, 0};
    if (parse("pov", argc, argv, &a, 0)) return BT_EXIT_BAD_INPUT;
    bt_out w;
    int rc = bt_output_open("pov", a.out, &w);
    if (!rc) rc = export("pov", &a, w.f, a.out);
    if (!rc) rc = bt_output_commit("pov", &w);
    bt_output_discard(&w);
    return rc;
}

/* Render folders are "blendtool-render-PID-XXXXXX" in $TMPDIR (or /tmp);
 * those of processes that are gone (killed with SIGKILL) are removed. */
static const char *tmp_root(void) {
    const char *t = getenv("TMPDIR");
    return t && *t ? t : "/tmp";
}

/* what a render folder holds: the scene, the image, and the state file
 * povray writes when it is stopped mid-render */
static const char *const RENDER_FILES[] = {"scene.pov", "image.png", "image.pov-state"};

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
        for (int i = 0; i < 3; ++i) {
            snprintf(path, sizeof path, "%s/%s/%s", tmp_root(), e->d_name, RENDER_FILES[i]);
            unlink(path);
        }
        snprintf(path, sizeof path, "%s/%s", tmp_root(), e->d_name);
        rmdir(path);
    }
    closedir(d);
}

/* povray on the exported scene; returns an exit code */
static int povray(const povargs *a, const char *pov, const char *png) {
    char inc[4096], outw[64], outh[64], th[64], q[32], in[4300], out[4300];
    snprintf(inc, sizeof inc, "+L%s", include_dir());
    snprintf(outw, sizeof outw, "+W%d", a->width);
    snprintf(outh, sizeof outh, "+H%d", a->height);
    snprintf(th, sizeof th, "+WT%d",
             a->threads > 0 ? a->threads : (int)sysconf(_SC_NPROCESSORS_ONLN));
    snprintf(q, sizeof q, "+Q%d", a->quality);
    snprintf(in, sizeof in, "+I%s", pov);
    snprintf(out, sizeof out, "+O%s", png);
    const pid_t pid = fork();
    if (pid == 0) {
        /* povray ends with blendtool, even when blendtool is killed */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() == 1) _exit(127);
        /* povray's own progress goes to stderr: the user sees it stream */
        execlp("povray", "povray", in, out, inc, outw, outh, th, q, "-D", "+FN", "-V",
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
        if (!(WIFEXITED(status) && WEXITSTATUS(status) == 127))
            bt_error("render", "povray failed (%s %d) on %s; its messages are above",
                     WIFEXITED(status) ? "exit status" : "signal",
                     WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), a->scene);
        return BT_EXIT_INTERNAL;
    }
    return BT_EXIT_OK;
}

/* copy the rendered image into the open output */
static int copy_image(const char *png, bt_out *w) {
    FILE *f = fopen(png, "rb");
    if (!f) {
        bt_error("render", "povray wrote no image (%s)", strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    char buf[65536];
    size_t n;
    int ok = 1;
    while (ok && (n = fread(buf, 1, sizeof buf, f)) > 0) ok = fwrite(buf, 1, n, w->f) == n;
    ok = ok && !ferror(f);
    fclose(f);
    if (!ok) {
        bt_error("render", "%s: copying the image failed (%s); nothing was written", w->path,
                 strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    return BT_EXIT_OK;
}

static int run_render(int argc, char **argv) {
    povargs a = {NULL, NULL, 0, 640, 480, 0, 9, 0};
    if (parse("render", argc, argv, &a, 1)) return BT_EXIT_BAD_INPUT;
    const size_t ol = strlen(a.out);
    if ((ol < 5 || strcmp(a.out + ol - 4, ".png") != 0) && !bt_is_stream(a.out)) {
        bt_error("render", "%s: allowed: an output name ending in .png (or a device or FIFO)",
                 a.out);
        return BT_EXIT_BAD_INPUT;
    }
    remove_stale_renders();
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/blendtool-render-%ld-XXXXXX", tmp_root(), (long)getpid());
    if (!mkdtemp(dir)) {
        bt_error("render", "%s: cannot create a temporary folder: %s", tmp_root(), strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    char pov[4200], png[4200], state[4200];
    snprintf(pov, sizeof pov, "%s/%s", dir, RENDER_FILES[0]);
    snprintf(png, sizeof png, "%s/%s", dir, RENDER_FILES[1]);
    snprintf(state, sizeof state, "%s/%s", dir, RENDER_FILES[2]);
    /* registered before they exist: the handler removes what is there */
    const int s1 = bt_signals_temp(pov), s2 = bt_signals_temp(png), s3 = bt_signals_temp(state);
    bt_signals_temp_dir(dir);
    bt_out w;
    int rc = bt_output_open("render", a.out, &w);
    if (!rc) {
        FILE *f = fopen(pov, "wb");
        if (!f) {
            bt_error("render", "%s: cannot write the scene (%s)", pov, strerror(errno));
            rc = BT_EXIT_INTERNAL;
        } else {
            rc = export("render", &a, f, pov);
            if (fclose(f) != 0 && !rc) {
                bt_error("render", "%s: cannot write the scene (%s)", pov, strerror(errno));
                rc = BT_EXIT_INTERNAL;
            }
        }
    }
    if (!rc) rc = povray(&a, pov, png);
    if (!rc) rc = copy_image(png, &w);
    if (!rc) rc = bt_output_commit("render", &w);
    bt_output_discard(&w);
    remove(pov);
    remove(png);
    remove(state);
    rmdir(dir);
    bt_signals_untemp(s1);
    bt_signals_untemp(s2);
    bt_signals_untemp(s3);
    bt_signals_temp_dir(NULL);
    return rc;
}

const bt_command bt_cmd_pov = {
    "pov", "the scene as a POV-Ray 3.7 file (isosurface with a computed max_gradient)",
    "usage: blendtool pov SCENE -o OUT.pov [--include-only] [--silhouette] [--width W --height "
    "H]\n\n"
    "Writes a complete POV-Ray 3.7 scene: the field as functions built with\n"
    "libblend.inc, one isosurface over the scene's bounds with a max_gradient\n"
    "computed by libblend, camera, lights and material from the scene's render\n"
    "section (or framing the bounds). Render it with\n"
    "  povray +IOUT.pov +L" LIBBLEND_POVRAY_DIR "\n"
    "  --include-only  only the function declarations (the field is LB_Field)\n"
    "  --silhouette    a white object on black, unshaded (for comparisons)\n"
    "  --width, --height  the image's aspect ratio for the camera (640 x 480)\n"
    "Exit status: 0 success, 2 bad scene (or one POV-Ray cannot express) or options, 1\n"
    "internal failure or failure writing OUT, 130 / 143 / 129 ended by SIGINT / SIGTERM /\n"
    "SIGHUP (nothing written).\n",
    run_pov};

const bt_command bt_cmd_render = {
    "render", "render the scene with POV-Ray into a PNG",
    "usage: blendtool render SCENE -o OUT.png [--width W] [--height H] [--threads N]\n"
    "                        [--quality Q] [--silhouette]\n\n"
    "Exports the scene (as blendtool pov) and runs povray on it; povray's progress\n"
    "streams to standard error. OUT.png appears only when the render succeeded.\n"
    "libblend.inc is taken from $LIBBLEND_POVRAY_INCLUDE or " LIBBLEND_POVRAY_DIR ".\n"
    "  --width, --height  image size (640 x 480)\n"
    "  --threads N        render threads (0 = one per CPU)\n"
    "  --quality Q        POV-Ray quality 0..11 (9)\n"
    "  --silhouette       a white object on black, unshaded\n"
    "A signal (SIGINT, SIGTERM, SIGHUP) ends povray too and removes the temporary\n"
    "folder ($TMPDIR or /tmp/blendtool-render-PID-*); a folder left by a killed run is\n"
    "removed by the next render.\n"
    "Exit status: 0 success, 2 bad scene or options, 1 povray failed or failure writing\n"
    "OUT, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP (nothing written).\n",
    run_render};
