/* Non-uniform scaling for soft objects [hsu-nonuniform 3-4], soft convention.
 *
 * s_i(h) = 0.5^(1 - m_i) h^m_i. Everything is solved in lambda = ln h, where
 * z_i = x_i / s_i(h) = a_i exp(-m_i lambda) with a_i = x_i 2^(1 - m_i):
 *   intersection B_Ak: T = sum_i [(1 + r_i - z_i)/r_i]+^p_i - 1
 *   union        B_Sk: T = 1 - sum_i [(r_i - 1 + z_i)/r_i]+^p_i
 * Both increase with lambda; brackets from shared/spec/operators.md section 7
 * (for r_i = 1 the union's upper end is where that term is <= 1/k).
 * Conic variants use H of lb__conic_H with u_i = z_i - 1 (intersection,
 * T = H) or u_i = 1 - z_i (union, T = -H), between the non-blending value
 * and the chord u1/r1 + u2/r2 = 1 (found first, by the same solver).
 * Gradient: dh/dx_i = -h (dT/dx_i)/(dT/dlambda). */
#include "../common/internal.h"
#include "../solver/root.h"

#define LN2 0.69314718055994530942

typedef struct {
    size_t k;
    const double *a, *r, *p, *m;
    int mode, union_like;
} soft_ctx;

static void soft_T(double lam, const void *vctx, double *T, double *dT, double *d2T,
                   double *smooth) {
    (void)d2T;
    (void)smooth;
    const soft_ctx *c = vctx;
    double sum = 0.0, dsum = 0.0;
    for (size_t i = 0; i < c->k; ++i) {
        const double z = c->a[i] * exp(-c->m[i] * lam);
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
        a[n] = x[i] * exp((1.0 - m[i]) * LN2);
        ra[n] = r[i];
        pa[n] = p[i];
        ma[n] = m[i];
        map[n++] = i;
    }
    if (n == 0) return 0.0;
    /* non-blending end of the bracket: min (intersection) / max (union) of ln(a_i)/m_i */
    size_t j = 0;
    double lam_nb = log(a[0]) / ma[0];
    for (size_t i = 1; i < n; ++i) {
        const double l = log(a[i]) / ma[i];
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
        const double z = a[i] * exp(-ma[i] * lam_nb);
        const double t = union_like ? (ra[i] - 1.0 + z) / ra[i] : (1.0 + ra[i] - z) / ra[i];
        if (t > 0.0) alone = 0;
    }
    if (alone) {
        const double h = pow(a[j], 1.0 / ma[j]);
        if (dx) dx[map[j]] = h / (ma[j] * x[map[j]]);
        return h;
    }
    double other = union_like ? -INFINITY : INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double l;
        if (union_like)
            l = ra[i] < 1.0 ? log(a[i] / (1.0 - ra[i])) / ma[i]
                            : (log(a[i]) + log((double)n) / pa[i]) / ma[i];
        else
            l = log(a[i] / (1.0 + ra[i])) / ma[i];
        if (union_like ? l > other : l < other) other = l;
    }
    const double lam = union_like ? lb__root_solve(soft_T, &ctx, lam_nb, other, lam_nb)
                                  : lb__root_solve(soft_T, &ctx, other, lam_nb, lam_nb);
    const double h = exp(lam);
    if (dx) {
        double q[LB_MAX_ARITY], E = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double z = a[i] * exp(-ma[i] * lam);
            const double t = union_like ? (ra[i] - 1.0 + z) / ra[i] : (1.0 + ra[i] - z) / ra[i];
            q[i] = t > 0.0 ? pa[i] / ra[i] * lb__pow_m1(t, pa[i], ctx.mode) * z : 0.0;
            E += q[i] * ma[i];
        }
        if (!(E > 0.0)) {
            for (size_t i = 0; i < n; ++i) q[i] = 0.0;
            q[j] = 1.0;
            E = ma[j];
        }
        for (size_t i = 0; i < n; ++i) dx[map[i]] = h * q[i] / (E * x[map[i]]);
    }
    return h;
}

