/* lb_mesh_velocities: the surface's velocity at every vertex, for motion
 * blur.
 *
 * - A translating sphere (zero and soft convention), speed 2 along a
 *   direction off the axes: every vertex's velocity is (s . n) n, n the
 *   sphere's exact normal there, within 1 % of the speed; the same with
 *   only the field after (one-sided difference), within 2 %.
 * - A growing sphere: g n exactly (1 % of g).
 * - A growing blend (two spheres under a displacement union, both radii
 *   growing, so the fillet moves too), where no closed form exists: the
 *   normal speed at each vertex against the distance along the normal to
 *   the surface at t + tau, found by bisection on the field (tau = 1e-3):
 *   within 1 % of the largest speed.
 * - Bad arguments: NULL pointers, both fields NULL, dt <= 0, NaN or
 *   infinite, fields of another convention; an empty mesh is fine. */
#include "testlib.h"

#include <math.h>
#include <stdlib.h>

static lb_evaluator *compile(const char *text) {
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(text, strlen(text), "v.json", &sc, &e) || lb_evaluator_create(sc, &ev, &e))
        fail_msg("%s\n%s", e.message, text);
    lb_scene_free(sc);
    return ev;
}

#define BOUNDS "\"bounds\": {\"min\": [-3, -3, -3], \"max\": [3, 3, 3]}, "

static lb_evaluator *sphere(const char *conv, const double c[3], double r) {
    char t[512];
    snprintf(t, sizeof t,
             "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"%s\", " BOUNDS
             "\"root\": {\"type\": \"sphere\", \"center\": [%.17g, %.17g, %.17g], \"radius\": "
             "%.17g%s}}",
             conv, c[0], c[1], c[2], r, conv[0] == 's' ? ", \"kernel\": \"wyvill\"" : "");
    return compile(t);
}

static lb_evaluator *blend(double r) {
    char t[768];
    snprintf(t, sizeof t,
             "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\", " BOUNDS
             "\"root\": {\"type\": \"displacement\", \"op\": \"union\", \"r\": 0.4, \"args\": ["
             "{\"type\": \"sphere\", \"center\": [-0.7, 0, 0], \"radius\": %.17g},"
             "{\"type\": \"sphere\", \"center\": [0.8, 0.1, 0], \"radius\": %.17g}]}}",
             r, 0.8 * r);
    return compile(t);
}

static lb_mesh *mesh_of(const lb_evaluator *ev) {
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    for (int d = 0; d < 3; ++d) o.bmin[d] = -3, o.bmax[d] = 3;
    o.resolution = 48;
    o.threads = 1;
    lb_mesh *m = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_true(m->nvertices > 500);
    return m;
}

static double *velocities(const lb_evaluator *ev, const lb_evaluator *b, const lb_evaluator *a,
                          const lb_mesh *m, double dt) {
    double *v = malloc(3 * m->nvertices * sizeof *v);
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_mesh_velocities(ev, b, a, m, dt, 2, v, &e), LB_OK);
    return v;
}

/* the largest |v - (s . n + g) n| over the vertices, n the normal of a
 * sphere centred at c: a sphere moving at s and growing at g */
static double sphere_error(const lb_mesh *m, const double *v, const double c[3], const double s[3],
                           double g) {
    double worst = 0.0;
    for (size_t i = 0; i < m->nvertices; ++i) {
        const double *p = m->positions + 3 * i;
        double n[3], l = 0.0, speed = g, err = 0.0;
        for (int d = 0; d < 3; ++d) n[d] = p[d] - c[d], l += n[d] * n[d];
        l = sqrt(l);
        for (int d = 0; d < 3; ++d) n[d] /= l, speed += s[d] * n[d];
        for (int d = 0; d < 3; ++d) err += pow(v[3 * i + d] - speed * n[d], 2);
        if (sqrt(err) > worst) worst = sqrt(err);
    }
    return worst;
}

