/* Interval bounds over an axis-aligned box on the compiled tape.
 *
 * The scheme (docs/design.md, "Interval bounds"):
 * - Primitives: the world box is mapped into the primitive's frame (centre
 *   and radius through |M|, an exact enclosure of the affine image). In that
 *   frame ellipsoid, LP and superquadric rho grow with each |x_i - c_i|, so
 *   the nearest and farthest corners give exact bounds; slab and half-space
 *   are linear in X (exact); cylinder, capsule and torus use their Lipschitz
 *   constant around the box centre. The kernel maps rho monotonically.
 * - Operators without bulge elimination are monotone in each argument
 *   (increasing; a difference decreases in its subtracted arguments), so the
 *   operator evaluated at the two extreme corners bounds it.
 * - Bulge elimination and bounded blends make ranges (and slopes) position
 *   functions; their bounds come from the root brackets of spec sections 4-6
 *   with the ranges at their extremes.
 * Every operator bound is widened by 1e-9 (1 + |v|) for the solvers'
 * tolerance. Unbounded stays unbounded: an end that nothing finite bounds
 * (an unknown lower end, a value beyond the core's argument range 1e100)
 * is stored as -INFINITY or +INFINITY, never as a large finite stand-in
 * that later arithmetic could cancel; every operator below either handles
 * infinite ends exactly (min, max, complement, the bulge and bounded
 * brackets) or returns an infinite end where one of its corners is
 * infinite. */
#include "../operators/bt_two.h"
#include "tape.h"

#include <stdlib.h>
#include <string.h>

typedef lb__iv iv;

#define BIG LB_MAX_ABS_ARG

/* returned by value: in registers, not through memory that the caller
 * would read back as one wide load (a stalled store forward) */
static iv prim_bounds(const lb__instr *in, const double bc[3], const double br[3]) {
    const lb_primitive *P = &in->prim;
    if (in->code == LB__I_ELLIPSOID) {
        /* zero-convention ellipsoid in world axes: nearest and farthest
         * points of the box, inline (the common case: spheres); times the
         * reciprocal semi-axes (a relative error of an ulp or two, far
         * inside the 1e-12 widening below) instead of six divisions */
        double sn = 0.0, sf = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double d = fabs(bc[i] - P->c[i]);
            const double dn = (d > br[i] ? d - br[i] : 0.0) * in->ia[i],
                         df = (d + br[i]) * in->ia[i];
            sn += dn * dn;
            sf += df * df;
        }
        const iv o = {sqrt(sn) * (1.0 - 1e-12) - 1.0, sqrt(sf) * (1.0 + 1e-12) - 1.0};
        return o;
    }
    double lc[3], lr[3];
    lb__affine_apply(&in->A, bc, lc);
    for (int i = 0; i < 3; ++i)
        lr[i] = fabs(in->A.M[3 * i]) * br[0] + fabs(in->A.M[3 * i + 1]) * br[1] +
                fabs(in->A.M[3 * i + 2]) * br[2];
    double lo = 0.0, hi = 0.0;
    switch (P->kind) {
    case LB_PRIM_ELLIPSOID:
    case LB_PRIM_LP:
    case LB_PRIM_SUPERQUADRIC: {
        double pn[3], pf[3];
        for (int i = 0; i < 3; ++i) {
            const double d = fabs(lc[i] - P->c[i]);
            pn[i] = P->c[i] + (d > lr[i] ? d - lr[i] : 0.0);
            pf[i] = P->c[i] + d + lr[i];
        }
        lo = lb_primitive_rho(P, pn, NULL);
        hi = lb_primitive_rho(P, pf, NULL);
        /* rounding in rho: keep the corner values conservative */
        lo *= 1.0 - 1e-12;
        hi *= 1.0 + 1e-12;
        break;
    }
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE: {
        const double sm =
            P->n[0] * (lc[0] - P->c[0]) + P->n[1] * (lc[1] - P->c[1]) + P->n[2] * (lc[2] - P->c[2]);
        const double sr = (fabs(P->n[0]) * lr[0] + fabs(P->n[1]) * lr[1] + fabs(P->n[2]) * lr[2]) *
                              (1.0 + 1e-12) +
                          1e-15 * fabs(sm);
        if (P->kind == LB_PRIM_SLAB) {
            lo = fabs(sm) > sr ? fabs(sm) - sr : 0.0;
            hi = fabs(sm) + sr;
        } else {
            lo = sm - sr > 0.0 ? sm - sr : 0.0;
            hi = sm + sr > 0.0 ? sm + sr : 0.0;
        }
        lo /= P->s0;
        hi /= P->s0;
        break;
    }
    default: {
        const double rc = lb_primitive_rho(P, lc, NULL);
        const double rad = sqrt(lr[0] * lr[0] + lr[1] * lr[1] + lr[2] * lr[2]) * in->lip;
        const double slack = 1e-12 * (rc + rad);
        lo = rc - rad - slack > 0.0 ? rc - rad - slack : 0.0;
        hi = rc + rad + slack;
        break;
    }
    }
    /* the kernel is increasing (zero) or decreasing (soft) in rho */
    iv o;
    if (P->kernel == LB_KERNEL_NONE) {
        o.lo = lo - 1.0;
        o.hi = hi - 1.0;
    } else {
        o.lo = lb__kernel(P->kernel, hi, NULL);
        o.hi = lb__kernel(P->kernel, lo, NULL);
    }
    return o;
}

