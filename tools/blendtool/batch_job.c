/* blendtool batch: reading and checking the job file (docs/batch.md). */
#define _GNU_SOURCE /* fopencookie */
#include "batch.h"

/* a bad job file: exit 2 with the file, the JSON path and what is allowed */
int batch_bad(const job *J, const char *path, const char *fmt, ...) {
    char msg[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    bt_error(CMD, "%s: %s: %s", J->file, path, msg);
    return BT_EXIT_BAD_INPUT;
}

/* every key of o one of keys, once (common/json_check.c, as for scenes) */
static int check_keys(const job *J, const cJSON *o, const char *path, const char *const *keys) {
    const cJSON *bad = NULL;
    const int k = lb__json_keys(o, keys, &bad);
    if (k == 2)
        return batch_bad(J, path, "key \"%s\" appears twice; allowed: each key once", bad->string);
    if (k == 1) {
        char allowed[512] = "";
        size_t o2 = 0;
        for (int i = 0; keys[i] && o2 < sizeof allowed; ++i)
            o2 +=
                (size_t)snprintf(allowed + o2, sizeof allowed - o2, "%s%s", i ? ", " : "", keys[i]);
        return batch_bad(J, path, "unknown key \"%s\"; allowed: %s", bad->string, allowed);
    }
    return 0;
}

static int get_int(const job *J, const cJSON *o, const char *key, const char *path, long lo,
                   long hi, long *out) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) return 0;
    if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble) || v->valuedouble < lo ||
        v->valuedouble > hi) {
        char num[64] = "";
        if (cJSON_IsNumber(v)) snprintf(num, sizeof num, " %.17g", v->valuedouble);
        return batch_bad(J, path, "\"%s\" is %s%s; allowed: an integer from %ld to %ld", key,
                         lb__json_kind(v), num, lo, hi);
    }
    *out = (long)v->valuedouble;
    return 0;
}

/* An optional boolean o[key] at path into *out (false when absent); what
 * says what true does. */
static int get_bool(const job *J, const cJSON *o, const char *key, const char *path,
                    const char *what, int *out) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (v && !cJSON_IsBool(v))
        return batch_bad(J, path, "expected true or false, found %s; allowed: true (%s) or false",
                         lb__json_kind(v), what);
    *out = cJSON_IsTrue(v);
    return 0;
}

char *batch_dupstr(const char *s) {
    char *d = malloc(strlen(s) + 1);
    if (d) strcpy(d, s);
    return d;
}

/* One safe file name and one --list field: ASCII letters, digits, '_', '-',
 * '.', '+' and well-formed UTF-8 beyond ASCII; not starting with '.' or
 * '-' (hidden files, options); 1 to 200 bytes. Nothing a shell, a tab-
 * separated list or a #SBATCH line gives a meaning to. */
static int safe_word(const char *s, int allow_lead_dot) {
    const unsigned char *u = (const unsigned char *)s;
    const size_t n = strlen(s);
    if (n < 1 || n > 200 || (!allow_lead_dot && u[0] == '.') || u[0] == '-') return 0;
    for (size_t i = 0; i < n;) {
        const unsigned char c = u[i];
        if (c < 0x80) {
            if (!(isalnum(c) || c == '_' || c == '-' || c == '.' || c == '+')) return 0;
            ++i;
            continue;
        }
        /* a UTF-8 sequence: its lead byte, then continuation bytes */
        const size_t len = c >= 0xF0 && c <= 0xF4  ? 4
                           : c >= 0xE0             ? 3
                           : c >= 0xC2 && c < 0xE0 ? 2
                                                   : 0;
        if (!len || i + len > n) return 0;
        for (size_t k = 1; k < len; ++k)
            if ((u[i + k] & 0xC0) != 0x80) return 0;
        i += len;
    }
    return strcmp(s, ".") && strcmp(s, "..");
}

#define SAFE_WORD_ALLOWED                                                                          \
    "1 to 200 bytes of letters, digits, '_', '-', '.', '+' or UTF-8 letters, not starting "        \
    "with '.' or '-'"

static char *num_text(double x) {
    char b[64];
    snprintf(b, sizeof b, "%.17g", x);
    /* the shortest text that reads back the same number */
    for (int p = 1; p <= 17; ++p) {
        char t[64];
        snprintf(t, sizeof t, "%.*g", p, x);
        if (strtod(t, NULL) == x) {
            strcpy(b, t);
            break;
        }
    }
    return batch_dupstr(b);
}

/* "root.args[0].radius" style: letters, digits, _, ., [n], $ */
static int path_ok(const char *p) {
    if (!*p) return 0;
    for (const char *c = p; *c; ++c)
        if (!(isalnum((unsigned char)*c) || *c == '_' || *c == '.' || *c == '[' || *c == ']' ||
              *c == '$'))
            return 0;
    return 1;
}

