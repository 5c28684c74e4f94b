/* The scene parser's nodes: the type table, primitives, operator nodes
 * and their parameters, refs and defs, local and bulge settings, node
 * materials. docs/scene-format.md is the reference for every name. */
#define _POSIX_C_SOURCE 200809L
#include "parse_internal.h"
#include "../common/glibc_compat.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- node allocation ---- */

static lb__node *new_node(pctx *c, lb__family fam, const char *type) {
    lb_scene *s = c->s;
    if (s->nnodes == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 64;
        lb__node **nn = realloc(s->nodes, cap * sizeof *nn);
        if (!nn) return NULL;
        s->nodes = nn;
        s->cap = cap;
    }
    lb__node *n = calloc(1, sizeof *n);
    if (!n) return NULL;
    n->walk_cost = 1.0;
    n->o.path = malloc(c->jp.len + 1);
    if (!n->o.path) {
        free(n);
        return NULL;
    }
    memcpy(n->o.path, c->jp.s, c->jp.len + 1);
    n->o.family = fam;
    n->type = type;
    n->depth = 1;
    s->nodes[s->nnodes++] = n;
    return n;
}

/* A per-argument parameter: a number (for every argument) or an array of k
 * numbers. Writes k values into a new array (or NULL when absent and not
 * required, in which case def is used for every argument when def_ok). */
static lb_status get_param(pctx *c, const cJSON *obj, const char *key, size_t k, int required,
                           int def_ok, double def, double lo, double hi, const char *allowed,
                           double **out) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = NULL;
    if (!j && !required && !def_ok) return LB_OK;
    const size_t old = lb__push_key(c, key);
    lb_status s = LB_OK;
    double *v = malloc(k * sizeof *v);
    if (!v) {
        s = lb__oom(c);
    } else if (!j) {
        if (required)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "missing required field; allowed: a number (for every argument) or an "
                         "array of %zu numbers (one per argument), each %s",
                         k, allowed);
        for (size_t i = 0; i < k; ++i) v[i] = def;
    } else if (cJSON_IsNumber(j)) {
        double x = 0.0;
        s = lb__number_value(c, j, lo, hi, allowed, &x);
        for (size_t i = 0; i < k; ++i) v[i] = x;
    } else if (cJSON_IsArray(j)) {
        const size_t n = (size_t)cJSON_GetArraySize(j);
        if (n != k) {
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "has %zu values for %zu arguments; allowed: a number or an array of "
                         "exactly %zu numbers (one per argument)",
                         n, k, k);
        } else {
            size_t i = 0;
            for (const cJSON *e = j->child; e && !s; e = e->next, ++i) {
                const size_t o2 = lb__push_index(c, i);
                s = lb__number_value(c, e, lo, hi, allowed, &v[i]);
                lb__pop(c, o2);
            }
        }
    } else {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected a number or an array of %zu numbers, found %s; allowed: each %s", k,
                     lb__json_kind(j), allowed);
    }
    lb__pop(c, old);
    if (s) {
        free(v);
        return s;
    }
    *out = v;
    return LB_OK;
}

/* ---- transforms ---- */

static lb_status get_transform(pctx *c, const cJSON *obj, lb__node *n) {
    double t[3] = {0, 0, 0}, rdeg[3] = {0, 0, 0}, sc[3] = {1, 1, 1};
    lb_status s;
    if ((s = lb__get_vec3(c, obj, "translate", 0, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                          "|value| <= 1e9", t)) ||
        (s = lb__get_vec3(c, obj, "rotate", 0, -36000.0, 36000.0,
                          "degrees about x, then y, then z, |value| <= 36000", rdeg)))
        return s;
    const cJSON *js = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (cJSON_IsNumber(js)) {
        double u = 1.0;
        if ((s = lb__get_number(c, obj, "scale", 0, 1e-6, 1e6, "1e-6 <= scale <= 1e6 (uniform)",
                                &u)))
            return s;
        sc[0] = sc[1] = sc[2] = u;
    } else if ((s = lb__get_vec3(c, obj, "scale", 0, 1e-6, 1e6, "1e-6 <= value <= 1e6", sc))) {
        return s;
    }
    n->has_transform = cJSON_GetObjectItemCaseSensitive(obj, "translate") ||
                       cJSON_GetObjectItemCaseSensitive(obj, "rotate") || js;
    if (!n->has_transform) return LB_OK;
    /* to_parent = T Rz Ry Rx S */
    lb__affine a, b;
    lb__affine_identity(&a);
    for (int i = 0; i < 3; ++i) a.M[4 * i] = sc[i];
    for (int axis = 0; axis < 3; ++axis) {
        const double th = rdeg[axis] * 3.14159265358979323846 / 180.0;
        const double cs = cos(th), sn = sin(th);
        const int i = (axis + 1) % 3, j = (axis + 2) % 3;
        lb__affine_identity(&b);
        b.M[3 * i + i] = cs;
        b.M[3 * i + j] = -sn;
        b.M[3 * j + i] = sn;
        b.M[3 * j + j] = cs;
        lb__affine_compose(&b, &a, &a);
    }
    memcpy(a.t, t, sizeof t);
    /* inverse: S^-1 R^T (x - t) */
    lb__affine inv;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            /* (R S)^-1 = S^-1 R^T; R = a.M S^-1 column-wise */
            inv.M[3 * i + j] = a.M[3 * j + i] / (sc[i] * sc[i]);
        }
    for (int i = 0; i < 3; ++i)
        inv.t[i] = -(inv.M[3 * i] * t[0] + inv.M[3 * i + 1] * t[1] + inv.M[3 * i + 2] * t[2]);
    n->to_local = malloc(sizeof *n->to_local);
    if (!n->to_local) return lb__oom(c);
    *n->to_local = inv;
    return LB_OK;
}