/* An instruction's interval into its register, clamped: two scalar stores
 * (a struct copy went through the stack as two narrow stores and one wide
 * load, a stalled store forward on every instruction of every pass). */
static inline void store_iv(iv *r, iv o) {
    /* beyond the argument range (or NaN): unbounded on that side; an end
     * past the range on the other side is pulled in, which stays sound */
    r->lo = !(o.lo >= -BIG) ? -INFINITY : o.lo > BIG ? BIG : o.lo;
    r->hi = !(o.hi <= BIG) ? INFINITY : o.hi < -BIG ? -BIG : o.hi;
}

/* Per-argument scratch of the passes, after the interval registers
 * (tape.h, LB__IV_SCRATCH doubles per argument of the widest operator):
 * the arguments' and bounding values' intervals, the culled list,
 * fast_bounds' 9 and op_bounds' 2. */
typedef struct bscr {
    iv *x, *c;
    uint16_t *act;
    double *fb, *xl;
} bscr;
static bscr scratch(const lb_evaluator *ev, iv *R) {
    double *S = lb__iv_scratch(ev, R);
    const size_t K = ev->kmax;
    return (bscr){(iv *)(void *)S, (iv *)(void *)(S + 2 * K), (uint16_t *)(void *)(S + 4 * K),
                  S + 5 * K, S + 14 * K};
}

/* The union-form root of displacement or conic at finite argument values
 * (the general paths of fast_bounds, without the reciprocal sharing). */
static double blend_finite(const lb__instr *in, const double *u, const double *r, const double *p,
                           const double *m, size_t na, double *ws) {
    if (na == 1) return u[0] / m[0];
    if (in->fast == LB__FAST_DISPLACEMENT)
        return lb__bt_union_ws(na, u, r, p, m, in->mode, NULL, NULL, NULL, ws);
    return lb__conic_union(u, r, in->op->shape, m, NULL, NULL, NULL);
}

/* Displacement and conic (no bulge) on the arguments a box can reach
 * (cull's list): the culled ones are inactive at both corners, so the
 * kernel on the rest gives the same values, without re-validation. ws: 9k
 * doubles of scratch. */
