/* The interval octree's descent, shared by the mesher's block selection
 * (meshing/mesher.c) and the local blend's cell search
 * (evaluation/local_curves.c): an integer box [lo, hi) of cells is visited,
 * and while the visit keeps it, halved along its longest side (the lower
 * half first) down to single cells. What a visit learns for its halves (a
 * plan, a reduced cone) it keeps by depth in its own context. Not
 * installed. */
#ifndef LIBBLEND_BOXTREE_H
#define LIBBLEND_BOXTREE_H

#include "internal.h"

#include <stdint.h>

/* One box: cell says it is a single cell (nothing to halve); *split = 1
 * asks for its halves (ignored for a cell). A failure stops the descent. */
typedef lb_status (*lb__box_visit)(void *ctx, const uint32_t lo[3], const uint32_t hi[3], int depth,
                                   int cell, int *split);

/* Depths of a descent from depth 0 over n[0] x n[1] x n[2] cells: each
 * level halves one side, so one per doubling of each side, plus the root. */
static inline int lb__box_depths(const uint32_t n[3]) {
    int d = 1;
    for (int a = 0; a < 3; ++a)
        for (uint32_t s = 1; s < n[a]; s *= 2) ++d;
    return d;
}

/* The descent from [lo, hi) at depth (each level one more); depth grows by
 * one per halving, so it is at most the sum of log2 of the sides plus one. */
static inline lb_status lb__box_descend(void *ctx, lb__box_visit visit, const uint32_t lo[3],
                                        const uint32_t hi[3], int depth) {
    int axis = -1;
    uint32_t span = 1;
    for (int d = 0; d < 3; ++d)
        if (hi[d] - lo[d] > span) {
            span = hi[d] - lo[d];
            axis = d;
        }
    int split = 0;
    lb_status s = visit(ctx, lo, hi, depth, axis < 0, &split);
    if (s || !split || axis < 0) return s;
    uint32_t mid[3] = {hi[0], hi[1], hi[2]}, lo2[3] = {lo[0], lo[1], lo[2]};
    mid[axis] = lo[axis] + span / 2;
    lo2[axis] = mid[axis];
    s = lb__box_descend(ctx, visit, lo, mid, depth + 1);
    return s ? s : lb__box_descend(ctx, visit, lo2, hi, depth + 1);
}

#endif
