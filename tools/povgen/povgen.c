/* povgen: writes povray_include/libblend.inc, libblend's operators as
 * POV-Ray 3.7 SDL, from the C library's definitions.
 *
 * The include is generated, never edited: the committed copy must equal a
 * fresh run (tests/povray/test_pov_stale). What is generated from the C side:
 * - the formulas, written once here next to the C kernels they mirror;
 * - the number of unrolled Newton steps of every root-solved macro: povgen
 *   runs the very recurrence the SDL performs (step_sim) against the C
 *   library (lb_displacement) over random cases in the documented ranges and
 *   emits enough steps for every case to reach its early exit, refusing to
 *   write the file when a case misses the C value by more than 1e-10.
 *
 * Usage: povgen OUT.inc */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include "../../libblend/src/common/splitmix.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KMAX 16    /* arguments of a k-ary macro */
#define TOL 1e-10  /* early exit: the Newton step below TOL (1 + abs(h)); the exit takes it */
#define P_MIN 1.05 /* documented ranges of the root-solved macros */
#define P_MAX 16.0
#define M_MIN LB_SOFT_MIN_SLOPE /* the library's soft slope range */
#define M_MAX LB_SOFT_MAX_SLOPE

/* ---- the documented ranges, checked against the C library ---- */

typedef lb__splitmix rng;
static double unit(rng *r) {
    return lb__splitmix_unit(r);
}
static double logu(rng *r, double a, double b) {
    return exp(log(a) + (log(b) - log(a)) * unit(r));
}
/* p in [P_MIN, P_MAX]: 2 (the closed form), an integer, or general */
static double rand_p(rng *g) {
    const double u = unit(g);
    const double p = u < 0.3   ? 2.0
                     : u < 0.6 ? (double)(1 + (int)(unit(g) * P_MAX))
                               : logu(g, P_MIN, P_MAX);
    return p < P_MIN ? 2.0 : p;
}

/* A solver's verdict over its random cases: the steps it needs, or exit. */
static int steps_needed(const char *what, int worst, double maxerr) {
    if (worst > 400 || maxerr > 1e-10) {
        fprintf(stderr, "povgen: the %s SDL recurrence misses the C library (%d steps, error %g)\n",
                what, worst, maxerr);
        exit(1);
    }
    fprintf(stderr, "povgen: %s: %d steps cover every case (error <= %.2g)\n", what, worst, maxerr);
    return worst + 2;
}

/* The recurrence of LB_Displacement's SDL, step for step (same formulas,
 * same order of operations as the emitted text). Returns the value and the
 * number of Newton steps evaluated. */
static double step_sim(int k, const double *d, const double *r, const double *p, const double *m,
                       int steps, int *used) {
    double h = INFINITY, lo = INFINITY;
    for (int i = 0; i < k; ++i) {
        h = fmin(h, d[i] / m[i]);
        lo = fmin(lo, (d[i] - r[i]) / m[i]);
    }
    for (int n = 0; n < steps; ++n) {
        double T = -1.0, D = 0.0;
        for (int i = 0; i < k; ++i) {
            const double u = (r[i] - d[i] + m[i] * h) / r[i];
            T += pow(fmax(0.0, u), p[i]);
            D += (p[i] * m[i] / r[i]) * (u > 0.0) * pow(fmax(0.0, u), p[i] - 1.0);
        }
        const double dl = T / D;
        *used = n + 1;
        if (fabs(dl) - TOL * (1.0 + fabs(h)) <= 0.0) return h - dl;
        h = fmax(lo, h - dl);
    }
    *used = steps + 1;
    return h;
}

/* One case: the SDL recurrence against lb_displacement. */
static void displacement_case(int k, const double *d, const double *r, const double *p,
                              const double *m, int *worst, double *maxerr) {
    int used = 0;
    const double v = step_sim(k, d, r, p, m, 400, &used);
    double ref;
    lb_error e;
    if (lb_displacement(LB_UNION, (size_t)k, d, r, p, m, &ref, NULL, &e)) {
        fprintf(stderr, "povgen: %s\n", e.message);
        exit(1);
    }
    const double err = fabs(v - ref) / (1.0 + fabs(ref));
    if (used > *worst) *worst = used;
    if (err > *maxerr) *maxerr = err;
}

static int choose_steps(void) {
    rng g = {20261122};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        const int k = 1 + (int)(unit(&g) * KMAX);
        double d[KMAX], r[KMAX], p[KMAX], m[KMAX];
        const double scale = logu(&g, 0.01, 10.0);
        for (int i = 0; i < k; ++i) {
            r[i] = scale * logu(&g, 0.05, 1.0);
            d[i] = scale * (2.0 * unit(&g) - 1.0);
            p[i] = rand_p(&g);
            m[i] = logu(&g, M_MIN, M_MAX);
        }
        displacement_case(k, d, r, p, m, &worst, &maxerr);
    }
    /* the scale method's use: d = -1 (B_A, m = y/min y >= 1) or d = 1 (B_S, m = y/max y
     * in (1 - r, 1]) */
    for (int c = 0; c < 200000; ++c) {
        const int k = 1 + (int)(unit(&g) * KMAX);
        const int bs = c & 1;
        double d[KMAX], r[KMAX], p[KMAX], m[KMAX];
        for (int i = 0; i < k; ++i) {
            r[i] = logu(&g, 0.01, bs ? 1.0 : 100.0);
            d[i] = bs ? 1.0 : -1.0;
            m[i] = i == 0 ? 1.0
                   : bs   ? 1.0 - r[i] * unit(&g)
                          : 1.0 + logu(&g, 1e-6, 1.0) * (1.0 + r[i]);
            if (!(m[i] > 0.0)) m[i] = 1e-3;
            p[i] = rand_p(&g);
        }
        displacement_case(k, d, r, p, m, &worst, &maxerr);
    }
    return steps_needed("displacement", worst, maxerr);
}

/* ---- soft non-uniform blends: bracketed Newton in lambda = ln h ---- */

#define LTOL 1e-13 /* |Newton step| in lambda (= relative in h) */
#define LN2 0.69314718055994530942

/* T and T' of the soft k-ary blend in lambda, as the SDL computes them */
static void soft_TD(int u, int k, const double *a, const double *r, const double *p,
                    const double *m, double lam, double *T, double *D) {
    double s = 0.0, d = 0.0;
    for (int i = 0; i < k; ++i) {
        const double z = exp(a[i] - m[i] * lam);
        const double t = u ? (r[i] - 1.0 + z) / r[i] : (1.0 + r[i] - z) / r[i];
        if (t > 0.0) {
            s += pow(t, p[i]);
            d += p[i] / r[i] * pow(t, p[i] - 1.0) * m[i] * z;
        }
    }
    *T = u ? 1.0 - s : s - 1.0;
    *D = d;
}

/* The SDL's bracketed Newton in lambda, shared by the soft solvers: start
 * at `lam`, Newton inside [lo, hi], bisection otherwise; exit when
 * |T/D| < LTOL. *used becomes the most steps any call evaluated. */
typedef void (*td_fn)(const void *ctx, double lam, double *T, double *D);

static double bnewton_sim(td_fn td, const void *ctx, double lo, double hi, double lam, int steps,
                          int *used) {
    for (int n = 0; n < steps; ++n) {
        double T, D;
        td(ctx, lam, &T, &D);
        if (n + 1 > *used) *used = n + 1;
        const double st = T / D;
        if (fabs(st) - LTOL <= 0.0) return fmin(hi, fmax(lo, lam - st));
        if (T > 0.0)
            hi = lam;
        else
            lo = lam;
        const double nx = lam - st;
        lam = nx > lo && nx < hi ? nx : 0.5 * (lo + hi);
    }
    *used = steps + 1;
    return lam;
}

typedef struct sh {
    int u, k;
    const double *a, *r, *p, *m;
} sh;

static void sh_TD(const void *c, double lam, double *T, double *D) {
    const sh *q = c;
    soft_TD(q->u, q->k, q->a, q->r, q->p, q->m, lam, T, D);
}

static int choose_soft_steps(void) {
    rng g = {424242};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        const int u = c & 1;
        const int k = 1 + (int)(unit(&g) * KMAX);
        double x[KMAX], r[KMAX], p[KMAX], m[KMAX], a[KMAX];
        for (int i = 0; i < k; ++i) {
            x[i] = unit(&g) < 0.1 ? 1e-9 * unit(&g) : unit(&g);
            r[i] = u ? logu(&g, 0.02, 1.0) : logu(&g, 0.02, 3.0);
            if (u && unit(&g) < 0.1) r[i] = 1.0;
            p[i] = rand_p(&g);
            m[i] = logu(&g, 0.05, 20.0);
        }
        double ref;
        lb_error e;
        if (lb_soft_hyper(u ? LB_UNION : LB_INTERSECTION, (size_t)k, x, r, p, m, &ref, NULL, &e)) {
            fprintf(stderr, "povgen: %s\n", e.message);
            exit(1);
        }
        /* the SDL's brackets */
        int npos = 0;
        double nb = u ? -INFINITY : INFINITY, other = u ? -INFINITY : INFINITY;
        for (int i = 0; i < k; ++i) {
            a[i] = log(x[i]) + (1.0 - m[i]) * LN2;
            npos += x[i] > 0.0;
        }
        for (int i = 0; i < k; ++i) {
            nb = u ? fmax(nb, a[i] / m[i]) : fmin(nb, a[i] / m[i]);
            const double l = u ? (r[i] < 1.0 ? (a[i] - log1p(-r[i])) / m[i]
                                             : (a[i] + log((double)npos) / p[i]) / m[i])
                               : (a[i] - log1p(r[i])) / m[i];
            other = u ? fmax(other, l) : fmin(other, l);
        }
        int used = 0;
        const sh q = {u, k, a, r, p, m};
        const double lam = u ? bnewton_sim(sh_TD, &q, nb, other, nb, 400, &used)
                             : bnewton_sim(sh_TD, &q, other, nb, nb, 400, &used);
        const double v = exp(lam);
        const double err = fabs(v - ref) / fmax(1.0, fabs(ref));
        if (used > worst) worst = used;
        if (err > maxerr) maxerr = err;
    }
    return steps_needed("soft blends", worst, maxerr);
}

/* The soft conic's two solves (chord, then H) in lambda, as the SDL does them. */
typedef struct sc {
    double a[2], r[2], m[2], p;
    int u, chord;
} sc;

static void sc_TD(const void *vc, double lam, double *T, double *D) {
    const sc *c = vc;
    double uu[2], du[2];
    for (int i = 0; i < 2; ++i) {
        const double z = exp(c->a[i] - c->m[i] * lam);
        uu[i] = c->u ? 1.0 - z : z - 1.0;
        du[i] = c->u ? c->m[i] * z : -c->m[i] * z;
    }
    const double sg = c->u ? 1.0 : -1.0;
    if (c->chord) {
        *T = sg * (uu[0] / c->r[0] + uu[1] / c->r[1] - 1.0);
        *D = sg * (du[0] / c->r[0] + du[1] / c->r[1]);
        return;
    }
    const double r1 = c->r[0], r2 = c->r[1], n = 1.0 / (r1 * r1 * r2 * r2);
    const double H = r2 * r2 * uu[0] * uu[0] + r1 * r1 * uu[1] * uu[1] + r1 * r1 * r2 * r2 -
                     2.0 * r2 * r2 * r1 * uu[0] - 2.0 * r1 * r1 * r2 * uu[1] +
                     2.0 * c->p * uu[0] * uu[1];
    const double H1 = 2.0 * (r2 * r2 * (uu[0] - r1) + c->p * uu[1]);
    const double H2 = 2.0 * (r1 * r1 * (uu[1] - r2) + c->p * uu[0]);
    *T = -sg * n * H;
    *D = -sg * n * (H1 * du[0] + H2 * du[1]);
}

