/*
 * libblend — operators.h: scalar blend operators with analytic gradients.
 *
 * Naming and invariants (hg_sdf style, stated once for every family):
 *  - One entry point per family: lb_<family>(op, k, x, <per-argument
 *    parameters>, value, grad, err). `op` selects union, intersection or
 *    difference; the difference subtracts x[1..k-1] from x[0].
 *  - x[0..k-1] are the values of the blended fields at one point. Per-argument
 *    parameter arrays have length k: r (blending range, > 0; accepted in
 *    [LB_MIN_RANGE, LB_MAX_RANGE]), p (curvature exponent, > 1 so the result
 *    is C1; at most LB_MAX_EXPONENT), m (subsequent-blend parameter, > 0;
 *    accepted in [LB_MIN_SLOPE, LB_MAX_SLOPE];
 *    m = 1 everywhere reproduces the older operator exactly). m may be NULL,
 *    meaning m_i = 1.
 *  - `value` receives the blend; `grad` (may be NULL) receives the k partial
 *    derivatives d value / d x_i. The spatial gradient is the chain rule
 *    sum_i grad[i] * grad f_i(X).
 *  - Root-solved operators use one safeguarded solver (Newton inside a bracket,
 *    bisection fallback): the result never leaves the bracket stated in
 *    docs/operators.md, and gradients come from the implicit function
 *    theorem, so they are exact to rounding.
 *  - For every finite input (|x_i| <= LB_MAX_ABS_ARG) and valid parameters the
 *    value and the gradient are finite. Non-finite or larger inputs give
 *    LB_ERR_NOT_FINITE; invalid parameters
 *    give LB_ERR_INVALID_ARGUMENT naming the parameter and its allowed range.
 *  - Conventions: `zero` families (displacement, conic, scale, bounded,
 *    R-functions) have f < 0 inside and f = 0 on the surface; `soft` families
 *    (soft_hyper, soft_conic, scale_ba/bs, sum, Ricci, Perlin) have f > 0.5
 *    inside and f = 0.5 on the surface.
 */
#ifndef LIBBLEND_OPERATORS_H
#define LIBBLEND_OPERATORS_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest number of arguments one operator call takes: LB_MAX_ARITY, and
 * LB_MAX_ARITY_WIDE for the k-ary unions scenes use with thousands of
 * primitives: lb_displacement, and lb_classic's LB_MIN, LB_MAX,
 * LB_SOFT_SUM and LB_RICCI_UNION (the same in scenes: docs/scene-format.md). */
#define LB_MAX_ARITY 256
#define LB_MAX_ARITY_WIDE 65535
/* Largest curvature exponent p accepted. */
#define LB_MAX_EXPONENT 1000.0
/* Largest |argument| accepted (field values, bounding values, gradients):
 * far beyond any real field, and small enough that no intermediate product
 * of the operators can overflow. Larger values give LB_ERR_NOT_FINITE. */
#define LB_MAX_ABS_ARG 1e100
/* Accepted blending ranges r and subsequent-blend parameters m (zero
 * families): wide enough for any scene, bounded so that no intermediate
 * quantity of an operator can overflow. The soft families take field values
 * in [0, 1] and m in [LB_SOFT_MIN_SLOPE, LB_SOFT_MAX_SLOPE] (their value grows
 * like x^(1/m); the papers use m from 0.3 to 1.5). */
#define LB_MIN_RANGE 1e-9
#define LB_MAX_RANGE 1e9
#define LB_MIN_SLOPE 1e-6
#define LB_MAX_SLOPE 1e6
#define LB_SOFT_MIN_SLOPE 0.05
#define LB_SOFT_MIN_FIELD 1e-300 /* soft values below this count as 0 */
/* Largest soft argument accepted: soft fields start in [0, 1], but a soft
 * union (B_Sk, soft_sum, Ricci) can exceed 1 and feed a subsequent blend. */
#define LB_SOFT_MAX_FIELD 1e6
#define LB_SOFT_MAX_SLOPE 20.0

typedef enum lb_setop {
    LB_UNION = 0,
    LB_INTERSECTION = 1,
    LB_DIFFERENCE = 2 /* x[0] minus x[1..k-1] */
} lb_setop;

