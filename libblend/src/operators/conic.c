/* Binary conic BT_2 [hsu2006 3.2.1, Eq. 4], zero convention.
 *
 * H(u1,u2) = r2^2 u1^2 + r1^2 u2^2 + r1^2 r2^2 - 2 r2^2 r1 u1 - 2 r1^2 r2 u2
 *            + 2 p u1 u2,  p < r1 r2,
 * with u_i = x_i - m_i h. Outside region II the union is h1 = min(x1/m1, x2/m2).
 * Inside, the root of H(u(h)) = 0 between the chord value h2 and h1. We
 * solve in the shifted variable s = h - h1 (u_i = v_i - m_i s with
 * v_i = x_i - m_i h1 >= 0, one of them 0), which keeps the quadratic's
 * coefficients of the size of r even when |x| is huge, and take the root
 * with the cancellation-free formula q = -(b + sign(b) sqrt(D))/2.
 * Gradients by the implicit function theorem with E = m1 H_u1 + m2 H_u2:
 * dh/dx_i = H_ui / E, dh/dm_i = -h H_ui / E, dh/dr_i = H_ri / E.
 *
 * Two paths compute that root. conic_fast (value and d/dx, the calls that
 * scenes, POV-Ray export and the public scalar entry make) scales the same
 * quadratic so that one division serves the value and the gradient; it
 * declines the rare cases where that loses digits (nearly degenerate conics,
 * the root outside [h2, h1] by rounding). conic_union_general (those cases,
 * and every call that asks for d/dr or d/dm) is the shifted form above.
 * Both agree with a long-double reference to 1e-12 (tests/test_conic.c). */
#include "../common/internal.h"
#include "../solver/root.h"

typedef struct {
    double v1, v2, r1, r2, p, m1, m2;
} conic_ctx;

/* The argument attaining min(x0/m0, x1/m1), compared cross-multiplied */
static inline size_t conic_argmin(const double x[2], const double m[2]) {
    return x[1] * m[0] < x[0] * m[1];
}

/* Region II test; fills the shifted context and h1. Returns 0 outside. */
static int conic_setup(const double x[2], const double r[2], double p, const double m[2],
                       conic_ctx *c, double *h1, size_t *argmin) {
    *argmin = conic_argmin(x, m);
    *h1 = x[*argmin] / m[*argmin];
    c->r1 = r[0];
    c->r2 = r[1];
    c->p = p;
    c->m1 = m[0];
    c->m2 = m[1];
    c->v1 = *argmin == 0 ? 0.0 : x[0] - m[0] * *h1;
    c->v2 = *argmin == 1 ? 0.0 : x[1] - m[1] * *h1;
    /* region II <=> the other argument is within its range at h1 */
    return *argmin == 0 ? c->v2 < r[1] : c->v1 < r[0];
}

static double conic_grads(const conic_ctx *c, double h1, double s, double dx[2], double dr[2],
                          double dm[2]) {
    const double u1 = c->v1 - c->m1 * s, u2 = c->v2 - c->m2 * s;
    double H1, H2;
    lb__conic_H(c->r1, c->r2, c->p, u1, u2, &H1, &H2);
    const double iE = 1.0 / (c->m1 * H1 + c->m2 * H2);
    const double h = h1 + s;
    if (dx) {
        dx[0] = H1 * iE;
        dx[1] = H2 * iE;
    }
    if (dm) {
        dm[0] = -h * H1 * iE;
        dm[1] = -h * H2 * iE;
    }
    if (dr) {
        const double r1 = c->r1, r2 = c->r2;
        dr[0] = 2.0 * (r1 * u2 * u2 + r1 * r2 * r2 - r2 * r2 * u1 - 2.0 * r1 * r2 * u2) * iE;
        dr[1] = 2.0 * (r2 * u1 * u1 + r1 * r1 * r2 - 2.0 * r1 * r2 * u1 - r1 * r1 * u2) * iE;
    }
    return h;
}

static double outside_grads(size_t j, const double m[2], double h1, double dx[2], double dr[2],
                            double dm[2]) {
    for (size_t i = 0; i < 2; ++i) {
        if (dx) dx[i] = i == j ? 1.0 / m[i] : 0.0;
        if (dr) dr[i] = 0.0;
        if (dm) dm[i] = i == j ? -h1 / m[i] : 0.0;
    }
    return h1;
}