static int choose_sconic_steps(void) {
    rng g = {99};
    int worst = 0;
    double maxerr = 0.0;
    for (int c = 0; c < 200000; ++c) {
        sc C;
        C.u = c & 1;
        double x[2];
        for (int i = 0; i < 2; ++i) {
            x[i] = unit(&g);
            C.r[i] = C.u ? logu(&g, 0.02, 1.0) : logu(&g, 0.02, 3.0);
            C.m[i] = logu(&g, 0.05, 20.0);
            C.a[i] = log(x[i]) + (1.0 - C.m[i]) * LN2;
        }
        C.p = C.r[0] * C.r[1] * (c % 5 == 0 ? 0.0 : -3.0 + 3.95 * unit(&g));
        double ref;
        lb_error e;
        if (lb_soft_conic(C.u ? LB_UNION : LB_INTERSECTION, x, C.r, C.p, C.m, &ref, NULL, &e)) {
            fprintf(stderr, "povgen: %s\n", e.message);
            exit(1);
        }
        const double l0 = C.a[0] / C.m[0], l1 = C.a[1] / C.m[1];
        const int j = C.u ? l1 > l0 : l1 < l0, o = 1 - j;
        const double nb = j ? l1 : l0;
        const double zo = exp(C.a[o] - C.m[o] * nb), uo = C.u ? 1.0 - zo : zo - 1.0;
        double v;
        int used = 0;
        if (uo >= C.r[o]) {
            v = exp(nb);
        } else {
            double far = C.u ? -INFINITY : INFINITY;
            for (int i = 0; i < 2; ++i) {
                const double l = (C.a[i] - log1p(C.u ? -0.5 * C.r[i] : 0.5 * C.r[i])) / C.m[i];
                far = C.u ? fmax(far, l) : fmin(far, l);
            }
            C.chord = 1;
            const double lc = C.u ? bnewton_sim(sc_TD, &C, nb, far, nb, 400, &used)
                                  : bnewton_sim(sc_TD, &C, far, nb, nb, 400, &used);
            C.chord = 0;
            const double lam = C.u ? bnewton_sim(sc_TD, &C, nb, lc, nb, 400, &used)
                                   : bnewton_sim(sc_TD, &C, lc, nb, nb, 400, &used);
            v = exp(lam);
        }
        const double err = fabs(v - ref) / fmax(1.0, fabs(ref));
        if (used > worst) worst = used;
        if (err > maxerr) maxerr = err;
    }
    return steps_needed("soft conic", worst, maxerr);
}

/* ---- writing ---- */

static FILE *out;
static void w(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vfprintf(out, fmt, ap);
    va_end(ap);
}

/* the parameter list "d0, d1, ..., d15" */
static void dlist(void) {
    /* only the K in use: the macro knows K when POV-Ray parses the body */
    w("lbd0");
    for (int i = 1; i < KMAX; ++i) w(" #if (K > %d), lbd%d #end", i, i);
}

static void header(void) {
    w("// libblend.inc: libblend's blend operators for POV-Ray 3.7 isosurfaces.\n"
      "// GENERATED by tools/povgen from the C library (libblend %d.%d.%d). Do not edit:\n"
      "// tests/povray fail when this file differs from a fresh generation.\n"
      "// Every macro returns a function(x, y, z); pass functions in arrays and\n"
      "// per-function parameters as arrays of the same length (LB_Same(F, v) makes one\n"
      "// with v for every function). Every parameter is checked while POV-Ray parses:\n"
      "// a bad one stops the parse with the macro, the parameter, its value and what\n"
      "// is allowed. Zero convention: inside f < 0. Documentation: povray_include/README.md.\n"
      "#ifndef (LB_INC_TEMP)\n#declare LB_INC_TEMP = version;\n#version 3.7;\n\n",
      LB_VERSION_MAJOR, LB_VERSION_MINOR, LB_VERSION_PATCH);
    w("// ---- names and checks shared by the macros ----\n"
      "// the set operation of a blend (its Op argument)\n"
      "#declare LB_UNION = 0;\n#declare LB_INTERSECTION = 1;\n#declare LB_DIFFERENCE = 2;\n"
      "// LB_Same(F, V): an array holding V once for every function of the array F\n"
      "#macro LB_Same(F, V)\n"
      "  #local lbA = array[dimension_size(F, 1)];\n"
      "  #for (lbI, 0, dimension_size(F, 1) - 1) #local lbA[lbI] = V; #end\n"
      "  lbA\n#end\n"
      "#macro LB__Op(Mac, Op)\n"
      "  #if (Op != 0 & Op != 1 & Op != 2)\n"
      "    #error concat(Mac, \": Op = \", str(Op, 0, 6), \"; allowed: LB_UNION (0), "
      "LB_INTERSECTION (1) or LB_DIFFERENCE (2)\")\n  #end\n#end\n"
      "#macro LB__Count(Mac, F, Most)\n"
      "  #if (dimension_size(F, 1) < 1 | dimension_size(F, 1) > Most)\n"
      "    #error concat(Mac, \": \", str(dimension_size(F, 1), 0, 0), \" functions; allowed: 1 "
      "to \", str(Most, 0, 0))\n  #end\n#end\n"
      "#macro LB__Per(Mac, Name, A, K, Lo, Hi, Allowed)\n"
      "  #if (dimension_size(A, 1) != K)\n"
      "    #error concat(Mac, \": \", Name, \" has \", str(dimension_size(A, 1), 0, 0), \" values "
      "for \", str(K, 0, 0), \" functions; allowed: one per function (LB_Same(F, v): one for "
      "all)\")\n  #end\n"
      "  #for (lbI, 0, K - 1)\n"
      "    #if (!(A[lbI] >= Lo & A[lbI] <= Hi))\n"
      "      #error concat(Mac, \": \", Name, \"[\", str(lbI, 0, 0), \"] = \", str(A[lbI], 0, 9), "
      "\"; allowed: \", Allowed)\n    #end\n  #end\n#end\n"
      "// LB_Transform(F, S, R, T): the field F moved as POV-Ray moves an object with\n"
      "// `scale S rotate R translate T` (S a vector or one number, R in degrees, x then\n"
      "// y then z): the new field at P is F at the point that transform takes to P.\n"
      "// A scale below 1 steepens the field: divide max_gradient's share of F by the\n"
      "// smallest scale.\n"
      "#macro LB_Transform(F, S, R, T)\n"
      "  #local lbS = <1, 1, 1> * S; #local lbR = <0, 0, 0> + R; #local lbT = <0, 0, 0> + T;\n"
      "  #if (lbS.x = 0 | lbS.y = 0 | lbS.z = 0)\n"
      "    #error concat(\"LB_Transform: S = <\", vstr(3, lbS, \", \", 0, 9), \">; allowed: no "
      "zero "
      "component\")\n  #end\n"
      "  #local lbE1 = vrotate(vrotate(vrotate(x, <0, 0, -lbR.z>), <0, -lbR.y, 0>), <-lbR.x, 0, "
      "0>);\n"
      "  #local lbE2 = vrotate(vrotate(vrotate(y, <0, 0, -lbR.z>), <0, -lbR.y, 0>), <-lbR.x, 0, "
      "0>);\n"
      "  #local lbE3 = vrotate(vrotate(vrotate(z, <0, 0, -lbR.z>), <0, -lbR.y, 0>), <-lbR.x, 0, "
      "0>);\n"
      "  #local lb00 = lbE1.x / lbS.x; #local lb01 = lbE2.x / lbS.x; #local lb02 = lbE3.x / "
      "lbS.x;\n"
      "  #local lb10 = lbE1.y / lbS.y; #local lb11 = lbE2.y / lbS.y; #local lb12 = lbE3.y / "
      "lbS.y;\n"
      "  #local lb20 = lbE1.z / lbS.z; #local lb21 = lbE2.z / lbS.z; #local lb22 = lbE3.z / "
      "lbS.z;\n"
      "  #local lbtx = lbT.x; #local lbty = lbT.y; #local lbtz = lbT.z;\n"
      "  function(x, y, z) { F(lb00 * (x - lbtx) + lb01 * (y - lbty) + lb02 * (z - lbtz), lb10 * "
      "(x - lbtx) + lb11 * (y - lbty) + lb12 * (z - lbtz), lb20 * (x - lbtx) + lb21 * (y - lbty) "
      "+ lb22 * (z - lbtz)) }\n#end\n"
      "// LB_MaxGradient(F, Lo, Hi, N): a max_gradient for the isosurface F = 0 in the\n"
      "// box Lo..Hi (for a soft field's -F, threshold -0.5: pass F - 0.5), found the\n"
      "// way blendtool pov finds one: the largest |grad F| (central differences, step\n"
      "// 1e-5 of the box's diagonal) over an N x N x N grid of the box, among the\n"
      "// points the surface may be near (|F| at most two grid diagonals times\n"
      "// |grad F|), times 1.25 (as the exporter). Choose N so that the grid's\n"
      "// spacing is at most the smallest primitive's radius, half-width or\n"
      "// semi-axis, and N >= 24 (tests/povray/test_pov_gradient.py); it costs\n"
      "// 6 N^3 evaluations of F at parse time.\n"
      "#macro LB_MaxGradient(F, Lo, Hi, N)\n"
      "  #local lbLo = <0, 0, 0> + Lo; #local lbHi = <0, 0, 0> + Hi;\n"
      "  #if (!(N >= 2 & N <= 200 & int(N) = N))\n"
      "    #error concat(\"LB_MaxGradient: N = \", str(N, 0, 9), \"; allowed: a whole number "
      "from 2 to 200 (24 is usual)\")\n  #end\n"
      "  #if (!(lbHi.x > lbLo.x & lbHi.y > lbLo.y & lbHi.z > lbLo.z))\n"
      "    #error concat(\"LB_MaxGradient: the box <\", vstr(3, lbLo, \", \", 0, 9), \"> .. <\", "
      "vstr(3, lbHi, \", \", 0, 9), \"> is empty; allowed: Lo below Hi on every axis (the "
      "isosurface's contained_by box)\")\n  #end\n"
      "  #local lbH = 1e-5 * vlength(lbHi - lbLo); #local lbM = 0; #local lbAll = 0;\n"
      "  #local lbBand = 2 * vlength(lbHi - lbLo) / (N - 1);\n"
      "  #for (lbI, 0, N - 1)\n    #for (lbJ, 0, N - 1)\n      #for (lbK, 0, N - 1)\n"
      "        #local lbX = lbLo.x + (lbHi.x - lbLo.x) * lbI / (N - 1);\n"
      "        #local lbY = lbLo.y + (lbHi.y - lbLo.y) * lbJ / (N - 1);\n"
      "        #local lbZ = lbLo.z + (lbHi.z - lbLo.z) * lbK / (N - 1);\n"
      "        #local lbGx = F(lbX + lbH, lbY, lbZ) - F(lbX - lbH, lbY, lbZ);\n"
      "        #local lbGy = F(lbX, lbY + lbH, lbZ) - F(lbX, lbY - lbH, lbZ);\n"
      "        #local lbGz = F(lbX, lbY, lbZ + lbH) - F(lbX, lbY, lbZ - lbH);\n"
      "        #local lbG = sqrt(lbGx * lbGx + lbGy * lbGy + lbGz * lbGz) / (2 * lbH);\n"
      "        #if (lbG > lbAll) #local lbAll = lbG; #end\n"
      "        #if (lbG > lbM & abs(F(lbX, lbY, lbZ)) <= lbBand * lbG) #local lbM = lbG; #end\n"
      "      #end\n    #end\n  #end\n"
      "  #if (lbM = 0) #local lbM = lbAll; #end\n"
      "  (lbM > 0 ? 1.25 * lbM : 1.1)\n#end\n"
      "#macro LB__One(Mac, Name, V, Lo, Hi, Allowed)\n"
      "  #if (!(V >= Lo & V <= Hi))\n"
      "    #error concat(Mac, \": \", Name, \" = \", str(V, 0, 9), \"; allowed: \", Allowed)\n"
      "  #end\n#end\n\n");
}

/* The checks of a per-function range R (LB_MIN_RANGE ..), at most rmax. */
static void check_r(const char *mac, const char *k, double rmax) {
    w("  LB__Per(\"%s\", \"R\", R, %s, %.17g, %.17g, \"r > 0 and at most %g\")\n", mac, k,
      LB_MIN_RANGE, rmax, rmax);
}

/* vector components are not allowed inside functions: unpack them first */
static void unpack(const char *v, const char *name) {
    w("  #local %sv = %s;\n  #local %sx = %sv.x; #local %sy = %sv.y; #local %sz = %sv.z;\n", name,
      v, name, name, name, name, name, name);
}

