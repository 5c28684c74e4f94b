/* blend_demo: the README's main job until blendtool exists (issue 3).
 *
 * The default scene is the hsu2006 figure-7 setting: a rounded cube (BT_3
 * intersection of three slabs) in union with a super-ellipsoid, blended by
 * BT_2 with the super-ellipsoid's subsequent-blend parameter m2 = 1.2, 0.9,
 * 0.6, 0.3. It walks a ray from the cube's centre through the junction,
 * finds where the ray leaves the blended solid (f = 0) by bisection on the
 * library's field, and prints that exit distance and the analytic normal
 * there for each m2, next to the field value at two points off the surface.
 * It shows the papers' point: the surface does not move with m2 (the exit
 * point is the same to the last digits), while the field around it - what a
 * subsequent blend sees - changes with m2. */
#include <libblend/libblend.h>

#include <math.h>
#include <stdio.h>

typedef struct {
    lb_primitive slab[3], blob;
    double m2;
} scene;

/* field and spatial gradient of the scene at X; returns 0 on failure */
static int field(const scene *s, const double X[3], double *f, double G[3], lb_error *e) {
    double fi[3], gi[3][3], cube, gc[3], gb[3];
    for (int i = 0; i < 3; ++i) fi[i] = lb_primitive_eval(&s->slab[i], X, gi[i]);
    const double r3[3] = {0.25, 0.25, 0.25}, p3[3] = {2, 2, 2};
    if (lb_displacement(LB_INTERSECTION, 3, fi, r3, p3, NULL, &cube, gc, e)) return 0;
    const double fb = lb_primitive_eval(&s->blob, X, gb);
    const double x2[2] = {cube, fb}, r2[2] = {0.5, 0.5}, p2[2] = {2.5, 2.5}, m[2] = {1.0, s->m2};
    double g2[2];
    if (lb_displacement(LB_UNION, 2, x2, r2, p2, m, f, g2, e)) return 0;
    for (int d = 0; d < 3; ++d) {
        G[d] = g2[1] * gb[d];
        for (int i = 0; i < 3; ++i) G[d] += g2[0] * gc[i] * gi[i][d];
    }
    return 1;
}

int main(void) {
    lb_error e = {LB_OK, ""};
    scene s;
    const double o[3] = {0, 0, 0}, ax[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const double c[3] = {1.1, 0.0, 0.0}, a[3] = {0.9, 0.6, 0.6};
    int ok = 1;
    for (int i = 0; i < 3; ++i) ok &= lb_primitive_slab(&s.slab[i], o, ax[i], 1.0, &e) == LB_OK;
    ok &= lb_primitive_superquadric(&s.blob, c, a, 0.6, 0.6, &e) == LB_OK;
    if (!ok) {
        fprintf(stderr, "blend_demo: %s\n", e.message);
        return 1;
    }
    printf("libblend %d.%d.%d demo: rounded cube U super-ellipsoid (hsu2006 Fig. 7 setting)\n",
           lb_version() / 10000, lb_version() / 100 % 100, lb_version() % 100);
    printf("ray from the cube centre; exit distance t and unit normal where f = 0;\n"
           "field f at P = (1.3, 0.9, 0) outside and Q = (0.9, 0.5, 0) inside\n\n");
    const double dirs[2][3] = {{0.8, 0.6, 0.0}, {0.0, 0.0, 1.0}};
    const char *names[2] = {"through the junction", "away from it"};
    for (int d = 0; d < 2; ++d) {
        printf("%s, direction (%.1f, %.1f, %.1f)\n", names[d], dirs[d][0], dirs[d][1], dirs[d][2]);
        printf("  %5s %20s   %-32s %10s %10s\n", "m2", "t", "normal", "f(P)", "f(Q)");
        const double ms[4] = {1.2, 0.9, 0.6, 0.3};
        for (int k = 0; k < 4; ++k) {
            s.m2 = ms[k];
            double lo = 0.0, hi = 4.0, f, G[3], X[3];
            for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) { /* f < 0 inside */
                const double t = 0.5 * (lo + hi);
                for (int i = 0; i < 3; ++i) X[i] = t * dirs[d][i];
                if (!field(&s, X, &f, G, &e)) {
                    fprintf(stderr, "blend_demo: %s\n", e.message);
                    return 1;
                }
                if (f < 0)
                    lo = t;
                else
                    hi = t;
            }
            for (int i = 0; i < 3; ++i) X[i] = lo * dirs[d][i];
            field(&s, X, &f, G, &e);
            const double n = sqrt(G[0] * G[0] + G[1] * G[1] + G[2] * G[2]);
            const double P[3] = {1.3, 0.9, 0.0}, Q[3] = {0.9, 0.5, 0.0};
            double fp, fq, Gp[3];
            field(&s, P, &fp, Gp, &e);
            field(&s, Q, &fq, Gp, &e);
            printf("  %5.2f %20.15f   (%+.6f, %+.6f, %+.6f) %+10.5f %+10.5f\n", ms[k], lo, G[0] / n,
                   G[1] / n, G[2] / n, fp, fq);
        }
    }
    return 0;
}
