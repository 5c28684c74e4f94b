/* Scene files (format "libblend-scene", version 1): JSON parsed by cJSON,
 * validated into lb__node trees. Every failure is one message:
 *   FILE[:LINE:COL]: $.json.path: what is wrong; allowed: what would be right
 * Line and column are known for syntax errors (cJSON keeps no positions for
 * values); the JSON path is always given. docs/scene-format.md is the
 * reference for every name accepted here. */
#define _POSIX_C_SOURCE 200809L
#include "scene_internal.h"
#include "../common/glibc_compat.h"
#include "../common/platform.h"

#include <sys/stat.h>

#include <cjson/cJSON.h>
#include <jansson.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PATH_MAX_LEN 480
/* cJSON's own nesting limit is 1000 levels; each node level costs at most
 * 3 JSON levels, so this is checked first with a clear message. */
#define JSON_MAX_NESTING (3 * LB_SCENE_MAX_DEPTH + 16)

typedef struct def_entry {
    const char *name;
    cJSON *json;
    lb__node *node;
    int state; /* 0 not built, 1 building, 2 built */
} def_entry;

typedef struct pctx {
    lb_scene *s;
    const char *file;
    lb_error *err;
    char path[PATH_MAX_LEN];
    size_t plen;
    def_entry *defs;
    size_t ndefs;
    size_t count;
} pctx;

/* ---- messages and paths ---- */

static lb_status perr(pctx *c, lb_status st, const char *fmt, ...) LB_PRINTF(3, 4);
static lb_status perr(pctx *c, lb_status st, const char *fmt, ...) {
    char msg[LB_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (c->plen > 160) /* deep paths: the start and the end say where */
        return lb__fail(c->err, st, "%s: %.60s...%s: %s", c->file, c->path, c->path + c->plen - 80,
                        msg);
    return lb__fail(c->err, st, "%s: %s: %s", c->file, c->path, msg);
}

static size_t push_key(pctx *c, const char *key) {
    const size_t old = c->plen;
    int n = snprintf(c->path + old, sizeof c->path - old, ".%s", key);
    c->plen = n > 0 && (size_t)n < sizeof c->path - old ? old + (size_t)n : strlen(c->path);
    return old;
}

static size_t push_index(pctx *c, size_t i) {
    const size_t old = c->plen;
    int n = snprintf(c->path + old, sizeof c->path - old, "[%zu]", i);
    c->plen = n > 0 && (size_t)n < sizeof c->path - old ? old + (size_t)n : strlen(c->path);
    return old;
}

static void pop(pctx *c, size_t old) {
    c->plen = old;
    c->path[old] = '\0';
}

static const char *json_kind(const cJSON *j) {
    if (!j) return "nothing";
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an invalid value";
}

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
    n->path = malloc(c->plen + 1);
    if (!n->path) {
        free(n);
        return NULL;
    }
    memcpy(n->path, c->path, c->plen + 1);
    n->family = fam;
    n->type = type;
    n->depth = 1;
    lb__affine_identity(&n->to_local);
    lb__affine_identity(&n->to_parent);
    s->nodes[s->nnodes++] = n;
    return n;
}

static lb_status oom(pctx *c) {
    return perr(c, LB_ERR_NO_MEMORY, "out of memory while building the scene");
}

/* ---- field readers ---- */

/* Every member of obj must be one of the names in allowed (NULL-terminated),
 * and appear once. */
static lb_status check_keys(pctx *c, const cJSON *obj, const char *const *allowed,
                            const char *what) {
    for (const cJSON *it = obj->child; it; it = it->next) {
        int ok = 0;
        for (const char *const *a = allowed; *a && !ok; ++a) ok = strcmp(*a, it->string) == 0;
        if (!ok) {
            char list[320] = "";
            size_t len = 0;
            for (const char *const *a = allowed; *a; ++a) {
                int w = snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "", *a);
                if (w < 0 || (size_t)w >= sizeof list - len) break;
                len += (size_t)w;
            }
            return perr(c, LB_ERR_INVALID_ARGUMENT, "unknown field \"%.60s\" in %s; allowed: %s",
                        it->string, what, list);
        }
        for (const cJSON *o = obj->child; o != it; o = o->next)
            if (strcmp(o->string, it->string) == 0)
                return perr(c, LB_ERR_INVALID_ARGUMENT,
                            "field \"%.60s\" appears twice; allowed: each field once", it->string);
    }
    return LB_OK;
}

static lb_status number_value(pctx *c, const cJSON *j, double lo, double hi, const char *allowed,
                              double *out) {
    if (!cJSON_IsNumber(j))
        return perr(c, LB_ERR_INVALID_ARGUMENT, "expected a number, found %s; allowed: %s",
                    json_kind(j), allowed);
    const double v = j->valuedouble;
    if (!isfinite(v))
        return perr(c, LB_ERR_NOT_FINITE, "%g is not finite; allowed: %s", v, allowed);
    if (!(v >= lo && v <= hi))
        return perr(c, LB_ERR_INVALID_ARGUMENT, "%.15g is out of range; allowed: %s", v, allowed);
    *out = v;
    return LB_OK;
}

/* Optional number field: *out keeps its default when absent. */
static lb_status get_number(pctx *c, const cJSON *obj, const char *key, int required, double lo,
                            double hi, const char *allowed, double *out) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s", allowed);
    } else {
        s = number_value(c, j, lo, hi, allowed, out);
    }
    pop(c, old);
    return s;
}

static lb_status get_vec3(pctx *c, const cJSON *obj, const char *key, int required, double lo,
                          double hi, const char *allowed, double out[3]) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s", allowed);
    } else if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != 3) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "expected an array of 3 numbers, found %s%s; allowed: [x, y, z], each %s",
                 json_kind(j), cJSON_IsArray(j) ? " of another length" : "", allowed);
    } else {
        double v[3];
        for (int i = 0; i < 3 && !s; ++i) {
            const size_t o2 = push_index(c, (size_t)i);
            s = number_value(c, cJSON_GetArrayItem(j, i), lo, hi, allowed, &v[i]);
            pop(c, o2);
        }
        if (!s) memcpy(out, v, sizeof v);
    }
    pop(c, old);
    return s;
}

static lb_status get_string(pctx *c, const cJSON *obj, const char *key, int required,
                            const char *allowed, const char **out) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s", allowed);
    } else if (!cJSON_IsString(j)) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "expected a string, found %s; allowed: %s",
                 json_kind(j), allowed);
    } else {
        *out = j->valuestring;
    }
    pop(c, old);
    return s;
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
    const size_t old = push_key(c, key);
    lb_status s = LB_OK;
    double *v = malloc(k * sizeof *v);
    if (!v) {
        s = oom(c);
    } else if (!j) {
        if (required)
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "missing required field; allowed: a number (for every argument) or an "
                     "array of %zu numbers (one per argument), each %s",
                     k, allowed);
        for (size_t i = 0; i < k; ++i) v[i] = def;
    } else if (cJSON_IsNumber(j)) {
        double x = 0.0;
        s = number_value(c, j, lo, hi, allowed, &x);
        for (size_t i = 0; i < k; ++i) v[i] = x;
    } else if (cJSON_IsArray(j)) {
        const size_t n = (size_t)cJSON_GetArraySize(j);
        if (n != k) {
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "has %zu values for %zu arguments; allowed: a number or an array of "
                     "exactly %zu numbers (one per argument)",
                     n, k, k);
        } else {
            size_t i = 0;
            for (const cJSON *e = j->child; e && !s; e = e->next, ++i) {
                const size_t o2 = push_index(c, i);
                s = number_value(c, e, lo, hi, allowed, &v[i]);
                pop(c, o2);
            }
        }
    } else {
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "expected a number or an array of %zu numbers, found %s; allowed: each %s", k,
                 json_kind(j), allowed);
    }
    pop(c, old);
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
    if ((s = get_vec3(c, obj, "translate", 0, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                      "|value| <= 1e9", t)) ||
        (s = get_vec3(c, obj, "rotate", 0, -36000.0, 36000.0,
                      "degrees about x, then y, then z, |value| <= 36000", rdeg)))
        return s;
    const cJSON *js = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    if (cJSON_IsNumber(js)) {
        double u = 1.0;
        if ((s = get_number(c, obj, "scale", 0, 1e-6, 1e6, "1e-6 <= scale <= 1e6 (uniform)", &u)))
            return s;
        sc[0] = sc[1] = sc[2] = u;
    } else if ((s = get_vec3(c, obj, "scale", 0, 1e-6, 1e6, "1e-6 <= value <= 1e6", sc))) {
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
    n->to_parent = a;
    /* inverse: S^-1 R^T (x - t) */
    lb__affine inv;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            /* (R S)^-1 = S^-1 R^T; R = a.M S^-1 column-wise */
            inv.M[3 * i + j] = a.M[3 * j + i] / (sc[i] * sc[i]);
        }
    for (int i = 0; i < 3; ++i)
        inv.t[i] = -(inv.M[3 * i] * t[0] + inv.M[3 * i + 1] * t[1] + inv.M[3 * i + 2] * t[2]);
    n->to_local = inv;
    return LB_OK;
}