static int parse_axis(const job *J, const cJSON *a, const char *path, axis *X) {
    static const char *const keys[] = {"path", "values", "range", "label", NULL};
    if (!cJSON_IsObject(a))
        return batch_bad(J, path,
                         "expected an object {\"path\": ..., \"values\": [...]} or "
                         "{\"path\": ..., \"range\": {...}}, found %s",
                         lb__json_kind(a));
    int rc = check_keys(J, a, path, keys);
    if (rc) return rc;
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(a, "path");
    if (!cJSON_IsString(p) || !path_ok(p->valuestring))
        return batch_bad(J, path,
                         "\"path\" is %s; allowed: a JSON path into the scene such as "
                         "\"root.args[0].radius\"",
                         lb__json_kind(p));
    X->path = batch_dupstr(p->valuestring);
    const cJSON *lab = cJSON_GetObjectItemCaseSensitive(a, "label");
    if (lab) {
        /* printed on the sheet and into image metadata: printable ASCII */
        const char *l = cJSON_IsString(lab) ? lab->valuestring : NULL;
        int ok = l && *l && strlen(l) < sizeof X->label;
        for (const char *c = l; ok && *c; ++c) ok = *c > ' ' && *c < 127 && *c != '=';
        if (!ok)
            return batch_bad(J, path,
                             "\"label\" is %s; allowed: 1 to %zu printable ASCII characters "
                             "without spaces or '=' (such as \"m2\")",
                             l ? "not such a name" : lb__json_kind(lab), sizeof X->label - 1);
        memcpy(X->label, l, strlen(l) + 1);
    }
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(a, "values");
    const cJSON *rg = cJSON_GetObjectItemCaseSensitive(a, "range");
    if (!!vals == !!rg) return batch_bad(J, path, "give one of \"values\" (a list) or \"range\"");
    if (vals) {
        if (!cJSON_IsArray(vals) || cJSON_GetArraySize(vals) < 1)
            return batch_bad(J, path, "\"values\" is %s; allowed: a non-empty list of JSON values",
                             lb__json_kind(vals));
        X->n = (size_t)cJSON_GetArraySize(vals);
        X->values = calloc(X->n, sizeof *X->values);
        size_t i = 0;
        for (const cJSON *v = vals->child; v && X->values; v = v->next)
            X->values[i++] = cJSON_PrintUnformatted(v);
        return X->values ? 0 : BT_EXIT_INTERNAL;
    }
    static const char *const rkeys[] = {"from", "to", "count", NULL};
    lb__jpath rpath;
    lb__jpath_set(&rpath, path);
    lb__jpath_key(&rpath, "range");
    const char *rp = rpath.s;
    if (!cJSON_IsObject(rg))
        return batch_bad(J, rp, "expected {\"from\": A, \"to\": B, \"count\": N}");
    if ((rc = check_keys(J, rg, rp, rkeys))) return rc;
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(rg, "from"),
                *t = cJSON_GetObjectItemCaseSensitive(rg, "to");
    long count = -1;
    if (!cJSON_IsNumber(f) || !cJSON_IsNumber(t))
        return batch_bad(J, rp, "\"from\" is %s and \"to\" %s; allowed: numbers", lb__json_kind(f),
                         lb__json_kind(t));
    if ((rc = get_int(J, rg, "count", rp, 1, MAX_TASKS, &count))) return rc;
    if (count < 1)
        return batch_bad(J, rp, "\"count\" is missing; allowed: an integer from 1 to %d",
                         MAX_TASKS);
    const double va = f->valuedouble, vb = t->valuedouble;
    if (!isfinite(va) || !isfinite(vb) || fabs(va) > 1e300 || fabs(vb) > 1e300)
        return batch_bad(J, rp, "from %g to %g; allowed: finite numbers of magnitude at most 1e300",
                         va, vb);
    X->n = (size_t)count;
    X->values = calloc(X->n, sizeof *X->values);
    for (size_t i = 0; i < X->n && X->values; ++i) {
        const double u = X->n == 1 ? 0.0 : (double)i / (double)(X->n - 1);
        X->values[i] = num_text(va + (vb - va) * u);
    }
    return X->values ? 0 : BT_EXIT_INTERNAL;
}

/* the value of a keyframed path at frame fr: linear, step or smooth (ease
 * in and out) between the keys around it, held before the first and after
 * the last */
static double key_value(const cJSON *keys, const char *interp, double fr) {
    const cJSON *k0 = keys->child, *prev = NULL;
    for (const cJSON *k = k0; k; prev = k, k = k->next) {
        const double f = cJSON_GetArrayItem(k, 0)->valuedouble;
        const double v = cJSON_GetArrayItem(k, 1)->valuedouble;
        if (fr <= f) {
            if (!prev || fr == f) return v;
            const double pf = cJSON_GetArrayItem(prev, 0)->valuedouble;
            const double pv = cJSON_GetArrayItem(prev, 1)->valuedouble;
            double u = (fr - pf) / (f - pf);
            if (strcmp(interp, "step") == 0) return pv;
            if (strcmp(interp, "smooth") == 0) u = u * u * (3.0 - 2.0 * u);
            return pv + (v - pv) * u;
        }
    }
    return cJSON_GetArrayItem(prev, 1)->valuedouble;
}

