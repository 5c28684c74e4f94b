/* Renders without holes: every scene in scenes/ is rendered by POV-Ray as a silhouette (blendtool
 * render --silhouette, 240 x 180) and compared by OpenImageIO's idiff with
 * a silhouette made by libblend itself: its mesh (384 cells across) projected
 * through the same camera (lb_pov_camera). At least 99 % of the pixels must
 * agree, and POV-Ray must not warn that max_gradient was too low.
 *
 * Usage: test_pov_silhouette BLENDTOOL SOURCE_DIR WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define W 240
#define H 180

static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static void unit(double *a) {
    const double l = sqrt(dot(a, a));
    for (int d = 0; d < 3; ++d) a[d] /= l;
}

static int silhouette(const lb_scene *sc, const lb_mesh *m, unsigned char *img) {
    const double aspect = (double)W / H;
    double loc[3], at[3], sky[3], angle;
    lb_pov_camera(sc, aspect, loc, at, sky, &angle);
    /* the right-handed view the exporter asks POV-Ray for: right = forward x up */
    double D[3] = {at[0] - loc[0], at[1] - loc[1], at[2] - loc[2]}, R[3], U[3];
    unit(D);
    cross(D, sky, R);
    unit(R);
    cross(R, D, U);
    unit(U);
    const double dlen = 0.5 * aspect / tan(0.5 * angle * M_PI / 180.0);
    double *px = malloc(2 * m->nvertices * sizeof *px);
    if (!px) return -1;
    for (size_t i = 0; i < m->nvertices; ++i) {
        const double *X = m->positions + 3 * i;
        const double p[3] = {X[0] - loc[0], X[1] - loc[1], X[2] - loc[2]};
        const double zc = dot(p, D);
        const double u = dot(p, R) / zc * dlen / aspect, v = dot(p, U) / zc * dlen;
        px[2 * i] = (u + 0.5) * W - 0.5;
        px[2 * i + 1] = (0.5 - v) * H - 0.5;
    }
    memset(img, 0, 3 * W * H);
    for (size_t t = 0; t < m->ntriangles; ++t) {
        const double *a = px + 2 * m->triangles[3 * t], *b = px + 2 * m->triangles[3 * t + 1],
                     *c = px + 2 * m->triangles[3 * t + 2];
        const int x0 = (int)fmax(0, floor(fmin(a[0], fmin(b[0], c[0])))),
                  x1 = (int)fmin(W - 1, ceil(fmax(a[0], fmax(b[0], c[0])))),
                  y0 = (int)fmax(0, floor(fmin(a[1], fmin(b[1], c[1])))),
                  y1 = (int)fmin(H - 1, ceil(fmax(a[1], fmax(b[1], c[1]))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double e0 = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
                const double e1 = (c[0] - b[0]) * (y - b[1]) - (c[1] - b[1]) * (x - b[0]);
                const double e2 = (a[0] - c[0]) * (y - c[1]) - (a[1] - c[1]) * (x - c[0]);
                if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))
                    memset(img + 3 * (y * W + x), 255, 3);
            }
    }
    free(px);
    return 0;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: test_pov_silhouette BLENDTOOL SOURCE_DIR WORK_DIR\n");
        return 2;
    }
    char dirp[4096];
    snprintf(dirp, sizeof dirp, "%s/scenes", argv[2]);
    DIR *dir = opendir(dirp);
    if (!dir) return 1;
    struct dirent *ent;
    int fails = 0, n = 0;
    static unsigned char img[3 * W * H];
    while ((ent = readdir(dir))) {
        const size_t l = strlen(ent->d_name);
        if (l < 6 || strcmp(ent->d_name + l - 5, ".json")) continue;
        char path[8192], png[4096], ppm[4096], log[4096], cmd[32768];
        snprintf(path, sizeof path, "%s/%s", dirp, ent->d_name);
        snprintf(png, sizeof png, "%s/sil-pov.png", argv[3]);
        snprintf(ppm, sizeof ppm, "%s/sil-mesh.ppm", argv[3]);
        snprintf(log, sizeof log, "%s/sil.log", argv[3]);
        remove(png);
        snprintf(cmd, sizeof cmd,
                 "'%s' render '%s' -o '%s' --width %d --height %d --silhouette --threads 2 > "
                 "'%s' 2>&1",
                 argv[1], path, png, W, H, log);
        if (system(cmd) != 0) {
            fprintf(stderr, "%s: render failed (see %s)\n", path, log);
            ++fails;
            continue;
        }
        snprintf(cmd, sizeof cmd, "grep -q 'may contain holes' '%s'", log);
        if (system(cmd) == 0) {
            fprintf(stderr, "%s: POV-Ray found a gradient above max_gradient\n", path);
            ++fails;
        }
        lb_error e;
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        lb_mesh *m = NULL;
        lb_mesh_options o;
        lb_mesh_options_init(&o);
        o.resolution = 384;
        if (lb_scene_load(path, &sc, &e) || lb_evaluator_create(sc, &ev, &e) ||
            !lb_scene_bounds(sc, o.bmin, o.bmax) || lb_mesh_create(ev, &o, &m, &e) ||
            silhouette(sc, m, img)) {
            fprintf(stderr, "%s: %s\n", path, e.message);
            return 1;
        }
        FILE *f = fopen(ppm, "wb");
        fprintf(f, "P6\n%d %d\n255\n", W, H);
        fwrite(img, 1, sizeof img, f);
        fclose(f);
        /* idiff: FAILURE when more than 1 % of the pixels differ by more than 0.5 */
        snprintf(cmd, sizeof cmd, "idiff -v -fail 0.5 -failpercent 1 '%s' '%s' > '%s' 2>&1", png,
                 ppm, log);
        const int rc = system(cmd);
        snprintf(cmd, sizeof cmd, "grep -E 'over 0.5|PASS|FAIL' '%s' | head -2 | tr '\\n' ' '",
                 log);
        fprintf(stderr, "  %-40s ", ent->d_name);
        fflush(stderr);
        if (system(cmd)) {
        }
        fprintf(stderr, "\n");
        if (!(WIFEXITED(rc) && (WEXITSTATUS(rc) == 0 || WEXITSTATUS(rc) == 1))) {
            fprintf(stderr, "%s: silhouettes differ on more than 1 %% of the pixels\n", path);
            ++fails;
        }
        lb_mesh_free(m);
        lb_evaluator_free(ev);
        lb_scene_free(sc);
        ++n;
    }
    closedir(dir);
    fprintf(stderr, "%d scenes, %d failures\n", n, fails);
    return fails || n < 15 ? 1 : 0;
}
