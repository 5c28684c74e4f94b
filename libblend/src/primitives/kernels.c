/* Field kernels: the zero convention f = rho - 1 and the soft kernels
 * K(rho) with K(1) = 0.5 [hsu-nonuniform 2.1]. */
#include "../common/internal.h"

lb_status lb_primitive_soften(lb_primitive *prim, lb_kernel kernel, lb_error *err) {
    if (!prim) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_primitive_soften: prim is NULL");
    if (kernel != LB_KERNEL_NONE && kernel != LB_KERNEL_WYVILL && kernel != LB_KERNEL_BLINN)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_primitive_soften: kernel = %d; allowed: LB_KERNEL_NONE (0), "
                        "LB_KERNEL_WYVILL (1), LB_KERNEL_BLINN (2)",
                        (int)kernel);
    prim->kernel = kernel;
    return LB_OK;
}

double lb__kernel(lb_kernel kernel, double rho, double *df) {
    double f, d;
    switch (kernel) {
    case LB_KERNEL_WYVILL: {
        const double a = 0.5 * rho;
        if (a >= 1.0) {
            f = d = 0.0;
        } else {
            /* factored, W = (1 - a^2)^2 (1 - 4/9 a^2): never negative, and
             * exact to rounding near a = 1 where the expanded form cancels */
            const double b = a * a, u = 1.0 - b;
            f = u * u * (1.0 - 4.0 / 9.0 * b);
            d = a * u * (-22.0 / 9.0 + 12.0 / 9.0 * b);
        }
        break;
    }
    case LB_KERNEL_BLINN:
        f = exp(-0.69314718055994530942 * rho * rho);
        d = -2.0 * 0.69314718055994530942 * rho * f;
        break;
    default:
        f = rho - 1.0;
        d = 1.0;
        break;
    }
    if (df) *df = d;
    return f;
}

double lb_primitive_eval(const lb_primitive *P, const double X[3], double grad[3]) {
    if (!P || !X) return NAN;
    double g[3], df;
    const double f = lb__kernel(P->kernel, lb_primitive_rho(P, X, g), &df);
    if (grad)
        for (int i = 0; i < 3; ++i) grad[i] = df * g[i];
    return f;
}
