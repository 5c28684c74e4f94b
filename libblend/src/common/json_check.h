/* JSON checks shared by every reader of JSON in the project: the library's
 * scene parser (scene/parse*.c) and blendtool's job files
 * (tools/blendtool/batch_job.c), which compiles this file in as well, so
 * that both name a value's kind, check an object's keys and hold a text to
 * RFC 8259 the same way. cJSON builds the tree; these look at it, or at the
 * text before it. Not installed. */
#ifndef LIBBLEND_JSON_CHECK_H
#define LIBBLEND_JSON_CHECK_H

#include "internal.h"

#include <cjson/cJSON.h>
#include <stddef.h>

/* A JSON path being built ($.root.args[2].r): pushed and popped as a
 * reader walks into objects and arrays; too long a path is cut, never
 * overrun. */
#define LB__JPATH_MAX 480
typedef struct lb__jpath {
    char s[LB__JPATH_MAX];
    size_t len;
} lb__jpath;
/* the path root (usually "$") */
LB_INTERNAL void lb__jpath_set(lb__jpath *p, const char *root);
/* .key appended; returns the old length for lb__jpath_pop */
LB_INTERNAL size_t lb__jpath_key(lb__jpath *p, const char *key);
/* [i] appended; returns the old length for lb__jpath_pop */
LB_INTERNAL size_t lb__jpath_index(lb__jpath *p, size_t i);
/* back to an old length */
LB_INTERNAL void lb__jpath_pop(lb__jpath *p, size_t old);

/* "a number", "a string", "an object", ... for messages ("nothing" for NULL) */
LB_INTERNAL const char *lb__json_kind(const cJSON *j);

/* Every member of obj is one of allowed (NULL-terminated) and appears once:
 * 0, or 1 with *bad the first unknown member, or 2 with *bad the first
 * repeated one. */
LB_INTERNAL int lb__json_keys(const cJSON *obj, const char *const *allowed, const cJSON **bad);

/* What cJSON accepts beyond RFC 8259 (leading zeros, a bare decimal point,
 * raw control characters in strings, \u0000, text after a NUL byte, lone
 * surrogates, bytes that are not UTF-8), found in one pass over the text
 * with nothing allocated: NULL when the text is RFC 8259 JSON, else what is
 * wrong, with its 1-based line and column and up to 8 printable characters
 * of what is there (near, 16 bytes; '?' for others). The nesting must be
 * bounded by the caller (recursion). */
LB_INTERNAL const char *lb__json_strictness(const char *text, size_t length, size_t *line,
                                            size_t *col, char near[16]);

#endif