static void translating(const char *conv, int one_sided, double bar) {
    const double c0[3] = {0.2, -0.1, 0.3}, s[3] = {1.2, -1.4, 0.8}; /* |s| = 2 */
    const double dt = 1e-3, R = 1.1;
    double cb[3], ca[3];
    for (int d = 0; d < 3; ++d) cb[d] = c0[d] - s[d] * dt, ca[d] = c0[d] + s[d] * dt;
    lb_evaluator *ev = sphere(conv, c0, R), *b = sphere(conv, cb, R), *a = sphere(conv, ca, R);
    lb_mesh *m = mesh_of(ev);
    double *v = velocities(ev, one_sided ? NULL : b, a, m, dt);
    const double worst = sphere_error(m, v, c0, s, 0.0);
    printf("translating sphere, %s, %s: %zu vertices, worst error %.2e (%.3f %% of the speed)\n",
           conv, one_sided ? "after only" : "central", m->nvertices, worst, 100 * worst / 2.0);
    assert_true(worst <= bar * 2.0);
    free(v);
    lb_mesh_free(m);
    lb_evaluator_free(ev), lb_evaluator_free(b), lb_evaluator_free(a);
}

static void test_translating_sphere(void **state) {
    (void)state;
    translating("zero", 0, 0.01);
    translating("soft", 0, 0.01);
    translating("zero", 1, 0.02);
    translating("soft", 1, 0.02);
}

static void test_growing_sphere(void **state) {
    (void)state;
    const double c[3] = {0.1, 0.2, -0.3}, g = 0.5, dt = 1e-3;
    lb_evaluator *ev = sphere("zero", c, 1.0), *b = sphere("zero", c, 1.0 - g * dt),
                 *a = sphere("zero", c, 1.0 + g * dt);
    lb_mesh *m = mesh_of(ev);
    const double still[3] = {0, 0, 0};
    double *v = velocities(ev, b, a, m, dt);
    const double worst = sphere_error(m, v, c, still, g);
    printf("growing sphere: worst error %.2e of the speed %.1f\n", worst, g);
    assert_true(worst <= 0.01 * g);
    free(v);
    lb_mesh_free(m);
    lb_evaluator_free(ev), lb_evaluator_free(b), lb_evaluator_free(a);
}

/* the signed step along the unit vector n from p to the zero set of ev,
 * by bisection within [-h, h] */
