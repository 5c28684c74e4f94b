/* Scene files (format "libblend-scene", version 1): JSON parsed by cJSON,
 * validated into lb__node trees. Every failure is one message:
 *   FILE[:LINE:COL]: $.json.path: what is wrong; allowed: what would be right
 * Line and column are known for syntax errors (cJSON keeps no positions for
 * values); the JSON path is always given. docs/scene-format.md is the
 * reference for every name accepted here. */
#define _POSIX_C_SOURCE 200809L
#include "parse_internal.h"
#include "../common/glibc_compat.h"
#include "../common/platform.h"

#include <sys/stat.h>

#include <cjson/cJSON.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* cJSON's own nesting limit is 1000 levels; each node level costs at most
 * 3 JSON levels, so this is checked first with a clear message. */
#define JSON_MAX_NESTING (3 * LB_SCENE_MAX_DEPTH + 16)

/* ---- top level ---- */

static lb_status parse_bounds(pctx *c, const cJSON *root) {
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(root, "bounds");
    if (!b) return LB_OK;
    static const char *const keys[] = {"min", "max", NULL};
    const size_t old = lb__push_key(c, "bounds");
    lb_status s = LB_OK;
    if (!cJSON_IsObject(b))
        s = lb__perr(
            c, LB_ERR_INVALID_ARGUMENT,
            "expected an object, found %s; allowed: {\"min\": [x, y, z], \"max\": [x, y, z]}",
            lb__json_kind(b));
    else if (!(s = lb__check_keys(c, b, keys, "bounds")) &&
             !(s = lb__get_vec3(c, b, "min", 1, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                                "|value| <= 1e9", c->s->bmin)) &&
             !(s = lb__get_vec3(c, b, "max", 1, -LB_SCENE_MAX_COORD, LB_SCENE_MAX_COORD,
                                "|value| <= 1e9", c->s->bmax))) {
        for (int i = 0; i < 3 && !s; ++i)
            if (!(c->s->bmin[i] < c->s->bmax[i]))
                s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                             "min[%d] = %g is not below max[%d] = %g; allowed: min < max on every "
                             "axis",
                             i, c->s->bmin[i], i, c->s->bmax[i]);
        c->s->has_bounds = !s;
    }
    lb__pop(c, old);
    return s;
}

