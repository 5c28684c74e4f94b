/* The family registry: every node type of a scene, one row each, in
 * families.def. Not installed.
 *
 * A row says what a node type is: its JSON name, the conventions it works
 * in, its set operations and arity, the keys it takes, its per-argument
 * parameters and its one scalar parameter with their ranges (from the
 * named constants of the public headers), how it is applied at a point,
 * how it is bounded over a box and which arguments a box can drop, the
 * POV-Ray macro that writes it, and how the description prints it. The
 * parser, the compiler, the evaluators' generic dispatch, the interval
 * bounds, the description, the material rule and the POV-Ray writer read
 * these rows; `blendtool info --families --json` prints them, and the
 * JSON Schema, the add-on's property lists and the fuzz dictionary are
 * checked against that print (tests/schema/test_registry.py).
 *
 * The operator an instruction or a node applies is an lb__op: the family
 * and its parameters, nothing of the scene's tree (no arguments, no
 * transform), so the compiled tape holds lb__ops and never scene nodes.
 * docs/design.md, "Adding a family", walks through a new row. */
#ifndef LIBBLEND_REGISTRY_H
#define LIBBLEND_REGISTRY_H

#include "../common/internal.h"
#include "libblend/scene.h"

#include <stdint.h>

/* Node families: one per operator row of families.def, and primitives
 * (nine JSON types, one family). */
typedef enum lb__family {
    LB__F_PRIMITIVE = 0,
#define LB__ROW(ID, ...) LB__F_##ID,
#include "families.def"
#undef LB__ROW
    LB__F_COUNT
} lb__family;

/* local_union / clean_union parameters (docs/scene-format.md) */
typedef struct lb__local_params {
    int has_feature;
    double feature[2]; /* feature sizes d_i (user), else from the curvature */
    int has_limits;
    double limits[2];    /* v1, v2 (user), else by stepping off the curve */
    double radius;       /* blending volume support R (user), 0 = automatic */
    int feature_support; /* R = 2 min(d1, d2) instead of the progressive rule */
    double support;      /* progressive: R = support x the curve's diameter */
    double exponent;     /* n in beta = v^n */
    double alpha[2];     /* convolution weights of the clean union */
    double zero_scale;   /* zero convention: g = C (1 - f / zero_scale) */
} lb__local_params;

/* One operator with its parameters: what a node applies, and what an
 * instruction of the compiled tape holds. */
typedef struct lb__op {
    lb__family family;
    lb_setop op; /* families with an "op" */
    size_t k;
    double *r, *p, *m;   /* k each where the family uses them, else NULL */
    double shape;        /* the row's scalar parameter (conic p, ricci n, level) */
    int bulge;           /* bulge elimination on (rows with a bulge family; k = 2) */
    lb_bulge_params bp;  /* bulge */
    lb__local_params lp; /* local_union, clean_union */
    char *path;          /* the node's JSON path, for messages (owned by the node or instruction) */
} lb__op;

/* An interval. */
typedef struct lb__iv {
    double lo, hi;
} lb__iv;

/* Conventions a row works in (bits). */
enum { LB__CONV_ZERO = 1, LB__CONV_SOFT = 2, LB__CONV_BOTH = 3 };
/* Set operations a row takes through "op". */
enum { LB__OPS_NONE = 0, LB__OPS_ALL = 1 /* union, intersection, difference */, LB__OPS_UI = 2 };
/* How the POV-Ray writer writes a row (export/pov.c). */
enum {
    LB__POV_MACRO = 0,  /* a macro of the include: NAME([op, ]args[, bounds], r, p, m[, shape]) */
    LB__POV_SELECT,     /* POV-Ray's own min() / max() over the arguments */
    LB__POV_COMPLEMENT, /* -f or max(0, 1 - f), written out */
    LB__POV_LEVEL,      /* f - h or max(0, f - h + 0.5), written out */
    LB__POV_LOCAL,      /* the local blend's curves and volumes (export/pov.c) */
    LB__POV_GROUP       /* the transformed argument itself */
};
/* Row flags. */
enum {
    LB__R_BOUNDING = 1u,     /* one bounding solid per argument ("bounds") */
    LB__R_CURVES = 2u,       /* finds intersection curves when compiled (local_union) */
    LB__R_POV16 = 4u,        /* the POV-Ray macro takes at most LB_POV_MAX_ARITY arguments */
    LB__R_NO_PARSE = 8u,     /* made by the parser, never named in a scene (a transformed ref) */
    LB__R_FOLD_BINARY = 16u, /* k > 2 is folded into nested binary nodes by the parser */
    LB__R_CLEAN_UNION = 32u, /* built on the clean union UC: bounded by evaluation/local_bounds.c */
    /* its surface depends only on where its arguments are inside, never on
     * their values away from their surfaces (min, max, complement, a
     * transform, R-functions, the clean union): a subsequent-blend m below
     * it acts only through a value-using operator above it */
    LB__R_ZERO_SETS_ONLY = 64u
};

