/* POV-Ray agrees with the C library: for every operator family and
 * primitive in povray_include/libblend.inc, a scene that evaluates the
 * generated functions at >= 1000 random points (random parameters, ties,
 * single active terms, non-blending regions) is run by the real povray, and
 * every value must match the C library within 1e-9 (absolute or relative,
 * whichever is larger).
 *
 * Usage: test_pov_agreement SOURCE_DIR WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include "../../libblend/src/common/splitmix.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef lb__splitmix rng;
static double unit(rng *r) {
    return lb__splitmix_unit(r);
}
static double range(rng *r, double a, double b) {
    return a + (b - a) * unit(r);
}
static double range_neg(rng *r) { /* a conic shape factor: 0, or in [-3, 0.95) */
    return unit(r) < 0.2 ? 0.0 : -3.0 + 3.95 * unit(r);
}
static double logu(rng *r, double a, double b) {
    return exp(range(r, log(a), log(b)));
}
/* p in [1.05, 16]: 2 (the closed form), an integer, or general */
static double rand_p(rng *g) {
    const double u = unit(g);
    const double p = u < 0.3   ? 2.0
                     : u < 0.6 ? (double)(1 + (int)(unit(g) * 16))
                               : logu(g, 1.05, 16);
    return p < 1.05 ? 2.0 : p;
}

#define MAXCASES 100000
static double expect[MAXCASES];
static const char *family[MAXCASES];
static size_t ncases;
static FILE *pov;

/* one evaluation: the .pov writes F(x, y, z); we remember the C value */
static void record(const char *fam, const char *fn, double x, double y, double z, double value) {
    if (ncases >= MAXCASES) abort();
    fprintf(pov, "#write (FO, str(%s(%.17g, %.17g, %.17g), 0, 17), \"\\n\")\n", fn, x, y, z);
    family[ncases] = fam;
    expect[ncases++] = value;
}

/* k argument functions F_i(x, y, z) = a_i x + b_i, declared as an array */
static void args_array(const char *name, size_t k, const double *a, const double *b) {
    fprintf(pov, "#declare %s = array[%zu] {", name, k);
    for (size_t i = 0; i < k; ++i)
        fprintf(pov, "%s function(x, y, z) { x * %.17g + %.17g }", i ? "," : "", a[i], b[i]);
    fprintf(pov, " };\n");
}

static void farray(const char *name, size_t k, const double *v) {
    fprintf(pov, "#declare %s = array[%zu] {", name, k);
    for (size_t i = 0; i < k; ++i) fprintf(pov, "%s%.17g", i ? ", " : "", v[i]);
    fprintf(pov, "};\n");
}

