/* libFuzzer target for the scene parser and everything a parsed scene
 * reaches: compile, evaluate a few points (value and gradient), bound a box,
 * describe the tree. Built with clang under ASan + UBSan (LIBBLEND_FUZZ);
 * tests/fuzz/run_fuzz.sh runs it for a bounded time from the scenes/ corpus. */
#include <libblend/libblend.h>

#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    if (lb_scene_parse((const char *)data, size, "fuzz.json", &sc, &e) != LB_OK) {
        if (sc || e.status == LB_OK || !e.message[0]) abort(); /* a failure must explain itself */
        return 0;
    }
    const size_t need = lb_scene_describe(sc, NULL, 0);
    char *text = malloc(need + 1);
    if (text) {
        if (lb_scene_describe(sc, text, need + 1) != need) abort();
        free(text);
    }
    lb_evaluator *ev = NULL;
    if (lb_evaluator_create(sc, &ev, &e) == LB_OK) {
        const double x[5] = {0.0, 0.5, -1.25, 2.0, 0.125}, y[5] = {0.0, -0.5, 0.75, 1.0, 3.0},
                     z[5] = {0.0, 0.25, -0.5, -2.0, 0.0625};
        double v[5], gx[5], gy[5], gz[5], lo, hi;
        if (lb_evaluator_eval(ev, 5, x, y, z, v, gx, gy, gz, 1, &e) == LB_OK) {
            const double bmin[3] = {-1.5, -1.0, -0.75}, bmax[3] = {2.0, 3.0, 0.5};
            if (lb_evaluator_bounds(ev, bmin, bmax, &lo, &hi, &e) != LB_OK) abort();
            /* the bound holds at the points inside the box */
            for (int i = 1; i < 5; ++i)
                if (x[i] >= bmin[0] && x[i] <= bmax[0] && y[i] >= bmin[1] && y[i] <= bmax[1] &&
                    z[i] >= bmin[2] && z[i] <= bmax[2] && !(v[i] >= lo && v[i] <= hi))
                    abort();
        }
        lb_evaluator_free(ev);
    }
    lb_scene_free(sc);
    return 0;
}
