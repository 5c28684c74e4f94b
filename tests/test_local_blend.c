/* The local_union node (local blending around intersection curves): the
 * curves against closed forms, component counts, no blend at a distance
 * (bit for bit, fields and meshes), the clean union outside every volume,
 * C1 across the volume's border, sound interval bounds, closed meshes, the
 * progressive drop sweep, and the zero convention's union surface. */
#include "testlib.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "../libblend/src/evaluation/tape.h"

#include <stdlib.h>

static lb_scene *parse(const char *text) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(text, strlen(text), "local.json", &sc, &e)) fail_msg("%s", e.message);
    return sc;
}

static lb_evaluator *compile(const lb_scene *sc) {
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_evaluator_create(sc, &ev, &e)) fail_msg("%s", e.message);
    return ev;
}

static void eval1(const lb_evaluator *ev, const double X[3], double *v, double g[3]) {
    lb_error e = {LB_OK, ""};
    double gx, gy, gz;
    if (lb_evaluator_eval(ev, 1, X, X + 1, X + 2, v, &gx, &gy, &gz, 1, &e))
        fail_msg("%s", e.message);
    if (g) {
        g[0] = gx;
        g[1] = gy;
        g[2] = gz;
    }
}

static char *two_spheres(const char *type, double c2, double r2, const char *conv) {
    char *t = malloc(1024);
    snprintf(t, 1024,
             "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"%s\","
             "\"bounds\":{\"min\":[-2,-2,-2],\"max\":[3.5,2,2]},\"root\":{\"type\":\"%s\","
             "\"args\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},"
             "{\"type\":\"sphere\",\"center\":[%.17g,0,0],\"radius\":%.17g}]}}",
             conv, type, c2, r2);
    return t;
}

/* soft sphere field, independently of the scene */
static double sphere_field(const double c[3], double r, const double X[3], double g[3]) {
    lb_primitive p;
    assert_int_equal(lb_primitive_sphere(&p, c, r, NULL), LB_OK);
    assert_int_equal(lb_primitive_soften(&p, LB_KERNEL_WYVILL, NULL), LB_OK);
    return lb_primitive_eval(&p, X, g);
}

static void test_two_sphere_circle(void **st) {
    (void)st;
    const double d = 1.2, r1 = 1.0, r2 = 0.8, size = sqrt(5.5 * 5.5 + 16.0 + 16.0);
    char *t = two_spheres("local_union", d, r2, "soft");
    lb_scene *sc = parse(t);
    lb_evaluator *ev = compile(sc);
    const struct lb__curves *C = lb__local_nth(ev, 0);
    assert_non_null(C);
    assert_int_equal(C->ncomp, 1);
    assert_true(C->comp[0].closed);
    assert_true(C->nv >= 64);
    const double xc = (d * d + r1 * r1 - r2 * r2) / (2.0 * d), rho = sqrt(r1 * r1 - xc * xc);
    const double c1[3] = {0, 0, 0}, c2[3] = {d, 0, 0};
    for (size_t i = 0; i < C->nv; ++i) {
        const double *P = C->pts + 3 * i;
        double g1[3], g2[3];
        const double f1 = sphere_field(c1, r1, P, g1), f2 = sphere_field(c2, r2, P, g2);
        const double e1 = fabs(f1 - 0.5) / sqrt(g1[0] * g1[0] + g1[1] * g1[1] + g1[2] * g1[2]);
        const double e2 = fabs(f2 - 0.5) / sqrt(g2[0] * g2[0] + g2[1] * g2[1] + g2[2] * g2[2]);
        if (!(e1 <= 1e-9 * size && e2 <= 1e-9 * size))
            fail_msg("vertex %zu off the surfaces by %g, %g", i, e1, e2);
        const double rad = hypot(P[1], P[2]);
        if (!(fabs(rad - rho) <= 1e-9 * rho && fabs(P[0] - xc) <= 1e-9))
            fail_msg("vertex %zu: radius %.17g (want %.17g), x %.17g (want %.17g)", i, rad, rho,
                     P[0], xc);
    }
    /* the polyline's midpoints stray at most the stated tolerance */
    for (size_t i = 0; i < C->nv; ++i) {
        const double *a = C->pts + 3 * i, *b = C->pts + 3 * ((i + 1) % C->nv);
        const double m[3] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
        const double dev = rho - hypot(m[1], m[2]);
        if (!(dev <= 1e-5 * size)) fail_msg("segment %zu strays %g", i, dev);
    }
    /* automatic parameters: d_i from the curvature radius (r_i / 2) */
    assert_true(fabs(C->comp[0].d1 - 0.5) < 1e-3 && fabs(C->comp[0].d2 - 0.4) < 1e-3);
    assert_true(fabs(C->comp[0].diameter - 2.0 * rho) < 1e-6);
    assert_true(fabs(C->comp[0].length - 2.0 * M_PI * rho) < 1e-3 * rho);
    char buf[512];
    assert_true(lb_evaluator_describe_local(ev, buf, sizeof buf) > 0);
    assert_non_null(strstr(buf, "$.root: 1 intersection curve"));
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    free(t);
}

