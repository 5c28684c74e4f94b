/* Every invalid parameter is rejected with a message that names it and the
 * allowed range; nothing is clamped. Table-driven: each row is one call. */
#include "testlib.h"

typedef struct {
    const char *what;
    lb_status (*call)(lb_error *err);
    lb_status status;
    const char *needle; /* must appear in the message */
} row_t;

static const double X2[2] = {0.1, 0.2}, R2[2] = {0.5, 0.5}, P2[2] = {2, 2}, M2[2] = {1, 1};
static double out;

/* one invalid call as a function of its error record */
#define CALL(name, ...)                                                                            \
    static lb_status name(lb_error *err) {                                                         \
        __VA_ARGS__                                                                                \
    }
CALL(k0, return lb_displacement(LB_UNION, 0, X2, R2, P2, M2, &out, NULL, err);)
CALL(kbig, static double big[LB_MAX_ARITY_WIDE + 1];
     return lb_displacement(LB_UNION, LB_MAX_ARITY_WIDE + 1, big, big, big, big, &out, NULL, err);)
CALL(kscale, static double big[LB_MAX_ARITY + 1];
     return lb_scale(LB_UNION, LB_MAX_ARITY + 1, big, big, big, &out, NULL, err);)
CALL(kperlin, static double big[LB_MAX_ARITY + 1];
     return lb_classic(LB_PERLIN_UNION, LB_MAX_ARITY + 1, big, 0.0, &out, NULL, err);)
CALL(kmin, static double big[LB_MAX_ARITY_WIDE + 1];
     return lb_classic(LB_MIN, LB_MAX_ARITY_WIDE + 1, big, 0.0, &out, NULL, err);)
CALL(rneg, const double r[2] = {0.5, -1};
     return lb_displacement(LB_UNION, 2, X2, r, P2, M2, &out, NULL, err);)
CALL(rzero, const double r[2] = {0, 1};
     return lb_displacement(LB_UNION, 2, X2, r, P2, M2, &out, NULL, err);)
CALL(pone, const double p[2] = {2, 1};
     return lb_displacement(LB_UNION, 2, X2, R2, p, M2, &out, NULL, err);)
CALL(pbig, const double p[2] = {2, 2000};
     return lb_displacement(LB_UNION, 2, X2, R2, p, M2, &out, NULL, err);)
CALL(mzero, const double m[2] = {1, 0};
     return lb_displacement(LB_UNION, 2, X2, R2, P2, m, &out, NULL, err);)
CALL(xnan, const double x[2] = {0, NAN};
     return lb_displacement(LB_UNION, 2, x, R2, P2, M2, &out, NULL, err);)
CALL(xhuge, const double x[2] = {0, 1e101};
     return lb_displacement(LB_UNION, 2, x, R2, P2, M2, &out, NULL, err);)
CALL(xinf, const double x[2] = {INFINITY, 0};
     return lb_displacement(LB_UNION, 2, x, R2, P2, M2, &out, NULL, err);)
CALL(rnan, const double r[2] = {NAN, 1};
     return lb_displacement(LB_UNION, 2, X2, r, P2, M2, &out, NULL, err);)
CALL(badop, return lb_displacement((lb_setop)7, 2, X2, R2, P2, M2, &out, NULL, err);)
CALL(nullx, return lb_displacement(LB_UNION, 2, NULL, R2, P2, M2, &out, NULL, err);)
CALL(nullout, return lb_displacement(LB_UNION, 2, X2, R2, P2, M2, NULL, NULL, err);)
CALL(conicp, return lb_conic(LB_UNION, X2, R2, 0.25, M2, &out, NULL, err);)
CALL(conicr, const double r[2] = {-1, 1};
     return lb_conic(LB_UNION, X2, r, 0.0, M2, &out, NULL, err);)
CALL(conicm, const double m[2] = {-1, 1};
     return lb_conic(LB_UNION, X2, R2, 0.0, m, &out, NULL, err);)
CALL(bsr, const double r[2] = {0.5, 1.5}; return lb_scale_bs(2, X2, r, P2, &out, NULL, err);)
CALL(scaleir, const double r[2] = {0.5, 1.5};
     return lb_scale(LB_INTERSECTION, 2, X2, r, P2, &out, NULL, err);)
CALL(scalep, const double p[2] = {0.5, 2};
     return lb_scale(LB_UNION, 2, X2, R2, p, &out, NULL, err);)
CALL(boundp, const double p[2] = {1, 2};
     return lb_bounded(LB_UNION, 2, X2, X2, p, &out, NULL, NULL, err);)
CALL(boundc, const double c[2] = {NAN, 2};
     return lb_bounded(LB_UNION, 2, X2, c, P2, &out, NULL, NULL, err);)