static void displacement_cases(rng *g) {
    /* three kinds of sets in turn: up to 16 arguments; p = 2 everywhere (the
     * macro's exact active-set path); 17 to 48 arguments (the path that
     * evaluates the arguments again at every step) */
    static const char *const fams[3][3] = {
        {"displacement union", "displacement intersection", "displacement difference"},
        {"displacement union, all p = 2", "displacement intersection, all p = 2",
         "displacement difference, all p = 2"},
        {"displacement union, 17-48 args", "displacement intersection, 17-48 args",
         "displacement difference, 17-48 args"}};
    for (int set = 0; set < 1800; ++set) {
        const int op = set % 3, kind = (set / 3) % 3, all2 = kind == 1;
        const size_t k = kind == 2 ? 17 + (size_t)(unit(g) * 32) : 1 + (size_t)(unit(g) * 16);
        double a[48], b[48], r[48], p[48], m[48];
        const double scale = logu(g, 0.01, 10.0);
        const int tie = set % 7 == 0, alone = set % 11 == 0;
        for (size_t i = 0; i < k; ++i) {
            a[i] = tie ? 1.0 : range(g, 0.5, 1.5);
            b[i] = tie ? 0.0 : scale * range(g, -1.0, 1.0);
            if (alone && i > 0) b[i] += 50.0 * scale * (op == 1 ? -1 : 1); /* one active term */
            r[i] = scale * logu(g, 0.05, 1.0);
            p[i] = all2 ? 2.0 : rand_p(g);
            m[i] = logu(g, 0.05, 20.0);
        }
        args_array("A", k, a, b);
        farray("R", k, r);
        farray("P", k, p);
        farray("M", k, m);
        fprintf(pov, "#declare G = LB_Displacement(%d, A, R, P, M)\n", op);
        for (int q = 0; q < 5; ++q) {
            const double x = scale * range(g, -1.0, 1.0);
            double d[48], v;
            for (size_t i = 0; i < k; ++i) d[i] = x * a[i] + b[i];
            lb_error e;
            if (lb_displacement((lb_setop)op, k, d, r, p, m, &v, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[kind][op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n");
    }
}

static void conic_cases(rng *g) {
    static const char *const fams[3] = {"conic union", "conic intersection", "conic difference"};
    for (int set = 0; set < 600; ++set) {
        const int op = set % 3;
        const double scale = logu(g, 0.01, 10.0);
        double a[2], b[2], r[2], m[2];
        for (int i = 0; i < 2; ++i) {
            a[i] = range(g, 0.5, 1.5);
            b[i] = scale * range(g, -1.0, 1.0);
            r[i] = scale * logu(g, 0.05, 1.0);
            m[i] = logu(g, 0.05, 20.0);
        }
        if (set % 9 == 0) { /* ties */
            a[1] = a[0];
            b[1] = b[0];
        }
        const double shape = r[0] * r[1] * (set % 5 == 0 ? 0.0 : range(g, -3.0, 0.95));
        args_array("A", 2, a, b);
        fprintf(pov, "#declare F1 = A[0];\n#declare F2 = A[1];\n");
        farray("R", 2, r);
        farray("M", 2, m);
        fprintf(pov, "#declare G = LB_Conic(%d, F1, F2, R, %.17g, M)\n", op, shape);
        for (int q = 0; q < 5; ++q) {
            const double x = scale * range(g, -1.0, 1.0);
            const double d[2] = {x * a[0] + b[0], x * a[1] + b[1]};
            double v;
            lb_error e;
            if (lb_conic((lb_setop)op, d, r, shape, m, &v, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n#undef F1\n#undef F2\n");
    }
}

static void scale_cases(rng *g) {
    static const char *const fams[3] = {"scale union", "scale intersection", "scale difference"};
    for (int set = 0; set < 600; ++set) {
        const int op = set % 3;
        const size_t k = 1 + (size_t)(unit(g) * 16);
        double a[16], b[16], r[16], p[16];
        for (size_t i = 0; i < k; ++i) {
            a[i] = range(g, 0.5, 1.5);
            b[i] = range(g, -1.0, 2.0);
            r[i] = op == 0 ? logu(g, 0.05, 3.0) : logu(g, 0.05, 1.0);
            p[i] = rand_p(g);
        }
        args_array("A", k, a, b);
        farray("R", k, r);
        farray("P", k, p);
        fprintf(pov, "#declare G = LB_Scale(%d, A, R, P)\n", op);
        for (int q = 0; q < 5; ++q) {
            const double x = range(g, -1.0, 1.0);
            double d[16], v;
            for (size_t i = 0; i < k; ++i) d[i] = x * a[i] + b[i];
            lb_error e;
            if (lb_scale((lb_setop)op, k, d, r, p, &v, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n");
    }
}

/* bounded: spheres (f = |X - c|/a - 1 along x: here a_i x + b_i) with
 * bounding values c_i = (f_i + 1) / s_i - 1, s_i > 1 (union: a larger solid)
 * or < 1 (intersection), sometimes not containing (R floored at omega) */
static void bounded_cases(rng *g) {
    static const char *const fams[3] = {"bounded union", "bounded intersection",
                                        "bounded difference"};
    for (int set = 0; set < 600; ++set) {
        const int op = set % 3;
        const size_t k = 1 + (size_t)(unit(g) * 16);
        double a[16], b[16], ca[16], cb[16], p[16];
        for (size_t i = 0; i < k; ++i) {
            a[i] = range(g, 0.5, 1.5);
            b[i] = range(g, -1.0, 2.0);
            const int union_like = op == 0 || (op == 2 && i > 0);
            const double sc = union_like ? range(g, 1.05, 3.0) : range(g, 0.3, 0.95);
            const double s2 = set % 13 == 0 ? 1.0 / sc : sc; /* a wrong-sized bounding solid */
            ca[i] = a[i] / s2;
            cb[i] = (b[i] + 1.0) / s2 - 1.0;
            p[i] = rand_p(g);
        }
        args_array("A", k, a, b);
        args_array("C", k, ca, cb);
        farray("P", k, p);
        fprintf(pov, "#declare G = LB_Bounded(%d, A, C, P)\n", op);
        for (int q = 0; q < 5; ++q) {
            const double x = range(g, -1.0, 1.0);
            double d[16], c[16], v;
            for (size_t i = 0; i < k; ++i) {
                d[i] = x * a[i] + b[i];
                c[i] = x * ca[i] + cb[i];
            }
            lb_error e;
            if (lb_bounded((lb_setop)op, k, d, c, p, &v, NULL, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n#undef C\n");
    }
}

static void soft_hyper_cases(rng *g) {
    static const char *const fams[3] = {"soft hyper union", "soft hyper intersection",
                                        "soft hyper difference"};
    for (int set = 0; set < 600; ++set) {
        const int op = set % 3;
        const size_t k = 1 + (size_t)(unit(g) * 16);
        double a[16], b[16], r[16], p[16], m[16];
        for (size_t i = 0; i < k; ++i) {
            a[i] = range(g, 0.0, 0.5);
            b[i] = range(g, 0.0, 0.5);
            if (set % 10 == 0 && i == k - 1) a[i] = b[i] = 0.0; /* a zero field */
            r[i] = op == 0 ? logu(g, 0.02, 1.0) : logu(g, 0.02, 3.0);
            if (op == 0 && unit(g) < 0.1) r[i] = 1.0;
            p[i] = rand_p(g);
            m[i] = logu(g, 0.05, 20.0);
        }
        args_array("A", k, a, b);
        farray("R", k, r);
        farray("P", k, p);
        farray("M", k, m);
        fprintf(pov, "#declare G = LB_SoftHyper(%d, A, R, P, M)\n", op);
        for (int q = 0; q < 5; ++q) {
            const double x = unit(g);
            double d[16], v;
            for (size_t i = 0; i < k; ++i) d[i] = x * a[i] + b[i];
            lb_error e;
            if (lb_soft_hyper((lb_setop)op, k, d, r, p, m, &v, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n");
    }
}

static void soft_conic_cases(rng *g) {
    static const char *const fams[3] = {"soft conic union", "soft conic intersection",
                                        "soft conic difference"};
    for (int set = 0; set < 600; ++set) {
        const int op = set % 3;
        double a[2], b[2], r[2], m[2];
        for (int i = 0; i < 2; ++i) {
            a[i] = range(g, 0.0, 0.5);
            b[i] = range(g, 0.0, 0.5);
            r[i] = op == 0 ? logu(g, 0.02, 1.0) : logu(g, 0.02, 3.0);
            m[i] = logu(g, 0.05, 20.0);
        }
        if (set % 10 == 0) a[1] = b[1] = 0.0;
        const double shape = r[0] * r[1] * (set % 5 == 0 ? 0.0 : range(g, -3.0, 0.95));
        args_array("A", 2, a, b);
        fprintf(pov, "#declare F1 = A[0];\n#declare F2 = A[1];\n");
        farray("R", 2, r);
        farray("M", 2, m);
        fprintf(pov, "#declare G = LB_SoftConic(%d, F1, F2, R, %.17g, M)\n", op, shape);
        for (int q = 0; q < 5; ++q) {
            const double x = unit(g);
            const double d[2] = {x * a[0] + b[0], x * a[1] + b[1]};
            double v;
            lb_error e;
            if (lb_soft_conic((lb_setop)op, d, r, shape, m, &v, NULL, &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            record(fams[op], "G", x, 0, 0, v);
        }
        fprintf(pov, "#undef G\n#undef A\n#undef F1\n#undef F2\n");
    }
}

/* bulge elimination: the core function of values and gradients */
static void bulge_cases(rng *g) {
    static const char *const fams[3][3] = {
        {"bulge displacement union", "bulge displacement intersection",
         "bulge displacement difference"},
        {"bulge conic union", "bulge conic intersection", "bulge conic difference"},
        {"bulge scale union", "bulge scale intersection", "bulge scale difference"}};
    for (int set = 0; set < 1800; ++set) {
        const int fam = set % 3, op = (set / 3) % 3;
        lb_bulge_params bp;
        memset(&bp, 0, sizeof bp);
        bp.omega = set % 4 == 0 ? 0.001 : logu(g, 1e-3, 0.5);
        bp.flags = fam == 2 ? 1u : (unsigned)(1 + (set / 9) % 3);
        const int ranged = bp.flags & 1u;
        for (int i = 0; i < 2; ++i) {
            bp.r[i] = logu(g, 0.05, 1.0);
            if (fam == 2 && op != 0) bp.r[i] = logu(g, 0.02, 1.0 / (2.0 + bp.omega));
            const double u = unit(g);
            bp.p[i] = u < 0.4   ? 2.0
                      : u < 0.7 ? (double)(1 + (int)(unit(g) * 16))
                                : logu(g, 1.05, 16);
            if (bp.p[i] < 1.05) bp.p[i] = 2.0;
            bp.m[i] = logu(g, 0.1, 10.0);
        }
        bp.conic_p = bp.r[0] * bp.r[1] * (ranged ? bp.omega * bp.omega : 1.0) * range_neg(g);
        fprintf(pov,
                "#declare G = LB_BulgeCore(%d, %d, array[2] {%.17g, %.17g}, array[2] {%.17g, "
                "%.17g}, %.17g, array[2] {%.17g, %.17g}, %u, %.17g)\n",
                fam, op, bp.r[0], bp.r[1], bp.p[0], bp.p[1], bp.conic_p, bp.m[0], bp.m[1], bp.flags,
                bp.omega);
        for (int q = 0; q < 5; ++q) {
            double x[2], g1[3], g2[3], v;
            for (int i = 0; i < 2; ++i) x[i] = range(g, -0.6, 0.6);
            for (int d = 0; d < 3; ++d) {
                g1[d] = range(g, -2, 2);
                g2[d] = range(g, -2, 2);
            }
            if (q == 1)
                for (int d = 0; d < 3; ++d) g2[d] = 0.7 * g1[d]; /* parallel */
            if (q == 2)
                for (int d = 0; d < 3; ++d) g2[d] = -1.3 * g1[d];    /* opposite */
            if (q == 3 && set % 5 == 0) g1[0] = g1[1] = g1[2] = 0.0; /* no angle */
            lb_error e;
            if (lb_bulge((lb_bulge_family)fam, (lb_setop)op, &bp, x, g1, g2, &v, NULL, NULL, NULL,
                         &e)) {
                fprintf(stderr, "%s\n", e.message);
                exit(1);
            }
            if (ncases >= MAXCASES) abort();
            fprintf(pov,
                    "#write (FO, str(G(%.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g), 0, "
                    "17), \"\\n\")\n",
                    x[0], x[1], g1[0], g1[1], g1[2], g2[0], g2[1], g2[2]);
            family[ncases] = fams[fam][op];
            expect[ncases++] = v;
        }
        fprintf(pov, "#undef G\n");
    }
}

static void classic_cases(rng *g) {
    static const struct {
        const char *fam, *macro;
        lb_classic_kind kind;
        int soft, binary;
    } K[] = {
        {"R-function union", "LB_RUnion", LB_RFUNC_UNION, 0, 1},
        {"R-function intersection", "LB_RIntersection", LB_RFUNC_INTERSECTION, 0, 1},
        {"soft sum", "LB_SoftSum", LB_SOFT_SUM, 1, 0},
        {"Ricci union", "LB_Ricci", LB_RICCI_UNION, 1, 0},
        {"Perlin union", "LB_PerlinUnion", LB_PERLIN_UNION, 1, 0},
        {"Perlin intersection", "LB_PerlinIntersection", LB_PERLIN_INTERSECTION, 1, 0},
        {"Perlin difference", "LB_PerlinDifference", LB_PERLIN_DIFFERENCE, 1, 0},
    };
    for (size_t f = 0; f < sizeof K / sizeof K[0]; ++f)
        for (int set = 0; set < 200; ++set) {
            const size_t k = K[f].binary ? 2 : 1 + (size_t)(unit(g) * 8);
            double a[16], b[16];
            for (size_t i = 0; i < k; ++i) {
                a[i] = K[f].soft ? range(g, 0.0, 0.5) : range(g, -1.0, 1.0);
                b[i] = K[f].soft ? range(g, 0.0, 0.5) : range(g, -2.0, 2.0);
            }
            const double n = logu(g, 1.0, 8.0);
            args_array("A", k, a, b);
            if (K[f].binary)
                fprintf(pov, "#declare G = %s(A[0], A[1])\n", K[f].macro);
            else if (K[f].kind == LB_RICCI_UNION)
                fprintf(pov, "#declare G = %s(A, %.17g)\n", K[f].macro, n);
            else
                fprintf(pov, "#declare G = %s(A)\n", K[f].macro);
            for (int q = 0; q < 5; ++q) {
                const double x = K[f].soft ? unit(g) : range(g, -2.0, 2.0);
                double d[16], v;
                for (size_t i = 0; i < k; ++i) d[i] = x * a[i] + b[i];
                lb_error e;
                if (lb_classic(K[f].kind, k, d, n, &v, NULL, &e)) {
                    fprintf(stderr, "%s: %s\n", K[f].fam, e.message);
                    exit(1);
                }
                record(K[f].fam, "G", x, 0, 0, v);
            }
            fprintf(pov, "#undef G\n#undef A\n");
        }
}

static void primitive_cases(rng *g) {
    for (int set = 0; set < 12000; ++set) {
        const int kind = set % 12;
        double c[3], q[3], ax[3], R = logu(g, 0.1, 3.0), R2 = R * range(g, 0.1, 0.5);
        for (int d = 0; d < 3; ++d) {
            c[d] = range(g, -2, 2);
            q[d] = range(g, -2, 2);
            ax[d] = range(g, -1, 1);
        }
        lb_primitive P;
        lb_error e;
        const char *fam = NULL;
        lb_status s = LB_OK;
        switch (kind) {
        case 0:
            fam = "sphere";
            s = lb_primitive_sphere(&P, c, R, &e);
            fprintf(pov, "#declare G = LB_Sphere(<%.17g, %.17g, %.17g>, %.17g)\n", c[0], c[1], c[2],
                    R);
            break;
        case 1: {
            fam = "ellipsoid";
            const double A[3] = {R, R * range(g, 0.3, 2), R * range(g, 0.3, 2)};
            s = lb_primitive_ellipsoid(&P, c, A, &e);
            fprintf(pov,
                    "#declare G = LB_Ellipsoid(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>)\n",
                    c[0], c[1], c[2], A[0], A[1], A[2]);
            break;
        }
        case 2:
            fam = "slab";
            s = lb_primitive_slab(&P, c, ax, R, &e);
            fprintf(pov,
                    "#declare G = LB_Slab(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n",
                    c[0], c[1], c[2], ax[0], ax[1], ax[2], R);
            break;
        case 3:
            fam = "cylinder";
            s = lb_primitive_cylinder(&P, c, ax, R, &e);
            fprintf(
                pov,
                "#declare G = LB_Cylinder(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n",
                c[0], c[1], c[2], ax[0], ax[1], ax[2], R);
            break;
        case 4:
            fam = "capsule";
            s = lb_primitive_capsule(&P, c, q, R, &e);
            fprintf(
                pov,
                "#declare G = LB_Capsule(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n",
                c[0], c[1], c[2], q[0], q[1], q[2], R);
            break;
        case 6: {
            fam = "LP metric";
            const double A[3] = {R, R * range(g, 0.3, 2), R * range(g, 0.3, 2)};
            const double n = logu(g, 1.0, 12.0);
            s = lb_primitive_lp(&P, c, A, n, &e);
            fprintf(pov,
                    "#declare G = LB_LP(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g)\n",
                    c[0], c[1], c[2], A[0], A[1], A[2], n);
            break;
        }
        case 7: {
            fam = "superquadric";
            const double A[3] = {R, R * range(g, 0.3, 2), R * range(g, 0.3, 2)};
            const double e1 = logu(g, 0.1, 3.0), e2 = logu(g, 0.1, 3.0);
            s = lb_primitive_superquadric(&P, c, A, e1, e2, &e);
            fprintf(pov,
                    "#declare G = LB_Superquadric(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, "
                    "%.17g, %.17g)\n",
                    c[0], c[1], c[2], A[0], A[1], A[2], e1, e2);
            break;
        }
        case 8:
            fam = "halfspace";
            s = lb_primitive_halfspace(&P, c, ax, R, &e);
            fprintf(pov,
                    "#declare G = LB_Halfspace(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, "
                    "%.17g)\n",
                    c[0], c[1], c[2], ax[0], ax[1], ax[2], R);
            break;
        case 9:
        case 10: {
            /* soft kernels over a sphere: K(rho) with rho = f + 1 */
            fam = kind == 9 ? "Wyvill kernel" : "Blinn kernel";
            s = lb_primitive_sphere(&P, c, R, &e);
            if (!s) s = lb_primitive_soften(&P, kind == 9 ? LB_KERNEL_WYVILL : LB_KERNEL_BLINN, &e);
            fprintf(pov,
                    "#declare G0 = LB_Sphere(<%.17g, %.17g, %.17g>, %.17g)\n"
                    "#declare G = function(x, y, z) { %s(G0(x, y, z) + 1) }\n#undef G0\n",
                    c[0], c[1], c[2], R, kind == 9 ? "LB_Wyvill" : "LB_Blinn");
            break;
        }
        case 11:
        default:
            fam = "torus";
            s = lb_primitive_torus(&P, c, ax, R, R2, &e);
            fprintf(pov,
                    "#declare G = LB_Torus(<%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g>, %.17g, "
                    "%.17g)\n",
                    c[0], c[1], c[2], ax[0], ax[1], ax[2], R, R2);
            break;
        }
        if (s) {
            fprintf(stderr, "%s: %s\n", fam, e.message);
            exit(1);
        }
        for (int k = 0; k < 1; ++k) {
            const double sp = kind >= 9 && kind <= 10 ? 0.6 * R : 4.0;
            const double X[3] = {c[0] + range(g, -sp, sp), c[1] + range(g, -sp, sp),
                                 c[2] + range(g, -sp, sp)};
            record(fam, "G", X[0], X[1], X[2], lb_primitive_eval(&P, X, NULL));
        }
        fprintf(pov, "#undef G\n");
    }
}

/* one evaluation of a scalar expression (the include's scalar functions) */
static void record_expr(const char *fam, const char *expr, double value) {
    if (ncases >= MAXCASES) abort();
    fprintf(pov, "#write (FO, str(%s, 0, 17), \"\\n\")\n", expr);
    family[ncases] = fam;
    expect[ncases++] = value;
}

/* a soft value: inside, outside, on the iso value, zero, or above 1 */
static double soft_value(rng *g) {
    const double u = unit(g);
    return u < 0.1 ? 0.5 : u < 0.15 ? 0.0 : u < 0.2 ? range(g, 1.0, 2.0) : unit(g);
}

/* The clean unions, Barthe's blend and the local mix against
 * lb_clean_union, lb_barthe_blend and lb_local_mix. */
static void local_cases(rng *g) {
    static const char *const fams[4] = {"clean union UR", "clean union UC2", "clean union UC3",
                                        "clean union UC"};
    static const char *const fns[4] = {"lb_clean_ur", "lb_clean_uc2", "lb_clean_uc3",
                                       "lb_clean_uc"};
    char e[512];
    for (int kind = LB_CLEAN_UR; kind <= LB_CLEAN_UC; ++kind)
        for (int i = 0; i < 1200; ++i) {
            double f[2] = {soft_value(g), soft_value(g)};
            if (i % 10 == 0) f[1] = f[0]; /* the diagonal */
            const double C = i % 3 ? 0.5 : range(g, 0.1, 0.9);
            const double al[2] = {i % 2 ? 0.0 : range(g, 0.0, 0.95),
                                  i % 2 ? 0.0 : range(g, 0.0, 0.95)};
            double v = 0.0;
            if (lb_clean_union((lb_clean_kind)kind, f, C, al, &v, NULL, NULL)) abort();
            if (kind == LB_CLEAN_UR)
                snprintf(e, sizeof e, "lb_clean_ur(%.17g, %.17g)", f[0], f[1]);
            else if (kind == LB_CLEAN_UC2)
                snprintf(e, sizeof e, "lb_clean_uc2(%.17g, %.17g, %.17g)", f[0], f[1], C);
            else
                snprintf(e, sizeof e, "%s(%.17g, %.17g, %.17g, %.17g, %.17g)", fns[kind], f[0],
                         f[1], C, al[0], al[1]);
            record_expr(fams[kind], e, v);
        }
    for (int i = 0; i < 1200; ++i) {
        const double x[2] = {range(g, -0.2, 1.5), range(g, -0.2, 1.5)};
        const double p = i % 5 ? range(g, 0.0, LB_BARTHE_MAX_PQ) : 0.0;
        const double q = i % 7 ? range(g, 0.0, LB_BARTHE_MAX_PQ) : 0.0;
        double v = 0.0;
        if (lb_barthe_blend(x, p, q, &v, NULL, NULL)) abort();
        snprintf(e, sizeof e, "lb_barthe(%.17g, %.17g, %.17g, %.17g)", x[0], x[1], p, q);
        record_expr("Barthe UB", e, v);
    }
    for (int i = 0; i < 1200; ++i) {
        const double uc = unit(g), ub = uc + 0.3 * unit(g);
        const double v = i % 9 ? unit(g) : i % 2 ? 0.0 : 1.0, n = i % 4 ? range(g, 1.0, 8.0) : 1.0;
        double u = 0.0;
        if (lb_local_mix(uc, ub, v, n, &u, NULL, NULL)) abort();
        snprintf(e, sizeof e, "lb_local_mix(%.17g, %.17g, %.17g, %.17g)", uc, ub, v, n);
        record_expr("local mix", e, u);
    }
    /* the clean-union macros over argument functions: soft, and zero
     * convention through g = 0.5 (1 - f / s) and back */
    for (int i = 0; i < 200; ++i) {
        const double a[2] = {range(g, -1, 1), range(g, -1, 1)},
                     b[2] = {range(g, 0.0, 1.0), range(g, 0.0, 1.0)};
        const double al[2] = {i % 2 ? 0.0 : range(g, 0.0, 0.9), i % 2 ? 0.0 : range(g, 0.0, 0.9)};
        const int zero = i % 2;
        const double s = zero ? range(g, 0.2, 3.0) : 1.0;
        fprintf(pov,
                "#ifdef (CU) #undef CU #undef CA #undef CB #end\n"
                "#declare CA = function(x, y, z) { x * %.17g + %.17g }\n"
                "#declare CB = function(x, y, z) { x * %.17g + %.17g }\n",
                a[0], b[0], a[1], b[1]);
        if (zero)
            fprintf(pov, "#declare CU = LB_CleanUnionZero(CA, CB, %.17g, %.17g, %.17g)\n", al[0],
                    al[1], s);
        else
            fprintf(pov, "#declare CU = LB_CleanUnion(CA, CB, %.17g, %.17g)\n", al[0], al[1]);
        for (int j = 0; j < 5; ++j) {
            const double X = range(g, -1, 1);
            double f[2] = {a[0] * X + b[0], a[1] * X + b[1]}, u = 0.0;
            if (zero)
                for (int k = 0; k < 2; ++k) f[k] = 0.5 * (1.0 - f[k] / s);
            if (lb_clean_union(LB_CLEAN_UC, f, 0.5, al, &u, NULL, NULL)) abort();
            record(zero ? "clean union macro, zero" : "clean union macro, soft", "CU", X, 0.0, 0.0,
                   zero ? s * (1.0 - u / 0.5) : fmax(0.0, u));
        }
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: test_pov_agreement SOURCE_DIR WORK_DIR\n");
        return 2;
    }
    char path[4096], outp[4096], cmd[16384];
    snprintf(path, sizeof path, "%s/agree.pov", argv[2]);
    snprintf(outp, sizeof outp, "%s/agree.txt", argv[2]);
    pov = fopen(path, "w");
    if (!pov) {
        perror(path);
        return 1;
    }
    fprintf(pov, "#version 3.7;\n#include \"%s/povray_include/libblend.inc\"\n", argv[1]);
    fprintf(pov, "#fopen FO \"%s\" write\n", outp);
    rng g = {77};
    displacement_cases(&g);
    conic_cases(&g);
    scale_cases(&g);
    bounded_cases(&g);
    soft_hyper_cases(&g);
    soft_conic_cases(&g);
    bulge_cases(&g);
    classic_cases(&g);
    primitive_cases(&g);
    local_cases(&g);
    fprintf(pov, "#fclose FO\n");
    fclose(pov);
    remove(outp);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +I'%s' -D -F +W1 +H1 -V -GR -GS -GW +L'%s/povray_include' "
             "> povray.log 2>&1",
             argv[2], path, argv[1]);
    if (system(cmd) != 0) {
        fprintf(stderr, "povray failed; see %s/povray.log\n", argv[2]);
        return 1;
    }
    FILE *in = fopen(outp, "r");
    if (!in) {
        perror(outp);
        return 1;
    }
    size_t n = 0, bad = 0;
    double worst = 0.0;
    double v;
    while (n < ncases && fscanf(in, "%lf", &v) == 1) {
        const double tol = 1e-9 * fmax(1.0, fabs(expect[n]));
        const double err = fabs(v - expect[n]);
        if (!(err <= tol)) {
            if (bad < 10)
                fprintf(stderr, "  %s case %zu: povray %.17g, C %.17g\n", family[n], n, v,
                        expect[n]);
            ++bad;
        }
        if (err / fmax(1.0, fabs(expect[n])) > worst) worst = err / fmax(1.0, fabs(expect[n]));
        ++n;
    }
    fclose(in);
    /* per family counts */
    const char *seen[64];
    size_t counts[64], ns = 0;
    for (size_t i = 0; i < ncases; ++i) {
        size_t j = 0;
        while (j < ns && strcmp(seen[j], family[i])) ++j;
        if (j == ns) {
            seen[ns] = family[i];
            counts[ns++] = 0;
        }
        counts[j]++;
    }
    for (size_t j = 0; j < ns; ++j) fprintf(stderr, "  %-28s %zu points\n", seen[j], counts[j]);
    fprintf(stderr, "%zu of %zu values read, %zu outside 1e-9, worst %.3g\n", n, ncases, bad,
            worst);
    return n == ncases && bad == 0 ? 0 : 1;
}