/* n small spheres cut by one wide flat ellipsoid: n curves */
static void test_component_counts(void **st) {
    (void)st;
    for (int n = 0; n <= 3; ++n) {
        char t[2048];
        int w =
            snprintf(t, sizeof t,
                     "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"soft\","
                     "\"bounds\":{\"min\":[-1.5,-3,-1.5],\"max\":[7.5,3,1.5]},\"root\":{\"type\":"
                     "\"local_union\",\"args\":[{\"type\":\"max\",\"args\":[");
        for (int i = 0; i < (n ? n : 1); ++i)
            w += snprintf(t + w, sizeof t - (size_t)w,
                          "%s{\"type\":\"sphere\",\"center\":[%d,%s,0],\"radius\":0.6}",
                          i ? "," : "", 3 * i, n ? "0" : "2");
        snprintf(t + w, sizeof t - (size_t)w,
                 "]},{\"type\":\"ellipsoid\",\"center\":[3,-1.5,0],\"semi_axes\":[20,1.2,20]}]}}");
        lb_scene *sc = parse(t);
        lb_evaluator *ev = compile(sc);
        const struct lb__curves *C = lb__local_nth(ev, 0);
        assert_non_null(C);
        if ((int)C->ncomp != n) fail_msg("%d spheres: %zu curves", n, C->ncomp);
        for (size_t c = 0; c < C->ncomp; ++c) assert_true(C->comp[c].closed);
        lb_evaluator_free(ev);
        lb_scene_free(sc);
    }
}

static int cmp(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static void check_closed(const lb_mesh *m) {
    /* every directed edge once, and its reverse once */
    const size_t ne = 3 * m->ntriangles;
    uint64_t *e = malloc((ne ? ne : 1) * sizeof *e);
    for (size_t t = 0; t < m->ntriangles; ++t)
        for (int k = 0; k < 3; ++k)
            e[3 * t + k] =
                (uint64_t)m->triangles[3 * t + k] << 32 | m->triangles[3 * t + (k + 1) % 3];
    qsort(e, ne, sizeof *e, cmp);
    for (size_t i = 0; i < ne; ++i) {
        if (i && e[i] == e[i - 1]) fail_msg("directed edge twice");
        const uint64_t r = e[i] >> 32 | e[i] << 32;
        if (!bsearch(&r, e, ne, sizeof *e, cmp)) fail_msg("edge without its reverse: not closed");
    }
    free(e);
}
static lb_mesh *mesh_of(const lb_evaluator *ev, const lb_scene *sc, unsigned res) {
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    lb_scene_bounds(sc, o.bmin, o.bmax);
    o.resolution = res;
    o.threads = 2;
    lb_mesh *m = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_mesh_create(ev, &o, &m, &e)) fail_msg("%s", e.message);
    return m;
}

/* Closer than any blend range of the classic operators, not touching: no
 * curve, and the field and mesh are the clean union's, bit for bit. */
static void test_no_blend_at_a_distance(void **st) {
    (void)st;
    char *a = two_spheres("local_union", 2.05, 1.0, "soft"),
         *b = two_spheres("clean_union", 2.05, 1.0, "soft");
    lb_scene *sa = parse(a), *sb = parse(b);
    lb_evaluator *ea = compile(sa), *eb = compile(sb);
    assert_int_equal(lb__local_nth(ea, 0)->ncomp, 0);
    rng_t r = {77};
    for (int i = 0; i < 20000; ++i) {
        const double X[3] = {rng_range(&r, -2, 3.5), rng_range(&r, -2, 2), rng_range(&r, -2, 2)};
        double va, vb, ga[3], gb[3];
        eval1(ea, X, &va, ga);
        eval1(eb, X, &vb, gb);
        if (va != vb || memcmp(ga, gb, sizeof ga))
            fail_msg("differs from the clean union at %d", i);
    }
    for (unsigned res = 32; res <= 64; res += 32) {
        lb_mesh *ma = mesh_of(ea, sa, res), *mb = mesh_of(eb, sb, res);
        assert_int_equal(ma->nvertices, mb->nvertices);
        assert_int_equal(ma->ntriangles, mb->ntriangles);
        assert_memory_equal(ma->positions, mb->positions, 3 * ma->nvertices * sizeof(double));
        assert_memory_equal(ma->triangles, mb->triangles, 3 * ma->ntriangles * sizeof(uint32_t));
        check_closed(ma);
        lb_mesh_free(ma);
        lb_mesh_free(mb);
    }
    lb_evaluator_free(ea);
    lb_evaluator_free(eb);
    lb_scene_free(sa);
    lb_scene_free(sb);
    free(a);
    free(b);
}

