/* libblend meshing: watertight, manifold triangle meshes of a compiled scene.
 *
 * Contract (stated once for the whole header):
 *  - lb_mesh_create reads a compiled evaluator (read-only, so several meshes
 *    of one evaluator may be built at once) and returns a mesh the caller
 *    frees with lb_mesh_free, the only free function. All arrays in the mesh
 *    belong to it.
 *  - The mesh is the surface of the scene's solid (zero convention f < 0,
 *    soft convention f > 0.5) inside the region: indexed triangles with
 *    shared vertices, counter-clockwise seen from outside, every vertex on
 *    the surface (refined along its grid edge by a safeguarded root solve to
 *    |f| / |grad f| <= 1e-7 cell sizes) with its normal from the analytic
 *    gradient (with LB_MESH_FEATURES, a crease or corner point to the same
 *    tolerance, its normal the mean of its cell polygon's; and a local
 *    union's blending volume narrower than a quarter cell is meshed as the
 *    sharp union it rounds: there the vertices are on the clean union,
 *    within about the volume's radius of the surface). Closed (every
 *    edge in exactly two triangles) and 2-manifold;
 *    where the region cuts the solid the mesh is closed by a cap on the
 *    region's faces, or left open with LB_MESH_OPEN_BOUNDARY.
 *  - The output does not depend on the thread count: the same vertices and
 *    triangles in the same order, bit for bit.
 *  - Threads: opt->threads (0 = one per online CPU, 1 = the calling thread
 *    only). The progress callback runs only on the calling thread.
 *  - Limits: the region is cut into at most LB_MESH_MAX_CELLS_PER_AXIS cells
 *    per axis; the memory a run may use is capped (opt->max_memory); a run
 *    that would exceed either fails before the large allocations, with a
 *    message naming the limit and the resolution that would fit.
 *
 * Method (docs/meshing.md): the grid is split into blocks of 8^3 cells; an
 * octree over the blocks skips every box whose interval bound
 * (lb_evaluator_bounds) excludes the surface, so the cost grows with the
 * surface area, not the volume. Each remaining cell gets one polygon per
 * loop of its surface, with vertices on its 12 edges only; on a face whose
 * inside corners are diagonal, those corners are cut off separately, a rule
 * that depends on the face alone, so the two cells of a face agree and the
 * result is always a closed 2-manifold. Polygons are cut into triangles
 * through the cell's interior only. LB_MESH_TETRAHEDRA splits each cell
 * into six tetrahedra instead (about 3x the triangles). */
#ifndef LIBBLEND_MESH_H
#define LIBBLEND_MESH_H

#include "scene.h"

#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LB_MESH_MAX_CELLS_PER_AXIS 8192
#define LB_MESH_DEFAULT_RESOLUTION 128
#define LB_MESH_DEFAULT_MAX_MEMORY ((size_t)8 << 30) /* 8 GiB */
#define LB_MESH_MAX_SIMPLIFY 1.0                     /* cells: lb_mesh_options.simplify */

/* flags */
#define LB_MESH_OPEN_BOUNDARY 1u /* do not close the mesh where the region cuts the solid */
/* extract with the Kuhn split of each cell into six tetrahedra instead of
 * the default cube polygons: about 3x the triangles, the zero set of one
 * piecewise-linear function (docs/meshing.md, Method) */
#define LB_MESH_TETRAHEDRA 2u
/* keep sharp creases and corners: where the normals of a cell's surface
 * disagree (a crease of min, max, a clean or local union, a slab, the
 * region's cap), the cell gets a vertex on the crease or corner, found from
 * the normals by a least-squares fit within the cell and put on the surface;
 * still closed, manifold and independent of the thread count (docs/meshing.md,
 * Sharp features). A local union's blending volume of radius under a quarter
 * of the smallest cell side, a fillet the grid cannot hold, is meshed as the
 * clean union there (its crease kept, the fillet left out: no vertex can
 * hold it, and the fans from a vertex on it cut the sides beyond it by a
 * tenth of a cell). Not with LB_MESH_TETRAHEDRA
 * (ignored there). */
#define LB_MESH_FEATURES 4u
/* with LB_MESH_FEATURES: also a normal per side of each crease for the
 * triangle corners there (lb_mesh.corner_normals), so renderers shade the
 * crease sharp; costs a third more of the meshing time where many cells
 * are creased (docs/meshing.md, Sharp features). Ignored without features. */