static lb_status parse_document(pctx *c, const cJSON *root) {
    static const char *const keys[] = {"format", "version", "convention", "title",  "description",
                                       "bounds", "defs",    "root",       "render", NULL};
    lb_status s;
    if (!cJSON_IsObject(root))
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                        "expected a JSON object at the top, found %s; allowed: {\"format\": "
                        "\"libblend-scene\", \"version\": 1, ...}",
                        lb__json_kind(root));
    const char *fmt = NULL, *conv = NULL, *str = NULL;
    if ((s = lb__get_string(c, root, "format", 1, "\"libblend-scene\"", &fmt))) return s;
    if (strcmp(fmt, "libblend-scene") != 0) {
        const size_t old = lb__push_key(c, "format");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "\"%.40s\" is not a libblend scene; allowed: \"libblend-scene\"", fmt);
        lb__pop(c, old);
        return s;
    }
    double version = 0;
    if ((s = lb__get_number(c, root, "version", 1, -1e9, 1e9, "1", &version))) return s;
    if (version != 1.0) {
        const size_t old = lb__push_key(c, "version");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "version %g is not supported by libblend %d.%d; allowed: 1", version,
                     LB_VERSION_MAJOR, LB_VERSION_MINOR);
        lb__pop(c, old);
        return s;
    }
    if ((s = lb__check_keys(c, root, keys, "a scene")) ||
        (s = lb__get_string(c, root, "title", 0, "a string", &str)) ||
        (s = lb__get_string(c, root, "description", 0, "a string", &str)) ||
        (s = lb__get_string(c, root, "convention", 1, "\"zero\" or \"soft\"", &conv)))
        return s;
    if (strcmp(conv, "zero") == 0)
        c->s->convention = LB_CONVENTION_ZERO;
    else if (strcmp(conv, "soft") == 0)
        c->s->convention = LB_CONVENTION_SOFT;
    else {
        const size_t old = lb__push_key(c, "convention");
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "unknown convention \"%.40s\"; allowed: \"zero\" (inside f < 0) or \"soft\" "
                     "(inside f > 0.5)",
                     conv);
        lb__pop(c, old);
        return s;
    }
    if ((s = parse_bounds(c, root)) || (s = lb__parse_render(c, root))) return s;
    const cJSON *defs = cJSON_GetObjectItemCaseSensitive(root, "defs");
    if (defs) {
        const size_t old = lb__push_key(c, "defs");
        if (!cJSON_IsObject(defs)) {
            s = lb__perr(
                c, LB_ERR_INVALID_ARGUMENT,
                "expected an object of named nodes, found %s; allowed: {\"name\": node, ...}",
                lb__json_kind(defs));
        } else {
            const size_t nd = (size_t)cJSON_GetArraySize(defs);
            c->defs = calloc(nd ? nd : 1, sizeof *c->defs);
            if (!c->defs) s = lb__oom(c);
            for (const cJSON *d = defs->child; d && !s; d = d->next) {
                /* a def's name goes into node paths, messages, `info` and
                 * POV-Ray comments: one line of text, nothing to escape */
                for (const unsigned char *q = (const unsigned char *)d->string; *q && !s; ++q)
                    if (*q < 0x20 || *q == 0x7f)
                        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                                     "def \"%.60s\" has a control character; allowed: names "
                                     "without control characters (no newline, tab, ...)",
                                     d->string);
                if (!*d->string)
                    s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                                 "a def with an empty name; allowed: a non-empty name");
                for (size_t i = 0; i < c->ndefs; ++i)
                    if (strcmp(c->defs[i].name, d->string) == 0)
                        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                                     "def \"%.60s\" appears twice; allowed: unique names",
                                     d->string);
                c->defs[c->ndefs].name = d->string;
                c->defs[c->ndefs].json = (cJSON *)d;
                c->ndefs++;
            }
        }
        lb__pop(c, old);
        if (s) return s;
    }
    const cJSON *rootnode = cJSON_GetObjectItemCaseSensitive(root, "root");
    const size_t old = lb__push_key(c, "root");
    if (!rootnode)
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: a node object");
    else
        s = lb__parse_node(c, rootnode, 1, &c->s->root);
    lb__pop(c, old);
    if (s) return s;
    /* unused defs are still validated: a typo there should not wait */
    for (size_t i = 0; i < c->ndefs && !s; ++i) {
        lb__node *n = NULL;
        s = lb__build_def(c, &c->defs[i], 1, &n);
    }
    return s;
}

static void line_col(const char *text, size_t len, size_t off, size_t *line, size_t *col) {
    *line = 1;
    *col = 1;
    for (size_t i = 0; i < off && i < len; ++i) {
        if (text[i] == '\n') {
            ++*line;
            *col = 1;
        } else {
            ++*col;
        }
    }
}

/* RFC 8259 exactly (common/json_check.c), after cJSON accepted the text */
static lb_status strict_json(const char *text, size_t length, const char *file, lb_error *err) {
    size_t line, col;
    char near[16];
    const char *what = lb__json_strictness(text, length, &line, &col, near);
    if (!what) return LB_OK;
    return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                    "%s:%zu:%zu: invalid JSON: %s%s%s%s; allowed: a JSON document (RFC 8259: no "
                    "leading zeros, digits after a decimal point, control characters in strings "
                    "escaped, no \\u0000, UTF-8 text, nothing after the document)",
                    file, line, col, what, *near ? " near '" : "", near, *near ? "'" : "");
}

