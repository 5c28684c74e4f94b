/* libblend volumes: a scene's field as a sparse narrow-band level set on a
 * voxel lattice, the form in which OpenVDB files, Blender's volume objects
 * and Houdini's VDB nodes exchange surfaces (`blendtool vdb` writes it as a
 * .vdb file; docs/volumes.md).
 *
 * Contract (stated once for the whole header):
 *  - lb_level_set_create reads a compiled evaluator (read-only, so several
 *    level sets of one evaluator may be built at once) and returns a level
 *    set the caller frees with lb_level_set_free, the only free function.
 *    All arrays belong to it.
 *  - The lattice: voxel (i, j, k) sits at the point (i h, j h, k h), h the
 *    voxel size. Index space is world space divided by h with no offset, so
 *    level sets of a scene at one voxel size line up with each other (the
 *    frames of an animation) and with OpenVDB's linear transform of voxel
 *    size h. The voxels are those of the region [bmin, bmax]: indices
 *    ceil(bmin / h) .. floor(bmax / h) on each axis (imin .. imax).
 *  - Leaves: the voxels are grouped in blocks of 8^3 whose first index is a
 *    multiple of 8 on each axis (OpenVDB's leaf nodes). A leaf is computed
 *    only when the field's interval bounds over its voxels' box, grown by
 *    the band on every side, do not exclude the surface (the octree
 *    descent the mesher's block selection uses), and kept when one of its
 *    voxels is active. Leaves are in increasing (x, y, z) order of their
 *    first voxel, x slowest.
 *  - Values: phi is the field with phi < 0 inside (zero convention: phi =
 *    f; soft: phi = 0.5 - f). A voxel's value is the first-order distance
 *    estimate phi / |grad phi| in world units, clamped to [-background,
 *    background] (background = band * h); it is active when its estimate
 *    is strictly inside that range. Inactive voxels hold +-background with
 *    the sign of phi there (a vanishing or non-finite gradient counts as
 *    far). The sign of every value is the sign of phi at its voxel (0
 *    where phi is 0). Voxels outside the kept leaves are not stored: a
 *    reader decides their sign from the band (OpenVDB's signed flood fill).
 *  - The output does not depend on the thread count, bit for bit.
 *  - Threads: opt->threads (0 = one per online CPU, 1 = the calling thread
 *    only). No callbacks.
 *  - Limits: at most LB_LEVEL_SET_MAX_VOXELS_PER_AXIS voxels per axis, the
 *    region within LB_LEVEL_SET_MAX_INDEX voxels of the origin,
 *    band 1 .. LB_LEVEL_SET_MAX_BAND voxels, the memory the leaves take
 *    capped (opt->max_memory); a run over a limit fails before the large
 *    allocations with a message naming the limit and what would fit. */
#ifndef LIBBLEND_VOLUME_H
#define LIBBLEND_VOLUME_H

#include "scene.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LB_LEVEL_SET_MAX_VOXELS_PER_AXIS 8192
#define LB_LEVEL_SET_MAX_BAND 32.0
/* |coordinate| / voxel size of the region's corners (voxel indices are
 * 32-bit, as in OpenVDB) */
#define LB_LEVEL_SET_MAX_INDEX (1 << 30)
#define LB_LEVEL_SET_DEFAULT_BAND 3.0 /* OpenVDB's default half width */
#define LB_LEVEL_SET_DEFAULT_RESOLUTION 128
#define LB_LEVEL_SET_DEFAULT_MAX_MEMORY ((size_t)8 << 30) /* 8 GiB */
#define LB_LEVEL_SET_LEAF 8                               /* voxels per leaf side */
#define LB_LEVEL_SET_LEAF_VOXELS 512

/* flags: extra per-voxel data of the kept leaves */
#define LB_LEVEL_SET_FIELD 1u    /* the field f itself (lb_level_set.fields) */
#define LB_LEVEL_SET_GRADIENT 2u /* f's gradient (lb_level_set.gradients) */

typedef struct lb_level_set_options {
    double bmin[3], bmax[3];    /* the region (required: bmin < bmax on every axis) */
    double voxel_size;          /* > 0: the voxel size h; 0: from resolution */
    unsigned resolution;        /* voxels along the region's longest side (h = side / resolution) */
    double band;                /* half width of the band in voxels, 1 .. LB_LEVEL_SET_MAX_BAND */
    unsigned flags;             /* LB_LEVEL_SET_* */
    int threads;                /* 0 = one per online CPU, 1 = calling thread only */
    size_t max_memory;          /* bytes the leaves may take; 0 = LB_LEVEL_SET_DEFAULT_MAX_MEMORY */
    const volatile int *cancel; /* may be NULL; non-zero cancels (from any thread) */
} lb_level_set_options;

typedef struct lb_level_set {
    double voxel_size;        /* h */
    double band;              /* in voxels */
    float background;         /* band * h */
    int32_t imin[3], imax[3]; /* the region's voxel indices, inclusive */
    size_t nleaves;
    size_t nactive;   /* active voxels over all leaves */
    int32_t *origins; /* 3 per leaf: the index of its first voxel (multiples of 8) */
    /* 512 per leaf: voxel (x, y, z) of the leaf (0..7 each) at x * 64 + y * 8 + z */
    float *values;
    uint64_t *active;  /* 8 per leaf: voxel n active when bit n % 64 of word n / 64 is set */
    float *fields;     /* LB_LEVEL_SET_FIELD: 512 per leaf, f (voxels outside the region: 0) */
    float *gradients;  /* LB_LEVEL_SET_GRADIENT: 3 per voxel, grad f */
    size_t nevaluated; /* voxels whose field was evaluated (the cost) */
} lb_level_set;

/* Defaults: resolution LB_LEVEL_SET_DEFAULT_RESOLUTION, band
 * LB_LEVEL_SET_DEFAULT_BAND, all CPUs, the default memory cap, no extra
 * data; the region is empty (bmin = bmax = 0) and must be set. */
LB_API void lb_level_set_options_init(lb_level_set_options *opt);

/* The narrow-band level set of ev's field over the region (the contract
 * above). LB_ERR_INVALID_ARGUMENT for options out of range (the message
 * names the option and its allowed range) and when the leaves near the
 * surface would take more than the memory cap (found during the leaf
 * selection, before the leaves' arrays are allocated), LB_ERR_NO_MEMORY when
 * an allocation fails, LB_ERR_CANCELLED when *opt->cancel became non-zero; *out is
 * NULL on failure. */
LB_API lb_status lb_level_set_create(const lb_evaluator *ev, const lb_level_set_options *opt,
                                     lb_level_set **out, lb_error *err);
LB_API void lb_level_set_free(lb_level_set *ls);

#ifdef __cplusplus
}
#endif

#endif