/* ---- the registry's lists, in words (only for messages) ---- */

/* keys every node takes: its transform and its material */
#define TRANSFORM_KEYS LB__TRANSFORM_KEYS

/* every type a scene names, in the registry's order */
static void type_list(char *buf, size_t size) {
    size_t np = 0, len = 0;
    const lb__primitive_row *P = lb__primitive_rows(&np);
    buf[0] = '\0';
    for (size_t i = 0; i < np && len < size; ++i)
        len += (size_t)snprintf(buf + len, size - len, "%s, ", P[i].name);
    for (int f = 1; f < LB__F_COUNT && len < size; ++f) {
        const lb__family_row *row = lb__family_info((lb__family)f);
        if (!(row->flags & LB__R_NO_PARSE))
            len += (size_t)snprintf(buf + len, size - len, "%s, ", row->name);
    }
    if (len >= 2 && len < size) snprintf(buf + len - 2, size - len + 2, " (or {\"ref\": NAME})");
}

/* the operators of one convention (bit), or those that take up to
 * LB_MAX_ARITY_WIDE arguments (bit 0) */
static int listed(const lb__family_row *row, int bit) {
    return !(row->flags & LB__R_NO_PARSE) &&
           (bit ? (row->conv & bit) != 0 : row->kmax == LB_MAX_ARITY_WIDE);
}
static void row_list(int bit, char *buf, size_t size) {
    size_t len = 0, n = 0, count = 0;
    for (int f = 1; f < LB__F_COUNT; ++f) count += listed(lb__family_info((lb__family)f), bit);
    buf[0] = '\0';
    for (int f = 1; f < LB__F_COUNT && len < size; ++f) {
        const lb__family_row *row = lb__family_info((lb__family)f);
        if (!listed(row, bit)) continue;
        ++n;
        const char *sep = n == 1 ? "" : !bit && n == count ? " and " : ", ";
        len += (size_t)snprintf(buf + len, size - len, "%s%s", sep, row->name);
    }
}

/* the row's keys (and more, may be NULL) and every node's, NULL-terminated,
 * into keys (32) */
static void node_keys(const char *const *own, const char *const *more, const char **keys) {
    static const char *const common[] = {TRANSFORM_KEYS, NULL};
    size_t n = 0;
    for (const char *const *k = own; *k && n < 20; ++k) keys[n++] = *k;
    for (const char *const *k = more; k && *k && n < 24; ++k) keys[n++] = *k;
    for (const char *const *k = common; *k; ++k) keys[n++] = *k;
    keys[n] = NULL;
}

/* ---- primitives ---- */