/* ---- conic variants ---- */
typedef struct {
    double a[2], r[2], m[2], p;
    int union_like, chord; /* chord: solve the chord equation instead of H */
} sconic_ctx;

static void sconic_u(const sconic_ctx *c, double lam, double u[2], double du[2]) {
    for (int i = 0; i < 2; ++i) {
        const double z = c->a[i] * exp(-c->m[i] * lam);
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
        c.a[i] = x[i] > 0.0 ? x[i] * exp((1.0 - m[i]) * LN2) : 0.0;
        lnb[i] = x[i] > 0.0 ? log(c.a[i]) / m[i] : -INFINITY;
    }
    const int j = union_like ? lnb[1] > lnb[0] : lnb[1] < lnb[0];
    const int o = 1 - j;
    const double lam_nb = lnb[j];
    double u[2], du[2];
    sconic_u(&c, lam_nb, u, du);
    if (x[o] <= 0.0 || u[o] >= r[o]) { /* outside region II */
        const double h = exp(lam_nb);
        if (dx) dx[j] = h / (m[j] * x[j]);
        return h;
    }
    /* chord end of the bracket: where each u_i >= r_i/2 the chord value is >= 0 */
    double far = union_like ? -INFINITY : INFINITY;
    for (int i = 0; i < 2; ++i) {
        const double l = log(c.a[i] / (union_like ? 1.0 - 0.5 * r[i] : 1.0 + 0.5 * r[i])) / m[i];
        if (union_like ? l > far : l < far) far = l;
    }
    c.chord = 1;
    const double lam_c = union_like ? lb__root_solve(sconic_T, &c, lam_nb, far, lam_nb)
                                    : lb__root_solve(sconic_T, &c, far, lam_nb, lam_nb);
    c.chord = 0;
    const double lam = union_like ? lb__root_solve(sconic_T, &c, lam_nb, lam_c, lam_nb)
                                  : lb__root_solve(sconic_T, &c, lam_c, lam_nb, lam_nb);
    const double h = exp(lam);
    if (dx) {
        double H1, H2;
        sconic_u(&c, lam, u, du);
        lb__conic_H(r[0], r[1], p, u[0], u[1], &H1, &H2);
        const double dTl = H1 * du[0] + H2 * du[1]; /* dH/dlambda */
        for (int i = 0; i < 2; ++i) {
            /* u_i = +-(z_i - 1) with z_i = x_i / s_i: du_i/dx_i = +-z_i / x_i */
            const double z = c.a[i] * exp(-m[i] * lam);
            const double dudxi = (union_like ? -z : z) / x[i];
            dx[i] = dTl != 0.0 ? -h * (H1 * (i == 0) + H2 * (i == 1)) * dudxi / dTl : 0.0;
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
    if (conic) {
        if ((s = lb__check_conic(fn, x, r, conic_p, m, value, err))) return s;
        if (op == LB_UNION && (r[0] > 1.0 || r[1] > 1.0))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: r = (%g, %g) is out of range for a union; allowed: 0 < r <= 1", fn,
                            r[0], r[1]);
    } else {
        if ((s = lb__check_k(fn, k, 1, LB_MAX_ARITY, err)) || (s = lb__check_out(fn, value, err)) ||
            (s = lb__check_finite(fn, "x", k, x, err)) ||
            (s = lb__check_blend_params(fn, k, r, p, m, op == LB_UNION ? 1.0 : INFINITY, err)))
            return s;
    }
    if (!m) {
        for (size_t i = 0; i < k; ++i) ones[i] = 1.0;
        m = ones;
    }
    for (size_t i = 0; i < k; ++i) xt[i] = (op == LB_DIFFERENCE && i > 0) ? 1.0 - x[i] : x[i];
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
