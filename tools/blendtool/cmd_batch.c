/* blendtool batch: a job file (docs/batch.md) expanded into a deterministic
 * task list (scenes x sweep axes x frames), run locally, by task, shard or
 * frame range, resumable through per-task manifests, logged as JSON lines;
 * --slurm writes (and --submit submits) an array job running the shards. */
#define _GNU_SOURCE /* fopencookie */
#include "blendtool.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <xxhash.h>

#define CMD "batch"
#define MAX_TASKS 100000
#define MAX_AXES 16

/* ---- the job ---- */

typedef struct axis {
    char *path; /* JSON path into the scene */
    size_t n;
    char **values; /* JSON text per step (sweeps) or per frame (animation) */
} axis;

typedef struct job {
    const char *file;
    char dir[4096]; /* the job file's folder: relative paths start there */
    char name[256]; /* output base name */
    char pattern[256];
    char outdir[4096];
    size_t nscenes;
    char **scenes; /* resolved paths */
    char **scene_stems;
    size_t nfixed;
    bt_set fixed[BT_MAX_SETS];
    char **fixed_text;
    size_t naxes;
    axis axes[MAX_AXES];
    int has_frames;
    long first, last;
    size_t nanim;
    axis anim[MAX_AXES];
    /* outputs */
    int mesh, mesh_res;
    lb_mesh_format mesh_fmt;
    int pov, pov_w, pov_h;
    int image, img_w, img_h, img_quality, img_alpha, img_fmt;
    int sheet, sheet_cols, sheet_w, sheet_h;
    bt_image_plan img_plan; /* how the images are made on this machine */
    int threads;
    uint64_t spec_hash[2]; /* of the outputs section: a change redoes every task */
} job;

typedef struct task {
    size_t id, scene, combo;
    long frame;
    char name[512];
    size_t nsets;
    bt_set sets[BT_MAX_SETS];
    char *set_text[BT_MAX_SETS];
    char label[1024];
} task;

