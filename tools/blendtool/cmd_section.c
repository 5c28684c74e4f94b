/* blendtool section: a plot of the field on an axis-aligned plane, the
 * surface's contour for each value of one parameter overlaid in one image
 * (the papers' 2D plots), computed by libblend's evaluator and written by
 * OpenImageIO. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SECTION_MAX_VALUES 8
#define LEGEND_H 44 /* pixels under the plot: the legend and the caption */

/* one colour per parameter value, sRGB */
static const float PALETTE[SECTION_MAX_VALUES][3] = {
    {0.80f, 0.12f, 0.10f}, {0.95f, 0.55f, 0.05f}, {0.15f, 0.55f, 0.20f}, {0.10f, 0.35f, 0.80f},
    {0.55f, 0.20f, 0.70f}, {0.05f, 0.60f, 0.65f}, {0.50f, 0.30f, 0.10f}, {0.00f, 0.00f, 0.00f}};

typedef struct secargs {
    const char *scene, *out, *sweep, *label;
    int width, height, threads, axis, have_region;
    double at, region[4];
    bt_set sets[BT_MAX_SETS];
    size_t nsets;
} secargs;

static int parse_numbers(const char *cmd, const char *opt, const char *v, double *out, int n) {
    const char *p = v;
    for (int i = 0; i < n; ++i) {
        char *end = NULL;
        errno = 0;
        out[i] = strtod(p, &end);
        if (end == p || errno || !isfinite(out[i]) || fabs(out[i]) > 1e12 ||
            (i < n - 1 ? *end != ',' : *end != '\0')) {
            bt_error(cmd,
                     "%s %s: expected %d numbers separated by commas (finite, magnitude at "
                     "most 1e12)",
                     opt, v, n);
            return -1;
        }
        p = end + 1;
    }
    return 0;
}

static int parse_size(const char *cmd, const char *opt, const char *v, int *out) {
    char *end = NULL;
    errno = 0;
    const long n = strtol(v, &end, 10);
    if (!end || end == v || *end || errno || n < 64 || n > 4096) {
        bt_error(cmd, "%s %s; allowed: an integer from 64 to 4096", opt, v);
        return -1;
    }
    *out = (int)n;
    return 0;
}

static int parse(int argc, char **argv, secargs *a) {
    const char *cmd = "section", *v = NULL;
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option(cmd, argc, argv, &i, "-o", &v)) ||
            (r = bt_option(cmd, argc, argv, &i, "--output", &v))) {
            if (r < 0) return -1;
            a->out = v;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--plane", &v))) {
            if (r < 0) return -1;
            if (!(v[0] == 'x' || v[0] == 'y' || v[0] == 'z') || v[1] != '=' ||
                parse_numbers(cmd, "--plane", v + 2, &a->at, 1)) {
                bt_error(cmd, "--plane %s; allowed: x=C, y=C or z=C (a number C)", v);
                return -1;
            }
            a->axis = v[0] - 'x';
        } else if ((r = bt_option(cmd, argc, argv, &i, "--region", &v))) {
            if (r < 0 || parse_numbers(cmd, "--region", v, a->region, 4)) return -1;
            if (!(a->region[0] < a->region[2] && a->region[1] < a->region[3])) {
                bt_error(cmd, "--region %s; allowed: U0,V0,U1,V1 with U0 < U1 and V0 < V1", v);
                return -1;
            }
            a->have_region = 1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--width", &v))) {
            if (r < 0 || parse_size(cmd, "--width", v, &a->width)) return -1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--height", &v))) {
            if (r < 0 || parse_size(cmd, "--height", v, &a->height)) return -1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--threads", &v))) {
            if (r < 0 || bt_parse_threads(cmd, v, &a->threads)) return -1;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--sweep", &v))) {
            if (r < 0) return -1;
            a->sweep = v;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--label", &v))) {
            if (r < 0) return -1;
            int ok = *v && strlen(v) <= 32;
            for (const char *c = v; ok && *c; ++c) ok = *c > ' ' && *c < 127 && *c != '=';
            if (!ok) {
                bt_error(cmd,
                         "--label %s; allowed: 1 to 32 printable ASCII characters without "
                         "spaces or '=' (such as m2)",
                         v);
                return -1;
            }
            a->label = v;
        } else if ((r = bt_option(cmd, argc, argv, &i, "--set", &v))) {
            /* one place stays free for the --sweep value */
            if (r < 0 || bt_set_arg(cmd, v, a->sets, &a->nsets, BT_MAX_SETS - 1)) return -1;
        } else if (bt_scene_arg(cmd, argv[i], &a->scene)) {
            return -1;
        }
    }
    if (!a->scene || !a->out || a->axis < 0) {
        bt_error(cmd, "%s; see blendtool section --help",
                 !a->scene ? "no scene given"
                 : !a->out ? "no output (-o)"
                           : "no --plane");
        return -1;
    }
    return 0;
}

