/* blendtool batch: the task list (scenes x sweep axes x frames), each
 * task's outputs and manifest, and the JSON-lines log. */
#define _GNU_SOURCE /* fopencookie */
#include "batch.h"

/* ---- the task list ---- */

static size_t combos(const job *J) {
    size_t n = 1;
    for (size_t a = 0; a < J->naxes; ++a) n *= J->axes[a].n;
    return n;
}

size_t batch_ntasks_of(const job *J) {
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

void batch_task_free(task *T) {
    for (size_t i = 0; i < T->nsets; ++i) free(T->set_text[i]);
    T->nsets = 0;
}

/* task id: scene slowest, then the sweep axes (first slowest), frames fastest */
int batch_make_task(const job *J, size_t id, task *T) {
    memset(T, 0, sizeof *T);
    T->id = id;
    const size_t nf = J->has_frames ? (size_t)(J->last - J->first + 1) : 1, nc = combos(J);
    const size_t fi = id % nf, ci = id / nf % nc;
    T->scene = id / nf / nc;
    T->combo = ci;
    T->frame = J->has_frames ? J->first + (long)fi : (long)ci; /* a sweep: its index */
    for (size_t i = 0; i < J->nfixed; ++i) {
        T->set_text[T->nsets] = batch_dupstr(J->fixed[i].path);
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
        last = X->label[0] ? X->label : last ? last + 1 : X->path;
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
size_t batch_outputs_of(const job *J, const task *T, char out[BATCH_MAX_OUTPUTS][600]) {
    size_t n = 0;
    if (J->mesh) snprintf(out[n++], 600, "%s.%s", T->name, mesh_ext(J->mesh_fmt));
    if (J->pov) snprintf(out[n++], 600, "%s.pov", T->name);
    if (J->vdb) snprintf(out[n++], 600, "%s.vdb", T->name);
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

void batch_manifest_path(const job *J, const task *T, char *out, size_t len) {
    snprintf(out, len, "%s/.libblend-manifest/%s.json", J->outdir, T->name);
}

/* the manifest's identity of a task: scene hash, overrides, version, outputs spec */
char *batch_identity(const job *J, const task *T, const uint64_t scene[2]) {
    cJSON *o = cJSON_CreateObject();
    char hex[33];
    bt_hash_hex(scene, hex);
    cJSON_AddStringToObject(o, "scene_hash", hex);
    cJSON_AddStringToObject(o, "scene", J->scene_stems[T->scene]);
    cJSON *p = cJSON_AddArrayToObject(o, "parameters");
    for (size_t i = 0; i < T->nsets; ++i)
        cJSON_AddItemToArray(p, cJSON_CreateString(T->sets[i].path));
    cJSON_AddStringToObject(o, "label", T->label); /* it is in the image's metadata */
    cJSON_AddStringToObject(o, "libblend", BT_VERSION);
    bt_hash_hex(J->spec_hash, hex);
    cJSON_AddStringToObject(o, "outputs_spec", hex);
    if (J->image && J->blender) { /* who made the image: another Blender re-renders */
        cJSON *r = cJSON_AddObjectToObject(o, "renderer");
        cJSON_AddStringToObject(r, "name", "blender");
        cJSON_AddStringToObject(r, "version", J->blender_version);
        cJSON_AddStringToObject(r, "engine", J->engine);
        cJSON_AddNumberToObject(r, "samples", J->samples);
        cJSON_AddNumberToObject(r, "seed", J->seed);
        if (J->shutter > 0) {
            cJSON_AddNumberToObject(r, "motion_blur", J->shutter);
            cJSON_AddNumberToObject(r, "fps", J->fps);
        }
    }
    char *t = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return t;
}

/* is the task complete: manifest matching and every output with its hash? */
int batch_task_done(const job *J, const task *T, const char *ident) {
    char mp[8192];
    batch_manifest_path(J, T, mp, sizeof mp);
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
        char names[BATCH_MAX_OUTPUTS][600];
        const size_t n = batch_outputs_of(J, T, names);
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

double batch_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void batch_log_event(logger *L, cJSON *e) {
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

cJSON *batch_event(const char *kind_, const task *T) {
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "event", kind_);
    if (T) {
        cJSON_AddNumberToObject(e, "task", (double)T->id);
        cJSON_AddStringToObject(e, "name", T->name);
    }
    return e;
}