static void fast_bounds(const lb__instr *in, const iv *x, const uint16_t *act, size_t na, iv *out,
                        double *ws) {
    const lb__op *n = in->op;
    const size_t K = n->k;
    double *lo = ws, *hi = lo + K, *r = hi + K, *p = r + K, *m = p + K;
    ws = m + K;
    for (size_t j = 0; j < na; ++j) {
        const iv u = lb__dual_iv(n->op, act[j], x[act[j]]);
        lo[j] = u.lo;
        hi[j] = u.hi;
        r[j] = n->r[act[j]];
        p[j] = n->p ? n->p[act[j]] : 2.0;
        m[j] = n->m[act[j]];
    }
    double v1, v2;
    /* Infinite ends: any argument at -inf takes the root to -inf (h <= u/m);
     * an argument at +inf adds nothing to T at a finite root, so the upper
     * end is the blend of the others (+inf when none is left). */
    int lo_inf = 0;
    size_t nh = 0;
    for (size_t j = 0; j < na; ++j) {
        lo_inf |= lo[j] == -INFINITY;
        nh += hi[j] != INFINITY;
    }
    if (lo_inf || nh < na) {
        iv o = {-INFINITY, INFINITY};
        if (!lo_inf) o.lo = blend_finite(in, lo, r, p, m, na, ws);
        if (nh) {
            size_t q = 0;
            for (size_t j = 0; j < na; ++j)
                if (hi[j] != INFINITY) {
                    hi[q] = hi[j];
                    r[q] = r[j];
                    p[q] = p[j];
                    m[q] = m[j];
                    ++q;
                }
            o.hi = blend_finite(in, hi, r, p, m, nh, ws);
        }
        v1 = o.lo;
        v2 = o.hi;
    } else if (na == 1) {
        v1 = lo[0] / m[0];
        v2 = hi[0] / m[0];
    } else if (in->fast == LB__FAST_DISPLACEMENT && in->mode == LB__P_TWO) {
        /* lb__bt_union_ws's p = 2 path, the reciprocals of r and m taken
         * once for both ends (the same bits) */
        double *ir = ws, *im = ws + na;
        lb__bt_recip(na, r, m, ir, im);
        v1 = lb__bt_two_union_recip(na, lo, r, m, ir, im, NULL, ws + 2 * na);
        v2 = lb__bt_two_union_recip(na, hi, r, m, ir, im, NULL, ws + 2 * na);
    } else if (in->fast == LB__FAST_DISPLACEMENT) {
        v1 = lb__bt_union_ws(na, lo, r, p, m, in->mode, NULL, NULL, NULL, ws);
        v2 = lb__bt_union_ws(na, hi, r, p, m, in->mode, NULL, NULL, NULL, ws);
    } else {
        v1 = lb__conic_union(lo, r, n->shape, m, NULL, NULL, NULL);
        v2 = lb__conic_union(hi, r, n->shape, m, NULL, NULL, NULL);
    }
    /* union form: lo <= root <= hi; the duals negate */
    if (n->op == LB_UNION) {
        out->lo = v1;
        out->hi = v2;
    } else {
        out->lo = -v2;
        out->hi = -v1;
    }
    out->lo -= 1e-9 * (1.0 + fabs(out->lo));
    out->hi += 1e-9 * (1.0 + fabs(out->hi));
}

static void plan_needs(const lb_evaluator *ev, lb__plan *plan, const lb__plan *parent) {
    for (uint32_t q = 0; q < plan->nlist; ++q) plan->need[plan->list[q]] = 0;
    const size_t m = parent ? parent->nlist : ev->n;
    plan->need[ev->n - 1] = 1;
    for (size_t q = m; q-- > 0;) {
        const size_t i = parent ? parent->list[q] : q;
        const lb__instr *in = &ev->ins[i];
        if (!plan->need[i] || in->code != LB__I_OP) continue;
        const uint16_t *act = plan->act + in->aoff;
        for (uint16_t a = 0; a < plan->nact[i]; ++a) {
            plan->need[in->srci[act[a]]] = 1;
            if ((lb__family_info(in->op->family)->flags & LB__R_BOUNDING))
                plan->need[in->srcb[act[a]]] = 1;
        }
        if (in->op->bulge) /* the Hessian terms re-run both arguments' prefixes */
            for (size_t a = 0; a < in->op->k; ++a) plan->need[in->srci[a]] = 1;
    }
    uint32_t c = 0;
    for (size_t q = 0; q < m; ++q) {
        const uint32_t i = parent ? parent->list[q] : (uint32_t)q;
        if (plan->need[i]) plan->list[c++] = i;
    }
    plan->nlist = c;
}