/* distance from X to the polyline, by brute force */
static double curve_dist(const struct lb__curves *C, const double X[3]) {
    double best = INFINITY;
    for (size_t s = 0; s < C->nseg; ++s) {
        const double *a = C->pts + 3 * C->seg[2 * s], *b = C->pts + 3 * C->seg[2 * s + 1];
        double ab[3], ax[3], ll = 0, t = 0;
        for (int d = 0; d < 3; ++d) {
            ab[d] = b[d] - a[d];
            ax[d] = X[d] - a[d];
            ll += ab[d] * ab[d];
            t += ab[d] * ax[d];
        }
        t = ll > 0 ? fmin(1.0, fmax(0.0, t / ll)) : 0.0;
        double dd = 0;
        for (int d = 0; d < 3; ++d) dd += (ax[d] - t * ab[d]) * (ax[d] - t * ab[d]);
        if (sqrt(dd) < best) best = sqrt(dd);
    }
    return best;
}

static void test_volume_border(void **st) {
    (void)st;
    char *a = two_spheres("local_union", 1.2, 0.8, "soft"),
         *b = two_spheres("clean_union", 1.2, 0.8, "soft");
    lb_scene *sa = parse(a), *sb = parse(b);
    lb_evaluator *ea = compile(sa), *eb = compile(sb);
    const struct lb__curves *C = lb__local_nth(ea, 0);
    const double R = C->comp[0].R;
    rng_t r = {78};
    long outside = 0, inside_more = 0, c1 = 0;
    for (int i = 0; i < 20000; ++i) {
        const double X[3] = {rng_range(&r, -2, 3.5), rng_range(&r, -2, 2), rng_range(&r, -2, 2)};
        double va, vb, ga[3], gb[3];
        eval1(ea, X, &va, ga);
        eval1(eb, X, &vb, gb);
        const double dist = curve_dist(C, X);
        if (dist >= R * (1.0 + 1e-9)) {
            if (va != vb || memcmp(ga, gb, sizeof ga))
                fail_msg("outside the volume (%g >= R %g) but not the clean union", dist, R);
            ++outside;
        } else if (va > vb) {
            ++inside_more;
        }
    }
    assert_true(outside > 10000);
    assert_true(inside_more > 100); /* the blend adds material near the curve */
    /* C1 across the border: random rays through the torus of radius R
     * around the circle, one-sided gradients agree */
    for (int i = 0; i < 2000; ++i) {
        const size_t v = rng_int(&r, 0, C->nv - 1);
        const double *P = C->pts + 3 * v;
        const double ang = rng_range(&r, 0, 2 * M_PI), rad = hypot(P[1], P[2]);
        /* the plane normal to the circle at P: the x axis and P's radial direction */
        const double u[3] = {cos(ang), sin(ang) * P[1] / rad, sin(ang) * P[2] / rad};
        double X[3], gp[3], gm[3], vp, vm;
        /* the distance is to the polyline: move along u until it is R */
        double t = R;
        for (int it = 0; it < 60; ++it) {
            for (int d = 0; d < 3; ++d) X[d] = P[d] + t * u[d];
            t += R - curve_dist(C, X);
        }
        for (int d = 0; d < 3; ++d) X[d] = P[d] + t * (1 + 1e-7) * u[d];
        eval1(ea, X, &vp, gp);
        for (int d = 0; d < 3; ++d) X[d] = P[d] + t * (1 - 1e-7) * u[d];
        eval1(ea, X, &vm, gm);
        const double s = 1e-3 * (fabs(gp[0]) + fabs(gp[1]) + fabs(gp[2]) + 1e-3);
        if (!(fabs(gp[0] - gm[0]) <= s && fabs(gp[1] - gm[1]) <= s && fabs(gp[2] - gm[2]) <= s))
            fail_msg("gradient jumps across the border: (%g %g %g) vs (%g %g %g)", gp[0], gp[1],
                     gp[2], gm[0], gm[1], gm[2]);
        ++c1;
    }
    assert_int_equal(c1, 2000);
    /* bounds contain dense samples on random boxes */
    for (int b2 = 0; b2 < 150; ++b2) {
        double lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            const double c = rng_range(&r, -1.5, 2.5), h = rng_log(&r, 0.01, 1.0);
            lo[d] = c - h;
            hi[d] = c + h;
        }
        double blo, bhi;
        lb_error e = {LB_OK, ""};
        assert_int_equal(lb_evaluator_bounds(ea, lo, hi, &blo, &bhi, &e), LB_OK);
        for (int k = 0; k < 512; ++k) {
            const double X[3] = {rng_range(&r, lo[0], hi[0]), rng_range(&r, lo[1], hi[1]),
                                 rng_range(&r, lo[2], hi[2])};
            double v;
            eval1(ea, X, &v, NULL);
            if (!(v >= blo && v <= bhi)) fail_msg("%g outside the bound [%g, %g]", v, blo, bhi);
        }
    }
    for (unsigned res = 40; res <= 80; res += 40) {
        lb_mesh *m = mesh_of(ea, sa, res);
        assert_true(m->ntriangles > 1000);
        check_closed(m);
        lb_mesh_free(m);
    }
    lb_evaluator_free(ea);
    lb_evaluator_free(eb);
    lb_scene_free(sa);
    lb_scene_free(sb);
    free(a);
    free(b);
}

