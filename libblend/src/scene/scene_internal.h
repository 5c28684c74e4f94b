/* Internal scene representation shared by the parser, the reference walk,
 * the describer and the compiler. Not installed. */
#ifndef LIBBLEND_SCENE_INTERNAL_H
#define LIBBLEND_SCENE_INTERNAL_H

#include "../common/internal.h"
#include "../operators/registry.h"
#include "libblend/scene.h"

/* y = M x + t */
typedef struct lb__affine {
    double M[9];
    double t[3];
} lb__affine;

typedef struct lb__node lb__node;
struct lb__node {
    lb__op o;          /* the family and its parameters; o.path: the node's JSON path */
    const char *type;  /* the scene's "type" string (stable identifier) */
    lb_primitive prim; /* LB__F_PRIMITIVE */
    lb__node **args;   /* o.k */
    lb__node **bounds; /* o.k (LB__R_BOUNDING) */
    int has_transform;
    /* parent coordinates -> this node's coordinates; allocated only with
     * has_transform (most nodes of a large scene have none), else NULL */
    lb__affine *to_local;
    char *def_name;     /* name when the node is a def, else NULL */
    size_t depth;       /* height: 1 for a leaf */
    size_t bulge_depth; /* bulge nodes on the longest path down (4 re-evaluations each) */
    double walk_cost;   /* nodes the reference walk visits per point (shared nodes per use) */
    size_t mat;         /* its own "material": index into the scene's materials, 0 = inherited */
    int mat_below;      /* some node strictly below (args only) has its own material */
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

/* materials (scene/material.c): the score (sign * a + offset, smallest
 * decides) of argument i's value a under operator o's material rule */
LB_INTERNAL void lb__material_score(const lb__op *o, lb_convention conv, size_t i, double *sign,
                                    double *offset);

#endif