lb_status lb_scene_parse(const char *text, size_t length, const char *name, lb_scene **out,
                         lb_error *err) {
    const char *file = name ? name : "<scene>";
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_parse: out is NULL");
    *out = NULL;
    if (!text) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_parse: text is NULL");
    if (length > LB_SCENE_MAX_BYTES)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the scene is %zu bytes; allowed: at most %u bytes", file, length,
                        LB_SCENE_MAX_BYTES);
    /* Pre-scan, outside strings, allocating nothing: the nesting, and the
     * number of objects, arrays and values (commas), each capped at what a
     * scene of LB_SCENE_MAX_NODES nodes can hold, and the length of every
     * array (scene.h), so a file that cannot be a scene (63 MB of [], an r
     * list of millions) is refused before any parser builds a tree of it. */
    {
        size_t depth = 0, line = 1, col = 1, nobj = 0, narr = 0, nval = 0;
        /* per open bracket: its array's commas so far, or UINT32_MAX for an object */
        uint32_t commas[JSON_MAX_NESTING + 2];
        int in_str = 0, esc = 0;
        for (size_t i = 0; i < length; ++i) {
            const char ch = text[i];
            if (ch == '\n') {
                ++line;
                col = 0;
            }
            ++col;
            if (in_str) {
                if (esc)
                    esc = 0;
                else if (ch == '\\')
                    esc = 1;
                else if (ch == '"')
                    in_str = 0;
                continue;
            }
            const char *over = NULL;
            size_t cap = 0;
            if (ch == '{' && ++nobj > LB_SCENE_MAX_JSON_OBJECTS)
                over = "objects", cap = LB_SCENE_MAX_JSON_OBJECTS;
            else if (ch == '[' && ++narr > LB_SCENE_MAX_JSON_ARRAYS)
                over = "arrays", cap = LB_SCENE_MAX_JSON_ARRAYS;
            else if ((ch == ',' || ch == '[' || ch == '{') && ++nval > LB_SCENE_MAX_JSON_VALUES)
                over = "values", cap = LB_SCENE_MAX_JSON_VALUES;
            if (over)
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s:%zu:%zu: more than %zu JSON %s; allowed: what a scene of at "
                                "most %d nodes holds (at most %d objects, %d arrays, %d values)",
                                file, line, col - 1, cap, over, LB_SCENE_MAX_NODES,
                                LB_SCENE_MAX_JSON_OBJECTS, LB_SCENE_MAX_JSON_ARRAYS,
                                LB_SCENE_MAX_JSON_VALUES);
            if (ch == '"')
                in_str = 1;
            else if (ch == '[' || ch == '{') {
                if (++depth > JSON_MAX_NESTING)
                    return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                    "%s:%zu:%zu: JSON nested deeper than %d levels; allowed: "
                                    "at most %d levels of nodes (use defs and refs to share "
                                    "subtrees)",
                                    file, line, col - 1, JSON_MAX_NESTING, LB_SCENE_MAX_DEPTH);
                commas[depth] = ch == '[' ? 0 : UINT32_MAX;
            } else if ((ch == ']' || ch == '}') && depth) {
                --depth;
            } else if (ch == ',' && depth && commas[depth] != UINT32_MAX &&
                       ++commas[depth] >= LB_SCENE_MAX_JSON_ARRAY) {
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s:%zu:%zu: a JSON array of more than %d elements; allowed: at "
                                "most %d arguments of an operator, and as many values in its "
                                "r, p and m lists",
                                file, line, col - 1, LB_SCENE_MAX_JSON_ARRAY, LB_MAX_ARITY_WIDE);
            }
        }
    }
    /* the strict check first (one pass, nothing allocated);
     * its message is given only when cJSON accepted the text (cJSON's
     * messages come first) */
    const lb_status strict = strict_json(text, length, file, err);
    const char *end = NULL;
    cJSON *doc = cJSON_ParseWithLengthOpts(text, length, &end, 0);
    if (!doc) {
        size_t off = end && end >= text ? (size_t)(end - text) : 0;
        if (off > length) off = length;
        while (off < length &&
               (text[off] == ' ' || text[off] == '\t' || text[off] == '\r' || text[off] == '\n'))
            ++off;
        size_t line, col;
        line_col(text, length, off, &line, &col);
        char near[24] = "";
        size_t nl = 0;
        for (size_t i = off; i < length && nl < 16 && text[i] != '\n'; ++i)
            near[nl++] = (text[i] >= 32 && text[i] < 127) ? text[i] : '?';
        near[nl] = '\0';
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s:%zu:%zu: invalid JSON%s%s%s; allowed: a JSON document (RFC 8259: no "
                        "comments, no trailing commas, no NaN or Infinity)",
                        file, line, col, nl ? " near \"" : " at the end of the input",
                        nl ? near : "", nl ? "\"" : "");
    }
    /* trailing content after the document */
    if (end) {
        size_t off = (size_t)(end - text);
        while (off < length &&
               (text[off] == ' ' || text[off] == '\n' || text[off] == '\r' || text[off] == '\t'))
            ++off;
        if (off < length && text[off] != '\0') {
            size_t line, col;
            line_col(text, length, off, &line, &col);
            cJSON_Delete(doc);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s:%zu:%zu: text after the end of the JSON document; allowed: one "
                            "JSON object",
                            file, line, col);
        }
    }
    if (strict) {
        cJSON_Delete(doc);
        return strict; /* err still holds its message: nothing since has written to it */
    }
    lb_scene *s = calloc(1, sizeof *s);
    if (!s) {
        cJSON_Delete(doc);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", file);
    }
    s->name = malloc(strlen(file) + 1);
    if (s->name) strcpy(s->name, file);
    pctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.file = file;
    c.err = err;
    lb__jpath_set(&c.jp, "$");
    lb_status st = s->name ? parse_document(&c, doc) : lb__oom(&c);
    free(c.defs);
    cJSON_Delete(doc);
    if (st) {
        lb_scene_free(s);
        return st;
    }
    *out = s;
    return LB_OK;
}