static int parse_frames(job *J, const cJSON *fr) {
    static const char *const keys[] = {"first", "last", "fps", "animate", NULL};
    if (!cJSON_IsObject(fr))
        return batch_bad(J, "$.frames",
                         "expected {\"first\": A, \"last\": B, \"animate\": [...]}, found %s",
                         lb__json_kind(fr));
    int rc = check_keys(J, fr, "$.frames", keys);
    if (rc) return rc;
    J->first = J->last = -1;
    if ((rc = get_int(J, fr, "first", "$.frames", 0, 9999999, &J->first)) ||
        (rc = get_int(J, fr, "last", "$.frames", 0, 9999999, &J->last)))
        return rc;
    if (J->first < 0 || J->last < J->first || J->last - J->first >= MAX_TASKS)
        return batch_bad(J, "$.frames",
                         "first %ld, last %ld; allowed: both given, first <= last, at most %d "
                         "frames",
                         J->first, J->last, MAX_TASKS);
    J->has_frames = 1;
    long fps = 24;
    if ((rc = get_int(J, fr, "fps", "$.frames", 1, 1000, &fps))) return rc;
    J->fps = (int)fps;
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(fr, "animate");
    if (!an) return 0;
    if (!cJSON_IsArray(an) || cJSON_GetArraySize(an) > MAX_AXES)
        return batch_bad(J, "$.frames.animate", "expected a list of at most %d animated paths",
                         MAX_AXES);
    size_t i = 0;
    for (const cJSON *a = an->child; a; a = a->next, ++i) {
        lb__jpath jp;
        lb__jpath_set(&jp, "$.frames");
        lb__jpath_key(&jp, "animate");
        lb__jpath_index(&jp, i);
        const char *path = jp.s;
        static const char *const akeys[] = {"path", "keys", "interpolation", NULL};
        if (!cJSON_IsObject(a))
            return batch_bad(J, path, "expected an object, found %s", lb__json_kind(a));
        if ((rc = check_keys(J, a, path, akeys))) return rc;
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(a, "path"),
                    *k = cJSON_GetObjectItemCaseSensitive(a, "keys"),
                    *in = cJSON_GetObjectItemCaseSensitive(a, "interpolation");
        if (!cJSON_IsString(p) || !path_ok(p->valuestring))
            return batch_bad(J, path, "\"path\" is %s; allowed: a JSON path into the scene",
                             lb__json_kind(p));
        const char *interp = in ? (cJSON_IsString(in) ? in->valuestring : "") : "linear";
        if (strcmp(interp, "linear") && strcmp(interp, "step") && strcmp(interp, "smooth"))
            return batch_bad(J, path,
                             "\"interpolation\" is %s; allowed: \"linear\", \"step\", \"smooth\"",
                             in && cJSON_IsString(in) ? in->valuestring : lb__json_kind(in));
        if (!cJSON_IsArray(k) || cJSON_GetArraySize(k) < 1)
            return batch_bad(J, path, "\"keys\" is %s; allowed: a list of [frame, number] pairs",
                             lb__json_kind(k));
        double lastf = -INFINITY;
        size_t j = 0;
        for (const cJSON *q = k->child; q; q = q->next, ++j) {
            const cJSON *f = cJSON_GetArrayItem(q, 0), *v = cJSON_GetArrayItem(q, 1);
            if (!cJSON_IsArray(q) || cJSON_GetArraySize(q) != 2 || !cJSON_IsNumber(f) ||
                !cJSON_IsNumber(v))
                return batch_bad(J, path, "keys[%zu] is %s; allowed: a [frame, number] pair", j,
                                 lb__json_kind(q));
            if (!(f->valuedouble > lastf))
                return batch_bad(J, path,
                                 "keys[%zu]: frame %g after %g; allowed: increasing frames", j,
                                 f->valuedouble, lastf);
            lastf = f->valuedouble;
        }
        axis *X = &J->anim[J->nanim++];
        X->path = batch_dupstr(p->valuestring);
        X->n = (size_t)(J->last - J->first + 1);
        X->values = calloc(X->n, sizeof *X->values);
        X->keys = cJSON_Duplicate(k, 1);
        snprintf(X->interp, sizeof X->interp, "%s", interp);
        for (size_t f = 0; f < X->n && X->values; ++f)
            X->values[f] = num_text(key_value(k, interp, (double)(J->first + (long)f)));
    }
    return 0;
}

/* outputs.image's renderer: "povray" (the default) or "blender" with its
 * engine, samples, seed, device, threads and motion blur; each key is
 * refused where its renderer has no use for it. mres: the mesh resolution
 * (Blender always renders a mesh: 128 cells unless "mesh" says) */
static int parse_renderer(job *J, const cJSON *im, long *mres) {
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(im, "renderer");
    const char *rn = r ? (cJSON_IsString(r) ? r->valuestring : "") : "povray";
    if (strcmp(rn, "povray") && strcmp(rn, "blender"))
        return batch_bad(J, "$.outputs.image.renderer", "%s; allowed: \"povray\" or \"blender\"",
                         r && cJSON_IsString(r) ? r->valuestring : lb__json_kind(r));
    J->blender = !strcmp(rn, "blender");
    static const char *const pov_only[] = {"quality", "antialias", NULL};
    static const char *const blender_only[] = {"engine", "samples",     "seed",
                                               "device", "motion_blur", NULL};
    const char *const *other = J->blender ? pov_only : blender_only;
    for (size_t i = 0; other[i]; ++i)
        if (cJSON_GetObjectItemCaseSensitive(im, other[i])) {
            char path[64];
            snprintf(path, sizeof path, "$.outputs.image.%s", other[i]);
            return batch_bad(J, path,
                             "is for the %s renderer; allowed with \"renderer\": \"%s\": %s",
                             J->blender ? "povray" : "blender", rn,
                             J->blender ? "engine, samples, seed, device, threads, motion_blur"
                                        : "quality, antialias, mesh");
        }
    if (!J->blender) {
        if (cJSON_GetObjectItemCaseSensitive(im, "threads"))
            return batch_bad(J, "$.outputs.image.threads",
                             "is for the blender renderer; allowed for povray: --threads");
        return 0;
    }
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(im, "engine"),
                *d = cJSON_GetObjectItemCaseSensitive(im, "device");
    const char *en = e ? (cJSON_IsString(e) ? e->valuestring : "") : "cycles";
    if (strcmp(en, "cycles") && strcmp(en, "eevee"))
        return batch_bad(J, "$.outputs.image.engine", "%s; allowed: \"cycles\" or \"eevee\"",
                         e && cJSON_IsString(e) ? e->valuestring : lb__json_kind(e));
    if (d && !(cJSON_IsString(d) && !strcmp(d->valuestring, "CPU")))
        return batch_bad(J, "$.outputs.image.device",
                         "%s; allowed: \"CPU\" (farm nodes render on their processors)",
                         cJSON_IsString(d) ? d->valuestring : lb__json_kind(d));
    snprintf(J->engine, sizeof J->engine, "%s", en);
    long samples = 16, seed = 0, threads = 0;
    int rc;
    if ((rc = get_int(J, im, "samples", "$.outputs.image", 1, 65536, &samples)) ||
        (rc = get_int(J, im, "seed", "$.outputs.image", 0, 2147483647L, &seed)) ||
        (rc = get_int(J, im, "threads", "$.outputs.image", 0, 1024, &threads)))
        return rc;
    J->samples = (int)samples;
    J->seed = (int)seed;
    J->blender_threads = (int)threads;
    const cJSON *mb = cJSON_GetObjectItemCaseSensitive(im, "motion_blur");
    J->shutter = 0;
    if (mb) {
        if (!cJSON_IsNumber(mb) || !(mb->valuedouble > 0) || mb->valuedouble > 2)
            return batch_bad(J, "$.outputs.image.motion_blur",
                             "is %s; allowed: the shutter in frames, a number in (0, 2]",
                             cJSON_IsNumber(mb) ? "out of range" : lb__json_kind(mb));
        if (!J->has_frames)
            return batch_bad(J, "$.outputs.image.motion_blur",
                             "needs frames; allowed: a job with \"frames\" (an animation)");
        J->shutter = mb->valuedouble;
    }
    if (!*mres) *mres = 128;
    return 0;
}