/* a bad job file: exit 2 with the file, the JSON path and what is allowed */
static int bad(const job *J, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int bad(const job *J, const char *path, const char *fmt, ...) {
    char msg[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    bt_error(CMD, "%s: %s: %s", J->file, path, msg);
    return BT_EXIT_BAD_INPUT;
}

static const char *kind(const cJSON *v) {
    return !v                  ? "nothing"
           : cJSON_IsNumber(v) ? "a number"
           : cJSON_IsString(v) ? "a string"
           : cJSON_IsBool(v)   ? "a boolean"
           : cJSON_IsArray(v)  ? "an array"
           : cJSON_IsObject(v) ? "an object"
                               : "null";
}

static int check_keys(const job *J, const cJSON *o, const char *path, const char *const *keys) {
    for (const cJSON *c = o->child; c; c = c->next) {
        int ok = 0;
        for (int i = 0; keys[i] && !ok; ++i) ok = strcmp(c->string, keys[i]) == 0;
        if (!ok) {
            char allowed[512] = "";
            size_t o2 = 0;
            for (int i = 0; keys[i]; ++i)
                o2 += (size_t)snprintf(allowed + o2, sizeof allowed - o2, "%s%s", i ? ", " : "",
                                       keys[i]);
            return bad(J, path, "unknown key \"%s\"; allowed: %s", c->string, allowed);
        }
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
        return bad(J, path, "\"%s\" is %s%s; allowed: an integer from %ld to %ld", key, kind(v),
                   num, lo, hi);
    }
    *out = (long)v->valuedouble;
    return 0;
}

static char *dupstr(const char *s) {
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
    return dupstr(b);
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
    static const char *const keys[] = {"path", "values", "range", NULL};
    if (!cJSON_IsObject(a))
        return bad(J, path,
                   "expected an object {\"path\": ..., \"values\": [...]} or "
                   "{\"path\": ..., \"range\": {...}}, found %s",
                   kind(a));
    int rc = check_keys(J, a, path, keys);
    if (rc) return rc;
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(a, "path");
    if (!cJSON_IsString(p) || !path_ok(p->valuestring))
        return bad(J, path,
                   "\"path\" is %s; allowed: a JSON path into the scene such as "
                   "\"root.args[0].radius\"",
                   kind(p));
    X->path = dupstr(p->valuestring);
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(a, "values");
    const cJSON *rg = cJSON_GetObjectItemCaseSensitive(a, "range");
    if (!!vals == !!rg) return bad(J, path, "give one of \"values\" (a list) or \"range\"");
    if (vals) {
        if (!cJSON_IsArray(vals) || cJSON_GetArraySize(vals) < 1)
            return bad(J, path, "\"values\" is %s; allowed: a non-empty list of JSON values",
                       kind(vals));
        X->n = (size_t)cJSON_GetArraySize(vals);
        X->values = calloc(X->n, sizeof *X->values);
        size_t i = 0;
        for (const cJSON *v = vals->child; v && X->values; v = v->next)
            X->values[i++] = cJSON_PrintUnformatted(v);
        return X->values ? 0 : BT_EXIT_INTERNAL;
    }
    static const char *const rkeys[] = {"from", "to", "count", NULL};
    char rp[512];
    snprintf(rp, sizeof rp, "%s.range", path);
    if (!cJSON_IsObject(rg)) return bad(J, rp, "expected {\"from\": A, \"to\": B, \"count\": N}");
    if ((rc = check_keys(J, rg, rp, rkeys))) return rc;
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(rg, "from"),
                *t = cJSON_GetObjectItemCaseSensitive(rg, "to");
    long count = -1;
    if (!cJSON_IsNumber(f) || !cJSON_IsNumber(t))
        return bad(J, rp, "\"from\" is %s and \"to\" %s; allowed: numbers", kind(f), kind(t));
    if ((rc = get_int(J, rg, "count", rp, 1, MAX_TASKS, &count))) return rc;
    if (count < 1)
        return bad(J, rp, "\"count\" is missing; allowed: an integer from 1 to %d", MAX_TASKS);
    const double va = f->valuedouble, vb = t->valuedouble;
    if (!isfinite(va) || !isfinite(vb) || fabs(va) > 1e300 || fabs(vb) > 1e300)
        return bad(J, rp, "from %g to %g; allowed: finite numbers of magnitude at most 1e300", va,
                   vb);
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
    static const char *const keys[] = {"first", "last", "animate", NULL};
    if (!cJSON_IsObject(fr))
        return bad(J, "$.frames",
                   "expected {\"first\": A, \"last\": B, \"animate\": [...]}, found %s", kind(fr));
    int rc = check_keys(J, fr, "$.frames", keys);
    if (rc) return rc;
    J->first = J->last = -1;
    if ((rc = get_int(J, fr, "first", "$.frames", 0, 9999999, &J->first)) ||
        (rc = get_int(J, fr, "last", "$.frames", 0, 9999999, &J->last)))
        return rc;
    if (J->first < 0 || J->last < J->first || J->last - J->first >= MAX_TASKS)
        return bad(J, "$.frames",
                   "first %ld, last %ld; allowed: both given, first <= last, at most %d "
                   "frames",
                   J->first, J->last, MAX_TASKS);
    J->has_frames = 1;
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(fr, "animate");
    if (!an) return 0;
    if (!cJSON_IsArray(an) || cJSON_GetArraySize(an) > MAX_AXES)
        return bad(J, "$.frames.animate", "expected a list of at most %d animated paths", MAX_AXES);
    size_t i = 0;
    for (const cJSON *a = an->child; a; a = a->next, ++i) {
        char path[128];
        snprintf(path, sizeof path, "$.frames.animate[%zu]", i);
        static const char *const akeys[] = {"path", "keys", "interpolation", NULL};
        if (!cJSON_IsObject(a)) return bad(J, path, "expected an object, found %s", kind(a));
        if ((rc = check_keys(J, a, path, akeys))) return rc;
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(a, "path"),
                    *k = cJSON_GetObjectItemCaseSensitive(a, "keys"),
                    *in = cJSON_GetObjectItemCaseSensitive(a, "interpolation");
        if (!cJSON_IsString(p) || !path_ok(p->valuestring))
            return bad(J, path, "\"path\" is %s; allowed: a JSON path into the scene", kind(p));
        const char *interp = in ? (cJSON_IsString(in) ? in->valuestring : "") : "linear";
        if (strcmp(interp, "linear") && strcmp(interp, "step") && strcmp(interp, "smooth"))
            return bad(J, path,
                       "\"interpolation\" is %s; allowed: \"linear\", \"step\", \"smooth\"",
                       in && cJSON_IsString(in) ? in->valuestring : kind(in));
        if (!cJSON_IsArray(k) || cJSON_GetArraySize(k) < 1)
            return bad(J, path, "\"keys\" is %s; allowed: a list of [frame, number] pairs",
                       kind(k));
        double lastf = -INFINITY;
        size_t j = 0;
        for (const cJSON *q = k->child; q; q = q->next, ++j) {
            const cJSON *f = cJSON_GetArrayItem(q, 0), *v = cJSON_GetArrayItem(q, 1);
            if (!cJSON_IsArray(q) || cJSON_GetArraySize(q) != 2 || !cJSON_IsNumber(f) ||
                !cJSON_IsNumber(v))
                return bad(J, path, "keys[%zu] is %s; allowed: a [frame, number] pair", j, kind(q));
            if (!(f->valuedouble > lastf))
                return bad(J, path, "keys[%zu]: frame %g after %g; allowed: increasing frames", j,
                           f->valuedouble, lastf);
            lastf = f->valuedouble;
        }
        axis *X = &J->anim[J->nanim++];
        X->path = dupstr(p->valuestring);
        X->n = (size_t)(J->last - J->first + 1);
        X->values = calloc(X->n, sizeof *X->values);
        for (size_t f = 0; f < X->n && X->values; ++f)
            X->values[f] = num_text(key_value(k, interp, (double)(J->first + (long)f)));
    }
    return 0;
}

static int parse_outputs(job *J, const cJSON *o) {
    static const char *const keys[] = {"mesh", "pov", "image", "contact_sheet", NULL};
    if (!cJSON_IsObject(o) || !o->child)
        return bad(J, "$.outputs", "expected an object with at least one of mesh, pov, image");
    int rc = check_keys(J, o, "$.outputs", keys);
    if (rc) return rc;
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(o, "mesh");
    if (m) {
        static const char *const mk[] = {"format", "resolution", NULL};
        if (!cJSON_IsObject(m))
            return bad(J, "$.outputs.mesh", "expected an object, found %s", kind(m));
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
                return bad(J, "$.outputs.mesh.format",
                           "%s; allowed: \"ply\", \"obj\", \"stl\", \"glb\"",
                           cJSON_IsString(f) ? f->valuestring : kind(f));
        }
        long r = 128;
        if ((rc = get_int(J, m, "resolution", "$.outputs.mesh", 1, LB_MESH_MAX_CELLS_PER_AXIS, &r)))
            return rc;
        J->mesh_res = (int)r;
    }
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "pov");
    if (p) {
        static const char *const pk[] = {"width", "height", NULL};
        if (!cJSON_IsObject(p))
            return bad(J, "$.outputs.pov", "expected an object, found %s", kind(p));
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
        static const char *const ik[] = {"format", "bits",   "pixel",   "alpha",
                                         "width",  "height", "quality", NULL};
        if (!cJSON_IsObject(im))
            return bad(J, "$.outputs.image", "expected an object, found %s", kind(im));
        if ((rc = check_keys(J, im, "$.outputs.image", ik))) return rc;
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(im, "format"),
                    *px = cJSON_GetObjectItemCaseSensitive(im, "pixel"),
                    *al = cJSON_GetObjectItemCaseSensitive(im, "alpha");
        const char *fmt = f ? (cJSON_IsString(f) ? f->valuestring : "") : "png";
        if (strcmp(fmt, "png") && strcmp(fmt, "exr"))
            return bad(J, "$.outputs.image.format", "%s; allowed: \"png\" or \"exr\"",
                       f && cJSON_IsString(f) ? f->valuestring : kind(f));
        long bits = 8, w = 320, h = 240, q = 9;
        if ((rc = get_int(J, im, "bits", "$.outputs.image", 8, 16, &bits))) return rc;
        if (bits != 8 && bits != 16)
            return bad(J, "$.outputs.image.bits", "%ld; allowed: 8 or 16", bits);
        if (!strcmp(fmt, "exr") && cJSON_GetObjectItemCaseSensitive(im, "bits"))
            return bad(J, "$.outputs.image.bits", "is for PNG; allowed for EXR: \"pixel\"");
        if (!strcmp(fmt, "png") && px)
            return bad(J, "$.outputs.image.pixel", "is for EXR; allowed for PNG: \"bits\"");
        const char *pix = px ? (cJSON_IsString(px) ? px->valuestring : "") : "half";
        if (strcmp(pix, "half") && strcmp(pix, "float"))
            return bad(J, "$.outputs.image.pixel", "%s; allowed: \"half\" or \"float\"",
                       px && cJSON_IsString(px) ? px->valuestring : kind(px));
        if (al && !cJSON_IsBool(al))
            return bad(J, "$.outputs.image.alpha", "is %s; allowed: true or false", kind(al));
        if ((rc = get_int(J, im, "width", "$.outputs.image", 1, 16384, &w)) ||
            (rc = get_int(J, im, "height", "$.outputs.image", 1, 16384, &h)) ||
            (rc = get_int(J, im, "quality", "$.outputs.image", 0, 11, &q)))
            return rc;
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
            return bad(J, "$.outputs.contact_sheet", "expected an object, found %s", kind(cs));
        if ((rc = check_keys(J, cs, "$.outputs.contact_sheet", ck))) return rc;
        if (!J->image)
            return bad(J, "$.outputs.contact_sheet",
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

static void relative(const job *J, const char *p, char *out, size_t len) {
    if (p[0] == '/')
        snprintf(out, len, "%s", p);
    else
        snprintf(out, len, "%s/%s", J->dir, p);
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

static int parse_job(job *J, const char *file) {
    memset(J, 0, sizeof *J);
    J->file = file;
    J->threads = 1;
    snprintf(J->dir, sizeof J->dir, "%s", file);
    char *slash = strrchr(J->dir, '/');
    if (slash)
        *slash = '\0';
    else
        strcpy(J->dir, ".");
    size_t len = 0;
    char why[256];
    char *text = bt_read_file(file, 16u << 20, &len, why, sizeof why);
    if (!text) {
        bt_error(CMD,
                 "%s: cannot read the job file (%s); allowed: a readable file of at most 16 MiB",
                 file, why);
        return BT_EXIT_BAD_INPUT;
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
        return BT_EXIT_BAD_INPUT;
    }
    const char *end = NULL;
    cJSON *doc = strlen(text) == len ? cJSON_ParseWithOpts(text, &end, 1) : NULL;
    if (!doc) {
        long line, col;
        text_pos(text, end ? end : cJSON_GetErrorPtr(), &line, &col);
        free(text);
        bt_error(CMD,
                 "%s:%ld:%ld: not valid JSON; allowed: a libblend-job document (docs/batch.md)",
                 file, line, col);
        return BT_EXIT_BAD_INPUT;
    }
    free(text);
    int rc = 0;
    static const char *const keys[] = {"format",  "version", "name",   "scene",   "scenes",
                                       "set",     "sweep",   "frames", "outputs", "output_dir",
                                       "pattern", "threads", NULL};
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(doc, "format"),
                *v = cJSON_GetObjectItemCaseSensitive(doc, "version");
    if (!cJSON_IsObject(doc)) {
        rc = bad(J, "$",
                 "expected an object, found %s; allowed: a libblend-job object (docs/batch.md)",
                 kind(doc));
        goto out;
    }
    if (!cJSON_IsString(f) || strcmp(f->valuestring, "libblend-job")) {
        rc = bad(J, "$.format", "is %s; allowed: \"libblend-job\"",
                 cJSON_IsString(f) ? f->valuestring : kind(f));
        goto out;
    }
    if (!cJSON_IsNumber(v) || v->valuedouble != 1) {
        rc = bad(J, "$.version", "is %s; allowed: 1", kind(v));
        goto out;
    }
    if ((rc = check_keys(J, doc, "$", keys))) goto out;
    /* name: the job file's stem unless given */
    const cJSON *nm = cJSON_GetObjectItemCaseSensitive(doc, "name");
    if (nm) {
        if (!cJSON_IsString(nm) || !safe_word(nm->valuestring, 0)) {
            rc = bad(J, "$.name", "is %s; allowed: a name of " SAFE_WORD_ALLOWED,
                     !cJSON_IsString(nm) ? kind(nm) : "not a safe name");
            goto out;
        }
        snprintf(J->name, sizeof J->name, "%s", nm->valuestring);
    } else {
        const char *b = strrchr(file, '/');
        snprintf(J->name, sizeof J->name, "%s", b ? b + 1 : file);
        char *dot = strrchr(J->name, '.');
        if (dot && dot != J->name) *dot = '\0';
        if (!safe_word(J->name, 0)) {
            rc = bad(J, "$.name",
                     "missing, and the job file's name is not a safe output name; allowed: "
                     "give \"name\", " SAFE_WORD_ALLOWED);
            goto out;
        }
    }
    /* scenes */
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(doc, "scene"),
                *scs = cJSON_GetObjectItemCaseSensitive(doc, "scenes");
    if (!!sc == !!scs) {
        rc = bad(J, "$", "give one of \"scene\" (a file) or \"scenes\" (a list of files)");
        goto out;
    }
    if (sc && !cJSON_IsString(sc)) {
        rc = bad(J, "$.scene", "is %s; allowed: a scene file, relative to the job file", kind(sc));
        goto out;
    }
    if (scs &&
        (!cJSON_IsArray(scs) || cJSON_GetArraySize(scs) < 1 || cJSON_GetArraySize(scs) > 10000)) {
        rc = bad(J, "$.scenes", "is %s; allowed: a list of 1 to 10000 scene files", kind(scs));
        goto out;
    }
    J->nscenes = sc ? 1 : (size_t)cJSON_GetArraySize(scs);
    J->scenes = calloc(J->nscenes, sizeof *J->scenes);
    J->scene_stems = calloc(J->nscenes, sizeof *J->scene_stems);
    for (size_t i = 0; i < J->nscenes; ++i) {
        const cJSON *s = sc ? sc : cJSON_GetArrayItem(scs, (int)i);
        char path[64];
        snprintf(path, sizeof path, sc ? "$.scene" : "$.scenes[%zu]", i);
        if (!cJSON_IsString(s) || !*s->valuestring) {
            rc = bad(J, path, "is %s; allowed: a scene file, relative to the job file", kind(s));
            goto out;
        }
        char full[8192];
        relative(J, s->valuestring, full, sizeof full);
        struct stat st;
        if (stat(full, &st) != 0 || !S_ISREG(st.st_mode)) {
            rc = bad(J, path, "%s: %s; allowed: an existing scene file (relative to the job file)",
                     full, stat(full, &st) != 0 ? strerror(errno) : "not a regular file");
            goto out;
        }
        J->scenes[i] = dupstr(full);
        const char *b = strrchr(s->valuestring, '/');
        J->scene_stems[i] = dupstr(b ? b + 1 : s->valuestring);
        char *dot = strrchr(J->scene_stems[i], '.');
        if (dot && dot != J->scene_stems[i]) *dot = '\0';
    }
    /* fixed overrides */
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(doc, "set");
    if (set) {
        if (!cJSON_IsObject(set) || cJSON_GetArraySize(set) > BT_MAX_SETS / 2) {
            rc = bad(J, "$.set",
                     "is %s; allowed: an object of at most %d {\"path\": value} overrides",
                     kind(set), BT_MAX_SETS / 2);
            goto out;
        }
        J->fixed_text = calloc((size_t)cJSON_GetArraySize(set) + 1, sizeof *J->fixed_text);
        for (const cJSON *c = set->child; c; c = c->next) {
            if (!path_ok(c->string)) {
                rc = bad(J, "$.set",
                         "\"%s\" is not a JSON path; allowed: paths such as root.args[0].radius",
                         c->string);
                goto out;
            }
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
    }
    /* sweep axes */
    const cJSON *sw = cJSON_GetObjectItemCaseSensitive(doc, "sweep");
    if (sw) {
        if (!cJSON_IsArray(sw) || cJSON_GetArraySize(sw) < 1 || cJSON_GetArraySize(sw) > MAX_AXES) {
            rc = bad(J, "$.sweep", "is %s; allowed: a list of 1 to %d axes", kind(sw), MAX_AXES);
            goto out;
        }
        size_t i = 0;
        for (const cJSON *a = sw->child; a; a = a->next, ++i) {
            char path[64];
            snprintf(path, sizeof path, "$.sweep[%zu]", i);
            if ((rc = parse_axis(J, a, path, &J->axes[J->naxes++]))) goto out;
        }
    }
    const cJSON *fr = cJSON_GetObjectItemCaseSensitive(doc, "frames");
    if (fr && (rc = parse_frames(J, fr))) goto out;
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(doc, "outputs");
    if (!o) {
        rc = bad(J, "$.outputs",
                 "missing; allowed: {\"mesh\": {...}, \"pov\": {...}, \"image\": {...}}");
        goto out;
    }
    if ((rc = parse_outputs(J, o))) goto out;
    const cJSON *od = cJSON_GetObjectItemCaseSensitive(doc, "output_dir");
    if (od && (!cJSON_IsString(od) || !*od->valuestring)) {
        rc = bad(J, "$.output_dir", "is %s; allowed: a folder, relative to the job file", kind(od));
        goto out;
    }
    relative(J, od ? od->valuestring : "out", J->outdir, sizeof J->outdir);
    const cJSON *pt = cJSON_GetObjectItemCaseSensitive(doc, "pattern");
    if (pt) {
        char why[160] = "";
        if (!cJSON_IsString(pt) || !pattern_ok(pt->valuestring, why, sizeof why)) {
            rc = bad(J, "$.pattern",
                     "is %s%s; allowed: #### for the frame (zero-padded to the number of #), "
                     "{name}, {scene}, {task}, and " SAFE_WORD_ALLOWED,
                     cJSON_IsString(pt) ? "a pattern with " : kind(pt), why);
            goto out;
        }
        snprintf(J->pattern, sizeof J->pattern, "%s", pt->valuestring);
    } else {
        snprintf(J->pattern, sizeof J->pattern, "%s%s####",
                 J->nscenes > 1 ? "{name}_{scene}_" : "{name}_",
                 J->has_frames && J->naxes ? "t{task}_" : "");
    }
    /* the scene stems become part of the names */
    for (size_t i = 0; strstr(J->pattern, "{scene}") && i < J->nscenes; ++i)
        if (!safe_word(J->scene_stems[i], 0)) {
            char path[64];
            snprintf(path, sizeof path, sc ? "$.scene" : "$.scenes[%zu]", i);
            rc = bad(J, path,
                     "the file name's stem \"%s\" goes into the output names ({scene}) but is "
                     "not a safe name; allowed: " SAFE_WORD_ALLOWED " (rename the file)",
                     J->scene_stems[i]);
            goto out;
        }
    long th = 1;
    if ((rc = get_int(J, doc, "threads", "$", 0, 1024, &th))) goto out;
    J->threads = (int)th;
out:
    cJSON_Delete(doc);
    return rc;
}

/* ---- the task list ---- */

static size_t combos(const job *J) {
    size_t n = 1;
    for (size_t a = 0; a < J->naxes; ++a) n *= J->axes[a].n;
    return n;
}

static size_t ntasks_of(const job *J) {
    const size_t nf = J->has_frames ? (size_t)(J->last - J->first + 1) : 1;
    return J->nscenes * combos(J) * nf;
}

/* the output name of a task from the pattern */
static void name_task(const job *J, const task *T, char *out, size_t len) {
    size_t o = 0;
    for (const char *p = J->pattern; *p && o + 1 < len;) {
        if (*p == '#') {
            int w = 0;
            while (*p == '#') ++w, ++p;
            o += (size_t)snprintf(out + o, len - o, "%0*ld", w, T->frame);
        } else if (!strncmp(p, "{name}", 6)) {
            o += (size_t)snprintf(out + o, len - o, "%s", J->name);
            p += 6;
        } else if (!strncmp(p, "{scene}", 7)) {
            o += (size_t)snprintf(out + o, len - o, "%s", J->scene_stems[T->scene]);
            p += 7;
        } else if (!strncmp(p, "{task}", 6)) {
            o += (size_t)snprintf(out + o, len - o, "%zu", T->combo);
            p += 6;
        } else {
            out[o++] = *p++;
        }
    }
    out[o < len ? o : len - 1] = '\0';
}

static void task_free(task *T) {
    for (size_t i = 0; i < T->nsets; ++i) free(T->set_text[i]);
    T->nsets = 0;
}

/* task id: scene slowest, then the sweep axes (first slowest), frames fastest */
static int make_task(const job *J, size_t id, task *T) {
    memset(T, 0, sizeof *T);
    T->id = id;
    const size_t nf = J->has_frames ? (size_t)(J->last - J->first + 1) : 1, nc = combos(J);
    const size_t fi = id % nf, ci = id / nf % nc;
    T->scene = id / nf / nc;
    T->combo = ci;
    T->frame = J->has_frames ? J->first + (long)fi : (long)ci; /* a sweep: its index */
    for (size_t i = 0; i < J->nfixed; ++i) {
        T->set_text[T->nsets] = dupstr(J->fixed[i].path);
        T->sets[T->nsets] = J->fixed[i];
        T->sets[T->nsets].path = T->set_text[T->nsets];
        T->sets[T->nsets].value = T->set_text[T->nsets] + J->fixed[i].plen + 1;
        ++T->nsets;
    }
    size_t lo = 0, rest = ci;
    size_t stride = nc;
    for (size_t a = 0; a < J->naxes + J->nanim; ++a) {
        const axis *X = a < J->naxes ? &J->axes[a] : &J->anim[a - J->naxes];
        size_t k;
        if (a < J->naxes) {
            stride /= X->n;
            k = rest / stride;
            rest %= stride;
        } else {
            k = fi;
        }
        const size_t l = strlen(X->path) + strlen(X->values[k]) + 2;
        char *t = malloc(l);
        if (!t) return BT_EXIT_INTERNAL;
        snprintf(t, l, "%s=%s", X->path, X->values[k]);
        T->set_text[T->nsets] = t;
        T->sets[T->nsets].path = t;
        T->sets[T->nsets].plen = strlen(X->path);
        T->sets[T->nsets].value = t + strlen(X->path) + 1;
        ++T->nsets;
        /* the label: the path's last part and the value, numbers to 4 digits */
        const char *last = strrchr(X->path, '.');
        last = last ? last + 1 : X->path;
        char *endp = NULL;
        const double num = strtod(X->values[k], &endp);
        char val[64];
        if (endp && !*endp)
            snprintf(val, sizeof val, "%.4g", num);
        else
            snprintf(val, sizeof val, "%.40s", X->values[k]);
        const int w =
            snprintf(T->label + lo, sizeof T->label - lo, "%s%s=%s", lo ? " " : "", last, val);
        if (w > 0 && lo + (size_t)w < sizeof T->label) lo += (size_t)w;
    }
    if (!lo) snprintf(T->label, sizeof T->label, "%s", J->scene_stems[T->scene]);
    name_task(J, T, T->name, sizeof T->name);
    return 0;
}

/* ---- outputs, manifests ---- */

static const char *mesh_ext(lb_mesh_format f) {
    return f == LB_MESH_FORMAT_OBJ   ? "obj"
           : f == LB_MESH_FORMAT_STL ? "stl"
           : f == LB_MESH_FORMAT_GLB ? "glb"
                                     : "ply";
}

/* the task's outputs, as file names inside the output folder */
static size_t outputs_of(const job *J, const task *T, char out[3][600]) {
    size_t n = 0;
    if (J->mesh) snprintf(out[n++], 600, "%s.%s", T->name, mesh_ext(J->mesh_fmt));
    if (J->pov) snprintf(out[n++], 600, "%s.pov", T->name);
    if (J->image)
        snprintf(out[n++], 600, "%s.%s", T->name,
                 J->img_fmt == LBI_PNG8 || J->img_fmt == LBI_PNG16 ? "png" : "exr");
    return n;
}

static int hash_file(const char *path, uint64_t h[2]) {
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    XXH3_state_t *s = XXH3_createState();
    XXH3_128bits_reset(s);
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) XXH3_128bits_update(s, buf, n);
    const int err = ferror(f);
    fclose(f);
    const XXH128_hash_t r = XXH3_128bits_digest(s);
    XXH3_freeState(s);
    h[0] = r.high64;
    h[1] = r.low64;
    return err ? -1 : 0;
}

static void manifest_path(const job *J, const task *T, char *out, size_t len) {
    snprintf(out, len, "%s/.libblend-manifest/%s.json", J->outdir, T->name);
}

/* the manifest's identity of a task: scene hash, overrides, version, outputs spec */
static char *identity(const job *J, const task *T, const uint64_t scene[2]) {
    cJSON *o = cJSON_CreateObject();
    char hex[33];
    bt_hash_hex(scene, hex);
    cJSON_AddStringToObject(o, "scene_hash", hex);
    cJSON_AddStringToObject(o, "scene", J->scene_stems[T->scene]);
    cJSON *p = cJSON_AddArrayToObject(o, "parameters");
    for (size_t i = 0; i < T->nsets; ++i)
        cJSON_AddItemToArray(p, cJSON_CreateString(T->sets[i].path));
    cJSON_AddStringToObject(o, "libblend", BT_VERSION);
    bt_hash_hex(J->spec_hash, hex);
    cJSON_AddStringToObject(o, "outputs_spec", hex);
    char *t = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return t;
}

/* is the task complete: manifest matching and every output with its hash? */
static int task_done(const job *J, const task *T, const char *ident) {
    char mp[8192];
    manifest_path(J, T, mp, sizeof mp);
    size_t len = 0;
    char why[256];
    char *text = bt_read_file(mp, 1u << 20, &len, why, sizeof why);
    if (!text) return 0;
    cJSON *m = cJSON_Parse(text);
    free(text);
    int ok = 0;
    const cJSON *id = cJSON_GetObjectItemCaseSensitive(m, "identity"),
                *outs = cJSON_GetObjectItemCaseSensitive(m, "outputs");
    if (cJSON_IsString(id) && !strcmp(id->valuestring, ident) && cJSON_IsArray(outs)) {
        char names[3][600];
        const size_t n = outputs_of(J, T, names);
        ok = (size_t)cJSON_GetArraySize(outs) == n;
        for (size_t i = 0; i < n && ok; ++i) {
            const cJSON *e = cJSON_GetArrayItem(outs, (int)i);
            const cJSON *fn = cJSON_GetObjectItemCaseSensitive(e, "file"),
                        *hh = cJSON_GetObjectItemCaseSensitive(e, "hash");
            char full[8192], hex[33];
            uint64_t h[2];
            snprintf(full, sizeof full, "%s/%s", J->outdir, names[i]);
            ok = cJSON_IsString(fn) && !strcmp(fn->valuestring, names[i]) && cJSON_IsString(hh) &&
                 hash_file(full, h) == 0;
            if (ok) {
                bt_hash_hex(h, hex);
                ok = !strcmp(hh->valuestring, hex);
            }
        }
    }
    cJSON_Delete(m);
    return ok;
}

/* ---- logging ---- */

typedef struct logger {
    FILE *f;    /* JSON lines, or NULL */
    int bar;    /* progress on a terminal */
    int failed; /* a line could not be written (errno in err) */
    int err;
} logger;

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void log_event(logger *L, cJSON *e) {
    if (L->f) {
        char *t = cJSON_PrintUnformatted(e);
        if (t && !L->failed && (fprintf(L->f, "%s\n", t) < 0 || fflush(L->f) != 0)) {
            L->failed = 1;
            L->err = errno;
        }
        free(t);
    }
    cJSON_Delete(e);
}

static cJSON *event(const char *kind_, const task *T) {
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "event", kind_);
    if (T) {
        cJSON_AddNumberToObject(e, "task", (double)T->id);
        cJSON_AddStringToObject(e, "name", T->name);
    }
    return e;
}

/* ---- running a task ---- */

static int write_bytes(const char *path, const void *data, size_t len) {
    return bt_write_file(CMD, path, data, len);
}

/* A manifest vouches for the bytes this process wrote, never for what a
 * path holds afterwards (another process may have replaced it): every
 * output goes through a stream that hashes what passes on its way to the
 * temporary file, and the hash is taken before the file is linked into
 * place. */
typedef struct hash_tee {
    FILE *to;
    XXH3_state_t *h;
} hash_tee;

static ssize_t tee_write(void *c, const char *buf, size_t n) {
    hash_tee *t = c;
    if (fwrite(buf, 1, n, t->to) != n) return -1;
    XXH3_128bits_update(t->h, buf, n);
    return (ssize_t)n;
}

typedef struct hashed_out {
    bt_out out;
    hash_tee t;
    FILE *f; /* write here */
} hashed_out;

static int hashed_open(const char *path, hashed_out *H) {
    memset(H, 0, sizeof *H);
    int rc = bt_output_open(CMD, path, &H->out);
    if (rc) return rc;
    H->t.to = H->out.f;
    H->t.h = XXH3_createState();
    cookie_io_functions_t io = {NULL, tee_write, NULL, NULL};
    if (H->t.h) XXH3_128bits_reset(H->t.h);
    H->f = H->t.h ? fopencookie(&H->t, "w", io) : NULL;
    if (!H->f) {
        XXH3_freeState(H->t.h);
        bt_output_discard(&H->out);
        bt_error(CMD, "%s: out of memory", path);
        return BT_EXIT_INTERNAL;
    }
    return 0;
}

static void hashed_discard(hashed_out *H) {
    if (H->f) fclose(H->f);
    H->f = NULL;
    XXH3_freeState(H->t.h);
    H->t.h = NULL;
    bt_output_discard(&H->out);
}

/* flush, hash, link into place; failed: nothing at the path */
static int hashed_commit(const char *path, hashed_out *H, char hex[33]) {
    const int bad_write = fclose(H->f) != 0;
    H->f = NULL;
    const XXH128_hash_t r = XXH3_128bits_digest(H->t.h);
    XXH3_freeState(H->t.h);
    H->t.h = NULL;
    const uint64_t h[2] = {r.high64, r.low64};
    bt_hash_hex(h, hex);
    if (bad_write || ferror(H->out.f)) {
        bt_error(CMD, "%s: writing the output failed (%s); nothing was written", path,
                 strerror(errno));
        bt_output_discard(&H->out);
        return BT_EXIT_INTERNAL;
    }
    return bt_output_commit(CMD, &H->out);
}

static int hashed_bytes(const char *path, const void *data, size_t len, char hex[33]) {
    hashed_out H;
    int rc = hashed_open(path, &H);
    if (rc) return rc;
    if (len && fwrite(data, 1, len, H.f) != len) {
        hashed_discard(&H);
        bt_error(CMD, "%s: writing the output failed (%s); nothing was written", path,
                 strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    return hashed_commit(path, &H, hex);
}

static int run_task(const job *J, const task *T, const char *ident, const uint64_t scene_hash[2],
                    lb_scene *sc, logger *L, int threads) {
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_status s = LB_OK;
    const int crc = bt_compile(CMD, J->scenes[T->scene], sc, &ev);
    if (crc) return crc;
    char names[3][600], hexes[3][33];
    const size_t n = outputs_of(J, T, names);
    cJSON *manifest = cJSON_CreateObject();
    cJSON_AddStringToObject(manifest, "identity", ident);
    cJSON *outs = cJSON_AddArrayToObject(manifest, "outputs");
    int rc = 0;
    size_t k = 0;
    char full[8192];
    if (J->mesh) {
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[k]);
        lb_mesh_options o;
        lb_mesh_options_init(&o);
        o.resolution = (unsigned)J->mesh_res;
        o.threads = threads;
        lb_mesh *m = NULL;
        hashed_out H;
        if (!lb_scene_bounds(sc, o.bmin, o.bmax)) {
            bt_error(CMD, "%s: the scene has no bounds; allowed: a scene with \"bounds\"",
                     J->scenes[T->scene]);
            rc = BT_EXIT_BAD_INPUT;
        } else if ((s = lb_mesh_create(ev, &o, &m, &e))) {
            rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
        } else if (!(rc = hashed_open(full, &H))) {
            if ((s = lb_mesh_write_stream(m, H.f, J->mesh_fmt, &e))) {
                hashed_discard(&H);
                rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
            } else {
                rc = hashed_commit(full, &H, hexes[k]);
            }
        }
        lb_mesh_free(m);
        ++k;
    }
    if (!rc && J->pov) {
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[k]);
        lb_pov_options o = {0, 0, (double)J->pov_w / (double)J->pov_h, 0.0, threads};
        hashed_out H;
        if (!(rc = hashed_open(full, &H))) {
            if ((s = lb_scene_write_pov_stream(sc, ev, &o, H.f, NULL, &e))) {
                hashed_discard(&H);
                rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
            } else {
                rc = hashed_commit(full, &H, hexes[k]);
            }
        }
        ++k;
    }
    if (!rc && J->image) {
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[k]);
        bt_render_dir R;
        if ((rc = bt_render_dir_open(&R)) == 0) {
            lb_pov_options o = {0, 0, (double)J->img_w / (double)J->img_h, 0.0, threads};
            if ((s = lb_scene_write_pov(sc, ev, &o, R.pov, NULL, &e)))
                rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
            if (!rc)
                rc = bt_povray(J->scenes[T->scene], &R, J->img_w, J->img_h, threads ? threads : 1,
                               J->img_quality, J->img_plan.bits16, J->img_plan.alpha, 1);
            if (!rc) {
                char hex[33], settings[128], err[1024] = "";
                bt_hash_hex(scene_hash, hex);
                snprintf(settings, sizeof settings, "%dx%d quality %d", J->img_w, J->img_h,
                         J->img_quality);
                const lbi_meta meta[5] = {{"libblend:scene_hash", hex},
                                          {"libblend:version", BT_VERSION},
                                          {"libblend:render", settings},
                                          {"libblend:parameters", T->label},
                                          {"libblend:task", T->name}};
                unsigned char *img = NULL;
                size_t len = 0;
                if (bt_image_finish(&J->img_plan, R.png, J->img_fmt, meta, 5, &img, &len, err,
                                    sizeof err)) {
                    bt_error(CMD, "%s: writing the image failed: %s", full, err);
                    rc = BT_EXIT_INTERNAL;
                } else {
                    rc = hashed_bytes(full, img, len, hexes[k]);
                }
                free(img);
            }
            bt_render_dir_close(&R);
        }
        ++k;
    }
    for (size_t i = 0; i < n && !rc; ++i) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "file", names[i]);
        cJSON_AddStringToObject(o, "hash", hexes[i]);
        cJSON_AddItemToArray(outs, o);
        cJSON *ev2 = event("output", T);
        cJSON_AddStringToObject(ev2, "file", names[i]);
        cJSON_AddStringToObject(ev2, "hash", hexes[i]);
        log_event(L, ev2);
    }
    if (!rc) { /* the manifest last: only a complete task has one */
        char mp[8192], *text = cJSON_Print(manifest), mhex[33];
        manifest_path(J, T, mp, sizeof mp);
        rc = text ? hashed_bytes(mp, text, strlen(text), mhex) : BT_EXIT_INTERNAL;
        free(text);
    }
    cJSON_Delete(manifest);
    lb_evaluator_free(ev);
    return rc;
}

