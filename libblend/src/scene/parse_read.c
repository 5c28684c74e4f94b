/* The scene parser's messages, JSON paths and field readers (numbers,
 * vectors, strings, known keys): every failure names the file and the JSON
 * path of the value. */
#define _POSIX_C_SOURCE 200809L
#include "parse_internal.h"
#include "../common/glibc_compat.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- messages and paths ---- */

lb_status lb__perr(pctx *c, lb_status st, const char *fmt, ...) {
    char msg[LB_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (c->jp.len > 160) /* deep paths: the start and the end say where */
        return lb__fail(c->err, st, "%s: %.60s...%s: %s", c->file, c->jp.s,
                        c->jp.s + c->jp.len - 80, msg);
    return lb__fail(c->err, st, "%s: %s: %s", c->file, c->jp.s, msg);
}

size_t lb__push_key(pctx *c, const char *key) {
    return lb__jpath_key(&c->jp, key);
}

size_t lb__push_index(pctx *c, size_t i) {
    return lb__jpath_index(&c->jp, i);
}

void lb__pop(pctx *c, size_t old) {
    lb__jpath_pop(&c->jp, old);
}

lb_status lb__oom(pctx *c) {
    return lb__perr(c, LB_ERR_NO_MEMORY, "out of memory while building the scene");
}

/* ---- field readers ---- */

/* Every member of obj must be one of the names in allowed (NULL-terminated),
 * and appear once. */
lb_status lb__check_keys(pctx *c, const cJSON *obj, const char *const *allowed, const char *what) {
    const cJSON *it = NULL;
    const int k = lb__json_keys(obj, allowed, &it);
    if (k == 1) {
        char list[320] = "";
        size_t len = 0;
        for (const char *const *a = allowed; *a; ++a) {
            int w = snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "", *a);
            if (w < 0 || (size_t)w >= sizeof list - len) break;
            len += (size_t)w;
        }
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT, "unknown field \"%.60s\" in %s; allowed: %s",
                        it->string, what, list);
    }
    if (k == 2)
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                        "field \"%.60s\" appears twice; allowed: each field once", it->string);
    return LB_OK;
}

lb_status lb__number_value(pctx *c, const cJSON *j, double lo, double hi, const char *allowed,
                           double *out) {
    if (!cJSON_IsNumber(j))
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected a number, found %s; allowed: %s",
                        lb__json_kind(j), allowed);
    const double v = j->valuedouble;
    if (!isfinite(v))
        return lb__perr(c, LB_ERR_NOT_FINITE, "%g is not finite; allowed: %s", v, allowed);
    if (!(v >= lo && v <= hi))
        return lb__perr(c, LB_ERR_INVALID_ARGUMENT, "%.15g is out of range; allowed: %s", v,
                        allowed);
    *out = v;
    return LB_OK;
}

/* Optional number field: *out keeps its default when absent. */
lb_status lb__get_number(pctx *c, const cJSON *obj, const char *key, int required, double lo,
                         double hi, const char *allowed, double *out) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = lb__push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s",
                         allowed);
    } else {
        s = lb__number_value(c, j, lo, hi, allowed, out);
    }
    lb__pop(c, old);
    return s;
}

lb_status lb__get_vec3(pctx *c, const cJSON *obj, const char *key, int required, double lo,
                       double hi, const char *allowed, double out[3]) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = lb__push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s",
                         allowed);
    } else if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != 3) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT,
                     "expected an array of 3 numbers, found %s%s; allowed: [x, y, z], each %s",
                     lb__json_kind(j), cJSON_IsArray(j) ? " of another length" : "", allowed);
    } else {
        double v[3];
        for (int i = 0; i < 3 && !s; ++i) {
            const size_t o2 = lb__push_index(c, (size_t)i);
            s = lb__number_value(c, cJSON_GetArrayItem(j, i), lo, hi, allowed, &v[i]);
            lb__pop(c, o2);
        }
        if (!s) memcpy(out, v, sizeof v);
    }
    lb__pop(c, old);
    return s;
}

lb_status lb__get_string(pctx *c, const cJSON *obj, const char *key, int required,
                         const char *allowed, const char **out) {
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    const size_t old = lb__push_key(c, key);
    lb_status s = LB_OK;
    if (!j) {
        if (required)
            s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "missing required field; allowed: %s",
                         allowed);
    } else if (!cJSON_IsString(j)) {
        s = lb__perr(c, LB_ERR_INVALID_ARGUMENT, "expected a string, found %s; allowed: %s",
                     lb__json_kind(j), allowed);
    } else {
        *out = j->valuestring;
    }
    lb__pop(c, old);
    return s;
}