/* ---- Displacement family BT_k (zero convention) [hsu2006 3.1-3.4] --------
 * Union: h with sum_i [(r_i - x_i + m_i h)/r_i]+^p_i = 1; equals
 * min_i x_i/m_i away from the blending region; the zero set does not depend
 * on m. m = 1 is Rockwood's displacement union. Intersection is
 * -union(-x), difference -union(-x_0, x_1, ..., x_{k-1}).
 * Fast paths: all p_i = 2 is solved in closed form per active set; integer
 * p_i use products instead of pow().
 * Parameters: 1 <= k <= LB_MAX_ARITY_WIDE (beyond LB_MAX_ARITY the call
 * allocates 56 bytes of scratch per argument); r_i > 0; 1 < p_i <= LB_MAX_EXPONENT;
 * m_i > 0 (m may be NULL). */
LB_API lb_status lb_displacement(lb_setop op, size_t k, const double *x, const double *r,
                                 const double *p, const double *m, double *value, double *grad,
                                 lb_error *err);

/* ---- Binary conic BT_2 (zero convention) [hsu2006 3.2.1, Eq. 4] ----------
 * Closed form. x, r, m have 2 entries (m may be NULL); p is the conic's shape
 * parameter, -inf < p < r1 r2 (p = 0 is the quarter ellipse, identical to
 * lb_displacement with p_1 = p_2 = 2). */
LB_API lb_status lb_conic(lb_setop op, const double x[2], const double r[2], double p,
                          const double m[2], double *value, double grad[2], lb_error *err);

/* ---- Scale method (Hsu-Lee) [hsu-bounded 2.4.2; hsu-nonuniform 2.3] -------
 * lb_scale_ba: soft-domain Min-like B_A(y) (r_i > 0); equals min(y) when
 * min(y) <= 0. lb_scale_bs: Max-like B_S(y) (0 < r_i <= 1); equals max(y)
 * when max(y) <= 0; all r_i = 1 is Ricci's (sum y_i^p)^(1/p).
 * lb_scale: zero-convention set operations B_U, B_I, B_D built from them
 * (docs/operators.md section 5). Parameters: 1 < p_i <= LB_MAX_EXPONENT;
 * lb_scale_ba: r_i > 0; lb_scale_bs: 0 < r_i <= 1; lb_scale: 0 < r_i <= 1 for
 * intersection and difference (they use B_S), any r_i > 0 for the union
 * (where a union argument is <= -1, outside the ray-linear range f >= -1, its
 * dual branch B_S uses min(r_i, 1)).
 * The scale method shares the displacement kernel (B_A and B_S are BT_k in
 * 1/h), so it has the same p = 2 closed form and integer-p fast paths. */
LB_API lb_status lb_scale_ba(size_t k, const double *y, const double *r, const double *p,
                             double *value, double *grad, lb_error *err);
LB_API lb_status lb_scale_bs(size_t k, const double *y, const double *r, const double *p,
                             double *value, double *grad, lb_error *err);
LB_API lb_status lb_scale(lb_setop op, size_t k, const double *x, const double *r, const double *p,
                          double *value, double *grad, lb_error *err);

/* ---- Bounded primitives [hsu-bounded 3] ------------------------------------
 * Scale-method set operations whose ranges are position functions built from
 * a bounding solid per argument: c[i] is the value of the bounding solid of
 * argument i at the point (same kind of ray-linear function as x[i]).
 * union: R_i = (x_i + 1)/(c_i + 1) - 1; intersection: R_i = 1 - (x_i + 1)/(c_i + 1);
 * difference: R_0 as for intersection, the others as for union. Where
 * c_i <= -1, or R_i would fall below omega (a bounding solid that does not
 * contain its primitive there), R_i = omega = LB_BOUNDED_OMEGA. Outside its
 * bounding solid an argument does not blend: the union's blending region of
 * f_i is exactly {f_i >= 0, f_ci <= 0}. grad_x and grad_c (each may be NULL)
 * receive d value / d x_i and d value / d c_i. Parameters: 1 < p_i <= LB_MAX_EXPONENT. */
#define LB_BOUNDED_OMEGA 1e-3
LB_API lb_status lb_bounded(lb_setop op, size_t k, const double *x, const double *c,
                            const double *p, double *value, double *grad_x, double *grad_c,
                            lb_error *err);

