/* libblend — scenes: a blend tree read from a JSON scene file (format
 * "libblend-scene", version 1; docs/scene-format.md), and the compiled
 * evaluator that answers questions about its field.
 *
 * Layering (as in libfive): scene (the parsed, validated tree; a DAG when
 * "defs" are shared) -> evaluator (compiled once into a flat instruction
 * tape) -> one entry point per question: values and gradients of point
 * batches, and interval bounds over boxes. Meshers and exporters build on
 * those two.
 *
 * Contracts shared by every function here:
 * - Handles are opaque; each has one free function, which accepts NULL.
 * - A scene or evaluator is immutable once built: any number of threads may
 *   evaluate the same evaluator at once. No global state, no callbacks.
 * - Buffers are owned by the caller. Failures return a status and fill `err`
 *   (may be NULL) with one message naming the file, line:column where known,
 *   the JSON path (like $.root.args[1].r) and what is allowed.
 */
#ifndef LIBBLEND_SCENE_H
#define LIBBLEND_SCENE_H

#include "common.h"
#include "operators.h" /* LB_MAX_ARITY_WIDE */

#ifdef __cplusplus
extern "C" {
#endif

/* Limits a scene must respect; larger input is rejected with a message. */
#define LB_SCENE_MAX_BYTES (64u * 1024u * 1024u) /* scene file size */
#define LB_SCENE_MAX_DEPTH 64                    /* nesting of nodes below the root */
#define LB_SCENE_MAX_NODES 100000                /* nodes in one scene, refs included */
/* What a scene of LB_SCENE_MAX_NODES nodes can hold, checked on the text
 * before it is parsed (a node is one object, with a few more for its
 * material and parameters; at most 8 arrays and 40 values each): a file
 * beyond them cannot be a scene, and is refused without building a tree. */
#define LB_SCENE_MAX_JSON_OBJECTS (4 * LB_SCENE_MAX_NODES + 64)
#define LB_SCENE_MAX_JSON_ARRAYS (8 * LB_SCENE_MAX_NODES + 64)
#define LB_SCENE_MAX_JSON_VALUES (40 * LB_SCENE_MAX_NODES + 1024)
/* Elements of one JSON array, checked the same way: 4 times the longest
 * list a scene holds (an operator's arguments, or its r, p, m lists), so a
 * list a little too long still gets the node's own message. */
#define LB_SCENE_MAX_JSON_ARRAY (4 * LB_MAX_ARITY_WIDE)
#define LB_SCENE_MAX_LIGHTS 16
/* Bulge-eliminated blends nested inside each other's arguments: each level
 * re-evaluates its arguments 4 times for the Hessian terms of its gradient. */
#define LB_SCENE_MAX_BULGE_NESTING 4
/* The cost model (docs/scene-format.md, "Cost"): a point costs one run of
 * every instruction of the compiled tape, and each bulge-eliminated blend
 * re-runs the instructions each of its two arguments depends on twice more.
 * lb_evaluator_create refuses (LB_ERR_INVALID_ARGUMENT, naming the costliest
 * node) a scene whose cost per point exceeds LB_SCENE_MAX_COST_FACTOR times
 * its instruction count or LB_SCENE_MAX_COST, so evaluation time per point
 * is at most a fixed multiple of the tape size (lb_evaluator_cost). */
/* compiled tape size (a def used under N transforms is N copies) */
#define LB_SCENE_MAX_INSTRUCTIONS 200000
#define LB_SCENE_MAX_COST_FACTOR 64
#define LB_SCENE_MAX_COST 1000000
/* Largest |coordinate| anywhere in a scene (centres, translations, bounds)
 * and of evaluation points. */
#define LB_SCENE_MAX_COORD 1e9
/* A soft level node's level lies in (margin, 1 - margin): soft fields lie in
 * [0, 1], and a level at either end has no surface. */
#define LB_SOFT_LEVEL_MARGIN 1e-6
/* Compile-time work of local unions (their intersection curves are found
 * by evaluating both children on a grid and along the curves): counted in
 * instruction runs as it is done; lb_evaluator_create stops and refuses
 * the scene (LB_ERR_INVALID_ARGUMENT, naming the local_union) once it
 * passes the limit, which this machine reaches in a few seconds. A local
 * union met inside a child counts as LB_LOCAL_RUN_WEIGHT instructions
 * (its clean union, blend and mix), and LB_LOCAL_NEAR_WEIGHT more at a point
 * where one of its blending volumes may reach (the nearest-curve query). */
#define LB_SCENE_MAX_COMPILE_COST 5e8
#define LB_LOCAL_RUN_WEIGHT 16
#define LB_LOCAL_NEAR_WEIGHT 48

typedef struct lb_scene lb_scene;
typedef struct lb_evaluator lb_evaluator;

typedef enum lb_convention {
    LB_CONVENTION_ZERO = 0, /* inside f < 0, surface f = 0 */
    LB_CONVENTION_SOFT = 1  /* inside f > 0.5, surface f = 0.5, f in [0, 1] */
} lb_convention;

/* A surface material: colour and finish, each component in [0, 1]. */
typedef struct lb_material {
    double color[3];
    double ambient, diffuse, specular;
} lb_material;

/* The optional "render" section, with defaults filled in (docs/scene-format.md). */
typedef struct lb_render_light {
    double location[3];
    double color[3];
} lb_render_light;

/* Scenes are right-handed with z up (as Blender): a camera's up direction
 * defaults to +z, the floor lies under the scene along it. */
typedef struct lb_render {
    int has_camera;     /* 0: exporters frame the bounds themselves */
    double location[3]; /* camera position */
    double look_at[3];  /* camera target */
    double up[3];       /* the camera's up direction (default 0, 0, 1; unit length) */
    double angle;       /* horizontal field of view in degrees, (0, 180) */
    size_t light_count; /* 0: exporters use their default three-point lights */
    lb_render_light lights[LB_SCENE_MAX_LIGHTS];
    double color[3];                   /* material 0's colour, each in [0, 1] */
    double ambient, diffuse, specular; /* material 0's finish, each in [0, 1] */
    int floor;                         /* 1 (default): a floor under the surface, taking shadows */
    double floor_color[3];             /* default 0.75 grey */
    double background[3];              /* default a neutral 0.9 grey */
} lb_render;

typedef struct lb_scene_stats {
    size_t nodes;      /* distinct nodes (a shared def counts once) */
    size_t primitives; /* distinct primitive nodes */
    size_t operators;  /* distinct blend / set-operator nodes */
    size_t depth;      /* longest root-to-leaf path, in nodes */
} lb_scene_stats;

/* Parse and validate a scene held in memory. `text` need not be
 * NUL-terminated; `name` (may be NULL) is the file name used in messages.
 * On success *out owns a new scene (free with lb_scene_free). */
LB_API lb_status lb_scene_parse(const char *text, size_t length, const char *name, lb_scene **out,
                                lb_error *err);

/* Read, parse and validate a scene file. Missing, unreadable or too large
 * files fail with a message naming the path. */
LB_API lb_status lb_scene_load(const char *path, lb_scene **out, lb_error *err);

/* Release a scene. Evaluators built from it keep what they need. */
LB_API void lb_scene_free(lb_scene *scene);

LB_API lb_convention lb_scene_convention(const lb_scene *scene);

/* The declared bounds: returns 1 and fills min/max when the scene has
 * "bounds", else returns 0 and leaves them untouched. */
LB_API int lb_scene_bounds(const lb_scene *scene, double min[3], double max[3]);

/* The render section, defaults filled in. Never NULL for a valid scene. */
LB_API const lb_render *lb_scene_render(const lb_scene *scene);

LB_API void lb_scene_stats_get(const lb_scene *scene, lb_scene_stats *stats);

/* ---- materials (docs/scene-format.md, "Materials") --------------------------
 * Material 0 is the render section's; every distinct "material" a node
 * names is one more. A surface point takes the material of the node found
 * by walking down from the root: at each operator, into the argument that
 * decides the set operation there (a union's most-inside argument, an
 * intersection's most-outside one, a difference's most-outside among the
 * first and the complements of the others), until the subtree below holds
 * no material of its own; a node without one takes its parent's. */

/* Number of materials, 1 + those the nodes name (0 for NULL). */
LB_API size_t lb_scene_material_count(const lb_scene *scene);

/* Material i into *out; returns 1, or 0 (and leaves *out) when i is out of
 * range or an argument is NULL. */
LB_API int lb_scene_material(const lb_scene *scene, size_t i, lb_material *out);

/* The material index of each of n points (structure of arrays) by the rule
 * above, into index (n entries, caller-owned). ev is the scene's compiled
 * evaluator (needed when the scene has a local_union; may be NULL
 * otherwise). A scene whose nodes name no material fills zeros without
 * evaluating. Cost: one reference walk of each decided operator's arguments
 * per point; runs on the calling thread. */
LB_API lb_status lb_scene_material_index(const lb_scene *scene, const lb_evaluator *ev, size_t n,
                                         const double *x, const double *y, const double *z,
                                         uint32_t *index, lb_error *err);

/* ---- the subsequent-blend parameter m (docs/operators.md, section 4) ------
 * A blend's m never moves its own surface: away from its blending region it
 * divides the blend's values by m, which changes a surface only through an
 * operator above the blend that uses values (a blend, a level, a local
 * union). min, max, complement, transforms, R-functions and clean unions
 * depend only on where their arguments are inside, and pass this on. */

/* The nodes that set an m other than 1 that can change nothing: no path
 * from the root reaches them through a value-using operator. There m only
 * steepens the field (by up to 1 / m where m < 1: a POV-Ray max_gradient
 * must grow with it, and the render slows). Writes the JSON paths of the
 * first max of them, in scene order, into paths (caller-owned; the strings
 * belong to the scene and live as long as it; paths may be NULL to count)
 * and returns how many there are. Linear in the scene's size; returns 0 for
 * NULL and when memory is short (it only informs). */
LB_API size_t lb_scene_unused_m(const lb_scene *scene, const char **paths, size_t max);

/* Write the tree as indented text (one node per line, shared defs printed
 * once and referenced by name afterwards) into buf, NUL-terminated and
 * truncated to size. Returns the length the whole text needs (without the
 * NUL), like snprintf. A NULL buf (with any size) only measures. */
LB_API size_t lb_scene_describe(const lb_scene *scene, char *buf, size_t size);

/* The node types a scene can name, as one JSON object (the family
 * registry, docs/design.md "Adding a family"): for every primitive its
 * keys; for every operator its conventions, set operations, arity, keys,
 * per-argument parameters and scalar parameter with their ranges and
 * defaults, whether it takes bulge elimination and bounding solids, and
 * its POV-Ray macros. Tools generate or check their own lists against it
 * (the JSON Schema, the Blender add-on, the fuzz dictionary). Written into
 * buf like lb_scene_describe (NUL-terminated, truncated to size; returns
 * the length the whole text needs; a NULL buf only measures); 0 when
 * memory is short. Thread-safe: it reads constant tables only. */
LB_API size_t lb_scene_families_json(char *buf, size_t size);

/* Reference evaluator: a plain recursive walk over the scene tree, one
 * point, calling the public per-family functions. Slow on purpose; tests and
 * benchmarks compare the compiled evaluator against it. grad may be NULL.
 * The walk visits a shared def once per use, so it refuses a scene whose
 * walk would visit more than LB_SCENE_MAX_COST nodes per point. */
LB_API lb_status lb_scene_eval_reference(const lb_scene *scene, const double X[3], double *value,
                                         double grad[3], lb_error *err);

/* ---- compiled evaluator ---------------------------------------------------- */

/* Compile a scene into a flat instruction tape: every distinct node (a
 * shared def under the same transform) becomes one instruction, transforms
 * are folded into the primitives, parameters are validated and preprocessed
 * once. The evaluator does not depend on the scene afterwards. */
LB_API lb_status lb_evaluator_create(const lb_scene *scene, lb_evaluator **out, lb_error *err);
LB_API void lb_evaluator_free(lb_evaluator *ev);

/* lb_evaluator_create for a scene edited from the one previous (may be
 * NULL) was compiled from: the same evaluator, bit for bit (values,
 * gradients, bounds, lb_evaluator_cost and lb_evaluator_compile_cost, the
 * same refusals), made faster by copying the intersection curves of every
 * local_union whose children (their whole subtrees, every parameter) and
 * own parameters are those of one of previous's, inside the same scene
 * bounds, instead of finding them again: an edit traces only the curves of
 * the local unions above what it changed. *reused (may be NULL) receives
 * how many local unions' curves were copied. previous is only read (it may
 * be in use by other threads) and may be freed afterwards. */
LB_API lb_status lb_evaluator_create_reusing(const lb_scene *scene, const lb_evaluator *previous,
                                             lb_evaluator **out, size_t *reused, lb_error *err);

/* The convention of the scene the evaluator was compiled from. */
LB_API lb_convention lb_evaluator_convention(const lb_evaluator *ev);

/* Number of instructions on the tape. */
LB_API size_t lb_evaluator_size(const lb_evaluator *ev);

/* Instruction runs one point costs (the cost model above): at least
 * lb_evaluator_size, at most LB_SCENE_MAX_COST_FACTOR times it. 0 for NULL. */
LB_API double lb_evaluator_cost(const lb_evaluator *ev);

/* Instruction runs that compiling took to find the local unions' curves
 * (every child evaluation and interval pass over a child's instructions; a
 * nested local union counts LB_LOCAL_RUN_WEIGHT runs, and
 * LB_LOCAL_NEAR_WEIGHT more where its blending volumes may reach): at most
 * LB_SCENE_MAX_COMPILE_COST. 0 for NULL or a scene without local unions. */
LB_API double lb_evaluator_compile_cost(const lb_evaluator *ev);

/* The intersection curves and blending volumes of the local_union nodes,
 * as text (one line per node, one per curve: vertices, length, diameter,
 * R, v1, v2, d1, d2), into buf like lb_scene_describe. */
LB_API size_t lb_evaluator_describe_local(const lb_evaluator *ev, char *buf, size_t size);

/* Values and gradients at n points given as three coordinate arrays
 * (structure of arrays). value must be non-NULL; gx, gy, gz may each be NULL.
 * threads: 0 = one per online CPU, 1 = only the calling thread, N = at most
 * N threads (the batch is split into chunks; small batches use fewer).
 * Every |coordinate| must be <= LB_SCENE_MAX_COORD. On failure the outputs
 * are unspecified. */
LB_API lb_status lb_evaluator_eval(const lb_evaluator *ev, size_t n, const double *x,
                                   const double *y, const double *z, double *value, double *gx,
                                   double *gy, double *gz, int threads, lb_error *err);

/* An interval [*lo, *hi] guaranteed to contain the field at every point of
 * the box [bmin, bmax] (docs/design.md, "Interval bounds"). bmin <= bmax
 * componentwise; a degenerate box is a point. An end nothing finite bounds
 * is -INFINITY or +INFINITY (never a large finite stand-in). */
LB_API lb_status lb_evaluator_bounds(const lb_evaluator *ev, const double bmin[3],
                                     const double bmax[3], double *lo, double *hi, lb_error *err);

/* ---- the solid's extent (evaluation/extent.c) ---- */
enum {
    LB_EXTENT_EMPTY = 1,   /* no part of the solid in the search box */
    LB_EXTENT_TOUCHES = 2, /* it may reach a face of the search box: unbounded (a slab, a
                              half-space, a complement) or the search box is too small */
    LB_EXTENT_COARSE = 4   /* the pass cap was reached: sound, but looser than tol */
};
/* Interval passes one extent query makes at most (a sixth per face); then
 * it stops refining. */
#define LB_EXTENT_MAX_BOXES 200000

/* A box [out_min, out_max] that contains every point of the solid (f < 0;
 * soft convention: f > 0.5) inside the search box [smin, smax], found by
 * interval bounds alone (no sampling can miss a thin part): boxes the
 * bounds cannot prove outside, refined until at most tol across (the
 * result is at most about tol larger than the solid's own box on each side,
 * more where the bounds are loose, never smaller). *flags receives
 * LB_EXTENT_* bits; with LB_EXTENT_EMPTY the box is smin..smin; with
 * LB_EXTENT_TOUCHES the sides not refined when the touch was found are the
 * search box's. tol > 0 and
 * at least 1e-12 of the search box's longest side; search box finite with
 * min < max and |coordinate| <= LB_SCENE_MAX_COORD. Cost: a few passes per
 * level where the solid's extreme on a side is a point; where it is a
 * ridge or a flat face, about (size / tol)^1.5 or (size / tol)^2 passes, so
 * choose tol as coarse as the use allows; at most LB_EXTENT_MAX_BOXES
 * interval passes (each the cost of one lb_evaluator_bounds); runs on the
 * calling thread. Used by the Blender add-on to fit a field's region to the
 * field (tol: about a mesh cell). */
LB_API lb_status lb_evaluator_extent(const lb_evaluator *ev, const double smin[3],
                                     const double smax[3], double tol, double out_min[3],
                                     double out_max[3], int *flags, lb_error *err);

#ifdef __cplusplus
}
#endif

#endif
