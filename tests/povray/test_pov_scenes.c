/* Whole scenes through POV-Ray: every scene in scenes/ and tests/data/scenes
 * is exported by lb_scene_write_pov (include-only), POV-Ray evaluates the
 * field LB_Field at 300 points of the scene's bounds, and each value must
 * match the compiled evaluator within 1e-9 (1e-6 for scenes with bulge
 * elimination, whose POV-Ray form takes gradients by central differences).
 * S2's 64-argument displacement blend goes through the include's
 * any-arity path. A scene POV-Ray cannot express (a scale blend of more than
 * 16 arguments) must be refused with a message naming the node. Also checks
 * that the generated identifiers never carry user text.
 *
 * Usage: test_pov_scenes SOURCE_DIR WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include <libblend/libblend.h>

#include "../../libblend/src/evaluation/tape.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int check_scene(const char *src, const char *work, const char *path, int *checked) {
    lb_error e = {LB_OK, ""};
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    if (lb_scene_load(path, &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "%s: %s\n", path, e.message);
        return 1;
    }
    char pov[4096], out[4096], cmd[16384];
    snprintf(pov, sizeof pov, "%s/scene.pov", work);
    snprintf(out, sizeof out, "%s/scene.txt", work);
    lb_pov_options o = {1, 0, 0.0, 0.0, 1, 0, 0, 0.0, 0};
    const lb_status s = lb_scene_write_pov(sc, ev, &o, pov, NULL, &e);
    if (s) {
        fprintf(stderr, "%s: %s\n", path, e.message);
        return 1;
    }
    const int bulge = strstr(path, "fig9") != NULL || strstr(path, "all-families") != NULL;
    double lo[3], hi[3];
    lb_scene_bounds(sc, lo, hi);
    enum { N = 300 };
    double x[N], y[N], z[N], v[N];
    uint64_t st = 12345;
    for (int i = 0; i < N; ++i) {
        double u[3];
        for (int d = 0; d < 3; ++d) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            u[d] = (double)(st >> 11) * 0x1.0p-53;
        }
        x[i] = lo[0] + (hi[0] - lo[0]) * u[0];
        y[i] = lo[1] + (hi[1] - lo[1]) * u[1];
        z[i] = lo[2] + (hi[2] - lo[2]) * u[2];
    }
    /* local unions: half the points within R of the curves, where the
     * blending volumes act (from every local_union, in turn) */
    int near = 0;
    for (size_t w = 0; near < N / 2; ++w) {
        const struct lb__curves *C = lb__local_nth(ev, w);
        if (!C) {
            if (w == 0 || !near) break;
            w = (size_t)-1; /* round again */
            continue;
        }
        for (size_t c = 0; c < C->ncomp && near < N / 2; ++c, ++near) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            const lb__component *K = &C->comp[c];
            const double *P = C->pts + 3 * (K->first + (st >> 33) % K->count);
            double o[3];
            for (int d = 0; d < 3; ++d) {
                st = st * 6364136223846793005ull + 1442695040888963407ull;
                o[d] = ((double)(st >> 11) * 0x1.0p-53 * 2.0 - 1.0) * 0.9 * K->R;
            }
            x[near] = P[0] + o[0];
            y[near] = P[1] + o[1];
            z[near] = P[2] + o[2];
        }
    }
    if (lb_evaluator_eval(ev, N, x, y, z, v, NULL, NULL, NULL, 1, &e)) {
        fprintf(stderr, "%s: %s\n", path, e.message);
        return 1;
    }
    FILE *f = fopen(pov, "a");
    fprintf(f, "#fopen FO \"%s\" write\n", out);
    for (int i = 0; i < N; ++i)
        fprintf(f, "#write (FO, str(LB_Field(%.17g, %.17g, %.17g), 0, 17), \"\\n\")\n", x[i], y[i],
                z[i]);
    fprintf(f, "#fclose FO\n");
    fclose(f);
    remove(out);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +I'%s' -D -F +W1 +H1 -V -GR -GS -GW +L'%s/povray_include' > "
             "povray.log 2>&1",
             work, pov, src);
    if (system(cmd) != 0) {
        fprintf(stderr, "%s: povray failed (see %s/povray.log)\n", path, work);
        return 1;
    }
    FILE *in = fopen(out, "r");
    int n = 0;
    double worst = 0.0, val;
    while (in && n < N && fscanf(in, "%lf", &val) == 1) {
        const double err = fabs(val - v[n]) / fmax(1.0, fabs(v[n]));
        if (err > worst) worst = err;
        ++n;
    }
    if (in) fclose(in);
    const double tol = bulge ? 1e-6 : 1e-9;
    fprintf(stderr, "  %-46s %d points (%d near local curves), worst %.2g (tolerance %g)\n",
            path + strlen(src) + 1, n, near, worst, tol);
    *checked += n;
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return n != N || !(worst <= tol);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: test_pov_scenes SOURCE_DIR WORK_DIR\n");
        return 2;
    }
    const char *dirs[2] = {"scenes", "tests/data/scenes"};
    int fails = 0, scenes = 0, checked = 0;
    for (int d = 0; d < 2; ++d) {
        char full[4096];
        snprintf(full, sizeof full, "%s/%s", argv[1], dirs[d]);
        DIR *D = opendir(full);
        if (!D) return 1;
        struct dirent *ent;
        while ((ent = readdir(D))) {
            const size_t l = strlen(ent->d_name);
            if (l < 6 || strcmp(ent->d_name + l - 5, ".json")) continue;
            char path[8192];
            snprintf(path, sizeof path, "%s/%s", full, ent->d_name);
            fails += check_scene(argv[1], argv[2], path, &checked);
            ++scenes;
        }
        closedir(D);
    }
    /* user text never reaches an identifier: a def named like SDL */
    static const char evil[] =
        "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\", \"title\": "
        "\"x\\n#declare Boom = 1;\", \"bounds\": {\"min\": [-2, -2, -2], \"max\": [2, 2, 2]}, "
        "\"defs\": {\"}#end #declare\": {\"type\": \"sphere\", \"radius\": 1}}, \"root\": "
        "{\"ref\": \"}#end #declare\"}}";
    lb_error e;
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    char pov[4096];
    snprintf(pov, sizeof pov, "%s/evil.pov", argv[2]);
    if (lb_scene_parse(evil, strlen(evil), "evil\n#declare X=1;.json", &sc, &e) ||
        lb_evaluator_create(sc, &ev, &e) || lb_scene_write_pov(sc, ev, NULL, pov, NULL, &e)) {
        fprintf(stderr, "evil scene: %s\n", e.message);
        ++fails;
    } else {
        FILE *f = fopen(pov, "r");
        char line[65536];
        while (f && fgets(line, sizeof line, f))
            if (strncmp(line, "//", 2) != 0 &&
                (strstr(line, "#declare X") || strstr(line, "Boom") || strstr(line, "#end"))) {
                fprintf(stderr, "user text reached SDL: %s", line);
                ++fails;
            }
        if (f) fclose(f);
    }
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    sc = NULL;
    ev = NULL;
    /* a scale blend of 17 arguments: beyond the include, refused by name */
    char big[8192];
    size_t n =
        (size_t)snprintf(big, sizeof big,
                         "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": "
                         "\"zero\", \"bounds\": {\"min\": [-2, -2, -2], \"max\": [20, 2, 2]}, "
                         "\"root\": {\"type\": \"scale\", \"op\": \"union\", \"r\": 0.5, "
                         "\"args\": [");
    for (int i = 0; i < 17; ++i)
        n += (size_t)snprintf(big + n, sizeof big - n,
                              "%s{\"type\": \"sphere\", \"center\": [%d, 0, 0], \"radius\": 0.6}",
                              i ? ", " : "", i);
    snprintf(big + n, sizeof big - n, "]}}");
    snprintf(pov, sizeof pov, "%s/big.pov", argv[2]);
    remove(pov);
    if (lb_scene_parse(big, strlen(big), "big.json", &sc, &e) || lb_evaluator_create(sc, &ev, &e)) {
        fprintf(stderr, "big scene: %s\n", e.message);
        ++fails;
    } else {
        const lb_status s = lb_scene_write_pov(sc, ev, NULL, pov, NULL, &e);
        FILE *f = fopen(pov, "r");
        if (s != LB_ERR_INVALID_ARGUMENT || !strstr(e.message, "$.root") ||
            !strstr(e.message, "at most 16") || f) {
            fprintf(stderr, "17-argument scale blend: expected a refusal and no file, got %d: %s\n",
                    s, e.message);
            ++fails;
        }
        if (f) fclose(f);
    }
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    fprintf(stderr, "%d scenes, %d points, %d failures\n", scenes, checked, fails);
    return fails || checked < 3000 ? 1 : 0;
}
