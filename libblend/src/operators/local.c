/* Local blending's operators [bernhardt2010 §3; the project's local-blending
 * spec]: the clean unions UR, UC2, UC3 and UC (with the convolution weights
 * alpha), Barthe's smooth blend UB in the rationalised closed form, and the
 * interpolation U = (1 - beta) UC + beta UB, beta = v^n.
 *
 * Soft convention with iso value C > 0: f > C inside, the unions are
 * Max-like. Every blended form is written as max + w (V - max), so where V
 * equals max (on the union surface, and wherever the weight vanishes) the
 * result is max(f1, f2) bit for bit. Gradients are analytic; at ties max
 * differentiates with respect to the first argument, as lb_classic does. */
#include "../common/internal.h"

#define SQRT1_2 0.70710678118654752440
#define TWO_MINUS_SQRT2 0.58578643762690495120 /* 2 - sqrt 2 */

/* UR(x, y) = x + y + sqrt(x^2 + y^2) and its gradient */
static double ur(double x, double y, double g[2]) {
    /* |x|, |y| <= 1e100 (the callers' limit): the squares cannot overflow */
    const double q = sqrt(x * x + y * y);
    if (q > 0.0) {
        g[0] = 1.0 + x / q;
        g[1] = 1.0 + y / q;
    } else {
        g[0] = g[1] = 1.0 + SQRT1_2;
    }
    return x + y + q;
}

/* UC2 = C + UR(f1 - C, f2 - C) / (2 - sqrt 2): C on the union surface,
 * UC2(0, 0) = 0 */
static double uc2(const double f[2], double C, double g[2]) {
    const double v = ur(f[0] - C, f[1] - C, g);
    g[0] /= TWO_MINUS_SQRT2;
    g[1] /= TWO_MINUS_SQRT2;
    return C + v / TWO_MINUS_SQRT2;
}

/* The weight delta_c: 0 where u = f1 - a1 f2 <= 0 or v = f2 - a2 f1 <= 0,
 * else (4 u v / (u + v)^2)^4 (alpha = 0: delta). Values below
 * LB_SOFT_MIN_FIELD count as 0, so 1 / (u + v) stays finite. */
static double weight(const double f[2], const double a[2], double g[2]) {
    const double u = f[0] - a[0] * f[1], v = f[1] - a[1] * f[0];
    if (!(u > LB_SOFT_MIN_FIELD) || !(v > LB_SOFT_MIN_FIELD)) {
        g[0] = g[1] = 0.0;
        return 0.0;
    }
    const double is = 1.0 / (u + v), su = u * is, sv = v * is;
    const double t = 4.0 * su * sv, t3 = t * t * t;
    /* dt/du = 4 v (v - u) / s^3, dt/dv = 4 u (u - v) / s^3 */
    const double dtu = 4.0 * sv * (sv - su) * is, dtv = 4.0 * su * (su - sv) * is;
    const double du = 4.0 * t3 * dtu, dv = 4.0 * t3 * dtv;
    g[0] = du - a[1] * dv; /* du/df1 = 1, dv/df1 = -a2 */
    g[1] = dv - a[0] * du; /* du/df2 = -a1, dv/df2 = 1 */
    return t3 * t;
}

double lb__clean_eval(lb_clean_kind kind, const double f[2], double C, const double a[2],
                      double g[2]) {
    if (kind == LB_CLEAN_UR) return ur(f[0], f[1], g);
    if (kind == LB_CLEAN_UC2) return uc2(f, C, g);
    const int first = f[0] >= f[1];
    const double mx = first ? f[0] : f[1];
    const double gm[2] = {first ? 1.0 : 0.0, first ? 0.0 : 1.0};
    double gw[2], gv[2];
    const double w = weight(f, a, gw);
    double V;
    if (kind == LB_CLEAN_UC3 || mx < C) {
        V = uc2(f, C, gv); /* UC3 everywhere; UC outside both */
    } else if (!(f[0] < C) && !(f[1] < C)) {
        /* inside both: Barthe's clean union, no inner contraction */
        const double x = f[0] - C, y = f[1] - C, q = sqrt(x * x + y * y);
        V = C + q;
        gv[0] = q > 0.0 ? x / q : SQRT1_2;
        gv[1] = q > 0.0 ? y / q : SQRT1_2;
    } else {
        V = mx; /* inside one only: the union itself */
        gv[0] = gm[0];
        gv[1] = gm[1];
    }
    const double d = V - mx;
    for (int i = 0; i < 2; ++i) g[i] = gm[i] + w * (gv[i] - gm[i]) + d * gw[i];
    return w == 0.0 || d == 0.0 ? mx : mx + w * d;
}