/* A drop (radius 0.5) lowered onto water (a sphere of radius 5 whose top
 * is at y = 0): no curve before contact, then the support R and the blended
 * material (grid samples inside the local blend but outside the clean
 * union) grow with penetration. */
static void test_drop_sweep(void **st) {
    (void)st;
    double lastR = 0.0;
    long last_mat = -1;
    int contact = 0;
    for (int i = 0; i < 12; ++i) {
        const double y = 0.62 - 0.05 * i; /* drop centre: 0.62 (apart) .. 0.07 (deep) */
        char t[1024], u[1024];
        const char *fmt =
            "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":\"soft\","
            "\"bounds\":{\"min\":[-1.5,-1,-1.5],\"max\":[1.5,1.5,1.5]},\"root\":{"
            "\"type\":\"%s\",\"args\":[{\"type\":\"sphere\",\"center\":[0,%.17g,0],"
            "\"radius\":0.5},{\"type\":\"sphere\",\"center\":[0,-5,0],\"radius\":5}]}}";
        snprintf(t, sizeof t, fmt, "local_union", y);
        snprintf(u, sizeof u, fmt, "clean_union", y);
        lb_scene *sa = parse(t), *sb = parse(u);
        lb_evaluator *ea = compile(sa), *eb = compile(sb);
        const struct lb__curves *C = lb__local_nth(ea, 0);
        const int touching = y < 0.5;
        if (!touching && C->ncomp) fail_msg("drop at %g: a curve before contact", y);
        if (touching && C->ncomp != 1) fail_msg("drop at %g: %zu curves", y, C->ncomp);
        const double R = C->ncomp ? C->comp[0].R : 0.0;
        /* the blended material: samples inside the blend, outside the
         * clean union, on a fine grid around the contact */
        long mat = 0;
        for (int a = 0; a < 64; ++a)
            for (int b = 0; b < 64; ++b)
                for (int c = 0; c < 64; ++c) {
                    const double X[3] = {-0.8 + 1.6 * a / 63, -0.4 + 1.0 * b / 63,
                                         -0.8 + 1.6 * c / 63};
                    double va, vb;
                    eval1(ea, X, &va, NULL);
                    eval1(eb, X, &vb, NULL);
                    mat += va > 0.5 && !(vb > 0.5);
                }
        fprintf(stderr, "  drop at %.2f: %zu curves, R %.4g, blended samples %ld\n", y, C->ncomp, R,
                mat);
        if (!touching && mat) fail_msg("drop at %g: %ld blended samples before contact", y, mat);
        if (touching) {
            ++contact;
            if (!(R > lastR) || !(mat >= last_mat))
                fail_msg("drop at %g: R %g (before %g), material %ld (before %ld)", y, R, lastR,
                         mat, last_mat);
            lastR = R;
            last_mat = mat;
        }
        lb_evaluator_free(ea);
        lb_evaluator_free(eb);
        lb_scene_free(sa);
        lb_scene_free(sb);
    }
    assert_true(contact >= 9);
    assert_true(last_mat > 0);
}

/* zero convention: g = 0.5 (1 - f / zero_scale); the union surface is
 * min(f1, f2) = 0, so the clean union is 0 on each sphere outside the other */
