/* Affine maps y = M x + t: how node transforms are stored and composed. */
#include "scene_internal.h"

#include <string.h>

void lb__affine_identity(lb__affine *a) {
    memset(a, 0, sizeof *a);
    a->M[0] = a->M[4] = a->M[8] = 1.0;
}

void lb__affine_compose(const lb__affine *a, const lb__affine *b, lb__affine *c) {
    lb__affine out;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            out.M[3 * i + j] = a->M[3 * i] * b->M[j] + a->M[3 * i + 1] * b->M[3 + j] +
                               a->M[3 * i + 2] * b->M[6 + j];
        out.t[i] =
            a->M[3 * i] * b->t[0] + a->M[3 * i + 1] * b->t[1] + a->M[3 * i + 2] * b->t[2] + a->t[i];
    }
    *c = out;
}

void lb__affine_apply(const lb__affine *a, const double x[3], double y[3]) {
    double out[3];
    for (int i = 0; i < 3; ++i)
        out[i] = a->M[3 * i] * x[0] + a->M[3 * i + 1] * x[1] + a->M[3 * i + 2] * x[2] + a->t[i];
    memcpy(y, out, sizeof out);
}

void lb__affine_pullback(const lb__affine *a, const double g[3], double out[3]) {
    double o[3];
    for (int j = 0; j < 3; ++j) o[j] = a->M[j] * g[0] + a->M[3 + j] * g[1] + a->M[6 + j] * g[2];
    memcpy(out, o, sizeof o);
}

int lb__affine_is_identity(const lb__affine *a) {
    static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int i = 0; i < 9; ++i)
        if (a->M[i] != id[i]) return 0;
    return a->t[0] == 0.0 && a->t[1] == 0.0 && a->t[2] == 0.0;
}
