/* Classic operators: the baselines users know (docs/operators.md 8). */
#include "../common/internal.h"

static double classic_eval(lb_classic_kind kind, size_t k, const double *x, double n, double *g) {
    double v = 0.0;
    switch (kind) {
    case LB_MIN:
    case LB_MAX: {
        size_t j = 0;
        for (size_t i = 1; i < k; ++i)
            if (kind == LB_MIN ? x[i] < x[j] : x[i] > x[j]) j = i;
        if (g)
            for (size_t i = 0; i < k; ++i) g[i] = i == j;
        return x[j];
    }
    case LB_RFUNC_UNION:
    case LB_RFUNC_INTERSECTION: {
        const double s = kind == LB_RFUNC_UNION ? -1.0 : 1.0;
        const double q = hypot(x[0], x[1]);
        if (g) {
            if (q > 0.0) {
                g[0] = 1.0 + s * x[0] / q;
                g[1] = 1.0 + s * x[1] / q;
            } else {
                g[0] = g[1] = 1.0 + s * 0.70710678118654752440;
            }
        }
        return x[0] + x[1] + s * q;
    }
    case LB_SOFT_SUM:
        for (size_t i = 0; i < k; ++i) {
            v += x[i];
            if (g) g[i] = 1.0;
        }
        return v;
    case LB_RICCI_UNION: {
        double mx = 0.0;
        for (size_t i = 0; i < k; ++i)
            if (x[i] > mx) mx = x[i];
        if (mx == 0.0) {
            if (g)
                for (size_t i = 0; i < k; ++i) g[i] = 0.0;
            return 0.0;
        }
        /* scaled by the largest argument so x^n cannot overflow */
        double s = 0.0;
        for (size_t i = 0; i < k; ++i) s += x[i] > 0.0 ? pow(x[i] / mx, n) : 0.0;
        v = mx * pow(s, 1.0 / n);
        if (g)
            for (size_t i = 0; i < k; ++i) g[i] = x[i] > 0.0 ? pow(x[i] / v, n - 1.0) : 0.0;
        return v;
    }
    case LB_PERLIN_UNION:
    case LB_PERLIN_INTERSECTION:
    case LB_PERLIN_DIFFERENCE: {
        /* prod of factors f_i; union 1 - prod(1 - x), intersection prod x,
         * difference x_0 prod_{i>0} (1 - x_i) */
        double f[LB_MAX_ARITY], df[LB_MAX_ARITY];
        v = 1.0;
        for (size_t i = 0; i < k; ++i) {
            const int plain =
                kind == LB_PERLIN_INTERSECTION || (kind == LB_PERLIN_DIFFERENCE && i == 0);
            f[i] = plain ? x[i] : 1.0 - x[i];
            df[i] = plain ? 1.0 : -1.0;
            v *= f[i];
        }
        const double outer = kind == LB_PERLIN_UNION ? -1.0 : 1.0;
        if (g)
            for (size_t i = 0; i < k; ++i) {
                double rest = 1.0; /* product of the other factors, no division by f_i */
                for (size_t j = 0; j < k; ++j)
                    if (j != i) rest *= f[j];
                g[i] = outer * df[i] * rest;
            }
        return kind == LB_PERLIN_UNION ? 1.0 - v : v;
    }
    }
    return NAN;
}

lb_status lb_classic(lb_classic_kind kind, size_t k, const double *x, double param, double *value,
                     double *grad, lb_error *err) {
    static const char fn[] = "lb_classic";
    lb_status s;
    if ((int)kind < LB_MIN || kind > LB_PERLIN_DIFFERENCE)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: kind = %d; allowed: LB_MIN (0) .. LB_PERLIN_DIFFERENCE (8)", fn,
                        (int)kind);
    const int binary = kind == LB_RFUNC_UNION || kind == LB_RFUNC_INTERSECTION;
    /* min, max, the sum and Ricci's union need no per-argument scratch */
    const int wide =
        kind == LB_MIN || kind == LB_MAX || kind == LB_SOFT_SUM || kind == LB_RICCI_UNION;
    const size_t kmax = binary ? 2 : wide ? LB_MAX_ARITY_WIDE : LB_MAX_ARITY;
    if ((s = lb__check_k(fn, k, binary ? 2 : 1, kmax, err)) ||
        (s = lb__check_out(fn, value, err)) || (s = lb__check_finite(fn, "x", k, x, err)))
        return s;
    if (kind == LB_RICCI_UNION &&
        (s = lb__check_range(fn, "param (Ricci exponent n)", 1, &param, 1.0, 1, LB_MAX_EXPONENT, 1,
                             "1 <= n <= 1000", err)))
        return s;
    *value = classic_eval(kind, k, x, param, grad);
    return LB_OK;
}
