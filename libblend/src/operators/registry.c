/* The family registry's rows (families.def) with their key lists and
 * parameter tables, and the lookups. Every range is a named constant of
 * the public headers. */
#include "family_fns.h"
#include "libblend/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the keys of each kind of node (LB__TRANSFORM_KEYS besides) ---- */

static const char *const K_SPHERE[] = {"type", "center", "radius", NULL};
static const char *const K_ELLIPSOID[] = {"type", "center", "semi_axes", NULL};
static const char *const K_LP[] = {"type", "center", "semi_axes", "exponent", NULL};
static const char *const K_SUPERQUADRIC[] = {"type", "center", "semi_axes", "e1", "e2", NULL};
static const char *const K_SLAB[] = {"type", "point", "normal", "half_width", NULL};
static const char *const K_HALFSPACE[] = {"type", "point", "normal", "width", NULL};
static const char *const K_CYLINDER[] = {"type", "point", "axis", "radius", NULL};
static const char *const K_CAPSULE[] = {"type", "start", "end", "radius", NULL};
static const char *const K_TORUS[] = {"type",         "center",       "axis",
                                      "major_radius", "minor_radius", NULL};
/* what every primitive takes in a soft scene only */
const char *const lb__primitive_soft_keys[] = {"kernel", NULL};
static const char *const K_BT[] = {"type", "op", "args", "r", "p", "m", "bulge", NULL};
static const char *const K_SCALE[] = {"type", "op", "args", "r", "p", "bulge", NULL};
static const char *const K_BOUNDED[] = {"type", "op", "args", "bounds", "p", NULL};
static const char *const K_SOFT[] = {"type", "op", "args", "r", "p", "m", NULL};
static const char *const K_ARGS[] = {"type", "args", NULL};
static const char *const K_OPARGS[] = {"type", "op", "args", NULL};
static const char *const K_RICCI[] = {"type", "args", "n", NULL};
static const char *const K_LEVEL[] = {"type", "args", "level", NULL};
static const char *const K_LOCAL[] = {
    "type",           "args",     "feature_size", "limits",     "radius", "support",
    "support_factor", "exponent", "alpha",        "zero_scale", NULL};
static const char *const K_CLEAN[] = {"type", "args", "alpha", "zero_scale", NULL};

/* ---- per-argument parameters ---- */

#define OPS_ID ((1u << LB_INTERSECTION) | (1u << LB_DIFFERENCE))
#define PR(hi_alt, ops, note_alt)                                                                  \
    {                                                                                              \
        "r", 1, 0.0, LB_MIN_RANGE, LB_MAX_RANGE, 0, hi_alt, ops, "", note_alt,                     \
            "blend range: how far from the surfaces the blend reaches"                             \
    }
#define PP                                                                                         \
    {                                                                                              \
        "p", 0, 2.0, 1.0, LB_MAX_EXPONENT, 1, 0.0, 0u, "", "",                                     \
            "curvature exponent (2: circular, larger: sharper)"                                    \
    }
#define PM                                                                                         \
    { "m", 0, 1.0, LB_MIN_SLOPE, LB_MAX_SLOPE, 0, 0.0, 0u, "", "", "slope at the surface" }
#define PM_SOFT                                                                                    \
    {                                                                                              \
        "m", 0, 1.0, LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE, 0, 0.0, 0u, "(soft)", "",               \
            "slope at the surface"                                                                 \
    }
#define PEND                                                                                       \
    { NULL, 0, 0.0, 0.0, 0.0, 0, 0.0, 0u, NULL, NULL, NULL }

static const lb__param P_DISPLACEMENT[] = {PR(0.0, 0u, ""), PP, PM, PEND};
static const lb__param P_CONIC[] = {PR(0.0, 0u, ""), PM, PEND};
/* scale: r <= 1 for intersection and difference (B_I, B_D need r < 1 + f) */
static const lb__param P_SCALE[] = {PR(1.0, OPS_ID, "(intersection, difference)"), PP, PEND};
static const lb__param P_BOUNDED[] = {PP, PEND};
/* soft union: r <= 1 (the field's range is [0, 1]) */
static const lb__param P_SOFT_HYPER[] = {PR(1.0, 1u << LB_UNION, "(soft union)"), PM_SOFT, PP,
                                         PEND};
static const lb__param P_SOFT_CONIC[] = {PR(1.0, 1u << LB_UNION, "(soft union)"), PM_SOFT, PEND};
static const lb__param P_NONE[] = {PEND};

/* ---- scalar parameters ---- */

static const lb__shape S_CONIC = {"p",
                                  0,
                                  0.0,
                                  {-1e18, -1e18},
                                  {1e18, 1e18},
                                  {NULL, NULL},
                                  1,
                                  "conic shape: below r1 r2 (0: the quarter ellipse)"};
static const lb__shape S_RICCI = {"n",
                                  1,
                                  2.0,
                                  {1.0, 1.0},
                                  {LB_MAX_EXPONENT, LB_MAX_EXPONENT},
                                  {NULL, NULL},
                                  0,
                                  "Ricci's exponent (1: the sum, large: max)"};
