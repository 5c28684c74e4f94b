/* Internal scene representation shared by the parser, the reference walk,
 * the describer and the compiler. Not installed. */
#ifndef LIBBLEND_SCENE_INTERNAL_H
#define LIBBLEND_SCENE_INTERNAL_H

#include "../common/internal.h"
#include "libblend/scene.h"

/* Node families. Primitives carry an lb_primitive; every other family is an
 * operator over args (and, for bounded blends, one bounding solid per arg). */
typedef enum lb__family {
    LB__F_PRIMITIVE = 0,
    LB__F_DISPLACEMENT, /* BT_k, zero */
    LB__F_CONIC,        /* BT_2 conic, zero */
    LB__F_SCALE,        /* B_U / B_I / B_D, zero */
    LB__F_BOUNDED,      /* bounded primitives, zero */
    LB__F_SOFT_HYPER,   /* B_Sk / B_Ak, soft */
    LB__F_SOFT_CONIC,   /* binary conic soft, soft */
    LB__F_MIN,          /* both conventions */
    LB__F_MAX,          /* both conventions */
    LB__F_RFUNCTION,    /* Rvachev union / intersection, zero, binary */
    LB__F_SOFT_SUM,     /* Wyvill sum, soft */
    LB__F_RICCI,        /* (sum x^n)^(1/n), soft */
    LB__F_PERLIN,       /* Perlin union / intersection / difference, soft */
    LB__F_COMPLEMENT,   /* -f (zero) or 1 - f (soft), one arg */
    LB__F_GROUP,        /* a transform applied to one arg (a transformed ref) */
    LB__F_LOCAL,        /* local blend around the intersection curves, binary, both */
    LB__F_CLEAN,        /* clean union UC, binary, both */
    LB__F_LEVEL,        /* its argument's h-level set as the surface (shape = h), one arg, both */
    LB__F_COUNT
} lb__family;

/* y = M x + t */
typedef struct lb__affine {
    double M[9];
    double t[3];
} lb__affine;

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

typedef struct lb__node lb__node;
struct lb__node {
    lb__family family;
    const char *type;  /* the scene's "type" string (stable identifier) */
    lb_setop op;       /* families with an "op" */
    lb_primitive prim; /* LB__F_PRIMITIVE */
    size_t k;
    lb__node **args;   /* k */
    lb__node **bounds; /* k (bounded) */
    double *r, *p, *m; /* k each where the family uses them, else NULL */
    double shape;      /* conic p, ricci n */
    int bulge;         /* bulge elimination on (displacement, conic, scale; k = 2) */
    lb_bulge_params bp;
    int has_transform;
    lb__affine to_local; /* parent coordinates -> this node's coordinates */
    lb__affine to_parent;
    char *path;          /* JSON path of the node, for messages */
    char *def_name;      /* name when the node is a def, else NULL */
    size_t depth;        /* height: 1 for a leaf */
    size_t bulge_depth;  /* bulge nodes on the longest path down (4 re-evaluations each) */
    double walk_cost;    /* nodes the reference walk visits per point (shared nodes per use) */
    lb__local_params lp; /* LB__F_LOCAL, LB__F_CLEAN */
    size_t mat;          /* its own "material": index into the scene's materials, 0 = inherited */
    int mat_below;       /* some node strictly below (args only) has its own material */
};

struct lb_scene {
    lb_convention convention;
    int has_bounds;
    double bmin[3], bmax[3];
    lb_render render;
    lb__node *root;
    lb__node **nodes; /* every node, for freeing */
    size_t nnodes, cap;
    char *name; /* file name for messages */
    /* materials named by nodes: mats[i - 1] is material i (0 is the render
     * section's); equal materials share one index */
    lb_material *mats;
    size_t nmats, matcap;
};

/* affine helpers (scene/affine.c) */
LB_INTERNAL void lb__affine_identity(lb__affine *a);
/* c = a after b (c(x) = a(b(x))) */
LB_INTERNAL void lb__affine_compose(const lb__affine *a, const lb__affine *b, lb__affine *c);
LB_INTERNAL void lb__affine_apply(const lb__affine *a, const double x[3], double y[3]);
/* g_parent = M^T g_local */
LB_INTERNAL void lb__affine_pullback(const lb__affine *a, const double g[3], double out[3]);
LB_INTERNAL int lb__affine_is_identity(const lb__affine *a);

/* one operator node at one point: x = argument values (k), c = bounding
 * values (k, bounded only), g = argument gradients (3k, used by bulge), on
 * success value, dx (k) and, for bulge, dg (3k: d value / d g_i). */
LB_INTERNAL lb_status lb__node_apply(const lb__node *n, lb_convention conv, const double *x,
                                     const double *c, const double *g, double *value, double *dx,
                                     double *dc, double *dg, lb_error *err);

/* the reference walk of one node (scene/scene.c): Ap maps world
 * coordinates to the node's parent frame; ev is needed for local_union */
LB_INTERNAL lb_status lb__ref_eval(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                                   const lb_evaluator *ev, const double X[3], double *v,
                                   double g[3], lb_error *err);

/* materials (scene/material.c): the set operation n applies for the
 * material rule, and the score (sign * a + offset, smallest decides) of
 * argument i's value a */
LB_INTERNAL lb_setop lb__material_op(const lb__node *n);
LB_INTERNAL void lb__material_score(const lb__node *n, lb_convention conv, size_t i, double *sign,
                                    double *offset);

/* local_union / clean_union (scene/apply.c): children in the soft form the
 * operators take (zero convention: g = C (1 - f / zero_scale), C = 0.5),
 * and the result back in the scene's convention; the clean union alone. */
#define LB__LOCAL_ISO 0.5
LB_INTERNAL void lb__local_in(const lb__node *n, lb_convention conv, const double f[2],
                              double g[2]);
LB_INTERNAL double lb__local_out(const lb__node *n, lb_convention conv, double u);
LB_INTERNAL lb_status lb__clean_apply(const lb__node *n, lb_convention conv, const double *x,
                                      double *value, double *dx, lb_error *err);

#endif