/* ---- Bulge elimination [hsu2006 5; hsu-bounded 2.5] ------------------------
 * Binary blends whose ranges (and, for the displacement family, m) depend on
 * the angle theta between the argument gradients g1, g2:
 *   R_i = r_i (1 - cos theta + omega)                 (LB_BULGE_RANGE)
 *   M_i as in docs/operators.md section 4      (LB_BULGE_SLOPE; not for
 *                                                      the scale family)
 * Gradients: dx[2] = d value / d x_i, dg1[3], dg2[3] = d value / d g1, g2
 * (each may be NULL); M_i is kept within [LB_MIN_SLOPE, LB_MAX_SLOPE] (it
 * leaves that only for gradient magnitudes 1e6 apart). The spatial gradient is dx[0] g1 + dx[1] g2
 * + H1 dg1 + H2 dg2 with H_i the Hessians of the arguments. Where a gradient
 * is zero, cos theta is taken as 0 and M_i = m_i. For intersection and difference the
 * angle is measured between the gradients of the arguments as they enter the
 * dual union (the subtracted argument's gradient is negated). A gradient
 * shorter than LB_BULGE_MIN_GRAD counts as zero; components beyond
 * LB_BULGE_MAX_GRAD are rejected (d cos(theta)/d g ~ 1/|g| and the slope ratio
 * |g1|/|g2| must stay representable). */
#define LB_BULGE_MIN_GRAD 1e-30
#define LB_BULGE_MAX_GRAD 1e30 /* larger gradient components are rejected */
typedef enum lb_bulge_family {
    LB_BULGE_DISPLACEMENT = 0, /* lb_displacement with k = 2 */
    LB_BULGE_CONIC = 1,        /* lb_conic */
    LB_BULGE_SCALE = 2         /* lb_scale with k = 2 */
} lb_bulge_family;

enum { LB_BULGE_RANGE = 1u, LB_BULGE_SLOPE = 2u };

typedef struct lb_bulge_params {
    double r[2];    /* base ranges r_i > 0 (<= 1 for the scale family) */
    double p[2];    /* curvature exponents (displacement, scale) */
    double conic_p; /* conic shape parameter (conic family), < R_1 R_2 everywhere */
    double m[2];    /* base m_i > 0 (displacement, conic) */
    double omega;   /* >= 0, range floor; 0.001 in the papers */
    unsigned flags; /* LB_BULGE_RANGE | LB_BULGE_SLOPE */
} lb_bulge_params;

LB_API lb_status lb_bulge(lb_bulge_family family, lb_setop op, const lb_bulge_params *params,
                          const double x[2], const double g1[3], const double g2[3], double *value,
                          double dx[2], double dg1[3], double dg2[3], lb_error *err);

/* ---- Non-uniform scaling for soft objects [hsu-nonuniform 3-4] -------------
 * s_i(h) = 0.5^(1 - m_i) h^m_i. lb_soft_hyper: super-ellipsoidal k-ary union
 * B_Sk (Max-like, 0 < r_i <= 1), intersection B_Ak (Min-like, r_i > 0) and
 * difference B_Ak(x_0, 1 - x_1, ...) (r_0 > 0, the others as intersection).
 * The 0.5 surface does not depend on m. Away from the blending region the
 * result is Max/Min of 0.5 (x_i / 0.5)^(1/m_i).
 * lb_soft_conic: the binary variants with the conic of lb_conic as base curve
 * (p < r1 r2), solved numerically. */
LB_API lb_status lb_soft_hyper(lb_setop op, size_t k, const double *x, const double *r,
                               const double *p, const double *m, double *value, double *grad,
                               lb_error *err);
LB_API lb_status lb_soft_conic(lb_setop op, const double x[2], const double r[2], double p,
                               const double m[2], double *value, double grad[2], lb_error *err);

/* ---- Classic operators (baselines) ----------------------------------------
 * zero: LB_MIN (union), LB_MAX (intersection), R-functions (binary, k = 2):
 * union f1 + f2 - sqrt(f1^2 + f2^2), intersection f1 + f2 + sqrt(f1^2 + f2^2).
 * soft: LB_SOFT_SUM (Wyvill sum), LB_RICCI_UNION (sum x_i^n)^(1/n) with
 * param = n >= 1 on x_i >= 0 (negative x_i count as 0), Perlin union
 * 1 - prod(1 - x_i), intersection prod x_i, difference x_0 prod_{i>0}(1 - x_i).
 * At ties, min/max differentiate with respect to the first extreme argument;
 * the R-functions' gradient at (0, 0) is taken as (1/2, 1/2) times the limit
 * along the diagonal, i.e. (1 - 1/sqrt 2) for union. k: 2 for the
 * R-functions; up to LB_MAX_ARITY_WIDE for min, max, the sum and Ricci's
 * union; up to LB_MAX_ARITY for Perlin's operators. */