static double step_to_surface(const lb_evaluator *ev, const double p[3], const double n[3],
                              double h) {
    double lo = -h, hi = h;
    double x, y, z, f;
    lb_error e = {LB_OK, ""};
    x = p[0] + lo * n[0], y = p[1] + lo * n[1], z = p[2] + lo * n[2];
    lb_evaluator_eval(ev, 1, &x, &y, &z, &f, NULL, NULL, NULL, 1, &e);
    const double flo = f;
    x = p[0] + hi * n[0], y = p[1] + hi * n[1], z = p[2] + hi * n[2];
    lb_evaluator_eval(ev, 1, &x, &y, &z, &f, NULL, NULL, NULL, 1, &e);
    if (!(flo < 0.0 && f > 0.0)) return NAN;
    for (int k = 0; k < 80; ++k) {
        const double mid = 0.5 * (lo + hi);
        x = p[0] + mid * n[0], y = p[1] + mid * n[1], z = p[2] + mid * n[2];
        lb_evaluator_eval(ev, 1, &x, &y, &z, &f, NULL, NULL, NULL, 1, &e);
        if (f < 0.0)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

static void test_growing_blend(void **state) {
    (void)state;
    const double r0 = 0.8, g = 0.6, dt = 1e-3, tau = 1e-3;
    lb_evaluator *ev = blend(r0), *b = blend(r0 - g * dt), *a = blend(r0 + g * dt),
                 *later = blend(r0 + g * tau);
    lb_mesh *m = mesh_of(ev);
    double *v = velocities(ev, b, a, m, dt);
    double worst = 0.0, vmax = 0.0;
    size_t checked = 0;
    for (size_t i = 0; i < m->nvertices; ++i) {
        const double *p = m->positions + 3 * i;
        double x = p[0], y = p[1], z = p[2], f, gr[3];
        lb_error e = {LB_OK, ""};
        lb_evaluator_eval(ev, 1, &x, &y, &z, &f, &gr[0], &gr[1], &gr[2], 1, &e);
        const double l = sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
        if (!(l > 0.0)) continue;
        const double n[3] = {gr[0] / l, gr[1] / l, gr[2] / l};
        /* where the surface is now along the normal, and where it is at t + tau */
        const double s0 = step_to_surface(ev, p, n, 0.05);
        const double s1 = step_to_surface(later, p, n, 0.05);
        if (isnan(s0) || isnan(s1)) continue;
        const double speed = (s1 - s0) / tau;
        const double vn = v[3 * i] * n[0] + v[3 * i + 1] * n[1] + v[3 * i + 2] * n[2];
        if (fabs(speed) > vmax) vmax = fabs(speed);
        if (fabs(vn - speed) > worst) worst = fabs(vn - speed);
        ++checked;
    }
    printf("growing blend: %zu of %zu vertices checked, normal speeds up to %.3f, worst error "
           "%.2e (%.3f %%)\n",
           checked, m->nvertices, vmax, worst, 100 * worst / vmax);
    assert_true(checked > m->nvertices * 9 / 10);
    assert_true(vmax > 0.4);
    assert_true(worst <= 0.01 * vmax);
    free(v);
    lb_mesh_free(m);
    lb_evaluator_free(ev), lb_evaluator_free(b), lb_evaluator_free(a), lb_evaluator_free(later);
}

static void test_bad_arguments(void **state) {
    (void)state;
    const double c[3] = {0, 0, 0};
    lb_evaluator *ev = sphere("zero", c, 1.0), *soft = sphere("soft", c, 1.0);
    lb_mesh *m = mesh_of(ev);
    double *v = malloc(3 * m->nvertices * sizeof *v);
    lb_error e = {LB_OK, ""};
#define BAD(call)                                                                                  \
    do {                                                                                           \
        e.status = LB_OK, e.message[0] = 0;                                                        \
        assert_int_equal((call), LB_ERR_INVALID_ARGUMENT);                                         \
        assert_true(strstr(e.message, "lb_mesh_velocities") != NULL);                              \
    } while (0)
    BAD(lb_mesh_velocities(NULL, ev, ev, m, 0.1, 1, v, &e));
    BAD(lb_mesh_velocities(ev, NULL, NULL, m, 0.1, 1, v, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, NULL, 0.1, 1, v, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, m, 0.1, 1, NULL, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, m, 0.0, 1, v, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, m, -1.0, 1, v, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, m, NAN, 1, v, &e));
    BAD(lb_mesh_velocities(ev, ev, ev, m, INFINITY, 1, v, &e));
    BAD(lb_mesh_velocities(ev, soft, NULL, m, 0.1, 1, v, &e));
    BAD(lb_mesh_velocities(ev, NULL, soft, m, 0.1, 1, v, &e));
    lb_mesh empty = *m;
    empty.nvertices = 0, empty.positions = NULL;
    assert_int_equal(lb_mesh_velocities(ev, ev, NULL, &empty, 0.1, 1, NULL, &e), LB_OK);
    /* without err: a status, no crash */
    assert_int_equal(lb_mesh_velocities(ev, NULL, NULL, m, 0.1, 1, v, NULL),
                     LB_ERR_INVALID_ARGUMENT);
    free(v);
    lb_mesh_free(m);
    lb_evaluator_free(ev), lb_evaluator_free(soft);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_translating_sphere),
        cmocka_unit_test(test_growing_sphere),
        cmocka_unit_test(test_growing_blend),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