/* A per-argument parameter ("r", "p", "m"): a number for every argument
 * or one per argument. In [lo, hi] ((lo, hi] when open_lo); under the set
 * operations of hi_alt_ops (bits 1 << op) the upper end is hi_alt. */
typedef struct lb__param {
    const char *key;
    int required; /* else def */
    double def;
    double lo, hi;
    int open_lo;
    double hi_alt;
    unsigned hi_alt_ops;
    const char *note;     /* after the range in messages, e.g. "(soft)"; "" for none */
    const char *note_alt; /* the same under hi_alt_ops */
    const char *blurb;    /* what it means, for the exported registry */
} lb__param;

/* The row's one scalar parameter (conic "p", ricci "n", level "level"):
 * in [lo[c], hi[c]] for convention c (0 zero, 1 soft). */
typedef struct lb__shape {
    const char *key;
    int required; /* else def */
    double def;
    double lo[2], hi[2];
    const char *allowed[2]; /* the range in words, per convention (NULL: from lo and hi) */
    int below_r1r2;         /* also below r1 r2 (the conics) */
    const char *blurb;
} lb__shape;

/* the operator at one point: x = argument values (k), c = bounding values
 * (k, LB__R_BOUNDING only), g = argument gradients (3k, used by bulge); on
 * success value, dx (k) and, for bulge, dg (3k: d value / d g_i). */
typedef lb_status (*lb__apply_fn)(const lb__op *o, lb_convention conv, const double *x,
                                  const double *c, const double *g, double *value, double *dx,
                                  double *dc, double *dg, lb_error *err);
/* a sound enclosure of the operator over argument intervals x (and
 * bounding intervals c) into *out; ws: 2k doubles of scratch */
typedef void (*lb__interval_fn)(const lb__op *o, lb_convention conv, const lb__iv *x,
                                const lb__iv *c, lb__iv *out, double *ws);
/* the arguments that can decide the value anywhere in a box whose
 * argument intervals are x, into act; returns how many */
typedef uint16_t (*lb__cull_fn)(const lb__op *o, const lb__iv *x, uint16_t *act);

typedef struct lb__family_row {
    lb__family id;
    const char *name; /* the JSON "type" (the group row: "transform", never parsed) */
    int conv;         /* LB__CONV_* */
    int ops;          /* LB__OPS_* */
    size_t kmin, kmax;
    int bulge_family;         /* lb_bulge_family when "bulge" is taken, else -1 */
    int select;               /* +1 min, -1 max: the value is one argument's; else 0 */
    unsigned flags;           /* LB__R_* */
    const char *const *keys;  /* the node's own keys, NULL-terminated (transform keys apart) */
    const lb__param *params;  /* per-argument parameters, key NULL-terminated */
    const lb__shape *shape;   /* NULL for none */
    lb__apply_fn apply;       /* operators/apply.c */
    lb__interval_fn interval; /* operators/intervals.c */
    lb__cull_fn cull;         /* NULL: every argument stays */
    int pov_form;             /* LB__POV_* */
    const char *pov[3];       /* the macro; one per set operation when pov[1] is set */
    const char *blurb;        /* one line for the description and the exported registry */
} lb__family_row;