/* ---- type table ---- */

/* keys every node takes: its transform and its material */
#define TRANSFORM_KEYS "translate", "rotate", "scale", "material"

typedef struct type_info {
    const char *name;
    lb__family family;
    int prim_kind; /* primitives */
    int conv;      /* bit 1: zero, bit 2: soft */
    int has_op;    /* 1: union/intersection/difference; 2: union/intersection only */
    size_t kmin, kmax;
    const char *const *keys;
} type_info;

static const char *const k_sphere[] = {"type", "center", "radius", "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_ellipsoid[] = {"type",   "center",       "semi_axes",
                                          "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_lp[] = {"type",   "center",       "semi_axes", "exponent",
                                   "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_superquadric[] = {"type", "center", "semi_axes",    "e1",
                                             "e2",   "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_slab[] = {"type",   "point",        "normal", "half_width",
                                     "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_halfspace[] = {"type",   "point",        "normal", "width",
                                          "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_cylinder[] = {"type",   "point",        "axis", "radius",
                                         "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_capsule[] = {"type",   "start",        "end", "radius",
                                        "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_torus[] = {"type",         "center", "axis",         "major_radius",
                                      "minor_radius", "kernel", TRANSFORM_KEYS, NULL};
static const char *const k_displacement[] = {"type", "op",    "args",         "r", "p",
                                             "m",    "bulge", TRANSFORM_KEYS, NULL};
static const char *const k_scale[] = {"type", "op",    "args",         "r",
                                      "p",    "bulge", TRANSFORM_KEYS, NULL};
static const char *const k_bounded[] = {"type", "op", "args", "bounds", "p", TRANSFORM_KEYS, NULL};
static const char *const k_soft[] = {"type", "op", "args", "r", "p", "m", TRANSFORM_KEYS, NULL};
static const char *const k_args[] = {"type", "args", TRANSFORM_KEYS, NULL};
static const char *const k_opargs[] = {"type", "op", "args", TRANSFORM_KEYS, NULL};
static const char *const k_ricci[] = {"type", "args", "n", TRANSFORM_KEYS, NULL};
static const char *const k_level[] = {"type", "args", "level", TRANSFORM_KEYS, NULL};
static const char *const k_local[] = {"type",   "args",       "feature_size",   "limits",
                                      "radius", "support",    "support_factor", "exponent",
                                      "alpha",  "zero_scale", TRANSFORM_KEYS,   NULL};
static const char *const k_clean[] = {"type", "args", "alpha", "zero_scale", TRANSFORM_KEYS, NULL};

enum { CONV_ZERO = 1, CONV_SOFT = 2, CONV_BOTH = 3 };

static const type_info TYPES[] = {
    {"sphere", LB__F_PRIMITIVE, LB_PRIM_ELLIPSOID, CONV_BOTH, 0, 0, 0, k_sphere},
    {"ellipsoid", LB__F_PRIMITIVE, LB_PRIM_ELLIPSOID, CONV_BOTH, 0, 0, 0, k_ellipsoid},
    {"lp", LB__F_PRIMITIVE, LB_PRIM_LP, CONV_BOTH, 0, 0, 0, k_lp},
    {"superquadric", LB__F_PRIMITIVE, LB_PRIM_SUPERQUADRIC, CONV_BOTH, 0, 0, 0, k_superquadric},
    {"slab", LB__F_PRIMITIVE, LB_PRIM_SLAB, CONV_BOTH, 0, 0, 0, k_slab},
    {"halfspace", LB__F_PRIMITIVE, LB_PRIM_HALFSPACE, CONV_BOTH, 0, 0, 0, k_halfspace},
    {"cylinder", LB__F_PRIMITIVE, LB_PRIM_CYLINDER, CONV_BOTH, 0, 0, 0, k_cylinder},
    {"capsule", LB__F_PRIMITIVE, LB_PRIM_CAPSULE, CONV_BOTH, 0, 0, 0, k_capsule},
    {"torus", LB__F_PRIMITIVE, LB_PRIM_TORUS, CONV_BOTH, 0, 0, 0, k_torus},
    {"displacement", LB__F_DISPLACEMENT, 0, CONV_ZERO, 1, 1, LB_MAX_ARITY_WIDE, k_displacement},
    {"conic", LB__F_CONIC, 0, CONV_ZERO, 1, 2, 2, k_displacement},
    {"scale", LB__F_SCALE, 0, CONV_ZERO, 1, 1, LB_MAX_ARITY, k_scale},
    {"bounded", LB__F_BOUNDED, 0, CONV_ZERO, 1, 1, LB_MAX_ARITY, k_bounded},
    {"soft_hyper", LB__F_SOFT_HYPER, 0, CONV_SOFT, 1, 1, LB_MAX_ARITY, k_soft},
    {"soft_conic", LB__F_SOFT_CONIC, 0, CONV_SOFT, 1, 2, 2, k_soft},
    {"min", LB__F_MIN, 0, CONV_BOTH, 0, 1, LB_MAX_ARITY_WIDE, k_args},
    {"max", LB__F_MAX, 0, CONV_BOTH, 0, 1, LB_MAX_ARITY_WIDE, k_args},
    {"rfunction", LB__F_RFUNCTION, 0, CONV_ZERO, 2, 2, 2, k_opargs},
    {"soft_sum", LB__F_SOFT_SUM, 0, CONV_SOFT, 0, 1, LB_MAX_ARITY_WIDE, k_args},
    {"ricci", LB__F_RICCI, 0, CONV_SOFT, 0, 1, LB_MAX_ARITY_WIDE, k_ricci},
    {"perlin", LB__F_PERLIN, 0, CONV_SOFT, 1, 1, LB_MAX_ARITY, k_opargs},
    {"complement", LB__F_COMPLEMENT, 0, CONV_BOTH, 0, 1, 1, k_args},
    {"local_union", LB__F_LOCAL, 0, CONV_BOTH, 0, 2, LB_MAX_ARITY, k_local},
    {"clean_union", LB__F_CLEAN, 0, CONV_BOTH, 0, 2, LB_MAX_ARITY, k_clean},
    {"level", LB__F_LEVEL, 0, CONV_BOTH, 0, 1, 1, k_level},
};
#define NTYPES (sizeof TYPES / sizeof TYPES[0])

static const char TYPE_LIST[] =
    "sphere, ellipsoid, lp, superquadric, slab, halfspace, cylinder, capsule, torus, "
    "displacement, conic, scale, bounded, soft_hyper, soft_conic, min, max, rfunction, "
    "soft_sum, ricci, perlin, complement, local_union, clean_union, level (or {\"ref\": "
    "NAME})";

/* ---- primitives ---- */

