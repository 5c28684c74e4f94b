/* A scene as a POV-Ray 3.7 file (pov.h): the node DAG as #declare'd
 * functions built with povray_include/libblend.inc, one isosurface, camera,
 * lights and material. */
#define _POSIX_C_SOURCE 200809L
#include "pov_internal.h"

#include <errno.h>
#include <stdarg.h>

void lb__pov_sb(sbuf *b, const char *fmt, ...) {
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int w = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (w < 0) {
            b->oom = 1;
            return;
        }
        if (b->s && b->n + (size_t)w < b->cap) {
            b->n += (size_t)w;
            return;
        }
        size_t nc = b->cap ? 2 * b->cap : 65536;
        while (nc < b->n + (size_t)w + 1) nc *= 2;
        char *q = realloc(b->s, nc);
        if (!q) {
            b->oom = 1;
            return;
        }
        b->s = q;
        b->cap = nc;
    }
}

/* user text in a comment: printable ASCII only */
void lb__pov_comment(sbuf *b, const char *label, const char *text) {
    if (!text || !*text) return;
    sb(b, "// %s: ", label);
    for (const char *c = text; *c && b->n < ((size_t)1 << 30); ++c)
        sb(b, "%c", *c >= 32 && *c < 127 ? *c : ' ');
    sb(b, "\n");
}

/* A #warning for each m that can change nothing (lb_scene_unused_m), so a
 * POV-Ray user who renders the file later sees it too; the path is printed
 * with only the characters a POV-Ray string takes as they are. */
static void unused_m_warnings(sbuf *b, const lb_scene *scene) {
    enum { SHOWN = 4 };
    const char *paths[SHOWN];
    const size_t n = lb_scene_unused_m(scene, paths, SHOWN);
    for (size_t i = 0; i < n && i < SHOWN; ++i) {
        sb(b, "#warning \"libblend: m at ");
        for (const char *c = paths[i]; *c && b->n < ((size_t)1 << 30); ++c)
            sb(b, "%c", *c >= 32 && *c < 127 && *c != '"' && *c != '\\' ? *c : '?');
        sb(b, " has no effect (no blend above uses its values); it only steepens the field. "
              "Fix: m = 1\"\n");
    }
    if (n > SHOWN) sb(b, "#warning \"libblend: and %zu more nodes like it\"\n", n - SHOWN);
}

void lb__pov_array(sbuf *b, size_t k, const double *v, double fallback) {
    sb(b, "array[%zu] {", k);
    for (size_t i = 0; i < k; ++i) sb(b, "%s%.17g", i ? ", " : "", v ? v[i] : fallback);
    sb(b, "}");
}

void lb_pov_camera(const lb_scene *scene, double aspect, double loc[3], double at[3], double up[3],
                   double *angle) {
    (void)aspect;
    if (!scene || !loc || !at || !up || !angle) return; /* nothing to write to, or from */
    const lb_render *R = &scene->render;
    *angle = R->has_camera ? R->angle : 40.0;
    memcpy(up, R->up, 3 * sizeof *up);
    if (R->has_camera) {
        memcpy(loc, R->location, 3 * sizeof *loc);
        memcpy(at, R->look_at, 3 * sizeof *at);
        return;
    }
    /* frame the bounding sphere from the front (-y), a little above (+z)
     * and to the right (+x) */
    double diag = 0.0, ctr[3];
    for (int d = 0; d < 3; ++d) {
        diag += (scene->bmax[d] - scene->bmin[d]) * (scene->bmax[d] - scene->bmin[d]);
        ctr[d] = 0.5 * (scene->bmin[d] + scene->bmax[d]);
    }
    diag = sqrt(diag);
    const double dir[3] = {0.45, -1.0, 0.5}, dl = sqrt(0.45 * 0.45 + 1.0 + 0.25);
    const double dist = 0.5 * diag / sin(0.5 * *angle * M_PI / 180.0) * 1.05;
    for (int d = 0; d < 3; ++d) {
        at[d] = ctr[d];
        loc[d] = ctr[d] + dir[d] / dl * dist;
    }
}

