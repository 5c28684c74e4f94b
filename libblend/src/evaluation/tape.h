/* The compiled evaluator: a flat instruction tape over registers.
 *
 * Compilation (compile.c) walks the scene DAG once from the root, carrying
 * the world -> local affine map; each distinct (node, map) pair becomes one
 * instruction, so shared defs stay shared and transforms are folded into the
 * primitives (group nodes vanish). Instructions are in dependency order and
 * write registers assigned by last use, so the register file stays small.
 *
 * Evaluation (eval_points.c) runs the tape over chunks of LB__CHUNK points:
 * each register holds value and gradient for a chunk as four arrays
 * (structure of arrays), primitives run as tight loops over the chunk.
 * Bounds (eval_bounds.c) run the same tape over intervals. */
#ifndef LIBBLEND_TAPE_H
#define LIBBLEND_TAPE_H

#include "../scene/scene_internal.h"

#include <stdint.h>

#define LB__CHUNK 64

enum lb__code {
    LB__I_PRIM = 0,  /* general primitive with affine map */
    LB__I_ELLIPSOID, /* zero-convention ellipsoid, translation-only map folded into c */
    LB__I_OP         /* operator node */
};

typedef struct lb__instr {
    int code;
    uint32_t dst; /* output register */
    /* primitives */
    lb_primitive prim;
    lb__affine A; /* world -> primitive frame (operators: -> the node's frame) */
    int identity;
    /* operators: the operator and its parameters (the tape's own copy) and
     * source registers */
    lb__op *op;
    uint32_t *src;  /* k argument registers, then k bounding registers (bounded) */
    uint32_t *srci; /* k argument instruction indices (bulge: prefix re-evaluation) */
    uint32_t *srcb; /* k bounding-solid instruction indices (bounded), else NULL */
    uint32_t *cone; /* bulge, local_union: the instructions each argument depends on, in tape order,
                       argument 0's ncone[0] then argument 1's ncone[1] (re-run for the
                       Hessian terms) */
    uint32_t ncone[2];
    double cost;               /* instruction runs per point, reruns included (the cost model) */
    struct lb__curves *curves; /* local_union: intersection curves, blending volumes */
    const void *node;          /* the scene node it came from: an identity for the exports,
                                  never followed */
    int fast;                  /* LB__FAST_* */
    int mode;                  /* exponent mode for the fast kernels */
    double lip;                /* primitives: Lipschitz factor of rho in the primitive frame */
    double ia[3];              /* LB__I_ELLIPSOID: the reciprocals of its semi-axes */
    size_t aoff;               /* operators: offset of this instruction's slots in a plan's act */
} lb__instr;

enum { LB__FAST_NONE = 0, LB__FAST_DISPLACEMENT, LB__FAST_CONIC, LB__FAST_SCALE, LB__FAST_MINMAX };

struct lb_evaluator {
    lb_convention conv;
    lb__instr *ins;
    size_t n;
    size_t nregs;
    uint32_t out;        /* register of the root */
    size_t total_k;      /* sum of operator arities */
    size_t kmax;         /* largest operator arity (sizes the scratch after the registers) */
    int cullable;        /* some operator can drop arguments per box (lb__bounds_pass) */
    double cost;         /* instruction runs per point for the whole tape (the cost model) */
    double compile_cost; /* instruction runs the local unions' curve finding took */
    /* a local union's blending volumes of radius R below this are not
     * blended: the clean union there (0 for every compiled evaluator; the
     * mesher's copy with sharp features sets it, mesher.c) */
    double sharp_below;
};

/* What one box needs (argument culling, libfive-style tape specialisation):
 * need[i] says whether instruction i contributes to the root anywhere in the
 * box, and list[0..nlist) names those i in tape order (need[i] is 1 for
 * exactly the listed i), so passes and runs under a plan cost what the plan
 * keeps, not the tape's length; act + ins[i].aoff lists the nact[i]
 * arguments of operator i that can contribute (the others provably leave
 * value and gradient unchanged). */
typedef struct lb__plan {
    uint8_t *need;
    uint16_t *nact;
    uint16_t *act;
    uint32_t *list;
    uint32_t nlist;
} lb__plan;

/* A plan with nothing needed yet (allocated for ev; NULL members and
 * LB_ERR_NO_MEMORY when memory is short). */
LB_INTERNAL lb_status lb__plan_alloc(const lb_evaluator *ev, lb__plan *P, lb_error *err);

