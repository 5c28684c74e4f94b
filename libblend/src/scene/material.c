/* Materials: which node's material a surface point takes.
 *
 * The rule (docs/scene-format.md, "Materials"): walk down from the root; at
 * each operator whose arguments hold materials of their own, go into the
 * argument that decides the set operation at the point, and stop where the
 * subtree below holds none. The deciding argument is the one a sharp set
 * operation would take the value of: a union's most-inside argument, an
 * intersection's most-outside one, a difference's most-outside among the
 * first argument and the complements of the others. A blend keeps that
 * choice: its surface leaves each argument's where the others are far, and
 * in the blend region the boundary runs where the arguments are equally
 * inside. lb__material_score states it once for the POV-Ray writer too. */
#include "scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t lb_scene_material_count(const lb_scene *s) {
    return s ? 1 + s->nmats : 0;
}

int lb_scene_material(const lb_scene *s, size_t i, lb_material *out) {
    if (!s || !out || i > s->nmats) return 0;
    if (i == 0) {
        const lb_render *R = &s->render;
        memcpy(out->color, R->color, sizeof out->color);
        out->ambient = R->ambient;
        out->diffuse = R->diffuse;
        out->specular = R->specular;
    } else {
        *out = s->mats[i - 1];
    }
    return 1;
}

/* The deciding argument has the smallest score: the sign and offset that
 * turn argument i's value a into "how far inside the result it keeps" */
void lb__material_score(const lb__op *o, lb_convention conv, size_t i, double *sign,
                        double *offset) {
    *offset = 0.0;
    const int select = lb__family_info(o->family)->select;
    if (select) {
        *sign = select > 0 ? 1.0 : -1.0; /* the value taken: min +1, max -1 */
        return;
    }
    const int zero = conv == LB_CONVENTION_ZERO;
    const double inside = zero ? 1.0 : -1.0; /* most inside: smallest (zero), largest (soft) */
    const lb_setop op = lb__material_op(o);  /* union for rows without "op" */
    if (op == LB_UNION) {
        *sign = inside;
    } else if (op == LB_INTERSECTION || i == 0) {
        *sign = -inside;
    } else {
        /* the complement's most-outside: zero -(-a) = a, soft 1 - a */
        *sign = zero ? 1.0 : -1.0;
        *offset = zero ? 0.0 : 1.0;
    }
}
