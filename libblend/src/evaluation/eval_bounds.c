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

static int finite_all(const double *v, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* dual (union-form) argument interval: intersection -x, difference -x_0 */
static iv dual_iv(lb_setop op, size_t i, iv x) {
    const int neg = op == LB_INTERSECTION || (op == LB_DIFFERENCE && i == 0);
    if (!neg) return x;
    iv o = {-x.hi, -x.lo};
    return o;
}

static void bulge_bounds(const lb__node *n, const iv *x, iv *out) {
    const lb_bulge_params *bp = &n->bp;
    const int range = (bp->flags & LB_BULGE_RANGE) != 0, slope = (bp->flags & LB_BULGE_SLOPE) != 0;
    double L = INFINITY, H = INFINITY;
    int unknown_lo = 0;
    for (size_t i = 0; i < 2; ++i) {
        const iv u = dual_iv(n->op, i, x[i]);
        const double rhi = range ? bp->r[i] * (2.0 + bp->omega) : bp->r[i];
        if (n->family == LB__F_SCALE) {
            const double ylo = u.lo + 1.0;
            if (ylo > 0.0) {
                const double t = ylo / (1.0 + rhi) - 1.0;
                if (t < L) L = t;
            } else {
                unknown_lo = 1;
            }
            if (u.hi < H) H = u.hi;
        } else {
            const double m = bp->m[i];
            const double num = u.lo - rhi;
            const double gl = num < 0.0 ? num / m : (slope ? 0.0 : num / m);
            const double gh = u.hi >= 0.0 ? u.hi / m : (slope ? 0.0 : u.hi / m);
            if (gl < L) L = gl;
            if (gh < H) H = gh;
        }
    }
    if (unknown_lo) L = -INFINITY;
    if (n->op == LB_UNION) {
        out->lo = L;
        out->hi = H;
    } else {
        out->lo = -H;
        out->hi = -L;
    }
}

static void bounded_bounds(const lb__node *n, const iv *x, const iv *c, iv *out) {
    const size_t k = n->k;
    const double om = LB_BOUNDED_OMEGA;
    if (n->op == LB_UNION) {
        double L = INFINITY, H = INFINITY;
        int unknown = 0;
        for (size_t i = 0; i < k; ++i) {
            const double ylo = x[i].lo + 1.0, yclo = c[i].lo + 1.0;
            if (x[i].hi < H) H = x[i].hi;
            if (!(ylo > 0.0)) {
                unknown = 1;
                continue;
            }
            double t = ylo / (1.0 + om);
            const double tc = yclo > 0.0 ? yclo : 0.0;
            if (tc < t) t = tc;
            if (t - 1.0 < L) L = t - 1.0;
        }
        out->lo = unknown ? -INFINITY : L;
        out->hi = H;
        /* Where every bounding value stays above -1 the union is monotone
         * (non-decreasing) in each x_i and each c_i: with y = x + 1 and
         * y_c = c + 1, R_i = y_i / y_ci - 1 turns argument i's term into
         * [y_i (h - y_ci) / (h (y_i - y_ci))]+^p_i, which falls as y_i or
         * y_ci grows (h <= y_i), so the root h rises; where R_i is floored
         * at omega it no longer depends on c_i. The corners then bound it
         * exactly; the brackets above stay as a safeguard. */
        int mono = 1;
        double xl[LB_MAX_ARITY], xh[LB_MAX_ARITY], cl[LB_MAX_ARITY], ch[LB_MAX_ARITY];
        for (size_t i = 0; i < k && mono; ++i) {
            mono = c[i].lo > -1.0;
            xl[i] = x[i].lo;
            xh[i] = x[i].hi;
            cl[i] = c[i].lo;
            ch[i] = c[i].hi;
        }
        double v1, v2;
        if (mono && finite_all(xl, k) && finite_all(xh, k) && finite_all(cl, k) &&
            finite_all(ch, k) &&
            !lb__node_apply(n, LB_CONVENTION_ZERO, xl, cl, NULL, &v1, NULL, NULL, NULL, NULL) &&
            !lb__node_apply(n, LB_CONVENTION_ZERO, xh, ch, NULL, &v2, NULL, NULL, NULL, NULL)) {
            if (v1 > out->lo) out->lo = v1;
            if (v2 < out->hi) out->hi = v2;
        }
        return;
    }
    double pmin = n->p[0];
    for (size_t i = 1; i < k; ++i)
        if (n->p[i] < pmin) pmin = n->p[i];
    const double grow = pow((double)k, 1.0 / pmin);
    double L = -INFINITY, Y = -INFINITY;
    for (size_t i = 0; i < k; ++i) {
        iv a = x[i];
        if (n->op == LB_DIFFERENCE && i > 0) {
            a.lo = -x[i].hi;
            a.hi = -x[i].lo;
        }
        if (a.lo > L) L = a.lo;
        if (a.hi + 1.0 > Y) Y = a.hi + 1.0;
    }
    out->lo = L;
    out->hi = (Y > 0.0 ? grow * Y : 0.0) - 1.0;
}

static int is_difference_family(lb__family f) {
    return f == LB__F_DISPLACEMENT || f == LB__F_CONIC || f == LB__F_SCALE ||
           f == LB__F_SOFT_HYPER || f == LB__F_SOFT_CONIC || f == LB__F_PERLIN;
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
    const lb__node *n = in->op;
    const size_t K = n->k;
    double *lo = ws, *hi = lo + K, *r = hi + K, *p = r + K, *m = p + K;
    ws = m + K;
    for (size_t j = 0; j < na; ++j) {
        const iv u = dual_iv(n->op, act[j], x[act[j]]);
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

/* Where Perlin's arguments lie: 0 all within [0, 1] at the top, 1 some
 * finite top above 1, 2 some end infinite (unbounded) */
static int perlin_reach(const iv *x, size_t k) {
    int r = 0;
    for (size_t i = 0; i < k; ++i) {
        if (!isfinite(x[i].lo) || !isfinite(x[i].hi)) return 2;
        if (x[i].hi > 1.0) r = 1;
    }
    return r;
}

static void op_bounds(lb_convention conv, const lb__node *n, const iv *x, const iv *c, iv *out,
                      double *xl) {
    const size_t k = n->k;
    if (n->bulge) {
        bulge_bounds(n, x, out);
    } else if (n->family == LB__F_BOUNDED) {
        bounded_bounds(n, x, c, out);
    } else if (n->family == LB__F_COMPLEMENT) {
        if (conv == LB_CONVENTION_ZERO) {
            out->lo = -x[0].hi;
            out->hi = -x[0].lo;
        } else { /* max(0, 1 - f) */
            out->lo = 1.0 - x[0].hi > 0.0 ? 1.0 - x[0].hi : 0.0;
            out->hi = 1.0 - x[0].lo > 0.0 ? 1.0 - x[0].lo : 0.0;
        }
        return; /* exact */
    } else if (n->family == LB__F_MIN || n->family == LB__F_MAX) {
        /* exact, infinite ends included */
        const int mn = n->family == LB__F_MIN;
        *out = x[0];
        for (size_t i = 1; i < k; ++i) {
            out->lo = mn ? fmin(out->lo, x[i].lo) : fmax(out->lo, x[i].lo);
            out->hi = mn ? fmin(out->hi, x[i].hi) : fmax(out->hi, x[i].hi);
        }
        return;
    } else if (n->family == LB__F_PERLIN && perlin_reach(x, k) == 2) {
        out->lo = 0.0; /* soft fields are >= 0; nothing finite bounds the top */
        out->hi = INFINITY;
        return;
    } else if (n->family == LB__F_PERLIN && perlin_reach(x, k) == 1) {
        /* Perlin's products are monotone only on [0, 1]: an argument a soft
         * union took above 1 flips a factor's sign. Interval products then
         * (sound, and exact for points): union 1 - prod(1 - f_i),
         * intersection prod f_i, difference f_0 prod_{i>0} (1 - f_i). */
        iv P = {1.0, 1.0};
        for (size_t i = 0; i < k; ++i) {
            const int flip = n->op == LB_UNION || (n->op == LB_DIFFERENCE && i > 0);
            const iv f = flip ? (iv){1.0 - x[i].hi, 1.0 - x[i].lo} : x[i];
            const double a = P.lo * f.lo, b = P.lo * f.hi, c2 = P.hi * f.lo, d = P.hi * f.hi;
            P.lo = fmin(fmin(a, b), fmin(c2, d));
            P.hi = fmax(fmax(a, b), fmax(c2, d));
        }
        if (n->op == LB_UNION) P = (iv){1.0 - P.hi, 1.0 - P.lo};
        out->lo = P.lo > 0.0 ? P.lo : 0.0;
        out->hi = P.hi > 0.0 ? P.hi : 0.0;
    } else {
        double *xh = xl + k, v1 = 0.0, v2 = 0.0; /* xl: the caller's 2k doubles */
        for (size_t i = 0; i < k; ++i) {
            const int dec = n->op == LB_DIFFERENCE && i > 0 && is_difference_family(n->family);
            xl[i] = dec ? x[i].hi : x[i].lo;
            xh[i] = dec ? x[i].lo : x[i].hi;
        }
        /* a corner with an infinite argument, or one the operator refuses:
         * nothing is known at that end (an end at 1e100 would be a finite
         * stand-in that the operator's arithmetic can cancel) */
        const int ok1 = finite_all(xl, k) &&
                        !lb__node_apply(n, conv, xl, NULL, NULL, &v1, NULL, NULL, NULL, NULL);
        const int ok2 = finite_all(xh, k) &&
                        !lb__node_apply(n, conv, xh, NULL, NULL, &v2, NULL, NULL, NULL, NULL);
        /* The lower end from xl, the upper from xh (monotone), each
         * unknown where its corner is. Rounding in operators such as the
         * R-functions (x + y - sqrt(x^2 + y^2)) is relative to the
         * arguments, not to the result: widen by their size too. */
        double big = 0.0;
        for (size_t i = 0; i < 2 * k; ++i)
            if (isfinite(xl[i]) && fabs(xl[i]) > big) big = fabs(xl[i]);
        out->lo = ok1 ? (ok2 ? fmin(v1, v2) : v1) : -INFINITY;
        out->hi = ok2 ? (ok1 ? fmax(v1, v2) : v2) : INFINITY;
        out->lo -= 1e-9 * (1.0 + fabs(out->lo)) + 1e-14 * big;
        out->hi += 1e-9 * (1.0 + fabs(out->hi)) + 1e-14 * big;
        if (conv == LB_CONVENTION_SOFT && out->lo < 0.0) out->lo = 0.0;
        return;
    }
    out->lo -= 1e-9 * (1.0 + fabs(out->lo));
    out->hi += 1e-9 * (1.0 + fabs(out->hi));
    if (conv == LB_CONVENTION_SOFT && out->lo < 0.0) out->lo = 0.0; /* soft fields are >= 0 */
}

/* Argument culling for one operator over a box (the plan's act list):
 * - displacement and conic (no bulge), in union form u (duals negate): the
 *   root h <= H = min_i hi(u_i)/m_i, so argument j's term
 *   [(r_j - u_j + m_j h)/r_j]+ is 0 on the whole box when
 *   lo(u_j) - m_j H >= r_j; dropping it leaves T, its root and the gradient
 *   unchanged (the conic is then outside region II: min(u_i/m_i));
 * - min / max: an argument whose interval lies above the smallest upper
 *   bound (below the largest lower bound) is never selected.
 * The argument attaining H (or the extreme bound) always stays. */
static uint16_t cull(const lb__node *n, const iv *x, uint16_t *act) {
    const size_t k = n->k;
    uint16_t na = 0;
    if (!n->bulge && (n->family == LB__F_DISPLACEMENT || n->family == LB__F_CONIC)) {
        double H = INFINITY;
        for (size_t i = 0; i < k; ++i) {
            const iv u = dual_iv(n->op, i, x[i]);
            const double t = u.hi / n->m[i];
            if (t < H) H = t;
        }
        for (size_t i = 0; i < k; ++i) {
            const iv u = dual_iv(n->op, i, x[i]);
            /* a relative margin keeps rounding in the kernel on the safe side */
            const double reach = u.lo - n->m[i] * H;
            if (!(reach >= n->r[i] * (1.0 + 1e-9) + 1e-12 * fabs(u.lo))) act[na++] = (uint16_t)i;
        }
        return na;
    }
    if (n->family == LB__F_MIN || n->family == LB__F_MAX) {
        const int mn = n->family == LB__F_MIN;
        double ext = mn ? INFINITY : -INFINITY;
        for (size_t i = 0; i < k; ++i) {
            if (mn && x[i].hi < ext) ext = x[i].hi;
            if (!mn && x[i].lo > ext) ext = x[i].lo;
        }
        for (size_t i = 0; i < k; ++i)
            if (mn ? !(x[i].lo > ext) : !(x[i].hi < ext)) act[na++] = (uint16_t)i;
        return na;
    }
    for (size_t i = 0; i < k; ++i) act[na++] = (uint16_t)i;
    return na;
}

/* What the root needs, backwards from the plan's argument lists: need and
 * the list. Only instructions of parent's list can be needed when parent
 * is given (a box inside parent's), so only they are visited. */
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
            if (in->op->family == LB__F_BOUNDED) plan->need[in->srcb[act[a]]] = 1;
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
            if (in->op->family == LB__F_BOUNDED)
                for (size_t j = 0; j < k; ++j) c[j] = R[in->src[k + j]];
            if (in->fast == LB__FAST_DISPLACEMENT || in->fast == LB__FAST_CONIC) {
                uint16_t *act = plan ? plan->act + in->aoff : S.act;
                const uint16_t na = cull(in->op, x, act);
                if (plan) plan->nact[i] = na;
                fast_bounds(in, x, act, na, &o, S.fb);
            } else if (in->op->family == LB__F_LOCAL || in->op->family == LB__F_CLEAN) {
                lb__local_bounds(ev, in, x, bc, br, &o);
                if (plan) plan->nact[i] = cull(in->op, x, plan->act + in->aoff);
            } else {
                op_bounds(ev->conv, in->op, x, c, &o, S.xl);
                if (plan) plan->nact[i] = cull(in->op, x, plan->act + in->aoff);
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
    if (in->op->family == LB__F_BOUNDED)
        for (size_t j = 0; j < k; ++j) c[j] = R[in->src[k + j]];
    if (in->op->family == LB__F_LOCAL || in->op->family == LB__F_CLEAN)
        lb__local_bounds(ev, in, x, bc, br, o);
    else
        op_bounds(ev->conv, in->op, x, c, o, S.xl);
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
                const int mn = in->op->family == LB__F_MIN;
                o = x[pa[0]];
                for (uint16_t j = 1; j < pn; ++j) {
                    const iv a = x[pa[j]];
                    if (mn ? a.lo < o.lo : a.lo > o.lo) o.lo = a.lo;
                    if (mn ? a.hi < o.hi : a.hi > o.hi) o.hi = a.hi;
                }
            } else {
                /* cull among the parent's arguments, as cull() does */
                const lb__node *n = in->op;
                double H = INFINITY;
                for (uint16_t j = 0; j < pn; ++j) {
                    const iv u = dual_iv(n->op, pa[j], x[pa[j]]);
                    const double t = u.hi / n->m[pa[j]];
                    if (t < H) H = t;
                }
                uint16_t *act = S.act, na = 0;
                for (uint16_t j = 0; j < pn; ++j) {
                    const uint16_t a = pa[j];
                    const iv u = dual_iv(n->op, a, x[a]);
                    const double reach = u.lo - n->m[a] * H;
                    if (!(reach >= n->r[a] * (1.0 + 1e-9) + 1e-12 * fabs(u.lo))) act[na++] = a;
                }
                fast_bounds(in, x, act, na, &o, S.fb);
                if (child) {
                    memcpy(child->act + in->aoff, act, na * sizeof *act);
                    child->nact[i] = na;
                }
            }
            if (child && in->fast == LB__FAST_MINMAX) inherit_args(child, parent, in, i);
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
