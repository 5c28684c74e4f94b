/* Ray-linear shapes rho(X) and their constructors [hsu-bounded 2.1]. */
#include "rho.h"

#include <string.h>

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static lb_status start(const char *fn, lb_primitive *out, lb_primitive_kind kind, const double c[3],
                       lb_error *err) {
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    lb_status s = lb__check_finite(fn, "c", 3, c, err);
    if (s) return s;
    memset(out, 0, sizeof *out);
    out->kind = kind;
    out->kernel = LB_KERNEL_NONE;
    memcpy(out->c, c, sizeof out->c);
    out->a[0] = out->a[1] = out->a[2] = 1.0;
    return LB_OK;
}

static lb_status length(const char *fn, const char *name, double v, lb_error *err) {
    return lb__check_range(fn, name, 1, &v, 0.0, 0, INFINITY, 0, "finite and > 0", err);
}

static lb_status direction(const char *fn, const char *name, const double d[3], double out[3],
                           lb_error *err) {
    lb_status s = lb__check_finite(fn, name, 3, d, err);
    if (s) return s;
    const double len = sqrt(dot3(d, d));
    if (!(len > 0.0) || !isfinite(len))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %s = (%g, %g, %g) is not a direction; allowed: a non-zero vector", fn,
                        name, d[0], d[1], d[2]);
    for (int i = 0; i < 3; ++i) out[i] = d[i] / len;
    return LB_OK;
}

lb_status lb_primitive_ellipsoid(lb_primitive *out, const double c[3], const double a[3],
                                 lb_error *err) {
    static const char fn[] = "lb_primitive_ellipsoid";
    lb_status s = start(fn, out, LB_PRIM_ELLIPSOID, c, err);
    if (s || (s = lb__check_range(fn, "a", 3, a, 0.0, 0, INFINITY, 0, "finite and > 0", err)))
        return s;
    memcpy(out->a, a, sizeof out->a);
    return LB_OK;
}

lb_status lb_primitive_sphere(lb_primitive *out, const double c[3], double radius, lb_error *err) {
    lb_status s = length("lb_primitive_sphere", "radius", radius, err);
    if (s) return s;
    const double a[3] = {radius, radius, radius};
    return lb_primitive_ellipsoid(out, c, a, err);
}

lb_status lb_primitive_lp(lb_primitive *out, const double c[3], const double a[3], double n,
                          lb_error *err) {
    static const char fn[] = "lb_primitive_lp";
    lb_status s = start(fn, out, LB_PRIM_LP, c, err);
    if (s || (s = lb__check_range(fn, "a", 3, a, 0.0, 0, INFINITY, 0, "finite and > 0", err)) ||
        (s = lb__check_range(fn, "n", 1, &n, 1.0, 1, 1000.0, 1, "1 <= n <= 1000", err)))
        return s;
    memcpy(out->a, a, sizeof out->a);
    out->s0 = n;
    return LB_OK;
}

lb_status lb_primitive_superquadric(lb_primitive *out, const double c[3], const double a[3],
                                    double e1, double e2, lb_error *err) {
    static const char fn[] = "lb_primitive_superquadric";
    lb_status s = start(fn, out, LB_PRIM_SUPERQUADRIC, c, err);
    if (s || (s = lb__check_range(fn, "a", 3, a, 0.0, 0, INFINITY, 0, "finite and > 0", err)) ||
        (s = lb__check_range(fn, "e1", 1, &e1, 0.01, 1, 10.0, 1, "0.01 <= e1 <= 10", err)) ||
        (s = lb__check_range(fn, "e2", 1, &e2, 0.01, 1, 10.0, 1, "0.01 <= e2 <= 10", err)))
        return s;
    memcpy(out->a, a, sizeof out->a);
    out->s0 = e1;
    out->s1 = e2;
    return LB_OK;
}

static lb_status planar(const char *fn, lb_primitive_kind kind, lb_primitive *out,
                        const double c[3], const double n[3], double w, lb_error *err) {
    lb_status s = start(fn, out, kind, c, err);
    if (s || (s = direction(fn, "n", n, out->n, err)) || (s = length(fn, "w", w, err))) return s;
    out->s0 = w;
    return LB_OK;
}

lb_status lb_primitive_slab(lb_primitive *out, const double c[3], const double n[3], double w,
                            lb_error *err) {
    return planar("lb_primitive_slab", LB_PRIM_SLAB, out, c, n, w, err);
}

lb_status lb_primitive_halfspace(lb_primitive *out, const double c[3], const double n[3], double w,
                                 lb_error *err) {
    return planar("lb_primitive_halfspace", LB_PRIM_HALFSPACE, out, c, n, w, err);
}

lb_status lb_primitive_cylinder(lb_primitive *out, const double c[3], const double axis[3],
                                double radius, lb_error *err) {
    static const char fn[] = "lb_primitive_cylinder";
    lb_status s = start(fn, out, LB_PRIM_CYLINDER, c, err);
    if (s || (s = direction(fn, "axis", axis, out->n, err)) ||
        (s = length(fn, "radius", radius, err)))
        return s;
    out->s0 = radius;
    return LB_OK;
}

lb_status lb_primitive_capsule(lb_primitive *out, const double p0[3], const double p1[3],
                               double radius, lb_error *err) {
    static const char fn[] = "lb_primitive_capsule";
    lb_status s = start(fn, out, LB_PRIM_CAPSULE, p0, err);
    if (s || (s = lb__check_finite(fn, "p1", 3, p1, err)) ||
        (s = length(fn, "radius", radius, err)))
        return s;
    memcpy(out->q, p1, sizeof out->q);
    out->s0 = radius;
    return LB_OK;
}

lb_status lb_primitive_torus(lb_primitive *out, const double c[3], const double axis[3],
                             double major_radius, double minor_radius, lb_error *err) {
    static const char fn[] = "lb_primitive_torus";
    lb_status s = start(fn, out, LB_PRIM_TORUS, c, err);
    if (s || (s = direction(fn, "axis", axis, out->n, err)) ||
        (s = length(fn, "major_radius", major_radius, err)) ||
        (s = length(fn, "minor_radius", minor_radius, err)))
        return s;
    out->s0 = major_radius;
    out->s1 = minor_radius;
    return LB_OK;
}

double lb_primitive_rho(const lb_primitive *P, const double X[3], double g[3]) {
    if (!P || !X) return NAN;
    double scratch[3];
    return lb__rho(P->kind, P, X, g ? g : scratch);
}