static lb_status parse_primitive(pctx *c, const cJSON *j, const lb__primitive_row *t, lb__node *n) {
    double ctr[3] = {0, 0, 0}, a[3] = {1, 1, 1}, nv[3] = {0, 0, 1}, q[3] = {0, 0, 0};
    double s0 = 1.0, s1 = 1.0;
    const double CMAX = LB_SCENE_MAX_COORD;
    const char *len_ok = "1e-9 <= value <= 1e9 (a length)";
    lb_status s = LB_OK;
    lb_error perr_local = {LB_OK, ""};
    switch (t->kind) {
    case LB_PRIM_ELLIPSOID:
        if ((s = lb__get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr))) return s;
        if (strcmp(t->name, "sphere") == 0) {
            if ((s = lb__get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0))) return s;
            s = lb_primitive_sphere(&n->prim, ctr, s0, &perr_local);
        } else {
            if ((s = lb__get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a))) return s;
            s = lb_primitive_ellipsoid(&n->prim, ctr, a, &perr_local);
        }
        break;
    case LB_PRIM_LP:
        if ((s = lb__get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a)) ||
            (s = lb__get_number(c, j, "exponent", 1, 1.0, 1000.0, "1 <= exponent <= 1000", &s0)))
            return s;
        s = lb_primitive_lp(&n->prim, ctr, a, s0, &perr_local);
        break;
    case LB_PRIM_SUPERQUADRIC:
        if ((s = lb__get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a)) ||
            (s = lb__get_number(c, j, "e1", 1, 0.01, 10.0, "0.01 <= e1 <= 10 (1 = round)", &s0)) ||
            (s = lb__get_number(c, j, "e2", 1, 0.01, 10.0, "0.01 <= e2 <= 10 (1 = round)", &s1)))
            return s;
        s = lb_primitive_superquadric(&n->prim, ctr, a, s0, s1, &perr_local);
        break;
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE: {
        const int slab = t->kind == LB_PRIM_SLAB;
        if ((s = lb__get_vec3(c, j, "point", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "normal", 1, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = lb__get_number(c, j, slab ? "half_width" : "width", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = slab ? lb_primitive_slab(&n->prim, ctr, nv, s0, &perr_local)
                 : lb_primitive_halfspace(&n->prim, ctr, nv, s0, &perr_local);
        break;
    }
    case LB_PRIM_CYLINDER:
        if ((s = lb__get_vec3(c, j, "point", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "axis", 1, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = lb__get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = lb_primitive_cylinder(&n->prim, ctr, nv, s0, &perr_local);
        break;
    case LB_PRIM_CAPSULE:
        if ((s = lb__get_vec3(c, j, "start", 1, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "end", 1, -CMAX, CMAX, "|value| <= 1e9", q)) ||
            (s = lb__get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = lb_primitive_capsule(&n->prim, ctr, q, s0, &perr_local);
        break;
    case LB_PRIM_TORUS:
        if ((s = lb__get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = lb__get_vec3(c, j, "axis", 0, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = lb__get_number(c, j, "major_radius", 1, 1e-9, 1e9, len_ok, &s0)) ||
            (s = lb__get_number(c, j, "minor_radius", 1, 1e-9, 1e9, len_ok, &s1)))
            return s;
        s = lb_primitive_torus(&n->prim, ctr, nv, s0, s1, &perr_local);
        break;
    }
    if (s) return lb__perr(c, s, "%s", perr_local.message);
    const char *kernel = NULL;
    if ((s = lb__get_string(c, j, "kernel", 0, "\"wyvill\" or \"blinn\" (soft scenes only)",
                            &kernel)))
        return s;
    if (c->s->convention == LB_CONVENTION_ZERO) {
        if (kernel) {
            const size_t old = lb__push_key(c, "kernel");
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "a kernel is only meaningful in a soft scene; allowed: leave it out "
                         "(zero convention: f = rho - 1)");
            lb__pop(c, old);
            return s;
        }
    } else {
        lb_kernel kn = LB_KERNEL_WYVILL;
        if (kernel && strcmp(kernel, "blinn") == 0) {
            kn = LB_KERNEL_BLINN;
        } else if (kernel && strcmp(kernel, "wyvill") != 0) {
            const size_t old = lb__push_key(c, "kernel");
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "unknown kernel \"%.40s\"; allowed: \"wyvill\" (default) or \"blinn\"",
                         kernel);
            lb__pop(c, old);
            return s;
        }
        lb_primitive_soften(&n->prim, kn, NULL);
    }
    return LB_OK;
}

/* ---- materials of nodes ---- */

/* A node's own "material" (fields left out take the render section's):
 * n->mat is its index, equal materials sharing one. */
static lb_status node_material(pctx *c, const cJSON *j, lb__node *n) {
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(j, "material");
    if (!mat) return LB_OK;
    const lb_render *R = &c->s->render;
    lb_material m = {{R->color[0], R->color[1], R->color[2]}, R->ambient, R->diffuse, R->specular};
    const size_t o = lb__push_key(c, "material");
    lb_status s = lb__material_fields(c, mat, &m);
    lb__pop(c, o);
    if (s) return s;
    lb_scene *sc = c->s;
    for (size_t i = 0; i < sc->nmats; ++i)
        if (memcmp(&sc->mats[i], &m, sizeof m) == 0) {
            n->mat = i + 1;
            return LB_OK;
        }
    if (sc->nmats == sc->matcap) {
        const size_t cap = sc->matcap ? 2 * sc->matcap : 8;
        lb_material *a = realloc(sc->mats, cap * sizeof *a);
        if (!a) return lb__oom(c);
        sc->mats = a;
        sc->matcap = cap;
    }
    sc->mats[sc->nmats++] = m;
    n->mat = sc->nmats;
    return LB_OK;
}

/* ---- nodes ---- */

lb_status lb__build_def(pctx *c, def_entry *d, size_t depth, lb__node **out) {
    if (d->state == 2) {
        *out = d->node;
        return LB_OK;
    }
    if (d->state == 1)
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                        "reference cycle through def \"%.60s\"; allowed: a def may use only defs "
                        "that do not use it",
                        d->name);
    d->state = 1;
    const lb__jpath saved = c->jp; /* a def is read at its own path */
    lb__jpath_set(&c->jp, "$.defs");
    lb__jpath_key(&c->jp, d->name);
    lb__node *n = NULL;
    lb_status s = lb__parse_node(c, d->json, depth, &n);
    c->jp = saved;
    if (s) return s;
    if (!n->def_name) {
        n->def_name = malloc(strlen(d->name) + 1);
        if (!n->def_name) return lb__oom(c);
        strcpy(n->def_name, d->name);
    }
    d->node = n;
    d->state = 2;
    *out = n;
    return LB_OK;
}

static lb_status parse_ref(pctx *c, const cJSON *j, size_t depth, lb__node **out) {
    static const char *const keys[] = {"ref", TRANSFORM_KEYS, NULL};
    lb_status s;
    const char *name = NULL;
    if ((s = lb__check_keys(c, j, keys, "a ref")) ||
        (s = lb__get_string(c, j, "ref", 1, "the name of an entry of $.defs", &name)))
        return s;
    def_entry *d = NULL;
    for (size_t i = 0; i < c->ndefs && !d; ++i)
        if (strcmp(c->defs[i].name, name) == 0) d = &c->defs[i];
    if (!d) {
        const size_t old = lb__push_key(c, "ref");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "no def named \"%.60s\"; allowed: a name from $.defs%s", name,
                     c->ndefs ? "" : " (this scene has no defs)");
        lb__pop(c, old);
        return s;
    }
    lb__node *target = NULL;
    if ((s = lb__build_def(c, d, depth, &target))) return s;
    lb__node tmp;
    memset(&tmp, 0, sizeof tmp);
    if ((s = get_transform(c, j, &tmp))) return s;
    const int has_mat = cJSON_GetObjectItemCaseSensitive(j, "material") != NULL;
    if (!tmp.has_transform && !has_mat) {
        *out = target;
        return LB_OK;
    }
    /* a ref with its own transform or material is a group over the def */
    lb__node *g = new_node(c, LB__F_GROUP, "ref");
    if (!g) {
        free(tmp.to_local);
        return lb__oom(c);
    }
    g->has_transform = tmp.has_transform;
    g->to_local = tmp.to_local; /* the group owns it now */
    g->o.k = 1;
    g->args = malloc(sizeof *g->args);
    if (!g->args) return lb__oom(c);
    g->args[0] = target;
    if ((s = node_material(c, j, g))) return s;
    g->mat_below = target->mat || target->mat_below;
    g->depth = target->depth + 1;
    g->bulge_depth = target->bulge_depth;
    g->walk_cost = 1.0 + target->walk_cost;
    *out = g;
    return LB_OK;
}

static lb_status parse_args(pctx *c, const cJSON *j, const char *key, const lb__family_row *t,
                            size_t kmin, size_t kmax, size_t depth, lb__node ***out,
                            size_t *k_out) {
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(j, key);
    const size_t old = lb__push_key(c, key);
    lb_status s = LB_OK;
    char allowed[96];
    if (kmin == kmax)
        snprintf(allowed, sizeof allowed, "an array of exactly %zu node%s", kmin,
                 kmin == 1 ? "" : "s");
    else
        snprintf(allowed, sizeof allowed, "an array of %zu to %zu nodes", kmin, kmax);
    if (!a) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s", allowed);
    } else if (!cJSON_IsArray(a)) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected an array, found %s; allowed: %s",
                     lb__json_kind(a), allowed);
    } else {
        const size_t k = (size_t)cJSON_GetArraySize(a);
        if (k < kmin || k > kmax) {
            char wide[160] = "";
            if (k > kmax && kmax == LB_MAX_ARITY) {
                char names[120];
                row_list(0, names, sizeof names);
                snprintf(wide, sizeof wide, " (%s take up to %d; or nest this node)", names,
                         LB_MAX_ARITY_WIDE);
            }
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "%s \"%s\" has %zu argument%s; allowed: %s%s",
                         t->name, key, k, k == 1 ? "" : "s", allowed, wide);
        } else {
            lb__node **v = calloc(k, sizeof *v);
            if (!v) {
                s = lb__oom(c);
            } else {
                size_t i = 0;
                for (cJSON *e = a->child, *next; e && !s; e = next, ++i) {
                    next = e->next;
                    const size_t o2 = lb__push_index(c, i);
                    s = lb__parse_node(c, e, depth + 1, &v[i]);
                    lb__pop(c, o2);
                    /* nothing reads an argument's JSON again once its node
                     * exists (a def is built once): freed now, so that the
                     * document and the nodes are not both held whole */
                    if (!s) cJSON_Delete(cJSON_DetachItemViaPointer((cJSON *)a, e));
                }
                if (s)
                    free(v);
                else {
                    *out = v;
                    *k_out = k;
                }
            }
        }
    }
    lb__pop(c, old);
    return s;
}

