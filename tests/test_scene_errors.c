/* Bad scenes: every malformed or invalid scene is refused with the right
 * status and one message naming the file, line:column (syntax errors), the
 * JSON path and what is allowed. Table-driven: each row is a scene text and
 * the substrings its message must contain. */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"
#include "testfs.h"

#include <stdlib.h>
#include <unistd.h>

#define HEAD "{\"format\": \"libblend-scene\", \"version\": 1, "
#define ZERO(root) HEAD "\"convention\": \"zero\", \"root\": " root "}"
#define SOFT(root) HEAD "\"convention\": \"soft\", \"root\": " root "}"
#define SPH "{\"type\": \"sphere\", \"radius\": 1}"
#define SSPH "{\"type\": \"sphere\", \"radius\": 1, \"kernel\": \"wyvill\"}"
#define DISP(extra) "{\"type\": \"displacement\", \"op\": \"union\", " extra "}"

typedef struct bad {
    const char *name;
    const char *text;
    lb_status status;
    const char *want[3]; /* substrings of the message (NULL: unused) */
} bad;

static const bad BAD[] = {
    {"syntax error",
     "{\"format\": ",
     LB_ERR_INVALID_ARGUMENT,
     {"bad.json:1:12: invalid JSON at the end of the input", "allowed: a JSON document"}},
    {"trailing comma",
     ZERO("{\"type\": \"sphere\", \"radius\": 1,}"),
     LB_ERR_INVALID_ARGUMENT,
     {"bad.json:1:", "invalid JSON near \"}\""}},
    {"NaN literal",
     ZERO("{\"type\": \"sphere\", \"radius\": NaN}"),
     LB_ERR_INVALID_ARGUMENT,
     {"invalid JSON near \"NaN}}\"", "no NaN or Infinity"}},
    {"comment",
     "{\n  // a comment\n}",
     LB_ERR_INVALID_ARGUMENT,
     {"bad.json:2:4: invalid JSON near \"/ a comment\""}},
    {"text after the document",
     ZERO(SPH) "\n{}",
     LB_ERR_INVALID_ARGUMENT,
     {"bad.json:2:1: text after the end of the JSON document"}},
    {"empty file", "", LB_ERR_INVALID_ARGUMENT, {"bad.json:1:1: invalid JSON"}},
    {"top-level array",
     "[1, 2]",
     LB_ERR_INVALID_ARGUMENT,
     {"bad.json: $: expected a JSON object at the top, found an array"}},
    {"missing format",
     "{\"version\": 1}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.format: missing required field", "\"libblend-scene\""}},
    {"wrong format",
     "{\"format\": \"pov-scene\", \"version\": 1}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.format: \"pov-scene\" is not a libblend scene"}},
    {"version 2",
     "{\"format\": \"libblend-scene\", \"version\": 2}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.version: version 2 is not supported", "allowed: 1"}},
    {"version string",
     "{\"format\": \"libblend-scene\", \"version\": \"1\"}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.version: expected a number, found a string"}},
    {"missing convention",
     HEAD "\"root\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.convention: missing required field", "\"zero\" or \"soft\""}},
    {"unknown convention",
     HEAD "\"convention\": \"hard\", \"root\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.convention: unknown convention \"hard\"", "\"zero\""}},
    {"unknown top-level field",
     HEAD "\"convention\": \"zero\", \"roots\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$: unknown field \"roots\" in a scene", "allowed: format"}},
    {"missing root",
     HEAD "\"convention\": \"zero\"}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.root: missing required field"}},
    {"root is a number",
     ZERO("3"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root: expected a node object, found a number"}},
    {"unknown node type",
     ZERO("{\"type\": \"sphear\", \"radius\": 1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.type: unknown node type \"sphear\"", "allowed: sphere, ellipsoid"}},
    {"missing type",
     ZERO("{\"radius\": 1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.type: missing required field"}},
    {"missing radius",
     ZERO("{\"type\": \"sphere\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.radius: missing required field", "allowed: 1e-9 <= value <= 1e9"}},
    {"negative radius",
     ZERO("{\"type\": \"sphere\", \"radius\": -1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.radius: -1 is out of range", "allowed: 1e-9 <= value <= 1e9"}},
    {"radius as string",
     ZERO("{\"type\": \"sphere\", \"radius\": \"1\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.radius: expected a number, found a string"}},
    {"center of two numbers",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"center\": [0, 0]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.center: expected an array of 3 numbers", "[x, y, z]"}},
    {"center beyond 1e9",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"center\": [0, 1e300, 0]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.center[1]: 1e+300 is out of range", "|value| <= 1e9"}},
    {"overflowing number",
     ZERO("{\"type\": \"sphere\", \"radius\": 1e999}"),
     LB_ERR_NOT_FINITE,
     {"$.root.radius: inf is not finite"}},
    {"misspelt field",
     ZERO("{\"type\": \"sphere\", \"raduis\": 1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root: unknown field \"raduis\" in a sphere node", "allowed: type, center, radius"}},
    {"duplicate field",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"radius\": 2}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root: field \"radius\" appears twice"}},
    {"blend without r",
     ZERO(DISP("\"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.r: missing required field", "one per argument"}},
    {"r of the wrong length",
     ZERO(DISP("\"r\": [0.1, 0.2, 0.3], \"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.r: has 3 values for 2 arguments", "exactly 2 numbers"}},
    {"p = 1",
     ZERO(DISP("\"r\": 0.1, \"p\": 1, \"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.p: 1 is out of range", "allowed: 1 < p <= 1000"}},
    {"m = 0",
     ZERO(DISP("\"r\": 0.1, \"m\": [1, 0], \"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.m[1]: 0 is out of range", "1e-6 <= m <= 1e6"}},
    {"r is NaN-free but a bool",
     ZERO(DISP("\"r\": true, \"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.r: expected a number or an array of 2 numbers"}},
    {"args not an array",
     ZERO(DISP("\"r\": 0.1, \"args\": " SPH)),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args: expected an array, found an object"}},
    {"no args",
     ZERO(DISP("\"r\": 0.1, \"args\": []")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args: displacement \"args\" has 0 arguments", "allowed: an array of 1 to 65535"}},
    {"arg not an object",
     ZERO(DISP("\"r\": 0.1, \"args\": [" SPH ", 7]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args[1]: expected a node object, found a number"}},
    {"unknown op",
     ZERO("{\"type\": \"scale\", \"op\": \"unite\", \"r\": 0.1, \"args\": [" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.op: unknown op \"unite\" for scale", "\"union\""}},
    {"missing op",
     ZERO("{\"type\": \"scale\", \"r\": 0.1, \"args\": [" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.op: missing required field"}},
    {"conic with 3 args",
     ZERO("{\"type\": \"conic\", \"op\": \"union\", \"r\": 0.1, \"args\": [" SPH ", " SPH ", " SPH
          "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args: conic \"args\" has 3 arguments", "exactly 2 nodes"}},
    {"conic p not below r1 r2",
     ZERO("{\"type\": \"conic\", \"op\": \"union\", \"r\": [0.2, 0.5], \"p\": 0.1, \"args\": [" SPH
          ", " SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.p: p = 0.10000000000000001 is not below r1 r2", "0.1"}},
    {"soft operator in a zero scene",
     ZERO("{\"type\": \"soft_hyper\", \"op\": \"union\", \"r\": 0.5, \"args\": [" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.type: soft_hyper is a soft-convention operator but the scene's convention is "
      "\"zero\"",
      "allowed: displacement, conic"}},
    {"zero operator in a soft scene",
     SOFT(DISP("\"r\": 0.1, \"args\": [" SSPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.type: displacement is a zero-convention operator", "allowed: soft_hyper"}},
    {"kernel in a zero scene",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"kernel\": \"wyvill\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.kernel: a kernel is only meaningful in a soft scene"}},
    {"unknown kernel",
     SOFT("{\"type\": \"sphere\", \"radius\": 1, \"kernel\": \"gauss\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.kernel: unknown kernel \"gauss\"", "\"blinn\""}},
    {"soft union r > 1",
     SOFT("{\"type\": \"soft_hyper\", \"op\": \"union\", \"r\": [0.5, 1.5], \"args\": [" SSPH
          ", " SSPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.r[1]: 1.5 is out of range", "r <= 1 (soft union)"}},
    {"bulge on three arguments",
     ZERO(DISP("\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH ", " SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bulge: bulge elimination needs exactly 2 arguments", "binary blends only"}},
    {"bulge slope on scale",
     ZERO("{\"type\": \"scale\", \"op\": \"union\", \"r\": 0.1, \"bulge\": {\"slope\": true}, "
          "\"args\": [" SPH ", " SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bulge: \"slope\" needs m", "{\"range\": true}"}},
    {"bulge flag not a bool",
     ZERO(DISP("\"r\": 0.1, \"bulge\": {\"range\": 1}, \"args\": [" SPH ", " SPH "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bulge.range: expected true or false, found a number"}},
    {"soft level outside (0, 1)",
     SOFT("{\"type\": \"level\", \"level\": 1.2, \"args\": [" SSPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.level", "1.2 is out of range", "0 < level < 1"}},
    {"level without its level",
     ZERO("{\"type\": \"level\", \"args\": [" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.level", "missing required field"}},
    {"level of two arguments",
     ZERO("{\"type\": \"level\", \"level\": 0.1, \"args\": [" SPH ", " SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args", "exactly 1 node"}},
    {"material on a bounding solid",
     ZERO("{\"type\": \"bounded\", \"op\": \"union\", \"args\": [" SPH "], \"bounds\": "
          "[{\"type\": \"sphere\", \"radius\": 2, \"material\": {\"color\": [1, 0, 0]}}]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bounds[0]", "a bounding solid has a material", "allowed: materials on args"}},
    {"material colour out of range",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"material\": {\"color\": [1, 2, 0]}}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.material.color[1]", "2 is out of range", "0 <= value <= 1"}},
    {"material with an unknown field",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"material\": {\"colour\": [1, 0, 0]}}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.material", "unknown field \"colour\" in material",
      "allowed: color, ambient, diffuse, specular"}},
    {"material not an object",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"material\": \"red\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.material", "expected an object, found a string"}},
    {"bounded without bounds",
     ZERO("{\"type\": \"bounded\", \"op\": \"union\", \"args\": [" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bounds: missing required field", "one per argument"}},
    {"bounded with too few bounds",
     ZERO("{\"type\": \"bounded\", \"op\": \"union\", \"args\": [" SPH ", " SPH "], \"bounds\": "
          "[" SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bounds: has 1 bounding solids for 2 arguments"}},
    {"bounding solid inside its primitive",
     ZERO("{\"type\": \"bounded\", \"op\": \"union\", \"args\": [" SPH "], \"bounds\": "
          "[{\"type\": \"sphere\", \"radius\": 0.5}]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bounds[0]: the bounding solid (semi-axis 0.5) does not contain argument 0",
      "allowed: a bounding solid that contains its argument"}},
    {"ref to a missing def",
     ZERO("{\"ref\": \"wheel\"}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.ref: no def named \"wheel\"", "(this scene has no defs)"}},
    {"ref cycle",
     HEAD
     "\"convention\": \"zero\", \"defs\": {\"a\": {\"type\": \"min\", \"args\": [{\"ref\": "
     "\"b\"}]}, \"b\": {\"type\": \"min\", \"args\": [{\"ref\": \"a\"}]}}, \"root\": {\"ref\": "
     "\"a\"}}",
     LB_ERR_INVALID_ARGUMENT,
     {"reference cycle through def \"a\"", "$.defs.b.args[0]"}},
    {"defs not an object",
     HEAD "\"convention\": \"zero\", \"defs\": [1], \"root\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.defs: expected an object of named nodes, found an array"}},
    {"bounds min above max",
     HEAD "\"convention\": \"zero\", \"bounds\": {\"min\": [0, 0, 2], \"max\": [1, 1, 1]}, "
          "\"root\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.bounds: min[2] = 2 is not below max[2] = 1"}},
    {"bounds without max",
     HEAD "\"convention\": \"zero\", \"bounds\": {\"min\": [0, 0, 0]}, \"root\": " SPH "}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.bounds.max: missing required field"}},
    {"camera looking at itself",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"camera\": {\"location\": "
          "[1, 1, 1], \"look_at\": [1, 1, 1]}}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.camera: location equals look_at"}},
    {"camera up along the line of sight",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"camera\": {\"location\": "
          "[0, 0, 5], \"up\": [0, 0, 2]}}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.camera: up [0, 0, 2] is along the line of sight", "default [0, 0, 1]"}},
    {"camera up zero",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"camera\": {\"location\": "
          "[0, -5, 0], \"up\": [0, 0, 0]}}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.camera: up [0, 0, 0] is zero"}},
    {"floor as a number",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"floor\": 1}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.floor: expected true, false or {\"color\": [r, g, b]}, found a number"}},
    {"floor colour above 1",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"floor\": {\"color\": "
          "[0.5, 0.5, 3]}}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.floor.color[2]: 3 is out of range", "0 <= value <= 1"}},
    {"background of two numbers",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"background\": [1, 1]}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.background: expected an array of 3 numbers"}},
    {"material colour above 1",
     HEAD "\"convention\": \"zero\", \"root\": " SPH ", \"render\": {\"material\": {\"color\": "
          "[1, 2, 0]}}}",
     LB_ERR_INVALID_ARGUMENT,
     {"$.render.material.color[1]: 2 is out of range", "0 <= value <= 1"}},
    {"zero scale",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"scale\": 0}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.scale: 0 is out of range", "1e-6 <= scale <= 1e6"}},
    {"rotate with a string",
     ZERO("{\"type\": \"sphere\", \"radius\": 1, \"rotate\": [0, \"90\", 0]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.rotate[1]: expected a number, found a string", "degrees"}},
    {"superquadric exponent",
     ZERO("{\"type\": \"superquadric\", \"semi_axes\": [1, 1, 1], \"e1\": 20, \"e2\": 1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.e1: 20 is out of range", "0.01 <= e1 <= 10"}},
    {"slab with a zero normal",
     ZERO("{\"type\": \"slab\", \"normal\": [0, 0, 0], \"half_width\": 1}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root: lb_primitive_slab: n = (0, 0, 0) is not a direction"}},
    {"ricci exponent",
     SOFT("{\"type\": \"ricci\", \"n\": 0.5, \"args\": [" SSPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.n: 0.5 is out of range", "1 <= n <= 1000"}},
    {"complement of two",
     ZERO("{\"type\": \"complement\", \"args\": [" SPH ", " SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args: complement \"args\" has 2 arguments", "exactly 1"}},
    {"rfunction difference",
     ZERO("{\"type\": \"rfunction\", \"op\": \"difference\", \"args\": [" SPH ", " SPH "]}"),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.op: unknown op \"difference\" for rfunction", "\"union\" or \"intersection\""}},
    {"bulge nested five deep",
     ZERO(DISP("\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH ", " DISP(
         "\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH
         ", " DISP("\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH ", " DISP(
             "\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH ", " DISP(
                 "\"r\": 0.1, \"bulge\": {}, \"args\": [" SPH ", " SPH "]") "]") "]") "]") "]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.bulge: bulge elimination nested 5 deep", "at most 4 bulge-eliminated blends"}},
    {"bad node deep inside",
     ZERO(DISP("\"r\": 0.1, \"args\": [" SPH ", {\"type\": \"min\", \"args\": [" SPH
               ", {\"type\": \"torus\", \"major_radius\": 1}]}]")),
     LB_ERR_INVALID_ARGUMENT,
     {"$.root.args[1].args[1].minor_radius: missing required field"}},
};

static void check_message(const char *name, const lb_error *e, const char *const want[3]) {
    for (int i = 0; i < 3; ++i)
        if (want[i] && !strstr(e->message, want[i]))
            fail_msg("%s: message \"%s\" lacks \"%s\"", name, e->message, want[i]);
}

static void test_bad_scene_table(void **state) {
    (void)state;
    const size_t n = sizeof BAD / sizeof BAD[0];
    assert_true(n >= 60);
    for (size_t i = 0; i < n; ++i) {
        lb_scene *sc = (lb_scene *)1;
        lb_error e = {LB_OK, ""};
        const lb_status s = lb_scene_parse(BAD[i].text, strlen(BAD[i].text), "bad.json", &sc, &e);
        if (s != BAD[i].status)
            fail_msg("%s: status %d (%s), expected %d", BAD[i].name, s, e.message, BAD[i].status);
        assert_null(sc);
        assert_int_equal(e.status, s);
        check_message(BAD[i].name, &e, BAD[i].want);
        /* one message naming the file */
        assert_true(strncmp(e.message, "bad.json", 8) == 0);
    }
}

static char *repeat(const char *head, const char *unit, size_t n, const char *tail) {
    const size_t len = strlen(head) + n * strlen(unit) + strlen(tail) + 1;
    char *s = malloc(len);
    assert_non_null(s);
    strcpy(s, head);
    char *p = s + strlen(head);
    for (size_t i = 0; i < n; ++i) {
        strcpy(p, unit);
        p += strlen(unit);
    }
    strcpy(p, tail);
    return s;
}

static void expect(const char *text, size_t len, lb_status status, const char *const want[3]) {
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    const lb_status s = lb_scene_parse(text, len, "big.json", &sc, &e);
    if (s != status) fail_msg("status %d (%s), expected %d", s, e.message, status);
    check_message("generated", &e, want);
}

/* Limits: node nesting, JSON nesting, node count, text size. */
static void test_limits(void **state) {
    (void)state;
    /* 70 nested complements: deeper than LB_SCENE_MAX_DEPTH */
    char *deep = repeat(HEAD "\"convention\": \"zero\", \"root\": ",
                        "{\"type\": \"complement\", \"args\": [", 70, SPH);
    char *full = malloc(strlen(deep) + 3 * 70 + 2);
    strcpy(full, deep);
    for (int i = 0; i < 70; ++i) strcat(full, "]}");
    strcat(full, "}");
    expect(full, strlen(full), LB_ERR_INVALID_ARGUMENT,
           (const char *const[3]){"nodes nested deeper than 64 levels", "at most 64 levels",
                                  "$.root.args[0].args[0]"});
    /* the same depth within the limit parses */
    free(deep);
    free(full);
    /* JSON nested beyond what any valid scene needs */
    char *arrays = repeat(HEAD "\"convention\": \"zero\", \"root\": ", "[", 300, "");
    expect(arrays, strlen(arrays), LB_ERR_INVALID_ARGUMENT,
           (const char *const[3]){"big.json:1:", "JSON nested deeper than 208 levels"});
    free(arrays);
    /* a list longer than any scene's, refused before a tree is built (its
     * 3 M values once took 21 times the file's size in memory) */
    char *longr = repeat(HEAD "\"convention\": \"zero\", \"root\": {\"type\": \"displacement\", "
                              "\"op\": \"union\", \"r\": [0.5",
                         ",0.5", 4 * 65535, "], \"args\": [" SPH ", " SPH "]}}");
    expect(longr, strlen(longr), LB_ERR_INVALID_ARGUMENT,
           (const char *const[3]){"big.json:1:", "a JSON array of more than 262140 elements",
                                  "at most 65535 arguments"});
    free(longr);
    /* more than LB_SCENE_MAX_NODES nodes (refs count) */
    char *inner =
        repeat("{\"type\": \"min\", \"args\": [{\"ref\": \"s\"}", ", {\"ref\": \"s\"}", 255, "]}");
    size_t cap = 2 * 256 * (strlen(inner) + 2) + 4096;
    char *many = malloc(cap);
    size_t len = (size_t)snprintf(many, cap,
                                  HEAD "\"convention\": \"zero\", \"defs\": {\"s\": " SPH
                                       "}, \"root\": {\"type\": "
                                       "\"min\", \"args\": [{\"type\": \"min\", \"args\": [");
    for (int a = 0; a < 2; ++a) {
        if (a)
            len += (size_t)snprintf(many + len, cap - len, "]}, {\"type\": \"min\", \"args\": [");
        for (int i = 0; i < 256; ++i)
            len += (size_t)snprintf(many + len, cap - len, "%s%s", i ? ", " : "", inner);
    }
    len += (size_t)snprintf(many + len, cap - len, "]}]}}");
    assert_true(len < cap);
    expect(many, strlen(many), LB_ERR_INVALID_ARGUMENT,
           (const char *const[3]){"more than 100000 nodes", "allowed: at most 100000 nodes"});
    free(inner);
    free(many);
    /* arity: 257 arguments of a family capped at LB_MAX_ARITY name the wide
     * families; 65536 of a wide one are refused */
    static const struct {
        const char *head;
        size_t more; /* arguments after the first */
        const char *want[3];
    } wide[] = {
        {"{\"type\": \"scale\", \"op\": \"union\", \"r\": 0.1, \"args\": [",
         256,
         {"$.root.args: scale \"args\" has 257 arguments", "allowed: an array of 1 to 256 nodes",
          "displacement, min, max, soft_sum and ricci take up to 65535"}},
        {"{\"type\": \"min\", \"args\": [",
         65535,
         {"$.root.args: min \"args\" has 65536 arguments",
          "allowed: an array of 1 to 65535 nodes"}},
    };
    for (size_t w = 0; w < sizeof wide / sizeof wide[0]; ++w) {
        char head[256];
        snprintf(head, sizeof head, HEAD "\"convention\": \"zero\", \"root\": %s" SPH,
                 wide[w].head);
        char *text = repeat(head, ", " SPH, wide[w].more, "]}}");
        expect(text, strlen(text), LB_ERR_INVALID_ARGUMENT, wide[w].want);
        free(text);
    }
    /* text larger than LB_SCENE_MAX_BYTES: refused before it is read */
    static const char small[] = "{}";
    expect(
        small, (size_t)LB_SCENE_MAX_BYTES + 1, LB_ERR_INVALID_ARGUMENT,
        (const char *const[3]){"big.json: the scene is 67108865 bytes", "at most 67108864 bytes"});
}

/* RFC 8259 exactly (scene/json_strict.c): what cJSON alone accepts is
 * refused with line:column and what is wrong, and the message stays one
 * line (control characters escaped); UTF-8 text and escaped surrogate pairs
 * are accepted. */
static void test_strict_json(void **state) {
    (void)state;
    static const char head[] = "{\"format\":\"libblend-scene\",\"version\":1,\"convention\":";
#define SPH_TAIL "\"root\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1}}"
    struct {
        const char *tail; /* after head */
        size_t extra;     /* bytes of tail past its NUL that belong to the text */
        const char *want; /* NULL: accepted */
    } cases[] = {
        {"\"zero\",\"root\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":01}}", 0,
         "bad.json:1:110: invalid JSON: a number with a leading zero near '01}}'"},
        {"\"zero\",\"root\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1.}}", 0,
         "bad.json:1:110: invalid JSON: a decimal point without digits after it near '1.}}'"},
        {"\"ze\nro\"," SPH_TAIL, 0,
         "bad.json:1:56: invalid JSON: a control character in a string (escape it) near '?ro\","},
        {"\"ze\tro\"," SPH_TAIL, 0, "bad.json:1:56: invalid JSON: a control character in a string"},
        {"\"zero\\u0000\"," SPH_TAIL, 0, "bad.json:1:58: invalid JSON: \\u0000 is not allowed"},
        {"\"zero\"," SPH_TAIL "\0x", 2, "invalid JSON: a NUL byte in the text near '?x'"},
        {"\"zero\",\"defs\":{\"a\xff\":{\"type\":\"sphere\",\"radius\":1}}," SPH_TAIL, 0,
         "bad.json:1:70: invalid JSON: a byte that is not UTF-8"},
        {"\"zero\",\"defs\":{\"a\xc0\xaf\":{\"type\":\"sphere\",\"radius\":1}}," SPH_TAIL, 0,
         "bad.json:1:70: invalid JSON: a byte sequence that is not UTF-8"},
        {"\"zero\",\"defs\":{\"a\xed\xa0\x80\":{\"type\":\"sphere\",\"radius\":1}}," SPH_TAIL, 0,
         "bad.json:1:70: invalid JSON: a byte sequence that is not UTF-8"},
        {"\"zero\",\"defs\":{\"\xc3\xa9\xf0\x9f\x98\x80\\ud83d\\ude00\":{\"type\":\"sphere\","
         "\"radius\":1}}," SPH_TAIL,
         0, NULL},
        {"\"zero\"," SPH_TAIL "  \n\t", 0, NULL},
    };
#undef SPH_TAIL
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char text[512];
        const size_t hl = strlen(head), tl = strlen(cases[i].tail) + cases[i].extra;
        memcpy(text, head, hl);
        memcpy(text + hl, cases[i].tail, tl);
        lb_scene *sc = NULL;
        lb_error e = {LB_OK, ""};
        const lb_status s = lb_scene_parse(text, hl + tl, "bad.json", &sc, &e);
        if (!cases[i].want) {
            if (s != LB_OK) fail_msg("strict case %zu: refused: %s", i, e.message);
            lb_scene_free(sc);
            continue;
        }
        if (s != LB_ERR_INVALID_ARGUMENT || !strstr(e.message, cases[i].want))
            fail_msg("strict case %zu: status %d, message \"%s\", want \"%s\"", i, s, e.message,
                     cases[i].want);
        for (const char *q = e.message; *q; ++q)
            if ((unsigned char)*q < 32 || (unsigned char)*q >= 127)
                fail_msg("strict case %zu: a control or non-ASCII byte in \"%s\"", i, e.message);
        assert_null(sc);
    }
}

/* Files: missing, a directory, too large (a sparse file), and a good one. */
static void test_files(void **state) {
    (void)state;
    lb_scene *sc = NULL;
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_scene_load("/nonexistent/scene.json", &sc, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "/nonexistent/scene.json: cannot open the scene file (No "
                                      "such file or directory)"));
    char dir[512], path[600];
    assert_int_equal(test_mkdtemp(dir, sizeof dir, "libblend-files"), 0);
    assert_int_equal(lb_scene_load(dir, &sc, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, ": is a directory"));
    assert_non_null(strstr(e.message, dir));
    /* a file over the size limit (sparse where the file system can) */
    snprintf(path, sizeof path, "%s/big.json", dir);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
#ifdef _WIN32
    assert_int_equal(_chsize_s(_fileno(f), (long long)LB_SCENE_MAX_BYTES + 10), 0);
#else
    assert_int_equal(ftruncate(fileno(f), (off_t)LB_SCENE_MAX_BYTES + 10), 0);
#endif
    fclose(f);
    assert_int_equal(lb_scene_load(path, &sc, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "the scene file is 67108874 bytes"));
    remove(path);
    test_rmdir(dir);
#ifndef _WIN32
    /* endless devices: read to the size limit, then bad input (not memory);
     * POSIX only (Windows has no such files) */
    assert_int_equal(lb_scene_load("/dev/zero", &sc, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "/dev/zero: the scene file is larger than 67108864 bytes"));
    assert_int_equal(lb_scene_load("/dev/urandom", &sc, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "/dev/urandom: the scene file is larger than"));
#endif
    assert_null(sc);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_scene_table),
        cmocka_unit_test(test_limits),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_strict_json),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