static void primitives(void) {
    w("// ---- primitives (zero convention: f = rho - 1) ----\n\n");
    w("#macro LB_Sphere(C, R)\n");
    unpack("C", "lbc");
    w("  function(x, y, z) { sqrt((x - lbcx) * (x - lbcx) + (y - lbcy) * (y - lbcy) + "
      "(z - lbcz) * (z - lbcz)) / R - 1 }\n#end\n\n");
    w("#macro LB_Ellipsoid(C, A)\n");
    unpack("C", "lbc");
    unpack("A", "lba");
    w("  function(x, y, z) { sqrt(pow((x - lbcx) / lbax, 2) + pow((y - lbcy) / lbay, 2) + "
      "pow((z - lbcz) / lbaz, 2)) - 1 }\n#end\n\n");
    w("// the space between two parallel planes through C with normal N (any length)\n"
      "#macro LB_Slab(C, N, HalfWidth)\n");
    unpack("C", "lbc");
    unpack("vnormalize(N)", "lbu");
    w("  function(x, y, z) { abs(lbux * (x - lbcx) + lbuy * (y - lbcy) + lbuz * (z - lbcz)) / "
      "HalfWidth - 1 }\n#end\n\n");
    w("// infinite cylinder through C along Axis\n#macro LB_Cylinder(C, Axis, R)\n");
    unpack("C", "lbc");
    unpack("vnormalize(Axis)", "lbu");
    w("  function(x, y, z) { sqrt(max(0, pow(x - lbcx, 2) + pow(y - lbcy, 2) + pow(z - lbcz, 2) "
      "- pow(lbux * (x - lbcx) + lbuy * (y - lbcy) + lbuz * (z - lbcz), 2))) / R - 1 }\n"
      "#end\n\n");
    w("// segment skeleton from S to E\n#macro LB_Capsule(S, E, R)\n");
    unpack("S", "lbs");
    unpack("E - S", "lbd");
    w("  #local lbl2 = vdot(E - S, E - S);\n"
      "  #local lbt = function(x, y, z) { min(1, max(0, (lbdx * (x - lbsx) + lbdy * (y - lbsy) "
      "+ lbdz * (z - lbsz)) / lbl2)) }\n"
      "  function(x, y, z) { sqrt(pow(x - lbsx - lbt(x, y, z) * lbdx, 2) + pow(y - lbsy - "
      "lbt(x, y, z) * lbdy, 2) + pow(z - lbsz - lbt(x, y, z) * lbdz, 2)) / R - 1 }\n#end\n\n");
    w("// distance to the circle of radius Major around Axis through C, over Minor\n"
      "#macro LB_Torus(C, Axis, Major, Minor)\n");
    unpack("C", "lbc");
    unpack("vnormalize(Axis)", "lbu");
    w("  #local lba = function(x, y, z) { lbux * (x - lbcx) + lbuy * (y - lbcy) + lbuz * "
      "(z - lbcz) }\n"
      "  #local lbq = function(x, y, z) { sqrt(max(0, pow(x - lbcx, 2) + pow(y - lbcy, 2) + "
      "pow(z - lbcz, 2) - pow(lba(x, y, z), 2))) }\n"
      "  function(x, y, z) { sqrt(pow(lbq(x, y, z) - Major, 2) + pow(lba(x, y, z), 2)) / Minor "
      "- 1 }\n#end\n\n");
}

/* the other primitives and the soft kernels */
static void primitives2(void) {
    w("// LP metric: (sum |x_i / a_i|^N)^(1/N), N >= 1\n#macro LB_LP(C, A, N)\n");
    unpack("C", "lbc");
    unpack("A", "lba");
    w("  #local lbn = N;\n"
      "  function(x, y, z) { pow(pow(abs(x - lbcx) / lbax, lbn) + pow(abs(y - lbcy) / lbay, lbn) "
      "+ pow(abs(z - lbcz) / lbaz, lbn), 1 / lbn) - 1 }\n#end\n\n");
    w("// Barr's superquadric: ((|x/a1|^(2/E2) + |y/a2|^(2/E2))^(E2/E1) + |z/a3|^(2/E1))^(E1/2)\n"
      "#macro LB_Superquadric(C, A, E1, E2)\n");
    unpack("C", "lbc");
    unpack("A", "lba");
    w("  #local lbe1 = E1; #local lbe2 = E2;\n"
      "  function(x, y, z) { pow(pow(pow(abs(x - lbcx) / lbax, 2 / lbe2) + pow(abs(y - lbcy) / "
      "lbay, 2 / lbe2), lbe2 / lbe1) + pow(abs(z - lbcz) / lbaz, 2 / lbe1), lbe1 / 2) - 1 }\n"
      "#end\n\n");
    w("// one-branch plane: max(N.(X - C), 0) / W - 1 (only C0 on the plane)\n"
      "#macro LB_Halfspace(C, N, W)\n");
    unpack("C", "lbc");
    unpack("vnormalize(N)", "lbu");
    w("  function(x, y, z) { max(0, lbux * (x - lbcx) + lbuy * (y - lbcy) + lbuz * (z - lbcz)) / "
      "W - 1 }\n#end\n\n");
    w("// soft kernels of rho (rho = f + 1 of a zero-convention primitive): 0.5 on the surface\n"
      "#declare LB_Wyvill = function(lbrho) { select(lbrho - 2, pow(1 - lbrho * lbrho / 4, 2) * "
      "(1 - lbrho * lbrho / 9), 0, 0) }\n"
      "#declare LB_Blinn = function(lbrho) { exp(-%.17g * lbrho * lbrho) }\n\n",
      LN2);
}

static void classic(void) {
    w("// ---- classic operators ----\n\n");
    w("// Rvachev R-functions (binary, zero convention)\n"
      "#macro LB_RUnion(F1, F2)\n  function(x, y, z) { F1(x, y, z) + F2(x, y, z) - "
      "sqrt(pow(F1(x, y, z), 2) + pow(F2(x, y, z), 2)) }\n#end\n"
      "#macro LB_RIntersection(F1, F2)\n  function(x, y, z) { F1(x, y, z) + F2(x, y, z) + "
      "sqrt(pow(F1(x, y, z), 2) + pow(F2(x, y, z), 2)) }\n#end\n\n");
    w("// soft convention (inside f > 0.5): Wyvill's sum, Ricci's union, Perlin's products\n"
      "#macro LB_SoftSum(F)\n  #local K = dimension_size(F, 1);\n"
      "  function(x, y, z) { 0 #for (I, 0, K - 1) + F[I](x, y, z) #end }\n#end\n"
      "#macro LB_Ricci(F, N)\n  LB__One(\"LB_Ricci\", \"N\", N, 1, 1000, \"1 to 1000\")\n"
      "  #local K = dimension_size(F, 1);\n"
      "  function(x, y, z) { pow(0 #for (I, 0, K - 1) + pow(max(0, F[I](x, y, z)), N) #end, "
      "1 / N) }\n#end\n"
      "#macro LB_PerlinUnion(F)\n  #local K = dimension_size(F, 1);\n"
      "  function(x, y, z) { max(0, 1 - (1 #for (I, 0, K - 1) * (1 - F[I](x, y, z)) #end)) }\n"
      "#end\n"
      "#macro LB_PerlinIntersection(F)\n  #local K = dimension_size(F, 1);\n"
      "  function(x, y, z) { max(0, 1 #for (I, 0, K - 1) * F[I](x, y, z) #end) }\n#end\n"
      "#macro LB_PerlinDifference(F)\n  #local K = dimension_size(F, 1);\n"
      "  function(x, y, z) { max(0, F[0](x, y, z) #for (I, 1, K - 1) * (1 - F[I](x, y, z)) "
      "#end) }\n#end\n\n");
}

/* LB_Conic(Op, F1, F2, R, P, M): the binary conic BT_2 in closed form,
 * mirroring lb__conic_union step for step (shifted variable s = h - h1). */
/* Write a template: $X = the extra parameters of the variable form, $A and
 * $W = the quadratic's leading coefficient and the chord weight (constants,
 * or expressions in the parameters), $P = the function-name prefix. */
static void wt(const char *t, int var, const char *pre) {
    for (; *t; ++t) {
        if (t[0] != '$') {
            fputc(*t, out);
            continue;
        }
        ++t;
        if (*t == 'X')
            w("%s", var ? ", lbr1, lbr2, lbm1, lbm2" : "");
        else if (*t == 'A')
            w("%s", var ? "(lbr2 * lbr2 * lbm1 * lbm1 + lbr1 * lbr1 * lbm2 * lbm2 + 2 * lbp * "
                          "lbm1 * lbm2)"
                        : "lba");
        else if (*t == 'W')
            w("%s", var ? "(lbr1 * lbm2 + lbr2 * lbm1)" : "lbw");
        else if (*t == 'P')
            w("%s", pre);
    }
}

/* The conic union of lb__conic_union as a chain of functions ending in
 * <pre>U(x1, x2 [, r1, r2, m1, m2]): with var, the ranges and slopes are
 * parameters (bulge elimination), else the constants lbr1.. of the macro. */
static void conic_chain(int var, const char *pre) {
    /* distance of a candidate from [s2, 0] */
    wt("  #local $Pdist = function(lbc, lbs2) { select(-lbc, lbc, select(lbc - lbs2, lbs2 - lbc, "
       "0)) }\n",
       var, pre);
    wt("  #local $Ppick = function(lbsa, lbsb, lbs2) { min(0, max(lbs2, select($Pdist(lbsb, lbs2) "
       "- $Pdist(lbsa, lbs2), lbsb, lbsa))) }\n",
       var, pre);
    wt("  #local $Ps4 = function(lbq, lbcc, lbch$X) { select((lbcc / lbq <= 0) * (lbcc / lbq * $W "
       ">= lbch) - 0.5, $Ppick(lbcc / lbq, lbq / $A, lbch / $W), lbcc / lbq) }\n",
       var, pre);
    wt("  #local $Ps3 = function(lbb, lbcc, lbch$X) { $Ps4(-0.5 * (lbb + select(lbb, -sqrt(max(0, "
       "lbb * lbb - 4 * $A * lbcc)), sqrt(max(0, lbb * lbb - 4 * $A * lbcc)))), lbcc, lbch$X) }\n",
       var, pre);
    wt("  #local $Ps2 = function(lbv1, lbv2, lbch$X) { $Ps3(2 * ((lbr1 - lbv1) * lbr2 * lbr2 * "
       "lbm1 + (lbr2 - lbv2) * lbr1 * lbr1 * lbm2 - lbp * (lbv1 * lbm2 + lbv2 * lbm1)), lbch * "
       "lbch + 2 * (lbp - lbr1 * lbr2) * lbv1 * lbv2, lbch$X) }\n",
       var, pre);
    wt("  #local $Pin = function(lbh1, lbv1, lbv2$X) { lbh1 + $Ps2(lbv1, lbv2, lbr1 * lbv2 + lbr2 "
       "* lbv1 - lbr1 * lbr2$X) }\n",
       var, pre);
    /* region II and h1 */
    wt("  #local $Pu = function(lbx1, lbx2, lbh1, lbc$X) { select(lbc, select(lbx1 - lbm1 * lbh1 "
       "- lbr1, $Pin(lbh1, lbx1 - lbm1 * lbh1, 0$X), lbh1), select(lbx2 - lbm2 * lbh1 - lbr2, "
       "$Pin(lbh1, 0, lbx2 - lbm2 * lbh1$X), lbh1)) }\n",
       var, pre);
    wt("  #local $PU = function(lbx1, lbx2$X) { $Pu(lbx1, lbx2, select(lbx2 * lbm1 - lbx1 * lbm2, "
       "lbx2 / lbm2, lbx1 / lbm1), lbx2 * lbm1 - lbx1 * lbm2$X) }\n",
       var, pre);
}

/* LB_Conic(Op, F1, F2, R, P, M): the binary conic BT_2 in closed form,
 * mirroring lb__conic_union step for step (shifted variable s = h - h1). */