/* "PATH=[v1, v2, ...]": the path and each value's JSON text (malloc'd, freed
 * by the caller) */
static int parse_sweep(const char *arg, char *path, size_t plen, char **values, size_t *n) {
    const char *eq = strchr(arg, '=');
    *n = 0;
    if (!eq || eq == arg || (size_t)(eq - arg) >= plen) {
        bt_error("section", "--sweep %s; allowed: PATH=[V1, V2, ...] (JSON values)", arg);
        return -1;
    }
    memcpy(path, arg, (size_t)(eq - arg));
    path[eq - arg] = '\0';
    cJSON *list = cJSON_Parse(eq + 1);
    const int k = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : -1;
    if (k < 1 || k > SECTION_MAX_VALUES) {
        bt_error("section", "--sweep %s: the values are %s; allowed: a JSON list of 1 to %d values",
                 arg, k < 0 ? "not a JSON list" : "an empty list", SECTION_MAX_VALUES);
        if (k > SECTION_MAX_VALUES) bt_error("section", "(%d values given)", k);
        cJSON_Delete(list);
        return -1;
    }
    for (const cJSON *e = list->child; e; e = e->next) values[(*n)++] = cJSON_PrintUnformatted(e);
    cJSON_Delete(list);
    for (size_t i = 0; i < *n; ++i)
        if (!values[i]) return -1;
    return 0;
}

/* the plot's pixel centres, and the field and its gradient there */
typedef struct plotgrid {
    double *x, *y, *z, *f, *g[3];
} plotgrid;