/* A task's lock, held while the task is checked and run: an open file
 * description lock (F_OFD_SETLK) on one byte of OUT/.libblend-manifest/
 * tasks.lock, at an offset hashed from the task's name, so every process
 * and every job writing into OUT locks the same byte for the same output
 * names. The kernel releases it when the descriptor closes or the process
 * dies however it dies; the file itself stays (empty), as the manifest
 * folder does. Returns the descriptor, -1 when another process holds the
 * task and wait is 0, -2 on an error (errno). */
static int task_lock(const job *J, const task *T, int wait) {
    char lp[8192];
    snprintf(lp, sizeof lp, "%s/.libblend-manifest/tasks.lock", J->outdir);
    const int fd = open(lp, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return -2;
    struct flock fl;
    memset(&fl, 0, sizeof fl);
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;
    fl.l_start = (off_t)(XXH3_64bits(T->name, strlen(T->name)) >> 2); /* 62 bits */
    fl.l_len = 1;
    while (fcntl(fd, wait ? F_OFD_SETLKW : F_OFD_SETLK, &fl) != 0) {
        if (errno == EINTR) continue;
        const int e = errno;
        close(fd);
        errno = e;
        return e == EAGAIN || e == EACCES ? -1 : -2;
    }
    return fd;
}

static int mkdirs(const char *path) {
    char p[8192];
    snprintf(p, sizeof p, "%s", path);
    for (char *c = p + 1; *c; ++c)
        if (*c == '/') {
            *c = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) return -1;
            *c = '/';
        }
    return mkdir(p, 0777) != 0 && errno != EEXIST ? -1 : 0;
}