typedef enum lb_classic_kind {
    LB_MIN = 0,
    LB_MAX = 1,
    LB_RFUNC_UNION = 2,
    LB_RFUNC_INTERSECTION = 3,
    LB_SOFT_SUM = 4,
    LB_RICCI_UNION = 5,
    LB_PERLIN_UNION = 6,
    LB_PERLIN_INTERSECTION = 7,
    LB_PERLIN_DIFFERENCE = 8
} lb_classic_kind;

LB_API lb_status lb_classic(lb_classic_kind kind, size_t k, const double *x, double param,
                            double *value, double *grad, lb_error *err);

/* ---- Local blending's operators [bernhardt2010 §3] ------------------------
 * Soft convention with iso value C > 0 (0.5 for fields in [0, 1]): f > C
 * inside, the unions are Max-like. These are the pieces of the local blend
 * (two objects blend only inside a volume around their intersection
 * curves): a clean union UC outside it, Barthe's smooth blend UB inside, and
 * their interpolation.
 *  - LB_CLEAN_UR:  UR(f1, f2) = f1 + f2 + sqrt(f1^2 + f2^2) (Rvachev; C unused).
 *  - LB_CLEAN_UC2: C + UR(f1 - C, f2 - C) / (2 - sqrt 2): exactly C on the
 *    union surface max(f1, f2) = C, 0 at (0, 0).
 *  - LB_CLEAN_UC3: max + w (UC2 - max), w the weight below.
 *  - LB_CLEAN_UC:  max + w (V - max) with V = UC2 outside both objects,
 *    C + sqrt((f1 - C)^2 + (f2 - C)^2) inside both, max elsewhere: no
 *    contraction inside (UC(f, C) = f for f >= C).
 * The weight w is 0 where u = f1 - alpha1 f2 <= 0 or v = f2 - alpha2 f1 <= 0,
 * else (4 u v / (u + v)^2)^4; alpha (may be NULL: 0, 0, finite support, so
 * UC = f1 where f2 = 0) takes each alpha_i in [0, 1) for fields of infinite
 * support (convolution surfaces). UC and UC3 equal max(f1, f2) exactly on
 * the union surface and wherever w = 0, and are C1 away from the union
 * surface. */
typedef enum lb_clean_kind {
    LB_CLEAN_UR = 0,
    LB_CLEAN_UC2 = 1,
    LB_CLEAN_UC3 = 2,
    LB_CLEAN_UC = 3
} lb_clean_kind;

/* Smallest iso value C accepted by the clean unions. */
#define LB_SOFT_MIN_ISO 1e-100

LB_API lb_status lb_clean_union(lb_clean_kind kind, const double f[2], double C,
                                const double alpha[2], double *value, double grad[2],
                                lb_error *err);

/* Largest p, q accepted by Barthe's blend (the formula needs p, q < 1). */
#define LB_BARTHE_MAX_PQ 0.999

/* Barthe's smooth union UB(x, y) with 0 <= p, q <= LB_BARTHE_MAX_PQ: max(x, y)
 * where y <= q x or x <= p y; between those lines the level u is the quarter
 * ellipse ((x - p u)/(1 - p))^2 + ((y - q u)/(1 - q))^2 = u^2, tangent to
 * x = u and y = u, evaluated in the rationalised closed form
 * UB = D / (B + sqrt(B^2 - A D)). With q = v1 / C and p = v2 / C the blend
 * leaves f1 = C where f2 = v1 and f2 = C where f1 = v2. Homogeneous of
 * degree 1. grad (may be NULL) receives dUB/dx, dUB/dy. */
LB_API lb_status lb_barthe_blend(const double x[2], double p, double q, double *value,
                                 double grad[2], lb_error *err);

/* The local blend's interpolation U = (1 - beta) uc + beta ub, beta = v^n,
 * v in [0, 1] the blending volume's field, n in [1, 1000]: U = uc exactly
 * where v = 0 and ub exactly where v = 1. grad (may be NULL) receives
 * dU/duc, dU/dub, dU/dv. */
LB_API lb_status lb_local_mix(double uc, double ub, double v, double n, double *value,
                              double grad[3], lb_error *err);

#ifdef __cplusplus
}
#endif

#endif
