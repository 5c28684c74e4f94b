/* Scene overrides (`--set PATH=VALUE`, batch sweeps): a JSON path into the
 * scene document and a JSON value put there, then the scene parsed by the
 * library as usual, so an override that makes the scene invalid gets the
 * scene's own message, with the overrides named. Paths: `root.args[0].radius`
 * (a leading `$.` is allowed, as in the library's messages). */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"
#include "../../libblend/src/common/json_check.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

char *bt_read_file(const char *path, size_t max, size_t *len, char *why, size_t whylen) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, whylen, "%s", strerror(errno));
        return NULL;
    }
    size_t cap = 65536, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        const size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (n < cap) break;
        if (cap >= max) {
            snprintf(why, whylen, "larger than %zu bytes", max);
            free(buf);
            buf = NULL;
            break;
        }
        char *q = realloc(buf, 2 * cap + 1);
        if (!q) {
            free(buf);
            buf = NULL;
        } else {
            buf = q;
            cap *= 2;
        }
    }
    if (buf && ferror(f)) {
        snprintf(why, whylen, "%s", strerror(errno));
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) {
        buf[n] = '\0';
        *len = n;
    }
    return buf;
}

/* every number in v is finite (cJSON reads 1e999 as infinity) */
static int all_finite(const cJSON *v) {
    if (cJSON_IsNumber(v)) return isfinite(v->valuedouble);
    for (const cJSON *c = v->child; c; c = c->next)
        if (!all_finite(c)) return 0;
    return 1;
}

int bt_set_arg(const char *cmd, const char *arg, bt_set *sets, size_t *nsets, size_t max) {
    if (*nsets >= max) {
        bt_error(cmd, "more than %zu --set overrides", max);
        return -1;
    }
    return bt_set_parse(cmd, arg, &sets[(*nsets)++]);
}

int bt_set_parse(const char *cmd, const char *arg, bt_set *out) {
    const char *eq = strchr(arg, '=');
    if (!eq || eq == arg) {
        bt_error(cmd, "--set %s: expected PATH=VALUE, e.g. --set root.args[0].radius=0.5", arg);
        return -1;
    }
    cJSON *v = cJSON_ParseWithOpts(eq + 1, NULL, 1); /* nothing may follow the value */
    if (!v) {
        bt_error(cmd,
                 "--set %s: the value %s is not one JSON value; allowed: a number, true, false, "
                 "null, a \"quoted string\", an array or an object, with nothing after it",
                 arg, eq + 1);
        return -1;
    }
    const int finite = all_finite(v);
    cJSON_Delete(v);
    if (!finite) {
        bt_error(cmd,
                 "--set %s: the value %s holds a number beyond the range of a double; allowed: "
                 "finite numbers (magnitude below 1.8e308)",
                 arg, eq + 1);
        return -1;
    }
    for (const char *c = arg; c < eq; ++c)
        if (*c == '[') { /* an index: digits, no leading zero */
            const char *d = c + 1;
            size_t nd = 0;
            while (d + nd < eq && isdigit((unsigned char)d[nd])) ++nd;
            if (!nd || d + nd >= eq || d[nd] != ']' || (nd > 1 && d[0] == '0') || nd > 9) {
                bt_error(cmd,
                         "--set %s: the index at \"%.*s\" is not [N]; allowed: [0], [1], ... "
                         "without leading zeros",
                         arg, (int)(eq - c), c);
                return -1;
            }
        }
    out->path = arg;
    out->plen = (size_t)(eq - arg);
    out->value = eq + 1;
    return 0;
}

/* Puts value at path in doc; on failure writes why (naming the part of the
 * path that does not exist) and returns -1. */
static int apply_one(cJSON *doc, const bt_set *s, char *why, size_t whylen) {
    const char *p = s->path, *end = s->path + s->plen;
    if (end - p >= 2 && p[0] == '$' && p[1] == '.') p += 2;
    cJSON *cur = doc, *parent = NULL;
    const char *key = NULL;
    size_t keylen = 0;
    long index = -1;
    lb__jpath wp; /* where the walk is, as a JSON path */
    lb__jpath_set(&wp, "$");
    const char *where = wp.s;
    while (p < end) {
        if (*p == '.') ++p;
        parent = cur;
        key = NULL;
        index = -1;
        if (*p == '[') {
            char *e2 = NULL;
            index = strtol(p + 1, &e2, 10);
            if (!e2 || e2 >= end || *e2 != ']' || index < 0 || e2 == p + 1 ||
                !isdigit((unsigned char)p[1]) || (e2 - p > 2 && p[1] == '0') || e2 - p > 10) {
                snprintf(why, whylen,
                         "after %s: expected [INDEX], INDEX digits without leading zeros", where);
                return -1;
            }
            p = e2 + 1;
            if (!cJSON_IsArray(parent)) {
                snprintf(why, whylen, "%s is not an array", where);
                return -1;
            }
            const int n = cJSON_GetArraySize(parent);
            if (index >= n) {
                snprintf(why, whylen, "%s has %d element%s; allowed: indexes 0 to %d", where, n,
                         n == 1 ? "" : "s", n - 1);
                return -1;
            }
            cur = cJSON_GetArrayItem(parent, (int)index);
            lb__jpath_index(&wp, (size_t)index);
        } else {
            key = p;
            while (p < end && *p != '.' && *p != '[') ++p;
            keylen = (size_t)(p - key);
            if (!keylen) {
                snprintf(why, whylen, "after %s: an empty key", where);
                return -1;
            }
            if (!cJSON_IsObject(parent)) {
                snprintf(why, whylen, "%s is not an object", where);
                return -1;
            }
            char k[256];
            if (keylen >= sizeof k) {
                snprintf(why, whylen, "after %s: a key longer than 255 bytes", where);
                return -1;
            }
            memcpy(k, key, keylen);
            k[keylen] = '\0';
            cur = cJSON_GetObjectItemCaseSensitive(parent, k);
            lb__jpath_key(&wp, k);
            if (!cur && p < end) {
                snprintf(why, whylen, "%s does not exist", where);
                return -1;
            }
        }
    }
    if (!parent) {
        snprintf(why, whylen, "the path is empty; allowed: a path such as root.args[0].radius");
        return -1;
    }
    cJSON *v = cJSON_ParseWithOpts(s->value, NULL, 1);
    if (!v || !all_finite(v)) {
        cJSON_Delete(v);
        snprintf(why, whylen,
                 "the value %.60s is not one finite JSON value; allowed: a number, true, false, "
                 "null, a \"quoted string\", an array or an object",
                 s->value);
        return -1;
    }
    if (index >= 0) {
        cJSON_ReplaceItemInArray(parent, (int)index, v);
    } else {
        char k[256];
        memcpy(k, key, keylen);
        k[keylen] = '\0';
        if (cJSON_GetObjectItemCaseSensitive(parent, k))
            cJSON_ReplaceItemInObjectCaseSensitive(parent, k, v);
        else
            cJSON_AddItemToObject(parent, k, v);
    }
    return 0;
}

