/* The scene parser's shared parts (scene/parse*.c): its context and the
 * readers every part uses. parse.c reads the document (size and nesting
 * checks, strict JSON, the top-level keys, bounds, defs, root);
 * parse_read.c holds the messages, the JSON path and the field readers;
 * parse_node.c the node types, primitives and operator nodes;
 * parse_render.c the render section and materials. Every failure is one
 * message naming the file and the JSON path (lb__perr). */
#ifndef LB_PARSE_INTERNAL_H
#define LB_PARSE_INTERNAL_H

#include "scene_internal.h"

#include "../common/json_check.h"

#include <cjson/cJSON.h>
#include <stddef.h>

typedef struct def_entry {
    const char *name;
    cJSON *json;
    lb__node *node;
    int state; /* 0 not built, 1 building, 2 built */
} def_entry;

typedef struct pctx {
    lb_scene *s;
    const char *file;
    lb_error *err;
    lb__jpath jp; /* where the reader is ($.root.args[1]...) */
    def_entry *defs;
    size_t ndefs;
    size_t count;
} pctx;

/* ---- parse_read.c ---- */
/* the one failure message of a parse: FILE: $.path: what is wrong; allowed: ... (st returned) */
LB_INTERNAL lb_status lb__perr(pctx *c, lb_status st, const char *fmt, ...) LB_PRINTF(3, 4);
/* append ".key" to the current JSON path; returns the old length for lb__pop */
LB_INTERNAL size_t lb__push_key(pctx *c, const char *key);
/* append "[i]" to the current JSON path; returns the old length for lb__pop */
LB_INTERNAL size_t lb__push_index(pctx *c, size_t i);
/* cut the current JSON path back to old */
LB_INTERNAL void lb__pop(pctx *c, size_t old);
/* the out-of-memory failure */
LB_INTERNAL lb_status lb__oom(pctx *c);
/* every member of obj is one of allowed (NULL-terminated) and appears once; what names
 * the object in the message */
LB_INTERNAL lb_status lb__check_keys(pctx *c, const cJSON *obj, const char *const *allowed,
                                     const char *what);
/* the number j in [lo, hi] into *out */
LB_INTERNAL lb_status lb__number_value(pctx *c, const cJSON *j, double lo, double hi,
                                       const char *allowed, double *out);
/* the number obj.key in [lo, hi] into *out (left as is when absent and not required) */
LB_INTERNAL lb_status lb__get_number(pctx *c, const cJSON *obj, const char *key, int required,
                                     double lo, double hi, const char *allowed, double *out);
/* three numbers obj.key, each in [lo, hi], into out */
LB_INTERNAL lb_status lb__get_vec3(pctx *c, const cJSON *obj, const char *key, int required,
                                   double lo, double hi, const char *allowed, double out[3]);
/* the string obj.key into *out (borrowed from the document) */
LB_INTERNAL lb_status lb__get_string(pctx *c, const cJSON *obj, const char *key, int required,
                                     const char *allowed, const char **out);

/* ---- parse_node.c ---- */
/* the node j at depth into *out (a new node, or the shared node of a ref) */
LB_INTERNAL lb_status lb__parse_node(pctx *c, const cJSON *j, size_t depth, lb__node **out);
/* the def d, built once (a cycle of refs is an error) */
LB_INTERNAL lb_status lb__build_def(pctx *c, def_entry *d, size_t depth, lb__node **out);

/* ---- parse_render.c ---- */
/* {"color", "ambient", "diffuse", "specular"} into *m; fields left out keep what *m holds */
LB_INTERNAL lb_status lb__material_fields(pctx *c, const cJSON *mat, lb_material *m);
/* the document's "render" section into the scene */
LB_INTERNAL lb_status lb__parse_render(pctx *c, const cJSON *root);

#endif
