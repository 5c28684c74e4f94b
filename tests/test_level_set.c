/* lb_level_set_create: narrow-band level sets against closed forms.
 *
 * - Random unions (min) of 1 to 4 spheres, zero convention: a sphere's
 *   field is |X - c| / r - 1, so the distance estimate f / |grad f| is
 *   |X - c_k| - r_k for the sphere k that attains the min. Every stored
 *   voxel of the region holds it (active: to float rounding) or, inactive,
 *   +-background with its sign; every voxel of the whole region whose
 *   estimate is under the band is active (none is missed by the leaf
 *   selection); the extra grids hold f and grad f; the leaves are in (x, y,
 *   z) order with first voxels on multiples of 8.
 * - A soft sphere (Wyvill kernel): phi = 0.5 - K(rho), the sign and the
 *   estimate from the kernel's closed form.
 * - The same bits for 1, 2 and 3 threads (S2, 64 blended spheres).
 * - Options out of range (a region past 32-bit voxel indices too), the
 *   memory cap and the cancel flag: the status,
 *   a message with the allowed range, and no level set. */
#include "testlib.h"

#include <libblend/volume.h>

#include <stdlib.h>

#define HEAD "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"%s\", \"root\": "
#define HEADZERO                                                                                   \
    "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\", \"root\": "
#define HEADSOFT                                                                                   \
    "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"soft\", \"root\": "

static lb_evaluator *compile(const char *text) {
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse(text, strlen(text), "x.json", &sc, &e)) fail_msg("%s\n%s", e.message, text);
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    lb_scene_free(sc);
    return ev;
}

static void region(lb_level_set_options *o, double lo, double hi) {
    for (int d = 0; d < 3; ++d) {
        o->bmin[d] = lo;
        o->bmax[d] = hi;
    }
}

/* the leaf slot of voxel I, or -1 */
static long find_leaf(const lb_level_set *L, const long I[3]) {
    for (size_t i = 0; i < L->nleaves; ++i) {
        int in = 1;
        for (int d = 0; d < 3; ++d)
            in &= I[d] >= L->origins[3 * i + d] && I[d] < L->origins[3 * i + d] + 8;
        if (in) return (long)i;
    }
    return -1;
}