static lb_status parse_op(pctx *c, const cJSON *j, const lb__family_row *t, lb_setop *op) {
    const char *str = NULL;
    const char *allowed = t->ops == LB__OPS_UI ? "\"union\" or \"intersection\""
                                               : "\"union\", \"intersection\" or \"difference\"";
    lb_status s = lb__get_string(c, j, "op", 1, allowed, &str);
    if (s) return s;
    if (strcmp(str, "union") == 0)
        *op = LB_UNION;
    else if (strcmp(str, "intersection") == 0)
        *op = LB_INTERSECTION;
    else if (strcmp(str, "difference") == 0 && t->ops == LB__OPS_ALL)
        *op = LB_DIFFERENCE;
    else {
        const size_t old = lb__push_key(c, "op");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "unknown op \"%.40s\" for %s; allowed: %s", str,
                     t->name, allowed);
        lb__pop(c, old);
    }
    return s;
}

/* local_union / clean_union parameters, with their defaults */
static lb_status parse_local(pctx *c, const cJSON *j, lb__node *n) {
    lb__local_params *L = &n->o.lp;
    memset(L, 0, sizeof *L);
    L->support = 0.25;
    L->exponent = 2.0;
    L->zero_scale = 1.0;
    lb_status s;
    double *v = NULL;
    if ((s = get_param(c, j, "alpha", 2, 0, 1, 0.0, 0.0, 0.999,
                       "0 <= alpha <= 0.999 (0: fields of finite support)", &v)))
        return s;
    L->alpha[0] = v[0];
    L->alpha[1] = v[1];
    free(v);
    v = NULL;
    if ((s = lb__get_number(c, j, "zero_scale", 0, 1e-9, 1e9,
                            "1e-9 <= zero_scale <= 1e9 (scene units: g = 0.5 (1 - f / zero_scale))",
                            &L->zero_scale)))
        return s;
    if (!(lb__family_info(n->o.family)->flags & LB__R_CURVES)) return LB_OK; /* clean_union */
    if ((s = get_param(c, j, "feature_size", 2, 0, 0, 0.0, 1e-9, 1e9,
                       "1e-9 <= value <= 1e9 (half the radius of the smallest feature to keep)",
                       &v)))
        return s;
    if (v) {
        L->has_feature = 1;
        L->feature[0] = v[0];
        L->feature[1] = v[1];
        free(v);
        v = NULL;
    }
    if ((s = get_param(c, j, "limits", 2, 0, 0, 0.0, 0.0, 0.4995,
                       "0 <= value <= 0.4995 (field values below the iso value 0.5)", &v)))
        return s;
    if (v) {
        L->has_limits = 1;
        L->limits[0] = v[0];
        L->limits[1] = v[1];
        free(v);
    }
    const char *mode = NULL;
    if ((s = lb__get_number(c, j, "radius", 0, 1e-9, 1e9, "1e-9 <= radius <= 1e9 (scene units)",
                            &L->radius)) ||
        (s = lb__get_number(c, j, "support_factor", 0, 1e-3, 100.0, "1e-3 <= value <= 100",
                            &L->support)) ||
        (s = lb__get_number(c, j, "exponent", 0, 1.0, 1000.0, "1 <= exponent <= 1000",
                            &L->exponent)) ||
        (s = lb__get_string(c, j, "support", 0, "\"progressive\" or \"feature\"", &mode)))
        return s;
    if (mode && strcmp(mode, "progressive") != 0) {
        if (strcmp(mode, "feature") != 0) {
            const size_t old = lb__push_key(c, "support");
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "\"%.40s\"; allowed: \"progressive\" (R = support_factor x the curve's "
                         "diameter) or \"feature\" (R = 2 min(d1, d2))",
                         mode);
            lb__pop(c, old);
            return s;
        }
        L->feature_support = 1;
    }
    return LB_OK;
}

