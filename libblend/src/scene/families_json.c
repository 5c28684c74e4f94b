/* The family registry as JSON (lb_scene_families_json): what the rows of
 * operators/families.def say, for the tools that keep their own lists. */
#include "scene_internal.h"
#include "libblend/pov.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <string.h>

static cJSON *string_list(const char *const *v) {
    cJSON *a = cJSON_CreateArray();
    for (; a && *v; ++v) cJSON_AddItemToArray(a, cJSON_CreateString(*v));
    return a;
}

static const char *const OPS[] = {"union", "intersection", "difference"};

/* the set operations of bits (1 << op) */
static cJSON *ops_list(unsigned bits) {
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < 3; ++i)
        if (bits & (1u << i)) cJSON_AddItemToArray(a, cJSON_CreateString(OPS[i]));
    return a;
}

static cJSON *param_json(const lb__param *p) {
    cJSON *o = cJSON_CreateObject();
    char ok[96];
    cJSON_AddStringToObject(o, "key", p->key);
    cJSON_AddBoolToObject(o, "per_argument", 1);
    cJSON_AddBoolToObject(o, "required", p->required);
    if (p->required)
        cJSON_AddNullToObject(o, "default");
    else
        cJSON_AddNumberToObject(o, "default", p->def);
    cJSON_AddNumberToObject(o, p->open_lo ? "exclusive_minimum" : "minimum", p->lo);
    cJSON_AddNumberToObject(o, "maximum", p->hi);
    lb__param_allowed(p, 0, ok, sizeof ok);
    cJSON_AddStringToObject(o, "allowed", ok);
    if (p->hi_alt_ops) {
        cJSON *alt = cJSON_AddObjectToObject(o, "maximum_under");
        cJSON_AddItemToObject(alt, "ops", ops_list(p->hi_alt_ops));
        cJSON_AddNumberToObject(alt, "maximum", p->hi_alt);
        lb__param_allowed(p, 1, ok, sizeof ok);
        cJSON_AddStringToObject(alt, "allowed", ok);
    }
    cJSON_AddStringToObject(o, "description", p->blurb);
    return o;
}

static cJSON *shape_json(const lb__shape *sh) {
    static const char *const conv[] = {"zero", "soft"};
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "key", sh->key);
    cJSON_AddBoolToObject(o, "per_argument", 0);
    cJSON_AddBoolToObject(o, "required", sh->required);
    if (sh->required)
        cJSON_AddNullToObject(o, "default");
    else
        cJSON_AddNumberToObject(o, "default", sh->def);
    cJSON_AddBoolToObject(o, "below_r1_r2", sh->below_r1r2);
    cJSON *by = cJSON_AddObjectToObject(o, "range");
    for (int c = 0; c < 2 && by; ++c) {
        cJSON *r = cJSON_AddObjectToObject(by, conv[c]);
        if (sh->below_r1r2) continue; /* a bound that depends on r: below_r1_r2 */
        cJSON_AddNumberToObject(r, "minimum", sh->lo[c]);
        cJSON_AddNumberToObject(r, "maximum", sh->hi[c]);
    }
    cJSON_AddStringToObject(o, "description", sh->blurb);
    return o;
}

static cJSON *operator_json(const lb__family_row *row) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", row->name);
    cJSON *conv = cJSON_AddArrayToObject(o, "conventions");
    if (row->conv & LB__CONV_ZERO) cJSON_AddItemToArray(conv, cJSON_CreateString("zero"));
    if (row->conv & LB__CONV_SOFT) cJSON_AddItemToArray(conv, cJSON_CreateString("soft"));
    cJSON_AddItemToObject(o, "ops",
                          ops_list(row->ops == LB__OPS_ALL  ? 7u
                                   : row->ops == LB__OPS_UI ? 3u
                                                            : 0u));
    cJSON_AddNumberToObject(o, "min_args", (double)row->kmin);
    cJSON_AddNumberToObject(o, "max_args", (double)row->kmax);
    cJSON_AddItemToObject(o, "keys", string_list(row->keys));
    cJSON *ps = cJSON_AddArrayToObject(o, "parameters");
    for (const lb__param *p = row->params; p->key && ps; ++p)
        cJSON_AddItemToArray(ps, param_json(p));
    if (row->shape) cJSON_AddItemToArray(ps, shape_json(row->shape));
    cJSON_AddBoolToObject(o, "bulge", row->bulge_family >= 0);
    cJSON_AddBoolToObject(o, "bounding_solids", (row->flags & LB__R_BOUNDING) != 0);
    cJSON_AddBoolToObject(o, "folds_to_binary", (row->flags & LB__R_FOLD_BINARY) != 0);
    cJSON_AddBoolToObject(o, "uses_argument_values", !(row->flags & LB__R_ZERO_SETS_ONLY));
    cJSON_AddNumberToObject(o, "pov_max_args",
                            row->flags & LB__R_POV16 ? LB_POV_MAX_ARITY : LB_MAX_ARITY);
    cJSON *pov = cJSON_AddArrayToObject(o, "pov_macros");
    for (int i = 0; i < 3 && pov && row->pov[i]; ++i)
        cJSON_AddItemToArray(pov, cJSON_CreateString(row->pov[i]));
    cJSON_AddStringToObject(o, "description", row->blurb);
    return o;
}

static cJSON *registry_json(void) {
    cJSON *root = cJSON_CreateObject();
    char version[32];
    snprintf(version, sizeof version, "%d.%d.%d", LB_VERSION_MAJOR, LB_VERSION_MINOR,
             LB_VERSION_PATCH);
    cJSON_AddStringToObject(root, "libblend", version);
    static const char *const common[] = {LB__TRANSFORM_KEYS, NULL};
    cJSON_AddItemToObject(root, "common_keys", string_list(common));
    cJSON *prims = cJSON_AddArrayToObject(root, "primitives");
    size_t np = 0;
    const lb__primitive_row *P = lb__primitive_rows(&np);
    for (size_t i = 0; i < np && prims; ++i) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "type", P[i].name);
        cJSON_AddItemToObject(o, "keys", string_list(P[i].keys));
        cJSON_AddItemToObject(o, "soft_keys", string_list(lb__primitive_soft_keys));
        cJSON_AddStringToObject(o, "description", P[i].blurb);
        cJSON_AddItemToArray(prims, o);
    }
    cJSON *ops = cJSON_AddArrayToObject(root, "operators");
    for (int f = 1; f < LB__F_COUNT && ops; ++f) {
        const lb__family_row *row = lb__family_info((lb__family)f);
        if (!(row->flags & LB__R_NO_PARSE)) cJSON_AddItemToArray(ops, operator_json(row));
    }
    return root;
}

size_t lb_scene_families_json(char *buf, size_t size) {
    if (!buf) size = 0;
    if (buf && size) buf[0] = '\0';
    cJSON *root = registry_json();
    char *txt = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!txt) return 0;
    const size_t len = strlen(txt);
    if (buf && size) {
        const size_t n = len < size - 1 ? len : size - 1;
        memcpy(buf, txt, n);
        buf[n] = '\0';
    }
    cJSON_free(txt);
    return len;
}