#define LB_MESH_CORNER_NORMALS 8u
/* merge flat regions: where the surface is a plane (a box's side, a slab's,
 * a cylinder's cap; with LB_MESH_FEATURES their creases are mesh edges),
 * the triangles there become a triangulation of the region's outline, its
 * vertices inside and on straight creases between two flat regions gone.
 * No tolerance: every point of the surface stays where it was, and every
 * vertex is one of the unmerged mesh's; still closed, 2-manifold and
 * independent of the thread count. One thread, after the meshing; about half
 * of the meshing's work where there is something to merge, about 1 %
 * where there is not (docs/meshing.md, Flat regions). Also the first step of
 * simplify (below). */
#define LB_MESH_MERGE_FLAT 16u
/* with simplify > 0: mesh coarse first instead of collapsing edges
 * afterwards. Each whole block of the grid (8 cells a side) is meshed on
 * cells of twice the cell size wherever every coarse triangle stays within
 * simplify cells of the surface, checked against the field at each
 * triangle's centroid and edge midpoints and by how far its edges bow
 * between its vertices' normals (a check, not a bound), and on the grid's
 * own cells elsewhere: where that check fails, where a coarse cell's
 * corners could miss a part of the surface the field's bounds do not rule
 * out, and where a loop has no unfolded triangulation. The two sizes meet
 * on cells whose edges and faces are split where a fine cell is across;
 * every block's boundary faces are meshed at the grid's own size, so
 * blocks decide alone (docs/meshing.md, Coarse first). Still closed,
 * 2-manifold, free of self-intersections and independent of the thread
 * count and of the cache, every vertex on the surface. At 0.25 cells: 0.37
 * to 0.67 of the uniform triangles for 1.4-2.3x its meshing time (the
 * collapses: 0.03-0.17 of them for 5-12x, 2026-12-06). Ignored with
 * LB_MESH_FEATURES or LB_MESH_TETRAHEDRA (the blocks are meshed as without
 * it, and the collapses run). */
#define LB_MESH_COARSE_FIRST 32u

/* Called on the calling thread with the fraction of work done, in [0, 1];
 * return non-zero to cancel the run (lb_mesh_create then fails with
 * LB_ERR_CANCELLED and returns no mesh). */
typedef int (*lb_mesh_progress_fn)(double fraction, void *user);

typedef struct lb_mesh_options {
    double bmin[3], bmax[3];      /* the region (required: bmin < bmax on every axis) */
    unsigned resolution;          /* cells along the region's longest side, 1..8192 */
    double cell_size;             /* > 0: use this cell size instead of resolution */
    unsigned flags;               /* LB_MESH_* */
    int threads;                  /* 0 = one per online CPU, 1 = calling thread only */
    size_t max_memory;            /* bytes; 0 = LB_MESH_DEFAULT_MAX_MEMORY */
    lb_mesh_progress_fn progress; /* may be NULL */
    void *user;                   /* passed to progress */
    const volatile int *cancel;   /* may be NULL; non-zero cancels (from any thread) */
    /* > 0: adaptive simplification. Vertices are removed by edge collapses
     * wherever every moved triangle stays within this many cells (of the
     * smallest cell side) of the surface, checked against the field itself
     * by sampling each moved triangle at most a cell apart (64 samples
     * along an edge at most), and the removed vertex stays within as much
     * of the moved triangles; never across a crease (edges whose
     * triangles' normals differ by more than 26 degrees: with
     * LB_MESH_FEATURES, the kept creases), so corners stay. Still closed,
     * 2-manifold and independent of the thread count; every vertex stays a
     * vertex of the unsimplified mesh (on the surface). After the meshing,
     * on the same threads (regions of the grid in parallel, the seams
     * between them last); costs several times the meshing (docs/meshing.md,
     * Adaptive simplification). 0 = off; at most LB_MESH_MAX_SIMPLIFY. */
    double simplify;
} lb_mesh_options;

typedef struct lb_mesh {
    size_t nvertices;
    size_t ntriangles;
    double *positions;   /* 3 per vertex */
    double *normals;     /* 3 per vertex, unit length, pointing out of the solid */
    uint32_t *triangles; /* 3 vertex indices per triangle, counter-clockwise from outside */
    /* the grid that was used */
    double origin[3];  /* the first grid node */
    double cell[3];    /* cell size per axis (equal unless the region forced otherwise) */
    unsigned cells[3]; /* cells per axis covering the region */
    /* Shading normals per triangle corner, so a renderer shows a crease
     * sharp. With LB_MESH_CORNER_NORMALS, where a feature point's triangles lie on
     * sides of a crease (their normals more than 26 degrees apart), corner c
     * of triangle t is shaded with normals[3 * corner_normals[3 t + c] ...];
     * normals then holds nnormals entries: the nvertices vertex normals
     * first, then one per side of each such point (the field's unit gradient
     * a quarter of a cell from the point into that side). A corner's entry
     * is its own vertex or one of the normals added for that vertex alone.
     * NULL, with nnormals = nvertices, when no corner needs its own normal
     * (no crease, or not asked for): shade with the vertex normals. */
    size_t nnormals;
    uint32_t *corner_normals; /* 3 per triangle, indices into normals, or NULL */
} lb_mesh;