/* ---- contact sheet ---- */

static int contact_sheet(const job *J, size_t ntasks, logger *L) {
    char **imgs = calloc(ntasks, sizeof *imgs), **labels = calloc(ntasks, sizeof *labels);
    int rc = imgs && labels ? 0 : BT_EXIT_INTERNAL;
    for (size_t i = 0; i < ntasks && !rc; ++i) {
        task T;
        if ((rc = make_task(J, i, &T))) break;
        char names[3][600], full[8192];
        const size_t n = outputs_of(J, &T, names);
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[n - 1]);
        imgs[i] = dupstr(full);
        labels[i] = dupstr(T.label);
        task_free(&T);
        struct stat st;
        if (stat(full, &st) != 0) {
            bt_error(CMD,
                     "%s: the contact sheet needs every task's image; missing %s; allowed: run "
                     "the job (or the missing tasks) first",
                     J->file, full);
            rc = BT_EXIT_BAD_INPUT;
        }
    }
    if (!rc) {
        char full[8192], err[1024] = "the image writer is not available (above)";
        const bt_imageio *io = NULL;
        snprintf(full, sizeof full, "%s/%s_sheet.png", J->outdir, J->name);
        unsigned char *data = NULL;
        size_t len = 0;
        const lbi_meta meta[2] = {{"libblend:version", BT_VERSION}, {"libblend:job", J->name}};
        if (!(io = bt_imageio_get(CMD)) ||
            io->contact_sheet((const char *const *)imgs, (const char *const *)labels, ntasks,
                              J->sheet_cols, J->sheet_w, J->sheet_h, LBI_PNG8, meta, 2, &data, &len,
                              err, sizeof err)) {
            bt_error(CMD, "%s: the contact sheet: %s", full, err);
            rc = BT_EXIT_INTERNAL;
        } else {
            rc = write_bytes(full, data, len);
            cJSON *e = event("contact_sheet", NULL);
            cJSON_AddStringToObject(e, "file", full + strlen(J->outdir) + 1);
            if (!rc)
                log_event(L, e);
            else
                cJSON_Delete(e);
        }
        free(data);
    }
    for (size_t i = 0; i < ntasks; ++i) {
        if (imgs) free(imgs[i]);
        if (labels) free(labels[i]);
    }
    free(imgs);
    free(labels);
    return rc;
}

