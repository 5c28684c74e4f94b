/* Meshing internals (mesh.h is the contract; docs/meshing.md the method).
 *
 * Naming: the field meshed is phi, with phi < 0 inside in both conventions
 * (zero: phi = f; soft: phi = 0.5 - f), and, for a closed mesh, phi is
 * intersected with the region box: phi_c = max(phi, g), g the box's
 * distance-like function (negative inside). Grid nodes are (gx, gy, gz)
 * with linear index (gz * N[1] + gy) * N[0] + gx; a grid edge runs from a
 * node to the node + d, d a non-zero 0/1 offset given as a bit mask
 * (bit 0 = x, 1 = y, 2 = z), and its key is node index * 8 + mask. */
#ifndef LIBBLEND_MESH_INTERNAL_H
#define LIBBLEND_MESH_INTERNAL_H

#include "../common/internal.h"
#include "../evaluation/tape.h"

#include <libblend/mesh.h>

#include <stdint.h>

#define LB__MB 8 /* cells per block side */

typedef struct lb__grid {
    double origin[3]; /* node (0,0,0) */
    double h[3];      /* cell size per axis */
    uint32_t cells[3];
    uint32_t N[3]; /* nodes per axis = cells + 1 */
    int closed;    /* phi_c = max(phi, box) */
    double bmin[3], bmax[3];
    int soft;
} lb__grid;

/* One block of LB__MB^3 cells (fewer at the far end of the grid). */
typedef struct lb__block {
    uint32_t b[3];  /* block coordinates */
    uint32_t nc[3]; /* cells per axis in this block */
    uint64_t id;    /* linear block index (sort key) */
    double *vals;   /* (nc+1)^3 node values of phi_c, x fastest */
    double *grads;  /* their gradients, 3 per node */
    uint8_t *nmask; /* nodes evaluated (corners of cells that may cross) */
    uint8_t *cmask; /* cells that may cross the surface, nc[0] * nc[1] * nc[2] */
    /* output: vertices keyed by grid edge, triangles by local vertex index */
    size_t nv, nt;
    uint64_t *vkey;
    double *vpos, *vnrm;
    uint32_t *tri;
} lb__block;

static inline uint64_t lb__node_index(const lb__grid *g, uint64_t x, uint64_t y, uint64_t z) {
    return (z * g->N[1] + y) * g->N[0] + x;
}

static inline void lb__node_pos(const lb__grid *g, uint64_t x, uint64_t y, uint64_t z,
                                double X[3]) {
    X[0] = g->origin[0] + (double)x * g->h[0];
    X[1] = g->origin[1] + (double)y * g->h[1];
    X[2] = g->origin[2] + (double)z * g->h[2];
}

/* The world box of a block's nodes, widened by a hair for rounding. */
LB_INTERNAL void lb__block_box(const lb__grid *g, const lb__block *B, double bmin[3],
                               double bmax[3]);

/* phi_c and its gradient from the field's value and gradient at X. */
LB_INTERNAL double lb__mesh_phi(const lb__grid *g, const double X[3], double f, const double gf[3],
                                double gphi[3]);

/* Marching tetrahedra over one block whose node values are final: finds the
 * crossing edges, refines a vertex on each (lb__refine_edges) and writes the
 * block's vertices and triangles. */
LB_INTERNAL lb_status lb__mesh_block(const lb_evaluator *ev, const lb__grid *g, lb__block *B,
                                     lb_error *err);

/* Safeguarded, batched root solve of phi_c along n grid edges: a[i] inside
 * (phi < 0), b[i] outside, pa/pb their values and ga/gb their gradients
 * (3 per edge), all inside block B; writes the surface points and unit
 * normals. */
LB_INTERNAL lb_status lb__refine_edges(const lb_evaluator *ev, const lb__grid *g,
                                       const lb__block *B, size_t n, const double *a,
                                       const double *b, const double *pa, const double *pb,
                                       const double *ga, const double *gb, double *pos, double *nrm,
                                       lb_error *err);

#endif