/* Defaults: resolution LB_MESH_DEFAULT_RESOLUTION, closed, all CPUs, the
 * default memory cap; the region is left empty (bmin = bmax = 0) and must
 * be set. */
LB_API void lb_mesh_options_init(lb_mesh_options *opt);

/* Mesh the field of ev over opt's region. On failure *out is NULL. */
LB_API lb_status lb_mesh_create(const lb_evaluator *ev, const lb_mesh_options *opt, lb_mesh **out,
                                lb_error *err);

LB_API void lb_mesh_free(lb_mesh *mesh);

/* Incremental remeshing: a cache of the last mesh's blocks, so that
 * meshing an edited scene (a primitive moved, resized or reparameterised,
 * an argument added or removed, a blend's r, p or m changed) recomputes
 * only the blocks whose field can differ and takes every other block's
 * output from the cache. The result is byte-identical to lb_mesh_create
 * with the same evaluator and options: same vertices, normals and
 * triangles in the same order.
 *
 * Which blocks are recomputed (docs/meshing.md, Incremental remeshing): a
 * block's node values, vertices and triangles are a function of the grid
 * and of its plan, the instructions and blend arguments that the interval
 * passes keep for the block's box, with their parameters. The cache keeps
 * each block's plan as the instructions' contents (primitive, transform,
 * operator and parameters, local unions' curves) and their arguments' own
 * contents, recursively; a block is taken from the cache only when its plan
 * and the plans of the blocks within two blocks after it on each axis
 * (whose values and vertices its far faces share) are identical, content
 * for content, and those blocks are kept in both meshes. Anything else
 * (another grid, region, resolution or flags, another convention) meshes
 * everything again. The passes after the blocks (sharp-feature flips,
 * corner normals, simplification) run over the whole mesh every time.
 *
 * The cache is the caller's: lb_mesh_cache_create makes an empty one,
 * lb_mesh_cache_free frees it (NULL is fine). It holds no pointer to an
 * evaluator (the last one may be freed) and about as much memory as the
 * last mesh, plus each block's plan and shared faces and the arrays a run
 * needs only while it runs, kept for the next (on a 512-sphere lattice at
 * 256 cells 14 of 234 MiB; with LB_MESH_COARSE_FIRST also each thread's
 * decision tables, about 3 MiB a thread, at most 64; lb_mesh_cache_stats.bytes). Use one cache from
 * one thread at a time (lb_mesh_create_cached uses opt->threads
 * internally); several caches may be used at once. A failed or cancelled
 * run leaves the cache's blocks as they were (the arrays it kept for the
 * next run may have grown). */
typedef struct lb_mesh_cache lb_mesh_cache;

typedef struct lb_mesh_cache_stats {
    size_t blocks;   /* blocks of the last mesh */
    size_t reused;   /* of them, taken from the cache */
    size_t recycled; /* runs so far that took at least one block from the cache */
    size_t bytes;    /* memory the cache holds */
} lb_mesh_cache_stats;

LB_API lb_status lb_mesh_cache_create(lb_mesh_cache **out, lb_error *err);
LB_API void lb_mesh_cache_free(lb_mesh_cache *cache);
/* lb_mesh_create through the cache (NULL: lb_mesh_create itself); on
 * success the cache holds this mesh's blocks. */
LB_API lb_status lb_mesh_create_cached(const lb_evaluator *ev, const lb_mesh_options *opt,
                                       lb_mesh_cache *cache, lb_mesh **out, lb_error *err);
/* Instead of lb_mesh_free for a mesh the caller is done with (any mesh
 * from lb_mesh_create or lb_mesh_create_cached; NULL is fine): the mesh is
 * freed, but the cache keeps its three arrays, and the next
 * lb_mesh_create_cached through this cache writes its output into them.
 * Their memory is then mapped already: writing a large mesh into fresh
 * memory makes the system map and zero every page, about a fifth of an
 * incremental run of a 3-million-triangle mesh (docs/meshing.md). The
 * cache keeps one mesh's arrays (a second mesh given back replaces the
 * first, which is freed); they count in lb_mesh_cache_stats.bytes until
 * used, and lb_mesh_cache_free frees them. With cache NULL: lb_mesh_free.
 * The output is the same bytes with or without a mesh given back. */