/* ---- Slurm ---- */

/* Slurm partition lists: names of [A-Za-z0-9_.-] separated by commas */
static int partition_ok(const char *p) {
    if (!*p || strlen(p) > 1000 || *p == ',' || p[strlen(p) - 1] == ',') return 0;
    for (const char *c = p; *c; ++c)
        if (!(isalnum((unsigned char)*c) || *c == '_' || *c == '-' || *c == '.' ||
              (*c == ',' && c[1] != ',')))
            return 0;
    return 1;
}

/* text as one shell word: single quotes, each ' as '\'' (no byte can end
 * it: inside single quotes the shell gives no character a meaning) */
static void sh_quote(char *out, size_t len, size_t *o, const char *text) {
    const char *parts[2] = {"'", "'\\''"};
    size_t n = *o;
    if (n + 1 < len) out[n++] = '\'';
    for (const char *c = text; *c && n + 5 < len; ++c) {
        if (*c == '\'')
            for (const char *q = parts[1]; *q; ++q) out[n++] = *q;
        else
            out[n++] = *c;
    }
    if (n + 1 < len) out[n++] = '\'';
    out[n < len ? n : len - 1] = '\0';
    *o = n;
}

/* A value sbatch's #SBATCH parser passes through unchanged inside double
 * quotes, and its file-name patterns leave alone: no '"', '\', '%' (file
 * name patterns), no control character. */
