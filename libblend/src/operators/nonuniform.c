/* Non-uniform scaling for soft objects [hsu-nonuniform 3-4], soft convention.
 *
 * s_i(h) = 0.5^(1 - m_i) h^m_i. Everything is solved in lambda = ln h, where
 * z_i = x_i / s_i(h) = a_i exp(-m_i lambda) with a_i = x_i 2^(1 - m_i):
 *   intersection B_Ak: T = sum_i [(1 + r_i - z_i)/r_i]+^p_i - 1
 *   union        B_Sk: T = 1 - sum_i [(r_i - 1 + z_i)/r_i]+^p_i
 * Both increase with lambda; brackets from docs/operators.md section 7
 * (for r_i = 1 the union's upper end is where that term is <= 1/k).
 * Conic variants use H of lb__conic_H with u_i = z_i - 1 (intersection,
 * T = H) or u_i = 1 - z_i (union, T = -H), between the non-blending value
 * and the chord u1/r1 + u2/r2 = 1 (found first, by the same solver).
 * Gradient: dh/dx_i = -h (dT/dlambda)^-1 dT/dx_i. lambda is solved to an
 * absolute tolerance, which is h's relative one. */
#include "../common/internal.h"
#include "../solver/root.h"

#define LN2 0.69314718055994530942

typedef struct {
    size_t k;
    const double *a, *r, *p, *m; /* a: ln a_i = ln x_i + (1 - m_i) ln 2 */
    int mode, union_like;
} soft_ctx;

static void soft_T(double lam, const void *vctx, double *T, double *dT, double *d2T,
                   double *smooth) {
    (void)d2T;
    (void)smooth;
    const soft_ctx *c = vctx;
    double sum = 0.0, dsum = 0.0;
    for (size_t i = 0; i < c->k; ++i) {
        const double z = exp(c->a[i] - c->m[i] * lam);
        const double t =
            c->union_like ? (c->r[i] - 1.0 + z) / c->r[i] : (1.0 + c->r[i] - z) / c->r[i];
        if (t > 0.0) {
            const double tp1 = lb__pow_m1(t, c->p[i], c->mode);
            sum += tp1 * t;
            dsum += c->p[i] / c->r[i] * tp1 * c->m[i] * z;
        }
    }
    *T = c->union_like ? 1.0 - sum : sum - 1.0;
    *dT = dsum;
}

/* B_Sk (union_like) or B_Ak over the x_i > 0. */
static double soft_hyper_kernel(int union_like, size_t k, const double *x, const double *r,
                                const double *p, const double *m, double *dx) {
    double a[LB_MAX_ARITY], ra[LB_MAX_ARITY], pa[LB_MAX_ARITY], ma[LB_MAX_ARITY];
    size_t map[LB_MAX_ARITY], n = 0;
    if (dx)
        for (size_t i = 0; i < k; ++i) dx[i] = 0.0;
    for (size_t i = 0; i < k; ++i) {
        if (x[i] <= 0.0) {
            if (!union_like) return 0.0; /* min(x) <= 0: the intersection is 0 */
            continue;                    /* never active in a union */
        }
        a[n] = log(x[i]) + (1.0 - m[i]) * LN2; /* ln a_i: no underflow */
        ra[n] = r[i];
        pa[n] = p[i];
        ma[n] = m[i];
        map[n++] = i;
    }
    if (n == 0) return 0.0;
    /* non-blending end of the bracket: min (intersection) / max (union) of ln(a_i)/m_i */
    size_t j = 0;
    double lam_nb = a[0] / ma[0];
    for (size_t i = 1; i < n; ++i) {
        const double l = a[i] / ma[i];
        if (union_like ? l > lam_nb : l < lam_nb) {
            lam_nb = l;
            j = i;
        }
    }
    const soft_ctx ctx = {n, a, ra, pa, ma, lb__exponent_mode(n, pa), union_like};
    /* non-blending: no other term active at lam_nb; then h = a_j^(1/m_j) exactly */
    int alone = 1;
    for (size_t i = 0; i < n && alone; ++i) {
        if (i == j) continue;
        const double z = exp(a[i] - ma[i] * lam_nb);
        const double t = union_like ? (ra[i] - 1.0 + z) / ra[i] : (1.0 + ra[i] - z) / ra[i];
        if (t > 0.0) alone = 0;
    }
    if (alone) {
        const double h = exp(lam_nb);
        if (dx) dx[map[j]] = exp((1.0 - ma[j]) * (lam_nb + LN2)) / ma[j]; /* h / (m x) */
        return h;
    }
    double other = union_like ? -INFINITY : INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double l;
        if (union_like)
            l = ra[i] < 1.0 ? (a[i] - log1p(-ra[i])) / ma[i]
                            : (a[i] + log((double)n) / pa[i]) / ma[i];
        else
            l = (a[i] - log1p(ra[i])) / ma[i];
        if (union_like ? l > other : l < other) other = l;
    }
    const double lam = union_like ? lb__root_solve_scaled(soft_T, &ctx, lam_nb, other, lam_nb, 1.0)
                                  : lb__root_solve_scaled(soft_T, &ctx, other, lam_nb, lam_nb, 1.0);
    const double h = exp(lam);
    if (dx) {
        double q[LB_MAX_ARITY], E = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double z = exp(a[i] - ma[i] * lam);
            const double t = union_like ? (ra[i] - 1.0 + z) / ra[i] : (1.0 + ra[i] - z) / ra[i];
            q[i] = t > 0.0 ? pa[i] / ra[i] * lb__pow_m1(t, pa[i], ctx.mode) * z : 0.0;
            E += q[i] * ma[i];
        }
        if (!(E > 0.0)) {
            for (size_t i = 0; i < n; ++i) q[i] = 0.0;
            q[j] = 1.0;
            E = ma[j];
        }
        /* q_i carries z_i = x_i/s_i; dh/dx_i = h q_i / (E x_i) = (h/s_i) (q_i/z_i) / E,
         * with h/s_i = exp((1 - m_i)(lambda + ln 2)) (no division by a tiny x_i) */
        for (size_t i = 0; i < n; ++i) {
            const double z = exp(a[i] - ma[i] * lam);
            const double hs = exp((1.0 - ma[i]) * (lam + LN2));
            dx[map[i]] = q[i] > 0.0 && z > 0.0 ? hs * (q[i] / z) / E : 0.0;
        }
    }
    return h;
}