static void conic(void) {
    w("// ---- binary conic blend BT_2 (hsu2006 Eq. 4), closed form ----\n"
      "// LB_Conic(Op, F1, F2, R, Shape, M): Op 0 union, 1 intersection, 2 difference;\n"
      "// R, M arrays of 2 (r > 0, m > 0); Shape (the paper's p) below R[0] R[1]; 0 is\n"
      "// the quarter ellipse, the same as LB_Displacement with p = 2.\n");
    w("#macro LB_Conic(Op, F1, F2, R, Shape, M)\n"
      "  LB__Op(\"LB_Conic\", Op)\n");
    check_r("LB_Conic", "2", LB_MAX_RANGE);
    w("  LB__Per(\"LB_Conic\", \"M\", M, 2, %g, %g, \"m > 0, %g to %g\")\n"
      "  #if (Shape >= R[0] * R[1])\n"
      "    #error concat(\"LB_Conic: Shape = \", str(Shape, 0, 9), \"; allowed: below R[0] R[1] = "
      "\", "
      "str(R[0] * R[1], 0, 9))\n  #end\n",
      LB_MIN_SLOPE, LB_MAX_SLOPE, LB_MIN_SLOPE, LB_MAX_SLOPE);
    w("  #local lbr1 = R[0]; #local lbr2 = R[1]; #local lbm1 = M[0]; #local lbm2 = M[1];\n"
      "  #local lbp = Shape;\n"
      "  #local lba = lbr2 * lbr2 * lbm1 * lbm1 + lbr1 * lbr1 * lbm2 * lbm2 + 2 * lbp * lbm1 * "
      "lbm2;\n"
      "  #local lbw = lbr1 * lbm2 + lbr2 * lbm1;\n");
    conic_chain(0, "lb");
    w("  #local lbSG = select(Op - 1, 1, -1, -1);\n"
      "  #local lbSO = select(abs(Op - 1), -1, -1, 1);\n"
      "  function(x, y, z) { lbSG * lbU(lbSG * F1(x, y, z), lbSO * F2(x, y, z)) }\n#end\n\n");
}

/* "lbd0, ..., lbd15, lbm0, ..., lbm15, lbr0, ..., lbr15" */
static void vlist(void) {
    for (int i = 0; i < KMAX; ++i) w("lbd%d, ", i);
    for (int i = 0; i < KMAX; ++i) w("lbm%d, ", i);
    for (int i = 0; i < KMAX; ++i) w("%slbr%d", i ? ", " : "", i);
}

/* The displacement root with every d, m and r a parameter (p baked from the
 * array lbP): lbVB(d..., m..., r...) inside the current macro. Used where m
 * or r vary with the point (scale method, bounded primitives). */
static void vsolver(int steps) {
    w("  #local lbVS = function(lbh, ");
    vlist();
    w(") {\n    (-1");
    for (int i = 0; i < KMAX; ++i)
        w(" + pow(max(0, (lbr%d - lbd%d + lbm%d * lbh) / lbr%d), lbP[%d])", i, i, i, i, i);
    w(")\n    / (0");
    for (int i = 0; i < KMAX; ++i)
        w(" + (lbP[%d] * lbm%d / lbr%d) * ((lbr%d - lbd%d + lbm%d * lbh) / lbr%d > 0) * "
          "pow(max(0, (lbr%d - lbd%d + lbm%d * lbh) / lbr%d), lbP[%d] - 1)",
          i, i, i, i, i, i, i, i, i, i, i, i);
    w(") }\n");
    w("  #local lbVN%d = function(lbh, lbl, ", steps);
    vlist();
    w(") { lbh }\n");
    for (int n = steps - 1; n >= 0; --n) {
        w("  #local lbVE%d = function(lbh, lbs, lbl, ", n);
        vlist();
        w(") { select(abs(lbs) - %.17g * (1 + abs(lbh)), lbh - lbs, lbh - lbs, "
          "lbVN%d(max(lbl, lbh - lbs), lbl, ",
          TOL, n + 1);
        vlist();
        w(")) }\n");
        w("  #local lbVN%d = function(lbh, lbl, ", n);
        vlist();
        w(") { lbVE%d(lbh, lbVS(lbh, ", n);
        vlist();
        w("), lbl, ");
        vlist();
        w(") }\n");
    }
    w("  #local lbVB = function(");
    vlist();
    w(") { lbVN0(min(");
    for (int i = 0; i < KMAX; ++i) w("%slbd%d / lbm%d", i ? ", " : "", i, i);
    w("), min(");
    for (int i = 0; i < KMAX; ++i) w("%s(lbd%d - lbr%d) / lbm%d", i ? ", " : "", i, i, i);
    w("), ");
    vlist();
    w(") }\n");
}

/* "lby0, ..., lby15" with an optional sign */
static void ylist(const char *sign) {
    for (int i = 0; i < KMAX; ++i) w("%s%slby%d", i ? ", " : "", sign, i);
}

/* "lbq0, ..., lbq15": per-point ranges */
static void qlist(const char *fmt) {
    for (int i = 0; i < KMAX; ++i) {
        if (i) w(", ");
        w(fmt, i);
    }
}

/* The scale method's zero-convention set operations with the ranges as
 * parameters (lbq0..15), mirroring scale_zero: lbZU(y..., q...) (union) and
 * lbZI(y..., q...) (intersection; difference negates its tail first). */
