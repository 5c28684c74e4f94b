/* Ray-linear shapes rho(X) and their constructors [hsu-bounded 2.1]. */
#include "../common/internal.h"

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

/* rho = |v| / scale with gradient v / (|v| scale), 0 at v = 0. */
static double norm_over(const double v[3], double scale, double *g) {
    const double len = sqrt(dot3(v, v));
    if (g)
        for (int i = 0; i < 3; ++i) g[i] = len > 0.0 ? v[i] / (len * scale) : 0.0;
    return len / scale;
}

double lb_primitive_rho(const lb_primitive *P, const double X[3], double g[3]) {
    double d[3] = {X[0] - P->c[0], X[1] - P->c[1], X[2] - P->c[2]};
    switch (P->kind) {
    case LB_PRIM_ELLIPSOID: {
        double u[3];
        for (int i = 0; i < 3; ++i) u[i] = d[i] / P->a[i];
        const double f = sqrt(dot3(u, u));
        if (g)
            for (int i = 0; i < 3; ++i) g[i] = f > 0.0 ? u[i] / (P->a[i] * f) : 0.0;
        return f;
    }
    case LB_PRIM_LP: {
        const double n = P->s0;
        double u[3], mx = 0.0, s = 0.0;
        for (int i = 0; i < 3; ++i) {
            u[i] = fabs(d[i]) / P->a[i];
            if (u[i] > mx) mx = u[i];
        }
        if (mx == 0.0) {
            if (g) g[0] = g[1] = g[2] = 0.0;
            return 0.0;
        }
        for (int i = 0; i < 3; ++i) s += pow(u[i] / mx, n);
        const double f = mx * pow(s, 1.0 / n);
        if (g)
            for (int i = 0; i < 3; ++i)
                g[i] = pow(u[i] / f, n - 1.0) * (d[i] < 0.0 ? -1.0 : 1.0) / P->a[i];
        return f;
    }
    case LB_PRIM_SUPERQUADRIC: {
        const double e1 = P->s0, e2 = P->s1, al = 2.0 / e2, be = 2.0 / e1;
        double u[3];
        for (int i = 0; i < 3; ++i) u[i] = fabs(d[i]) / P->a[i];
        /* scale by the largest |u| so the powers cannot overflow: rho is ray-linear */
        const double mx = fmax(u[0], fmax(u[1], u[2]));
        if (mx == 0.0) {
            if (g) g[0] = g[1] = g[2] = 0.0;
            return 0.0;
        }
        for (int i = 0; i < 3; ++i) u[i] /= mx;
        const double A = pow(u[0], al) + pow(u[1], al);
        const double B = A > 0.0 ? pow(A, be / al) : 0.0;
        const double S = B + pow(u[2], be);
        const double f1 = pow(S, 1.0 / be); /* rho at the scaled point */
        if (g) {
            const double k = f1 / S;
            const double Ab = A > 0.0 ? pow(A, be / al - 1.0) : 0.0;
            for (int i = 0; i < 2; ++i)
                g[i] = u[i] > 0.0
                           ? k * Ab * pow(u[i], al - 1.0) * (d[i] < 0.0 ? -1.0 : 1.0) / P->a[i]
                           : 0.0;
            g[2] = u[2] > 0.0 ? k * pow(u[2], be - 1.0) * (d[2] < 0.0 ? -1.0 : 1.0) / P->a[2] : 0.0;
        }
        return mx * f1;
    }
    case LB_PRIM_SLAB:
    case LB_PRIM_HALFSPACE: {
        const double t = dot3(P->n, d);
        const double sg = t < 0.0 ? (P->kind == LB_PRIM_SLAB ? -1.0 : 0.0) : 1.0;
        if (g)
            for (int i = 0; i < 3; ++i) g[i] = sg * P->n[i] / P->s0;
        return sg * t / P->s0;
    }
    case LB_PRIM_CYLINDER: {
        const double t = dot3(P->n, d);
        double v[3];
        for (int i = 0; i < 3; ++i) v[i] = d[i] - t * P->n[i];
        return norm_over(v, P->s0, g);
    }
    case LB_PRIM_CAPSULE: {
        double e[3], v[3];
        for (int i = 0; i < 3; ++i) e[i] = P->q[i] - P->c[i];
        const double ee = dot3(e, e);
        double t = ee > 0.0 ? dot3(d, e) / ee : 0.0;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
        for (int i = 0; i < 3; ++i) v[i] = d[i] - t * e[i];
        return norm_over(v, P->s0, g);
    }
    case LB_PRIM_TORUS: {
        const double t = dot3(P->n, d);
        double rad[3], v[3];
        for (int i = 0; i < 3; ++i) rad[i] = d[i] - t * P->n[i];
        const double rl = sqrt(dot3(rad, rad));
        /* nearest circle point: along the radial direction (any direction on the axis) */
        for (int i = 0; i < 3; ++i) {
            const double dir = rl > 0.0 ? rad[i] / rl : 0.0;
            v[i] = rad[i] - P->s0 * dir + t * P->n[i];
        }
        if (!(rl > 0.0)) { /* on the axis: every circle point is equally near */
            const double f = sqrt(P->s0 * P->s0 + t * t) / P->s1;
            if (g)
                for (int i = 0; i < 3; ++i)
                    g[i] = f > 0.0 ? t * P->n[i] / (f * P->s1 * P->s1) : 0.0;
            return f;
        }
        return norm_over(v, P->s1, g);
    }
    }
    if (g) g[0] = g[1] = g[2] = 0.0;
    return NAN;
}