static const lb__shape S_LEVEL = {
    "level",
    1,
    0.0,
    {-LB_SCENE_MAX_COORD, LB_SOFT_LEVEL_MARGIN},
    {LB_SCENE_MAX_COORD, 1.0 - LB_SOFT_LEVEL_MARGIN},
    {"|level| <= 1e9", "0 < level < 1 (soft fields lie in [0, 1])"},
    0,
    "the level set taken as the surface (zero: an offset; soft: another threshold)"};

/* ---- the rows ---- */

const lb__family_row lb__family_rows[LB__F_COUNT] = {
    {LB__F_PRIMITIVE,
     NULL,
     LB__CONV_BOTH,
     LB__OPS_NONE,
     0,
     0,
     -1,
     0,
     0,
     NULL,
     P_NONE,
     NULL,
     NULL,
     NULL,
     NULL,
     0,
     {NULL, NULL, NULL},
     "a primitive solid"},
#define LB__ROW(ID, name, conv, ops, kmin, kmax, bulge, select, flags, keys, params, shape, apply, \
                interval, cull, form, blurb, ...)                                                  \
    {LB__F_##ID, name,   conv,  ops,   kmin,     kmax, bulge, select,        flags,                \
     keys,       params, shape, apply, interval, cull, form,  {__VA_ARGS__}, blurb},
#include "families.def"
#undef LB__ROW
};

static const lb__primitive_row PRIMS[] = {
    {"sphere", LB_PRIM_ELLIPSOID, K_SPHERE, "a sphere (the ellipsoid with equal semi-axes)"},
    {"ellipsoid", LB_PRIM_ELLIPSOID, K_ELLIPSOID, "an axis-aligned ellipsoid"},
    {"lp", LB_PRIM_LP, K_LP, "an Lp ball (a rounded box for large exponents)"},
    {"superquadric", LB_PRIM_SUPERQUADRIC, K_SUPERQUADRIC, "Barr's superquadric (e1, e2)"},
    {"slab", LB_PRIM_SLAB, K_SLAB, "the space between two parallel planes"},
    {"halfspace", LB_PRIM_HALFSPACE, K_HALFSPACE, "the space below a plane"},
    {"cylinder", LB_PRIM_CYLINDER, K_CYLINDER, "an infinite cylinder"},
    {"capsule", LB_PRIM_CAPSULE, K_CAPSULE, "a segment swept by a ball"},
    {"torus", LB_PRIM_TORUS, K_TORUS, "a torus about an axis"},
};

const lb__primitive_row *lb__primitive_rows(size_t *n) {
    *n = sizeof PRIMS / sizeof PRIMS[0];
    return PRIMS;
}

const lb__family_row *lb__family_find(const char *type, const lb__primitive_row **prim) {
    *prim = NULL;
    for (size_t i = 0; i < sizeof PRIMS / sizeof PRIMS[0]; ++i)
        if (strcmp(PRIMS[i].name, type) == 0) {
            *prim = &PRIMS[i];
            return &lb__family_rows[LB__F_PRIMITIVE];
        }
    for (size_t f = 1; f < LB__F_COUNT; ++f)
        if (!(lb__family_rows[f].flags & LB__R_NO_PARSE) &&
            strcmp(lb__family_rows[f].name, type) == 0)
            return &lb__family_rows[f];
    return NULL;
}

const lb__param *lb__family_param(const lb__family_row *row, const char *key) {
    for (const lb__param *p = row->params; p->key; ++p)
        if (strcmp(p->key, key) == 0) return p;
    return NULL;
}

void lb__short_number(double v, char *buf, size_t size) {
    char t[40];
    if (v != 0.0 && (fabs(v) >= 1e6 || fabs(v) < 1e-4)) {
        /* the fewest digits that read back as v, in the exponent form */
        for (int prec = 0; prec <= 16; ++prec) {
            snprintf(t, sizeof t, "%.*e", prec, v);
            if (strtod(t, NULL) == v) break;
        }
        /* 1e-09 -> 1e-9, 1e+09 -> 1e9 */
        char *e = strchr(t, 'e'), *q = e + 1, *w = e + 1;
        if (*q == '+')
            ++q;
        else if (*q == '-')
            *w++ = *q++;
        while (*q == '0' && q[1]) ++q;
        memmove(w, q, strlen(q) + 1);
    } else {
        snprintf(t, sizeof t, "%.15g", v);
    }
    snprintf(buf, size, "%s", t);
}

void lb__param_allowed(const lb__param *p, int alt, char *buf, size_t size) {
    char lo[40], hi[40];
    lb__short_number(p->lo, lo, sizeof lo);
    lb__short_number(alt ? p->hi_alt : p->hi, hi, sizeof hi);
    const char *note = alt ? p->note_alt : p->note;
    snprintf(buf, size, "%s %s %s <= %s%s%s", lo, p->open_lo ? "<" : "<=", p->key, hi,
             *note ? " " : "", note);
}
