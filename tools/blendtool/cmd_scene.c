/* blendtool validate / info: read a scene, report what it is. */
#include "blendtool.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

/* Parse, validate and compile: what every later command needs to succeed. */
static int load_and_compile(const char *cmd, const char *path, lb_scene **sc, lb_evaluator **ev) {
    int rc = bt_load_scene(cmd, path, sc);
    if (!rc && (rc = bt_compile(cmd, path, *sc, ev))) {
        lb_scene_free(*sc);
        *sc = NULL;
    }
    return rc;
}

static int unknown_option(const char *cmd, const char *a) {
    bt_error(cmd, "unknown option %s; see blendtool %s --help", a, cmd);
    return BT_EXIT_BAD_INPUT;
}

static int run_validate(int argc, char **argv) {
    const char *cmd = "validate";
    int nfiles = 0, worst = 0, quiet = 0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quiet") == 0 || strcmp(argv[i], "-q") == 0)
            quiet = 1;
        else if (argv[i][0] == '-' && argv[i][1])
            return unknown_option(cmd, argv[i]);
    }
    for (int i = 1; i < argc; ++i) {
        if (argv[i][0] == '-' && argv[i][1]) continue;
        ++nfiles;
        lb_scene *sc = NULL;
        lb_evaluator *ev = NULL;
        const int rc = load_and_compile(cmd, argv[i], &sc, &ev);
        if (rc) {
            if (rc > worst || worst == 0) worst = rc;
            continue;
        }
        if (!quiet) bt_warn_unused_m(cmd, argv[i], sc);
        lb_scene_stats st;
        lb_scene_stats_get(sc, &st);
        if (!quiet)
            printf("%s: ok (%s convention, %zu nodes, %zu instructions, cost %.0f per point)\n",
                   argv[i], lb_scene_convention(sc) == LB_CONVENTION_ZERO ? "zero" : "soft",
                   st.nodes, lb_evaluator_size(ev), lb_evaluator_cost(ev));
        lb_evaluator_free(ev);
        lb_scene_free(sc);
    }
    if (!nfiles) {
        bt_error(cmd, "no scene given; usage: blendtool validate SCENE...");
        return BT_EXIT_BAD_INPUT;
    }
    return worst;
}

/* info --families: the node types the library knows (its registry) */
static int print_families(const char *cmd, int json) {
    const size_t len = lb_scene_families_json(NULL, 0);
    char *txt = len ? malloc(len + 1) : NULL;
    if (!txt) {
        bt_error(cmd, "out of memory");
        return BT_EXIT_INTERNAL;
    }
    lb_scene_families_json(txt, len + 1);
    if (json) {
        printf("%s\n", txt);
        free(txt);
        return 0;
    }
    cJSON *root = cJSON_Parse(txt);
    free(txt);
    if (!root) {
        bt_error(cmd, "out of memory");
        return BT_EXIT_INTERNAL;
    }
    const cJSON *e;
    printf("primitives (both conventions):\n");
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(root, "primitives")) {
        printf("  %-13s %s\n", cJSON_GetObjectItem(e, "type")->valuestring,
               cJSON_GetObjectItem(e, "description")->valuestring);
    }
    printf("operators:\n");
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(root, "operators")) {
        const cJSON *c, *conv = cJSON_GetObjectItem(e, "conventions");
        printf("  %-13s %-9s args %g-%g  ", cJSON_GetObjectItem(e, "type")->valuestring,
               cJSON_GetArraySize(conv) == 2 ? "zero/soft" : conv->child->valuestring,
               cJSON_GetObjectItem(e, "min_args")->valuedouble,
               cJSON_GetObjectItem(e, "max_args")->valuedouble);
        cJSON_ArrayForEach(c, cJSON_GetObjectItem(e, "parameters")) {
            const cJSON *a = cJSON_GetObjectItem(c, "allowed");
            printf("%s%s", cJSON_GetObjectItem(c, "key")->valuestring, a ? "" : " ");
            if (a) printf(" (%s) ", a->valuestring);
        }
        printf("\n      %s\n", cJSON_GetObjectItem(e, "description")->valuestring);
    }
    cJSON_Delete(root);
    return 0;
}