static void test_zero_convention_surface(void **st) {
    (void)st;
    char *t = two_spheres("clean_union", 1.2, 0.8, "zero");
    lb_scene *sc = parse(t);
    lb_evaluator *ev = compile(sc);
    rng_t r = {79};
    long n = 0;
    for (int i = 0; i < 10000; ++i) {
        const double th = rng_range(&r, 0, M_PI), ph = rng_range(&r, 0, 2 * M_PI);
        const double X[3] = {cos(th), sin(th) * cos(ph), sin(th) * sin(ph)}; /* on sphere 1 */
        if (hypot(X[0] - 1.2, hypot(X[1], X[2])) <= 0.8 * 1.001) continue;
        double v;
        eval1(ev, X, &v, NULL);
        if (!(fabs(v) <= 1e-14)) fail_msg("clean union %g on the union surface", v);
        ++n;
    }
    assert_true(n > 5000);
    char *l = two_spheres("local_union", 1.2, 0.8, "zero");
    lb_scene *sl = parse(l);
    lb_evaluator *el = compile(sl);
    assert_int_equal(lb__local_nth(el, 0)->ncomp, 1);
    lb_mesh *m = mesh_of(el, sl, 48);
    check_closed(m);
    lb_mesh_free(m);
    lb_evaluator_free(el);
    lb_scene_free(sl);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    free(t);
    free(l);
    /* the reference walk refuses local_union by path */
    char *t2 = two_spheres("local_union", 1.2, 0.8, "soft");
    lb_scene *s2 = parse(t2);
    free(t2);
    const double X[3] = {0, 0, 0};
    double v;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_scene_eval_reference(s2, X, &v, NULL, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "$.root: a local_union needs"));
    lb_scene_free(s2);
}

/* A flat local_union of k spheres (a left fold): on a ring of radius
 * spacing k / 2 pi (spread: each meets its two neighbours), or crowded on a
 * ring of radius 1.5 (each within zero_scale of all), in either convention
 * (soft: Wyvill kernels of radius 2r); sphere `moved` shifted by dx along x
 * and the bounds grown by grow along -x (edits, for test_reuse_curves). */
static char *ring_scene_edit(int k, int spread, const char *conv, int moved, double dx,
                             double grow) {
    const double rad = spread ? k * 0.7 / (2.0 * M_PI) : 1.5;
    size_t cap = 256 + (size_t)k * 160, len = 0;
    char *t = malloc(cap);
    const int soft = !strcmp(conv, "soft");
    len += (size_t)snprintf(t + len, cap - len,
                            "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": "
                            "\"%s\", \"bounds\": {\"min\": [%g, %g, -1.5], \"max\": [%g, %g, 1.5]},"
                            " \"root\": {\"type\": \"local_union\", \"args\": [",
                            conv, -rad - 1.5 - grow, -rad - 1.5, rad + 1.5, rad + 1.5);
    for (int i = 0; i < k; ++i)
        len += (size_t)snprintf(
            t + len, cap - len, "%s{\"type\": \"sphere\", \"center\": [%.6f, %.6f, %.6f], %s}",
            i ? ", " : "", rad * cos(2.0 * M_PI * i / k) + (i == moved ? dx : 0.0),
            rad * sin(2.0 * M_PI * i / k), 0.2 * sin(7.0 * i),
            soft ? "\"radius\": 0.6, \"kernel\": \"wyvill\"" : "\"radius\": 0.5");
    snprintf(t + len, cap - len, "]}}");
    return t;
}

static char *ring_scene(int k, int spread, const char *conv) {
    return ring_scene_edit(k, spread, conv, -1, 0.0, 0.0);
}

/* a flat local union of k spheres in a 12-wide lattice (rows 0.9 apart,
 * radius 0.5: each meets its neighbours in the row and the rows beside it),
 * zero convention, zero_scale 0.2 */
static char *lattice_scene(int k) {
    const int w = 12, rows = (k + w - 1) / w;
    size_t cap = 512 + (size_t)k * 96, len = 0;
    char *t = malloc(cap);
    len +=
        (size_t)snprintf(t + len, cap - len,
                         "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": "
                         "\"zero\", \"bounds\": {\"min\": [-1, -1, -1], \"max\": [%g, %g, 1.2]},"
                         " \"root\": {\"type\": \"local_union\", \"zero_scale\": 0.2, \"args\": [",
                         (w - 1) * 0.9 + 1.0, (rows - 1) * 0.9 + 1.0);
    for (int i = 0; i < k; ++i)
        len +=
            (size_t)snprintf(t + len, cap - len,
                             "%s{\"type\": \"sphere\", \"center\": [%g, %g, %g], \"radius\": 0.5}",
                             i ? ", " : "", (i % w) * 0.9, (i / w) * 0.9, 0.05 * ((i * 7) % 5));
    snprintf(t + len, cap - len, "]}}");
    return t;
}