/* outputs.vdb: {"resolution": N | "voxel_size": H, "band": W, "grids": [...]} */
static int parse_vdb(job *J, const cJSON *v) {
    static const char *const vk[] = {"resolution", "voxel_size",    "band",
                                     "grids",      "voxel_centres", NULL};
    if (!cJSON_IsObject(v))
        return batch_bad(J, "$.outputs.vdb", "expected an object, found %s", lb__json_kind(v));
    int rc = check_keys(J, v, "$.outputs.vdb", vk);
    if (rc) return rc;
    J->vdb = 1;
    long r = LB_LEVEL_SET_DEFAULT_RESOLUTION;
    if ((rc =
             get_int(J, v, "resolution", "$.outputs.vdb", 1, LB_LEVEL_SET_MAX_VOXELS_PER_AXIS, &r)))
        return rc;
    J->vdb_res = (int)r;
    const cJSON *h = cJSON_GetObjectItemCaseSensitive(v, "voxel_size");
    if (h && cJSON_GetObjectItemCaseSensitive(v, "resolution"))
        return batch_bad(J, "$.outputs.vdb.voxel_size",
                         "given with resolution; allowed: one of them (the voxel size, or the "
                         "voxels along the longest side)");
    if (h && (!cJSON_IsNumber(h) || !(h->valuedouble > 0.0) || !isfinite(h->valuedouble)))
        return batch_bad(J, "$.outputs.vdb.voxel_size", "%s; allowed: a positive number",
                         cJSON_IsNumber(h) ? "out of range" : lb__json_kind(h));
    J->vdb_voxel = h ? h->valuedouble : 0.0;
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(v, "band");
    if (b && (!cJSON_IsNumber(b) || !(b->valuedouble >= 1.0) ||
              !(b->valuedouble <= LB_LEVEL_SET_MAX_BAND)))
        return batch_bad(J, "$.outputs.vdb.band", "%s; allowed: 1 to %g voxels",
                         cJSON_IsNumber(b) ? "out of range" : lb__json_kind(b),
                         LB_LEVEL_SET_MAX_BAND);
    J->vdb_band = b ? b->valuedouble : LB_LEVEL_SET_DEFAULT_BAND;
    const cJSON *vc = cJSON_GetObjectItemCaseSensitive(v, "voxel_centres");
    if (vc && !(cJSON_IsString(vc) &&
                (!strcmp(vc->valuestring, "openvdb") || !strcmp(vc->valuestring, "blender"))))
        return batch_bad(J, "$.outputs.vdb.voxel_centres",
                         "%s; allowed: \"openvdb\" (voxel (i, j, k) at (i h, j h, k h)) or "
                         "\"blender\" (placed for Blender's half-voxel convention)",
                         cJSON_IsString(vc) ? vc->valuestring : lb__json_kind(vc));
    J->vdb_blender = vc && !strcmp(vc->valuestring, "blender");
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(v, "grids");
    if (g && !cJSON_IsArray(g))
        return batch_bad(J, "$.outputs.vdb.grids", "expected an array, found %s", lb__json_kind(g));
    J->vdb_grids = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, g) {
        if (cJSON_IsString(it) && !strcmp(it->valuestring, "value"))
            J->vdb_grids |= LB_LEVEL_SET_FIELD;
        else if (cJSON_IsString(it) && !strcmp(it->valuestring, "gradient"))
            J->vdb_grids |= LB_LEVEL_SET_GRADIENT;
        else if (!(cJSON_IsString(it) && !strcmp(it->valuestring, "surface")))
            return batch_bad(J, "$.outputs.vdb.grids",
                             "%s; allowed: \"surface\" (always written), \"value\", "
                             "\"gradient\"",
                             cJSON_IsString(it) ? it->valuestring : lb__json_kind(it));
    }
    return 0;
}