/* A k-ary local or clean union is a left fold of binary ones (order
 * matters): n keeps (fold of the first k - 1, last). */
static lb_status fold_local(pctx *c, lb__node *n) {
    lb__node *acc = n->args[0];
    for (size_t i = 1; i + 1 < n->o.k; ++i) {
        lb__node *m = new_node(c, n->o.family, n->type);
        if (!m) return lb__oom(c);
        /* the fold's inner node: named by the arguments it unites */
        const size_t pl = strlen(m->o.path) + 32;
        char *path = malloc(pl);
        if (!path) return lb__oom(c);
        snprintf(path, pl, "%s (args 0-%zu)", m->o.path, i);
        free(m->o.path);
        m->o.path = path;
        m->o.lp = n->o.lp;
        m->o.k = 2;
        m->args = malloc(2 * sizeof *m->args);
        if (!m->args) return lb__oom(c);
        m->args[0] = acc;
        m->args[1] = n->args[i];
        for (int a = 0; a < 2; ++a) {
            if (m->args[a]->depth + 1 > m->depth) m->depth = m->args[a]->depth + 1;
            if (m->args[a]->bulge_depth > m->bulge_depth) m->bulge_depth = m->args[a]->bulge_depth;
            m->walk_cost += m->args[a]->walk_cost;
        }
        acc = m;
    }
    n->args[0] = acc;
    n->args[1] = n->args[n->o.k - 1];
    n->o.k = 2;
    return LB_OK;
}