static lb_status parse_primitive(pctx *c, const cJSON *j, const type_info *t, lb__node *n) {
    double ctr[3] = {0, 0, 0}, a[3] = {1, 1, 1}, nv[3] = {0, 0, 1}, q[3] = {0, 0, 0};
    double s0 = 1.0, s1 = 1.0;
    const double CMAX = LB_SCENE_MAX_COORD;
    const char *len_ok = "1e-9 <= value <= 1e9 (a length)";
    lb_status s = LB_OK;
    lb_error perr_local = {LB_OK, ""};
    switch ((lb_primitive_kind)t->prim_kind) {
    case LB_PRIM_ELLIPSOID:
        if ((s = get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr))) return s;
        if (strcmp(t->name, "sphere") == 0) {
            if ((s = get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0))) return s;
            s = lb_primitive_sphere(&n->prim, ctr, s0, &perr_local);
        } else {
            if ((s = get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a))) return s;
            s = lb_primitive_ellipsoid(&n->prim, ctr, a, &perr_local);
        }
        break;
    case LB_PRIM_LP:
        if ((s = get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a)) ||
            (s = get_number(c, j, "exponent", 1, 1.0, 1000.0, "1 <= exponent <= 1000", &s0)))
            return s;
        s = lb_primitive_lp(&n->prim, ctr, a, s0, &perr_local);
        break;
    case LB_PRIM_SUPERQUADRIC:
        if ((s = get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "semi_axes", 1, 1e-9, 1e9, len_ok, a)) ||
            (s = get_number(c, j, "e1", 1, 0.01, 10.0, "0.01 <= e1 <= 10 (1 = round)", &s0)) ||
            (s = get_number(c, j, "e2", 1, 0.01, 10.0, "0.01 <= e2 <= 10 (1 = round)", &s1)))
            return s;
        s = lb_primitive_superquadric(&n->prim, ctr, a, s0, s1, &perr_local);
        break;
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE: {
        const int slab = t->prim_kind == LB_PRIM_SLAB;
        if ((s = get_vec3(c, j, "point", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "normal", 1, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = get_number(c, j, slab ? "half_width" : "width", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = slab ? lb_primitive_slab(&n->prim, ctr, nv, s0, &perr_local)
                 : lb_primitive_halfspace(&n->prim, ctr, nv, s0, &perr_local);
        break;
    }
    case LB_PRIM_CYLINDER:
        if ((s = get_vec3(c, j, "point", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "axis", 1, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = lb_primitive_cylinder(&n->prim, ctr, nv, s0, &perr_local);
        break;
    case LB_PRIM_CAPSULE:
        if ((s = get_vec3(c, j, "start", 1, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "end", 1, -CMAX, CMAX, "|value| <= 1e9", q)) ||
            (s = get_number(c, j, "radius", 1, 1e-9, 1e9, len_ok, &s0)))
            return s;
        s = lb_primitive_capsule(&n->prim, ctr, q, s0, &perr_local);
        break;
    case LB_PRIM_TORUS:
        if ((s = get_vec3(c, j, "center", 0, -CMAX, CMAX, "|value| <= 1e9", ctr)) ||
            (s = get_vec3(c, j, "axis", 0, -1e9, 1e9, "a non-zero vector", nv)) ||
            (s = get_number(c, j, "major_radius", 1, 1e-9, 1e9, len_ok, &s0)) ||
            (s = get_number(c, j, "minor_radius", 1, 1e-9, 1e9, len_ok, &s1)))
            return s;
        s = lb_primitive_torus(&n->prim, ctr, nv, s0, s1, &perr_local);
        break;
    }
    if (s) return perr(c, s, "%s", perr_local.message);
    const char *kernel = NULL;
    if ((s = get_string(c, j, "kernel", 0, "\"wyvill\" or \"blinn\" (soft scenes only)", &kernel)))
        return s;
    if (c->s->convention == LB_CONVENTION_ZERO) {
        if (kernel) {
            const size_t old = push_key(c, "kernel");
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "a kernel is only meaningful in a soft scene; allowed: leave it out "
                     "(zero convention: f = rho - 1)");
            pop(c, old);
            return s;
        }
    } else {
        lb_kernel kn = LB_KERNEL_WYVILL;
        if (kernel && strcmp(kernel, "blinn") == 0) {
            kn = LB_KERNEL_BLINN;
        } else if (kernel && strcmp(kernel, "wyvill") != 0) {
            const size_t old = push_key(c, "kernel");
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "unknown kernel \"%.40s\"; allowed: \"wyvill\" (default) or \"blinn\"",
                     kernel);
            pop(c, old);
            return s;
        }
        lb_primitive_soften(&n->prim, kn, NULL);
    }
    return LB_OK;
}

/* ---- materials ---- */

/* {"color", "ambient", "diffuse", "specular"} into *m; fields left out keep
 * what *m holds. */
static lb_status material_fields(pctx *c, const cJSON *mat, lb_material *m) {
    static const char *const mat_keys[] = {"color", "ambient", "diffuse", "specular", NULL};
    lb_status s;
    if (!cJSON_IsObject(mat))
        return perr(c, LB_ERR_INVALID_ARGUMENT,
                    "expected an object, found %s; allowed: {\"color\": [r, g, b], "
                    "\"ambient\": a, \"diffuse\": d, \"specular\": s}",
                    json_kind(mat));
    if ((s = check_keys(c, mat, mat_keys, "material")) ||
        (s = get_vec3(c, mat, "color", 0, 0.0, 1.0, "0 <= value <= 1", m->color)) ||
        (s = get_number(c, mat, "ambient", 0, 0.0, 1.0, "0 <= ambient <= 1", &m->ambient)) ||
        (s = get_number(c, mat, "diffuse", 0, 0.0, 1.0, "0 <= diffuse <= 1", &m->diffuse)))
        return s;
    return get_number(c, mat, "specular", 0, 0.0, 1.0, "0 <= specular <= 1", &m->specular);
}

/* A node's own "material" (fields left out take the render section's):
 * n->mat is its index, equal materials sharing one. */
static lb_status node_material(pctx *c, const cJSON *j, lb__node *n) {
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(j, "material");
    if (!mat) return LB_OK;
    const lb_render *R = &c->s->render;
    lb_material m = {{R->color[0], R->color[1], R->color[2]}, R->ambient, R->diffuse, R->specular};
    const size_t o = push_key(c, "material");
    lb_status s = material_fields(c, mat, &m);
    pop(c, o);
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
        if (!a) return oom(c);
        sc->mats = a;
        sc->matcap = cap;
    }
    sc->mats[sc->nmats++] = m;
    n->mat = sc->nmats;
    return LB_OK;
}

/* ---- nodes ---- */

static lb_status parse_node(pctx *c, const cJSON *j, size_t depth, lb__node **out);

static lb_status build_def(pctx *c, def_entry *d, size_t depth, lb__node **out) {
    if (d->state == 2) {
        *out = d->node;
        return LB_OK;
    }
    if (d->state == 1)
        return perr(c, LB_ERR_INVALID_ARGUMENT,
                    "reference cycle through def \"%.60s\"; allowed: a def may use only defs "
                    "that do not use it",
                    d->name);
    d->state = 1;
    char saved[PATH_MAX_LEN];
    const size_t saved_len = c->plen;
    memcpy(saved, c->path, c->plen + 1);
    c->plen = 0;
    c->path[0] = '\0';
    int w = snprintf(c->path, sizeof c->path, "$.defs.%s", d->name);
    c->plen = w > 0 && (size_t)w < sizeof c->path ? (size_t)w : strlen(c->path);
    lb__node *n = NULL;
    lb_status s = parse_node(c, d->json, depth, &n);
    memcpy(c->path, saved, saved_len + 1);
    c->plen = saved_len;
    if (s) return s;
    if (!n->def_name) {
        n->def_name = malloc(strlen(d->name) + 1);
        if (!n->def_name) return oom(c);
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
    if ((s = check_keys(c, j, keys, "a ref")) ||
        (s = get_string(c, j, "ref", 1, "the name of an entry of $.defs", &name)))
        return s;
    def_entry *d = NULL;
    for (size_t i = 0; i < c->ndefs && !d; ++i)
        if (strcmp(c->defs[i].name, name) == 0) d = &c->defs[i];
    if (!d) {
        const size_t old = push_key(c, "ref");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "no def named \"%.60s\"; allowed: a name from $.defs%s", name,
                 c->ndefs ? "" : " (this scene has no defs)");
        pop(c, old);
        return s;
    }
    lb__node *target = NULL;
    if ((s = build_def(c, d, depth, &target))) return s;
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
    if (!g) return oom(c);
    g->k = 1;
    g->args = malloc(sizeof *g->args);
    if (!g->args) return oom(c);
    g->args[0] = target;
    if ((s = node_material(c, j, g))) return s;
    g->mat_below = target->mat || target->mat_below;
    g->has_transform = tmp.has_transform;
    g->to_local = tmp.to_local;
    g->to_parent = tmp.to_parent;
    g->depth = target->depth + 1;
    g->bulge_depth = target->bulge_depth;
    g->walk_cost = 1.0 + target->walk_cost;
    *out = g;
    return LB_OK;
}

static lb_status parse_args(pctx *c, const cJSON *j, const char *key, const type_info *t,
                            size_t depth, lb__node ***out, size_t *k_out) {
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(j, key);
    const size_t old = push_key(c, key);
    lb_status s = LB_OK;
    char allowed[96];
    if (t->kmin == t->kmax)
        snprintf(allowed, sizeof allowed, "an array of exactly %zu node%s", t->kmin,
                 t->kmin == 1 ? "" : "s");
    else
        snprintf(allowed, sizeof allowed, "an array of %zu to %zu nodes", t->kmin, t->kmax);
    if (!a) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s", allowed);
    } else if (!cJSON_IsArray(a)) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "expected an array, found %s; allowed: %s",
                 json_kind(a), allowed);
    } else {
        const size_t k = (size_t)cJSON_GetArraySize(a);
        if (k < t->kmin || k > t->kmax) {
            s = perr(c, LB_ERR_INVALID_ARGUMENT, "%s \"%s\" has %zu argument%s; allowed: %s%s",
                     t->name, key, k, k == 1 ? "" : "s", allowed,
                     k > t->kmax && t->kmax == LB_MAX_ARITY
                         ? " (displacement, min, max, soft_sum and ricci take up to 65535; "
                           "or nest this node)"
                         : "");
        } else {
            lb__node **v = calloc(k, sizeof *v);
            if (!v) {
                s = oom(c);
            } else {
                size_t i = 0;
                for (const cJSON *e = a->child; e && !s; e = e->next, ++i) {
                    const size_t o2 = push_index(c, i);
                    s = parse_node(c, e, depth + 1, &v[i]);
                    pop(c, o2);
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
    pop(c, old);
    return s;
}

static lb_status parse_op(pctx *c, const cJSON *j, const type_info *t, lb_setop *op) {
    const char *str = NULL;
    const char *allowed = t->has_op == 2 ? "\"union\" or \"intersection\""
                                         : "\"union\", \"intersection\" or \"difference\"";
    lb_status s = get_string(c, j, "op", 1, allowed, &str);
    if (s) return s;
    if (strcmp(str, "union") == 0)
        *op = LB_UNION;
    else if (strcmp(str, "intersection") == 0)
        *op = LB_INTERSECTION;
    else if (strcmp(str, "difference") == 0 && t->has_op == 1)
        *op = LB_DIFFERENCE;
    else {
        const size_t old = push_key(c, "op");
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "unknown op \"%.40s\" for %s; allowed: %s", str,
                 t->name, allowed);
        pop(c, old);
    }
    return s;
}

/* local_union / clean_union parameters, with their defaults */
static lb_status parse_local(pctx *c, const cJSON *j, lb__node *n) {
    lb__local_params *L = &n->lp;
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
    if ((s = get_number(c, j, "zero_scale", 0, 1e-9, 1e9,
                        "1e-9 <= zero_scale <= 1e9 (scene units: g = 0.5 (1 - f / zero_scale))",
                        &L->zero_scale)))
        return s;
    if (n->family == LB__F_CLEAN) return LB_OK;
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
    if ((s = get_number(c, j, "radius", 0, 1e-9, 1e9, "1e-9 <= radius <= 1e9 (scene units)",
                        &L->radius)) ||
        (s = get_number(c, j, "support_factor", 0, 1e-3, 100.0, "1e-3 <= value <= 100",
                        &L->support)) ||
        (s = get_number(c, j, "exponent", 0, 1.0, 1000.0, "1 <= exponent <= 1000", &L->exponent)) ||
        (s = get_string(c, j, "support", 0, "\"progressive\" or \"feature\"", &mode)))
        return s;
    if (mode && strcmp(mode, "progressive") != 0) {
        if (strcmp(mode, "feature") != 0) {
            const size_t old = push_key(c, "support");
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "\"%.40s\"; allowed: \"progressive\" (R = support_factor x the curve's "
                     "diameter) or \"feature\" (R = 2 min(d1, d2))",
                     mode);
            pop(c, old);
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
    for (size_t i = 1; i + 1 < n->k; ++i) {
        lb__node *m = new_node(c, n->family, n->type);
        if (!m) return oom(c);
        /* the fold's inner node: named by the arguments it unites */
        const size_t pl = strlen(m->path) + 32;
        char *path = malloc(pl);
        if (!path) return oom(c);
        snprintf(path, pl, "%s (args 0-%zu)", m->path, i);
        free(m->path);
        m->path = path;
        m->lp = n->lp;
        m->k = 2;
        m->args = malloc(2 * sizeof *m->args);
        if (!m->args) return oom(c);
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
    n->args[1] = n->args[n->k - 1];
    n->k = 2;
    return LB_OK;
}

static lb_status parse_bulge(pctx *c, const cJSON *j, lb__node *n) {
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bulge");
    if (!b) return LB_OK;
    static const char *const keys[] = {"range", "slope", "omega", NULL};
    const size_t old = push_key(c, "bulge");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(b)) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "expected an object, found %s; allowed: {\"range\": true, \"slope\": false, "
                 "\"omega\": 0.001}",
                 json_kind(b));
    } else if (n->k != 2) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "bulge elimination needs exactly 2 arguments, this node has %zu; allowed: "
                 "bulge on binary blends only",
                 n->k);
    } else if (!(s = check_keys(c, b, keys, "bulge"))) {
        unsigned flags = LB_BULGE_RANGE;
        const char *names[2] = {"range", "slope"};
        for (int i = 0; i < 2 && !s; ++i) {
            const cJSON *f = cJSON_GetObjectItemCaseSensitive(b, names[i]);
            if (!f) continue;
            const size_t o2 = push_key(c, names[i]);
            if (!cJSON_IsBool(f))
                s = perr(c, LB_ERR_INVALID_ARGUMENT, "expected true or false, found %s",
                         json_kind(f));
            else if (cJSON_IsTrue(f))
                flags |= i == 0 ? LB_BULGE_RANGE : LB_BULGE_SLOPE;
            else
                flags &= ~(i == 0 ? LB_BULGE_RANGE : LB_BULGE_SLOPE);
            pop(c, o2);
        }
        double omega = 0.001;
        if (!s)
            s = get_number(c, b, "omega", 0, 1e-12, 1.0, "0 < omega <= 1 (0.001 in the papers)",
                           &omega);
        if (!s && flags == 0)
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "both range and slope are false; allowed: at least one true, or leave out "
                     "\"bulge\"");
        if (!s && (flags & LB_BULGE_SLOPE) && n->family == LB__F_SCALE)
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "\"slope\" needs m, which the scale family does not have; allowed: "
                     "{\"range\": true}");
        if (!s) {
            n->bulge = 1;
            n->bp.flags = flags;
            n->bp.omega = omega;
            for (int i = 0; i < 2; ++i) {
                n->bp.r[i] = n->r ? n->r[i] : 1.0;
                n->bp.p[i] = n->p ? n->p[i] : 2.0;
                n->bp.m[i] = n->m ? n->m[i] : 1.0;
            }
            n->bp.conic_p = n->shape;
        }
    }
    pop(c, old);
    return s;
}

