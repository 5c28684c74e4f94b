/* The functions families.def names, one set per row: apply (apply.c),
 * interval and cull (intervals.c). Only the registry's own files include
 * this; everything else calls lb__op_apply, lb__op_interval and
 * lb__op_cull (registry.h), which go through the rows. */
#ifndef LIBBLEND_FAMILY_FNS_H
#define LIBBLEND_FAMILY_FNS_H

#include "registry.h"

#define LB__ROW(ID, name, conv, ops, kmin, kmax, bulge, select, flags, keys, params, shape, apply, \
                interval, cull, form, blurb, ...)                                                  \
    LB_INTERNAL lb_status apply(const lb__op *, lb_convention, const double *, const double *,     \
                                const double *, double *, double *, double *, double *,            \
                                lb_error *);
#include "families.def"
#undef LB__ROW

LB_INTERNAL void lb__iv_corners(const lb__op *, lb_convention, const lb__iv *, const lb__iv *,
                                lb__iv *, double *);
LB_INTERNAL void lb__iv_bounded(const lb__op *, lb_convention, const lb__iv *, const lb__iv *,
                                lb__iv *, double *);
LB_INTERNAL void lb__iv_select(const lb__op *, lb_convention, const lb__iv *, const lb__iv *,
                               lb__iv *, double *);
LB_INTERNAL void lb__iv_perlin(const lb__op *, lb_convention, const lb__iv *, const lb__iv *,
                               lb__iv *, double *);
LB_INTERNAL void lb__iv_complement(const lb__op *, lb_convention, const lb__iv *, const lb__iv *,
                                   lb__iv *, double *);
LB_INTERNAL uint16_t lb__cull_reach(const lb__op *, const lb__iv *, uint16_t *);
LB_INTERNAL uint16_t lb__cull_select(const lb__op *, const lb__iv *, uint16_t *);

#endif