/* A plan kept small, for many boxes at once (the mesher's blocks): the
 * listed instructions, then each listed operator's argument list.
 * lb__cplan_make allocates both in one block (act right after list), which
 * lb__cplan_free frees. */
typedef struct lb__cplan {
    uint32_t nlist, nact_total;
    uint32_t *list;
    uint16_t *act;
} lb__cplan;
LB_INTERNAL lb_status lb__cplan_make(const lb_evaluator *ev, const lb__plan *P, lb__cplan *C,
                                     lb_error *err);
LB_INTERNAL void lb__cplan_free(lb__cplan *C);
/* n plans made compact into C[0..n) in one allocation, returned (free it
 * once, not the plans one by one); NULL when out of memory. */
LB_INTERNAL void *lb__cplan_pack(const lb_evaluator *ev, const lb__plan *P, size_t n, lb__cplan *C);

/* Interval pass over the box centre bc, half-size br: R (nregs entries)
 * receives every register's interval; the root's is R[ev->out]. With a plan,
 * also decides argument culling and what each instruction is needed for. */
LB_INTERNAL void lb__bounds_pass(const lb_evaluator *ev, const double bc[3], const double br[3],
                                 lb__iv *R, lb__plan *plan);

/* The pass over a box inside the box a parent plan was made for: only the
 * instructions and blend arguments the parent kept (eval_bounds.c); child
 * (NULL for none) receives the smaller box's plan. */
LB_INTERNAL void lb__bounds_pass_sub(const lb_evaluator *ev, const lb__plan *parent,
                                     const double bc[3], const double br[3], lb__iv *R,
                                     lb__plan *child);

/* Run instructions list[0..nlist) (tape order, no culling) on n <= LB__CHUNK
 * points into regs: one argument's cone, at compile time (local_curves.c). */
LB_INTERNAL lb_status lb__tape_run_list(const lb_evaluator *ev, const uint32_t *list, size_t nlist,
                                        size_t n, const double *x, const double *y, const double *z,
                                        double *regs, lb_error *err);
/* The interval pass over instructions list[0..nlist) only (R as above). */
LB_INTERNAL void lb__bounds_pass_list(const lb_evaluator *ev, const uint32_t *list, size_t nlist,
                                      const double bc[3], const double br[3], lb__iv *R);

/* A child's cone reduced over a box (cone.c): the instructions that can
 * matter there, copied with registers of their own; local and clean unions
 * that pass one argument through over the whole box are dropped and their
 * readers read that argument. ev is a shallow copy of the evaluator with
 * this sub-tape as its instructions (run it with lb__tape_run_counted,
 * bound it with lb__bounds_pass); out is the register of the cone's value;
 * weight its instruction runs per point (a local union counts
 * LB_LOCAL_RUN_WEIGHT). The rest is scratch, kept from box to box. */
typedef struct lb__cone {
    lb_evaluator ev;
    uint32_t out;
    double weight;
    int reduced; /* 0: the cone holds bulge elimination, run it as it stands */
    int copied;  /* 0: more than 3/4 kept, not copied (ev, out, weight unset): run the source */
    lb__iv root; /* the cone's value over the box (the pass's interval) */
    lb__instr *ins;
    uint32_t *src, *srcq, *alias, *reg, *prod, *last, *freel, *grp;
    uint8_t *need;
    lb__iv *ivq, *R;
    size_t cap_ins, cap_src, cap_srcq, cap_alias, cap_reg, cap_prod, cap_last, cap_freel, cap_need,
        cap_q, cap_R, cap_grp;
} lb__cone;
/* Reduce instructions list[0..n) of ev (list NULL: ev's first n; tape
 * order, the cone's value last) over the box centre bc, half-size br, into
 * S (zeroed before first use, reused after). LB_ERR_NO_MEMORY when memory
 * is short. */
LB_INTERNAL lb_status lb__cone_reduce(const lb_evaluator *ev, const uint32_t *list, size_t n,
                                      const double bc[3], const double br[3], lb__cone *S,
                                      lb_error *err);
LB_INTERNAL void lb__cone_free(lb__cone *S);
/* does a blending volume of these curves reach the box? (conservative) */
LB_INTERNAL int lb__local_reaches(const struct lb__curves *C, const double bc[3],
                                  const double br[3]);

/* One intersection component and its blending volume (local_curves.c). */
typedef struct lb__component {
    size_t first, count; /* vertices [first, first + count) */
    int closed;
    double length, diameter, R, v1, v2, d1, d2, p, q;
} lb__component;