/* Each local union's children, reduced over boxes (cone.c), equal the
 * children run in full at points of the box (value and gradient to
 * rounding), the reduced interval contains them, and on a spread ring a
 * small box keeps at most a quarter of a long cone. The lattice is where
 * the max groups drop most links (children far from the box and from each
 * other). */
static void test_cone_reduction(void **st) {
    (void)st;
    tally_t eq = {"reduced cone = whole cone at points", 0, 0, 0};
    tally_t in = {"reduced cone's interval holds the points", 0, 0, 0};
    rng_t R = {7};
    double kept = 0.0, boxes = 0.0;
    const struct {
        int k, spread; /* 2: the lattice */
        const char *conv;
    } cases[] = {
        {48, 1, "zero"}, {40, 0, "zero"}, {48, 1, "soft"}, {32, 0, "soft"}, {72, 2, "zero"}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        char *text = cases[c].spread == 2 ? lattice_scene(cases[c].k)
                                          : ring_scene(cases[c].k, cases[c].spread, cases[c].conv);
        lb_scene *sc = parse(text);
        free(text);
        lb_evaluator *ev = compile(sc);
        double bmin[3], bmax[3];
        assert_true(lb_scene_bounds(sc, bmin, bmax));
        double *regs = malloc(lb__regs_len(ev) * sizeof *regs), *sub = NULL;
        lb__cone S;
        memset(&S, 0, sizeof S);
        const int k = cases[c].k;
        const double rad = cases[c].spread ? k * 0.7 / (2.0 * M_PI) : 1.5;
        int fold = 0;
        for (size_t i = 0; i < ev->n; ++i) {
            const lb__instr *ins = &ev->ins[i];
            if (ins->code != LB__I_OP || ins->op->family != LB__F_LOCAL) continue;
            const int s_right = ++fold; /* the fold's right child: sphere number fold */
            const int lat = cases[c].spread == 2;
            const double centre[3] = {
                lat ? (s_right % 12) * 0.9 : rad * cos(2.0 * M_PI * s_right / k),
                lat ? (s_right / 12) * 0.9 : rad * sin(2.0 * M_PI * s_right / k),
                lat ? 0.05 * ((s_right * 7) % 5) : 0.2 * sin(7.0 * s_right)};
            if (ins->ncone[0] < 24) continue;
            for (int b = 0; b < 6; ++b) {
                /* boxes from a tenth of a unit to the whole scene, around the
                 * fold's own sphere (where its curves are found) or anywhere */
                const double half = b == 5 ? 0.5 * (bmax[0] - bmin[0]) : 0.05 * (1 << b);
                double bc[3], br[3] = {half, half, half};
                for (int d = 0; d < 3; ++d)
                    bc[d] = b % 2 ? rng_range(&R, bmin[d], bmax[d])
                                  : centre[d] + rng_range(&R, -0.3, 0.3);
                lb_error e = {LB_OK, ""};
                if (lb__cone_reduce(ev, ins->cone, ins->ncone[0], bc, br, &S, &e))
                    fail_msg("%s", e.message);
                assert_true(S.reduced);
                if (b < 2 && cases[c].spread == 1) {
                    kept += S.copied ? (double)S.ev.n / ins->ncone[0] : 1.0;
                    boxes += 1.0;
                }
                if (!S.copied) continue;
                sub = realloc(sub, lb__regs_len(&S.ev) * sizeof *sub);
                double x[LB__CHUNK], y[LB__CHUNK], z[LB__CHUNK];
                for (int j = 0; j < LB__CHUNK; ++j) {
                    x[j] = bc[0] + rng_range(&R, -br[0], br[0]);
                    y[j] = bc[1] + rng_range(&R, -br[1], br[1]);
                    z[j] = bc[2] + rng_range(&R, -br[2], br[2]);
                }
                if (lb__tape_run_list(ev, ins->cone, ins->ncone[0], LB__CHUNK, x, y, z, regs, &e) ||
                    lb__tape_run_counted(&S.ev, LB__CHUNK, x, y, z, sub, NULL, &e))
                    fail_msg("%s", e.message);
                for (int j = 0; j < LB__CHUNK; ++j) {
                    double dv = 0.0, mag = 1.0;
                    for (int q = 0; q < 4; ++q) {
                        const double a = lb__reg(regs, ins->src[0], q)[j],
                                     r2 = lb__reg(sub, S.out, q)[j];
                        dv = fmax(dv, fabs(a - r2));
                        mag = fmax(mag, fabs(a));
                    }
                    const double v = lb__reg(regs, ins->src[0], 0)[j];
                    tally_check(&eq, dv <= 1e-12 * mag, "%s ring %d, fold %zu: differs by %g",
                                cases[c].conv, cases[c].k, i, dv);
                    tally_check(&in, v >= S.root.lo && v <= S.root.hi,
                                "%s ring %d, fold %zu: %.17g outside [%g, %g]", cases[c].conv,
                                cases[c].k, i, v, S.root.lo, S.root.hi);
                }
            }
        }
        lb__cone_free(&S);
        free(sub);
        free(regs);
        lb_evaluator_free(ev);
        lb_scene_free(sc);
    }
    tally_end(&eq, 10000);
    tally_end(&in, 10000);
    printf("  spread rings, boxes of 0.1 and 0.2 around the fold's sphere: %.1f %% of the left "
           "child's instructions kept\n",
           100.0 * kept / boxes);
    assert_true(boxes >= 100.0 && kept / boxes <= 0.25);
}