static void scale_body(int steps) {
    vsolver(steps);
    /* B_A(y), min y > 0: sc * (-1 / BT(-1; m = y / sc, r = q)) */
    w("  #local lbBA2 = function(lbsc, ");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { lbsc * (-1 / lbVB(");
    for (int i = 0; i < KMAX; ++i) w("-1, ");
    for (int i = 0; i < KMAX; ++i) w("lby%d / lbsc, ", i);
    qlist("lbq%d");
    w(")) }\n  #local lbBA = function(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { lbBA2(min(");
    ylist("");
    w("), ");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") }\n");
    /* B_S(y), max y > 0, r clamped to 1: terms that cannot be active masked */
    w("  #local lbBS2 = function(lbsc, ");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { lbsc * (1 / lbVB(");
    for (int i = 0; i < KMAX; ++i)
        w("select((lby%d / lbsc > 1 - min(lbq%d, 1)) * (lby%d / lbsc >= 1e-100) - 0.5, 1e30, 1), ",
          i, i, i);
    for (int i = 0; i < KMAX; ++i)
        w("select((lby%d / lbsc > 1 - min(lbq%d, 1)) * (lby%d / lbsc >= 1e-100) - 0.5, 1, lby%d / "
          "lbsc), ",
          i, i, i, i);
    qlist("min(lbq%d, 1)");
    w(")) }\n  #local lbBS = function(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { lbBS2(max(");
    ylist("");
    w("), ");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") }\n");
    /* union: B_AS(y) - 1; intersection, difference: B_SA(y) - 1 */
    w("  #local lbZU = function(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { select(-min(");
    ylist("");
    w("), lbBA(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w("), -lbBS(");
    ylist("-");
    w(", ");
    qlist("lbq%d");
    w("), -lbBS(");
    ylist("-");
    w(", ");
    qlist("lbq%d");
    w(")) - 1 }\n  #local lbZI = function(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w(") { select(-max(");
    ylist("");
    w("), lbBS(");
    ylist("");
    w(", ");
    qlist("lbq%d");
    w("), -lbBA(");
    ylist("-");
    w(", ");
    qlist("lbq%d");
    w("), -lbBA(");
    ylist("-");
    w(", ");
    qlist("lbq%d");
    w(")) - 1 }\n");
}

/* LB_Scale(Op, F, R, P): the scale method, mirroring lb__scale_setop. */
static void scale(int steps) {
    w("// ---- scale method (Hsu-Lee) ----\n"
      "// LB_Scale(Op, F, R, P): Op 0 union, 1 intersection, 2 difference; F 1 to %d\n"
      "// functions (ray-linear primitives: f >= -1); R (> 0; <= 1 for intersection and\n"
      "// difference) and P (%g to %g) one per function. Solved like LB_Displacement\n"
      "// (the scale method is the displacement equation in 1/h).\n",
      KMAX, P_MIN, P_MAX);
    w("#macro LB_Scale(Op, F, R, P)\n");
    w("  LB__Op(\"LB_Scale\", Op)\n  LB__Count(\"LB_Scale\", F, %d)\n"
      "  #local K = dimension_size(F, 1);\n"
      "  #if (Op = 0)\n",
      KMAX);
    check_r("LB_Scale", "K", LB_MAX_RANGE);
    w("  #else\n");
    check_r("LB_Scale", "K", 1.0);
    w("  #end\n"
      "  LB__Per(\"LB_Scale\", \"P\", P, K, %g, %g, \"%g to %g\")\n",
      P_MIN, P_MAX, P_MIN, P_MAX);
    w("  #local lbR = array[%d]; #local lbP = array[%d];\n", KMAX, KMAX);
    w("  #for (I, 0, %d) #if (I < K) #local lbR[I] = R[I]; #local lbP[I] = P[I]; #else #local "
      "lbR[I] = 1; #local lbP[I] = 2; #end #end\n",
      KMAX - 1);
    scale_body(steps);
    w("  #local lbFill = select(Op - 0.5, 1e30, -1e30);\n"
      "  #local lbSO = select(Op - 1.5, 1, -1);\n");
    w("  #if (Op = 0)\n  function(x, y, z) { lbZU(");
    for (int i = 0; i < KMAX; ++i)
        w("%s#if (K > %d) F[%d](x, y, z) + 1 #else lbFill #end", i ? ", " : "", i, i);
    w(", ");
    qlist("lbR[%d]");
    w(") }\n  #else\n  function(x, y, z) { lbZI(");
    for (int i = 0; i < KMAX; ++i)
        w("%s#if (K > %d) %sF[%d](x, y, z) + 1 #else lbFill #end", i ? ", " : "", i,
          i ? "lbSO * " : "", i);
    w(", ");
    qlist("lbR[%d]");
    w(") }\n  #end\n#end\n\n");
}

/* LB_Bounded(Op, F, C, P): bounded primitives, mirroring lb_bounded: the
 * scale method with per-point ranges from the bounding solids. */
static void bounded(int steps) {
    w("// ---- bounded primitives (hsu-bounded 3) ----\n"
      "// LB_Bounded(Op, F, C, P): Op 0 union, 1 intersection, 2 difference; F 1 to %d\n"
      "// ray-linear primitives and C their bounding solids (the same kind, containing F[i]\n"
      "// for union, inside it for intersection); P one per function (%g to %g). Outside its\n"
      "// bounding solid a primitive does not blend.\n",
      KMAX, P_MIN, P_MAX);
    w("#macro LB_Bounded(Op, F, C, P)\n"
      "  LB__Op(\"LB_Bounded\", Op)\n  LB__Count(\"LB_Bounded\", F, %d)\n"
      "  #local K = dimension_size(F, 1);\n"
      "  #if (dimension_size(C, 1) != K)\n"
      "    #error concat(\"LB_Bounded: C has \", str(dimension_size(C, 1), 0, 0), \" bounding "
      "solids for \", str(K, 0, 0), \" functions; allowed: one per function\")\n  #end\n"
      "  LB__Per(\"LB_Bounded\", \"P\", P, K, %g, %g, \"%g to %g\")\n",
      KMAX, P_MIN, P_MAX, P_MIN, P_MAX);
    w("  #local lbP = array[%d];\n", KMAX);
    w("  #for (I, 0, %d) #if (I < K) #local lbP[I] = P[I]; #else #local lbP[I] = 2; #end #end\n",
      KMAX - 1);
    scale_body(steps);
    /* R_i = omega where c_i + 1 <= 0, else max(omega, min(cap, sgn ((x+1)/(c+1) - 1))) */
    w("  #local lbCap = select(Op - 0.5, 1e300, 1);\n"
      "  #local lbRU = function(lbx, lbc) { select(lbc + 1, %.17g, %.17g, max(%.17g, min(lbCap, "
      "(lbx + 1) / (lbc + 1) - 1))) }\n"
      "  #local lbRI = function(lbx, lbc) { select(lbc + 1, %.17g, %.17g, max(%.17g, min(lbCap, "
      "1 - (lbx + 1) / (lbc + 1)))) }\n",
      LB_BOUNDED_OMEGA, LB_BOUNDED_OMEGA, LB_BOUNDED_OMEGA, LB_BOUNDED_OMEGA, LB_BOUNDED_OMEGA,
      LB_BOUNDED_OMEGA);
    /* unused slots: neutral after the difference's negation */
    w("  #local lbFillF = select(abs(Op - 1) - 0.5, -1e30, 1e30);\n"
      "  #local lbSO = select(Op - 1.5, 1, -1);\n");
    /* the values, then y = (signed) x + 1 and the ranges */
    w("  #local lbT = function(");
    for (int i = 0; i < KMAX; ++i) w("lbf%d, ", i);
    for (int i = 0; i < KMAX; ++i) w("%slbc%d", i ? ", " : "", i);
    w(") {\n    #if (Op = 0) lbZU(");
    for (int i = 0; i < KMAX; ++i) w("%slbf%d + 1", i ? ", " : "", i);
    w(", ");
    for (int i = 0; i < KMAX; ++i) w("%slbRU(lbf%d, lbc%d)", i ? ", " : "", i, i);
    w(")\n    #else lbZI(");
    for (int i = 0; i < KMAX; ++i) w("%s%slbf%d + 1", i ? ", " : "", i ? "lbSO * " : "", i);
    w(", lbRI(lbf0, lbc0)");
    for (int i = 1; i < KMAX; ++i)
        w(", select(Op - 1.5, lbRI(lbf%d, lbc%d), lbRU(lbf%d, lbc%d))", i, i, i, i);
    w(")\n    #end }\n");
    w("  function(x, y, z) { lbT(");
    for (int i = 0; i < KMAX; ++i)
        w("%s#if (K > %d) F[%d](x, y, z) #else lbFillF #end", i ? ", " : "", i, i);
    /* an unused slot gets c = f: range omega, never active */
    for (int i = 0; i < KMAX; ++i) w(", #if (K > %d) C[%d](x, y, z) #else lbFillF #end", i, i);
    w(") }\n#end\n\n");
}

/* "lba0, ..., lba15" */
static void alist(void) {
    for (int i = 0; i < KMAX; ++i) w("%slba%d", i ? ", " : "", i);
}

/* LB_SoftHyper(Op, F, R, P, M): mirroring lb_soft_hyper. */
/* LB_SoftHyper's bracketed Newton chain in lambda: lbN0 .. lbN<steps> */
static void soft_hyper_newton(int steps) {
    /* CPS bracketed Newton */
    w("  #local lbN%d = function(lbl, lblo, lbhi, ", steps);
    alist();
    w(") { lbl }\n");
    for (int n = steps - 1; n >= 0; --n) {
        /* F_n(next, lo, hi): Newton if inside, else bisection */
        w("  #local lbF%d = function(lbx, lblo, lbhi, ", n);
        alist();
        w(") { lbN%d(select((lbx > lblo) * (lbx < lbhi) - 0.5, 0.5 * (lblo + lbhi), lbx), lblo, "
          "lbhi, ",
          n + 1);
        alist();
        w(") }\n");
        /* E_n(lambda, T, D, lo, hi): exit, or the next step with the bracket updated */
        w("  #local lbE%d = function(lbl, lbt, lbd, lblo, lbhi, ", n);
        alist();
        w(") { select(abs(lbt / lbd) - %.17g, min(lbhi, max(lblo, lbl - lbt / lbd)), min(lbhi, "
          "max(lblo, lbl - lbt / lbd)), lbF%d(lbl - lbt / lbd, select(-lbt, lblo, lbl), "
          "select(-lbt, lbl, lbhi), ",
          LTOL, n);
        alist();
        w(")) }\n");
        w("  #local lbN%d = function(lbl, lblo, lbhi, ", n);
        alist();
        w(") { lbE%d(lbl, lbT(lbl, ", n);
        alist();
        w("), lbD(lbl, ");
        alist();
        w("), lblo, lbhi, ");
        alist();
        w(") }\n");
    }
}

static void soft_hyper(int steps) {
    w("// ---- soft objects: super-ellipsoidal blends with non-uniform scaling ----\n"
      "// LB_SoftHyper(Op, F, R, P, M) (soft convention): Op 0 union, 1 intersection,\n"
      "// 2 difference; F 1 to %d soft fields; R (> 0; <= 1 for union), P (%g to %g), M\n"
      "// (0.05 to 20) one per field. Solved in ln h by Newton inside the bracket of\n"
      "// spec section 7 (bisection when a step leaves it), %d unrolled steps.\n",
      KMAX, P_MIN, P_MAX, steps);
    w("#macro LB_SoftHyper(Op, F, R, P, M)\n"
      "  LB__Op(\"LB_SoftHyper\", Op)\n  LB__Count(\"LB_SoftHyper\", F, %d)\n"
      "  #local K = dimension_size(F, 1);\n"
      "  #if (Op = 0)\n",
      KMAX);
    check_r("LB_SoftHyper", "K", 1.0);
    w("  #else\n");
    check_r("LB_SoftHyper", "K", LB_MAX_RANGE);
    w("  #end\n"
      "  LB__Per(\"LB_SoftHyper\", \"P\", P, K, %g, %g, \"%g to %g\")\n"
      "  LB__Per(\"LB_SoftHyper\", \"M\", M, K, %g, %g, \"%g to %g\")\n",
      P_MIN, P_MAX, P_MIN, P_MAX, M_MIN, M_MAX, M_MIN, M_MAX);
    w("  #local lbR = array[%d]; #local lbP = array[%d]; #local lbM = array[%d];\n", KMAX, KMAX,
      KMAX);
    w("  #for (I, 0, %d) #if (I < K) #local lbR[I] = R[I]; #local lbP[I] = P[I]; #local lbM[I] = "
      "M[I]; #else #local lbR[I] = 1; #local lbP[I] = 2; #local lbM[I] = 1; #end #end\n",
      KMAX - 1);
    w("  #local lbU = (Op = 0);\n");
    /* T and D in lambda */
    w("  #local lbT = function(lbl, ");
    alist();
    w(") { select(lbU - 0.5, 1, -1) * (0");
    for (int i = 0; i < KMAX; ++i)
        w(" + pow(max(0, select(lbU - 0.5, (1 + lbR[%d] - exp(lba%d - lbM[%d] * lbl)) / lbR[%d], "
          "(lbR[%d] - 1 + exp(lba%d - lbM[%d] * lbl)) / lbR[%d])), lbP[%d])",
          i, i, i, i, i, i, i, i, i);
    w(") + select(lbU - 0.5, 1, -1) * -1 }\n");
    w("  #local lbD = function(lbl, ");
    alist();
    w(") { 0");
    for (int i = 0; i < KMAX; ++i)
        w(" + select(-select(lbU - 0.5, (1 + lbR[%d] - exp(lba%d - lbM[%d] * lbl)) / lbR[%d], "
          "(lbR[%d] - 1 + exp(lba%d - lbM[%d] * lbl)) / lbR[%d]), lbP[%d] / lbR[%d] * "
          "pow(select(lbU - 0.5, (1 + lbR[%d] - exp(lba%d - lbM[%d] * lbl)) / lbR[%d], "
          "(lbR[%d] - 1 + exp(lba%d - lbM[%d] * lbl)) / lbR[%d]), lbP[%d] - 1) * lbM[%d] * "
          "exp(lba%d - lbM[%d] * lbl), 0, 0)",
          i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i);
    w(" }\n");
    soft_hyper_newton(steps);
    /* from the (adjusted) values: a_i, the bracket, then h = exp(lambda) */
    w("  #local lbNpos = function(");
    ylist("");
    w(") { 0");
    for (int i = 0; i < KMAX; ++i) w(" + (lby%d > 0)", i);
    w(" }\n");
    w("  #local lbS2 = function(lbnb, lbot, ");
    alist();
    w(") { exp(select(lbU - 0.5, lbN0(lbnb, lbot, lbnb, ");
    alist();
    w("), lbN0(lbnb, lbnb, lbot, ");
    alist();
    w("))) }\n");
    /* a_i = ln y_i + (1 - m_i) ln 2, or -1e30 for y_i <= 0 (only in unions) */
    w("  #local lbS1 = function(lbn, ");
    alist();
    w(") { lbS2(select(lbU - 0.5, min(");
    for (int i = 0; i < KMAX; ++i) w("%slba%d / lbM[%d]", i ? ", " : "", i, i);
    w("), max(");
    for (int i = 0; i < KMAX; ++i) w("%slba%d / lbM[%d]", i ? ", " : "", i, i);
    w(")), select(lbU - 0.5, min(");
    for (int i = 0; i < KMAX; ++i)
        w("%s(lba%d - ln(1 + lbR[%d])) / lbM[%d]", i ? ", " : "", i, i, i);
    w("), max(");
    for (int i = 0; i < KMAX; ++i)
        w("%sselect(lbR[%d] - 1, (lba%d - ln(1 - lbR[%d])) / lbM[%d], (lba%d + ln(lbn) / lbP[%d]) "
          "/ lbM[%d])",
          i ? ", " : "", i, i, i, i, i, i, i);
    w(")), ");
    alist();
    w(") }\n");
    w("  #local lbS0 = function(");
    ylist("");
    w(") { select(select(lbU - 0.5, min(");
    ylist("");
    w("), max(");
    ylist("");
    w(")), 0, 0, lbS1(lbNpos(");
    ylist("");
    w(")");
    for (int i = 0; i < KMAX; ++i)
        w(", select(lby%d, -1e30, -1e30, ln(lby%d) + (1 - lbM[%d]) * %.17g)", i, i, i, LN2);
    w(")) }\n");
    /* the soft values, complemented in a difference's tail, below 1e-300 as 0 */
    w("  #local lbFill = select(lbU - 0.5, 1e300, 0);\n"
      "  #local lbV = function(lbv) { select(lbv - 1e-300, 0, lbv, lbv) }\n"
      "  function(x, y, z) { lbS0(");
    for (int i = 0; i < KMAX; ++i) {
        if (i == 0)
            w("lbV(F[0](x, y, z))");
        else
            w(", #if (K > %d) lbV(#if (Op = 2) 1 - #end F[%d](x, y, z)) #else lbFill #end", i, i);
    }
    w(") }\n#end\n\n");
}

/* A bracketed Newton chain in lambda over (lba0, lba1): functions
 * <pre>N0(lambda, lo, hi, lba0, lba1) returning the root, from SDL bodies
 * for T and T' (in lbl, lba0, lba1). */
static void bchain2(const char *pre, int steps, const char *T, const char *D) {
    w("  #local %sT = function(lbl, lba0, lba1) { %s }\n", pre, T);
    w("  #local %sD = function(lbl, lba0, lba1) { %s }\n", pre, D);
    w("  #local %sN%d = function(lbl, lblo, lbhi, lba0, lba1) { lbl }\n", pre, steps);
    for (int n = steps - 1; n >= 0; --n) {
        w("  #local %sF%d = function(lbx, lblo, lbhi, lba0, lba1) { %sN%d(select((lbx > lblo) * "
          "(lbx < lbhi) - 0.5, 0.5 * (lblo + lbhi), lbx), lblo, lbhi, lba0, lba1) }\n",
          pre, n, pre, n + 1);
        w("  #local %sE%d = function(lbl, lbt, lbd, lblo, lbhi, lba0, lba1) { select(abs(lbt / "
          "lbd) - %.17g, min(lbhi, max(lblo, lbl - lbt / lbd)), min(lbhi, max(lblo, lbl - lbt / "
          "lbd)), %sF%d(lbl - lbt / lbd, select(-lbt, lblo, lbl), select(-lbt, lbl, lbhi), lba0, "
          "lba1)) }\n",
          pre, n, LTOL, pre, n);
        w("  #local %sN%d = function(lbl, lblo, lbhi, lba0, lba1) { %sE%d(lbl, %sT(lbl, lba0, "
          "lba1), %sD(lbl, lba0, lba1), lblo, lbhi, lba0, lba1) }\n",
          pre, n, pre, n, pre, pre);
    }
}

/* LB_SoftConic(Op, F1, F2, R, Shape, M): mirroring lb_soft_conic. */
static void soft_conic(int steps) {
    w("// LB_SoftConic(Op, F1, F2, R, Shape, M) (soft convention): the binary conic\n"
      "// with non-uniform scaling; R, M arrays of 2 (R <= 1 for union), Shape below\n"
      "// R[0] R[1]. Two bracketed Newton solves in ln h (the chord, then the conic).\n");
    w("#macro LB_SoftConic(Op, F1, F2, R, Shape, M)\n"
      "  LB__Op(\"LB_SoftConic\", Op)\n"
      "  #if (Op = 0)\n");
    check_r("LB_SoftConic", "2", 1.0);
    w("  #else\n");
    check_r("LB_SoftConic", "2", LB_MAX_RANGE);
    w("  #end\n"
      "  LB__Per(\"LB_SoftConic\", \"M\", M, 2, %g, %g, \"%g to %g\")\n"
      "  #if (Shape >= R[0] * R[1])\n"
      "    #error concat(\"LB_SoftConic: Shape = \", str(Shape, 0, 9), \"; allowed: below R[0] "
      "R[1] "
      "= \", str(R[0] * R[1], 0, 9))\n  #end\n",
      M_MIN, M_MAX, M_MIN, M_MAX);
    w("  #local lbr1 = R[0]; #local lbr2 = R[1]; #local lbm1 = M[0]; #local lbm2 = M[1];\n"
      "  #local lbp = Shape; #local lbU = (Op = 0); #local lbsg = select(lbU - 0.5, -1, 1);\n"
      "  #local lbn = 1 / (lbr1 * lbr1 * lbr2 * lbr2);\n"
      "  #local lbz1 = function(lbl, lba0) { exp(lba0 - lbm1 * lbl) }\n"
      "  #local lbz2 = function(lbl, lba1) { exp(lba1 - lbm2 * lbl) }\n"
      "  #local lbu1 = function(lbl, lba0) { lbsg * (lbz1(lbl, lba0) - 1) * -1 }\n"
      "  #local lbu2 = function(lbl, lba1) { lbsg * (lbz2(lbl, lba1) - 1) * -1 }\n"
      "  #local lbd1 = function(lbl, lba0) { lbsg * lbm1 * lbz1(lbl, lba0) }\n"
      "  #local lbd2 = function(lbl, lba1) { lbsg * lbm2 * lbz2(lbl, lba1) }\n"
      "  #local lbH = function(lbv1, lbv2) { lbr2 * lbr2 * lbv1 * lbv1 + lbr1 * lbr1 * lbv2 * "
      "lbv2 + lbr1 * lbr1 * lbr2 * lbr2 - 2 * lbr2 * lbr2 * lbr1 * lbv1 - 2 * lbr1 * lbr1 * lbr2 "
      "* lbv2 + 2 * lbp * lbv1 * lbv2 }\n"
      "  #local lbH1 = function(lbv1, lbv2) { 2 * (lbr2 * lbr2 * (lbv1 - lbr1) + lbp * lbv2) }\n"
      "  #local lbH2 = function(lbv1, lbv2) { 2 * (lbr1 * lbr1 * (lbv2 - lbr2) + lbp * lbv1) }\n");
    bchain2("lbC", steps, "lbsg * (lbu1(lbl, lba0) / lbr1 + lbu2(lbl, lba1) / lbr2 - 1)",
            "lbsg * (lbd1(lbl, lba0) / lbr1 + lbd2(lbl, lba1) / lbr2)");
    bchain2("lbK", steps, "-lbsg * lbn * lbH(lbu1(lbl, lba0), lbu2(lbl, lba1))",
            "-lbsg * lbn * (lbH1(lbu1(lbl, lba0), lbu2(lbl, lba1)) * lbd1(lbl, lba0) + "
            "lbH2(lbu1(lbl, lba0), lbu2(lbl, lba1)) * lbd2(lbl, lba1))");
    /* after the chord: the H solve between the non-blending end and it */
    w("  #local lbS3 = function(lbnb, lbc, lba0, lba1) { exp(select(lbU - 0.5, lbKN0(lbnb, lbc, "
      "lbnb, lba0, lba1), lbKN0(lbnb, lbnb, lbc, lba0, lba1))) }\n");
    w("  #local lbS2 = function(lbnb, lbfar, lba0, lba1) { lbS3(lbnb, select(lbU - 0.5, "
      "lbCN0(lbnb, lbfar, lbnb, lba0, lba1), lbCN0(lbnb, lbnb, lbfar, lba0, lba1)), lba0, lba1) "
      "}\n");
    /* region II: the other argument within its range at lam_nb */
    w("  #local lbS1 = function(lbnb, lbo, lbro, lbx0, lbx1, lba0, lba1) { select(select(lbU - "
      "0.5, lbo - 1, 1 - lbo) - lbro, lbS2(lbnb, select(lbU - 0.5, min((lba0 - ln(1 + 0.5 * lbr1)) "
      "/ lbm1, (lba1 - ln(1 + 0.5 * lbr2)) / lbm2), max((lba0 - ln(1 - 0.5 * lbr1)) / lbm1, "
      "(lba1 - ln(1 - 0.5 * lbr2)) / lbm2)), lba0, lba1), exp(lbnb), exp(lbnb)) }\n");
    /* j: the argument of the non-blending end; o the other; the other's z at lam_nb */
    w("  #local lbS0 = function(lbx0, lbx1, lba0, lba1) { select(select(lbU - 0.5, lba1 / lbm2 "
      "- lba0 / lbm1, lba0 / lbm1 - lba1 / lbm2), lbS1(lba1 / lbm2, exp(lba0 - lbm1 * (lba1 / "
      "lbm2)), lbr1, lbx0, lbx1, lba0, lba1), lbS1(lba0 / lbm1, exp(lba1 - lbm2 * (lba0 / "
      "lbm1)), lbr2, lbx0, lbx1, lba0, lba1)) }\n");
    w("  #local lbA = function(lbx, lbm) { select(-lbx, ln(lbx) + (1 - lbm) * %.17g, -1e30) }\n",
      LN2);
    /* zero cases: intersection with a zero, union with both zero; x_o <= 0 outside region II */
    w("  #local lbS = function(lbx0, lbx1) { select(select(lbU - 0.5, min(lbx0, lbx1), max(lbx0, "
      "lbx1)), 0, 0, lbS0(lbx0, lbx1, lbA(lbx0, lbm1), lbA(lbx1, lbm2))) }\n");
    w("  #local lbV = function(lbv) { select(lbv - 1e-300, 0, lbv, lbv) }\n"
      "  function(x, y, z) { lbS(lbV(F1(x, y, z)), lbV(#if (Op = 2) 1 - #end F2(x, y, z))) }\n"
      "#end\n\n");
}

/* LB_BulgeCore / LB_Bulge: bulge elimination for binary blends, mirroring
 * lb_bulge (ranges R_i = r_i (1 - cos theta + omega), optionally slopes
 * M_i(cos theta, |g1|/|g2|)). */
static void bulge(int steps) {
    w("// ---- bulge elimination for binary blends (hsu2006 5; hsu-bounded 2.5) ----\n"
      "// LB_BulgeCore(Family, Op, R, P, Shape, M, Flags, Omega) returns\n"
      "// function(x1, x2, g1x, g1y, g1z, g2x, g2y, g2z): the blend of two values given their\n"
      "// gradients. Family 0 displacement, 1 conic, 2 scale; Op 0 union, 1 intersection,\n"
      "// 2 difference; R, P, M arrays of 2 (P unused by the conic, M by the scale method);\n"
      "// Shape the conic's p; Flags 1 = ranges, 2 = slopes (not for scale), 3 = both;\n"
      "// Omega the range floor (0.001 in the papers).\n"
      "// LB_Bulge(Family, Op, F1, F2, R, P, Shape, M, Flags, Omega, Eps) applies it to two\n"
      "// functions, their gradients by central differences of step Eps.\n");
    w("#macro LB_BulgeCore(Family, Op, R, P, Shape, M, Flags, Omega)\n"
      "  #if (Family != 0 & Family != 1 & Family != 2)\n"
      "    #error concat(\"LB_BulgeCore: Family = \", str(Family, 0, 6), \"; allowed: 0 "
      "(displacement), 1 (conic) or 2 (scale)\")\n  #end\n"
      "  LB__Op(\"LB_BulgeCore\", Op)\n");
    check_r("LB_BulgeCore", "2", LB_MAX_RANGE);
    w("  #if (Family = 0) LB__Per(\"LB_BulgeCore\", \"P\", P, 2, %g, %g, \"%g to %g\") #end\n"
      "  #if (Family != 2) LB__Per(\"LB_BulgeCore\", \"M\", M, 2, %g, %g, \"%g to %g\") #end\n"
      "  #if (Family = 1 & Shape >= R[0] * R[1])\n"
      "    #error concat(\"LB_BulgeCore: Shape = \", str(Shape, 0, 9), \"; allowed: below R[0] "
      "R[1] "
      "= \", str(R[0] * R[1], 0, 9))\n  #end\n"
      "  #if (Flags != 1 & Flags != 2 & Flags != 3 | (Family = 2 & Flags != 1))\n"
      "    #error concat(\"LB_BulgeCore: Flags = \", str(Flags, 0, 6), \"; allowed: 1 (ranges), 2 "
      "(slopes) or 3 (both); 1 for the scale method\")\n  #end\n"
      "  LB__One(\"LB_BulgeCore\", \"Omega\", Omega, 1e-6, 1, \"1e-6 to 1\")\n",
      P_MIN, P_MAX, P_MIN, P_MAX, M_MIN, M_MAX, M_MIN, M_MAX);
    w("  #local lbFam = Family; #local lbop = Op;\n"
      "  #local lbrng = (Flags = 1 | Flags = 3); #local lbslp = (Flags = 2 | Flags = 3);\n"
      "  #local lbom = Omega; #local lbp = Shape;\n"
      "  #local lbb1 = R[0]; #local lbb2 = R[1]; #local lbn1 = M[0]; #local lbn2 = M[1];\n"
      "  #local lbP = array[%d];\n"
      "  #for (I, 0, %d) #if (I < 2) #local lbP[I] = P[I]; #else #local lbP[I] = 2; #end #end\n",
      KMAX, KMAX - 1);
    /* the three base operators with ranges and slopes as parameters */
    w("  #if (lbFam = 0)\n");
    vsolver(steps);
    w("  #local lbBase = function(lbx1, lbx2, lbr1, lbr2, lbm1, lbm2) { lbVB(lbx1, lbx2");
    for (int i = 2; i < KMAX; ++i) w(", 1e30");
    w(", lbm1, lbm2");
    for (int i = 2; i < KMAX; ++i) w(", 1");
    w(", lbr1, lbr2");
    for (int i = 2; i < KMAX; ++i) w(", 1");
    w(") }\n  #elseif (lbFam = 1)\n");
    conic_chain(1, "lbc");
    w("  #local lbBase = function(lbx1, lbx2, lbr1, lbr2, lbm1, lbm2) { lbcU(lbx1, lbx2, lbr1, "
      "lbr2, lbm1, lbm2) }\n  #else\n");
    scale_body(steps);
    w("  #local lbBase = function(lbx1, lbx2, lbr1, lbr2, lbm1, lbm2) { #if (lbop = 0) "
      "lbZU(lbx1 + 1, lbx2 + 1");
    for (int i = 2; i < KMAX; ++i) w(", 1e30");
    w(", lbr1, lbr2");
    for (int i = 2; i < KMAX; ++i) w(", 1");
    w(") #else lbZI(lbx1 + 1, lbx2 + 1");
    for (int i = 2; i < KMAX; ++i) w(", -1e30");
    w(", lbr1, lbr2");
    for (int i = 2; i < KMAX; ++i) w(", 1");
    w(") #end }\n  #end\n");
    /* the duals of the displacement and conic families; the scale method
     * takes x as is and negates a difference's second argument itself */
    w("  #local lbSG = select(lbop - 1, 1, -1, -1);\n"
      "  #local lbSO = select(abs(lbop - 1), -1, -1, 1);\n"
      "  #local lbSig = select(lbop - 1.5, 1, -1);\n");
    w("  #local lbQ3 = function(lbx1, lbx2, lbr1, lbr2, lbm1, lbm2) {\n"
      "    #if (lbFam = 2) lbBase(lbx1, lbSig * lbx2, lbr1, lbr2, lbm1, lbm2)\n"
      "    #else lbSG * lbBase(lbSG * lbx1, lbSO * lbx2, lbr1, lbr2, lbm1, lbm2) #end }\n");
    /* slopes: M from cos+ = max(cs, 0) and G = |g1|/|g2|, kept in [1e-6, 1e6] */
    w("  #local lbQ2 = function(lbx1, lbx2, lbcs, lbG, lbboth) { lbQ3(lbx1, lbx2, "
      "select(lbrng - 0.5, lbb1, lbb1 * (1 - lbcs + lbom)), select(lbrng - 0.5, lbb2, lbb2 * (1 - "
      "lbcs + lbom)), select(lbslp * lbboth - 0.5, lbn1, select(lbn1 - lbn2 * lbG, min(%.17g, "
      "max(%.17g, lbn1 + (lbn2 * lbG - lbn1) * max(lbcs, 0))), lbn1, lbn1)), select(lbslp * "
      "lbboth - 0.5, lbn2, select(lbn1 - lbn2 * lbG, lbn2, lbn2, min(%.17g, max(%.17g, lbn2 + "
      "(lbn1 / lbG - lbn2) * max(lbcs, 0)))))) }\n",
      LB_MAX_SLOPE, LB_MIN_SLOPE, LB_MAX_SLOPE, LB_MIN_SLOPE);
    /* cos theta from unit vectors; a gradient below 1e-30 counts as zero */
    w("  #local lbQ1 = function(lbx1, lbx2, lbg1x, lbg1y, lbg1z, lbg2x, lbg2y, lbg2z, lbl1, lbl2) "
      "{ lbQ2(lbx1, lbx2, select((lbl1 >= %.17g) * (lbl2 >= %.17g) - 0.5, 0, min(1, max(-1, "
      "lbSig * ((lbg1x / lbl1) * (lbg2x / lbl2) + (lbg1y / lbl1) * (lbg2y / lbl2) + (lbg1z / "
      "lbl1) * (lbg2z / lbl2))))), select(lbl2, 1, 1, lbl1 / lbl2), (lbl1 >= %.17g) * (lbl2 >= "
      "%.17g)) }\n",
      LB_BULGE_MIN_GRAD, LB_BULGE_MIN_GRAD, LB_BULGE_MIN_GRAD, LB_BULGE_MIN_GRAD);
    w("  function(lbx1, lbx2, lbg1x, lbg1y, lbg1z, lbg2x, lbg2y, lbg2z) { lbQ1(lbx1, lbx2, lbg1x, "
      "lbg1y, lbg1z, lbg2x, lbg2y, lbg2z, sqrt(lbg1x * lbg1x + lbg1y * lbg1y + lbg1z * lbg1z), "
      "sqrt(lbg2x * lbg2x + lbg2y * lbg2y + lbg2z * lbg2z)) }\n#end\n\n");
    w("#macro LB_Bulge(Family, Op, F1, F2, R, P, Shape, M, Flags, Omega, Eps)\n"
      "  #local lbCore = LB_BulgeCore(Family, Op, R, P, Shape, M, Flags, Omega)\n"
      "  #local lbe = Eps;\n"
      "  function(x, y, z) { lbCore(F1(x, y, z), F2(x, y, z), (F1(x + lbe, y, z) - F1(x - lbe, "
      "y, z)) / (2 * lbe), (F1(x, y + lbe, z) - F1(x, y - lbe, z)) / (2 * lbe), (F1(x, y, z + "
      "lbe) - F1(x, y, z - lbe)) / (2 * lbe), (F2(x + lbe, y, z) - F2(x - lbe, y, z)) / (2 * "
      "lbe), (F2(x, y + lbe, z) - F2(x, y - lbe, z)) / (2 * lbe), (F2(x, y, z + lbe) - F2(x, y, "
      "z - lbe)) / (2 * lbe)) }\n#end\n\n");
}

/* LB_Displacement beyond KMAX arguments: more values than a POV-Ray
 * function takes parameters (56), so the solver carries only (h, x, y, z)
 * and every step evaluates the argument functions again (#for inside the
 * function bodies). The same Newton recurrence as the KMAX path; it costs
 * about 2 K argument calls per step. */
static void displacement_many(int steps) {
    /* argument i's value, dualised: sign * F[i](x, y, z) */
    static const char *const arg = "(#if (I = 0) lbSG #else lbSO #end * F[I](x, y, z))";
    w("  #local lbFS = function(lbh, x, y, z) {\n    (-1 #for (I, 0, K - 1) #if (P[I] = 2) + "
      "max(0, (R[I] - %s + M[I] * lbh) / R[I]) * max(0, (R[I] - %s + M[I] * lbh) / R[I]) #else + "
      "pow(max(0, (R[I] - %s + M[I] * lbh) / R[I]), P[I]) #end #end)\n",
      arg, arg, arg);
    w("    / (0 #for (I, 0, K - 1) #if (P[I] = 2) + (2 * M[I] / R[I]) * max(0, (R[I] - %s + M[I] "
      "* lbh) / R[I]) #else + (P[I] * M[I] / R[I]) * ((R[I] - %s + M[I] * lbh) / R[I] > 0) * "
      "pow(max(0, (R[I] - %s + M[I] * lbh) / R[I]), P[I] - 1) #end #end) }\n",
      arg, arg, arg);
    w("  #local lbFE%d = function(lbh, lbs, lbl, x, y, z) { lbh }\n", steps);
    for (int n = steps - 1; n >= 0; --n)
        w("  #local lbFE%d = function(lbh, lbs, lbl, x, y, z) { select(abs(lbs) - %.17g * (1 + "
          "abs(lbh)), lbh - lbs, lbh - lbs, lbFE%d(max(lbl, lbh - lbs), lbFS(max(lbl, lbh - lbs), "
          "x, y, z), lbl, x, y, z)) }\n",
          n, TOL, n + 1);
    w("  #local lbFB = function(lbh, lbl, x, y, z) { lbFE0(lbh, lbFS(lbh, x, y, z), lbl, x, y, z) "
      "}\n");
    w("  function(x, y, z) { lbSG * lbFB(min(#for (I, 0, K - 1) #if (I > 0), #end %s / M[I] "
      "#end), min(#for (I, 0, K - 1) #if (I > 0), #end (%s - R[I]) / M[I] #end), x, y, z) }\n",
      arg, arg);
}

/* the displacement root's bracket from the argument values lbd_i:
 * "min(d_i / m_i), min((d_i - r_i) / m_i)" (the K in use) */
static void bracket_args(void) {
    w("min(lbd0 / lbM[0], 1e300");
    for (int i = 1; i < KMAX; ++i) w(" #if (K > %d), lbd%d / lbM[%d] #end", i, i, i);
    w("), min((lbd0 - lbR[0]) / lbM[0], 1e300");
    for (int i = 1; i < KMAX; ++i) w(" #if (K > %d), (lbd%d - lbR[%d]) / lbM[%d] #end", i, i, i, i);
    w(")");
}

/* "lbb0, lbb1, ..." (the K in use) */
static void blist(void) {
    w("lbb0");
    for (int i = 1; i < KMAX; ++i) w(" #if (K > %d), lbb%d #end", i, i);
}

/* LB_Displacement with every p = 2, mirroring bt_two in
 * libblend/src/operators/displacement.c: T is piecewise quadratic between
 * the breakpoints b_i = (d_i - r_i)/m_i. From h = min d/m with the terms
 * active there (b_i < h), the larger root hq of that active set's quadratic
 * is the answer unless an active term has b_i > hq; then h moves to the
 * largest such b_i (which drops it) and the next pass solves again. At most
 * K + 1 passes, one or two in practice; exact, no tolerance. */
static void displacement_p2(void) {
    w("  #local lbC2 = array[%d]; #for (I, 0, %d) #local lbC2[I] = (lbM[I] / lbR[I]) * (lbM[I] / "
      "lbR[I]); #end\n",
      KMAX, KMAX - 1);
    /* hq from the active set's sums A = sum c^2, B = sum c^2 (h - b), C = sum c^2 (h - b)^2 */
    w("  #local lbQ2 = function(lbh, lbA, lbBs, lbC) { lbh + select(lbC - 1, 0, 0, "
      "select(lbBs * lbBs - lbA * (lbC - 1), -1e300, -(lbC - 1) / (lbBs + sqrt(lbBs * lbBs - lbA "
      "* (lbC - 1))), -(lbC - 1) / (lbBs + sqrt(lbBs * lbBs - lbA * (lbC - 1))))) }\n");
    w("  #local lbQ = function(lbh, ");
    blist();
    w(") { lbQ2(lbh, 0");
    for (int i = 0; i < KMAX; ++i) w(" #if (K > %d) + (lbb%d < lbh) * lbC2[%d] #end", i, i, i);
    w(", 0");
    for (int i = 0; i < KMAX; ++i)
        w(" #if (K > %d) + (lbb%d < lbh) * lbC2[%d] * (lbh - lbb%d) #end", i, i, i, i);
    w(", 0");
    for (int i = 0; i < KMAX; ++i)
        w(" #if (K > %d) + (lbb%d < lbh) * lbC2[%d] * (lbh - lbb%d) * (lbh - lbb%d) #end", i, i, i,
          i, i);
    w(") }\n");
    w("  #local lbAP%d = function(lbh, ", KMAX + 1);
    blist();
    w(") { lbh }\n");
    for (int n = KMAX; n >= 0; --n) {
        /* X: hq is the answer when no active term lies right of it (bd = -1e300) */
        w("  #local lbAX%d = function(lbhq, lbbd, ", n);
        blist();
        w(") { select(lbbd + 1e299, lbhq, lbhq, lbAP%d(lbbd, ", n + 1);
        blist();
        w(")) }\n");
        w("  #local lbAN%d = function(lbhq, lbh, ", n);
        blist();
        w(") { lbAX%d(lbhq, max(-1e300", n);
        for (int i = 0; i < KMAX; ++i)
            w(" #if (K > %d), select((lbb%d > lbhq) * (lbb%d < lbh) - 0.5, -1e300, lbb%d) #end", i,
              i, i, i);
        w("), ");
        blist();
        w(") }\n");
        w("  #local lbAP%d = function(lbh, ", n);
        blist();
        w(") { lbAN%d(lbQ(lbh, ", n);
        blist();
        w("), lbh, ");
        blist();
        w(") }\n");
    }
    w("  #local lbAC = function(lbhi, lbl, ");
    blist();
    w(") { max(lbl, min(lbhi, lbAP0(lbhi, ");
    blist();
    w("))) }\n");
    w("  #local lbB = function(");
    dlist();
    w(") { lbAC(");
    bracket_args();
    w(", (lbd0 - lbR[0]) / lbM[0]");
    for (int i = 1; i < KMAX; ++i) w(" #if (K > %d), (lbd%d - lbR[%d]) / lbM[%d] #end", i, i, i, i);
    w(") }\n");
}

/* LB_Displacement(Op, F, R, P, M): BT_k by unrolled CPS Newton. */
static void displacement(int steps) {
    w("// ---- displacement blends BT_k (hsu2006; m = 1 everywhere is Rockwood's) ----\n"
      "// LB_Displacement(Op, F, R, P, M): Op 0 union, 1 intersection, 2 difference (F[0]\n"
      "// minus the others); F an array of 1 to %d functions; R, P, M arrays of the same\n"
      "// length (r > 0, %g <= p <= %g, %g <= m <= %g). The root of\n"
      "// T(h) = sum [(r - d + m h)/r]+^p - 1 by Newton from h = min d/m (T convex: no\n"
      "// overshoot), %d unrolled steps, leaving as soon as a step is below %g (1 + |h|).\n",
      KMAX, P_MIN, P_MAX, M_MIN, M_MAX, steps, TOL);
    w("#macro LB_Displacement(Op, F, R, P, M)\n"
      "  LB__Op(\"LB_Displacement\", Op)\n"
      "  LB__Count(\"LB_Displacement\", F, %d)\n"
      "  #local K = dimension_size(F, 1);\n",
      LB_MAX_ARITY);
    check_r("LB_Displacement", "K", LB_MAX_RANGE);
    w("  LB__Per(\"LB_Displacement\", \"P\", P, K, %g, %g, \"%g to %g\")\n"
      "  LB__Per(\"LB_Displacement\", \"M\", M, K, %g, %g, \"%g to %g\")\n",
      P_MIN, P_MAX, P_MIN, P_MAX, M_MIN, M_MAX, M_MIN, M_MAX);
    w(
        /* the argument values are dualised for intersection and difference */
        "  #local lbSG = select(Op - 1, 1, -1, -1);\n"
        "  #local lbSO = select(abs(Op - 1), -1, -1, 1);\n"
        "  #if (K > %d)\n",
        KMAX);
    displacement_many(steps);
    w("  #else\n");
    /* per-slot constants: unused slots get r = 1, p = 2, m = 1 and d = 1e30 (never active) */
    w("  #local lbR = array[%d]; #local lbP = array[%d]; #local lbM = array[%d];\n", KMAX, KMAX,
      KMAX);
    w("  #for (I, 0, %d) #if (I < K) #local lbR[I] = R[I]; #local lbP[I] = P[I]; #local lbM[I] = "
      "M[I]; #else #local lbR[I] = 1; #local lbP[I] = 2; #local lbM[I] = 1; #end #end\n",
      KMAX - 1);
    w("  #local lbAll2 = true; #for (I, 0, K - 1) #if (lbP[I] != 2) #local lbAll2 = false; #end "
      "#end\n");
    /* the Newton step T / T' */
    w("  #local lbS = function(lbh, ");
    dlist();
    /* only the K terms in use are compiled (#if at parse time), and p = 2
     * is written as products: the step is T / T' */
    w(") {\n    (-1");
    for (int i = 0; i < KMAX; ++i)
        w("\n    #if (K > %d) #if (lbP[%d] = 2) + max(0, (lbR[%d] - lbd%d + lbM[%d] * lbh) / "
          "lbR[%d]) "
          "* max(0, (lbR[%d] - lbd%d + lbM[%d] * lbh) / lbR[%d]) #else + pow(max(0, (lbR[%d] - "
          "lbd%d + lbM[%d] * lbh) / lbR[%d]), lbP[%d]) #end #end",
          i, i, i, i, i, i, i, i, i, i, i, i, i, i, i);
    w(")\n    / (0");
    for (int i = 0; i < KMAX; ++i)
        w("\n    #if (K > %d) #if (lbP[%d] = 2) + (2 * lbM[%d] / lbR[%d]) * max(0, (lbR[%d] - "
          "lbd%d "
          "+ lbM[%d] * lbh) / lbR[%d]) #else + (lbP[%d] * lbM[%d] / lbR[%d]) * ((lbR[%d] - lbd%d + "
          "lbM[%d] * lbh) / lbR[%d] > 0) * pow(max(0, (lbR[%d] - lbd%d + lbM[%d] * lbh) / "
          "lbR[%d]), lbP[%d] - 1) #end #end",
          i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i, i);
    w(") }\n");
    /* E_n(h, step at h): leave, or take the step and continue with the step
     * at the new point (two calls per Newton step); E_steps returns h */
    w("  #local lbE%d = function(lbh, lbs, lbl, ", steps);
    dlist();
    w(") { lbh }\n");
    for (int n = steps - 1; n >= 0; --n) {
        w("  #local lbE%d = function(lbh, lbs, lbl, ", n);
        dlist();
        w(") { select(abs(lbs) - %.17g * (1 + abs(lbh)), lbh - lbs, lbh - lbs, "
          "lbE%d(max(lbl, lbh - lbs), lbS(max(lbl, lbh - lbs), ",
          TOL, n + 1);
        dlist();
        w("), lbl, ");
        dlist();
        w(")) }\n");
    }
    w("  #local lbB2 = function(lbh, lbl, ");
    dlist();
    w(") { lbE0(lbh, lbS(lbh, ");
    dlist();
    w("), lbl, ");
    dlist();
    w(") }\n");
    w("  #if (lbAll2)\n");
    displacement_p2();
    w("  #else\n");
    w("  #local lbB = function(");
    dlist();
    w(") { lbB2(");
    bracket_args();
    w(", ");
    dlist();
    w(") }\n  #end\n");
    w("  function(x, y, z) { lbSG * lbB(");
    for (int i = 0; i < KMAX; ++i) {
        if (i == 0)
            w("lbSG * F[0](x, y, z)");
        else
            w(" #if (K > %d), lbSO * F[%d](x, y, z) #end", i, i);
    }
    w(") }\n  #end\n#end\n\n");
}

/* Local blending [bernhardt2010; docs/local-blending.md]: the clean unions,
 * Barthe's UB and the interpolation as scalar functions, mirroring
 * operators/local.c formula for formula (soft convention, iso value C);
 * the node macros and the blending-volume distance helpers the exporter
 * calls. */
static void local_blend(void) {
    w("// ---- local blending (soft convention, iso value C; docs/local-blending.md) ----\n\n");
    w("// Rvachev's UR(x, y) = x + y + sqrt(x^2 + y^2)\n"
      "#declare lb_clean_ur = function(lbLx, lbLy) { lbLx + lbLy + sqrt(lbLx * lbLx + lbLy * lbLy) "
      "}\n");
    w("// UC2 = C + UR(f1 - C, f2 - C) / (2 - sqrt 2): C on the union surface\n"
      "#declare lb_clean_uc2 = function(lbLf1, lbLf2, lbLC) { lbLC + lb_clean_ur(lbLf1 - lbLC, "
      "lbLf2 - lbLC) / %.17g }\n",
      2.0 - sqrt(2.0));
    w("// the weight delta_c of u = f1 - a1 f2, v = f2 - a2 f1: 0 unless both > %.17g\n"
      "#declare lb_clean_w2 = function(lbLu, lbLv) { select(min(lbLu, lbLv) - %.17g, 0, 0, "
      "pow(4 * (lbLu / (lbLu + lbLv)) * (lbLv / (lbLu + lbLv)), 4)) }\n"
      "#declare lb_clean_w = function(lbLf1, lbLf2, lbLa1, lbLa2) { lb_clean_w2(lbLf1 - lbLa1 * "
      "lbLf2, lbLf2 - lbLa2 * lbLf1) }\n",
      LB_SOFT_MIN_FIELD, LB_SOFT_MIN_FIELD);
    w("// UC3 = max + w (UC2 - max)\n"
      "#declare lb_clean_uc3 = function(lbLf1, lbLf2, lbLC, lbLa1, lbLa2) { max(lbLf1, lbLf2) + "
      "lb_clean_w(lbLf1, lbLf2, lbLa1, lbLa2) * (lb_clean_uc2(lbLf1, lbLf2, lbLC) - max(lbLf1, "
      "lbLf2)) }\n");
    w("// UC's V: UC2 outside both, C + |(f1 - C, f2 - C)| inside both, max elsewhere\n"
      "#declare lb_clean_v = function(lbLf1, lbLf2, lbLC) { select(max(lbLf1, lbLf2) - lbLC, "
      "lb_clean_uc2(lbLf1, lbLf2, lbLC), select(min(lbLf1, lbLf2) - lbLC, max(lbLf1, lbLf2), "
      "lbLC + sqrt(pow(lbLf1 - lbLC, 2) + pow(lbLf2 - lbLC, 2)))) }\n"
      "// the final clean union UC = max + w (V - max): exact union surface, no inner contraction\n"
      "#declare lb_clean_uc = function(lbLf1, lbLf2, lbLC, lbLa1, lbLa2) { max(lbLf1, lbLf2) + "
      "lb_clean_w(lbLf1, lbLf2, lbLa1, lbLa2) * (lb_clean_v(lbLf1, lbLf2, lbLC) - max(lbLf1, "
      "lbLf2)) }\n\n");
    w("// Barthe's UB(x, y; p, q): max outside the wedge q x < y, p y < x, else the\n"
      "// rationalised root D / (B + sqrt(B^2 - A D)) of the level's quarter ellipse\n"
      "#declare lb_barthe_r = function(lbLA, lbLB, lbLD) { lbLD / (lbLB + sqrt(max(0, lbLB * lbLB "
      "- lbLA * lbLD))) }\n"
      "#declare lb_barthe_in = function(lbLx, lbLy, lbLp, lbLq) { lb_barthe_r(pow(1 - lbLq, 2) * "
      "lbLp * lbLp + pow(1 - lbLp, 2) * lbLq * lbLq - pow(1 - lbLp, 2) * pow(1 - lbLq, 2), "
      "pow(1 - lbLq, 2) * lbLp * lbLx + pow(1 - lbLp, 2) * lbLq * lbLy, pow(1 - lbLq, 2) * lbLx * "
      "lbLx + pow(1 - lbLp, 2) * lbLy * lbLy) }\n"
      "#declare lb_barthe = function(lbLx, lbLy, lbLp, lbLq) { select(min(lbLy - lbLq * lbLx, "
      "lbLx - lbLp * lbLy), max(lbLx, lbLy), max(lbLx, lbLy), lb_barthe_in(lbLx, lbLy, lbLp, "
      "lbLq)) }\n\n");
    w("// U = (1 - beta) UC + beta UB, beta = v^n (0 <= v <= 1, n >= 1)\n"
      "#declare lb_local_mixb = function(lbLuc, lbLub, lbLb) { lbLuc + lbLb * (lbLub - lbLuc) }\n"
      "#declare lb_local_mix = function(lbLuc, lbLub, lbLv, lbLn) { lb_local_mixb(lbLuc, lbLub, "
      "pow(max(0, lbLv), lbLn)) }\n"
      "// the blending volume's field: Wyvill's kernel of a = distance / R (0 for a >= 1)\n"
      "#declare lb_local_kernel = function(lbLa) { select(lbLa - 1, 1 + lbLa * lbLa * (-4 / 9 * "
      "pow(lbLa, 4) + 17 / 9 * lbLa * lbLa - 22 / 9), 0) }\n"
      "// one component's blend at a = distance / R: UC where a >= 1\n"
      "#declare lb_local_at = function(lbLg1, lbLg2, lbLa, lbLp, lbLq, lbLn, lbLuc) { "
      "select(lbLa - 1, lb_local_mix(lbLuc, lb_barthe(lbLg1, lbLg2, lbLp, lbLq), "
      "lb_local_kernel(lbLa), lbLn), lbLuc) }\n\n");
    w("// blending-volume distances (the exporter writes each curve's hierarchy of\n"
      "// boxes and segments with these): squared distance to a box, to a segment\n"
      "// from A along D (IL = 1 / |D|^2, 0 for a point)\n"
      "#declare lb_box2 = function(lbLx, lbLy, lbLz, lbLlx, lbLly, lbLlz, lbLhx, lbLhy, lbLhz) { "
      "pow(max(lbLlx - lbLx, 0, lbLx - lbLhx), 2) + pow(max(lbLly - lbLy, 0, lbLy - lbLhy), 2) + "
      "pow(max(lbLlz - lbLz, 0, lbLz - lbLhz), 2) }\n"
      "#declare lb_seg2t = function(lbLx, lbLy, lbLz, lbLdx, lbLdy, lbLdz, lbLt) { pow(lbLx - lbLt "
      "* lbLdx, 2) + pow(lbLy - lbLt * lbLdy, 2) + pow(lbLz - lbLt * lbLdz, 2) }\n"
      "#declare lb_seg2r = function(lbLx, lbLy, lbLz, lbLdx, lbLdy, lbLdz, lbLil) { "
      "lb_seg2t(lbLx, lbLy, lbLz, lbLdx, lbLdy, lbLdz, min(1, max(0, (lbLx * lbLdx + lbLy * lbLdy "
      "+ lbLz * lbLdz) * lbLil))) }\n"
      "#declare lb_seg2 = function(lbLx, lbLy, lbLz, lbLax, lbLay, lbLaz, lbLdx, lbLdy, lbLdz, "
      "lbLil) { lb_seg2r(lbLx - lbLax, lbLy - lbLay, lbLz - lbLaz, lbLdx, lbLdy, lbLdz, lbLil) "
      "}\n\n");
    w("// A clean union of two soft fields (iso 0.5) as a function(x, y, z); A1, A2 the\n"
      "// convolution weights (0 for finite support)\n"
      "#macro LB_CleanUnion(F1, F2, A1, A2)\n"
      "  function(x, y, z) { max(0, lb_clean_uc(F1(x, y, z), F2(x, y, z), 0.5, A1, A2)) }\n#end\n"
      "// the same for zero-convention fields, mapped to g = 0.5 (1 - f / S) and back\n"
      "#macro LB_CleanUnionZero(F1, F2, A1, A2, S)\n"
      "  function(x, y, z) { S * (1 - lb_clean_uc(0.5 * (1 - F1(x, y, z) / S), 0.5 * (1 - F2(x, "
      "y, z) / S), 0.5, A1, A2) / 0.5) }\n#end\n\n");
}

int main(int argc, char **argv) {
    if (argc != 2 || argv[1][0] == '-') {
        /* an option is never a file name: "povgen --help" once wrote the
         * include to a file called --help */
        fprintf(stderr, "usage: povgen OUT.inc (writes libblend.inc there)\n");
        return argc == 2 && strcmp(argv[1], "--help") == 0 ? 0 : 2;
    }
    const int steps = choose_steps();
    const int ssteps = choose_soft_steps();
    const int csteps = choose_sconic_steps();
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", argv[1]);
    out = fopen(tmp, "w");
    if (!out) {
        perror(tmp);
        return 1;
    }
    header();
    primitives();
    primitives2();
    classic();
    displacement(steps);
    conic();
    scale(steps);
    bounded(steps);
    soft_hyper(ssteps);
    soft_conic(csteps);
    bulge(steps);
    local_blend();
    w("#version LB_INC_TEMP;\n#end\n");
    if (fclose(out) != 0 || rename(tmp, argv[1]) != 0) {
        perror(argv[1]);
        remove(tmp);
        return 1;
    }
    return 0;
}
