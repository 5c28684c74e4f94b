/* Interval enclosures of the operator families (the rows' interval and
 * cull columns in families.def), and lb__op_interval / lb__op_cull, the
 * dispatch through the rows. The scheme is in evaluation/eval_bounds.c
 * and docs/design.md, "Interval bounds": operators without bulge
 * elimination are monotone in each argument (increasing; a difference
 * decreases in its subtracted arguments), so the operator at the two
 * extreme corners bounds it; min, max and the complement are exact;
 * bulge elimination and bounded blends bound their roots by brackets;
 * Perlin's products fall back to interval products off [0, 1]. Unbounded
 * ends stay infinite. */
#include "family_fns.h"

typedef lb__iv iv;

/* the solvers' tolerance: every enclosure but the exact ones is widened
 * by 1e-9 (1 + |v|); soft fields are >= 0 */
static void widen(lb_convention conv, iv *out) {
    out->lo -= 1e-9 * (1.0 + fabs(out->lo));
    out->hi += 1e-9 * (1.0 + fabs(out->hi));
    if (conv == LB_CONVENTION_SOFT && out->lo < 0.0) out->lo = 0.0;
}

static int finite_all(const double *v, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static void bulge_bounds(const lb__op *o, const iv *x, iv *out) {
    const lb_bulge_params *bp = &o->bp;
    const int range = (bp->flags & LB_BULGE_RANGE) != 0, slope = (bp->flags & LB_BULGE_SLOPE) != 0;
    double L = INFINITY, H = INFINITY;
    int unknown_lo = 0;
    for (size_t i = 0; i < 2; ++i) {
        const iv u = lb__dual_iv(o->op, i, x[i]);
        const double rhi = range ? bp->r[i] * (2.0 + bp->omega) : bp->r[i];
        if (lb__family_info(o->family)->bulge_family == LB_BULGE_SCALE) {
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
    if (o->op == LB_UNION) {
        out->lo = L;
        out->hi = H;
    } else {
        out->lo = -H;
        out->hi = -L;
    }
}

static void bounded_bounds(const lb__op *o, const iv *x, const iv *c, iv *out) {
    const size_t k = o->k;
    const double om = LB_BOUNDED_OMEGA;
    if (o->op == LB_UNION) {
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
            !lb__op_apply(o, LB_CONVENTION_ZERO, xl, cl, NULL, &v1, NULL, NULL, NULL, NULL) &&
            !lb__op_apply(o, LB_CONVENTION_ZERO, xh, ch, NULL, &v2, NULL, NULL, NULL, NULL)) {
            if (v1 > out->lo) out->lo = v1;
            if (v2 < out->hi) out->hi = v2;
        }
        return;
    }
    double pmin = o->p[0];
    for (size_t i = 1; i < k; ++i)
        if (o->p[i] < pmin) pmin = o->p[i];
    const double grow = pow((double)k, 1.0 / pmin);
    double L = -INFINITY, Y = -INFINITY;
    for (size_t i = 0; i < k; ++i) {
        iv a = x[i];
        if (o->op == LB_DIFFERENCE && i > 0) {
            a.lo = -x[i].hi;
            a.hi = -x[i].lo;
        }
        if (a.lo > L) L = a.lo;
        if (a.hi + 1.0 > Y) Y = a.hi + 1.0;
    }
    out->lo = L;
    out->hi = (Y > 0.0 ? grow * Y : 0.0) - 1.0;
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

/* Monotone operators at the two extreme corners (ws: 2k doubles) */
void lb__iv_corners(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                    double *xl) {
    (void)c;
    const size_t k = o->k;
    const int diff = lb__family_info(o->family)->ops == LB__OPS_ALL;
    double *xh = xl + k, v1 = 0.0, v2 = 0.0; /* xl: the caller's 2k doubles */
    for (size_t i = 0; i < k; ++i) {
        const int dec = o->op == LB_DIFFERENCE && i > 0 && diff;
        xl[i] = dec ? x[i].hi : x[i].lo;
        xh[i] = dec ? x[i].lo : x[i].hi;
    }
    /* a corner with an infinite argument, or one the operator refuses:
     * nothing is known at that end (an end at 1e100 would be a finite
     * stand-in that the operator's arithmetic can cancel) */
    const int ok1 =
        finite_all(xl, k) && !lb__op_apply(o, conv, xl, NULL, NULL, &v1, NULL, NULL, NULL, NULL);
    const int ok2 =
        finite_all(xh, k) && !lb__op_apply(o, conv, xh, NULL, NULL, &v2, NULL, NULL, NULL, NULL);
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
}

void lb__iv_bounded(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                    double *ws) {
    (void)ws;
    bounded_bounds(o, x, c, out);
    widen(conv, out);
}

void lb__iv_complement(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                       double *ws) {
    (void)o, (void)c, (void)ws;
    if (conv == LB_CONVENTION_ZERO) {
        out->lo = -x[0].hi;
        out->hi = -x[0].lo;
    } else { /* max(0, 1 - f) */
        out->lo = 1.0 - x[0].hi > 0.0 ? 1.0 - x[0].hi : 0.0;
        out->hi = 1.0 - x[0].lo > 0.0 ? 1.0 - x[0].lo : 0.0;
    }
    /* exact */
}

/* min and max: exact, infinite ends included */
void lb__iv_select(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                   double *ws) {
    (void)conv, (void)c, (void)ws;
    const int mn = lb__family_info(o->family)->select > 0;
    *out = x[0];
    for (size_t i = 1; i < o->k; ++i) {
        out->lo = mn ? fmin(out->lo, x[i].lo) : fmax(out->lo, x[i].lo);
        out->hi = mn ? fmin(out->hi, x[i].hi) : fmax(out->hi, x[i].hi);
    }
}

void lb__iv_perlin(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                   double *ws) {
    const size_t k = o->k;
    const int reach = perlin_reach(x, k);
    if (reach == 0) {
        lb__iv_corners(o, conv, x, c, out, ws);
        return;
    }
    if (reach == 2) {
        out->lo = 0.0; /* soft fields are >= 0; nothing finite bounds the top */
        out->hi = INFINITY;
        return;
    }
    /* Perlin's products are monotone only on [0, 1]: an argument a soft
     * union took above 1 flips a factor's sign. Interval products then
     * (sound, and exact for points): union 1 - prod(1 - f_i),
     * intersection prod f_i, difference f_0 prod_{i>0} (1 - f_i). */
    iv P = {1.0, 1.0};
    for (size_t i = 0; i < k; ++i) {
        const int flip = o->op == LB_UNION || (o->op == LB_DIFFERENCE && i > 0);
        const iv f = flip ? (iv){1.0 - x[i].hi, 1.0 - x[i].lo} : x[i];
        const double a = P.lo * f.lo, b = P.lo * f.hi, c2 = P.hi * f.lo, d = P.hi * f.hi;
        P.lo = fmin(fmin(a, b), fmin(c2, d));
        P.hi = fmax(fmax(a, b), fmax(c2, d));
    }
    if (o->op == LB_UNION) P = (iv){1.0 - P.hi, 1.0 - P.lo};
    out->lo = P.lo > 0.0 ? P.lo : 0.0;
    out->hi = P.hi > 0.0 ? P.hi : 0.0;
    widen(conv, out);
}

void lb__op_interval(const lb__op *o, lb_convention conv, const iv *x, const iv *c, iv *out,
                     double *ws) {
    if (o->bulge) {
        bulge_bounds(o, x, out);
        widen(conv, out);
        return;
    }
    lb__family_info(o->family)->interval(o, conv, x, c, out, ws);
}

/* Argument culling for one operator over a box (the plan's act list). */

/* displacement and conic (no bulge), in union form u (duals negate): the
 * root h <= H = min_i hi(u_i)/m_i, so argument j's term
 * [(r_j - u_j + m_j h)/r_j]+ is 0 on the whole box when
 * lo(u_j) - m_j H >= r_j; dropping it leaves T, its root and the gradient
 * unchanged (the conic is then outside region II: min(u_i/m_i)). The
 * argument attaining H always stays. */
uint16_t lb__cull_reach(const lb__op *o, const iv *x, uint16_t *act) {
    const size_t k = o->k;
    uint16_t na = 0;
    double H = INFINITY;
    for (size_t i = 0; i < k; ++i) {
        const iv u = lb__dual_iv(o->op, i, x[i]);
        const double t = u.hi / o->m[i];
        if (t < H) H = t;
    }
    for (size_t i = 0; i < k; ++i) {
        const iv u = lb__dual_iv(o->op, i, x[i]);
        /* a relative margin keeps rounding in the kernel on the safe side */
        const double reach = u.lo - o->m[i] * H;
        if (!(reach >= o->r[i] * (1.0 + 1e-9) + 1e-12 * fabs(u.lo))) act[na++] = (uint16_t)i;
    }
    return na;
}

/* min / max: an argument whose interval lies above the smallest upper
 * bound (below the largest lower bound) is never selected; the extreme
 * bound's argument always stays. */
uint16_t lb__cull_select(const lb__op *o, const iv *x, uint16_t *act) {
    const size_t k = o->k;
    uint16_t na = 0;
    const int mn = lb__family_info(o->family)->select > 0;
    double ext = mn ? INFINITY : -INFINITY;
    for (size_t i = 0; i < k; ++i) {
        if (mn && x[i].hi < ext) ext = x[i].hi;
        if (!mn && x[i].lo > ext) ext = x[i].lo;
    }
    for (size_t i = 0; i < k; ++i)
        if (mn ? !(x[i].lo > ext) : !(x[i].hi < ext)) act[na++] = (uint16_t)i;
    return na;
}

uint16_t lb__op_cull(const lb__op *o, const iv *x, uint16_t *act) {
    const lb__cull_fn f = o->bulge ? NULL : lb__family_info(o->family)->cull;
    if (f) return f(o, x, act);
    uint16_t na = 0;
    for (size_t i = 0; i < o->k; ++i) act[na++] = (uint16_t)i;
    return na;
}