/* Every number in b (outside // comments) in its shortest form that reads
 * back as the same double: the writer prints 17 significant digits, which
 * always round-trip, and this keeps the fewest that still do (0.3, not
 * 0.29999999999999999). Identifiers' digits (LBn12) are left alone. */
static void shorten_numbers(sbuf *b) {
    if (!b->s) return;
    size_t r = 0, w = 0;
    while (r < b->n) {
        const char ch = b->s[r];
        if (ch == '/' && r + 1 < b->n && b->s[r + 1] == '/') { /* a comment: copied as is */
            /* a mesh's data: its numbers are already single-precision
             * short (and millions), copied as is to the end marker */
            const size_t lb = sizeof LB_POV_VERBATIM_BEGIN - 1;
            if (b->n - r >= lb && memcmp(b->s + r, LB_POV_VERBATIM_BEGIN, lb) == 0) {
                const char *end = strstr(b->s + r, LB_POV_VERBATIM_END);
                const size_t stop = end ? (size_t)(end - b->s) : b->n;
                memmove(b->s + w, b->s + r, stop - r);
                w += stop - r;
                r = stop;
            }
            while (r < b->n && b->s[r] != '\n') b->s[w++] = b->s[r++];
            continue;
        }
        const char prev = w ? b->s[w - 1] : ' ';
        const int starts = (ch >= '0' && ch <= '9') ||
                           (ch == '.' && r + 1 < b->n && b->s[r + 1] >= '0' && b->s[r + 1] <= '9');
        const int word = (prev >= 'a' && prev <= 'z') || (prev >= 'A' && prev <= 'Z') ||
                         (prev >= '0' && prev <= '9') || prev == '_' || prev == '.';
        if (!starts || word) {
            b->s[w++] = b->s[r++];
            continue;
        }
        size_t e = r;
        while (e < b->n && b->s[e] >= '0' && b->s[e] <= '9') ++e;
        if (e < b->n && b->s[e] == '.') {
            ++e;
            while (e < b->n && b->s[e] >= '0' && b->s[e] <= '9') ++e;
        }
        if (e + 1 < b->n && (b->s[e] == 'e' || b->s[e] == 'E')) {
            size_t f = e + 1;
            if (f < b->n && (b->s[f] == '+' || b->s[f] == '-')) ++f;
            if (f < b->n && b->s[f] >= '0' && b->s[f] <= '9') {
                while (f < b->n && b->s[f] >= '0' && b->s[f] <= '9') ++f;
                e = f;
            }
        }
        char tok[64], best[64];
        const size_t len = e - r;
        if (len >= sizeof tok) { /* not a number the writer made: copied as is */
            while (r < e) b->s[w++] = b->s[r++];
            continue;
        }
        memcpy(tok, b->s + r, len);
        tok[len] = 0;
        const double v = strtod(tok, NULL);
        size_t blen = len;
        memcpy(best, tok, len + 1);
        for (int p = 1; p <= 17; ++p) {
            char t[64];
            const int n = snprintf(t, sizeof t, "%.*g", p, v);
            if (n > 0 && (size_t)n < blen && strtod(t, NULL) == v) {
                memcpy(best, t, (size_t)n + 1);
                blen = (size_t)n;
                break;
            }
        }
        memcpy(b->s + w, best, blen); /* never longer than what it replaces */
        w += blen;
        r = e;
    }
    b->n = w;
    b->s[w] = 0;
}

/* The floor's height along up: the lowest point of a coarse mesh of the
 * surface (48 cells), or of the bounds when there is no surface. */
