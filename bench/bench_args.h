/* The mesh options the meshing benchmarks take at the end of their
 * command lines, in this order: [--features | --corner-normals]
 * [--simplify TOL] [--coarse-first] (bench_mesh.c, bench_incremental.c).
 * Each one found is taken off argc and put into *flags or *simplify. */
#ifndef LIBBLEND_BENCH_ARGS_H
#define LIBBLEND_BENCH_ARGS_H

#include <libblend/libblend.h>

#include <stdlib.h>
#include <string.h>

static inline void bench_mesh_args(int *argc, char **argv, unsigned *flags, double *simplify) {
    if (*argc > 1 && strcmp(argv[*argc - 1], "--coarse-first") == 0) {
        *flags |= LB_MESH_COARSE_FIRST;
        --*argc;
    }
    if (*argc > 2 && strcmp(argv[*argc - 2], "--simplify") == 0) {
        *simplify = atof(argv[*argc - 1]);
        *argc -= 2;
    }
    if (*argc > 1 && strcmp(argv[*argc - 1], "--features") == 0) {
        *flags |= LB_MESH_FEATURES;
        --*argc;
    } else if (*argc > 1 && strcmp(argv[*argc - 1], "--corner-normals") == 0) {
        *flags |= LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS;
        --*argc;
    }
}

#endif