CALL(softur, const double r[2] = {0.5, 2};
     return lb_soft_hyper(LB_UNION, 2, X2, r, P2, M2, &out, NULL, err);)
CALL(softm, const double m[2] = {0.5, -2};
     return lb_soft_hyper(LB_INTERSECTION, 2, X2, R2, P2, m, &out, NULL, err);)
CALL(softconicr, const double r[2] = {0.5, 2};
     return lb_soft_conic(LB_UNION, X2, r, 0.0, M2, &out, NULL, err);)
CALL(softconicp, return lb_soft_conic(LB_INTERSECTION, X2, R2, 1.0, M2, &out, NULL, err);)
CALL(softx, const double x[2] = {0.5, -0.5};
     return lb_soft_hyper(LB_UNION, 2, x, R2, P2, M2, &out, NULL, err);)
CALL(softmsmall, const double m[2] = {1, 1e-4};
     return lb_soft_hyper(LB_INTERSECTION, 2, X2, R2, P2, m, &out, NULL, err);)
CALL(rtiny, const double r[2] = {1e-10, 1};
     return lb_displacement(LB_UNION, 2, X2, r, P2, M2, &out, NULL, err);)
CALL(ricci, return lb_classic(LB_RICCI_UNION, 2, X2, 0.5, &out, NULL, err);)
CALL(rfk, return lb_classic(LB_RFUNC_UNION, 3, X2, 0, &out, NULL, err);)
CALL(classkind, return lb_classic((lb_classic_kind)42, 2, X2, 0, &out, NULL, err);)
static const double G1[3] = {1, 0, 0}, G2[3] = {0, 1, 0};
CALL(bulgenull, return lb_bulge(LB_BULGE_DISPLACEMENT, LB_UNION, NULL, X2, G1, G2, &out, NULL, NULL,
                                NULL, err);)
CALL(bulgeomega, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.0, LB_BULGE_RANGE};
     return lb_bulge(LB_BULGE_DISPLACEMENT, LB_UNION, &bp, X2, G1, G2, &out, NULL, NULL, NULL,
                     err);)
CALL(bulgeflags, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.001, 8};
     return lb_bulge(LB_BULGE_DISPLACEMENT, LB_UNION, &bp, X2, G1, G2, &out, NULL, NULL, NULL,
                     err);)
CALL(bulgeslope, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.001, LB_BULGE_SLOPE};
     return lb_bulge(LB_BULGE_SCALE, LB_UNION, &bp, X2, G1, G2, &out, NULL, NULL, NULL, err);)
CALL(bulgescaler, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.001, LB_BULGE_RANGE};
     return lb_bulge(LB_BULGE_SCALE, LB_INTERSECTION, &bp, X2, G1, G2, &out, NULL, NULL, NULL,
                     err);)
CALL(bulgeconicp, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0.1, {1, 1}, 0.01, LB_BULGE_RANGE};
     return lb_bulge(LB_BULGE_CONIC, LB_UNION, &bp, X2, G1, G2, &out, NULL, NULL, NULL, err);)
CALL(bulgefam, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.001, 0};
     return lb_bulge((lb_bulge_family)9, LB_UNION, &bp, X2, G1, G2, &out, NULL, NULL, NULL, err);)
CALL(bulgeg, lb_bulge_params bp = {{0.5, 0.5}, {2, 2}, 0, {1, 1}, 0.001, 0};
     const double g[3] = {0, NAN, 0};
     return lb_bulge(LB_BULGE_DISPLACEMENT, LB_UNION, &bp, X2, g, G2, &out, NULL, NULL, NULL, err);)
static lb_primitive prim;
static const double C0[3] = {0, 0, 0};
CALL(sphr, return lb_primitive_sphere(&prim, C0, -1, err);)
CALL(ellipa, const double a[3] = {1, 0, 1}; return lb_primitive_ellipsoid(&prim, C0, a, err);)
CALL(lpn, const double a[3] = {1, 1, 1}; return lb_primitive_lp(&prim, C0, a, 0.5, err);)
CALL(sqe, const double a[3] = {1, 1, 1};
     return lb_primitive_superquadric(&prim, C0, a, 0.0, 1.0, err);)
CALL(slabn, return lb_primitive_slab(&prim, C0, C0, 1.0, err);)
CALL(slabw, return lb_primitive_slab(&prim, C0, G1, 0.0, err);)
CALL(cylc, const double c[3] = {0, INFINITY, 0};
     return lb_primitive_cylinder(&prim, c, G1, 1.0, err);)
