/* The library keeps no global state: the same calls made concurrently from
 * several threads give bit-identical results to a serial run. */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"

#include <pthread.h>

#define N_CALLS 50000
#define N_THREADS 4

typedef struct {
    double x[4], r[4], p[4], m[4], y[4];
} call_t;

static call_t calls[N_CALLS];
static double serial[N_CALLS][5];

static void run_one(const call_t *c, double out[5]) {
    double v, g[4];
    lb_displacement(LB_UNION, 4, c->x, c->r, c->p, c->m, &v, g, NULL);
    out[0] = v;
    out[1] = g[0];
    lb_scale(LB_INTERSECTION, 4, c->x, c->y, c->p, &v, g, NULL);
    out[2] = v;
    double r1[4];
    for (int i = 0; i < 4; ++i) r1[i] = c->y[i];
    lb_soft_hyper(LB_UNION, 4, c->y, r1, c->p, c->m, &v, g, NULL);
    out[3] = v;
    const double cr[2] = {c->r[0], c->r[1]}, cm[2] = {c->m[0], c->m[1]};
    lb_conic(LB_DIFFERENCE, c->x, cr, 0.0, cm, &v, g, NULL);
    out[4] = v;
}

typedef struct {
    int first;
    long mismatches;
} job_t;

static void *worker(void *arg) {
    job_t *j = arg;
    for (int n = 0; n < N_CALLS; ++n) {
        const int i = (n + j->first * (N_CALLS / N_THREADS)) % N_CALLS; /* different orders */
        double out[5];
        run_one(&calls[i], out);
        if (memcmp(out, serial[i], sizeof out) != 0) j->mismatches++;
    }
    return NULL;
}

static void test_concurrent_calls(void **state) {
    (void)state;
    rng_t g = {71};
    for (int n = 0; n < N_CALLS; ++n) {
        call_t *c = &calls[n];
        for (int i = 0; i < 4; ++i) {
            c->x[i] = rng_range(&g, -1.0, 1.0);
            c->r[i] = rng_log(&g, 0.05, 2.0);
            c->p[i] = rng_p(&g);
            c->m[i] = rng_log(&g, 0.2, 5.0);
            c->y[i] = rng_range(&g, 0.01, 1.0);
        }
        run_one(c, serial[n]);
    }
    pthread_t th[N_THREADS];
    job_t jobs[N_THREADS];
    for (int t = 0; t < N_THREADS; ++t) {
        jobs[t] = (job_t){t, 0};
        assert_int_equal(pthread_create(&th[t], NULL, worker, &jobs[t]), 0);
    }
    long bad = 0;
    for (int t = 0; t < N_THREADS; ++t) {
        pthread_join(th[t], NULL);
        bad += jobs[t].mismatches;
    }
    fprintf(stderr, "  %d threads x %d calls x 4 operators: %ld mismatches\n", N_THREADS, N_CALLS,
            bad);
    assert_int_equal(bad, 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_concurrent_calls)};
    return cmocka_run_group_tests_name("threads", tests, NULL, NULL);
}
