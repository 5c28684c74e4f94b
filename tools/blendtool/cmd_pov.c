/* blendtool pov: a scene as a POV-Ray file; blendtool render: the same,
 * rendered by povray into a PNG. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static int parse_int(const char *cmd, const char *opt, const char *v, long lo, long hi, int *out) {
    long n = 0;
    if (bt_parse_long(cmd, opt, v, lo, hi, "an integer", &n)) return -1;
    *out = (int)n;
    return 0;
}

typedef struct povargs {
    const char *scene, *out;
    int include_only, width, height, threads, quality, silhouette, bits, alpha, quiet, antialias,
        mesh, features, merge_flat;
    double simplify;
    const char *pixel;
    bt_set sets[BT_MAX_SETS];
    size_t nsets;
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
        } else if (render && (r = bt_option(cmd, argc, argv, &i, "--bits", &v))) {
            if (r < 0) return -1;
            if (strcmp(v, "8") && strcmp(v, "16")) {
                bt_error(cmd, "--bits %s; allowed: 8 or 16 (PNG)", v);
                return -1;
            }
            a->bits = atoi(v);
        } else if (render && (r = bt_option(cmd, argc, argv, &i, "--pixel", &v))) {
            if (r < 0) return -1;
            if (strcmp(v, "half") && strcmp(v, "float")) {
                bt_error(cmd, "--pixel %s; allowed: half or float (EXR)", v);
                return -1;
            }
            a->pixel = v;
        } else if (render && strcmp(argv[i], "--alpha") == 0) {
            a->alpha = 1;
        } else if (render && strcmp(argv[i], "--quiet") == 0) {
            a->quiet = 1;
        } else if (render && strcmp(argv[i], "--antialias") == 0) {
            a->antialias = 1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--mesh", &v))) {
            if (r < 0 || parse_int(cmd, "--mesh", v, 1, LB_POV_MAX_MESH_RESOLUTION, &a->mesh))
                return -1;
        } else if (strcmp(argv[i], "--features") == 0) {
            a->features = 1;
        } else if (strcmp(argv[i], "--merge-flat") == 0) {
            a->merge_flat = 1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--simplify", &v))) {
            if (r < 0) return -1;
            char *end = NULL;
            errno = 0;
            a->simplify = strtod(v, &end);
            if (errno || end == v || *end ||
                !(a->simplify > 0.0 && a->simplify <= LB_MESH_MAX_SIMPLIFY)) {
                bt_error(cmd,
                         "--simplify %s: expected a tolerance in cells, above 0 and at most %g", v,
                         LB_MESH_MAX_SIMPLIFY);
                return -1;
            }
        } else if (!render && strcmp(argv[i], "--include-only") == 0) {
            a->include_only = 1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--set", &v))) {
            if (r < 0 || bt_set_arg(cmd, v, a->sets, &a->nsets, BT_MAX_SETS)) return -1;
        } else if (strcmp(argv[i], "--silhouette") == 0) {
            a->silhouette = 1;
        } else if (bt_scene_arg(cmd, argv[i], &a->scene)) {
            return -1;
        }
    }
    if ((a->features || a->merge_flat || a->simplify > 0.0) && !a->mesh) {
        bt_error(cmd,
                 "%s without --mesh N; allowed: with --mesh N (they shape libblend's mesh; "
                 "the isosurface is exact)",
                 a->features     ? "--features"
                 : a->merge_flat ? "--merge-flat"
                                 : "--simplify");
        return -1;
    }
    if (a->mesh && a->include_only) {
        bt_error(cmd, "--mesh with --include-only; allowed: one of them (an include holds only "
                      "the field's functions)");
        return -1;
    }
    if (!a->scene || !a->out) {
        bt_error(cmd, "%s; see blendtool %s --help",
                 !a->scene ? "no scene given" : "no output (-o)", cmd);
        return -1;
    }
    return 0;
}

/* load, compile, write the .pov to an open output; hash (may be NULL)
 * receives the resolved scene's hash */
static int export(const char *cmd, const povargs *a, FILE *f, const char *out_name,
                  uint64_t hash[2]) {
    lb_scene *sc = NULL;
    int rc = bt_load_scene_set(cmd, a->scene, a->sets, a->nsets, &sc, hash);
    if (rc) return rc;
    lb_evaluator *ev = NULL;
    bt_warn_unused_m(cmd, a->scene, sc);
    if ((rc = bt_compile(cmd, a->scene, sc, &ev))) {
        lb_scene_free(sc);
        return rc;
    }
    lb_error e = {LB_OK, ""};
    const lb_pov_options o = {a->include_only,
                              a->silhouette,
                              (double)a->width / (double)a->height,
                              0.0,
                              a->threads,
                              a->mesh,
                              a->features,
                              a->simplify,
                              a->merge_flat};
    const lb_status s = lb_scene_write_pov_stream(sc, ev, &o, f, NULL, &e);
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
    povargs a = {.width = 640, .height = 480, .quality = 9};
    if (parse("pov", argc, argv, &a, 0)) return BT_EXIT_BAD_INPUT;
    bt_out w;
    int rc = bt_output_open("pov", a.out, &w);
    if (!rc) rc = export("pov", &a, w.f, a.out, NULL);
    if (!rc) rc = bt_output_commit("pov", &w);
    bt_output_discard(&w);
    return rc;
}

