/* libblend -> POV-Ray: a scene as a renderable .pov file.
 *
 * The field is built from the macros of povray_include/libblend.inc (one
 * declaration per distinct node: shared defs stay shared; transforms become
 * argument substitutions), rendered as one isosurface whose contained_by box
 * is the scene's bounds and whose max_gradient libblend computes: the
 * largest |grad f| on a dense grid over the box (LB_POV_GRADIENT_SAMPLES per
 * axis), among the samples the surface may be near (|f - threshold| at most
 * two grid diagonals times |grad f|), times LB_POV_GRADIENT_SAFETY. Camera, lights and material
 * come from the scene's render section, or frame the bounds by default. Nothing the scene's author
 * typed reaches an identifier: names are generated (LBn0, LBn1, ...) and user text appears only in
 * comments, stripped of anything but printable ASCII.
 *
 * Local unions: each use (node and world frame) is written with its
 * blending volumes as data, the curve's segments in a tree of functions
 * mirroring the evaluator's box hierarchy, so POV-Ray's field equals the
 * evaluator's to rounding; clean unions are one call of lb_clean_uc.
 *
 * Limits of the include: displacement blends, min and max take up to
 * LB_MAX_ARITY arguments (past LB_POV_MAX_ARITY each solver step evaluates
 * the arguments again, so they render slower); scale, bounded and soft hyper
 * blends take at most LB_POV_MAX_ARITY. A scene with a larger node (scenes
 * allow up to LB_MAX_ARITY_WIDE) is refused with a message naming the node. */
#ifndef LIBBLEND_POV_H
#define LIBBLEND_POV_H

#include "scene.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LB_POV_MAX_ARITY 16
#define LB_POV_GRADIENT_SAMPLES 48
#define LB_POV_GRADIENT_SAFETY 1.25
/* the largest lb_pov_options.mesh_resolution */
#define LB_POV_MAX_MESH_RESOLUTION 1024

typedef struct lb_pov_options {
    int include_only;     /* 1: only the #declare'd functions: the root is LB_Field, and
                             LB_Surface (< 0 inside), LB_FieldMin, LB_FieldMax,
                             LB_FieldMaxGradient, LB_FieldAccuracy are declared for a
                             hand-written scene */
    int silhouette;       /* 1: white object, black background, no shading (for comparisons) */
    double aspect;        /* image width / height for the camera (0: 4/3) */
    double max_gradient;  /* > 0: use this instead of computing it */
    int threads;          /* for the gradient sampling: 0 = all CPUs, 1 = caller only */
    int mesh_resolution;  /* > 0: the surface as a mesh2 of smooth triangles (lb_mesh_create at
                             this many cells along the region's longest side, normals from the
                             analytic gradient) instead of the isosurface: renders in seconds
                             where a soft-object isosurface takes minutes, within half a cell
                             of the surface; the materials' textures are the same; 0: the
                             isosurface (exact); ignored with include_only */
    int mesh_features;    /* with mesh_resolution, non-zero: sharp creases and corners kept
                             (LB_MESH_FEATURES) and each side of a crease shaded with its own
                             normal (LB_MESH_CORNER_NORMALS, as the mesh2's normal_indices) */
    double mesh_simplify; /* with mesh_resolution: lb_mesh_options.simplify (cells, 0 = off) */
    int mesh_merge_flat;  /* with mesh_resolution, non-zero: flat regions merged into few
                             triangles (LB_MESH_MERGE_FLAT: no vertex moves; mesh_simplify
                             merges them too) */
} lb_pov_options;

/* ---- render defaults every exporter shares (the POV-Ray writer and the
 * Blender add-on call these; docs/scene-format.md, "Defaults that read
 * shape") ---- */

/* The three-point lights for a camera at location looking at look_at with
 * up direction up: lights[0] the key (the one that casts soft shadows),
 * lights[1] the fill, lights[2] the rim, each at look_at + L (a right +
 * b up + c forward) of the camera's basis (L its distance to look_at), with
 * its strength as a grey colour. Writes nothing when a pointer is NULL or
 * the camera looks along up or at itself. */
LB_API void lb_render_three_point(const double location[3], const double look_at[3],
                                  const double up[3], lb_render_light lights[3]);

/* The floor's height along the direction up (any length: heights are
 * up . X): the lowest vertex of a 48-cell mesh of the field over [bmin,
 * bmax], less half the largest cell side times |up|, so the surface rests on
 * the floor; the box's lowest corner when there is no surface or the mesh
 * fails. threads as lb_mesh_options. */
LB_API lb_status lb_render_floor_height(const lb_evaluator *ev, const double bmin[3],
                                        const double bmax[3], const double up[3], int threads,
                                        double *height, lb_error *err);

/* The camera the exporter uses: the scene's render section, or one framing
 * the bounds from the front (-y), above (+z) and to the right (+x). The
 * scene is right-handed with up `up` (unit; +z unless the section says
 * otherwise); the exporter writes POV-Ray's camera with `sky up` and a
 * negated `right`, so POV-Ray's image is the right-handed view, the same as
 * Blender's. angle is the horizontal field of view in degrees, for image
 * aspect `aspect` (0: 4/3). Writes nothing when any pointer is NULL. */
LB_API void lb_pov_camera(const lb_scene *scene, double aspect, double location[3],
                          double look_at[3], double up[3], double *angle);

/* Write the scene to path (through an lb_output: libblend/output.h). ev must
 * be compiled from scene. The file includes "libblend.inc": render with
 * povray +L<dir of libblend.inc>. *max_gradient (may be NULL) receives the
 * value written. */
LB_API lb_status lb_scene_write_pov(const lb_scene *scene, const lb_evaluator *ev,
                                    const lb_pov_options *opt, const char *path,
                                    double *max_gradient, lb_error *err);

/* The same text into an open stream (flushed, not closed). */
LB_API lb_status lb_scene_write_pov_stream(const lb_scene *scene, const lb_evaluator *ev,
                                           const lb_pov_options *opt, FILE *stream,
                                           double *max_gradient, lb_error *err);

#ifdef __cplusplus
}
#endif

#endif