static int run(int argc, char **argv) {
    secargs a = {.width = 640, .height = 480, .axis = -1};
    if (parse(argc, argv, &a)) return BT_EXIT_BAD_INPUT;
    const int fmt = bt_image_format("section", a.out, 8, NULL);
    if (fmt < 0) return BT_EXIT_BAD_INPUT;
    char path[512] = "", *values[SECTION_MAX_VALUES] = {0};
    size_t nv = 0;
    int rc = 0;
    if (a.sweep && parse_sweep(a.sweep, path, sizeof path, values, &nv)) rc = BT_EXIT_BAD_INPUT;
    const size_t nruns = nv ? nv : 1;
    /* the plane's axes: u and v the two others, in x, y, z order */
    const int U = a.axis == 0 ? 1 : 0, V = a.axis == 2 ? 1 : 2;
    const int W = a.width, H = a.height, HT = H + LEGEND_H;
    float *px = rc ? NULL : malloc((size_t)W * (size_t)HT * 3 * sizeof *px);
    const size_t n = (size_t)W * (size_t)H;
    double *mem = rc ? NULL : malloc(7 * n * sizeof *mem);
    if (!rc && (!px || !mem)) rc = BT_EXIT_INTERNAL;
    plotgrid G = {NULL, NULL, NULL, NULL, {NULL, NULL, NULL}};
    if (!rc) {
        G.x = mem, G.y = G.x + n, G.z = G.y + n, G.f = G.z + n;
        G.g[0] = G.f + n, G.g[1] = G.g[0] + n, G.g[2] = G.g[1] + n;
        for (size_t i = 0; i < (size_t)W * (size_t)HT * 3; ++i) px[i] = 1.0f;
    }
    double u0 = 0, v0 = 0, step = 1;
    char hash_hex[33] = "", params[4096] = "";
    for (size_t run_i = 0; run_i < nruns && !rc; ++run_i) {
        bt_set sets[BT_MAX_SETS];
        memcpy(sets, a.sets, a.nsets * sizeof *sets);
        size_t ns = a.nsets;
        char text[1024];
        if (nv) {
            snprintf(text, sizeof text, "%s=%s", path, values[run_i]);
            if (bt_set_parse("section", text, &sets[ns++])) {
                rc = BT_EXIT_BAD_INPUT;
                break;
            }
        }
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        uint64_t hash[2];
        if ((rc = bt_load_scene_set("section", a.scene, sets, ns, &sc, hash))) break;
        if ((rc = bt_compile("section", a.scene, sc, &ev))) {
            lb_scene_free(sc);
            break;
        }
        if (run_i == 0) {
            bt_hash_hex(hash, hash_hex);
            double r[4];
            if (a.have_region) {
                memcpy(r, a.region, sizeof r);
            } else {
                double bmin[3], bmax[3];
                if (!lb_scene_bounds(sc, bmin, bmax)) {
                    bt_error("section",
                             "%s: the scene has no bounds; allowed: a scene with "
                             "\"bounds\", or --region U0,V0,U1,V1",
                             a.scene);
                    lb_evaluator_free(ev);
                    lb_scene_free(sc);
                    rc = BT_EXIT_BAD_INPUT;
                    break;
                }
                r[0] = bmin[U], r[1] = bmin[V], r[2] = bmax[U], r[3] = bmax[V];
            }
            /* square pixels: the region fits, centred */
            step = fmax((r[2] - r[0]) / W, (r[3] - r[1]) / H);
            u0 = 0.5 * (r[0] + r[2]) - 0.5 * W * step;
            v0 = 0.5 * (r[1] + r[3]) + 0.5 * H * step; /* the top row */
            for (int j = 0; j < H; ++j)
                for (int i = 0; i < W; ++i) {
                    double p[3];
                    p[a.axis] = a.at;
                    p[U] = u0 + (i + 0.5) * step;
                    p[V] = v0 - (j + 0.5) * step;
                    const size_t k = (size_t)j * W + i;
                    G.x[k] = p[0], G.y[k] = p[1], G.z[k] = p[2];
                }
        }
        lb_error e = {LB_OK, ""};
        const lb_status s =
            lb_evaluator_eval(ev, n, G.x, G.y, G.z, G.f, G.g[0], G.g[1], G.g[2], a.threads, &e);
        if (s) rc = bt_fail("section", a.scene, s, &e);
        const int soft = lb_scene_convention(sc) == LB_CONVENTION_SOFT;
        const double level = soft ? 0.5 : 0.0;
        lb_evaluator_free(ev);
        lb_scene_free(sc);
        if (rc) break;
        /* the first value's solid filled light grey, under every contour */
        if (run_i == 0)
            for (size_t k = 0; k < n; ++k)
                if (soft ? G.f[k] > level : G.f[k] < level)
                    for (int c = 0; c < 3; ++c) px[3 * k + c] = 0.86f;
        /* the contour, 2.5 pixels wide: the distance to it to first order,
         * |f - level| / |in-plane gradient|, in pixels */
        const float *col = PALETTE[run_i];
        for (size_t k = 0; k < n; ++k) {
            const double gu = G.g[U][k], gv = G.g[V][k], gl = sqrt(gu * gu + gv * gv);
            if (!(gl > 0.0) || !isfinite(G.f[k])) continue;
            const double d = fabs(G.f[k] - level) / (gl * step);
            const double cover = fmin(1.0, fmax(0.0, 1.75 - d));
            if (cover <= 0.0) continue;
            for (int c = 0; c < 3; ++c)
                px[3 * k + c] = (float)(px[3 * k + c] * (1.0 - cover) + col[c] * cover);
        }
        size_t l = strlen(params);
        if (nv) snprintf(params + l, sizeof params - l, "%s%s", l ? " " : "", text);
    }
    /* the legend: each value in its colour; the caption: the plane and the
     * region */
    lbi_text texts[SECTION_MAX_VALUES + 1];
    char legend[SECTION_MAX_VALUES][96], caption[256];
    size_t nt = 0;
    if (!rc) {
        const char *last = strrchr(path, '.');
        const char *name = a.label ? a.label : last ? last + 1 : path;
        int x = 8;
        for (size_t i = 0; i < nv; ++i) {
            snprintf(legend[i], sizeof legend[i], "%s = %.40s", name, values[i]);
            texts[nt] = (lbi_text){legend[i], x, H + 18, 15, {0, 0, 0}};
            memcpy(texts[nt].rgb, PALETTE[i], sizeof texts[nt].rgb);
            ++nt;
            x += 14 + (int)(strlen(legend[i]) * 8.5);
        }
        const char an[3] = {'x', 'y', 'z'};
        snprintf(caption, sizeof caption,
                 "section %c = %g; %c from %.4g to %.4g, %c from %.4g to %.4g; grey: inside%s",
                 an[a.axis], a.at, an[U], u0, u0 + W * step, an[V], v0 - H * step, v0,
                 nv ? " for the first value" : "");
        texts[nt++] = (lbi_text){caption, 8, H + 38, 12, {0.3f, 0.3f, 0.3f}};
    }
    const bt_imageio *io = rc ? NULL : bt_imageio_get("section");
    if (!rc && !io) rc = BT_EXIT_INTERNAL;
    unsigned char *img = NULL;
    size_t len = 0;
    if (!rc) {
        char settings[128], err[1024] = "";
        snprintf(settings, sizeof settings, "section %c=%.17g %dx%d", "xyz"[a.axis], a.at, W, H);
        const lbi_meta meta[4] = {{"libblend:scene_hash", hash_hex},
                                  {"libblend:version", BT_VERSION},
                                  {"libblend:render", settings},
                                  {"libblend:parameters", params}};
        if (io->write_pixels(px, W, HT, texts, nt, (lbi_format)fmt, meta, 4, &img, &len, err,
                             sizeof err)) {
            bt_error("section", "%s: writing the image failed: %s", a.out, err);
            rc = BT_EXIT_INTERNAL;
        }
    }
    if (!rc) {
        bt_out w;
        rc = bt_output_open("section", a.out, &w);
        if (!rc && fwrite(img, 1, len, w.f) != len) {
            bt_error("section", "%s: writing the image failed (%s); nothing was written", a.out,
                     strerror(errno));
            rc = BT_EXIT_INTERNAL;
        }
        if (!rc) rc = bt_output_commit("section", &w);
        bt_output_discard(&w);
    }
    free(img);
    for (size_t i = 0; i < nv; ++i) free(values[i]);
    free(px);
    free(mem);
    return rc;
}