static int parse_outputs(job *J, const cJSON *o) {
    static const char *const keys[] = {"mesh", "pov", "vdb", "image", "contact_sheet", NULL};
    if (!cJSON_IsObject(o) || !o->child)
        return batch_bad(J, "$.outputs",
                         "expected an object with at least one of mesh, pov, vdb, image");
    int rc = check_keys(J, o, "$.outputs", keys);
    if (rc) return rc;
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(o, "mesh");
    if (m) {
        static const char *const mk[] = {"format",   "resolution", "features",
                                         "simplify", "merge_flat", NULL};
        if (!cJSON_IsObject(m))
            return batch_bad(J, "$.outputs.mesh", "expected an object, found %s", lb__json_kind(m));
        if ((rc = check_keys(J, m, "$.outputs.mesh", mk))) return rc;
        J->mesh = 1;
        J->mesh_fmt = LB_MESH_FORMAT_PLY;
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(m, "format");
        if (f) {
            static const char *const names[] = {"ply", "obj", "stl", "glb"};
            J->mesh_fmt = LB_MESH_FORMAT_AUTO;
            for (int i = 0; i < 4 && cJSON_IsString(f); ++i)
                if (strcmp(f->valuestring, names[i]) == 0)
                    J->mesh_fmt = (lb_mesh_format)(LB_MESH_FORMAT_PLY + i);
            if (J->mesh_fmt == LB_MESH_FORMAT_AUTO)
                return batch_bad(J, "$.outputs.mesh.format",
                                 "%s; allowed: \"ply\", \"obj\", \"stl\", \"glb\"",
                                 cJSON_IsString(f) ? f->valuestring : lb__json_kind(f));
        }
        long r = 128;
        if ((rc = get_int(J, m, "resolution", "$.outputs.mesh", 1, LB_MESH_MAX_CELLS_PER_AXIS, &r)))
            return rc;
        J->mesh_res = (int)r;
        if ((rc = get_bool(J, m, "features", "$.outputs.mesh.features",
                           "keep sharp creases and corners", &J->mesh_features)) ||
            (rc = get_bool(J, m, "merge_flat", "$.outputs.mesh.merge_flat",
                           "flat faces in few triangles, the surface unchanged",
                           &J->mesh_merge_flat)))
            return rc;
        const cJSON *sp = cJSON_GetObjectItemCaseSensitive(m, "simplify");
        if (sp && (!cJSON_IsNumber(sp) || !(sp->valuedouble >= 0.0) ||
                   !(sp->valuedouble <= LB_MESH_MAX_SIMPLIFY)))
            return batch_bad(J, "$.outputs.mesh.simplify",
                             "%s; allowed: a tolerance in cells from 0 (off) to %g",
                             cJSON_IsNumber(sp) ? "out of range" : lb__json_kind(sp),
                             LB_MESH_MAX_SIMPLIFY);
        J->mesh_simplify = sp ? sp->valuedouble : 0.0;
    }
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, "vdb");
    if (v && (rc = parse_vdb(J, v))) return rc;
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "pov");
    if (p) {
        static const char *const pk[] = {"width", "height", NULL};
        if (!cJSON_IsObject(p))
            return batch_bad(J, "$.outputs.pov", "expected an object, found %s", lb__json_kind(p));
        if ((rc = check_keys(J, p, "$.outputs.pov", pk))) return rc;
        long w = 640, h = 480;
        if ((rc = get_int(J, p, "width", "$.outputs.pov", 1, 16384, &w)) ||
            (rc = get_int(J, p, "height", "$.outputs.pov", 1, 16384, &h)))
            return rc;
        J->pov = 1;
        J->pov_w = (int)w;
        J->pov_h = (int)h;
    }
    const cJSON *im = cJSON_GetObjectItemCaseSensitive(o, "image");
    if (im) {
        static const char *const ik[] = {"format",      "bits",    "pixel", "alpha",     "width",
                                         "height",      "quality", "mesh",  "antialias", "renderer",
                                         "engine",      "samples", "seed",  "device",    "threads",
                                         "motion_blur", NULL};
        if (!cJSON_IsObject(im))
            return batch_bad(J, "$.outputs.image", "expected an object, found %s",
                             lb__json_kind(im));
        if ((rc = check_keys(J, im, "$.outputs.image", ik))) return rc;
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(im, "format"),
                    *px = cJSON_GetObjectItemCaseSensitive(im, "pixel"),
                    *al = cJSON_GetObjectItemCaseSensitive(im, "alpha");
        const char *fmt = f ? (cJSON_IsString(f) ? f->valuestring : "") : "png";
        if (strcmp(fmt, "png") && strcmp(fmt, "exr"))
            return batch_bad(J, "$.outputs.image.format", "%s; allowed: \"png\" or \"exr\"",
                             f && cJSON_IsString(f) ? f->valuestring : lb__json_kind(f));
        long bits = 8, w = 320, h = 240, q = 9;
        if ((rc = get_int(J, im, "bits", "$.outputs.image", 8, 16, &bits))) return rc;
        if (bits != 8 && bits != 16)
            return batch_bad(J, "$.outputs.image.bits", "%ld; allowed: 8 or 16", bits);
        if (!strcmp(fmt, "exr") && cJSON_GetObjectItemCaseSensitive(im, "bits"))
            return batch_bad(J, "$.outputs.image.bits", "is for PNG; allowed for EXR: \"pixel\"");
        if (!strcmp(fmt, "png") && px)
            return batch_bad(J, "$.outputs.image.pixel", "is for EXR; allowed for PNG: \"bits\"");
        const char *pix = px ? (cJSON_IsString(px) ? px->valuestring : "") : "half";
        if (strcmp(pix, "half") && strcmp(pix, "float"))
            return batch_bad(J, "$.outputs.image.pixel", "%s; allowed: \"half\" or \"float\"",
                             px && cJSON_IsString(px) ? px->valuestring : lb__json_kind(px));
        if (al && !cJSON_IsBool(al))
            return batch_bad(J, "$.outputs.image.alpha", "is %s; allowed: true or false",
                             lb__json_kind(al));
        const cJSON *aa = cJSON_GetObjectItemCaseSensitive(im, "antialias");
        if (aa && !cJSON_IsBool(aa))
            return batch_bad(J, "$.outputs.image.antialias", "is %s; allowed: true or false",
                             lb__json_kind(aa));
        long mres = 0;
        if ((rc = get_int(J, im, "width", "$.outputs.image", 1, 16384, &w)) ||
            (rc = get_int(J, im, "height", "$.outputs.image", 1, 16384, &h)) ||
            (rc = get_int(J, im, "quality", "$.outputs.image", 0, 11, &q)) ||
            (rc = get_int(J, im, "mesh", "$.outputs.image", 1, LB_POV_MAX_MESH_RESOLUTION, &mres)))
            return rc;
        if ((rc = parse_renderer(J, im, &mres))) return rc;
        J->img_antialias = aa && cJSON_IsTrue(aa);
        J->img_mesh = (int)mres;
        J->image = 1;
        J->img_w = (int)w;
        J->img_h = (int)h;
        J->img_quality = (int)q;
        J->img_alpha = al && cJSON_IsTrue(al);
        J->img_fmt = !strcmp(fmt, "exr") ? (!strcmp(pix, "float") ? LBI_EXR_FLOAT : LBI_EXR_HALF)
                     : bits == 16        ? LBI_PNG16
                                         : LBI_PNG8;
    }
    const cJSON *cs = cJSON_GetObjectItemCaseSensitive(o, "contact_sheet");
    if (cs) {
        static const char *const ck[] = {"columns", "cell_width", "cell_height", NULL};
        if (!cJSON_IsObject(cs))
            return batch_bad(J, "$.outputs.contact_sheet", "expected an object, found %s",
                             lb__json_kind(cs));
        if ((rc = check_keys(J, cs, "$.outputs.contact_sheet", ck))) return rc;
        if (!J->image)
            return batch_bad(
                J, "$.outputs.contact_sheet",
                "needs \"image\" outputs to put on the sheet; allowed: add outputs.image");
        long c = 4, w = 160, h = 120;
        if ((rc = get_int(J, cs, "columns", "$.outputs.contact_sheet", 1, 64, &c)) ||
            (rc = get_int(J, cs, "cell_width", "$.outputs.contact_sheet", 8, 4096, &w)) ||
            (rc = get_int(J, cs, "cell_height", "$.outputs.contact_sheet", 8, 4096, &h)))
            return rc;
        J->sheet = 1;
        J->sheet_cols = (int)c;
        J->sheet_w = (int)w;
        J->sheet_h = (int)h;
    }
    char *text = cJSON_PrintUnformatted(o);
    if (!text) return BT_EXIT_INTERNAL;
    const XXH128_hash_t hh = XXH3_128bits(text, strlen(text));
    J->spec_hash[0] = hh.high64;
    J->spec_hash[1] = hh.low64;
    free(text);
    return 0;
}

