/* blendtool pov: a scene as a POV-Ray file; blendtool render: the same,
 * rendered by povray into a PNG. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
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

/* load, compile, write the .pov */
static int export(const char *cmd, const povargs *a, const char *path) {
    lb_scene *sc = NULL;
    int rc = bt_load_scene(cmd, a->scene, &sc);
    if (rc) return rc;
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_status s = lb_evaluator_create(sc, &ev, &e);
    if (!s) {
        lb_pov_options o = {a->include_only, a->silhouette, (double)a->width / (double)a->height,
                            0.0, a->threads};
        s = lb_scene_write_pov(sc, ev, &o, path, NULL, &e);
    }
    if (s) {
        bt_error(cmd, "%s: %s", a->scene, e.message);
        rc = s == LB_ERR_INVALID_ARGUMENT || s == LB_ERR_IO ? BT_EXIT_BAD_INPUT : BT_EXIT_INTERNAL;
    }
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return rc;
}

static int run_pov(int argc, char **argv) {
    povargs a = {NULL, NULL, 0, 640, 480, 0, 9, 0};
    if (parse("pov", argc, argv, &a, 0)) return BT_EXIT_BAD_INPUT;
    return export("pov", &a, a.out);
}

static int run_render(int argc, char **argv) {
    povargs a = {NULL, NULL, 0, 640, 480, 0, 9, 0};
    if (parse("render", argc, argv, &a, 1)) return BT_EXIT_BAD_INPUT;
    const size_t ol = strlen(a.out);
    if (ol < 5 || strcmp(a.out + ol - 4, ".png") != 0) {
        bt_error("render", "%s: allowed: an output name ending in .png", a.out);
        return BT_EXIT_BAD_INPUT;
    }
    char dir[] = "/tmp/blendtool-render-XXXXXX";
    if (!mkdtemp(dir)) {
        bt_error("render", "cannot create a temporary folder: %s", strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    char pov[512], png[512], inc[4096], outw[64], outh[64], th[64], q[32];
    snprintf(pov, sizeof pov, "%s/scene.pov", dir);
    snprintf(png, sizeof png, "%s/image.png", dir);
    int rc = export("render", &a, pov);
    if (!rc) {
        snprintf(inc, sizeof inc, "+L%s", include_dir());
        snprintf(outw, sizeof outw, "+W%d", a.width);
        snprintf(outh, sizeof outh, "+H%d", a.height);
        snprintf(th, sizeof th, "+WT%d",
                 a.threads > 0 ? a.threads : (int)sysconf(_SC_NPROCESSORS_ONLN));
        snprintf(q, sizeof q, "+Q%d", a.quality);
        char in[600], out[600];
        snprintf(in, sizeof in, "+I%s", pov);
        snprintf(out, sizeof out, "+O%s", png);
        const pid_t pid = fork();
        if (pid == 0) {
            /* povray's own progress goes to stderr: the user sees it stream */
            execlp("povray", "povray", in, out, inc, outw, outh, th, q, "-D", "+FN", "-V",
                   (char *)NULL);
            fprintf(stderr,
                    "blendtool render: cannot run povray (%s); allowed: install POV-Ray "
                    "3.7 (Debian package povray)\n",
                    strerror(errno));
            _exit(127);
        }
        int status = 0;
        if (pid < 0 || waitpid(pid, &status, 0) < 0) {
            bt_error("render", "cannot start povray: %s", strerror(errno));
            rc = BT_EXIT_INTERNAL;
        } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            if (!(WIFEXITED(status) && WEXITSTATUS(status) == 127))
                bt_error("render", "povray failed (%s %d) on %s; its messages are above",
                         WIFEXITED(status) ? "exit status" : "signal",
                         WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), a.scene);
            rc = BT_EXIT_INTERNAL;
        } else if (rename(png, a.out) != 0) {
            /* another file system: copy through */
            FILE *f = fopen(png, "rb");
            char *buf = NULL;
            size_t n = 0;
            if (f) {
                fseek(f, 0, SEEK_END);
                n = (size_t)ftell(f);
                fseek(f, 0, SEEK_SET);
                buf = malloc(n ? n : 1);
                if (!buf || fread(buf, 1, n, f) != n) n = 0;
                fclose(f);
            }
            rc = buf && n ? bt_write_file("render", a.out, buf, n) : BT_EXIT_INTERNAL;
            free(buf);
        }
    }
    remove(pov);
    remove(png);
    rmdir(dir);
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
    "Exit status: 0 success, 2 bad scene (or one POV-Ray cannot express), 1 internal\n"
    "failure.\n",
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
    "Exit status: 0 success, 2 bad scene or options, 1 povray failed.\n",
    run_render};