const bt_command bt_cmd_section = {
    "section", "a plot of the surface's contour on a plane, for several parameter values",
    "usage: blendtool section SCENE -o OUT.png --plane x=C|y=C|z=C [--region U0,V0,U1,V1]\n"
    "                         [--width W] [--height H] [--sweep PATH=[V1,V2,...]]\n"
    "                         [--label NAME] [--set PATH=VALUE]... [--threads N]\n\n"
    "Evaluates the field with libblend at every pixel of a section through the\n"
    "scene (the plane x, y or z = C; U and V are the other two axes in x, y, z\n"
    "order) and draws the surface's contour (the zero set, or the 0.5 set of a\n"
    "soft scene) as a line 2.5 pixels wide, placed by the field's value and\n"
    "analytic gradient; the solid is filled grey. With --sweep, one contour per\n"
    "value of the scene value PATH (up to 8, each in its own colour, the grey\n"
    "fill the first value's), and a legend NAME = value (NAME: --label, else\n"
    "the path's last part). The image, written by OpenImageIO, has the scene's\n"
    "hash and the parameters as metadata and no time stamp; OUT appears only\n"
    "when everything succeeded.\n"
    "  --plane x=C       the section (required)\n"
    "  --region U0,V0,U1,V1  the part of the plane shown, centred with square\n"
    "                    pixels (default: the scene's bounds)\n"
    "  --width, --height the plot's size in pixels, 64..4096 (640 x 480); a\n"
    "                    legend strip of 44 pixels is added underneath\n"
    "  --sweep PATH=[V1,...]  the values to overlay (JSON list, 1 to 8 values)\n"
    "  --label NAME      the legend's name for PATH, such as m2\n"
    "  --set PATH=VALUE  override a scene value first (VALUE is JSON); repeatable\n"
    "  --threads N       evaluation threads (0 = one per CPU)\n"
    "Exit status: 0 success, 2 bad scene or options, 1 failure writing OUT or no\n"
    "OpenImageIO module, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP.\n",
    run};
