/* blend_demo: the README's main job until blendtool exists. Evaluates the
 * hsu2006 figure-7 style blend along a line: the rounded cube (intersection
 * of three slabs) in union with a super-ellipsoid, for m2 = 1.2, 0.9, 0.6,
 * 0.3, and prints value and gradient. */
#include <libblend/libblend.h>

#include <math.h>
#include <stdio.h>

static int check(lb_status s, const lb_error *e) {
    if (s != LB_OK) {
        fprintf(stderr, "blend_demo: %s\n", e->message);
        return 1;
    }
    return 0;
}

int main(void) {
    lb_error e = {LB_OK, ""};
    lb_primitive slab[3], sq;
    const double o[3] = {0, 0, 0}, axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 3; ++i)
        if (check(lb_primitive_slab(&slab[i], o, axes[i], 1.0, &e), &e)) return 1;
    const double c[3] = {0.9, 0.9, 0.9}, a[3] = {0.6, 0.6, 0.6};
    if (check(lb_primitive_superquadric(&sq, c, a, 0.5, 0.5, &e), &e)) return 1;

    const double ms[4] = {1.2, 0.9, 0.6, 0.3};
    printf("libblend %d: rounded cube (BT_3 intersection of slabs) union super-ellipsoid (BT_2)\n",
           lb_version());
    printf("%6s %8s %22s %22s\n", "m2", "t", "value", "|grad|");
    for (int mi = 0; mi < 4; ++mi) {
        for (int s = 0; s <= 4; ++s) {
            const double t = 0.7 + 0.1 * s;
            const double X[3] = {t, t, t};
            double f[3], g[3][3], cube, gc[3], sv, gs[3];
            for (int i = 0; i < 3; ++i) f[i] = lb_primitive_eval(&slab[i], X, g[i]);
            const double r3[3] = {0.3, 0.3, 0.3}, p3[3] = {2, 2, 2};
            if (check(lb_displacement(LB_INTERSECTION, 3, f, r3, p3, NULL, &cube, gc, &e), &e))
                return 1;
            sv = lb_primitive_eval(&sq, X, gs);
            const double x2[2] = {cube, sv}, r2[2] = {0.4, 0.4}, p2[2] = {2, 2},
                         m2[2] = {1.0, ms[mi]};
            double v, gv[2];
            if (check(lb_displacement(LB_UNION, 2, x2, r2, p2, m2, &v, gv, &e), &e)) return 1;
            double G[3] = {0, 0, 0};
            for (int d = 0; d < 3; ++d) {
                for (int i = 0; i < 3; ++i) G[d] += gv[0] * gc[i] * g[i][d];
                G[d] += gv[1] * gs[d];
            }
            printf("%6.2f %8.3f %22.17g %22.17g\n", ms[mi], t, v,
                   sqrt(G[0] * G[0] + G[1] * G[1] + G[2] * G[2]));
        }
    }
    return 0;
}