/* p relative to the job file's folder (p itself when absolute) into out:
 * 0, or -1 when it does not fit in len bytes */
static int relative(const job *J, const char *p, char *out, size_t len) {
    const int n =
        p[0] == '/' ? snprintf(out, len, "%s", p) : snprintf(out, len, "%s/%s", J->dir, p);
    return n < 0 || (size_t)n >= len ? -1 : 0;
}

/* line and column (from 1) of at in text */
static void text_pos(const char *text, const char *at, long *line, long *col) {
    *line = *col = 1;
    for (const char *c = text; at && c < at && *c; ++c) {
        if (*c == '\n') {
            ++*line;
            *col = 1;
        } else {
            ++*col;
        }
    }
}

/* The first \\u0000 escape inside a JSON string of text, or NULL: cJSON
 * would decode it into a NUL that silently ends the C string. */
/* A pattern: at least one '#', the placeholders {name}, {scene}, {task},
 * and around them what a safe name allows; why names the first fault. */
static int pattern_ok(const char *p, char *why, size_t whylen) {
    char probe[512];
    size_t o = 0;
    int hashes = 0;
    for (const char *c = p; *c; ++c) {
        if (o + 8 >= sizeof probe) {
            snprintf(why, whylen, "more than 200 bytes");
            return 0;
        }
        if (*c == '{') {
            const char *e = strchr(c, '}');
            if (!e ||
                (strncmp(c, "{name}", 6) && strncmp(c, "{scene}", 7) && strncmp(c, "{task}", 6))) {
                snprintf(why, whylen, "an unknown placeholder at \"%.20s\"", c);
                return 0;
            }
            probe[o++] = 'x';
            c = e;
        } else {
            hashes += *c == '#';
            probe[o++] = *c == '#' ? '0' : *c;
        }
    }
    probe[o] = '\0';
    if (!hashes) {
        snprintf(why, whylen, "no # for the frame number");
        return 0;
    }
    if (strlen(p) > 200 || !safe_word(probe, 0)) {
        snprintf(why, whylen, "characters outside a safe name");
        return 0;
    }
    return 1;
}

static const char *nul_escape(const char *text, size_t len) {
    int in = 0;
    for (size_t i = 0; i < len; ++i) {
        if (!in) {
            in = text[i] == '"';
        } else if (text[i] == '"') {
            in = 0;
        } else if (text[i] == '\\' && i + 1 < len) {
            if (text[i + 1] == 'u' && i + 5 < len && !strncmp(text + i + 2, "0000", 4))
                return text + i;
            ++i; /* the escaped character */
        }
    }
    return NULL;
}

/* the job file's text as a cJSON document, or NULL after the message (exit 2) */
static cJSON *read_doc(const char *file) {
    size_t len = 0;
    char why[256];
    char *text = bt_read_file(file, 16u << 20, &len, why, sizeof why);
    if (!text) {
        bt_error(CMD,
                 "%s: cannot read the job file (%s); allowed: a readable file of at most 16 MiB",
                 file, why);
        return NULL;
    }
    const char *nul = nul_escape(text, len);
    if (nul) {
        long line, col;
        text_pos(text, nul, &line, &col);
        free(text);
        bt_error(CMD,
                 "%s:%ld:%ld: a string holds \\u0000 (a NUL byte), which would cut it short; "
                 "allowed: strings without NUL",
                 file, line, col);
        return NULL;
    }
    const char *end = NULL;
    cJSON *doc = strlen(text) == len ? cJSON_ParseWithOpts(text, &end, 1) : NULL;
    if (!doc) {
        long line, col;
        text_pos(text, end ? end : cJSON_GetErrorPtr(), &line, &col);
        bt_error(CMD,
                 "%s:%ld:%ld: not valid JSON; allowed: a libblend-job document (docs/batch.md)",
                 file, line, col);
    } else {
        /* RFC 8259 exactly, as for scenes (common/json_check.c) */
        size_t line, col;
        char near[16];
        const char *what = lb__json_strictness(text, len, &line, &col, near);
        if (what) {
            bt_error(CMD,
                     "%s:%zu:%zu: invalid JSON: %s%s%s%s; allowed: a libblend-job document "
                     "(RFC 8259, docs/batch.md)",
                     file, line, col, what, *near ? " near '" : "", near, *near ? "'" : "");
            cJSON_Delete(doc);
            doc = NULL;
        }
    }
    free(text);
    return doc;
}