void lb__bounds_pass(const lb_evaluator *ev, const double bc[3], const double br[3], iv *R,
                     lb__plan *plan) {
    const bscr S = scratch(ev, R);
    iv *x = S.x, *c = S.c;
    for (size_t i = 0; i < ev->n; ++i) {
        const lb__instr *in = &ev->ins[i];
        iv o;
        if (in->code != LB__I_OP) {
            o = prim_bounds(in, bc, br);
        } else {
            const size_t k = in->op->k;
            for (size_t j = 0; j < k; ++j) x[j] = R[in->src[j]];
            if ((lb__family_info(in->op->family)->flags & LB__R_BOUNDING))
                for (size_t j = 0; j < k; ++j) c[j] = R[in->src[k + j]];
            if (in->fast == LB__FAST_DISPLACEMENT || in->fast == LB__FAST_CONIC) {
                uint16_t *act = plan ? plan->act + in->aoff : S.act;
                const uint16_t na = lb__op_cull(in->op, x, act);
                if (plan) plan->nact[i] = na;
                fast_bounds(in, x, act, na, &o, S.fb);
            } else if ((lb__family_info(in->op->family)->flags & LB__R_CLEAN_UNION)) {
                lb__local_bounds(ev, in, x, bc, br, &o);
                if (plan) plan->nact[i] = lb__op_cull(in->op, x, plan->act + in->aoff);
            } else {
                lb__op_interval(in->op, ev->conv, x, c, &o, S.xl);
                if (plan) plan->nact[i] = lb__op_cull(in->op, x, plan->act + in->aoff);
            }
        }
        store_iv(&R[in->dst], o);
    }
    if (plan) plan_needs(ev, plan, NULL);
}

/* An operator over all its arguments' intervals (no culling). */
static void all_args_bounds(const lb_evaluator *ev, const lb__instr *in, const double bc[3],
                            const double br[3], iv *R, iv *o) {
    const bscr S = scratch(ev, R);
    iv *x = S.x, *c = S.c;
    const size_t k = in->op->k;
    for (size_t j = 0; j < k; ++j) x[j] = R[in->src[j]];
    if ((lb__family_info(in->op->family)->flags & LB__R_BOUNDING))
        for (size_t j = 0; j < k; ++j) c[j] = R[in->src[k + j]];
    if ((lb__family_info(in->op->family)->flags & LB__R_CLEAN_UNION))
        lb__local_bounds(ev, in, x, bc, br, o);
    else
        lb__op_interval(in->op, ev->conv, x, c, o, S.xl);
}

/* Operator i (in) keeps the parent's argument list in the child plan: the
 * operators whose bounds do not cull. */
static void inherit_args(lb__plan *child, const lb__plan *parent, const lb__instr *in, uint32_t i) {
    memcpy(child->act + in->aoff, parent->act + in->aoff, parent->nact[i] * sizeof *parent->act);
    child->nact[i] = parent->nact[i];
}

/* The same pass over a box inside the box of `parent` (a plan made by
 * lb__bounds_pass): instructions the parent does not need are skipped, and
 * blends consider only the arguments the parent kept, which are the only
 * ones that can matter inside. Fills R for the needed instructions; the
 * root's interval is R[ev->out]. With child (may be NULL), also the plan of
 * the smaller box: each blend keeps what the sub-box culling kept (a subset
 * of the parent's), every other operator the parent's list. */