typedef struct bvh_node {
    double lo[3], hi[3];
    uint32_t left, right; /* children, or (first, count) of segments when leaf */
    int leaf;
} bvh_node;

struct lb__curves {
    size_t nv, ncomp, nseg, nnodes;
    double *pts; /* 3 per vertex */
    lb__component *comp;
    uint32_t *seg;  /* 2 vertex indices per segment */
    uint32_t *segc; /* component of each segment */
    bvh_node *bvh;
    double rmax; /* largest R */
    double scene_size;
    /* what finding them took and where (lb_evaluator_create_reusing copies
     * curves found inside the same bounds, and counts their cost again) */
    double cost;
    double bmin[3], bmax[3];
};

/* The n-th local_union instruction's curves, in tape order (tests). */
LB_INTERNAL const struct lb__curves *lb__local_nth(const lb_evaluator *ev, size_t which);

/* ---- local blending (local_*.c) ----
 * After registers are assigned, every local_union instruction gets its
 * children's intersection curves (octree by intervals, segments exact on
 * each tetrahedron's linear pieces, chained, refined onto both surfaces),
 * the blending volumes' parameters and a bounding-volume hierarchy. With
 * prev (may be NULL), a local union whose record (its content, and its
 * arguments and cones matched deep, records.h) equals one of prev's, inside
 * the same bounds, gets a copy of prev's curves instead: finding them is
 * deterministic, so the copy is what finding them would give, bit for bit;
 * *reused (may be NULL) counts them. */
LB_INTERNAL lb_status lb__local_prepare(lb_evaluator *ev, const lb_scene *scene,
                                        const lb_evaluator *prev, size_t *reused, lb_error *err);
LB_INTERNAL void lb__curves_free(struct lb__curves *c);
/* Values and gradients of a local_union or clean_union over a chunk. */
LB_INTERNAL lb_status lb__local_run(const lb_evaluator *ev, const lb__instr *in, size_t n,
                                    const double *x, const double *y, const double *z, double *regs,
                                    lb_error *err);
/* An interval containing the node over the box, from its children's. */
LB_INTERNAL void lb__local_bounds(const lb_evaluator *ev, const lb__instr *in, const lb__iv x[2],
                                  const double bc[3], const double br[3], lb__iv *out);

/* The reference walk (lb_scene_eval_reference) that also walks local
 * unions: inside their blending volumes it takes the curves ev (compiled
 * from s) found, by brute force over every segment (tests). */
/* the reference walk of one node (reference.c): Ap maps world
 * coordinates to the node's parent frame; ev is needed for local_union */
LB_INTERNAL lb_status lb__ref_eval(const lb__node *n, lb_convention conv, const lb__affine *Ap,
                                   const lb_evaluator *ev, const double X[3], double *v,
                                   double g[3], lb_error *err);

LB_INTERNAL lb_status lb__scene_eval_walk(const lb_scene *s, const lb_evaluator *ev,
                                          const double X[3], double *value, double grad[3],
                                          lb_error *err);

/* lb_evaluator_bounds without its coordinate limit: the mesher's closing
 * layer lies half a cell beyond a region that may reach the limit. */
LB_INTERNAL lb_status lb__bounds_box(const lb_evaluator *ev, const double bmin[3],
                                     const double bmax[3], double *lo, double *hi, lb_error *err);

/* Centre and half-size of a box, the half-size rounded up to cover it. */
static inline void lb__box_centre(const double bmin[3], const double bmax[3], double bc[3],
                                  double br[3]) {
    for (int d = 0; d < 3; ++d) {
        bc[d] = 0.5 * (bmin[d] + bmax[d]);
        br[d] = 0.5 * (bmax[d] - bmin[d]);
        /* the centre is rounded: cover both ends exactly */
        const double a = fabs(bc[d] - bmin[d]), b = fabs(bmax[d] - bc[d]);
        const double e = (a > b ? a : b) * (1.0 + 1e-15);
        if (e > br[d]) br[d] = e;
    }
}

/* Run the whole tape, without culling, on n <= LB__CHUNK points into regs
 * (nregs * 4 * LB__CHUNK doubles), adding to *count (may be NULL) one per
 * instruction run, bulge re-runs included: the tests hold the cost model to
 * what the evaluator really does. */
LB_INTERNAL lb_status lb__tape_run_counted(const lb_evaluator *ev, size_t n, const double *x,
                                           const double *y, const double *z, double *regs,
                                           size_t *count, lb_error *err);