/* Bounding solid check where it is cheap [spec 6]: an untransformed
 * sphere/ellipsoid argument and bounding solid with the same centre. */
static lb_status check_bound_contains(pctx *c, const lb__node *n, size_t i) {
    const lb__node *a = n->args[i], *b = n->bounds[i];
    if (a->family != LB__F_PRIMITIVE || b->family != LB__F_PRIMITIVE || a->has_transform ||
        b->has_transform || a->prim.kind != LB_PRIM_ELLIPSOID || b->prim.kind != LB_PRIM_ELLIPSOID)
        return LB_OK;
    if (memcmp(a->prim.c, b->prim.c, sizeof a->prim.c) != 0) return LB_OK;
    const int union_like = n->op == LB_UNION || (n->op == LB_DIFFERENCE && i > 0);
    for (int d = 0; d < 3; ++d) {
        const int bad = union_like ? b->prim.a[d] < a->prim.a[d] : b->prim.a[d] > a->prim.a[d];
        if (bad) {
            const size_t o1 = push_key(c, "bounds"), o2 = push_index(c, i);
            lb_status s =
                perr(c, LB_ERR_INVALID_ARGUMENT,
                     "the bounding solid (semi-axis %g) does not %s argument %zu (semi-axis %g); "
                     "allowed: a bounding solid that %s its argument",
                     b->prim.a[d], union_like ? "contain" : "lie inside", i, a->prim.a[d],
                     union_like ? "contains" : "lies inside");
            pop(c, o2);
            pop(c, o1);
            return s;
        }
    }
    return LB_OK;
}