static lb_status parse_bulge(pctx *c, const cJSON *j, lb__node *n) {
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bulge");
    if (!b) return LB_OK;
    static const char *const keys[] = {"range", "slope", "omega", NULL};
    const size_t old = lb__push_key(c, "bulge");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(b)) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected an object, found %s; allowed: {\"range\": true, \"slope\": false, "
                     "\"omega\": 0.001}",
                     lb__json_kind(b));
    } else if (n->o.k != 2) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "bulge elimination needs exactly 2 arguments, this node has %zu; allowed: "
                     "bulge on binary blends only",
                     n->o.k);
    } else if (!(s = lb__check_keys(c, b, keys, "bulge"))) {
        unsigned flags = LB_BULGE_RANGE;
        const char *names[2] = {"range", "slope"};
        for (int i = 0; i < 2 && !s; ++i) {
            const cJSON *f = cJSON_GetObjectItemCaseSensitive(b, names[i]);
            if (!f) continue;
            const size_t o2 = lb__push_key(c, names[i]);
            if (!cJSON_IsBool(f))
                s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected true or false, found %s",
                             lb__json_kind(f));
            else if (cJSON_IsTrue(f))
                flags |= i == 0 ? LB_BULGE_RANGE : LB_BULGE_SLOPE;
            else
                flags &= ~(i == 0 ? LB_BULGE_RANGE : LB_BULGE_SLOPE);
            lb__pop(c, o2);
        }
        double omega = 0.001;
        if (!s)
            s = lb__get_number(c, b, "omega", 0, 1e-12, 1.0, "0 < omega <= 1 (0.001 in the papers)",
                               &omega);
        if (!s && flags == 0)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "both range and slope are false; allowed: at least one true, or leave out "
                         "\"bulge\"");
        const lb__family_row *row = lb__family_info(n->o.family);
        if (!s && (flags & LB_BULGE_SLOPE) && !lb__family_param(row, "m"))
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "\"slope\" needs m, which the %s family does not have; allowed: "
                         "{\"range\": true}",
                         row->name);
        if (!s) {
            n->o.bulge = 1;
            n->o.bp.flags = flags;
            n->o.bp.omega = omega;
            for (int i = 0; i < 2; ++i) {
                n->o.bp.r[i] = n->o.r ? n->o.r[i] : 1.0;
                n->o.bp.p[i] = n->o.p ? n->o.p[i] : 2.0;
                n->o.bp.m[i] = n->o.m ? n->o.m[i] : 1.0;
            }
            n->o.bp.conic_p = n->o.shape;
        }
    }
    lb__pop(c, old);
    return s;
}

/* Bounding solid check where it is cheap [spec 6]: an untransformed
 * sphere/ellipsoid argument and bounding solid with the same centre. */
static lb_status check_bound_contains(pctx *c, const lb__node *n, size_t i) {
    const lb__node *a = n->args[i], *b = n->bounds[i];
    if (a->o.family != LB__F_PRIMITIVE || b->o.family != LB__F_PRIMITIVE || a->has_transform ||
        b->has_transform || a->prim.kind != LB_PRIM_ELLIPSOID || b->prim.kind != LB_PRIM_ELLIPSOID)
        return LB_OK;
    if (memcmp(a->prim.c, b->prim.c, sizeof a->prim.c) != 0) return LB_OK;
    const int union_like = n->o.op == LB_UNION || (n->o.op == LB_DIFFERENCE && i > 0);
    for (int d = 0; d < 3; ++d) {
        const int bad = union_like ? b->prim.a[d] < a->prim.a[d] : b->prim.a[d] > a->prim.a[d];
        if (bad) {
            const size_t o1 = lb__push_key(c, "bounds"), o2 = lb__push_index(c, i);
            lb_status s = lb__perr(
                c, LB_ERR_INVALID_ARGUMENT,
                "the bounding solid (semi-axis %g) does not %s argument %zu (semi-axis %g); "
                "allowed: a bounding solid that %s its argument",
                b->prim.a[d], union_like ? "contain" : "lie inside", i, a->prim.a[d],
                union_like ? "contains" : "lies inside");
            lb__pop(c, o2);
            lb__pop(c, o1);
            return s;
        }
    }
    return LB_OK;
}

/* the conic's shape "p" of n (default 0, the quarter ellipse): below r1 r2,
 * n->o.r already read (conic and soft_conic) */
static lb_status get_conic_shape(pctx *c, const cJSON *j, lb__node *n) {
    char ok[96];
    snprintf(ok, sizeof ok, "a number below r1 r2 = %.17g (0 = quarter ellipse)",
             n->o.r[0] * n->o.r[1]);
    n->o.shape = 0.0;
    lb_status s = lb__get_number(c, j, "p", 0, -1e18, 1e18, ok, &n->o.shape);
    if (!s && !(n->o.shape < n->o.r[0] * n->o.r[1])) {
        const size_t old = lb__push_key(c, "p");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "p = %.17g is not below r1 r2; allowed: %s",
                     n->o.shape, ok);
        lb__pop(c, old);
    }
    return s;
}

/* a per-argument parameter of the row into the node's array (n->o.k known,
 * n->o.op read) */