/* ---- conic variants ---- */
typedef struct {
    double a[2], r[2], m[2], p; /* a: ln a_i */
    int union_like, chord;      /* chord: solve the chord equation instead of H */
} sconic_ctx;

static void sconic_u(const sconic_ctx *c, double lam, double u[2], double du[2]) {
    for (int i = 0; i < 2; ++i) {
        const double z = exp(c->a[i] - c->m[i] * lam);
        u[i] = c->union_like ? 1.0 - z : z - 1.0;
        du[i] = c->union_like ? c->m[i] * z : -c->m[i] * z;
    }
}

static void sconic_T(double lam, const void *vctx, double *T, double *dT, double *d2T,
                     double *smooth) {
    (void)d2T;
    (void)smooth;
    const sconic_ctx *c = vctx;
    double u[2], du[2], H1, H2;
    sconic_u(c, lam, u, du);
    const double sgn = c->union_like ? 1.0 : -1.0; /* both T increase with lambda */
    if (c->chord) {
        *T = sgn * (u[0] / c->r[0] + u[1] / c->r[1] - 1.0);
        *dT = sgn * (du[0] / c->r[0] + du[1] / c->r[1]);
        return;
    }
    const double H = lb__conic_H(c->r[0], c->r[1], c->p, u[0], u[1], &H1, &H2);
    const double n = 1.0 / (c->r[0] * c->r[0] * c->r[1] * c->r[1]); /* H is of size r1^2 r2^2 */
    *T = -sgn * n * H;
    *dT = -sgn * n * (H1 * du[0] + H2 * du[1]);
}