lb_status lb_clean_union(lb_clean_kind kind, const double f[2], double C, const double alpha[2],
                         double *value, double grad[2], lb_error *err) {
    static const char fn[] = "lb_clean_union";
    lb_status s;
    if ((int)kind < LB_CLEAN_UR || kind > LB_CLEAN_UC)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: kind = %d; allowed: LB_CLEAN_UR (0), LB_CLEAN_UC2, LB_CLEAN_UC3, "
                        "LB_CLEAN_UC (3)",
                        fn, (int)kind);
    if ((s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "f", 2, f, err))) return s;
    if (kind != LB_CLEAN_UR &&
        (s = lb__check_range(fn, "C (iso value)", 1, &C, LB_SOFT_MIN_ISO, 1, LB_MAX_ABS_ARG, 1,
                             "1e-100 <= C <= 1e100 (0.5 for fields in [0, 1])", err)))
        return s;
    const double zero[2] = {0.0, 0.0};
    if (alpha && (s = lb__check_range(fn, "alpha", 2, alpha, 0.0, 1, 1.0, 0,
                                      "0 <= alpha_i < 1 (0: finite support)", err)))
        return s;
    double g[2];
    *value = lb__clean_eval(kind, f, C, alpha ? alpha : zero, g);
    if (grad) {
        grad[0] = g[0];
        grad[1] = g[1];
    }
    return LB_OK;
}

/* UB: max outside the wedge q x < y, p y < x; inside, the rationalised
 * root of A u^2 - 2 B u + D = 0 (the level-u quarter ellipse through
 * (x, y), tangent to x = u and y = u). */
double lb__barthe_eval(const double xy[2], double p, double q, double g[2]) {
    const double x = xy[0], y = xy[1];
    if (y <= q * x || x <= p * y) {
        const int first = x >= y;
        g[0] = first ? 1.0 : 0.0;
        g[1] = first ? 0.0 : 1.0;
        return first ? x : y;
    }
    /* u is homogeneous of degree 1 in (x, y) and the gradient of degree 0:
     * solve for (x, y) / m, m = max(x, y) > 0 inside the wedge, so that
     * squares neither underflow (x = 4e-321, y = 7e-171 gave 0 / 0) nor
     * overflow */
    const double m = x > y ? x : y, xs = x / m, ys = y / m;
    const double P = 1.0 - p, Q = 1.0 - q, P2 = P * P, Q2 = Q * Q;
    const double A = Q2 * p * p + P2 * q * q - P2 * Q2;
    const double B = Q2 * p * xs + P2 * q * ys;
    const double D = Q2 * xs * xs + P2 * ys * ys;
    double disc = B * B - A * D;
    if (disc < 0.0) disc = 0.0; /* rounding only: inside the wedge it is positive */
    const double sq = sqrt(disc), us = D / (B + sq);
    if (sq > 0.0) {
        g[0] = Q2 * (xs - p * us) / sq;
        g[1] = P2 * (ys - q * us) / sq;
    } else {
        g[0] = g[1] = 0.5;
    }
    return us * m;
}

lb_status lb_barthe_blend(const double x[2], double p, double q, double *value, double grad[2],
                          lb_error *err) {
    static const char fn[] = "lb_barthe_blend";
    lb_status s;
    if ((s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", 2, x, err)) ||
        (s = lb__check_range(fn, "p", 1, &p, 0.0, 1, LB_BARTHE_MAX_PQ, 1,
                             "0 <= p <= 0.999 (the blend leaves x = u where y = p u)", err)) ||
        (s = lb__check_range(fn, "q", 1, &q, 0.0, 1, LB_BARTHE_MAX_PQ, 1,
                             "0 <= q <= 0.999 (the blend leaves y = u where x = q u)", err)))
        return s;
    double g[2];
    *value = lb__barthe_eval(x, p, q, g);
    if (grad) {
        grad[0] = g[0];
        grad[1] = g[1];
    }
    return LB_OK;
}

lb_status lb_local_mix(double uc, double ub, double v, double n, double *value, double grad[3],
                       lb_error *err) {
    static const char fn[] = "lb_local_mix";
    lb_status s;
    const double in[2] = {uc, ub};
    if ((s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "uc, ub", 2, in, err)) ||
        (s = lb__check_range(fn, "v (blending volume field)", 1, &v, 0.0, 1, 1.0, 1, "0 <= v <= 1",
                             err)) ||
        (s = lb__check_range(fn, "n", 1, &n, 1.0, 1, LB_MAX_EXPONENT, 1, "1 <= n <= 1000", err)))
        return s;
    const double beta = v > 0.0 ? pow(v, n) : 0.0;
    *value = beta == 0.0 ? uc : beta == 1.0 ? ub : uc + beta * (ub - uc);
    if (grad) {
        grad[0] = 1.0 - beta;
        grad[1] = beta;
        /* d beta / dv = n v^(n-1): 1 at v = 0 when n = 1, else 0 there */
        const double db = v > 0.0 ? n * pow(v, n - 1.0) : n == 1.0 ? 1.0 : 0.0;
        grad[2] = db * (ub - uc);
    }
    return LB_OK;
}