static double compile_cost_of(char *text) {
    lb_scene *sc = parse(text);
    free(text);
    lb_evaluator *ev = compile(sc);
    const double c = lb_evaluator_compile_cost(ev);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return c;
}

/* The compile work of a flat local union grows about linearly in its
 * children where each meets a bounded number of others (each fold
 * evaluates only the children its boxes meet): 4x the children, at most
 * 4^1.2 the compile cost. Measured 2026-12-03: a spread ring 32 -> 128
 * spheres x1.23 (x2.6 before max groups and fold cones, x5.8 before any
 * reduction); a 12-wide lattice 48 -> 192 spheres x3.96 (x12.1 before). */
static void test_compile_cost_linear(void **st) {
    (void)st;
    const double ring[2] = {compile_cost_of(ring_scene(32, 1, "zero")),
                            compile_cost_of(ring_scene(128, 1, "zero"))};
    const double lat[2] = {compile_cost_of(lattice_scene(48)), compile_cost_of(lattice_scene(192))};
    printf("  compile cost: spread ring 32 spheres %.3g, 128 spheres %.3g (x%.2f, exponent %.2f)\n",
           ring[0], ring[1], ring[1] / ring[0], log(ring[1] / ring[0]) / log(4.0));
    printf("  compile cost: lattice 48 spheres %.3g, 192 spheres %.3g (x%.2f, exponent %.2f)\n",
           lat[0], lat[1], lat[1] / lat[0], log(lat[1] / lat[0]) / log(4.0));
    assert_true(ring[0] > 0.0 && ring[1] / ring[0] <= pow(4.0, 1.2));
    assert_true(lat[0] > 0.0 && lat[1] / lat[0] <= pow(4.0, 1.2));
}

/* The edited scene compiled against the previous evaluator: the same
 * evaluator as a fresh compile (curves described alike, the same compile
 * cost, the same values, gradients and interval bounds, bit for bit), with
 * exactly the expected local unions' curves copied. */