static int run_info(int argc, char **argv) {
    const char *cmd = "info";
    const char *path = NULL;
    int json = 0, families = 0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (strcmp(argv[i], "--families") == 0)
            families = 1;
        else if (argv[i][0] == '-' && argv[i][1])
            return unknown_option(cmd, argv[i]);
        else if (path) {
            bt_error(cmd, "more than one scene given (%s, %s); info takes one", path, argv[i]);
            return BT_EXIT_BAD_INPUT;
        } else
            path = argv[i];
    }
    if (families && path) {
        bt_error(cmd,
                 "--families takes no scene (%s given); usage: blendtool info --families "
                 "[--json]",
                 path);
        return BT_EXIT_BAD_INPUT;
    }
    if (families) return print_families(cmd, json);
    if (!path) {
        bt_error(cmd, "no scene given; usage: blendtool info [--json] SCENE");
        return BT_EXIT_BAD_INPUT;
    }
    lb_scene *sc = NULL;
    lb_evaluator *ev = NULL;
    int rc = load_and_compile(cmd, path, &sc, &ev);
    if (rc) return rc;
    lb_scene_stats st;
    lb_scene_stats_get(sc, &st);
    double bmin[3], bmax[3];
    const int hb = lb_scene_bounds(sc, bmin, bmax);
    const char *conv = lb_scene_convention(sc) == LB_CONVENTION_ZERO ? "zero" : "soft";
    const size_t tlen = lb_scene_describe(sc, NULL, 0);
    char *tree = malloc(tlen + 1);
    if (!tree) {
        bt_error(cmd, "out of memory");
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    lb_scene_describe(sc, tree, tlen + 1);
    const size_t llen = lb_evaluator_describe_local(ev, NULL, 0);
    char *curves = malloc(llen + 1);
    if (!curves) {
        free(tree);
        bt_error(cmd, "out of memory");
        rc = BT_EXIT_INTERNAL;
        goto done;
    }
    lb_evaluator_describe_local(ev, curves, llen + 1);
    if (json) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", path);
        cJSON_AddStringToObject(o, "convention", conv);
        if (hb) {
            cJSON *b = cJSON_AddObjectToObject(o, "bounds");
            cJSON_AddItemToObject(b, "min", cJSON_CreateDoubleArray(bmin, 3));
            cJSON_AddItemToObject(b, "max", cJSON_CreateDoubleArray(bmax, 3));
        } else {
            cJSON_AddNullToObject(o, "bounds");
        }
        cJSON_AddNumberToObject(o, "nodes", (double)st.nodes);
        cJSON_AddNumberToObject(o, "primitives", (double)st.primitives);
        cJSON_AddNumberToObject(o, "operators", (double)st.operators);
        cJSON_AddNumberToObject(o, "depth", (double)st.depth);
        cJSON_AddNumberToObject(o, "instructions", (double)lb_evaluator_size(ev));
        cJSON_AddNumberToObject(o, "cost_per_point", lb_evaluator_cost(ev));
        cJSON_AddNumberToObject(o, "compile_cost", lb_evaluator_compile_cost(ev));
        cJSON_AddStringToObject(o, "tree", tree);
        cJSON_AddStringToObject(o, "local_blends", curves);
        char *txt = o ? cJSON_Print(o) : NULL;
        cJSON_Delete(o);
        if (!txt) {
            bt_error(cmd, "out of memory");
            rc = BT_EXIT_INTERNAL;
        } else {
            printf("%s\n", txt);
            cJSON_free(txt);
        }
    } else {
        printf("file: %s\nconvention: %s\n", path, conv);
        if (hb)
            printf("bounds: [%g, %g, %g] .. [%g, %g, %g]\n", bmin[0], bmin[1], bmin[2], bmax[0],
                   bmax[1], bmax[2]);
        else
            printf("bounds: none declared (mesh and render commands need --bounds)\n");
        printf("nodes: %zu (%zu primitives, %zu operators), depth %zu\n", st.nodes, st.primitives,
               st.operators, st.depth);
        printf("instructions: %zu\ncost: %.0f instruction runs per point (at most %d x the "
               "instructions)\ncompile cost: %.0f instruction runs (local unions' curves; at most "
               "%.0f)\ntree:\n%s",
               lb_evaluator_size(ev), lb_evaluator_cost(ev), LB_SCENE_MAX_COST_FACTOR,
               lb_evaluator_compile_cost(ev), LB_SCENE_MAX_COMPILE_COST, tree);
        if (llen) printf("local blends:\n%s", curves);
    }
    free(tree);
    free(curves);
done:
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    return rc;
}

const bt_command bt_cmd_validate = {
    "validate", "check scene files (parse, validate, compile)",
    "usage: blendtool validate [--quiet] SCENE...\n\n"
    "Parses, validates and compiles each scene file. Prints one line per valid\n"
    "scene (unless --quiet) and one message per invalid one on stderr, naming\n"
    "the file, line:column where known, the JSON path and what is allowed.\n"
    "Exit status: 0 all valid, 2 some scene is invalid, 1 internal failure.\n",
    run_validate};

const bt_command bt_cmd_info = {
    "info", "describe a scene: convention, bounds, tree, operator count",
    "usage: blendtool info [--json] SCENE\n"
    "       blendtool info --families [--json]\n\n"
    "Prints the scene's convention, declared bounds, node and operator counts,\n"
    "the size of the compiled tape and the tree (shared defs printed once).\n"
    "  --json       the same as one JSON object\n"
    "  --families   the node types the library knows instead of a scene: every\n"
    "               primitive and operator with its conventions, arity, keys and\n"
    "               parameter ranges (--json: the registry the JSON Schema, the\n"
    "               Blender add-on and the fuzz dictionary are checked against)\n"
    "Exit status: 0 success, 2 invalid scene, 1 internal failure.\n",
    run_info};