/* the largest |grad f| on a grid over the box */
static lb_status max_gradient(const lb_evaluator *ev, const double lo[3], const double hi[3],
                              int threads, double *g, lb_error *err) {
    const size_t N = LB_POV_GRADIENT_SAMPLES, n = N * N * N;
    double *mem = malloc(7 * n * sizeof *mem);
    if (!mem) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    double *x = mem, *y = x + n, *z = y + n, *v = z + n, *gx = v + n, *gy = gx + n, *gz = gy + n;
    for (size_t i = 0; i < n; ++i) {
        const size_t a = i % N, bq = i / N % N, cq = i / N / N;
        x[i] = lo[0] + (hi[0] - lo[0]) * (double)a / (double)(N - 1);
        y[i] = lo[1] + (hi[1] - lo[1]) * (double)bq / (double)(N - 1);
        z[i] = lo[2] + (hi[2] - lo[2]) * (double)cq / (double)(N - 1);
    }
    lb_status s = lb_evaluator_eval(ev, n, x, y, z, v, gx, gy, gz, threads, err);
    /* Only where the surface may be matters: POV-Ray's root search splits an
     * interval of a ray only while the function could reach the threshold
     * in it, so a steep field far from the surface never misleads it. A
     * sample counts when, to first order, the surface lies within two grid
     * diagonals of it: |f - threshold| <= 2 d |grad f|. */
    double d2 = 0.0;
    for (int d = 0; d < 3; ++d)
        d2 += (hi[d] - lo[d]) * (hi[d] - lo[d]) / ((double)(N - 1) * (double)(N - 1));
    const double band = 2.0 * sqrt(d2), level = ev->conv == LB_CONVENTION_SOFT ? 0.5 : 0.0;
    double m = 0.0, mall = 0.0;
    for (size_t i = 0; i < n && !s; ++i) {
        const double l = sqrt(gx[i] * gx[i] + gy[i] * gy[i] + gz[i] * gz[i]);
        if (l > mall) mall = l;
        if (l > m && fabs(v[i] - level) <= band * l) m = l;
    }
    free(mem);
    if (!(m > 0.0)) m = mall; /* no surface seen: the whole box's */
    *g = m * LB_POV_GRADIENT_SAFETY;
    if (!(*g > 0.0)) *g = 1.0;
    return s;
}

/* The camera, lights, floor, textures and the isosurface of a whole scene
 * after the field's declarations (c->b holds them); g is max_gradient. */
