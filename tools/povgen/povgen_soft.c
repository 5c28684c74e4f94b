/* povgen: the soft-convention operators as SDL macros (the
 * super-ellipsoidal and conic soft blends, bracketed Newton in
 * lambda = ln h). */
#define _POSIX_C_SOURCE 200809L
#include "povgen.h"

#include <math.h>
#include <string.h>

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

void soft_hyper(int steps) {
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
void soft_conic(int steps) {
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
