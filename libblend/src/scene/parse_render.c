/* The scene parser's render section: camera, lights, floor, background
 * and the materials (docs/scene-format.md, "render"). */
#define _POSIX_C_SOURCE 200809L
#include "parse_internal.h"
#include "../common/glibc_compat.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- materials ---- */

/* {"color", "ambient", "diffuse", "specular"} into *m; fields left out keep
 * what *m holds. */
lb_status lb__material_fields(pctx *c, const cJSON *mat, lb_material *m) {
    static const char *const mat_keys[] = {"color", "ambient", "diffuse", "specular", NULL};
    lb_status s;
    if (!cJSON_IsObject(mat))
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                        "expected an object, found %s; allowed: {\"color\": [r, g, b], "
                        "\"ambient\": a, \"diffuse\": d, \"specular\": s}",
                        lb__json_kind(mat));
    if ((s = lb__check_keys(c, mat, mat_keys, "material")) ||
        (s = lb__get_vec3(c, mat, "color", 0, 0.0, 1.0, "0 <= value <= 1", m->color)) ||
        (s = lb__get_number(c, mat, "ambient", 0, 0.0, 1.0, "0 <= ambient <= 1", &m->ambient)) ||
        (s = lb__get_number(c, mat, "diffuse", 0, 0.0, 1.0, "0 <= diffuse <= 1", &m->diffuse)))
        return s;
    return lb__get_number(c, mat, "specular", 0, 0.0, 1.0, "0 <= specular <= 1", &m->specular);
}

/* render.camera into R (has_camera set when it is valid) */
static lb_status parse_camera(pctx *c, const cJSON *r, lb_render *R) {
    static const char *const cam_keys[] = {"location", "look_at", "up", "angle", NULL};
    const double CM = LB_SCENE_MAX_COORD;
    lb_status s = LB_OK;
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(r, "camera");
    if (cam) {
        const size_t o = lb__push_key(c, "camera");
        if (!cJSON_IsObject(cam))
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected an object, found %s",
                         lb__json_kind(cam));
        else if (!(s = lb__check_keys(c, cam, cam_keys, "camera")) &&
                 !(s = lb__get_vec3(c, cam, "location", 1, -CM, CM, "|value| <= 1e9",
                                    R->location)) &&
                 !(s = lb__get_vec3(c, cam, "look_at", 0, -CM, CM, "|value| <= 1e9", R->look_at)) &&
                 !(s = lb__get_vec3(c, cam, "up", 0, -CM, CM, "|value| <= 1e9", R->up)) &&
                 !(s = lb__get_number(c, cam, "angle", 0, 1e-3, 179.0, "0 < angle < 180 (degrees)",
                                      &R->angle))) {
            const double d[3] = {R->look_at[0] - R->location[0], R->look_at[1] - R->location[1],
                                 R->look_at[2] - R->location[2]};
            const double *u = R->up;
            const double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]),
                         ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            const double cx[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2],
                                  d[0] * u[1] - d[1] * u[0]};
            const double sl = sqrt(cx[0] * cx[0] + cx[1] * cx[1] + cx[2] * cx[2]);
            if (!(dl > 0.0))
                s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                             "location equals look_at; allowed: a camera looking somewhere");
            else if (!(ul > 0.0) || !(sl > 1e-6 * dl * ul))
                s = lb__perr(
                    c, LB_ERR_INVALID_ARGUMENT,
                    "up [%g, %g, %g] is %s; allowed: a direction not along the line of sight "
                    "(default [0, 0, 1])",
                    u[0], u[1], u[2], ul > 0.0 ? "along the line of sight" : "zero");
            else
                for (int d2 = 0; d2 < 3; ++d2) R->up[d2] /= ul;
            R->has_camera = !s;
        }
        lb__pop(c, o);
    }
    return s;
}