static int run_render(int argc, char **argv) {
    povargs a = {.width = 640, .height = 480, .quality = 9};
    if (parse("render", argc, argv, &a, 1)) return BT_EXIT_BAD_INPUT;
    const int fmt = bt_image_format("render", a.out, a.bits, a.pixel);
    if (fmt < 0) return BT_EXIT_BAD_INPUT;
    bt_image_plan plan;
    memset(&plan, 0, sizeof plan);
    bt_render_dir R;
    if (bt_render_dir_open(&R)) return BT_EXIT_INTERNAL;
    bt_out w;
    uint64_t hash[2] = {0, 0};
    int rc = bt_output_open("render", a.out, &w);
    if (!rc) {
        FILE *f = fopen(R.pov, "wb");
        if (!f) {
            bt_error("render", "%s: cannot write the scene (%s)", R.pov, strerror(errno));
            rc = BT_EXIT_INTERNAL;
        } else {
            rc = export("render", &a, f, R.pov, hash);
            if (fclose(f) != 0 && !rc) {
                bt_error("render", "%s: cannot write the scene (%s)", R.pov, strerror(errno));
                rc = BT_EXIT_INTERNAL;
            }
        }
    }
    /* how the image is written (the OpenImageIO module, or POV-Ray's own
     * PNG): asked once the scene is known to be good, so a bad scene is
     * exit 2 whatever the output format */
    if (!rc && bt_image_plan_for("render", a.out, fmt, a.alpha, &plan)) rc = BT_EXIT_INTERNAL;
    const bt_pov_run P = {a.width,     a.height,   a.threads, a.quality,
                          plan.bits16, plan.alpha, a.quiet,   a.antialias};
    if (!rc) rc = bt_povray(a.scene, &R, &P);
    unsigned char *img = NULL;
    size_t len = 0;
    if (!rc) {
        char hex[33], settings[128], params[4096], err[1024] = "";
        bt_hash_hex(hash, hex);
        bt_render_settings(settings, sizeof settings, &P, a.silhouette, a.mesh);
        const size_t sl = strlen(settings); /* the mesh's own options, when given */
        snprintf(settings + sl, sizeof settings - sl, "%s%s", a.features ? " features" : "",
                 a.merge_flat ? " merge-flat" : "");
        if (a.simplify > 0.0) {
            const size_t sl2 = strlen(settings);
            snprintf(settings + sl2, sizeof settings - sl2, " simplify %g", a.simplify);
        }
        size_t o = 0;
        params[0] = '\0';
        for (size_t i = 0; i < a.nsets && o + 1 < sizeof params; ++i) {
            const int n =
                snprintf(params + o, sizeof params - o, "%s%s", i ? " " : "", a.sets[i].path);
            if (n > 0) o += (size_t)n;
        }
        const lbi_meta meta[4] = {{"libblend:scene_hash", hex},
                                  {"libblend:version", BT_VERSION},
                                  {"libblend:render", settings},
                                  {"libblend:parameters", params}};
        if (bt_image_finish(&plan, R.png, fmt, meta, 4, &img, &len, err, sizeof err)) {
            bt_error("render", "%s: writing the image failed: %s", a.out, err);
            rc = BT_EXIT_INTERNAL;
        }
    }
    if (!rc && fwrite(img, 1, len, w.f) != len) {
        bt_error("render", "%s: writing the image failed (%s); nothing was written", a.out,
                 strerror(errno));
        rc = BT_EXIT_INTERNAL;
    }
    free(img);
    if (!rc) rc = bt_output_commit("render", &w);
    bt_output_discard(&w);
    bt_render_dir_close(&R);
    return rc;
}