lb_status lb_scene_load(const char *path, lb_scene **out, lb_error *err) {
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_load: out is NULL");
    *out = NULL;
    if (!path) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_scene_load: path is NULL");
    FILE *f = lb__fopen(path, "rb");
    if (!f && lb__is_directory(path)) /* Windows opens no folder */
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: is a directory; allowed: a scene file",
                        path);
    if (!f)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: cannot open the scene file (%s); allowed: a readable file", path,
                        strerror(errno));
    struct stat sb;
    if (lb__fstat(fileno(f), &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) {
            fclose(f);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: is a directory; allowed: a scene file", path);
        }
        if (S_ISREG(sb.st_mode) && (unsigned long long)sb.st_size > LB_SCENE_MAX_BYTES) {
            fclose(f);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: the scene file is %lld bytes; allowed: at most %u bytes", path,
                            (long long)sb.st_size, LB_SCENE_MAX_BYTES);
        }
    }
    char *buf = NULL;
    size_t len = 0, cap = 0;
    lb_status st = LB_OK;
    for (;;) {
        if (len == cap) {
            if (len > LB_SCENE_MAX_BYTES) {
                st = lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                              "%s: the scene file is larger than %u bytes (or endless: a device "
                              "or FIFO is read to its end); allowed: at most %u bytes",
                              path, LB_SCENE_MAX_BYTES, LB_SCENE_MAX_BYTES);
                break;
            }
            cap = cap ? 2 * cap : 65536;
            if (cap > (size_t)LB_SCENE_MAX_BYTES + 1) cap = (size_t)LB_SCENE_MAX_BYTES + 1;
            char *nb = realloc(buf, cap + 1);
            if (!nb) {
                st = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory reading the file", path);
                break;
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f))
                st =
                    lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                             "%s: read error (is it a directory?); allowed: a readable file", path);
            break;
        }
    }
    fclose(f);
    if (!st) st = lb_scene_parse(buf ? buf : "", len, path, out, err);
    free(buf);
    return st;
}