LB_API void lb_mesh_cache_recycle(lb_mesh_cache *cache, lb_mesh *mesh);
/* The cache's figures (all 0 for NULL). */
LB_API void lb_mesh_cache_stats_get(const lb_mesh_cache *cache, lb_mesh_cache_stats *out);

/* The mesh's undirected edges and the edge of every triangle corner, for
 * hosts that store edges (Blender's meshes do). Corner c of triangle t
 * (index 3t + c) runs from triangles[3t + c] to triangles[3t + (c + 1) % 3];
 * corner_edge[3t + c] is the index of that edge. Edges are numbered in order
 * of first appearance over the corners and written as (smaller vertex,
 * larger vertex) pairs, so the result depends only on the triangles.
 * Buffers are the caller's: edges has room for 3 * ntriangles pairs
 * (6 * ntriangles values; a closed mesh uses exactly half of that),
 * corner_edge for 3 * ntriangles values. *nedges receives the edge count.
 * Linear time; allocates O(nvertices + ntriangles) scratch. Fails with
 * LB_ERR_INVALID_ARGUMENT on NULL buffers or a vertex index out of range. */
LB_API lb_status lb_mesh_edges(const lb_mesh *mesh, uint32_t *edges, uint32_t *corner_edge,
                               size_t *nedges, lb_error *err);

/* Per-vertex velocities of a moving surface, for motion blur
 * (meshing/velocity.c). mesh is a mesh of ev's surface at time t; before and
 * after are the same scene at t - dt and t + dt (either may be NULL, not
 * both; they must have ev's convention). Each vertex gets the velocity of the
 * surface along its normal, -(df/dt) grad f / |grad f|^2 with df/dt a
 * central difference of before and after at the vertex (one-sided with one
 * of them), in scene units per unit of t; the motion along the surface
 * cannot be seen in the field and is zero. A vertex without a gradient or a
 * finite value gets zero. It is first order: a surface that moves further
 * than its features' size within dt, or appears or vanishes, gets velocities
 * that say little. velocities (the caller's) has room for 3 * nvertices
 * values. threads as lb_evaluator_eval. Fails with LB_ERR_INVALID_ARGUMENT
 * for NULL pointers, dt not finite and > 0, or conventions that differ. */
LB_API lb_status lb_mesh_velocities(const lb_evaluator *ev, const lb_evaluator *before,
                                    const lb_evaluator *after, const lb_mesh *mesh, double dt,
                                    int threads, double *velocities, lb_error *err);

typedef enum lb_mesh_format {
    LB_MESH_FORMAT_AUTO = 0, /* from the file name's extension */
    LB_MESH_FORMAT_PLY = 1,  /* binary little-endian PLY, float positions and vertex normals */
    LB_MESH_FORMAT_OBJ = 2,  /* Wavefront OBJ with normals (v, vn, f v//vn; corner normals) */
    LB_MESH_FORMAT_STL = 3,  /* binary STL, facet normals from the triangles */
    LB_MESH_FORMAT_GLB = 4   /* glTF 2.0 binary: POSITION, NORMAL, indices (corner normals by
                                copies of a vertex, one per normal it is shaded with) */
} lb_mesh_format;

/* Write the mesh to path through an lb_output (libblend/output.h): the file
 * appears only when everything was written, so a failure leaves no partial
 * file; symbolic links are followed, devices and FIFOs written directly,
 * modes kept. An empty mesh is a valid file in every format. Corner normals
 * (corner_normals) go to OBJ and glTF; PLY carries one normal per vertex.
 * A mesh whose triangles or corner normals name an entry out of range is
 * refused (LB_ERR_INVALID_ARGUMENT, the triangle named) before anything is
 * written. */
LB_API lb_status lb_mesh_write(const lb_mesh *mesh, const char *path, lb_mesh_format format,
                               lb_error *err);

/* The same bytes into an open binary stream (for example an lb_output's);
 * format must not be LB_MESH_FORMAT_AUTO. The stream is flushed, not closed. */
LB_API lb_status lb_mesh_write_stream(const lb_mesh *mesh, FILE *stream, lb_mesh_format format,
                                      lb_error *err);

/* The format a file name's extension names (.ply .obj .stl .glb, any case),
 * LB_MESH_FORMAT_AUTO for none of them or NULL. */
LB_API lb_mesh_format lb_mesh_format_of(const char *path);

#ifdef __cplusplus
}
#endif

#endif