CALL(torr, return lb_primitive_torus(&prim, C0, G1, 1.0, -0.2, err);)
CALL(capnull, return lb_primitive_capsule(NULL, C0, G1, 1.0, err);)
CALL(kern, lb_primitive_sphere(&prim, C0, 1, NULL);
     return lb_primitive_soften(&prim, (lb_kernel)5, err);)

static const row_t rows[] = {
    {"k = 0", k0, LB_ERR_INVALID_ARGUMENT, "k = 0 arguments; allowed: 1 <= k <= 65535"},
    {"k too large", kbig, LB_ERR_INVALID_ARGUMENT, "k = 65536"},
    {"scale k too large", kscale, LB_ERR_INVALID_ARGUMENT,
     "k = 257 arguments; allowed: 1 <= k <= 256"},
    {"perlin k too large", kperlin, LB_ERR_INVALID_ARGUMENT,
     "k = 257 arguments; allowed: 1 <= k <= 256"},
    {"min k too large", kmin, LB_ERR_INVALID_ARGUMENT,
     "k = 65536 arguments; allowed: 1 <= k <= 65535"},
    {"negative r", rneg, LB_ERR_INVALID_ARGUMENT,
     "lb_displacement: r[1] = -1 is out of range; allowed: 1e-09 <= r <= 1e+09"},
    {"zero r", rzero, LB_ERR_INVALID_ARGUMENT, "r[0] = 0 is out of range"},
    {"p = 1", pone, LB_ERR_INVALID_ARGUMENT, "p[1] = 1 is out of range; allowed: 1 < p <= 1000"},
    {"p too large", pbig, LB_ERR_INVALID_ARGUMENT, "p[1] = 2000"},
    {"m = 0", mzero, LB_ERR_INVALID_ARGUMENT,
     "m[1] = 0 is out of range; allowed: 1e-06 <= m <= 1e+06"},
    {"x NaN", xnan, LB_ERR_NOT_FINITE, "x[1] = nan is not finite"},
    {"x beyond 1e100", xhuge, LB_ERR_NOT_FINITE,
     "x[1] = 1e+101 is beyond the supported range; allowed: |x| <= 1e+100"},
    {"x inf", xinf, LB_ERR_NOT_FINITE, "x[0] = inf is not finite"},
    {"r NaN", rnan, LB_ERR_INVALID_ARGUMENT, "r[0] = nan"},
    {"bad op", badop, LB_ERR_INVALID_ARGUMENT, "op = 7 is not a set operation"},
    {"NULL x", nullx, LB_ERR_INVALID_ARGUMENT, "x is NULL"},
    {"NULL value", nullout, LB_ERR_INVALID_ARGUMENT, "value (output) is NULL"},
    {"conic p >= r1 r2", conicp, LB_ERR_INVALID_ARGUMENT,
     "lb_conic: p = 0.25 is out of range; allowed: p < r[0]*r[1] = 0.25"},
    {"conic r", conicr, LB_ERR_INVALID_ARGUMENT, "lb_conic: r[0] = -1"},
    {"conic m", conicm, LB_ERR_INVALID_ARGUMENT, "lb_conic: m[0] = -1"},
    {"B_S r > 1", bsr, LB_ERR_INVALID_ARGUMENT,
     "lb_scale_bs: r[1] = 1.5 is out of range; allowed: 1e-09 <= r <= 1"},
    {"scale intersection r > 1", scaleir, LB_ERR_INVALID_ARGUMENT, "lb_scale: r[1] = 1.5"},
    {"scale p < 1", scalep, LB_ERR_INVALID_ARGUMENT, "lb_scale: p[0] = 0.5"},
    {"bounded p", boundp, LB_ERR_INVALID_ARGUMENT, "lb_bounded: p[0] = 1"},
    {"bounded c NaN", boundc, LB_ERR_NOT_FINITE, "lb_bounded: c[0] = nan"},
    {"soft union r > 1", softur, LB_ERR_INVALID_ARGUMENT,
     "lb_soft_hyper: r[1] = 2 is out of range; allowed: 1e-09 <= r <= 1"},
    {"soft m < 0", softm, LB_ERR_INVALID_ARGUMENT, "lb_soft_hyper: m[1] = -2"},
    {"soft conic union r > 1", softconicr, LB_ERR_INVALID_ARGUMENT,
     "lb_soft_conic: r[1] = 2 is out of range; allowed: 1e-09 <= r <= 1"},
    {"soft conic p", softconicp, LB_ERR_INVALID_ARGUMENT, "lb_soft_conic: p = 1"},
    {"soft x < 0", softx, LB_ERR_INVALID_ARGUMENT,
     "lb_soft_hyper: x[1] = -0.5 is out of range; allowed: 0 <= x <= 1e6 (a soft field value; soft "
     "unions may exceed 1)"},
    {"soft m too small", softmsmall, LB_ERR_INVALID_ARGUMENT,
     "m[1] = 0.0001 is out of range; allowed: 0.05 <= m <= 20"},
    {"r too small", rtiny, LB_ERR_INVALID_ARGUMENT,
     "r[0] = 1e-10 is out of range; allowed: 1e-09 <= r <= 1e+09"},
    {"Ricci n < 1", ricci, LB_ERR_INVALID_ARGUMENT, "param (Ricci exponent n) = 0.5"},
    {"R-function k", rfk, LB_ERR_INVALID_ARGUMENT, "this operator takes exactly 2"},
    {"classic kind", classkind, LB_ERR_INVALID_ARGUMENT, "kind = 42"},
    {"bulge NULL params", bulgenull, LB_ERR_INVALID_ARGUMENT, "params is NULL"},
    {"bulge omega = 0", bulgeomega, LB_ERR_INVALID_ARGUMENT, "params->omega = 0 is out of range"},
    {"bulge flags", bulgeflags, LB_ERR_INVALID_ARGUMENT, "flags = 8"},
    {"bulge slope on scale", bulgeslope, LB_ERR_INVALID_ARGUMENT, "LB_BULGE_SLOPE needs m"},
    {"bulge scale r too big", bulgescaler, LB_ERR_INVALID_ARGUMENT,
     "params->r[0] = 0.5 is out of range; allowed: 0 < r <= 1/(2 + omega)"},
    {"bulge conic p", bulgeconicp, LB_ERR_INVALID_ARGUMENT,
     "params->conic_p = 0.1 is out of range"},
    {"bulge family", bulgefam, LB_ERR_INVALID_ARGUMENT, "family = 9"},
    {"bulge g NaN", bulgeg, LB_ERR_INVALID_ARGUMENT,
     "g1[1] = nan is out of range; allowed: finite, |g1 component| <= 1e30"},
    {"sphere radius", sphr, LB_ERR_INVALID_ARGUMENT,
     "lb_primitive_sphere: radius = -1 is out of range; allowed: finite and > 0"},
    {"ellipsoid axis", ellipa, LB_ERR_INVALID_ARGUMENT, "lb_primitive_ellipsoid: a[1] = 0"},
    {"LP n", lpn, LB_ERR_INVALID_ARGUMENT,
     "lb_primitive_lp: n = 0.5 is out of range; allowed: 1 <= n <= 1000"},
    {"superquadric e1", sqe, LB_ERR_INVALID_ARGUMENT,
     "e1 = 0 is out of range; allowed: 0.01 <= e1 <= 10"},
    {"slab normal", slabn, LB_ERR_INVALID_ARGUMENT, "n = (0, 0, 0) is not a direction"},
    {"slab width", slabw, LB_ERR_INVALID_ARGUMENT, "lb_primitive_slab: w = 0"},
    {"cylinder centre", cylc, LB_ERR_NOT_FINITE, "c[1] = inf is not finite"},
    {"torus minor radius", torr, LB_ERR_INVALID_ARGUMENT, "minor_radius = -0.2"},
    {"capsule NULL", capnull, LB_ERR_INVALID_ARGUMENT, "out is NULL"},
    {"kernel", kern, LB_ERR_INVALID_ARGUMENT, "kernel = 5"},
};

static void test_rejections(void **state) {
    (void)state;
    long bad = 0;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
        lb_error err = {LB_OK, ""};
        out = 12345.0;
        const lb_status st = rows[i].call(&err);
        const int ok = st == rows[i].status && err.status == st &&
                       strstr(err.message, rows[i].needle) &&
                       out == 12345.0; /* no output written on failure */
        if (!ok) {
            ++bad;
            fprintf(stderr, "  [%s] status %d (want %d), message \"%s\" (want \"%s\")\n",
                    rows[i].what, (int)st, (int)rows[i].status, err.message, rows[i].needle);
        }
        /* a NULL error record must be accepted too */
        assert_int_equal(rows[i].call(NULL), rows[i].status);
    }
    fprintf(stderr, "  %zu invalid calls, %ld wrong\n", sizeof rows / sizeof rows[0], bad);
    assert_int_equal(bad, 0);
    assert_string_equal(lb_status_string(LB_ERR_NOT_FINITE), "non-finite input");
    assert_int_equal(lb_version(),
                     LB_VERSION_MAJOR * 10000 + LB_VERSION_MINOR * 100 + LB_VERSION_PATCH);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_rejections)};
    return cmocka_run_group_tests_name("validation", tests, NULL, NULL);
}
