/* The Kuhn (Freudenthal) split of a grid cell into six tetrahedra, shared
 * by the tetrahedral mesher (meshing/tetra.c) and the local blend's curve
 * tracing (evaluation/local_curves.c).
 *
 * Convention: a cell's corner c in 0..7 sits at offset (c & 1, (c >> 1) & 1,
 * (c >> 2) & 1) cells from the cell's first node. Each tetrahedron is a
 * monotone path from corner 0 to corner 7 along the cell's edges, one axis
 * per step: 0 -> e_a -> e_a + e_b -> 7 for the six orders of the axes. The
 * six share the diagonal 0-7, and neighbouring cells split their common face
 * along the same diagonal, so the tetrahedra of a grid fit face to face. */
#ifndef LB_KUHN_H
#define LB_KUHN_H

#include <stdint.h>

static const uint8_t LB__KUHN[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                       {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

#endif