static lb_status whole_scene(pctx *c, const lb_pov_options *opt, double g, double diag) {
    const lb_pov_options o = *opt;
    const lb_scene *scene = c->sc;
    const lb_evaluator *ev = c->ev;
    const double *lo = scene->bmin, *hi = scene->bmax;
    sbuf *b = c->b;
    const lb_render *R = &scene->render;
    const double aspect = o.aspect > 0.0 ? o.aspect : 4.0 / 3.0;
    double loc[3], at[3], up[3], angle;
    lb_pov_camera(scene, aspect, loc, at, up, &angle);
    /* the camera's distance to its target (the key light's size) */
    const double F[3] = {at[0] - loc[0], at[1] - loc[1], at[2] - loc[2]};
    const double L = sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2]);
    const double *bg = R->background;
    /* POV-Ray is left-handed: a negated right vector makes the image the
     * right-handed view; sky is the scene's up (the look_at keeps both) */
    sb(b,
       "\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb <%.17g, %.17g, %.17g> }\n"
       "camera { perspective location <%.17g, %.17g, %.17g> sky <%.17g, %.17g, %.17g> up y "
       "right -x * %.17g angle %.17g look_at <%.17g, %.17g, %.17g> }\n",
       o.silhouette ? 0.0 : bg[0], o.silhouette ? 0.0 : bg[1], o.silhouette ? 0.0 : bg[2], loc[0],
       loc[1], loc[2], up[0], up[1], up[2], aspect, angle, at[0], at[1], at[2]);
    if (o.silhouette) {
        /* no lights: the object is its ambient white */
    } else if (R->light_count) {
        for (size_t i = 0; i < R->light_count; ++i)
            sb(b, "light_source { <%.17g, %.17g, %.17g> rgb <%.17g, %.17g, %.17g> }\n",
               R->lights[i].location[0], R->lights[i].location[1], R->lights[i].location[2],
               R->lights[i].color[0], R->lights[i].color[1], R->lights[i].color[2]);
    } else {
        /* three-point lighting around the camera: a key light above and
         * to the left with soft shadows, a dim fill from the right and a
         * rim light from behind, both without shadows. The key's area
         * light is 3 x 3, not adaptive: every shadow sample is an
         * isosurface intersection, and a soft-object scene took 7x a
         * hard shadow's time at 5 x 5 adaptive (4x at 3 x 3). A mesh's
         * shadow rays are cheap, so there it is 9 x 9 without jitter:
         * shadows in 81 steps, without grain. */
        lb_render_light key[3];
        lb_render_three_point(loc, at, up, key);
        for (int k = 0; k < 3; ++k) {
            const double *X = key[k].location;
            if (k == 0)
                sb(b,
                   "light_source { <%.17g, %.17g, %.17g> rgb %.17g area_light <%.17g, 0, 0>, "
                   "<0, %.17g, 0>, %s circular orient }\n",
                   X[0], X[1], X[2], key[k].color[0], 0.2 * L, 0.2 * L,
                   o.mesh_resolution ? "9, 9 adaptive 1" : "3, 3 adaptive 0 jitter");
            else
                sb(b, "light_source { <%.17g, %.17g, %.17g> rgb %.17g shadowless }\n", X[0], X[1],
                   X[2], key[k].color[0]);
        }
    }
    if (R->floor && !o.silhouette) {
        double h = 0.0;
        lb_render_floor_height(ev, scene->bmin, scene->bmax, up, o.threads, &h, NULL);
        sb(b,
           "plane { <%.17g, %.17g, %.17g>, %.17g pigment { rgb <%.17g, %.17g, %.17g> } "
           "finish { ambient 0.15 diffuse 0.75 } }\n",
           up[0], up[1], up[2], h, R->floor_color[0], R->floor_color[1], R->floor_color[2]);
    }
    const int soft = scene->convention == LB_CONVENTION_SOFT;
    char texname[24] = "";
    if (!o.silhouette && lb_scene_material_count(scene) > 1) {
        sb(b, "\n");
        for (size_t i = 0; i < lb_scene_material_count(scene); ++i) {
            lb_material m;
            lb_scene_material(scene, i, &m);
            sb(b, "#declare LBmat%zu = ", i);
            lb__pov_material_texture(b, &m);
            sb(b, "\n");
        }
        lb__affine id;
        lb__affine_identity(&id);
        const lb_status s = lb__pov_texture(c, scene->root, &id, 0, texname);
        if (s) return s;
    }
    if (o.mesh_resolution) {
        int empty = 0;
        const lb_status s = lb__pov_mesh(b, ev, lo, hi, &o, &empty, c->err);
        if (s) return s;
        if (empty) {
            sb(b, "// no surface in the bounds at mesh_resolution %d\n", o.mesh_resolution);
            return LB_OK;
        }
    } else {
        sb(b,
           "isosurface {\n  function { %sLB_Field(x, y, z) }\n  threshold %s\n"
           "  contained_by { box { <%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g> } }\n"
           "  max_gradient %.17g\n  accuracy %.17g\n  ",
           soft ? "-" : "", soft ? "-0.5" : "0", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], g,
           1e-4 * diag);
    }
    if (texname[0]) {
        sb(b, "texture { %s }", texname);
    } else {
        /* one material (the silhouette: its ambient white) */
        const lb_material white = {{1.0, 1.0, 1.0}, 1.0, 0.0, 0.0};
        lb_material m0;
        lb_scene_material(scene, 0, &m0);
        lb__pov_material_texture(b, o.silhouette ? &white : &m0);
    }
    sb(b, "\n}\n");
    return LB_OK;
}

/* What a hand-written scene needs beside LB_Field (include_only): the
 * surface as a function negative inside, the box, a max_gradient and an
 * accuracy, under fixed names (povray_include/README.md, "Your own scene
 * around a libblend field"). */
static void include_tail(sbuf *b, const lb_scene *scene, double g, double diag) {
    const int soft = scene->convention == LB_CONVENTION_SOFT;
    const double *lo = scene->bmin, *hi = scene->bmax;
    sb(b,
       "\n// For your own scene: LB_Surface is < 0 inside, 0 on the surface; use it as\n"
       "// isosurface { function { LB_Surface(x, y, z) } threshold 0\n"
       "//   contained_by { box { LB_FieldMin, LB_FieldMax } } max_gradient LB_FieldMaxGradient\n"
       "//   accuracy LB_FieldAccuracy texture { ... } }\n");
    if (soft)
        sb(b, "#declare LB_Surface = function(x, y, z) { 0.5 - LB_Field(x, y, z) }\n");
    else
        sb(b, "#declare LB_Surface = LB_Field;\n");
    sb(b,
       "#declare LB_FieldMin = <%.17g, %.17g, %.17g>;\n#declare LB_FieldMax = <%.17g, %.17g, "
       "%.17g>;\n#declare LB_FieldMaxGradient = %.17g;\n#declare LB_FieldAccuracy = %.17g;\n",
       lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], g, 1e-4 * diag);
}