static double soft_conic_kernel(int union_like, const double x[2], const double r[2], double p,
                                const double m[2], double dx[2]) {
    if (dx) dx[0] = dx[1] = 0.0;
    if (!union_like && (x[0] <= 0.0 || x[1] <= 0.0)) return 0.0;
    if (union_like && x[0] <= 0.0 && x[1] <= 0.0) return 0.0;
    sconic_ctx c = {{0, 0}, {r[0], r[1]}, {m[0], m[1]}, p, union_like, 0};
    double lnb[2];
    for (int i = 0; i < 2; ++i) {
        c.a[i] = x[i] > 0.0 ? log(x[i]) + (1.0 - m[i]) * LN2 : -INFINITY; /* ln a_i */
        lnb[i] = c.a[i] / m[i];
    }
    const int j = union_like ? lnb[1] > lnb[0] : lnb[1] < lnb[0];
    const int o = 1 - j;
    const double lam_nb = lnb[j];
    double u[2], du[2];
    sconic_u(&c, lam_nb, u, du);
    if (x[o] <= 0.0 || u[o] >= r[o]) { /* outside region II */
        const double h = exp(lam_nb);
        if (dx) dx[j] = exp((1.0 - m[j]) * (lam_nb + LN2)) / m[j]; /* h / (m x) */
        return h;
    }
    /* chord end of the bracket: where each u_i >= r_i/2 the chord value is >= 0 */
    double far = union_like ? -INFINITY : INFINITY;
    for (int i = 0; i < 2; ++i) {
        const double l = (c.a[i] - log1p(union_like ? -0.5 * r[i] : 0.5 * r[i])) / m[i];
        if (union_like ? l > far : l < far) far = l;
    }
    c.chord = 1;
    const double lam_c = union_like ? lb__root_solve_scaled(sconic_T, &c, lam_nb, far, lam_nb, 1.0)
                                    : lb__root_solve_scaled(sconic_T, &c, far, lam_nb, lam_nb, 1.0);
    c.chord = 0;
    const double lam = union_like ? lb__root_solve_scaled(sconic_T, &c, lam_nb, lam_c, lam_nb, 1.0)
                                  : lb__root_solve_scaled(sconic_T, &c, lam_c, lam_nb, lam_nb, 1.0);
    const double h = exp(lam);
    if (dx) {
        double H1, H2;
        sconic_u(&c, lam, u, du);
        lb__conic_H(r[0], r[1], p, u[0], u[1], &H1, &H2);
        const double dTl = H1 * du[0] + H2 * du[1]; /* dH/dlambda */
        for (int i = 0; i < 2; ++i) {
            /* u_i = +-(z_i - 1) with z_i = x_i / s_i: du_i/dx_i = +-1/s_i, and
             * h/s_i = exp((1 - m_i)(lambda + ln 2)) */
            const double hs = exp((1.0 - m[i]) * (lam + LN2));
            const double g = -(union_like ? -hs : hs) * (i == 0 ? H1 : H2) / dTl;
            dx[i] = dTl != 0.0 && isfinite(g) ? g : 0.0;
        }
    }
    return h;
}

static lb_status soft_dispatch(const char *fn, lb_setop op, size_t k, const double *x,
                               const double *r, const double *p, const double *m, int conic,
                               double conic_p, double *value, double *grad, lb_error *err) {
    lb_status s;
    if ((s = lb__check_setop(fn, op, err))) return s;
    double ones[LB_MAX_ARITY], xt[LB_MAX_ARITY];
    const double rmax = op == LB_UNION ? 1.0 : INFINITY;
    if (conic) {
        if ((s = lb__check_conic(fn, x, r, conic_p, m, value, err))) return s;
    } else {
        if ((s = lb__check_k(fn, k, 1, LB_MAX_ARITY, err)) || (s = lb__check_out(fn, value, err)) ||
            (s = lb__check_finite(fn, "x", k, x, err)) || (s = lb__check_p(fn, k, p, err)))
            return s;
    }
    /* soft fields lie in [0, 1]; the result grows like x^(1/m), so m is kept
     * where that stays finite */
    if ((s = lb__check_range(fn, "x", k, x, 0.0, 1, LB_SOFT_MAX_FIELD, 1,
                             "0 <= x <= 1e6 (a soft field value; soft unions may exceed 1)",
                             err)) ||
        (s = lb__check_r_m(fn, "r", "m", k, r, m, rmax, LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE, err)))
        return s;
    if (!m) {
        for (size_t i = 0; i < k; ++i) ones[i] = 1.0;
        m = ones;
    }
    for (size_t i = 0; i < k; ++i) {
        xt[i] = (op == LB_DIFFERENCE && i > 0) ? 1.0 - x[i] : x[i];
        /* below LB_SOFT_MIN_FIELD a soft value counts as 0: the result grows like
         * x^(1/m), whose slope at such x exceeds the double range when m > 1 */
        if (xt[i] < LB_SOFT_MIN_FIELD) xt[i] = 0.0;
    }
    const int u = op == LB_UNION;
    *value = conic ? soft_conic_kernel(u, xt, r, conic_p, m, grad)
                   : soft_hyper_kernel(u, k, xt, r, p, m, grad);
    if (grad && op == LB_DIFFERENCE)
        for (size_t i = 1; i < k; ++i) grad[i] = -grad[i];
    return LB_OK;
}

lb_status lb_soft_hyper(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                        const double *m, double *value, double *grad, lb_error *err) {
    return soft_dispatch("lb_soft_hyper", op, k, x, r, p, m, 0, 0.0, value, grad, err);
}

lb_status lb_soft_conic(lb_setop op, const double x[2], const double r[2], double p,
                        const double m[2], double *value, double grad[2], lb_error *err) {
    return soft_dispatch("lb_soft_conic", op, 2, x, r, NULL, m, 1, p, value, grad, err);
}