/* Region II for the value and d/dx only, with one division and no division
 * before the square root (a call's cost is its instruction count and the
 * sqrt -> division chain). Let j attain min(x_i/m_i), o the other argument,
 * N = x_o m_j - m_o x_j = m_j v_o >= 0 and g = r_o m_j - N (> 0 inside).
 * m_j^2 H as a quadratic in u = u_j = x_j - m_j h is
 *     A u^2 + B u + C,  A = a,  B = 2 (p m_j N - r_j^2 m_o g - r_j r_o^2 m_j^2),
 *     C = r_j^2 g^2,
 * whose coefficients are of the size of r and m however large |x| is. The
 * root in range is C/q (q = -(B + sign(B) sqrt(D))/2, D = B^2 - 4AC), and
 * there E = m1 H1 + m2 H2 = sign(B) sqrt(D) / m_j, so R = 1/(q m_j sqrt(D))
 * gives h = (x_j q - C) sqrt(D) R, u = C m_j sqrt(D) R and 1/E. With
 * G_i = m_j H_ui (written with m_j u_o = N + m_o u): dh/dx_i = G_i sign(B)/sqrt(D).
 * Returns 0, writing nothing, when the root is not in [0, u_max] or D is
 * ill-conditioned (E would lose digits): conic_union_general decides those. */
static inline int conic_fast(const double x[2], const double r[2], double p, const double m[2],
                             size_t j, double *h, double dx[2]) {
    const size_t o = 1 - j;
    const double xj = x[j], rj = r[j], ro = r[o], mj = m[j], mo = m[o];
    const double N = x[o] * mj - mo * xj, romj = ro * mj, g = romj - N, rrj = rj * rj;
    const double A = r[1] * r[1] * m[0] * m[0] + r[0] * r[0] * m[1] * m[1] + 2.0 * p * m[0] * m[1];
    const double B = 2.0 * (p * mj * N - rrj * mo * g - rj * ro * romj * mj);
    const double C = rrj * g * g, f4 = 4.0 * A * C, D = B * B - f4;
    const double sD = sqrt(D > 0.0 ? D : 0.0);
    const double q = -0.5 * (B + copysign(sD, B)), Z = q * mj, den = Z * sD;
    const double R = 1.0 / den, iZ = sD * R, u = C * mj * iZ;
    const double w = rj * mo + romj; /* u_max w = r_j g: the chord value */
    if (!((u >= 0.0) & (u * w <= rj * g) & (D > 1e-4 * (B * B + fabs(f4))) & (fabs(den) > 1e-290) &
          (fabs(den) < 1e290)))
        return 0;
    *h = (xj * q - C) * iZ;
    if (dx) {
        const double mu_o = N + mo * u, iE = copysign(Z * R, B);
        dx[j] = 2.0 * (ro * ro * mj * (u - rj) + p * mu_o) * iE;
        dx[o] = 2.0 * (rrj * (mu_o - romj) + p * mj * u) * iE;
    }
    return 1;
}

static double conic_union_general(const double x[2], const double r[2], double p, const double m[2],
                                  double dx[2], double dr[2], double dm[2]);

/* lb__conic_union's body, inlined into lb_conic's union call */
static inline double conic_union(const double x[2], const double r[2], double p, const double m[2],
                                 double dx[2], double dr[2], double dm[2]) {
    const size_t j = conic_argmin(x, m), o = 1 - j;
    if (!(x[o] * m[j] - m[o] * x[j] < r[o] * m[j])) { /* outside region II */
        const double h1 = x[j] / m[j];
        return outside_grads(j, m, h1, dx, dr, dm);
    }
    double h;
    if (!dr && !dm && conic_fast(x, r, p, m, j, &h, dx)) return h;
    return conic_union_general(x, r, p, m, dx, dr, dm);
}

double lb__conic_union(const double x[2], const double r[2], double p, const double m[2],
                       double dx[2], double dr[2], double dm[2]) {
    return conic_union(x, r, p, m, dx, dr, dm);
}

/* The shifted quadratic in s = h - h1, with dr and dm, and the careful choice
 * of root when the obvious one is out of range. */