/* the conic's shape "p" of n (default 0, the quarter ellipse): below r1 r2,
 * n->r already read (conic and soft_conic) */
static lb_status get_conic_shape(pctx *c, const cJSON *j, lb__node *n) {
    char ok[96];
    snprintf(ok, sizeof ok, "a number below r1 r2 = %.17g (0 = quarter ellipse)",
             n->r[0] * n->r[1]);
    n->shape = 0.0;
    lb_status s = get_number(c, j, "p", 0, -1e18, 1e18, ok, &n->shape);
    if (!s && !(n->shape < n->r[0] * n->r[1])) {
        const size_t old = push_key(c, "p");
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "p = %.17g is not below r1 r2; allowed: %s", n->shape,
                 ok);
        pop(c, old);
    }
    return s;
}

static lb_status parse_node(pctx *c, const cJSON *j, size_t depth, lb__node **out) {
    lb_status s;
    if (!cJSON_IsObject(j))
        return perr(c, LB_ERR_INVALID_ARGUMENT,
                    "expected a node object, found %s; allowed: {\"type\": ...} or {\"ref\": ...}",
                    json_kind(j));
    if (depth > LB_SCENE_MAX_DEPTH)
        return perr(c, LB_ERR_INVALID_ARGUMENT,
                    "nodes nested deeper than %d levels; allowed: at most %d levels (use defs "
                    "and refs to share subtrees)",
                    LB_SCENE_MAX_DEPTH, LB_SCENE_MAX_DEPTH);
    if (++c->count > LB_SCENE_MAX_NODES)
        return perr(c, LB_ERR_INVALID_ARGUMENT, "more than %d nodes; allowed: at most %d nodes",
                    LB_SCENE_MAX_NODES, LB_SCENE_MAX_NODES);
    if (cJSON_GetObjectItemCaseSensitive(j, "ref")) return parse_ref(c, j, depth, out);
    const char *type = NULL;
    if ((s = get_string(c, j, "type", 1, TYPE_LIST, &type))) return s;
    const type_info *t = NULL;
    for (size_t i = 0; i < NTYPES && !t; ++i)
        if (strcmp(TYPES[i].name, type) == 0) t = &TYPES[i];
    if (!t) {
        const size_t old = push_key(c, "type");
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "unknown node type \"%.60s\"; allowed: %s", type,
                 TYPE_LIST);
        pop(c, old);
        return s;
    }
    char what[64];
    snprintf(what, sizeof what, "a %s node", t->name);
    if ((s = check_keys(c, j, t->keys, what))) return s;
    const int conv_bit = c->s->convention == LB_CONVENTION_ZERO ? CONV_ZERO : CONV_SOFT;
    if (!(t->conv & conv_bit)) {
        const size_t old = push_key(c, "type");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "%s is a %s-convention operator but the scene's convention is \"%s\"; allowed: "
                 "%s",
                 t->name, t->conv == CONV_ZERO ? "zero" : "soft",
                 conv_bit == CONV_ZERO ? "zero" : "soft",
                 conv_bit == CONV_ZERO ? "displacement, conic, scale, bounded, rfunction, min, "
                                         "max, complement, local_union, clean_union, level"
                                       : "soft_hyper, soft_conic, soft_sum, ricci, perlin, min, "
                                         "max, complement, local_union, clean_union, level");
        pop(c, old);
        return s;
    }
    lb__node *n = new_node(c, t->family, t->name);
    if (!n) return oom(c);
    if ((s = get_transform(c, j, n)) || (s = node_material(c, j, n))) return s;
    if (t->family == LB__F_PRIMITIVE) {
        if ((s = parse_primitive(c, j, t, n))) return s;
        *out = n;
        return LB_OK;
    }
    if (t->has_op && (s = parse_op(c, j, t, &n->op))) return s;
    if ((s = parse_args(c, j, "args", t, depth, &n->args, &n->k))) return s;
    const size_t k = n->k;
    const char *r_ok = "1e-9 <= r <= 1e9";
    const char *p_ok = "1 < p <= 1000";
    const char *m_ok = "1e-6 <= m <= 1e6";
    switch (t->family) {
    case LB__F_DISPLACEMENT:
        if ((s = get_param(c, j, "r", k, 1, 0, 0, 1e-9, 1e9, r_ok, &n->r)) ||
            (s = get_param(c, j, "p", k, 0, 1, 2.0, 1.0 + 1e-12, 1000.0, p_ok, &n->p)) ||
            (s = get_param(c, j, "m", k, 0, 1, 1.0, 1e-6, 1e6, m_ok, &n->m)) ||
            (s = parse_bulge(c, j, n)))
            return s;
        break;
    case LB__F_CONIC: {
        if ((s = get_param(c, j, "r", k, 1, 0, 0, 1e-9, 1e9, r_ok, &n->r)) ||
            (s = get_param(c, j, "m", k, 0, 1, 1.0, 1e-6, 1e6, m_ok, &n->m)))
            return s;
        if ((s = get_conic_shape(c, j, n)) || (s = parse_bulge(c, j, n))) return s;
        break;
    }
    case LB__F_SCALE: {
        const double rmax = n->op == LB_UNION ? 1e9 : 1.0;
        if ((s = get_param(c, j, "r", k, 1, 0, 0, 1e-9, rmax,
                           n->op == LB_UNION ? r_ok : "1e-9 <= r <= 1 (intersection, difference)",
                           &n->r)) ||
            (s = get_param(c, j, "p", k, 0, 1, 2.0, 1.0 + 1e-12, 1000.0, p_ok, &n->p)) ||
            (s = parse_bulge(c, j, n)))
            return s;
        break;
    }
    case LB__F_BOUNDED: {
        if ((s = get_param(c, j, "p", k, 0, 1, 2.0, 1.0 + 1e-12, 1000.0, p_ok, &n->p))) return s;
        const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bounds");
        if (!b) {
            const size_t old = push_key(c, "bounds");
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "missing required field; allowed: an array of %zu bounding solids, one per "
                     "argument",
                     k);
            pop(c, old);
            return s;
        }
        if (cJSON_IsArray(b) && (size_t)cJSON_GetArraySize(b) != k) {
            const size_t old = push_key(c, "bounds");
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "has %d bounding solids for %zu arguments; allowed: exactly one per argument",
                     cJSON_GetArraySize(b), k);
            pop(c, old);
            return s;
        }
        size_t kb = 0;
        type_info tb = *t;
        tb.kmin = tb.kmax = k;
        if ((s = parse_args(c, j, "bounds", &tb, depth, &n->bounds, &kb))) return s;
        for (size_t i = 0; i < k; ++i)
            if ((s = check_bound_contains(c, n, i))) return s;
        break;
    }
    case LB__F_SOFT_HYPER:
    case LB__F_SOFT_CONIC: {
        const double rmax = n->op == LB_UNION ? 1.0 : 1e9;
        if ((s = get_param(c, j, "r", k, 1, 0, 0, 1e-9, rmax,
                           n->op == LB_UNION ? "1e-9 <= r <= 1 (soft union)" : r_ok, &n->r)) ||
            (s = get_param(c, j, "m", k, 0, 1, 1.0, LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE,
                           "0.05 <= m <= 20 (soft)", &n->m)))
            return s;
        if (t->family == LB__F_SOFT_HYPER) {
            if ((s = get_param(c, j, "p", k, 0, 1, 2.0, 1.0 + 1e-12, 1000.0, p_ok, &n->p)))
                return s;
        } else if ((s = get_conic_shape(c, j, n))) {
            return s;
        }
        break;
    }
    case LB__F_LOCAL:
    case LB__F_CLEAN:
        if ((s = parse_local(c, j, n))) return s;
        if (k > 2 && (s = fold_local(c, n))) return s;
        break;
    case LB__F_RICCI:
        n->shape = 2.0;
        if ((s = get_number(c, j, "n", 1, 1.0, 1000.0, "1 <= n <= 1000", &n->shape))) return s;
        break;
    case LB__F_LEVEL:
        /* zero: any level (an offset surface); soft: inside the field's [0, 1] */
        if (c->s->convention == LB_CONVENTION_ZERO)
            s = get_number(c, j, "level", 1, -1e9, 1e9, "|level| <= 1e9", &n->shape);
        else
            s = get_number(c, j, "level", 1, 1e-6, 1.0 - 1e-6,
                           "0 < level < 1 (soft fields lie "
                           "in [0, 1])",
                           &n->shape);
        if (s) return s;
        break;
    default:
        break;
    }
    for (size_t i = 0; i < k; ++i) {
        const lb__node *a = n->args[i];
        n->mat_below |= a->mat || a->mat_below;
        if (n->bounds && (n->bounds[i]->mat || n->bounds[i]->mat_below)) {
            const size_t o1 = push_key(c, "bounds"), o2 = push_index(c, i);
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "a bounding solid has a material, but it is never on the surface; "
                     "allowed: materials on args (remove it here)");
            pop(c, o2);
            pop(c, o1);
            return s;
        }
        if (a->depth + 1 > n->depth) n->depth = a->depth + 1;
        if (a->bulge_depth > n->bulge_depth) n->bulge_depth = a->bulge_depth;
        if (n->bounds && n->bounds[i]->depth + 1 > n->depth) n->depth = n->bounds[i]->depth + 1;
        if (n->bounds && n->bounds[i]->bulge_depth > n->bulge_depth)
            n->bulge_depth = n->bounds[i]->bulge_depth;
        /* the reference walk visits a shared node once per use, and a
         * bulge-eliminated blend walks each argument twice more */
        n->walk_cost += (n->bulge ? 3.0 : 1.0) * a->walk_cost;
        if (n->bounds) n->walk_cost += n->bounds[i]->walk_cost;
    }
    if (n->bulge && ++n->bulge_depth > LB_SCENE_MAX_BULGE_NESTING) {
        const size_t old = push_key(c, "bulge");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "bulge elimination nested %zu deep (each level evaluates its arguments 4 more "
                 "times); allowed: at most %d bulge-eliminated blends on any path",
                 n->bulge_depth, LB_SCENE_MAX_BULGE_NESTING);
        pop(c, old);
        return s;
    }
    /* backstop: the operator itself accepts the parameters at a neutral point */
    {
        double *x = malloc(2 * k * sizeof *x), g[6] = {1, 0, 0, 0, 1, 0}, v = 0.0;
        if (!x) return oom(c);
        double *cb = x + k;
        for (size_t i = 0; i < k; ++i) {
            x[i] = c->s->convention == LB_CONVENTION_ZERO ? 0.0 : 0.5;
            cb[i] = 0.5;
        }
        lb_error e = {LB_OK, ""};
        const lb_status as =
            lb__node_apply(n, c->s->convention, x, cb, g, &v, NULL, NULL, NULL, &e);
        free(x);
        if (as) return perr(c, LB_ERR_INVALID_ARGUMENT, "%s", e.message);
    }
    *out = n;
    return LB_OK;
}

