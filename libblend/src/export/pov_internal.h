/* The POV-Ray writer's shared parts (export/pov*.c): pov.c writes the
 * document (camera, lights, isosurface, numbers), pov_nodes.c the node DAG
 * as #declare'd functions, pov_local.c a local_union's blending volumes,
 * pov_material.c the material rule as textures. Not installed. */
#ifndef LIBBLEND_POV_INTERNAL_H
#define LIBBLEND_POV_INTERNAL_H

#include "../evaluation/tape.h"
#include "libblend/output.h"

#include <libblend/mesh.h>
#include <libblend/pov.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* the name every message of the writer starts with */
#define FN "lb_scene_write_pov"

/* the text being written: grows as needed; oom once memory ran out (every
 * later append does nothing) */
typedef struct sbuf {
    char *s;
    size_t n, cap;
    int oom;
} sbuf;

/* appends printf-style text to b */
LB_INTERNAL void lb__pov_sb(sbuf *b, const char *fmt, ...) LB_PRINTF(2, 3);
/* user text in a comment: printable ASCII only */
LB_INTERNAL void lb__pov_comment(sbuf *b, const char *label, const char *text);
/* array[k] {v[0], ...} (fallback for every element when v is NULL) */
LB_INTERNAL void lb__pov_array(sbuf *b, size_t k, const double *v, double fallback);
/* the three coordinates y = M x + t as function arguments */
LB_INTERNAL void lb__pov_affine_args(sbuf *b, const lb__affine *A);
/* short names inside the writer */
#define sb lb__pov_sb
#define arr lb__pov_array
#define affine_args lb__pov_affine_args

/* What the node writer carries through the DAG. */
typedef struct pctx {
    sbuf *b;
    const lb_scene *sc;
    const lb__node **done;
    int *ids;
    size_t ndone, cap;
    int next;
    double eps; /* central-difference step of the bulge macros */
    const lb_evaluator *ev;
    lb__affine A;            /* world -> the parent frame of the node being written */
    lb__affine *doneA;       /* the frame each written node was written for */
    const lb__node **lnodes; /* nodes known to hold a local_union (or not: lflag) */
    int *lflag;
    size_t nl, lcap;
    lb_error *err;
    int ntex; /* material textures written (tex) */
} pctx;

/* ---- pov_nodes.c ---- */
/* n written (once per node, once per node and world frame under a
 * local_union); *out receives its function number (LBn<id>) */
LB_INTERNAL lb_status lb__pov_emit(pctx *c, const lb__node *n, int *out);
/* the id n was written under for the world frame F (n's own frame), or -1 */
LB_INTERNAL int lb__pov_written_id(pctx *c, const lb__node *n, const lb__affine *F);

/* ---- pov_local.c ---- */
/* the local_union or clean_union n (arguments written as LBn<a>, LBn<d>)
 * as function <name><id> */
LB_INTERNAL lb_status lb__pov_local(pctx *c, const lb__node *n, int id, const char *name, int a,
                                    int d);

/* ---- pov_mesh.c ---- */
/* comment lines around text the number shortener leaves as it is */
#define LB_POV_VERBATIM_BEGIN "// libblend mesh data:"
#define LB_POV_VERBATIM_END "// end of libblend mesh data"
/* "mesh2 { vertex_vectors ... face_indices ... " of a mesh of ev over
 * [lo, hi] at o's mesh_resolution cells, with its mesh_features,
 * mesh_simplify and mesh_merge_flat (the caller writes the texture and
 * the closing brace); nothing and *empty = 1 when the mesh has no triangle */
LB_INTERNAL lb_status lb__pov_mesh(sbuf *b, const lb_evaluator *ev, const double lo[3],
                                   const double hi[3], const lb_pov_options *o, int *empty,
                                   lb_error *err);

/* ---- pov_material.c ---- */
#define LB_POV_MAX_TEXTURES 4096
/* name (at least 24 bytes) receives the texture of n's surface (Ap: world
 * -> n's parent frame; inh: the inherited material) */
LB_INTERNAL lb_status lb__pov_texture(pctx *c, const lb__node *n, const lb__affine *Ap, size_t inh,
                                      char *name);
/* texture { pigment ... finish ... } of m */
LB_INTERNAL void lb__pov_material_texture(sbuf *b, const lb_material *m);

#endif