/* The same for the instructions a plan needs, with culled arguments skipped. */
LB_INTERNAL lb_status lb__tape_run_plan(const lb_evaluator *ev, const lb__plan *plan, size_t n,
                                        const double *x, const double *y, const double *z,
                                        double *regs, lb_error *err);

/* Evaluation of many batches of points inside one box under one plan, the
 * box's plan made beforehand (the mesher's block selection): any number of
 * runs (the mesher's node values and refinement rounds of one block). */
typedef struct lb__boxeval {
    lb__plan plan;
    double *regs;
    lb__iv *iv; /* the box's interval registers (scratch for sub-box passes afterwards) */
} lb__boxeval;
/* E for boxes whose plans were made beforehand (lb__cplan_make), reused
 * from box to box: allocated for ev with an empty plan (NULL members and
 * LB_ERR_NO_MEMORY when memory is short), then loaded with a box's plan C
 * (no allocation, no interval pass; any earlier plan of E's is replaced). */
LB_INTERNAL lb_status lb__boxeval_alloc(const lb_evaluator *ev, lb__boxeval *E, lb_error *err);
LB_INTERNAL void lb__boxeval_load(const lb_evaluator *ev, const lb__cplan *C, lb__boxeval *E);
LB_INTERNAL lb_status lb__boxeval_run(const lb_evaluator *ev, lb__boxeval *E, size_t n,
                                      const double *x, const double *y, const double *z, double *v,
                                      double *gx, double *gy, double *gz, lb_error *err);
LB_INTERNAL void lb__boxeval_free(lb__boxeval *E);
/* lb_evaluator_eval's values for n <= LB__FEW points on one thread, the
 * same bits (the same plans: of the points' box, then of each chunk's
 * within it), in E's registers and plan and outer (a plan allocated for
 * ev) instead of memory of its own: for the few points the mesher
 * evaluates after its blocks (lb__feature_unfold), whose scratch would
 * otherwise be fresh pages each time. E's plan is replaced. */
#define LB__FEW (4 * LB__CHUNK)
LB_INTERNAL lb_status lb__eval_few(const lb_evaluator *ev, lb__boxeval *E, lb__plan *outer,
                                   size_t n, const double *x, const double *y, const double *z,
                                   double *v, double *gx, double *gy, double *gz, lb_error *err);
/* A box inside E's box: E's plan becomes that box's (one sub-box pass under
 * the current plan; the culling only tightens), for the runs that follow.
 * Every later point must lie in [bmin, bmax]. */
LB_INTERNAL void lb__boxeval_narrow(const lb_evaluator *ev, lb__boxeval *E, const lb__plan *outer,
                                    const double bmin[3], const double bmax[3]);
/* P (allocated for ev, lb__plan_alloc) becomes a copy of from, without
 * allocating: E's plan kept so that E can be narrowed again from it. */
LB_INTERNAL void lb__plan_load(const lb_evaluator *ev, const lb__plan *from, lb__plan *P);
LB_INTERNAL void lb__plan_free(lb__plan *P);
/* How many primitives the plan runs per point. */
LB_INTERNAL size_t lb__plan_prims(const lb_evaluator *ev, const lb__plan *P);

static inline double *lb__reg(double *regs, uint32_t r, int comp) {
    return regs + ((size_t)r * 4u + (size_t)comp) * LB__CHUNK;
}

/* Per-argument scratch of the operators lives after the registers, in the
 * caller's allocation, so an operator of any arity needs no stack arrays
 * and no allocation of its own: a point register file is lb__regs_len(ev)
 * doubles (the registers, then LB__OP_SCRATCH doubles per argument of the
 * widest operator, from lb__op_scratch), an interval register file
 * lb__ivs_len(ev) intervals (then LB__IV_SCRATCH doubles per argument, from
 * lb__iv_scratch). */
#define LB__OP_SCRATCH 24
#define LB__IV_SCRATCH 16
static inline size_t lb__regs_len(const lb_evaluator *ev) {
    return ev->nregs * 4u * LB__CHUNK + LB__OP_SCRATCH * ev->kmax;
}
static inline double *lb__op_scratch(const lb_evaluator *ev, double *regs) {
    return regs + ev->nregs * 4u * LB__CHUNK;
}
static inline size_t lb__ivs_len(const lb_evaluator *ev) {
    return ev->nregs + LB__IV_SCRATCH / 2 * ev->kmax;
}
static inline double *lb__iv_scratch(const lb_evaluator *ev, lb__iv *R) {
    return (double *)(void *)(R + ev->nregs);
}

#endif