/* The keys every node takes besides its own (transforms, material). */
#define LB__TRANSFORM_KEYS "translate", "rotate", "scale", "material"

/* The primitive rows: JSON name, lb_primitive_kind, keys, blurb. */
typedef struct lb__primitive_row {
    const char *name;
    lb_primitive_kind kind;
    const char *const *keys;
    const char *blurb;
} lb__primitive_row;
/* the keys every primitive takes in a soft scene only (its kernel),
 * NULL-terminated */
LB_INTERNAL extern const char *const lb__primitive_soft_keys[];

/* every row, indexed by family (row 0, the primitive family, has name
 * NULL); lb__family_info(f) is the row of family f */
LB_INTERNAL extern const lb__family_row lb__family_rows[LB__F_COUNT];
static inline const lb__family_row *lb__family_info(lb__family f) {
    return &lb__family_rows[f];
}
/* the flags of o's row */
static inline unsigned lb__op_flags(const lb__op *o) {
    return lb__family_info(o->family)->flags;
}
/* the primitive rows, in order; *n receives their count */
LB_INTERNAL const lb__primitive_row *lb__primitive_rows(size_t *n);
/* the row named type, or NULL; *prim receives the primitive row for a
 * primitive type (family LB__F_PRIMITIVE) */
LB_INTERNAL const lb__family_row *lb__family_find(const char *type, const lb__primitive_row **prim);
/* the row's parameter key, or NULL */
LB_INTERNAL const lb__param *lb__family_param(const lb__family_row *row, const char *key);
/* "lo <= key <= hi" in words, from the numbers (short forms: 1e-9, 1000),
 * with the note; alt: the range under hi_alt_ops */
LB_INTERNAL void lb__param_allowed(const lb__param *p, int alt, char *buf, size_t size);
/* a number in its short form (1e-9, 1e9, 0.05, 1000) */
LB_INTERNAL void lb__short_number(double v, char *buf, size_t size);

/* ---- applying and bounding an operator (operators/apply.c, intervals.c) ---- */
LB_INTERNAL lb_status lb__op_apply(const lb__op *o, lb_convention conv, const double *x,
                                   const double *c, const double *g, double *value, double *dx,
                                   double *dc, double *dg, lb_error *err);
LB_INTERNAL void lb__op_interval(const lb__op *o, lb_convention conv, const lb__iv *x,
                                 const lb__iv *c, lb__iv *out, double *ws);
/* act receives every argument that can decide o over x (all when the row
 * has no cull rule); returns how many */
LB_INTERNAL uint16_t lb__op_cull(const lb__op *o, const lb__iv *x, uint16_t *act);
/* the union-form (dual) interval of argument i: intersection -x, difference
 * -x_0 (inline: the bounds passes call it per argument) */
static inline lb__iv lb__dual_iv(lb_setop op, size_t i, lb__iv x) {
    const int neg = op == LB_INTERSECTION || (op == LB_DIFFERENCE && i == 0);
    if (!neg) return x;
    const lb__iv o = {-x.hi, -x.lo};
    return o;
}

/* local_union / clean_union: children in the soft form the operators take
 * (zero convention: g = C (1 - f / zero_scale), C = 0.5), and the result
 * back in the scene's convention; the clean union alone. */
#define LB__LOCAL_ISO 0.5
LB_INTERNAL void lb__local_in(const lb__op *o, lb_convention conv, const double f[2], double g[2]);
LB_INTERNAL double lb__local_out(const lb__op *o, lb_convention conv, double u);
LB_INTERNAL lb_status lb__clean_apply(const lb__op *o, lb_convention conv, const double *x,
                                      double *value, double *dx, lb_error *err);

/* the set operation the material rule follows for o (union for rows
 * without "op") */
static inline lb_setop lb__material_op(const lb__op *o) {
    return lb__family_info(o->family)->ops ? o->op : LB_UNION;
}

#endif
