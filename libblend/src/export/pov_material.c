/* The POV-Ray writer's materials: the material rule (scene/material.c) as
 * textures. */
#include "pov_internal.h"

/* The material rule as textures.
 *
 * A texture per operator where the material is decided: a function
 * pattern that is 0.75 where the first group of arguments (those with the
 * same texture) has the smallest score and 0.25 elsewhere, mapping to that
 * group's texture or to the rest's. The arguments' functions are the ones
 * the field is written with, called in the operator's frame. */

static void score_expr(pctx *c, const lb__node *n, size_t i, int fid, const lb__affine *A) {
    double sign, off;
    lb__material_score(&n->o, c->sc->convention, i, &sign, &off);
    sb(c->b, "%s%sLBn%d(", off != 0.0 ? "1" : "", sign < 0 ? "-" : off != 0.0 ? "+" : "", fid);
    if (lb__affine_is_identity(A))
        sb(c->b, "x, y, z");
    else
        affine_args(c->b, A);
    sb(c->b, ")");
}

/* the scores of the arguments in group g (their texture is names[g]) */
static void group_expr(pctx *c, const lb__node *n, const int *group, int g, const int *fid,
                       const lb__affine *A) {
    int count = 0;
    for (size_t i = 0; i < n->o.k; ++i) count += group[i] == g;
    if (count > 1) sb(c->b, "min(");
    for (size_t i = 0, w = 0; i < n->o.k; ++i)
        if (group[i] == g) {
            if (w++) sb(c->b, ", ");
            score_expr(c, n, i, fid[i], A);
        }
    if (count > 1) sb(c->b, ")");
}

/* name (at least 24 bytes) receives the texture of n's surface: Ap maps
 * world coordinates to n's parent frame, inh is the inherited material */
lb_status lb__pov_texture(pctx *c, const lb__node *n, const lb__affine *Ap, size_t inh,
                          char *name) {
    const size_t eff = n->mat ? n->mat : inh;
    if (!n->mat_below) {
        snprintf(name, 24, "LBmat%zu", eff);
        return LB_OK;
    }
    lb__affine A = *Ap;
    if (n->has_transform) lb__affine_compose(n->to_local, Ap, &A);
    if (n->o.k == 1) return lb__pov_texture(c, n->args[0], &A, eff, name);
    const size_t k = n->o.k;
    char(*sub)[24] = malloc(k * sizeof *sub);
    int *fid = malloc(2 * k * sizeof *fid), *group = fid ? fid + k : NULL;
    lb_status s = sub && fid ? LB_OK : lb__fail(c->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    int G = 0;
    for (size_t i = 0; i < k && !s; ++i) {
        if ((s = lb__pov_texture(c, n->args[i], &A, eff, sub[i]))) break;
        lb__affine F = A;
        if (n->args[i]->has_transform) lb__affine_compose(n->args[i]->to_local, &A, &F);
        fid[i] = lb__pov_written_id(c, n->args[i], &F);
        if (fid[i] < 0) {
            s = lb__fail(c->err, LB_ERR_INTERNAL, "%s: %s: argument %zu was not written", FN,
                         n->o.path, i);
            break;
        }
        group[i] = -1;
        for (size_t j = 0; j < i && group[i] < 0; ++j)
            if (strcmp(sub[j], sub[i]) == 0) group[i] = group[j];
        if (group[i] < 0) group[i] = G++;
    }
    if (!s && G == 1) memcpy(name, sub[0], 24);
    /* the chain: group g against the groups after it, from the last pair up */
    char rest[24] = "";
    for (int g = G - 2; g >= 0 && !s; --g) {
        if (++c->ntex > LB_POV_MAX_TEXTURES) {
            s = lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                         "%s: %s: more than %d material textures (a def with materials used "
                         "under many parents); allowed: at most %d",
                         FN, n->o.path, LB_POV_MAX_TEXTURES, LB_POV_MAX_TEXTURES);
            break;
        }
        if (g == G - 2)
            for (size_t i = 0; i < k; ++i)
                if (group[i] == G - 1) memcpy(rest, sub[i], 24);
        const char *mine = NULL;
        for (size_t i = 0; i < k && !mine; ++i)
            if (group[i] == g) mine = sub[i];
        const int t = c->ntex;
        sb(c->b, "#declare LBq%d = function(x, y, z) { select(", t);
        group_expr(c, n, group, g, fid, &A);
        sb(c->b, " - %s", G - g > 2 ? "min(" : "");
        for (int h = g + 1; h < G; ++h) {
            if (h > g + 1) sb(c->b, ", ");
            group_expr(c, n, group, h, fid, &A);
        }
        sb(c->b, "%s, 0.75, 0.25) }\n", G - g > 2 ? ")" : "");
        sb(c->b,
           "#declare LBt%d = texture { function { LBq%d(x, y, z) } texture_map { [0.5 %s] [0.5 "
           "%s] } }\n",
           t, t, rest, mine);
        snprintf(rest, sizeof rest, "LBt%d", t);
    }
    if (!s && G > 1) memcpy(name, rest, 24);
    free(sub);
    free(fid);
    return s;
}

void lb__pov_material_texture(sbuf *b, const lb_material *m) {
    sb(b,
       "texture { pigment { rgb <%.17g, %.17g, %.17g> } finish { ambient %.17g diffuse %.17g "
       "specular %.17g } }",
       m->color[0], m->color[1], m->color[2], m->ambient, m->diffuse, m->specular);
}
