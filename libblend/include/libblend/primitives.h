/*
 * libblend — primitives.h: the fields that blends combine.
 *
 * Naming and invariants (stated once for every primitive):
 *  - A primitive is built into a caller-owned lb_primitive by one
 *    lb_primitive_<shape>() constructor, which validates every parameter.
 *    Treat the struct's fields as read-only.
 *  - Every shape is a ray-linear (or, for the torus, distance-like) function
 *    rho(X) >= 0 that is 1 on the surface [hsu-bounded 2.1].
 *    Zero convention (the default): f = rho - 1, so f >= -1, f < 0 inside.
 *    Soft convention (lb_primitive_soften): f = K(rho), f > 0.5 inside,
 *    f = 0.5 on the same surface [hsu-nonuniform 2.1]:
 *      LB_KERNEL_WYVILL: K(rho) = W(rho/2), W(a) = 1 - 4/9 a^6 + 17/9 a^4 - 22/9 a^2
 *                        for a <= 1, else 0 (support ends at rho = 2, i.e. at
 *                        twice the primitive's size)
 *      LB_KERNEL_BLINN:  K(rho) = exp(-ln 2 rho^2) (so K(1) = 0.5; never 0)
 *  - lb_primitive_eval returns the field and writes its spatial gradient.
 *    Where rho is not differentiable (a sphere's centre, a skeleton, a
 *    half-space's boundary) the gradient is a one-sided value or 0; it is
 *    always finite for finite X.
 */
#ifndef LIBBLEND_PRIMITIVES_H
#define LIBBLEND_PRIMITIVES_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lb_primitive_kind {
    LB_PRIM_ELLIPSOID = 0, /* rho = |diag(1/a) (X - c)|; a sphere when a is uniform */
    LB_PRIM_LP = 1,        /* rho = (sum |x_i/a_i|^n)^(1/n), n >= 1 */
    LB_PRIM_SUPERQUADRIC =
        2,            /* Barr: ((|x/a1|^(2/e2) + |y/a2|^(2/e2))^(e2/e1) + |z/a3|^(2/e1))^(e1/2) */
    LB_PRIM_SLAB = 3, /* rho = |n.(X - c)| / w: the space between two parallel planes */
    LB_PRIM_HALFSPACE =
        4, /* rho = [n.(X - c)]+ / w: inside is n.(X - c) < w; only C0 at n.(X-c) = 0 */
    LB_PRIM_CYLINDER = 5, /* rho = dist(X, axis through c along n) / R (infinite) */
    LB_PRIM_CAPSULE = 6,  /* rho = dist(X, segment c..q) / R */
    LB_PRIM_TORUS = 7     /* rho = dist(X, circle of radius R about axis n at c) / r */
} lb_primitive_kind;

typedef enum lb_kernel {
    LB_KERNEL_NONE = 0,   /* zero convention: f = rho - 1 */
    LB_KERNEL_WYVILL = 1, /* soft convention, Wyvill's soft object */
    LB_KERNEL_BLINN = 2   /* soft convention, Blinn's blob */
} lb_kernel;

typedef struct lb_primitive {
    lb_primitive_kind kind;
    lb_kernel kernel;
    double c[3]; /* centre, point on the plane(s) or axis, or segment start */
    double a[3]; /* semi-axes (ellipsoid, LP, superquadric) */
    double n[3]; /* unit normal (slab, half-space) or unit axis (cylinder, torus) */
    double q[3]; /* segment end (capsule) */
    double s0;   /* n (LP), e1 (superquadric), w (slab, half-space), R (cylinder, capsule, torus) */
    double s1;   /* e2 (superquadric), r (torus) */
} lb_primitive;

/* Constructors. Every length (a_i, w, R, r) must be finite and > 0, every
 * point finite, every direction finite and non-zero (it is normalised). */
LB_API lb_status lb_primitive_sphere(lb_primitive *out, const double c[3], double radius,
                                     lb_error *err);
LB_API lb_status lb_primitive_ellipsoid(lb_primitive *out, const double c[3], const double a[3],
                                        lb_error *err);
/* 1 <= n <= 1000 */
LB_API lb_status lb_primitive_lp(lb_primitive *out, const double c[3], const double a[3], double n,
                                 lb_error *err);
/* 0.01 <= e1, e2 <= 10 (1 = round, -> 0 = square) */
LB_API lb_status lb_primitive_superquadric(lb_primitive *out, const double c[3], const double a[3],
                                           double e1, double e2, lb_error *err);
LB_API lb_status lb_primitive_slab(lb_primitive *out, const double c[3], const double n[3],
                                   double w, lb_error *err);
LB_API lb_status lb_primitive_halfspace(lb_primitive *out, const double c[3], const double n[3],
                                        double w, lb_error *err);
LB_API lb_status lb_primitive_cylinder(lb_primitive *out, const double c[3], const double axis[3],
                                       double radius, lb_error *err);
/* p0 may equal p1 (a ball) */
LB_API lb_status lb_primitive_capsule(lb_primitive *out, const double p0[3], const double p1[3],
                                      double radius, lb_error *err);
LB_API lb_status lb_primitive_torus(lb_primitive *out, const double c[3], const double axis[3],
                                    double major_radius, double minor_radius, lb_error *err);

/* Switch a constructed primitive to the soft convention with the given
 * kernel (LB_KERNEL_NONE switches back to the zero convention). */
LB_API lb_status lb_primitive_soften(lb_primitive *prim, lb_kernel kernel, lb_error *err);

/* The ray-linear function rho at X (grad may be NULL; NaN when prim or X is
 * NULL). */
LB_API double lb_primitive_rho(const lb_primitive *prim, const double X[3], double grad[3]);

/* The primitive's field at X in its convention, and its gradient (grad may be
 * NULL). prim must come from a constructor above; NaN when prim or X is NULL. */
LB_API double lb_primitive_eval(const lb_primitive *prim, const double X[3], double grad[3]);

#ifdef __cplusplus
}
#endif

#endif