const bt_command bt_cmd_pov = {
    "pov", "the scene as a POV-Ray 3.7 file (isosurface with a computed max_gradient)",
    "usage: blendtool pov SCENE -o OUT.pov [--include-only] [--silhouette] [--width W --height "
    "H]\n"
    "                     [--mesh N [--features] [--merge-flat] [--simplify TOL]]\n"
    "                     [--set PATH=VALUE]...\n\n"
    "Writes a complete POV-Ray 3.7 scene: the field as functions built with\n"
    "libblend.inc, one isosurface over the scene's bounds with a max_gradient\n"
    "computed by libblend, camera, lights and material from the scene's render\n"
    "section (or framing the bounds). Render it with\n"
    "  povray +IOUT.pov +LDIR\n"
    "where DIR holds libblend.inc: $LIBBLEND_POVRAY_INCLUDE, else the copy\n"
    "installed with blendtool (share/libblend/povray beside its bin/).\n"
    "  --include-only  only the field, for a scene of your own: LB_Field, LB_Surface\n"
    "                  (< 0 inside), LB_FieldMin/Max, LB_FieldMaxGradient, LB_FieldAccuracy\n"
    "  --silhouette    a white object on black, unshaded (for comparisons)\n"
    "  --mesh N        the surface as libblend's mesh at N cells (1..1024; smooth\n"
    "                  triangles, within half a cell) instead of the isosurface:\n"
    "                  seconds to render where a soft or local blend takes minutes\n"
    "  --features      with --mesh: sharp creases and corners kept, each side of a\n"
    "                  crease shaded with its own normal (normal_indices)\n"
    "  --merge-flat    with --mesh: flat regions in few triangles, no vertex moved\n"
    "                  (as blendtool mesh --merge-flat)\n"
    "  --simplify TOL  with --mesh: merge triangles within TOL cells of the field\n"
    "                  (0 < TOL <= 1; as blendtool mesh --simplify)\n"
    "  --width, --height  the image's aspect ratio for the camera (640 x 480)\n"
    "  --set PATH=VALUE  override a scene value first (VALUE is JSON); repeatable\n"
    "Exit status: 0 success, 2 bad scene (or one POV-Ray cannot express) or options, 1\n"
    "internal failure or failure writing OUT, 130 / 143 / 129 ended by SIGINT / SIGTERM /\n"
    "SIGHUP (nothing written).\n",
    run_pov};

const bt_command bt_cmd_render = {
    "render", "render the scene with POV-Ray into a PNG",
    "usage: blendtool render SCENE -o OUT.{png,exr} [--width W] [--height H] [--threads N]\n"
    "                        [--quality Q] [--silhouette] [--bits 8|16] [--pixel half|float]\n"
    "                        [--alpha] [--antialias] [--quiet]\n"
    "                        [--mesh N [--features] [--merge-flat] [--simplify TOL]]\n"
    "                        [--set PATH=VALUE]...\n\n"
    "Exports the scene (as blendtool pov) and runs povray on it; povray's progress\n"
    "streams to standard error (--quiet: into a log, shown only if povray fails).\n"
    "The image is written by OpenImageIO: PNG (8 or 16 bits) or OpenEXR (half or\n"
    "float), RGB or with --alpha RGBA, with the scene's hash, libblend's version and\n"
    "the render settings as metadata and no time stamp: the same scene and options\n"
    "give the same bytes at --threads 1 (POV-Ray's threads share out the area\n"
    "light's jitter differently from run to run). OUT appears only when the render\n"
    "succeeded. Without OpenImageIO (its module cannot be loaded), POV-Ray writes\n"
    "the PNG itself, with the same metadata; EXR then fails.\n"
    "libblend.inc is taken from the folder $LIBBLEND_POVRAY_INCLUDE, else from the\n"
    "copy installed with blendtool (share/libblend/povray beside its bin/).\n"
    "  --width, --height  image size (640 x 480)\n"
    "  --threads N        render threads (0 = one per CPU)\n"
    "  --quality Q        POV-Ray quality 0..11 (9)\n"
    "  --silhouette       a white object on black, unshaded\n"
    "  --bits 8|16        PNG channel depth (8)\n"
    "  --pixel half|float EXR pixel type (half)\n"
    "  --alpha            keep the alpha channel (transparent background)\n"
    "  --antialias        POV-Ray's adaptive antialiasing (smooth edges; slower), no jitter\n"
    "  --quiet            no POV-Ray banner or progress (shown only when povray fails)\n"
    "  --mesh N           render libblend's mesh at N cells (1..1024) instead of the\n"
    "                     isosurface: much faster for soft and local blends, within\n"
    "                     half a cell of the surface (blendtool pov --help)\n"
    "  --set PATH=VALUE   override a scene value first (VALUE is JSON); repeatable\n"
    "A signal (SIGINT, SIGTERM, SIGHUP) ends povray too and removes the temporary\n"
    "folder ($TMPDIR or /tmp/blendtool-render-PID-*); a folder left by a killed run is\n"
    "removed by the next render.\n"
    "Exit status: 0 success, 2 bad scene or options, 1 povray failed or failure writing\n"
    "OUT, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP (nothing written).\n",
    run_render};