/* The whole .pov text into b (freed by the caller). */
static lb_status pov_text(const lb_scene *scene, const lb_evaluator *ev, const lb_pov_options *opt,
                          sbuf *out, double *out_gradient, lb_error *err) {
    lb_pov_options o = {0, 0, 0.0, 0.0, 0, 0, 0, 0.0, 0};
    if (opt) o = *opt;
    if (!scene->has_bounds)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the scene has no bounds; allowed: a scene with \"bounds\" (the "
                        "isosurface's contained_by box)",
                        FN);
    const double *lo = scene->bmin, *hi = scene->bmax;
    double diag = 0.0;
    for (int d = 0; d < 3; ++d) diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    diag = sqrt(diag);
    sbuf b = {NULL, 0, 0, 0};
    pctx c = {&b,   scene, NULL, NULL, 0, 0,   0, 1e-5 * diag, ev, {{0}, {0}},
              NULL, NULL,  NULL, 0,    0, err, 0};
    lb__affine_identity(&c.A);
    sb(&b, "// written by libblend %d.%d.%d (blendtool pov)\n", LB_VERSION_MAJOR, LB_VERSION_MINOR,
       LB_VERSION_PATCH);
    lb__pov_comment(&b, "scene", scene->name);
    sb(&b, "#version 3.7;\n#include \"libblend.inc\"\n");
    unused_m_warnings(&b, scene);
    sb(&b, "\n");
    int root = 0;
    lb_status s = lb__pov_emit(&c, scene->root, &root);
    double g = o.max_gradient;
    if (!s) {
        sb(&b, "#declare LB_Field = LBn%d;\n", root);
        if (!(g > 0.0)) s = max_gradient(ev, lo, hi, o.threads, &g, err);
    }
    if (!s && o.include_only)
        include_tail(&b, scene, g, diag);
    else if (!s)
        s = whole_scene(&c, &o, g, diag);
    free(c.done);
    free(c.ids);
    free(c.doneA);
    free(c.lnodes);
    free(c.lflag);
    if (!s && b.oom) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    if (s) {
        free(b.s);
        return s;
    }
    shorten_numbers(&b);
    *out = b;
    if (out_gradient) *out_gradient = g;
    return LB_OK;
}

lb_status lb_scene_write_pov_stream(const lb_scene *scene, const lb_evaluator *ev,
                                    const lb_pov_options *opt, FILE *stream, double *out_gradient,
                                    lb_error *err) {
    if (!scene || !ev || !stream)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_scene_write_pov_stream: scene, ev and stream must be given");
    sbuf b = {NULL, 0, 0, 0};
    double g = 0.0;
    lb_status s = pov_text(scene, ev, opt, &b, &g, err);
    if (s) return s;
    if (fwrite(b.s, 1, b.n, stream) != b.n || fflush(stream) != 0)
        s = lb__fail(err, LB_ERR_IO, "lb_scene_write_pov_stream: writing failed (%s)",
                     strerror(errno));
    free(b.s);
    if (!s && out_gradient) *out_gradient = g;
    return s;
}

lb_status lb_scene_write_pov(const lb_scene *scene, const lb_evaluator *ev,
                             const lb_pov_options *opt, const char *path, double *out_gradient,
                             lb_error *err) {
    if (!scene || !ev || !path || !*path)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: scene, ev and path must be given", FN);
    sbuf b = {NULL, 0, 0, 0};
    double g = 0.0;
    lb_status s = pov_text(scene, ev, opt, &b, &g, err);
    if (!s) s = lb_output_write_file(path, b.s, b.n, err);
    free(b.s);
    if (!s && out_gradient) *out_gradient = g;
    return s;
}
