/* blendtool mesh: a watertight triangle mesh of a scene (PLY, OBJ, STL, GLB). */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static const char CMD[] = "mesh";

typedef struct bar {
    int shown;
    int last;
} bar;

static int progress(double f, void *user) {
    bar *b = user;
    const int pct = (int)(f * 100.0);
    if (pct == b->last) return 0;
    b->last = pct;
    char cells[41];
    const int full = pct * 40 / 100;
    for (int i = 0; i < 40; ++i) cells[i] = i < full ? '#' : '.';
    cells[40] = '\0';
    fprintf(stderr, "\rmeshing [%s] %3d%%", cells, pct);
    fflush(stderr);
    b->shown = 1;
    return 0;
}

/* blendtool mesh's command line */
typedef struct mesh_args {
    const char *out, *scene_path;
    lb_mesh_options o;
    int have_bounds, quiet;
    lb_mesh_format format;
    bt_set sets[BT_MAX_SETS];
    size_t nsets;
} mesh_args;

static int parse_args(int argc, char **argv, mesh_args *A) {
    const char *val = NULL;
    memset(A, 0, sizeof *A);
    lb_mesh_options_init(&A->o);
    A->format = LB_MESH_FORMAT_AUTO;
    int have_res = 0;
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option(CMD, argc, argv, &i, "-o", &val)) ||
            (r = bt_option(CMD, argc, argv, &i, "--output", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            A->out = val;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--resolution", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            long n = 0;
            if (bt_parse_long(CMD, "--resolution", val, 1, LB_MESH_MAX_CELLS_PER_AXIS,
                              "cells along the longest side", &n))
                return BT_EXIT_BAD_INPUT;
            A->o.resolution = (unsigned)n;
            have_res = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--cell-size", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            char *end = NULL;
            A->o.cell_size = strtod(val, &end);
            if (!end || *end || end == val || !(A->o.cell_size > 0.0) ||
                !isfinite(A->o.cell_size)) {
                bt_error(CMD, "--cell-size %s: expected a positive number", val);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--bounds", &val))) {
            if (r < 0 || bt_bounds_arg(CMD, val, A->o.bmin, A->o.bmax)) return BT_EXIT_BAD_INPUT;
            A->have_bounds = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--simplify", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            char *end = NULL;
            errno = 0;
            const double t = strtod(val, &end);
            if (errno || end == val || *end || !(t > 0.0 && t <= LB_MESH_MAX_SIMPLIFY)) {
                bt_error(CMD,
                         "--simplify %s: expected a tolerance in cells, above 0 and at most %g",
                         val, LB_MESH_MAX_SIMPLIFY);
                return BT_EXIT_BAD_INPUT;
            }
            A->o.simplify = t;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--threads", &val))) {
            if (r < 0 || bt_parse_threads(CMD, val, &A->o.threads)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--format", &val))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            static const char *const names[] = {"ply", "obj", "stl", "glb"};
            A->format = LB_MESH_FORMAT_AUTO;
            for (int f = 0; f < 4; ++f)
                if (strcmp(val, names[f]) == 0)
                    A->format = (lb_mesh_format)(LB_MESH_FORMAT_PLY + f);
            if (A->format == LB_MESH_FORMAT_AUTO) {
                bt_error(CMD, "--format %s; allowed: ply, obj, stl or glb", val);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--set", &val))) {
            if (r < 0 || bt_set_arg(CMD, val, A->sets, &A->nsets, BT_MAX_SETS))
                return BT_EXIT_BAD_INPUT;
        } else if (strcmp(argv[i], "--open") == 0) {
            A->o.flags |= LB_MESH_OPEN_BOUNDARY;
        } else if (strcmp(argv[i], "--tetrahedra") == 0) {
            A->o.flags |= LB_MESH_TETRAHEDRA;
        } else if (strcmp(argv[i], "--features") == 0) {
            A->o.flags |= LB_MESH_FEATURES;
        } else if (strcmp(argv[i], "--merge-flat") == 0) {
            A->o.flags |= LB_MESH_MERGE_FLAT;
        } else if (strcmp(argv[i], "--coarse-first") == 0) {
            A->o.flags |= LB_MESH_COARSE_FIRST;
        } else if (strcmp(argv[i], "--quiet") == 0 || strcmp(argv[i], "-q") == 0) {
            A->quiet = 1;
        } else if (bt_scene_arg(CMD, argv[i], &A->scene_path)) {
            return BT_EXIT_BAD_INPUT;
        }
    }
    if ((A->o.flags & LB_MESH_COARSE_FIRST) && !(A->o.simplify > 0.0)) {
        bt_error(CMD, "--coarse-first without --simplify; allowed: with --simplify TOL (the "
                      "tolerance in cells it meshes to, e.g. --simplify 0.25)");
        return BT_EXIT_BAD_INPUT;
    }
    if (have_res && A->o.cell_size > 0.0) {
        bt_error(CMD, "--resolution and --cell-size both given; allowed: one of them (the cell "
                      "size, or the cells along the longest side)");
        return BT_EXIT_BAD_INPUT;
    }
    if (!A->scene_path || !A->out) {
        bt_error(CMD, "%s; usage: blendtool mesh SCENE -o OUT.{ply,obj,stl,glb}",
                 !A->scene_path ? "no scene given" : "no output given (-o OUT)");
        return BT_EXIT_BAD_INPUT;
    }
    if (A->format == LB_MESH_FORMAT_AUTO) A->format = lb_mesh_format_of(A->out);
    if (A->format == LB_MESH_FORMAT_AUTO) {
        bt_error(CMD,
                 "%s: unknown mesh format; allowed: a name ending in .ply, .obj, .stl or "
                 ".glb, or --format ply|obj|stl|glb",
                 A->out);
        return BT_EXIT_BAD_INPUT;
    }
    /* the formats that carry a normal per triangle corner get them */
    if ((A->o.flags & LB_MESH_FEATURES) &&
        (A->format == LB_MESH_FORMAT_OBJ || A->format == LB_MESH_FORMAT_GLB))
        A->o.flags |= LB_MESH_CORNER_NORMALS;
    return BT_EXIT_OK;
}

static int run(int argc, char **argv) {
    mesh_args A;
    int rc = parse_args(argc, argv, &A);
    if (rc) return rc;
    const char *const out = A.out, *const scene_path = A.scene_path;
    lb_mesh_options o = A.o;
    const int quiet = A.quiet;
    lb_scene *scene = NULL;
    rc = bt_load_scene_region(CMD, scene_path, A.sets, A.nsets, A.have_bounds, o.bmin, o.bmax,
                              &scene, NULL);
    if (rc) return rc;
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_mesh *mesh = NULL;
    bt_out w = {0};
    lb_status s = LB_OK;
    if ((rc = bt_compile(CMD, scene_path, scene, &ev))) goto done;
    /* the output path is checked before the work: a folder or a missing
     * folder is reported at once, not after minutes of meshing */
    if ((rc = bt_output_open(CMD, out, &w))) goto done;
    bar b = {0, -1};
    if (!quiet && isatty(STDERR_FILENO)) {
        o.progress = progress;
        o.user = &b;
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    s = lb_mesh_create(ev, &o, &mesh, &e);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (b.shown) fputc('\n', stderr);
    if (s) {
        rc = bt_fail(CMD, scene_path, s, &e);
        goto done;
    }
    s = lb_mesh_write_stream(mesh, w.f, A.format, &e);
    if (s) {
        bt_error(CMD, "%s: writing the mesh failed (%s); nothing was written", out,
                 strerror(errno));
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    if ((rc = bt_output_commit(CMD, &w))) goto done;
    if (!quiet)
        printf("%s: %zu vertices, %zu triangles, %u x %u x %u cells, %.3f s\n", out,
               mesh->nvertices, mesh->ntriangles, mesh->cells[0], mesh->cells[1], mesh->cells[2],
               (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
done:
    bt_output_discard(&w);
    lb_mesh_free(mesh);
    lb_evaluator_free(ev);
    lb_scene_free(scene);
    return rc;
}

const bt_command bt_cmd_mesh = {
    "mesh", "a closed triangle mesh of the scene (PLY, OBJ, STL, glTF binary)",
    "usage: blendtool mesh SCENE -o OUT.{ply,obj,stl,glb} [--resolution N | --cell-size H]\n"
    "                      [--bounds x0,y0,z0,x1,y1,z1] [--open] [--threads N] [--quiet]\n"
    "                      [--format ply|obj|stl|glb] [--set PATH=VALUE]... [--tetrahedra]\n"
    "                      [--features] [--merge-flat] [--simplify TOL [--coarse-first]]\n\n"
    "Meshes the scene's surface inside the region (the scene's bounds, or --bounds):\n"
    "closed and manifold, vertices on the surface with normals from the analytic\n"
    "gradient. Where the region cuts the solid the mesh is closed on the region's\n"
    "faces; --open leaves it open there. The format follows OUT's extension, or\n"
    "--format (needed for a device or FIFO such as /dev/stdout).\n"
    "  --resolution N  cells along the region's longest side (default 128, at most 8192)\n"
    "  --cell-size H   the cell size instead of a resolution\n"
    "  --threads N     0 = one per CPU (default), 1 = single-threaded; the mesh is the\n"
    "                  same for every thread count\n"
    "  --quiet         no progress bar (shown only on a terminal) and no summary line\n"
    "  --tetrahedra    split cells into six tetrahedra instead of cube polygons (about\n"
    "                  3x the triangles; the zero set of one piecewise-linear field)\n"
    "  --features      keep sharp creases and corners (of min, max, clean and local\n"
    "                  unions, slabs, the region's cap) exactly: a vertex on the crease\n"
    "                  or corner of each cell it passes through; .obj and .glb also\n"
    "                  get each side of a crease its own normal (sharp shading)\n"
    "  --merge-flat    flat faces in few triangles: where the surface is a plane (with\n"
    "                  --features, a box's face: 2 triangles), no tolerance, the surface\n"
    "                  unchanged\n"
    "  --simplify TOL  fewer triangles where the surface allows: merge triangles\n"
    "                  wherever the result stays within TOL cells of the field (0 < TOL\n"
    "                  <= 1; e.g. 0.1), never across a crease; with --features a flat\n"
    "                  face becomes a few large triangles\n"
    "  --coarse-first  --simplify's tolerance met by meshing cells of twice the size\n"
    "                  wherever the surface stays within it, instead of merging\n"
    "                  triangles after meshing: far faster, more triangles (not with\n"
    "                  --features or --tetrahedra, which merge as without it)\n"
    "  --set PATH=VALUE  override a scene value first (VALUE is JSON), e.g.\n"
    "                  --set root.args[0].radius=0.5; repeatable, applied in order\n"
    "OUT may be a symbolic link (its target is replaced), a device or a FIFO (written\n"
    "directly); a new file gets mode 0666 less the umask, an existing one keeps its mode.\n"
    "Ctrl-C (SIGINT), SIGTERM and SIGHUP cancel at any phase: nothing is written. The\n"
    "output appears only when complete.\n"
    "Exit status: 0 success, 2 bad scene or options (or over the memory cap, with the\n"
    "largest resolution that fits), 1 internal failure or failure writing OUT, 130 / 143 /\n"
    "129 ended by SIGINT / SIGTERM / SIGHUP.\n",
    run};