static int directive_ok(const char *v) {
    for (const unsigned char *c = (const unsigned char *)v; *c; ++c)
        if (*c < 32 || *c == 127 || *c == '"' || *c == '\\' || *c == '%') return 0;
    return 1;
}

/* The largest time and peak memory of the job's tasks that the shard logs
 * of earlier runs (OUT/logs/NAME_shard_*.jsonl) record as done (0 when
 * none do). */
static void measured_costs(const job *J, double *sec, double *rss_kb) {
    *sec = *rss_kb = 0.0;
    char logs[8192];
    snprintf(logs, sizeof logs, "%s/logs", J->outdir);
    DIR *d = opendir(logs);
    if (!d) return;
    char prefix[300];
    snprintf(prefix, sizeof prefix, "%s_shard_", J->name);
    for (struct dirent *e; (e = readdir(d));) {
        const size_t nl = strlen(e->d_name), pl = strlen(prefix);
        if (nl <= pl + 6 || strncmp(e->d_name, prefix, pl) || strcmp(e->d_name + nl - 6, ".jsonl"))
            continue;
        char path[8600];
        snprintf(path, sizeof path, "%s/%s", logs, e->d_name);
        FILE *f = fopen(path, "r");
        char line[4096];
        while (f && fgets(line, sizeof line, f)) {
            cJSON *ev = cJSON_Parse(line);
            const cJSON *k = cJSON_GetObjectItemCaseSensitive(ev, "event"),
                        *st = cJSON_GetObjectItemCaseSensitive(ev, "status"),
                        *s2 = cJSON_GetObjectItemCaseSensitive(ev, "seconds"),
                        *r = cJSON_GetObjectItemCaseSensitive(ev, "peak_rss_kb");
            if (cJSON_IsString(k) && !strcmp(k->valuestring, "task_end") && cJSON_IsString(st) &&
                !strcmp(st->valuestring, "done")) {
                if (cJSON_IsNumber(s2) && s2->valuedouble > *sec) *sec = s2->valuedouble;
                if (cJSON_IsNumber(r) && r->valuedouble > *rss_kb) *rss_kb = r->valuedouble;
            }
            cJSON_Delete(ev);
        }
        if (f) fclose(f);
    }
    closedir(d);
}