static lb_status read_param(pctx *c, const cJSON *j, const lb__param *p, lb__node *n) {
    double **dst = strcmp(p->key, "r") == 0   ? &n->o.r
                   : strcmp(p->key, "p") == 0 ? &n->o.p
                                              : &n->o.m;
    const int alt = (p->hi_alt_ops >> n->o.op) & 1u;
    char ok[96];
    lb__param_allowed(p, alt, ok, sizeof ok);
    /* an open lower end: the next representable step past it that the
     * kernels accept (1 < p: p >= 1 + 1e-12) */
    const double lo = p->open_lo ? p->lo + 1e-12 : p->lo;
    return get_param(c, j, p->key, n->o.k, p->required, !p->required, p->def, lo,
                     alt ? p->hi_alt : p->hi, ok, dst);
}

/* the row's scalar parameter into n->o.shape (n->o.r read: the conics) */
static lb_status read_shape(pctx *c, const cJSON *j, const lb__shape *sh, lb__node *n) {
    if (sh->below_r1r2) return get_conic_shape(c, j, n);
    const int cv = c->s->convention == LB_CONVENTION_SOFT;
    char ok[96], lo[40], hi[40];
    if (sh->allowed[cv]) {
        snprintf(ok, sizeof ok, "%s", sh->allowed[cv]);
    } else {
        lb__short_number(sh->lo[cv], lo, sizeof lo);
        lb__short_number(sh->hi[cv], hi, sizeof hi);
        snprintf(ok, sizeof ok, "%s <= %s <= %s", lo, sh->key, hi);
    }
    n->o.shape = sh->def;
    return lb__get_number(c, j, sh->key, sh->required, sh->lo[cv], sh->hi[cv], ok, &n->o.shape);
}

/* "bounds": one bounding solid per argument (LB__R_BOUNDING) */
static lb_status parse_bounds(pctx *c, const cJSON *j, const lb__family_row *t, size_t depth,
                              lb__node *n) {
    const size_t k = n->o.k;
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bounds");
    lb_status s = LB_OK;
    if (!b || (cJSON_IsArray(b) && (size_t)cJSON_GetArraySize(b) != k)) {
        const size_t old = lb__push_key(c, "bounds");
        if (!b)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "missing required field; allowed: an array of %zu bounding solids, one "
                         "per argument",
                         k);
        else
            s = lb__perr(
                c, LB_ERR_INVALID_ARGUMENT,
                "has %d bounding solids for %zu arguments; allowed: exactly one per argument",
                cJSON_GetArraySize(b), k);
        lb__pop(c, old);
        return s;
    }
    size_t kb = 0;
    if ((s = parse_args(c, j, "bounds", t, k, k, depth, &n->bounds, &kb))) return s;
    for (size_t i = 0; i < k; ++i)
        if ((s = check_bound_contains(c, n, i))) return s;
    return LB_OK;
}

/* an operator node's own fields, in the row's order: its parameters, its
 * scalar parameter, bulge, bounding solids, local blending */
static lb_status parse_operator(pctx *c, const cJSON *j, const lb__family_row *t, size_t depth,
                                lb__node *n) {
    lb_status s;
    if (t->ops && (s = parse_op(c, j, t, &n->o.op))) return s;
    if ((s = parse_args(c, j, "args", t, t->kmin, t->kmax, depth, &n->args, &n->o.k))) return s;
    for (const lb__param *p = t->params; p->key; ++p)
        if ((s = read_param(c, j, p, n))) return s;
    if (t->shape && (s = read_shape(c, j, t->shape, n))) return s;
    if (t->bulge_family >= 0 && (s = parse_bulge(c, j, n))) return s;
    if ((t->flags & LB__R_BOUNDING) && (s = parse_bounds(c, j, t, depth, n))) return s;
    if (t->flags & LB__R_FOLD_BINARY) {
        if ((s = parse_local(c, j, n))) return s;
        if (n->o.k > 2 && (s = fold_local(c, n))) return s;
    }
    return LB_OK;
}

/* what a node's arguments give it: height, bulge nesting, walk cost,
 * materials below; then the operator's own check at a neutral point */