/* ---- top level ---- */

static lb_status parse_bounds(pctx *c, const cJSON *root) {
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(root, "bounds");
    if (!b) return LB_OK;
    static const char *const keys[] = {"min", "max", NULL};
    const size_t old = push_key(c, "bounds");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(b))
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "expected an object, found %s; allowed: {\"min\": [x, y, z], \"max\": [x, y, z]}",
                 json_kind(b));
    else if (!(s = check_keys(c, b, keys, "bounds")) &&
             !(s = get_vec3(c, b, "min", 1, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                            "|value| <= 1e9", c->s->bmin)) &&
             !(s = get_vec3(c, b, "max", 1, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                            "|value| <= 1e9", c->s->bmax))) {
        for (int i = 0; i < 3 && !s; ++i)
            if (!(c->s->bmin[i] < c->s->bmax[i]))
                s = perr(c, LB_ERR_INVALID_ARGUMENT,
                         "min[%d] = %g is not below max[%d] = %g; allowed: min < max on every "
                         "axis",
                         i, c->s->bmin[i], i, c->s->bmax[i]);
        c->s->has_bounds = !s;
    }
    pop(c, old);
    return s;
}

static lb_status parse_render(pctx *c, const cJSON *root) {
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
    static const char *const cam_keys[] = {"location", "look_at", "up", "angle", NULL};
    static const char *const floor_keys[] = {"color", NULL};
    static const char *const light_keys[] = {"location", "color", NULL};
    const double CM = LB_SCENE_MAX_COORD;
    const size_t old = push_key(c, "render");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(r)) {
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "expected an object, found %s; allowed: {\"camera\": ..., \"lights\": [...], "
                 "\"material\": ...}",
                 json_kind(r));
        goto done;
    }
    if ((s = check_keys(c, r, keys, "render"))) goto done;
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(r, "camera");
    if (cam) {
        const size_t o = push_key(c, "camera");
        if (!cJSON_IsObject(cam))
            s = perr(c, LB_ERR_INVALID_ARGUMENT, "expected an object, found %s", json_kind(cam));
        else if (!(s = check_keys(c, cam, cam_keys, "camera")) &&
                 !(s = get_vec3(c, cam, "location", 1, -CM, CM, "|value| <= 1e9", R->location)) &&
                 !(s = get_vec3(c, cam, "look_at", 0, -CM, CM, "|value| <= 1e9", R->look_at)) &&
                 !(s = get_vec3(c, cam, "up", 0, -CM, CM, "|value| <= 1e9", R->up)) &&
                 !(s = get_number(c, cam, "angle", 0, 1e-3, 179.0, "0 < angle < 180 (degrees)",
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
                s = perr(c, LB_ERR_INVALID_ARGUMENT,
                         "location equals look_at; allowed: a camera looking somewhere");
            else if (!(ul > 0.0) || !(sl > 1e-6 * dl * ul))
                s = perr(c, LB_ERR_INVALID_ARGUMENT,
                         "up [%g, %g, %g] is %s; allowed: a direction not along the line of sight "
                         "(default [0, 0, 1])",
                         u[0], u[1], u[2], ul > 0.0 ? "along the line of sight" : "zero");
            else
                for (int d2 = 0; d2 < 3; ++d2) R->up[d2] /= ul;
            R->has_camera = !s;
        }
        pop(c, o);
        if (s) goto done;
    }
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(r, "lights");
    if (lights) {
        const size_t o = push_key(c, "lights");
        if (!cJSON_IsArray(lights) || cJSON_GetArraySize(lights) > LB_SCENE_MAX_LIGHTS) {
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected an array of at most %d lights, found %s; allowed: [{\"location\": "
                     "[x, y, z], \"color\": [r, g, b]}, ...]",
                     LB_SCENE_MAX_LIGHTS, json_kind(lights));
        } else {
            size_t i = 0;
            for (const cJSON *l = lights->child; l && !s; l = l->next, ++i) {
                const size_t o2 = push_index(c, i);
                lb_render_light *L = &R->lights[i];
                L->color[0] = L->color[1] = L->color[2] = 1.0;
                if (!cJSON_IsObject(l))
                    s = perr(c, LB_ERR_INVALID_ARGUMENT, "expected an object, found %s",
                             json_kind(l));
                else if (!(s = check_keys(c, l, light_keys, "a light")) &&
                         !(s = get_vec3(c, l, "location", 1, -CM, CM, "|value| <= 1e9",
                                        L->location)))
                    s = get_vec3(c, l, "color", 0, 0.0, 100.0, "0 <= value <= 100", L->color);
                pop(c, o2);
            }
            if (!s) R->light_count = i;
        }
        pop(c, o);
        if (s) goto done;
    }
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(r, "material");
    if (mat) {
        lb_material m = {
            {R->color[0], R->color[1], R->color[2]}, R->ambient, R->diffuse, R->specular};
        const size_t o = push_key(c, "material");
        s = material_fields(c, mat, &m);
        pop(c, o);
        if (s) goto done;
        memcpy(R->color, m.color, sizeof m.color);
        R->ambient = m.ambient;
        R->diffuse = m.diffuse;
        R->specular = m.specular;
    }
    const cJSON *fl = cJSON_GetObjectItemCaseSensitive(r, "floor");
    if (fl) {
        const size_t o = push_key(c, "floor");
        if (cJSON_IsBool(fl))
            R->floor = cJSON_IsTrue(fl);
        else if (!cJSON_IsObject(fl))
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected true, false or {\"color\": [r, g, b]}, found %s", json_kind(fl));
        else if (!(s = check_keys(c, fl, floor_keys, "floor")))
            s = get_vec3(c, fl, "color", 0, 0.0, 1.0, "0 <= value <= 1", R->floor_color);
        pop(c, o);
        if (s) goto done;
    }
    s = get_vec3(c, r, "background", 0, 0.0, 1.0, "0 <= value <= 1", R->background);
done:
    pop(c, old);
    return s;
}

static lb_status parse_document(pctx *c, const cJSON *root) {
    static const char *const keys[] = {"format", "version", "convention", "title",  "description",
                                       "bounds", "defs",    "root",       "render", NULL};
    lb_status s;
    if (!cJSON_IsObject(root))
        return perr(c, LB_ERR_INVALID_ARGUMENT,
                    "expected a JSON object at the top, found %s; allowed: {\"format\": "
                    "\"libblend-scene\", \"version\": 1, ...}",
                    json_kind(root));
    const char *fmt = NULL, *conv = NULL, *str = NULL;
    if ((s = get_string(c, root, "format", 1, "\"libblend-scene\"", &fmt))) return s;
    if (strcmp(fmt, "libblend-scene") != 0) {
        const size_t old = push_key(c, "format");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "\"%.40s\" is not a libblend scene; allowed: \"libblend-scene\"", fmt);
        pop(c, old);
        return s;
    }
    double version = 0;
    if ((s = get_number(c, root, "version", 1, -1e9, 1e9, "1", &version))) return s;
    if (version != 1.0) {
        const size_t old = push_key(c, "version");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "version %g is not supported by libblend %d.%d; allowed: 1", version,
                 LB_VERSION_MAJOR, LB_VERSION_MINOR);
        pop(c, old);
        return s;
    }
    if ((s = check_keys(c, root, keys, "a scene")) ||
        (s = get_string(c, root, "title", 0, "a string", &str)) ||
        (s = get_string(c, root, "description", 0, "a string", &str)) ||
        (s = get_string(c, root, "convention", 1, "\"zero\" or \"soft\"", &conv)))
        return s;
    if (strcmp(conv, "zero") == 0)
        c->s->convention = LB_CONVENTION_ZERO;
    else if (strcmp(conv, "soft") == 0)
        c->s->convention = LB_CONVENTION_SOFT;
    else {
        const size_t old = push_key(c, "convention");
        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                 "unknown convention \"%.40s\"; allowed: \"zero\" (inside f < 0) or \"soft\" "
                 "(inside f > 0.5)",
                 conv);
        pop(c, old);
        return s;
    }
    if ((s = parse_bounds(c, root)) || (s = parse_render(c, root))) return s;
    const cJSON *defs = cJSON_GetObjectItemCaseSensitive(root, "defs");
    if (defs) {
        const size_t old = push_key(c, "defs");
        if (!cJSON_IsObject(defs)) {
            s = perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected an object of named nodes, found %s; allowed: {\"name\": node, ...}",
                     json_kind(defs));
        } else {
            const size_t nd = (size_t)cJSON_GetArraySize(defs);
            c->defs = calloc(nd ? nd : 1, sizeof *c->defs);
            if (!c->defs) s = oom(c);
            for (const cJSON *d = defs->child; d && !s; d = d->next) {
                /* a def's name goes into node paths, messages, `info` and
                 * POV-Ray comments: one line of text, nothing to escape */
                for (const unsigned char *q = (const unsigned char *)d->string; *q && !s; ++q)
                    if (*q < 0x20 || *q == 0x7f)
                        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                                 "def \"%.60s\" has a control character; allowed: names "
                                 "without control characters (no newline, tab, ...)",
                                 d->string);
                if (!*d->string)
                    s = perr(c, LB_ERR_INVALID_ARGUMENT,
                             "a def with an empty name; allowed: a non-empty name");
                for (size_t i = 0; i < c->ndefs; ++i)
                    if (strcmp(c->defs[i].name, d->string) == 0)
                        s = perr(c, LB_ERR_INVALID_ARGUMENT,
                                 "def \"%.60s\" appears twice; allowed: unique names", d->string);
                c->defs[c->ndefs].name = d->string;
                c->defs[c->ndefs].json = (cJSON *)d;
                c->ndefs++;
            }
        }
        pop(c, old);
        if (s) return s;
    }
    const cJSON *rootnode = cJSON_GetObjectItemCaseSensitive(root, "root");
    const size_t old = push_key(c, "root");
    if (!rootnode)
        s = perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: a node object");
    else
        s = parse_node(c, rootnode, 1, &c->s->root);
    pop(c, old);
    if (s) return s;
    /* unused defs are still validated: a typo there should not wait */
    for (size_t i = 0; i < c->ndefs && !s; ++i) {
        lb__node *n = NULL;
        s = build_def(c, &c->defs[i], 1, &n);
    }
    return s;
}