static void test_sphere_unions(void **state) {
    (void)state;
    rng_t rng = {4242};
    tally_t t = {"sphere unions: values, band, sign", 0, 0, 0};
    for (int trial = 0; trial < 24; ++trial) {
        const int k = (int)rng_int(&rng, 1, 4);
        double c[4][3], r[4];
        char text[2048];
        int n = snprintf(text, sizeof text, HEAD "{\"type\": \"min\", \"args\": [", "zero");
        for (int i = 0; i < k; ++i) {
            for (int d = 0; d < 3; ++d) c[i][d] = rng_range(&rng, -0.6, 0.6);
            r[i] = rng_range(&rng, 0.2, 0.7);
            n += snprintf(text + n, sizeof text - (size_t)n,
                          "%s{\"type\": \"sphere\", \"center\": [%.17g, %.17g, %.17g], "
                          "\"radius\": %.17g}",
                          i ? ", " : "", c[i][0], c[i][1], c[i][2], r[i]);
        }
        snprintf(text + n, sizeof text - (size_t)n, "]}}");
        lb_evaluator *ev = compile(text);
        lb_level_set_options o;
        lb_level_set_options_init(&o);
        region(&o, -1.5 + 0.01 * trial, 1.5);
        o.resolution = (unsigned)rng_int(&rng, 16, 40);
        o.band = rng_range(&rng, 1.0, 4.0);
        o.threads = 2;
        o.flags = LB_LEVEL_SET_FIELD | LB_LEVEL_SET_GRADIENT;
        lb_level_set *L = NULL;
        lb_error e = {LB_OK, ""};
        assert_int_equal(lb_level_set_create(ev, &o, &L, &e), LB_OK);
        const double h = L->voxel_size, bg = L->background;
        tally_check(&t, fabs(h - 3.0 / o.resolution + 0.01 * trial / o.resolution) < 1e-12,
                    "voxel size %g", h);
        tally_check(&t, bg == (float)(o.band * h), "background %g", bg);
        size_t nactive = 0;
        for (size_t i = 0; i < L->nleaves; ++i) {
            for (int d = 0; d < 3; ++d) tally_check(&t, L->origins[3 * i + d] % 8 == 0, "origin");
            if (i) {
                const int32_t *a = L->origins + 3 * (i - 1), *b = L->origins + 3 * i;
                tally_check(&t,
                            a[0] < b[0] ||
                                (a[0] == b[0] && (a[1] < b[1] || (a[1] == b[1] && a[2] < b[2]))),
                            "leaf order");
            }
        }
        /* every voxel of the region */
        long I[3];
        for (I[0] = L->imin[0]; I[0] <= L->imax[0]; ++I[0])
            for (I[1] = L->imin[1]; I[1] <= L->imax[1]; ++I[1])
                for (I[2] = L->imin[2]; I[2] <= L->imax[2]; ++I[2]) {
                    const double X[3] = {I[0] * h, I[1] * h, I[2] * h};
                    int best = 0;
                    double fb = INFINITY, dist = 0;
                    for (int s = 0; s < k; ++s) {
                        const double q = sqrt((X[0] - c[s][0]) * (X[0] - c[s][0]) +
                                              (X[1] - c[s][1]) * (X[1] - c[s][1]) +
                                              (X[2] - c[s][2]) * (X[2] - c[s][2]));
                        if (q / r[s] - 1.0 < fb) {
                            fb = q / r[s] - 1.0;
                            best = s;
                            dist = q;
                        }
                    }
                    const double est = dist - r[best];
                    const long li = find_leaf(L, I);
                    if (li < 0) {
                        tally_check(&t, fabs(est) >= bg * (1 - 1e-6),
                                    "voxel (%ld %ld %ld) estimate %g within the band %g is in "
                                    "no leaf",
                                    I[0], I[1], I[2], est, bg);
                        continue;
                    }
                    const int nn = (int)((I[0] - L->origins[3 * li]) * 64 +
                                         (I[1] - L->origins[3 * li + 1]) * 8 +
                                         (I[2] - L->origins[3 * li + 2]));
                    const size_t at = (size_t)li * 512 + (size_t)nn;
                    const int on = (int)((L->active[li * 8 + nn / 64] >> (nn % 64)) & 1u);
                    const float v = L->values[at];
                    nactive += (size_t)on;
                    if (on) {
                        tally_check(&t, fabs(v - est) <= 1e-6 * (1 + fabs(est)) && fabs(v) < bg,
                                    "active value %g, closed form %g", v, est);
                        tally_check(&t, fabs(L->fields[at] - fb) <= 1e-6 * (1 + fabs(fb)),
                                    "field %g, closed form %g", L->fields[at], fb);
                        for (int d = 0; d < 3; ++d) {
                            const double g = (X[d] - c[best][d]) / (dist * r[best]);
                            tally_check(&t,
                                        fabs(L->gradients[3 * at + d] - g) <= 1e-5 * (1 + fabs(g)),
                                        "gradient %g, closed form %g", L->gradients[3 * at + d], g);
                        }
                    } else {
                        tally_check(&t, fabs(est) >= bg * (1 - 1e-6),
                                    "voxel estimate %g within the band %g is inactive", est, bg);
                        tally_check(&t, v == (est < 0 ? -bg : bg) || est == 0,
                                    "inactive value %g, estimate %g", v, est);
                    }
                }
        tally_check(&t, nactive == L->nactive, "nactive %zu, counted %zu", L->nactive, nactive);
        tally_check(&t, L->nactive > 0, "some active voxels");
        lb_level_set_free(L);
        lb_evaluator_free(ev);
    }
    tally_end(&t, 100000);
}

/* a soft sphere: rho = |X| / 0.8, K(rho) = W(rho / 2), W(a) = 1 - 4/9 a^6
 * + 17/9 a^4 - 22/9 a^2 (0 beyond a = 1) */
static void test_soft_sphere(void **state) {
    (void)state;
    lb_evaluator *ev =
        compile(HEADSOFT "{\"type\": \"sphere\", \"radius\": 0.8, \"kernel\": \"wyvill\"}}");
    assert_int_equal(lb_evaluator_convention(ev), LB_CONVENTION_SOFT);
    lb_level_set_options o;
    lb_level_set_options_init(&o);
    region(&o, -1.2, 1.2);
    o.resolution = 32;
    o.threads = 1;
    lb_level_set *L = NULL;
    assert_int_equal(lb_level_set_create(ev, &o, &L, NULL), LB_OK);
    tally_t t = {"soft sphere: phi = 0.5 - K", 0, 0, 0};
    for (size_t i = 0; i < L->nleaves; ++i)
        for (int n = 0; n < 512; ++n) {
            const long I[3] = {L->origins[3 * i] + n / 64, L->origins[3 * i + 1] + n / 8 % 8,
                               L->origins[3 * i + 2] + n % 8};
            int in = 1;
            for (int d = 0; d < 3; ++d) in &= I[d] >= L->imin[d] && I[d] <= L->imax[d];
            if (!in) continue;
            const double q =
                sqrt((double)(I[0] * I[0] + I[1] * I[1] + I[2] * I[2])) * L->voxel_size;
            const double a = q / 0.8 / 2.0;
            const double K =
                a >= 1 ? 0 : 1 - 4.0 / 9 * pow(a, 6) + 17.0 / 9 * pow(a, 4) - 22.0 / 9 * a * a;
            const double dK = a >= 1
                                  ? 0
                                  : (-24.0 / 9 * pow(a, 5) + 68.0 / 9 * pow(a, 3) - 44.0 / 9 * a) /
                                        (2 * 0.8); /* d K / d|X| */
            const double phi = 0.5 - K, est = dK != 0 ? phi / fabs(dK) : NAN;
            const int on = (int)((L->active[8 * i + (size_t)n / 64] >> (n % 64)) & 1u);
            const float v = L->values[512 * i + (size_t)n];
            tally_check(&t, (v < 0) == (phi < 0), "sign at |X| = %g: %g, phi %g", q, v, phi);
            if (on)
                tally_check(&t, fabs(v - est) <= 1e-5 * (1 + fabs(est)),
                            "value at |X| = %g: %g, closed form %g", q, v, est);
        }
    tally_end(&t, 5000);
    lb_level_set_free(L);
    lb_evaluator_free(ev);
}