/* the document is a libblend-job object of version 1 with known keys only */
static int parse_header(job *J, const cJSON *doc) {
    static const char *const keys[] = {"format",  "version", "name",   "scene",   "scenes",
                                       "set",     "sweep",   "frames", "outputs", "output_dir",
                                       "pattern", "threads", NULL};
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(doc, "format"),
                *v = cJSON_GetObjectItemCaseSensitive(doc, "version");
    if (!cJSON_IsObject(doc))
        return batch_bad(
            J, "$", "expected an object, found %s; allowed: a libblend-job object (docs/batch.md)",
            lb__json_kind(doc));
    if (!cJSON_IsString(f) || strcmp(f->valuestring, "libblend-job"))
        return batch_bad(J, "$.format", "is %s; allowed: \"libblend-job\"",
                         cJSON_IsString(f) ? f->valuestring : lb__json_kind(f));
    if (!cJSON_IsNumber(v) || v->valuedouble != 1)
        return batch_bad(J, "$.version", "is %s; allowed: 1", lb__json_kind(v));
    return check_keys(J, doc, "$", keys);
}

/* name: the job file's stem unless given */
static int parse_name(job *J, const cJSON *doc) {
    const cJSON *nm = cJSON_GetObjectItemCaseSensitive(doc, "name");
    if (nm) {
        if (!cJSON_IsString(nm) || !safe_word(nm->valuestring, 0))
            return batch_bad(J, "$.name", "is %s; allowed: a name of " SAFE_WORD_ALLOWED,
                             !cJSON_IsString(nm) ? lb__json_kind(nm) : "not a safe name");
        snprintf(J->name, sizeof J->name, "%s", nm->valuestring);
        return 0;
    }
    const char *b = strrchr(J->file, '/');
    snprintf(J->name, sizeof J->name, "%s", b ? b + 1 : J->file);
    char *dot = strrchr(J->name, '.');
    if (dot && dot != J->name) *dot = '\0';
    if (!safe_word(J->name, 0))
        return batch_bad(J, "$.name",
                         "missing, and the job file's name is not a safe output name; allowed: "
                         "give \"name\", " SAFE_WORD_ALLOWED);
    return 0;
}

/* "scene" or "scenes": resolved paths of existing files, and their stems */
static int parse_scenes(job *J, const cJSON *doc) {
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(doc, "scene"),
                *scs = cJSON_GetObjectItemCaseSensitive(doc, "scenes");
    if (!!sc == !!scs)
        return batch_bad(J, "$", "give one of \"scene\" (a file) or \"scenes\" (a list of files)");
    if (sc && !cJSON_IsString(sc))
        return batch_bad(J, "$.scene", "is %s; allowed: a scene file, relative to the job file",
                         lb__json_kind(sc));
    if (scs &&
        (!cJSON_IsArray(scs) || cJSON_GetArraySize(scs) < 1 || cJSON_GetArraySize(scs) > 10000))
        return batch_bad(J, "$.scenes", "is %s; allowed: a list of 1 to 10000 scene files",
                         lb__json_kind(scs));
    J->nscenes = sc ? 1 : (size_t)cJSON_GetArraySize(scs);
    J->scenes = calloc(J->nscenes, sizeof *J->scenes);
    J->scene_stems = calloc(J->nscenes, sizeof *J->scene_stems);
    for (size_t i = 0; i < J->nscenes; ++i) {
        const cJSON *s = sc ? sc : cJSON_GetArrayItem(scs, (int)i);
        char path[64];
        snprintf(path, sizeof path, sc ? "$.scene" : "$.scenes[%zu]", i);
        if (!cJSON_IsString(s) || !*s->valuestring)
            return batch_bad(J, path, "is %s; allowed: a scene file, relative to the job file",
                             lb__json_kind(s));
        char full[8192];
        if (relative(J, s->valuestring, full, sizeof full))
            return batch_bad(J, path, "the path is too long; allowed: at most %zu bytes",
                             sizeof full - 1);
        struct stat st;
        if (stat(full, &st) != 0 || !S_ISREG(st.st_mode))
            return batch_bad(J, path,
                             "%s: %s; allowed: an existing scene file (relative to the job file)",
                             full, stat(full, &st) != 0 ? strerror(errno) : "not a regular file");
        J->scenes[i] = batch_dupstr(full);
        const char *b = strrchr(s->valuestring, '/');
        J->scene_stems[i] = batch_dupstr(b ? b + 1 : s->valuestring);
        char *dot = strrchr(J->scene_stems[i], '.');
        if (dot && dot != J->scene_stems[i]) *dot = '\0';
    }
    return 0;
}

/* "set": the fixed overrides, as "path=value" texts */
static int parse_set(job *J, const cJSON *set) {
    if (!cJSON_IsObject(set) || cJSON_GetArraySize(set) > BT_MAX_SETS / 2)
        return batch_bad(J, "$.set",
                         "is %s; allowed: an object of at most %d {\"path\": value} overrides",
                         lb__json_kind(set), BT_MAX_SETS / 2);
    J->fixed_text = calloc((size_t)cJSON_GetArraySize(set) + 1, sizeof *J->fixed_text);
    for (const cJSON *c = set->child; c; c = c->next) {
        if (!path_ok(c->string))
            return batch_bad(
                J, "$.set", "\"%s\" is not a JSON path; allowed: paths such as root.args[0].radius",
                c->string);
        char *val = cJSON_PrintUnformatted(c);
        const size_t l = strlen(c->string) + strlen(val) + 2;
        char *t = malloc(l);
        snprintf(t, l, "%s=%s", c->string, val);
        free(val);
        J->fixed_text[J->nfixed] = t;
        J->fixed[J->nfixed].path = t;
        J->fixed[J->nfixed].plen = strlen(c->string);
        J->fixed[J->nfixed].value = t + strlen(c->string) + 1;
        ++J->nfixed;
    }
    return 0;
}