static void line_col(const char *text, size_t len, size_t off, size_t *line, size_t *col) {
    *line = 1;
    *col = 1;
    for (size_t i = 0; i < off && i < len; ++i) {
        if (text[i] == '\n') {
            ++*line;
            *col = 1;
        } else {
            ++*col;
        }
    }
}

/* RFC 8259 exactly, after cJSON (whose messages the bad-scene tables pin)
 * accepted the text: cJSON also takes leading zeros (01), a bare fraction
 * point (1.), raw control characters in strings, text after a NUL byte and
 * \u0000 (cutting the string there). Debian's libjansson is strict about all
 * of them and names the line and column (duplicate keys are the
 * validation's: it names the JSON path). */
static lb_status strict_json(const char *text, size_t length, const char *file, lb_error *err) {
    json_error_t je;
    json_t *j = json_loadb(text, length, 0, &je);
    if (j) {
        json_decref(j);
        return LB_OK;
    }
    /* 1e999 is valid RFC 8259 syntax: the validation names it as not finite */
    if (json_error_code(&je) == json_error_numeric_overflow) return LB_OK;
    size_t line = 1, col = 1;
    if (je.position >= 0 && je.line >= 0) {
        size_t off = (size_t)je.position;
        if (off > length) off = length;
        /* jansson's position is just past the offending character */
        line_col(text, length, off ? off - 1 : 0, &line, &col);
    }
    return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                    "%s:%zu:%zu: invalid JSON: %s; allowed: a JSON document (RFC 8259: no "
                    "leading zeros, digits after a decimal point, control characters in strings "
                    "escaped, no \\u0000, nothing after the document)",
                    file, line, col, je.text);
}

