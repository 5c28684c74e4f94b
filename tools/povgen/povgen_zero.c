/* povgen: the primitives and the zero-convention operators as SDL macros
 * (displacement, conic, scale, bounded, bulge elimination, the classic
 * ones, local blends). */
#define _POSIX_C_SOURCE 200809L
#include "povgen.h"

#include <math.h>
#include <string.h>

void primitives(void) {
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
void primitives2(void) {
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

void classic(void) {
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
void conic(void) {
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
void scale(int steps) {
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
void bounded(int steps) {
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

/* LB_BulgeCore / LB_Bulge: bulge elimination for binary blends, mirroring
 * lb_bulge (ranges R_i = r_i (1 - cos theta + omega), optionally slopes
 * M_i(cos theta, |g1|/|g2|)). */
void bulge(int steps) {
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
void displacement(int steps) {
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
void local_blend(void) {
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