/* "sweep": the axes */
static int parse_sweep(job *J, const cJSON *sw) {
    if (!cJSON_IsArray(sw) || cJSON_GetArraySize(sw) < 1 || cJSON_GetArraySize(sw) > MAX_AXES)
        return batch_bad(J, "$.sweep", "is %s; allowed: a list of 1 to %d axes", lb__json_kind(sw),
                         MAX_AXES);
    size_t i = 0;
    for (const cJSON *a = sw->child; a; a = a->next, ++i) {
        lb__jpath jp;
        lb__jpath_set(&jp, "$.sweep");
        lb__jpath_index(&jp, i);
        const int rc = parse_axis(J, a, jp.s, &J->axes[J->naxes++]);
        if (rc) return rc;
    }
    return 0;
}

/* "output_dir" and "pattern" (the output names), the scene stems they name */
static int parse_names(job *J, const cJSON *doc) {
    const cJSON *od = cJSON_GetObjectItemCaseSensitive(doc, "output_dir");
    if (od && (!cJSON_IsString(od) || !*od->valuestring))
        return batch_bad(J, "$.output_dir", "is %s; allowed: a folder, relative to the job file",
                         lb__json_kind(od));
    if (relative(J, od ? od->valuestring : "out", J->outdir, sizeof J->outdir))
        return batch_bad(J, "$.output_dir",
                         "the folder's path is too long; allowed: at most %zu bytes",
                         sizeof J->outdir - 1);
    const cJSON *pt = cJSON_GetObjectItemCaseSensitive(doc, "pattern");
    if (pt) {
        char why[160] = "";
        if (!cJSON_IsString(pt) || !pattern_ok(pt->valuestring, why, sizeof why))
            return batch_bad(J, "$.pattern",
                             "is %s%s; allowed: #### for the frame (zero-padded to the number of "
                             "#), {name}, {scene}, {task}, and " SAFE_WORD_ALLOWED,
                             cJSON_IsString(pt) ? "a pattern with " : lb__json_kind(pt), why);
        snprintf(J->pattern, sizeof J->pattern, "%s", pt->valuestring);
    } else {
        snprintf(J->pattern, sizeof J->pattern, "%s%s####",
                 J->nscenes > 1 ? "{name}_{scene}_" : "{name}_",
                 J->has_frames && J->naxes ? "t{task}_" : "");
    }
    /* the scene stems become part of the names */
    const int one = cJSON_GetObjectItemCaseSensitive(doc, "scene") != NULL;
    for (size_t i = 0; strstr(J->pattern, "{scene}") && i < J->nscenes; ++i)
        if (!safe_word(J->scene_stems[i], 0)) {
            char path[64];
            snprintf(path, sizeof path, one ? "$.scene" : "$.scenes[%zu]", i);
            return batch_bad(J, path,
                             "the file name's stem \"%s\" goes into the output names ({scene}) "
                             "but is not a safe name; allowed: " SAFE_WORD_ALLOWED
                             " (rename the file)",
                             J->scene_stems[i]);
        }
    return 0;
}

int batch_parse_job(job *J, const char *file) {
    memset(J, 0, sizeof *J);
    J->file = file;
    J->threads = 1;
    J->fps = 24;
    snprintf(J->dir, sizeof J->dir, "%s", file);
    char *slash = strrchr(J->dir, '/');
    if (slash)
        *slash = '\0';
    else
        strcpy(J->dir, ".");
    cJSON *doc = read_doc(file);
    if (!doc) return BT_EXIT_BAD_INPUT;
    int rc = 0;
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(doc, "set"),
                *sw = cJSON_GetObjectItemCaseSensitive(doc, "sweep"),
                *fr = cJSON_GetObjectItemCaseSensitive(doc, "frames"),
                *o = cJSON_GetObjectItemCaseSensitive(doc, "outputs");
    if ((rc = parse_header(J, doc)) || (rc = parse_name(J, doc)) || (rc = parse_scenes(J, doc)) ||
        (set && (rc = parse_set(J, set))) || (sw && (rc = parse_sweep(J, sw))) ||
        (fr && (rc = parse_frames(J, fr))))
        goto out;
    if (!o) {
        rc = batch_bad(J, "$.outputs",
                       "missing; allowed: {\"mesh\": {...}, \"pov\": {...}, \"image\": {...}}");
        goto out;
    }
    if ((rc = parse_outputs(J, o)) || (rc = parse_names(J, doc))) goto out;
    long th = 1;
    if ((rc = get_int(J, doc, "threads", "$", 0, 1024, &th))) goto out;
    J->threads = (int)th;
out:
    cJSON_Delete(doc);
    return rc;
}

char *batch_anim_value(const axis *X, double frame) {
    return X->keys ? num_text(key_value(X->keys, X->interp, frame)) : NULL;
}

void batch_job_free(job *J) {
    for (size_t i = 0; i < J->nscenes; ++i) {
        if (J->scenes) free(J->scenes[i]);
        if (J->scene_stems) free(J->scene_stems[i]);
    }
    free(J->scenes);
    free(J->scene_stems);
    for (size_t i = 0; J->fixed_text && i < J->nfixed; ++i) free(J->fixed_text[i]);
    free(J->fixed_text);
    for (size_t a = 0; a < J->naxes + J->nanim; ++a) {
        axis *X = a < J->naxes ? &J->axes[a] : &J->anim[a - J->naxes];
        for (size_t i = 0; X->values && i < X->n; ++i) free(X->values[i]);
        free(X->values);
        free(X->path);
        cJSON_Delete(X->keys);
    }
}