static char *read_text(const char *path) {
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_true(s && fread(s, 1, (size_t)n, f) == (size_t)n);
    s[n] = '\0';
    fclose(f);
    return s;
}

static void test_threads_identical(void **state) {
    (void)state;
    char *text = read_text(SOURCE_DIR "/scenes/bench-s2-64-spheres.json");
    lb_evaluator *ev = compile(text);
    free(text);
    lb_level_set *L[3] = {NULL, NULL, NULL};
    for (int t = 0; t < 3; ++t) {
        lb_level_set_options o;
        lb_level_set_options_init(&o);
        region(&o, -1.3, 1.3);
        o.resolution = 48;
        o.threads = t + 1;
        o.flags = LB_LEVEL_SET_GRADIENT;
        assert_int_equal(lb_level_set_create(ev, &o, &L[t], NULL), LB_OK);
    }
    assert_true(L[0]->nleaves > 50);
    for (int t = 1; t < 3; ++t) {
        assert_int_equal(L[t]->nleaves, L[0]->nleaves);
        assert_int_equal(L[t]->nactive, L[0]->nactive);
        const size_t n = L[0]->nleaves;
        assert_memory_equal(L[t]->origins, L[0]->origins, 3 * n * sizeof(int32_t));
        assert_memory_equal(L[t]->values, L[0]->values, 512 * n * sizeof(float));
        assert_memory_equal(L[t]->active, L[0]->active, 8 * n * sizeof(uint64_t));
        assert_memory_equal(L[t]->gradients, L[0]->gradients, 3 * 512 * n * sizeof(float));
        assert_null(L[t]->fields);
    }
    for (int t = 0; t < 3; ++t) lb_level_set_free(L[t]);
    lb_evaluator_free(ev);
}

static void refused(const lb_evaluator *ev, const lb_level_set_options *o, lb_status want,
                    const char *allowed) {
    lb_level_set *L = (lb_level_set *)1;
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_level_set_create(ev, o, &L, &e);
    if (s != want || L != NULL || !strstr(e.message, allowed))
        fail_msg("status %d (want %d), message \"%s\" (want \"%s\")", s, want, e.message, allowed);
}

static void test_refusals(void **state) {
    (void)state;
    lb_evaluator *ev = compile(HEADZERO "{\"type\": \"sphere\", \"radius\": 0.8}}");
    lb_level_set_options o;
    lb_level_set_options_init(&o);
    region(&o, -1, 1);
    o.band = 0.5;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: 1 to 32 voxels");
    o.band = 33;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: 1 to 32 voxels");
    o.band = NAN;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: 1 to 32 voxels");
    o.band = 3;
    o.resolution = 0;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: 1 to 8192 voxels");
    o.resolution = 8193;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: 1 to 8192 voxels");
    o.resolution = 16;
    o.voxel_size = 1e-4;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "at most 8192 voxels per axis");
    o.voxel_size = -1;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "a positive number");
    /* far from the origin in voxels: indices past 32 bits */
    o.voxel_size = 1e-6;
    o.bmin[0] = 1e5;
    o.bmax[0] = 1e5 + 1e-3;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "voxel indices are 32-bit");
    region(&o, -1, 1);
    o.voxel_size = 0.5;
    o.bmax[1] = -1;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "min < max");
    o.bmax[1] = 1;
    o.bmin[2] = 0.1;
    o.bmax[2] = 0.2; /* no lattice point between */
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "no voxel inside the region");
    region(&o, -1, 1);
    o.voxel_size = 0;
    o.flags = 64;
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "allowed: LB_LEVEL_SET_FIELD");
    o.flags = 0;
    o.resolution = 256;
    o.max_memory = 100000; /* a few leaves */
    refused(ev, &o, LB_ERR_INVALID_ARGUMENT, "memory cap");
    o.max_memory = 0;
    const volatile int stop = 1;
    o.cancel = &stop;
    refused(ev, &o, LB_ERR_CANCELLED, "cancelled");
    o.cancel = NULL;
    /* no surface in the region: an empty level set */
    region(&o, 2, 3);
    lb_level_set *L = NULL;
    assert_int_equal(lb_level_set_create(ev, &o, &L, NULL), LB_OK);
    assert_int_equal(L->nleaves, 0);
    assert_int_equal(L->nactive, 0);
    lb_level_set_free(L);
    lb_level_set_free(NULL);
    lb_evaluator_free(ev);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_unions),
        cmocka_unit_test(test_soft_sphere),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
