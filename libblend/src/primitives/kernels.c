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

double lb_primitive_eval(const lb_primitive *P, const double X[3], double grad[3]) {
    double g[3];
    const double rho = lb_primitive_rho(P, X, g);
    double f, df;
    switch (P->kernel) {
    case LB_KERNEL_WYVILL: {
        const double a = 0.5 * rho;
        if (a >= 1.0) {
            f = df = 0.0;
        } else {
            const double a2 = a * a;
            f = 1.0 + a2 * (-22.0 / 9.0 + a2 * (17.0 / 9.0 - 4.0 / 9.0 * a2));
            df = 0.5 * a * (-44.0 / 9.0 + a2 * (68.0 / 9.0 - 24.0 / 9.0 * a2));
        }
        break;
    }
    case LB_KERNEL_BLINN:
        f = exp(-0.69314718055994530942 * rho * rho);
        df = -2.0 * 0.69314718055994530942 * rho * f;
        break;
    default:
        f = rho - 1.0;
        df = 1.0;
        break;
    }
    if (grad)
        for (int i = 0; i < 3; ++i) grad[i] = df * g[i];
    return f;
}