static int slurm_script(const job *J, size_t ntasks, int array, const char *partition,
                        long time_min, long mem_mb, const char *self, char *out, size_t outlen) {
    if (mkdirs(J->outdir)) {
        bt_error(CMD, "%s: cannot create the output folder (%s)", J->outdir, strerror(errno));
        return BT_EXIT_BAD_INPUT;
    }
    if ((size_t)array > ntasks) array = (int)ntasks;
    char jobabs[8192], dirabs[8192];
    if (!realpath(J->file, jobabs) || !realpath(J->outdir, dirabs)) {
        bt_error(CMD, "%s: %s", J->file, strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    if (snprintf(out, outlen, "%s/%s.sbatch", dirabs, J->name) >= (int)outlen) {
        bt_error(CMD, "%s: the output folder's path is too long", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    /* --time and --mem: given, else measured on the job's tasks in the
     * shard logs of an earlier submission (twice the slowest task per task of the largest shard,
     * plus 5 minutes; twice the largest peak plus 256 MB), else 30 minutes per task of the largest
     * shard and 4096 MB (docs/batch.md) */
    const size_t per_shard = (ntasks + (size_t)array - 1) / (size_t)array;
    double sec = 0.0, rss = 0.0;
    if (!time_min || !mem_mb) measured_costs(J, &sec, &rss);
    if (!time_min) {
        const double t =
            sec > 0.0 ? ceil(2.0 * sec * (double)per_shard / 60.0) + 5.0 : 30.0 * (double)per_shard;
        time_min = t < 10.0 ? 10 : t > 525600.0 ? 525600 : (long)t;
    }
    if (!mem_mb) mem_mb = rss > 0.0 ? (long)ceil(2.0 * rss / 1024.0) + 256 : 4096;
    /* every path is a shell word in single quotes; the log folder goes into
     * a #SBATCH line only where sbatch keeps it as it is */
    char logs[8300], qself[20000], qjob[20000], qlog[20000];
    size_t o1 = 0, o2 = 0, o3 = 0;
    if (snprintf(logs, sizeof logs, "%s/logs", dirabs) >= (int)sizeof logs) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    char logfile[8800];
    if (snprintf(logfile, sizeof logfile, "%s/%s_shard_", logs, J->name) >= (int)sizeof logfile) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    sh_quote(qself, sizeof qself, &o1, self);
    sh_quote(qjob, sizeof qjob, &o2, jobabs);
    sh_quote(qlog, sizeof qlog, &o3, logfile);
    const int direct = directive_ok(logs);
    char text[80000];
    const int tl = snprintf(
        text, sizeof text,
        "#!/bin/sh\n"
        "# written by blendtool batch --slurm (libblend %s): %zu tasks in %d array tasks.\n"
        "# Submitting it again redoes only what is missing or incomplete.\n"
        "#SBATCH --job-name=%s\n"
        "#SBATCH --array=0-%d\n"
        "%s%s%s"
        "#SBATCH --ntasks=1\n"
        "#SBATCH --cpus-per-task=1\n"
        "#SBATCH --time=%ld\n"
        "#SBATCH --mem=%ldM\n"
        "%s%s%s"
        "%s%s%s"
        "exec %s batch %s --shard \"$SLURM_ARRAY_TASK_ID/%d\" --threads 1 "
        "--log %s\"$SLURM_ARRAY_TASK_ID\"'.jsonl'\n",
        BT_VERSION, ntasks, array, J->name, array - 1, direct ? "#SBATCH --output=\"" : "",
        direct ? logs : "", direct ? "/%x_%A_%a.log\"\n" : "", time_min, mem_mb,
        partition ? "#SBATCH --partition=" : "", partition ? partition : "", partition ? "\n" : "",
        direct ? ""
               : "# the output folder's path has characters a #SBATCH line cannot carry:\n"
                 "# the shard's messages go to its log from here (Slurm's own to\n"
                 "# slurm-JOB_TASK.out in the folder it was submitted from)\n"
                 "exec >>",
        direct ? "" : qlog, direct ? "" : "\"$SLURM_ARRAY_TASK_ID\"'.log' 2>&1\n", qself, qjob,
        array, qlog);
    if (tl >= (int)sizeof text || o1 + 1 >= sizeof qself || o2 + 1 >= sizeof qjob ||
        o3 + 1 >= sizeof qlog) {
        bt_error(CMD, "%s: paths too long for the script", dirabs);
        return BT_EXIT_BAD_INPUT;
    }
    if (mkdirs(logs)) {
        bt_error(CMD, "%s: cannot create the log folder (%s)", logs, strerror(errno));
        return BT_EXIT_INTERNAL;
    }
    int rc = write_bytes(out, text, strlen(text));
    if (!rc) chmod(out, 0755);
    return rc;
}

/* ---- the command ---- */

static int parse_range(const char *v, long *a, long *b) {
    char *end = NULL;
    *a = strtol(v, &end, 10);
    if (!end || end == v) return -1;
    if (*end == '\0') {
        *b = *a;
        return 0;
    }
    if (*end != '-') return -1;
    const char *s2 = end + 1;
    *b = strtol(s2, &end, 10);
    return !end || end == s2 || *end || *b < *a ? -1 : 0;
}

static void job_free(job *J) {
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
    }
}

static int run(int argc, char **argv) {
    const char *file = NULL, *v = NULL, *logpath = NULL, *partition = NULL;
    int list = 0, log_json = 0, fail_fast = 0, slurm = 0, submit = 0, array = 4, threads = -1;
    long time_min = 0, mem_mb = 0; /* --time, --mem of --slurm: 0 = measured or default */
    int sheet_only = 0;
    long task_id = -1, shard_i = -1, shard_n = 0, fa = -1, fb = -1;
    for (int i = 1; i < argc; ++i) {
        int r;
        if (!strcmp(argv[i], "--list")) {
            list = 1;
        } else if (!strcmp(argv[i], "--log-json")) {
            log_json = 1;
        } else if (!strcmp(argv[i], "--fail-fast")) {
            fail_fast = 1;
        } else if (!strcmp(argv[i], "--slurm")) {
            slurm = 1;
        } else if (!strcmp(argv[i], "--submit")) {
            submit = slurm = 1;
        } else if (!strcmp(argv[i], "--sheet")) {
            sheet_only = 1;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--task", &v))) {
            long b;
            if (r < 0 || parse_range(v, &task_id, &b) || b != task_id || task_id < 0) {
                if (r >= 0)
                    bt_error(CMD, "--task %s: expected a task id (a number from --list)", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--shard", &v))) {
            char *end = NULL;
            if (r < 0) return BT_EXIT_BAD_INPUT;
            shard_i = strtol(v, &end, 10);
            if (!end || *end != '/' || (shard_n = strtol(end + 1, &end, 10)) < 1 || *end ||
                shard_i < 0 || shard_i >= shard_n) {
                bt_error(CMD, "--shard %s: expected I/N with 0 <= I < N", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--frames", &v))) {
            if (r < 0 || parse_range(v, &fa, &fb) || fa < 0) {
                if (r >= 0)
                    bt_error(CMD, "--frames %s: expected A-B (or one frame A) with 0 <= A <= B", v);
                return BT_EXIT_BAD_INPUT;
            }
        } else if ((r = bt_option(CMD, argc, argv, &i, "--log", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            logpath = v;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--threads", &v))) {
            if (r < 0 || bt_parse_threads(CMD, v, &threads)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--array-size", &v))) {
            long a = 0;
            if (r < 0 || bt_parse_long(CMD, "--array-size", v, 1, 10000, "an integer", &a))
                return BT_EXIT_BAD_INPUT;
            array = (int)a;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--partition", &v))) {
            if (r < 0) return BT_EXIT_BAD_INPUT;
            if (!partition_ok(v)) {
                bt_error(CMD,
                         "--partition: %zu bytes that Slurm cannot take as a partition list; "
                         "allowed: names of letters, digits, '_', '-', '.', separated by commas",
                         strlen(v));
                return BT_EXIT_BAD_INPUT;
            }
            partition = v;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--time", &v))) {
            if (r < 0 ||
                bt_parse_long(CMD, "--time", v, 1, 525600, "minutes per array task", &time_min))
                return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option(CMD, argc, argv, &i, "--mem", &v))) {
            if (r < 0 ||
                bt_parse_long(CMD, "--mem", v, 16, 16777216, "megabytes per array task", &mem_mb))
                return BT_EXIT_BAD_INPUT;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            bt_error(CMD, "unknown option %s; see blendtool batch --help", argv[i]);
            return BT_EXIT_BAD_INPUT;
        } else if (!file) {
            file = argv[i];
        } else {
            bt_error(CMD, "more than one job file (%s, %s); allowed: one", file, argv[i]);
            return BT_EXIT_BAD_INPUT;
        }
    }
    if (!file) {
        bt_error(CMD, "no job file given; usage: blendtool batch JOB.json [--list]");
        return BT_EXIT_BAD_INPUT;
    }
    if ((task_id >= 0) + (shard_n > 0) > 1) {
        bt_error(CMD, "--task and --shard both given; allowed: one of them");
        return BT_EXIT_BAD_INPUT;
    }
    job J;
    int rc = parse_job(&J, file);
    if (rc) {
        job_free(&J);
        return rc;
    }
    if (threads >= 0) J.threads = threads;
    const size_t nt = ntasks_of(&J);
    if (nt > MAX_TASKS) {
        rc = bad(&J, "$", "%zu tasks (scenes x sweep values x frames); allowed: at most %d", nt,
                 MAX_TASKS);
        job_free(&J);
        return rc;
    }
    if (task_id >= 0 && (size_t)task_id >= nt) {
        bt_error(CMD, "--task %ld: the job has tasks 0 to %zu", task_id, nt - 1);
        job_free(&J);
        return BT_EXIT_BAD_INPUT;
    }
    if (fa >= 0 && !J.has_frames) {
        bt_error(CMD, "--frames %ld-%ld: %s has no \"frames\"", fa, fb, file);
        job_free(&J);
        return BT_EXIT_BAD_INPUT;
    }
    /* the selection: [lo, hi) of task ids, then the frame filter */
    size_t lo = 0, hi = nt;
    if (task_id >= 0) lo = (size_t)task_id, hi = lo + 1;
    if (shard_n > 0) {
        lo = nt * (size_t)shard_i / (size_t)shard_n;
        hi = nt * (size_t)(shard_i + 1) / (size_t)shard_n;
    }
    if (slurm) {
        char script[8192];
        char self[4096];
        const ssize_t sl = readlink("/proc/self/exe", self, sizeof self - 1);
        self[sl > 0 ? sl : 0] = '\0';
        rc = slurm_script(&J, nt, array, partition, time_min, mem_mb, self, script, sizeof script);
        if (!rc) printf("%s\n", script);
        if (!rc && submit) {
            fflush(stdout);
            const pid_t pid = fork();
            if (pid == 0) {
                execlp("sbatch", "sbatch", "--wait", script, (char *)NULL);
                fprintf(stderr,
                        "blendtool batch: cannot run sbatch (%s); allowed: install Slurm "
                        "(Debian package slurm-wlm) or submit the script yourself\n",
                        strerror(errno));
                _exit(127);
            }
            int st = 0;
            bt_signals_child(pid);
            while (pid > 0 && waitpid(pid, &st, 0) < 0 && errno == EINTR) {
            }
            bt_signals_child(0);
            rc = pid > 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : BT_EXIT_INTERNAL;
            if (rc)
                bt_error(CMD, "sbatch --wait %s: some array tasks failed (logs in %s/logs)", script,
                         J.outdir);
            else if (J.sheet) {
                logger L0 = {NULL, 0, 0, 0};
                rc = contact_sheet(&J, nt, &L0);
            }
        }
        job_free(&J);
        return rc;
    }
    if (list) {
        for (size_t i = lo; i < hi && !rc; ++i) {
            task T;
            if ((rc = make_task(&J, i, &T))) break;
            if (fa >= 0 && (T.frame < fa || T.frame > fb)) {
                task_free(&T);
                continue;
            }
            lb_scene *sc = NULL;
            uint64_t h[2] = {0, 0};
            rc = bt_load_scene_set(CMD, J.scenes[T.scene], T.sets, T.nsets, &sc, h);
            lb_scene_free(sc);
            if (!rc) {
                char hex[33], names[3][600];
                bt_hash_hex(h, hex);
                const size_t n = outputs_of(&J, &T, names);
                printf("%zu\t%s\t%s\t", T.id, T.name, hex);
                for (size_t k = 0; k < n; ++k) printf("%s%s", k ? "," : "", names[k]);
                printf("\t%s\n", T.label);
            }
            task_free(&T);
        }
        if (fflush(stdout) != 0) rc = BT_EXIT_INTERNAL;
        job_free(&J);
        return rc;
    }
    if (sheet_only && J.image && !J.sheet) { /* the documented defaults */
        J.sheet_cols = 4;
        J.sheet_w = 160;
        J.sheet_h = 120;
    }
    if (sheet_only && !J.image) {
        bt_error(CMD,
                 "--sheet: %s has no image outputs to put on a sheet; allowed: a job with "
                 "\"outputs\": {\"image\": {...}}",
                 file);
        job_free(&J);
        return BT_EXIT_BAD_INPUT;
    }
    /* every selected task's scene is read before anything is created: a job
     * whose scene or overrides are invalid leaves no output folder */
    for (size_t i = lo; i < hi && !sheet_only; ++i) {
        task T;
        if ((rc = make_task(&J, i, &T))) break;
        if (fa < 0 || (T.frame >= fa && T.frame <= fb)) {
            lb_scene *sc = NULL;
            uint64_t h[2];
            rc = bt_load_scene_set(CMD, J.scenes[T.scene], T.sets, T.nsets, &sc, h);
            lb_scene_free(sc);
        }
        task_free(&T);
        if (rc) {
            job_free(&J);
            return rc;
        }
    }
    /* the images can be made here (else nothing is created) */
    if (J.image && !sheet_only &&
        (rc = bt_image_plan_for(CMD, J.file, J.img_fmt, J.img_alpha, &J.img_plan)) == 0 &&
        J.sheet && !J.img_plan.io) {
        bt_error(CMD,
                 "%s: the contact sheet needs the image module (above); allowed: install "
                 "OpenImageIO 2.4 (Debian package libopenimageio2.4), or drop "
                 "outputs.contact_sheet and make the sheet elsewhere with --sheet",
                 J.file);
        rc = BT_EXIT_INTERNAL;
    }
    if (rc) {
        job_free(&J);
        return rc;
    }
    if (mkdirs(J.outdir)) {
        bt_error(CMD, "%s: cannot create the output folder (%s)", J.outdir, strerror(errno));
        job_free(&J);
        return BT_EXIT_BAD_INPUT;
    }
    char mdir[8192];
    snprintf(mdir, sizeof mdir, "%s/.libblend-manifest", J.outdir);
    if (mkdirs(mdir)) {
        bt_error(CMD, "%s: cannot create the manifest folder (%s)", mdir, strerror(errno));
        job_free(&J);
        return BT_EXIT_BAD_INPUT;
    }
    logger L = {NULL, 0, 0, 0};
    if (log_json) L.f = stdout;
    if (logpath) {
        L.f = fopen(logpath, "a");
        if (!L.f) {
            bt_error(CMD, "--log %s: %s", logpath, strerror(errno));
            job_free(&J);
            return BT_EXIT_BAD_INPUT;
        }
    }
    L.bar = isatty(STDERR_FILENO);
    if (sheet_only) {
        rc = contact_sheet(&J, nt, &L);
        if (L.f && L.f != stdout) fclose(L.f);
        job_free(&J);
        return rc;
    }
    cJSON *je = event("job", NULL);
    cJSON_AddStringToObject(je, "job", J.name);
    cJSON_AddNumberToObject(je, "tasks", (double)nt);
    cJSON_AddNumberToObject(je, "first", (double)lo);
    cJSON_AddNumberToObject(je, "end", (double)hi);
    log_event(&L, je);
    size_t done = 0, skipped = 0, failed = 0, nbusy = 0;
    int worst = 0; /* the exit code of the failed tasks: 1 when any failed inside */
    /* Tasks locked by another process (another run on the same OUT folder)
     * are passed over and taken at the end, waiting for their locks: by
     * then the other process has usually finished them, and they are
     * skipped as complete. */
    size_t *busy = malloc((hi - lo + 1) * sizeof *busy);
    if (!busy) rc = BT_EXIT_INTERNAL;
    for (size_t q = lo; busy && q < hi + nbusy; ++q) {
        const int second = q >= hi;
        const size_t i = second ? busy[q - hi] : q;
        task T;
        if (make_task(&J, i, &T)) {
            rc = BT_EXIT_INTERNAL;
            break;
        }
        if (fa >= 0 && (T.frame < fa || T.frame > fb)) {
            task_free(&T);
            continue;
        }
        const int lk = task_lock(&J, &T, second);
        if (lk == -1) {
            busy[nbusy++] = i;
            task_free(&T);
            continue;
        }
        const double t0 = now();
        if (L.bar) fprintf(stderr, "\r[%zu/%zu] %s ", q - lo + 1, hi - lo, T.name), fflush(stderr);
        lb_scene *sc = NULL;
        uint64_t h[2] = {0, 0};
        int trc = 0;
        if (lk < 0) {
            bt_error(CMD, "%s: cannot lock the task in %s (%s)", T.name, mdir, strerror(errno));
            trc = BT_EXIT_INTERNAL;
        } else {
            trc = bt_load_scene_set(CMD, J.scenes[T.scene], T.sets, T.nsets, &sc, h);
        }
        char *ident = trc ? NULL : identity(&J, &T, h);
        const char *status = "done";
        if (!trc && task_done(&J, &T, ident)) {
            status = "skipped";
            ++skipped;
        } else if (!trc) {
            log_event(&L, event("task_start", &T));
            trc = run_task(&J, &T, ident, h, sc, &L, J.threads);
        }
        if (lk >= 0) close(lk); /* the lock goes with the descriptor */
        if (trc) {
            status = "failed";
            ++failed;
            if (trc != BT_EXIT_BAD_INPUT || !worst) worst = trc;
        } else if (strcmp(status, "skipped")) {
            ++done;
        }
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        cJSON *e = event("task_end", &T);
        cJSON_AddStringToObject(e, "status", status);
        cJSON_AddNumberToObject(e, "seconds", now() - t0);
        cJSON_AddNumberToObject(e, "peak_rss_kb", (double)ru.ru_maxrss);
        if (trc) cJSON_AddStringToObject(e, "error", bt_last_error());
        log_event(&L, e);
        free(ident);
        lb_scene_free(sc);
        task_free(&T);
        if (trc && fail_fast) break;
    }
    free(busy);
    if (L.bar) fprintf(stderr, "\n");
    if (!rc && !failed && J.sheet && lo == 0 && hi == nt && fa < 0) rc = contact_sheet(&J, nt, &L);
    cJSON *e = event("job_end", NULL);
    cJSON_AddNumberToObject(e, "done", (double)done);
    cJSON_AddNumberToObject(e, "skipped", (double)skipped);
    cJSON_AddNumberToObject(e, "failed", (double)failed);
    log_event(&L, e);
    if (L.f && L.f != stdout && fclose(L.f) != 0 && !L.failed) {
        L.failed = 1;
        L.err = errno;
    }
    if (L.failed) {
        bt_error(CMD, "%s: writing the log failed (%s); the outputs and manifests are complete",
                 logpath ? logpath : "standard output", strerror(L.err));
        if (!rc) rc = BT_EXIT_INTERNAL;
    }
    fprintf(stderr, "blendtool batch: %s: %zu done, %zu skipped (complete), %zu failed\n", J.name,
            done, skipped, failed);
    job_free(&J);
    return rc ? rc : failed ? worst : BT_EXIT_OK;
}

const bt_command bt_cmd_batch = {
    "batch", "run a job file: sweeps and frames as tasks, resumable, sharded, on Slurm",
    "usage: blendtool batch JOB.json [--list] [--task ID | --shard I/N] [--frames A-B]\n"
    "                       [--threads N] [--log FILE | --log-json] [--fail-fast] [--sheet]\n"
    "       blendtool batch JOB.json --slurm [--array-size N] [--partition P] [--submit]\n\n"
    "Expands the job (docs/batch.md) into tasks: scenes x sweep values x frames, in a\n"
    "fixed order, and runs them: each task's outputs (mesh, POV-Ray scene, image) go\n"
    "into the output folder under temporary names and are renamed when complete; a\n"
    "manifest (scene hash, parameters, libblend version, output hashes) is written\n"
    "last. A task whose manifest and outputs match is skipped, so a rerun after a\n"
    "kill or a failure redoes only what is missing.\n"
    "  --list          print the tasks: id, name, scene hash, outputs, parameters\n"
    "  --task ID       run one task; --shard I/N the I-th of N contiguous chunks\n"
    "  --frames A-B    only the frames A to B\n"
    "  --threads N     threads per task (the job's \"threads\", default 1)\n"
    "  --log FILE      append one JSON line per event to FILE; --log-json to stdout\n"
    "  --fail-fast     stop at the first failed task (default: run the others)\n"
    "  --sheet         only (re)make the contact sheet from the finished images\n"
    "  --slurm         write OUT/NAME.sbatch, an array job of --array-size shards (4);\n"
    "                  --submit also runs sbatch --wait on it\n"
    "Exit status: 0 every selected task done or complete, 1 a task failed, 2 bad job file\n"
    "or options, 130 / 143 / 129 ended by SIGINT / SIGTERM / SIGHUP (the running task\n"
    "leaves no output and no manifest).\n",
    run};