/* render.lights into R */
static lb_status parse_lights(pctx *c, const cJSON *r, lb_render *R) {
    static const char *const light_keys[] = {"location", "color", NULL};
    const double CM = LB_SCENE_MAX_COORD;
    lb_status s = LB_OK;
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(r, "lights");
    if (lights) {
        const size_t o = lb__push_key(c, "lights");
        if (!cJSON_IsArray(lights) || cJSON_GetArraySize(lights) > LB_SCENE_MAX_LIGHTS) {
            s = lb__perr(
                c, LB_ERR_INVALID_ARGUMENT,
                "expected an array of at most %d lights, found %s; allowed: [{\"location\": "
                "[x, y, z], \"color\": [r, g, b]}, ...]",
                LB_SCENE_MAX_LIGHTS, lb__json_kind(lights));
        } else {
            size_t i = 0;
            for (const cJSON *l = lights->child; l && !s; l = l->next, ++i) {
                const size_t o2 = lb__push_index(c, i);
                lb_render_light *L = &R->lights[i];
                L->color[0] = L->color[1] = L->color[2] = 1.0;
                if (!cJSON_IsObject(l))
                    s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected an object, found %s",
                                 lb__json_kind(l));
                else if (!(s = lb__check_keys(c, l, light_keys, "a light")) &&
                         !(s = lb__get_vec3(c, l, "location", 1, -CM, CM, "|value| <= 1e9",
                                            L->location)))
                    s = lb__get_vec3(c, l, "color", 0, 0.0, 100.0, "0 <= value <= 100", L->color);
                lb__pop(c, o2);
            }
            if (!s) R->light_count = i;
        }
        lb__pop(c, o);
    }
    return s;
}

lb_status lb__parse_render(pctx *c, const cJSON *root) {
    lb_render *R = &c->s->render;
    R->angle = 40.0;
    R->color[0] = R->color[1] = R->color[2] = 0.8;
    R->ambient = 0.1;
    R->diffuse = 0.7;
    R->specular = 0.3;
    R->up[0] = R->up[1] = 0.0;
    R->up[2] = 1.0;
    R->floor = 1;
    R->floor_color[0] = R->floor_color[1] = R->floor_color[2] = 0.75;
    R->background[0] = R->background[1] = R->background[2] = 0.9;
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(root, "render");
    if (!r) return LB_OK;
    static const char *const keys[] = {"camera", "lights", "material", "floor", "background", NULL};
    static const char *const floor_keys[] = {"color", NULL};
    const size_t old = lb__push_key(c, "render");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(r)) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected an object, found %s; allowed: {\"camera\": ..., \"lights\": [...], "
                     "\"material\": ...}",
                     lb__json_kind(r));
        goto done;
    }
    if ((s = lb__check_keys(c, r, keys, "render"))) goto done;
    if ((s = parse_camera(c, r, R))) goto done;
    if ((s = parse_lights(c, r, R))) goto done;
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(r, "material");
    if (mat) {
        lb_material m = {
            {R->color[0], R->color[1], R->color[2]}, R->ambient, R->diffuse, R->specular};
        const size_t o = lb__push_key(c, "material");
        s = lb__material_fields(c, mat, &m);
        lb__pop(c, o);
        if (s) goto done;
        memcpy(R->color, m.color, sizeof m.color);
        R->ambient = m.ambient;
        R->diffuse = m.diffuse;
        R->specular = m.specular;
    }
    const cJSON *fl = cJSON_GetObjectItemCaseSensitive(r, "floor");
    if (fl) {
        const size_t o = lb__push_key(c, "floor");
        if (cJSON_IsBool(fl))
            R->floor = cJSON_IsTrue(fl);
        else if (!cJSON_IsObject(fl))
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "expected true, false or {\"color\": [r, g, b]}, found %s",
                         lb__json_kind(fl));
        else if (!(s = lb__check_keys(c, fl, floor_keys, "floor")))
            s = lb__get_vec3(c, fl, "color", 0, 0.0, 1.0, "0 <= value <= 1", R->floor_color);
        lb__pop(c, o);
        if (s) goto done;
    }
    s = lb__get_vec3(c, r, "background", 0, 0.0, 1.0, "0 <= value <= 1", R->background);
done:
    lb__pop(c, old);
    return s;
}