LB_NOINLINE static double conic_union_general(const double x[2], const double r[2], double p,
                                              const double m[2], double dx[2], double dr[2],
                                              double dm[2]) {
    conic_ctx c;
    double h1;
    size_t j;
    if (!conic_setup(x, r, p, m, &c, &h1, &j)) return outside_grads(j, m, h1, dx, dr, dm);
    const double r1 = c.r1, r2 = c.r2, m1 = c.m1, m2 = c.m2, v1 = c.v1, v2 = c.v2;
    const double a = r2 * r2 * m1 * m1 + r1 * r1 * m2 * m2 + 2.0 * p * m1 * m2;
    const double b =
        2.0 * ((r1 - v1) * r2 * r2 * m1 + (r2 - v2) * r1 * r1 * m2 - p * (v1 * m2 + v2 * m1));
    const double chord = r1 * v2 + r2 * v1 - r1 * r2;
    const double cc = chord * chord + 2.0 * (p - r1 * r2) * v1 * v2;
    const double w = r1 * m2 + r2 * m1; /* the chord value is s2 = chord / w <= 0 */
    double D = b * b - 4.0 * a * cc;
    if (D < 0.0) D = 0.0;
    const double q = -0.5 * (b + (b >= 0.0 ? sqrt(D) : -sqrt(D)));
    /* roots cc/q and q/a; the one in [s2, 0] is almost always cc/q, so that
     * one is tried first (the test s >= s2 is s w >= chord: no division) */
    double s = q != 0.0 ? cc / q : NAN;
    if (!(s <= 0.0 && s * w >= chord)) {
        const double s2 = chord / w;
        double best = s, best_dist = INFINITY;
        const double cand[2] = {s, a != 0.0 ? q / a : NAN};
        for (int i = 0; i < 2; ++i) {
            if (!isfinite(cand[i])) continue;
            const double d = cand[i] > 0.0 ? cand[i] : cand[i] < s2 ? s2 - cand[i] : 0.0;
            if (d < best_dist) {
                best_dist = d;
                best = cand[i];
            }
        }
        s = isfinite(best) ? best : 0.0;
        if (s > 0.0) s = 0.0;
        if (s < s2) s = s2;
    }
    return conic_grads(&c, h1, s, dx, dr, dm);
}

static void conic_T(double s, const void *vctx, double *T, double *dT, double *d2T,
                    double *smooth) {
    (void)d2T;
    (void)smooth;
    const conic_ctx *c = vctx;
    const double u1 = c->v1 - c->m1 * s, u2 = c->v2 - c->m2 * s;
    double H1, H2;
    const double n = 1.0 / (c->r1 * c->r1 * c->r2 * c->r2); /* H is of size r1^2 r2^2 */
    *T = n * lb__conic_H(c->r1, c->r2, c->p, u1, u2, &H1, &H2);
    *dT = -n * (c->m1 * H1 + c->m2 * H2);
}

double lb__conic_union_solved(const double x[2], const double r[2], double p, const double m[2],
                              double dx[2]) {
    conic_ctx c;
    double h1;
    size_t j;
    if (!conic_setup(x, r, p, m, &c, &h1, &j)) return outside_grads(j, m, h1, dx, NULL, NULL);
    const double s2 = (c.r1 * c.v2 + c.r2 * c.v1 - c.r1 * c.r2) / (c.r1 * c.m2 + c.r2 * c.m1);
    const double s = lb__root_solve(conic_T, &c, s2, 0.0, 0.0);
    return conic_grads(&c, h1, s, dx, NULL, NULL);
}

lb_status lb__check_conic(const char *fn, const double x[2], const double r[2], double p,
                          const double m[2], const void *value, lb_error *err) {
    lb_status s;
    if ((s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", 2, x, err)) ||
        (s = lb__check_r_m(fn, "r", "m", 2, r, m, INFINITY, LB_MIN_SLOPE, LB_MAX_SLOPE, err)))
        return s;
    if (!isfinite(p) || !(p < r[0] * r[1]))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: p = %g is out of range; allowed: p < r[0]*r[1] = %g (conic shape)", fn,
                        p, r[0] * r[1]);
    return LB_OK;
}

lb_status lb_conic(lb_setop op, const double x[2], const double r[2], double p, const double m[2],
                   double *value, double grad[2], lb_error *err) {
    static const char fn[] = "lb_conic";
    if (!((unsigned)op <= LB_DIFFERENCE && value && lb__fast_ok(2, x, r, NULL, m, INFINITY) &&
          p < r[0] * r[1] && p > -INFINITY)) {
        lb_status s;
        if ((s = lb__check_setop(fn, op, err)) || (s = lb__check_conic(fn, x, r, p, m, value, err)))
            return s;
        return lb__fail(err, LB_ERR_INTERNAL, "%s: parameter check disagreement", fn);
    }
    static const double ones[2] = {1.0, 1.0};
    if (op == LB_UNION) {
        *value = conic_union(x, r, p, m ? m : ones, grad, NULL, NULL);
        return LB_OK;
    }
    double xt[2], sg[2];
    lb__dual_args(op, 2, x, xt, sg);
    const double h = lb__conic_union(xt, r, p, m ? m : ones, grad, NULL, NULL);
    const double out = op == LB_UNION ? 1.0 : -1.0;
    *value = out * h;
    if (grad)
        for (size_t i = 0; i < 2; ++i) grad[i] *= out * sg[i];
    return LB_OK;
}