void lb__bounds_pass_sub(const lb_evaluator *ev, const lb__plan *parent, const double bc[3],
                         const double br[3], iv *R, lb__plan *child) {
    const bscr S = scratch(ev, R);
    iv *x = S.x;
    for (uint32_t q = 0; q < parent->nlist; ++q) {
        const uint32_t i = parent->list[q];
        const lb__instr *in = &ev->ins[i];
        iv o;
        if (in->code != LB__I_OP) {
            o = prim_bounds(in, bc, br);
        } else if (in->fast == LB__FAST_DISPLACEMENT || in->fast == LB__FAST_CONIC ||
                   in->fast == LB__FAST_MINMAX) {
            const uint16_t *pa = parent->act + in->aoff;
            const uint16_t pn = parent->nact[i];
            for (uint16_t j = 0; j < pn; ++j) x[pa[j]] = R[in->src[pa[j]]];
            if (in->fast == LB__FAST_MINMAX) {
                const int mn = lb__family_info(in->op->family)->select > 0;
                o = x[pa[0]];
                for (uint16_t j = 1; j < pn; ++j) {
                    const iv a = x[pa[j]];
                    if (mn ? a.lo < o.lo : a.lo > o.lo) o.lo = a.lo;
                    if (mn ? a.hi < o.hi : a.hi > o.hi) o.hi = a.hi;
                }
                if (child) {
                    /* among the parent's arguments, as lb__cull_select does:
                     * an argument whose interval lies wholly beyond the
                     * extreme of another's is never selected in the box, so
                     * the kept ones give the same bits (o is unchanged) */
                    uint16_t *act = child->act + in->aoff, na = 0;
                    for (uint16_t j = 0; j < pn; ++j)
                        if (mn ? !(x[pa[j]].lo > o.hi) : !(x[pa[j]].hi < o.lo)) act[na++] = pa[j];
                    child->nact[i] = na;
                }
            } else {
                /* cull among the parent's arguments, as cull() does */
                const lb__op *n = in->op;
                double H = INFINITY;
                for (uint16_t j = 0; j < pn; ++j) {
                    const iv u = lb__dual_iv(n->op, pa[j], x[pa[j]]);
                    const double t = u.hi / n->m[pa[j]];
                    if (t < H) H = t;
                }
                uint16_t *act = S.act, na = 0;
                for (uint16_t j = 0; j < pn; ++j) {
                    const uint16_t a = pa[j];
                    const iv u = lb__dual_iv(n->op, a, x[a]);
                    const double reach = u.lo - n->m[a] * H;
                    if (!(reach >= n->r[a] * (1.0 + 1e-9) + 1e-12 * fabs(u.lo))) act[na++] = a;
                }
                fast_bounds(in, x, act, na, &o, S.fb);
                if (child) {
                    memcpy(child->act + in->aoff, act, na * sizeof *act);
                    child->nact[i] = na;
                }
            }
        } else {
            all_args_bounds(ev, in, bc, br, R, &o);
            if (child) inherit_args(child, parent, in, i);
        }
        store_iv(&R[in->dst], o);
    }
    if (child) plan_needs(ev, child, parent);
}

void lb__bounds_pass_list(const lb_evaluator *ev, const uint32_t *list, size_t nlist,
                          const double bc[3], const double br[3], iv *R) {
    for (size_t q = 0; q < nlist; ++q) {
        const lb__instr *in = &ev->ins[list[q]];
        iv o;
        if (in->code != LB__I_OP)
            o = prim_bounds(in, bc, br);
        else
            all_args_bounds(ev, in, bc, br, R, &o);
        store_iv(&R[in->dst], o);
    }
}

lb_status lb_evaluator_bounds(const lb_evaluator *ev, const double bmin[3], const double bmax[3],
                              double *lo, double *hi, lb_error *err) {
    static const char fn[] = "lb_evaluator_bounds";
    if (!ev || !bmin || !bmax || !lo || !hi)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: every pointer must be non-NULL", fn);
    for (int d = 0; d < 3; ++d)
        if (!(fabs(bmin[d]) <= LB_SCENE_MAX_COORD) || !(fabs(bmax[d]) <= LB_SCENE_MAX_COORD))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: box %c range [%g, %g]; allowed: finite, |coordinate| <= %g", fn,
                            "xyz"[d], bmin[d], bmax[d], LB_SCENE_MAX_COORD);
    return lb__bounds_box(ev, bmin, bmax, lo, hi, err);
}

lb_status lb__bounds_box(const lb_evaluator *ev, const double bmin[3], const double bmax[3],
                         double *lo, double *hi, lb_error *err) {
    static const char fn[] = "lb_evaluator_bounds";
    double bc[3], br[3];
    for (int d = 0; d < 3; ++d) {
        if (!(bmin[d] <= bmax[d]))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: box min %c = %g is above max %c = %g; allowed: min <= max", fn,
                            "xyz"[d], bmin[d], "xyz"[d], bmax[d]);
    }
    lb__box_centre(bmin, bmax, bc, br);
    iv *R = malloc(lb__ivs_len(ev) * sizeof *R);
    if (!R) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
    lb__bounds_pass(ev, bc, br, R, NULL);
    *lo = R[ev->out].lo;
    *hi = R[ev->out].hi;
    free(R);
    return LB_OK;
}