static void check_reuse(const char *label, char *before, char *after, size_t want_reused,
                        tally_t *t) {
    lb_scene *s0 = parse(before), *s1 = parse(after);
    free(before);
    free(after);
    lb_evaluator *prev = compile(s0), *fresh = compile(s1), *re = NULL;
    size_t reused = 99;
    lb_error e = {LB_OK, ""};
    if (lb_evaluator_create_reusing(s1, prev, &re, &reused, &e)) fail_msg("%s", e.message);
    lb_evaluator_free(prev); /* the copy owns its curves */
    tally_check(t, reused == want_reused, "%s: %zu local unions reused, want %zu", label, reused,
                want_reused);
    static char d0[1 << 16], d1[1 << 16];
    lb_evaluator_describe_local(fresh, d0, sizeof d0);
    lb_evaluator_describe_local(re, d1, sizeof d1);
    tally_check(t, !strcmp(d0, d1) && d0[0], "%s: the curves described alike", label);
    tally_check(t, lb_evaluator_compile_cost(fresh) == lb_evaluator_compile_cost(re),
                "%s: compile cost %.17g, fresh %.17g", label, lb_evaluator_compile_cost(re),
                lb_evaluator_compile_cost(fresh));
    double bmin[3], bmax[3];
    assert_true(lb_scene_bounds(s1, bmin, bmax));
    rng_t R = {99};
    enum { N = 4000 };
    static double x[N], y[N], z[N], v[2][N], gx[2][N], gy[2][N], gz[2][N];
    for (int i = 0; i < N; ++i) {
        x[i] = rng_range(&R, bmin[0], bmax[0]);
        y[i] = rng_range(&R, bmin[1], bmax[1]);
        z[i] = rng_range(&R, bmin[2], bmax[2]);
    }
    const lb_evaluator *E[2] = {fresh, re};
    for (int k = 0; k < 2; ++k)
        if (lb_evaluator_eval(E[k], N, x, y, z, v[k], gx[k], gy[k], gz[k], 2, &e))
            fail_msg("%s", e.message);
    tally_check(t,
                !memcmp(v[0], v[1], sizeof v[0]) && !memcmp(gx[0], gx[1], sizeof gx[0]) &&
                    !memcmp(gy[0], gy[1], sizeof gy[0]) && !memcmp(gz[0], gz[1], sizeof gz[0]),
                "%s: values and gradients bit for bit", label);
    for (int b = 0; b < 200; ++b) {
        double lo[3], hi[3], l[2], h[2];
        for (int d = 0; d < 3; ++d) {
            const double c = rng_range(&R, bmin[d], bmax[d]), r = rng_log(&R, 0.01, 2.0);
            lo[d] = c - r;
            hi[d] = c + r;
        }
        for (int k = 0; k < 2; ++k)
            if (lb_evaluator_bounds(E[k], lo, hi, &l[k], &h[k], &e)) fail_msg("%s", e.message);
        tally_check(t, !memcmp(l, l + 1, sizeof *l) && !memcmp(h, h + 1, sizeof *h),
                    "%s: interval bounds bit for bit", label);
    }
    lb_evaluator_free(fresh);
    lb_evaluator_free(re);
    lb_scene_free(s0);
    lb_scene_free(s1);
}

/* lb_evaluator_create_reusing: a flat local union of k children is a fold
 * of k - 1 binary ones, fold j joining the first j children with child j,
 * so moving child m copies the curves of folds 1 .. m - 1 and finds the
 * rest again; the same scene copies all; other bounds copy none (the
 * curves are searched inside the bounds); no previous evaluator, none. */
static void test_reuse_curves(void **st) {
    (void)st;
    tally_t t = {"compile reusing a previous evaluator's curves", 0, 0, 0};
    check_reuse("zero ring, sphere 9 of 12 moved", ring_scene_edit(12, 1, "zero", -1, 0, 0),
                ring_scene_edit(12, 1, "zero", 9, 0.05, 0), 8, &t);
    check_reuse("zero ring, the last sphere moved", ring_scene_edit(12, 1, "zero", -1, 0, 0),
                ring_scene_edit(12, 1, "zero", 11, -0.03, 0), 10, &t);
    check_reuse("zero ring, sphere 0 moved", ring_scene_edit(12, 1, "zero", -1, 0, 0),
                ring_scene_edit(12, 1, "zero", 0, 0.02, 0), 0, &t);
    check_reuse("soft ring, sphere 5 of 10 moved", ring_scene_edit(10, 1, "soft", -1, 0, 0),
                ring_scene_edit(10, 1, "soft", 5, 0.04, 0), 4, &t);
    check_reuse("zero ring, the same scene", ring_scene_edit(12, 1, "zero", 3, 0.01, 0),
                ring_scene_edit(12, 1, "zero", 3, 0.01, 0), 11, &t);
    check_reuse("zero ring, other bounds", ring_scene_edit(12, 1, "zero", -1, 0, 0),
                ring_scene_edit(12, 1, "zero", -1, 0, 0.5), 0, &t);
    /* no previous evaluator: a plain compile */
    char *text = ring_scene(8, 1, "zero");
    lb_scene *sc = parse(text);
    free(text);
    lb_evaluator *ev = NULL;
    size_t reused = 99;
    assert_int_equal(lb_evaluator_create_reusing(sc, NULL, &ev, &reused, NULL), LB_OK);
    tally_check(&t, reused == 0 && lb_evaluator_compile_cost(ev) > 0, "no previous: none reused");
    lb_evaluator_free(ev);
    assert_int_equal(lb_evaluator_create_reusing(sc, NULL, &ev, NULL, NULL), LB_OK);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    tally_end(&t, 1200);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reuse_curves),
        cmocka_unit_test(test_two_sphere_circle),
        cmocka_unit_test(test_component_counts),
        cmocka_unit_test(test_no_blend_at_a_distance),
        cmocka_unit_test(test_volume_border),
        cmocka_unit_test(test_drop_sweep),
        cmocka_unit_test(test_zero_convention_surface),
        cmocka_unit_test(test_cone_reduction),
        cmocka_unit_test(test_compile_cost_linear),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