static lb_status finish_operator(pctx *c, lb__node *n) {
    const size_t k = n->o.k;
    lb_status s;
    for (size_t i = 0; i < k; ++i) {
        const lb__node *a = n->args[i];
        n->mat_below |= a->mat || a->mat_below;
        if (n->bounds && (n->bounds[i]->mat || n->bounds[i]->mat_below)) {
            const size_t o1 = lb__push_key(c, "bounds"), o2 = lb__push_index(c, i);
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                         "a bounding solid has a material, but it is never on the surface; "
                         "allowed: materials on args (remove it here)");
            lb__pop(c, o2);
            lb__pop(c, o1);
            return s;
        }
        if (a->depth + 1 > n->depth) n->depth = a->depth + 1;
        if (a->bulge_depth > n->bulge_depth) n->bulge_depth = a->bulge_depth;
        if (n->bounds && n->bounds[i]->depth + 1 > n->depth) n->depth = n->bounds[i]->depth + 1;
        if (n->bounds && n->bounds[i]->bulge_depth > n->bulge_depth)
            n->bulge_depth = n->bounds[i]->bulge_depth;
        /* the reference walk visits a shared node once per use, and a
         * bulge-eliminated blend walks each argument twice more */
        n->walk_cost += (n->o.bulge ? 3.0 : 1.0) * a->walk_cost;
        if (n->bounds) n->walk_cost += n->bounds[i]->walk_cost;
    }
    if (n->o.bulge && ++n->bulge_depth > LB_SCENE_MAX_BULGE_NESTING) {
        const size_t old = lb__push_key(c, "bulge");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "bulge elimination nested %zu deep (each level evaluates its arguments 4 more "
                     "times); allowed: at most %d bulge-eliminated blends on any path",
                     n->bulge_depth, LB_SCENE_MAX_BULGE_NESTING);
        lb__pop(c, old);
        return s;
    }
    /* backstop: the operator itself accepts the parameters at a neutral point */
    double *x = malloc(2 * k * sizeof *x), g[6] = {1, 0, 0, 0, 1, 0}, v = 0.0;
    if (!x) return lb__oom(c);
    double *cb = x + k;
    for (size_t i = 0; i < k; ++i) {
        x[i] = c->s->convention == LB_CONVENTION_ZERO ? 0.0 : 0.5;
        cb[i] = 0.5;
    }
    lb_error e = {LB_OK, ""};
    const lb_status as = lb__op_apply(&n->o, c->s->convention, x, cb, g, &v, NULL, NULL, NULL, &e);
    free(x);
    if (as) return lb__perr(c, LB_ERR_INVALID_ARGUMENT, "%s", e.message);
    return LB_OK;
}

/* the node's "type" looked up in the registry, its keys and convention
 * checked; *row and *prim receive the rows */
static lb_status node_type(pctx *c, const cJSON *j, const lb__family_row **row,
                           const lb__primitive_row **prim) {
    lb_status s;
    char list[512] = "";
    const cJSON *tj = cJSON_GetObjectItemCaseSensitive(j, "type");
    const char *type = NULL;
    if (!cJSON_IsString(tj)) type_list(list, sizeof list);
    if ((s = lb__get_string(c, j, "type", 1, list, &type))) return s;
    const lb__family_row *t = lb__family_find(type, prim);
    if (!t) {
        type_list(list, sizeof list);
        const size_t old = lb__push_key(c, "type");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "unknown node type \"%.60s\"; allowed: %s", type,
                     list);
        lb__pop(c, old);
        return s;
    }
    const char *keys[32];
    /* a kernel in a zero scene is refused by parse_primitive, naming the
     * kernel rather than an unknown key */
    node_keys(*prim ? (*prim)->keys : t->keys, *prim ? lb__primitive_soft_keys : NULL, keys);
    char what[64];
    snprintf(what, sizeof what, "a %s node", type);
    if ((s = lb__check_keys(c, j, keys, what))) return s;
    const int conv_bit = c->s->convention == LB_CONVENTION_ZERO ? LB__CONV_ZERO : LB__CONV_SOFT;
    if (!(t->conv & conv_bit)) {
        row_list(conv_bit, list, sizeof list);
        const size_t old = lb__push_key(c, "type");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "%s is a %s-convention operator but the scene's convention is \"%s\"; "
                     "allowed: %s",
                     t->name, t->conv == LB__CONV_ZERO ? "zero" : "soft",
                     conv_bit == LB__CONV_ZERO ? "zero" : "soft", list);
        lb__pop(c, old);
        return s;
    }
    *row = t;
    return LB_OK;
}

lb_status lb__parse_node(pctx *c, const cJSON *j, size_t depth, lb__node **out) {
    lb_status s;
    if (!cJSON_IsObject(j))
        return lb__perr(
            c, LB_ERR_INVALID_ARGUMENT,
            "expected a node object, found %s; allowed: {\"type\": ...} or {\"ref\": ...}",
            lb__json_kind(j));
    if (depth > LB_SCENE_MAX_DEPTH)
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                        "nodes nested deeper than %d levels; allowed: at most %d levels (use defs "
                        "and refs to share subtrees)",
                        LB_SCENE_MAX_DEPTH, LB_SCENE_MAX_DEPTH);
    if (++c->count > LB_SCENE_MAX_NODES)
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT, "more than %d nodes; allowed: at most %d nodes",
                        LB_SCENE_MAX_NODES, LB_SCENE_MAX_NODES);
    if (cJSON_GetObjectItemCaseSensitive(j, "ref")) return parse_ref(c, j, depth, out);
    const lb__family_row *t = NULL;
    const lb__primitive_row *prim = NULL;
    if ((s = node_type(c, j, &t, &prim))) return s;
    lb__node *n = new_node(c, t->id, prim ? prim->name : t->name);
    if (!n) return lb__oom(c);
    if ((s = get_transform(c, j, n)) || (s = node_material(c, j, n))) return s;
    if (prim) {
        if ((s = parse_primitive(c, j, prim, n))) return s;
    } else if ((s = parse_operator(c, j, t, depth, n)) || (s = finish_operator(c, n))) {
        return s;
    }
    *out = n;
    return LB_OK;
}