lb_status lb_scene_parse(const char *text, size_t length, const char *name, lb_scene **out,
                         lb_error *err) {
    const char *file = name ? name : "<scene>";
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_parse: out is NULL");
    *out = NULL;
    if (!text) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_parse: text is NULL");
    if (length > LB_SCENE_MAX_BYTES)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the scene is %zu bytes; allowed: at most %u bytes", file, length,
                        LB_SCENE_MAX_BYTES);
    /* Pre-scan, outside strings, allocating nothing: the nesting, and the
     * number of objects, arrays and values (commas), each capped at what a
     * scene of LB_SCENE_MAX_NODES nodes can hold (scene.h), so a file that
     * cannot be a scene (63 MB of []) is refused before any parser builds a
     * tree of it. */
    {
        size_t depth = 0, line = 1, col = 1, nobj = 0, narr = 0, nval = 0;
        int in_str = 0, esc = 0;
        for (size_t i = 0; i < length; ++i) {
            const char ch = text[i];
            if (ch == '\n') {
                ++line;
                col = 0;
            }
            ++col;
            if (in_str) {
                if (esc)
                    esc = 0;
                else if (ch == '\\')
                    esc = 1;
                else if (ch == '"')
                    in_str = 0;
                continue;
            }
            const char *over = NULL;
            size_t cap = 0;
            if (ch == '{' && ++nobj > LB_SCENE_MAX_JSON_OBJECTS)
                over = "objects", cap = LB_SCENE_MAX_JSON_OBJECTS;
            else if (ch == '[' && ++narr > LB_SCENE_MAX_JSON_ARRAYS)
                over = "arrays", cap = LB_SCENE_MAX_JSON_ARRAYS;
            else if ((ch == ',' || ch == '[' || ch == '{') && ++nval > LB_SCENE_MAX_JSON_VALUES)
                over = "values", cap = LB_SCENE_MAX_JSON_VALUES;
            if (over)
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s:%zu:%zu: more than %zu JSON %s; allowed: what a scene of at "
                                "most %d nodes holds (at most %d objects, %d arrays, %d values)",
                                file, line, col - 1, cap, over, LB_SCENE_MAX_NODES,
                                LB_SCENE_MAX_JSON_OBJECTS, LB_SCENE_MAX_JSON_ARRAYS,
                                LB_SCENE_MAX_JSON_VALUES);
            if (ch == '"')
                in_str = 1;
            else if (ch == '[' || ch == '{') {
                if (++depth > JSON_MAX_NESTING)
                    return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                    "%s:%zu:%zu: JSON nested deeper than %d levels; allowed: "
                                    "at most %d levels of nodes (use defs and refs to share "
                                    "subtrees)",
                                    file, line, col - 1, JSON_MAX_NESTING, LB_SCENE_MAX_DEPTH);
            } else if ((ch == ']' || ch == '}') && depth)
                --depth;
        }
    }
    /* the strict check first, alone: its tree is freed before cJSON builds
     * one, so the peak is one parser's tree, not both; its message is given
     * only when cJSON accepted the text (cJSON's messages come first) */
    const lb_status strict = strict_json(text, length, file, err);
    const char *end = NULL;
    cJSON *doc = cJSON_ParseWithLengthOpts(text, length, &end, 0);
    if (!doc) {
        size_t off = end && end >= text ? (size_t)(end - text) : 0;
        if (off > length) off = length;
        while (off < length &&
               (text[off] == ' ' || text[off] == '\t' || text[off] == '\r' || text[off] == '\n'))
            ++off;
        size_t line, col;
        line_col(text, length, off, &line, &col);
        char near[24] = "";
        size_t nl = 0;
        for (size_t i = off; i < length && nl < 16 && text[i] != '\n'; ++i)
            near[nl++] = (text[i] >= 32 && text[i] < 127) ? text[i] : '?';
        near[nl] = '\0';
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s:%zu:%zu: invalid JSON%s%s%s; allowed: a JSON document (RFC 8259: no "
                        "comments, no trailing commas, no NaN or Infinity)",
                        file, line, col, nl ? " near \"" : " at the end of the input",
                        nl ? near : "", nl ? "\"" : "");
    }
    /* trailing content after the document */
    if (end) {
        size_t off = (size_t)(end - text);
        while (off < length &&
               (text[off] == ' ' || text[off] == '\n' || text[off] == '\r' || text[off] == '\t'))
            ++off;
        if (off < length && text[off] != '\0') {
            size_t line, col;
            line_col(text, length, off, &line, &col);
            cJSON_Delete(doc);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s:%zu:%zu: text after the end of the JSON document; allowed: one "
                            "JSON object",
                            file, line, col);
        }
    }
    if (strict) {
        cJSON_Delete(doc);
        return strict; /* err still holds its message: nothing since has written to it */
    }
    lb_scene *s = calloc(1, sizeof *s);
    if (!s) {
        cJSON_Delete(doc);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", file);
    }
    s->name = malloc(strlen(file) + 1);
    if (s->name) strcpy(s->name, file);
    pctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.file = file;
    c.err = err;
    strcpy(c.path, "$");
    c.plen = 1;
    lb_status st = s->name ? parse_document(&c, doc) : oom(&c);
    free(c.defs);
    cJSON_Delete(doc);
    if (st) {
        lb_scene_free(s);
        return st;
    }
    *out = s;
    return LB_OK;
}

lb_status lb_scene_load(const char *path, lb_scene **out, lb_error *err) {
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_load: out is NULL");
    *out = NULL;
    if (!path) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_load: path is NULL");
    FILE *f = lb__fopen(path, "rb");
    if (!f && lb__is_directory(path)) /* Windows opens no folder */
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: is a directory; allowed: a scene file",
                        path);
    if (!f)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: cannot open the scene file (%s); allowed: a readable file", path,
                        strerror(errno));
    struct stat sb;
    if (lb__fstat(fileno(f), &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) {
            fclose(f);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: is a directory; allowed: a scene file", path);
        }
        if (S_ISREG(sb.st_mode) && (unsigned long long)sb.st_size > LB_SCENE_MAX_BYTES) {
            fclose(f);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: the scene file is %lld bytes; allowed: at most %u bytes", path,
                            (long long)sb.st_size, LB_SCENE_MAX_BYTES);
        }
    }
    char *buf = NULL;
    size_t len = 0, cap = 0;
    lb_status st = LB_OK;
    for (;;) {
        if (len == cap) {
            if (len > LB_SCENE_MAX_BYTES) {
                st = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                              "%s: the scene file is larger than %u bytes (or endless: a device "
                              "or FIFO is read to its end); allowed: at most %u bytes",
                              path, LB_SCENE_MAX_BYTES, LB_SCENE_MAX_BYTES);
                break;
            }
            cap = cap ? 2 * cap : 65536;
            if (cap > (size_t)LB_SCENE_MAX_BYTES + 1) cap = (size_t)LB_SCENE_MAX_BYTES + 1;
            char *nb = realloc(buf, cap + 1);
            if (!nb) {
                st = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory reading the file", path);
                break;
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f))
                st =
                    lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                             "%s: read error (is it a directory?); allowed: a readable file", path);
            break;
        }
    }
    fclose(f);
    if (!st) st = lb_scene_parse(buf ? buf : "", len, path, out, err);
    free(buf);
    return st;
}