/* "--set A=1, --set B=2" into buf */
static void list_sets(const bt_set *sets, size_t n, char *buf, size_t len) {
    size_t o = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < n && o + 1 < len; ++i) {
        const int w = snprintf(buf + o, len - o, "%s--set %s", i ? ", " : "", sets[i].path);
        if (w < 0) break;
        o += (size_t)w;
    }
}

int bt_load_scene_set(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                      lb_scene **scene, uint64_t hash[2]) {
    if (!nsets && !hash) return bt_load_scene(cmd, path, scene);
    char why[1024];
    size_t len = 0;
    char *text = bt_read_file(path, LB_SCENE_MAX_BYTES, &len, why, sizeof why);
    if (!text) { /* the library says why, in its words (missing, folder, too large) */
        const int rc = bt_load_scene(cmd, path, scene);
        if (!rc) {
            lb_scene_free(*scene);
            *scene = NULL;
            bt_error(cmd, "%s: cannot read the scene (%s)", path, why);
        }
        return rc ? rc : BT_EXIT_BAD_INPUT;
    }
    cJSON *doc = nsets ? cJSON_ParseWithLength(text, len) : NULL;
    if (nsets && !doc) { /* not JSON: the library's message (line and column) */
        free(text);
        return bt_load_scene(cmd, path, scene);
    }
    for (size_t i = 0; i < nsets; ++i)
        if (apply_one(doc, &sets[i], why, sizeof why)) {
            bt_error(cmd, "%s: --set %s: %s", path, sets[i].path, why);
            cJSON_Delete(doc);
            free(text);
            return BT_EXIT_BAD_INPUT;
        }
    char *resolved = doc ? cJSON_PrintUnformatted(doc) : NULL;
    cJSON_Delete(doc);
    if (doc && !resolved) {
        free(text);
        bt_error(cmd, "%s: out of memory", path);
        return BT_EXIT_INTERNAL;
    }
    const char *use = resolved ? resolved : text;
    const size_t ulen = resolved ? strlen(resolved) : len;
    lb_error e = {LB_OK, ""};
    lb_status s = lb_scene_parse(use, ulen, path, scene, &e);
    int rc = BT_EXIT_OK;
    if (s) {
        char sl[1024];
        list_sets(sets, nsets, sl, sizeof sl);
        rc = bt_exit_for(s);
        if (nsets)
            bt_error(cmd, "%s (with %s)", e.message, sl);
        else
            bt_error(cmd, "%s", e.message);
    } else if (hash) {
        const XXH128_hash_t h = XXH3_128bits(use, ulen);
        hash[0] = h.high64;
        hash[1] = h.low64;
    }
    free(resolved);
    free(text);
    return rc;
}

char *bt_scene_text_set(const char *cmd, const char *path, const bt_set *sets, size_t nsets,
                        size_t *len) {
    char why[1024];
    char *text = bt_read_file(path, LB_SCENE_MAX_BYTES, len, why, sizeof why);
    if (!text) {
        bt_error(cmd, "%s: cannot read the scene (%s)", path, why);
        return NULL;
    }
    if (!nsets) return text;
    cJSON *doc = cJSON_ParseWithLength(text, *len);
    free(text);
    for (size_t i = 0; doc && i < nsets; ++i)
        if (apply_one(doc, &sets[i], why, sizeof why)) {
            bt_error(cmd, "%s: --set %s: %s", path, sets[i].path, why);
            cJSON_Delete(doc);
            return NULL;
        }
    char *resolved = doc ? cJSON_PrintUnformatted(doc) : NULL;
    cJSON_Delete(doc);
    if (!resolved) bt_error(cmd, "%s: the scene is not JSON, or out of memory", path);
    *len = resolved ? strlen(resolved) : 0;
    return resolved;
}
