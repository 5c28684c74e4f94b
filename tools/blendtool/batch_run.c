/* blendtool batch: running one task (its outputs written atomically while
 * hashed, then its manifest) and the job's contact sheet. */
#define _GNU_SOURCE /* fopencookie */
#include "batch.h"

/* ---- running a task ---- */

int batch_write_bytes(const char *path, const void *data, size_t len) {
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

/* the scene text of task T (sets applied) into path; an exit code */
static int put_scene(const job *J, const task *T, const char *path) {
    size_t len = 0;
    char *text = bt_scene_text_set(CMD, J->scenes[T->scene], T->sets, T->nsets, &len);
    if (!text) return BT_EXIT_INTERNAL;
    FILE *f = fopen(path, "wb");
    int rc = f && fwrite(text, 1, len, f) == len ? 0 : BT_EXIT_INTERNAL;
    if (f && fclose(f) != 0) rc = BT_EXIT_INTERNAL;
    if (rc) bt_error(CMD, "%s: cannot write (%s)", path, strerror(errno));
    free(text);
    return rc;
}

/* Motion blur's velocities come from the field a small step before and
 * after the task's frame (a sub-frame, the animated paths at their keys'
 * interpolation there), so the difference quotient is the derivative, not
 * a whole frame's chord: 0.01 frame. */
#define SUBFRAME 0.01

/* the resolved scene of task T at its frame + d frames into path; an exit code */
static int put_subframe(const job *J, const task *T, double d, const char *path) {
    task N = *T; /* its sets, the animated ones (the last nanim) at frame + d */
    char *vals[MAX_AXES] = {0};
    int rc = 0;
    for (size_t a = 0; a < J->nanim && !rc; ++a) {
        const size_t i = T->nsets - J->nanim + a;
        const axis *X = &J->anim[a];
        char *v = batch_anim_value(X, (double)T->frame + d);
        const size_t l = v ? strlen(X->path) + strlen(v) + 2 : 0;
        vals[a] = v ? malloc(l) : NULL;
        if (!vals[a]) {
            rc = BT_EXIT_INTERNAL;
        } else {
            snprintf(vals[a], l, "%s=%s", X->path, v);
            N.sets[i].path = vals[a];
            N.sets[i].value = vals[a] + strlen(X->path) + 1;
        }
        free(v);
    }
    if (!rc) rc = put_scene(J, &N, path);
    for (size_t a = 0; a < J->nanim; ++a) free(vals[a]);
    return rc;
}

/* the render's progress: a log event, and the terminal's line */
typedef struct progress_ctx {
    const task *T;
    logger *L;
} progress_ctx;

static void on_progress(void *c, double f) {
    const progress_ctx *P = c;
    cJSON *e = batch_event("progress", P->T);
    cJSON_AddNumberToObject(e, "fraction", floor(f * 100 + 0.5) / 100);
    batch_log_event(P->L, e);
    if (P->L->bar) fprintf(stderr, "\r%s %3.0f%% ", P->T->name, 100 * f), fflush(stderr);
}

/* Task T's image rendered by the Blender worker into R->png: the resolved
 * scene (and for motion blur the frames around it) written into the render
 * folder, one request to the worker; an exit code. */
static int blender_render(const job *J, const task *T, const bt_render_dir *R, int threads,
                          logger *L) {
    int rc = put_scene(J, T, R->json);
    const int mb = J->shutter > 0;
    if (!rc && mb) rc = put_subframe(J, T, -SUBFRAME, R->before);
    if (!rc && mb) rc = put_subframe(J, T, +SUBFRAME, R->after);
    if (rc) return rc;
    cJSON *q = cJSON_CreateObject();
    cJSON_AddStringToObject(q, "scene", R->json);
    cJSON_AddStringToObject(q, "name", J->scene_stems[T->scene]);
    cJSON_AddStringToObject(q, "out", R->png);
    cJSON_AddNumberToObject(q, "width", J->img_w);
    cJSON_AddNumberToObject(q, "height", J->img_h);
    cJSON_AddStringToObject(q, "engine", J->engine);
    cJSON_AddNumberToObject(q, "samples", J->samples);
    cJSON_AddNumberToObject(q, "seed", J->seed);
    cJSON_AddNumberToObject(q, "threads", J->blender_threads ? J->blender_threads : threads);
    cJSON_AddNumberToObject(q, "resolution", J->img_mesh);
    cJSON_AddBoolToObject(q, "bits16", J->img_plan.bits16);
    cJSON_AddBoolToObject(q, "alpha", J->img_plan.alpha);           /* the PNG's channels */
    cJSON_AddBoolToObject(q, "transparent", J->img_plan.out_alpha); /* the background's alpha */
    cJSON_AddNumberToObject(q, "fps", J->fps);
    cJSON_AddNumberToObject(q, "shutter", J->shutter);
    if (mb) {
        cJSON_AddStringToObject(q, "before", R->before);
        cJSON_AddStringToObject(q, "after", R->after);
        cJSON_AddNumberToObject(q, "dt_frames", SUBFRAME);
    }
    char *line = cJSON_PrintUnformatted(q);
    cJSON_Delete(q);
    char err[4096] = "";
    progress_ctx P = {T, L};
    double sec[2] = {-1, -1};
    const int w =
        line ? bt_blender_task(J->worker, line, err, sizeof err, on_progress, &P, sec) : 2;
    free(line);
    if (w) {
        const int eevee = w == 2 && !strcmp(J->engine, "eevee");
        bt_error(CMD, "%s: rendering with Blender failed: %s%s", T->name,
                 err[0] ? err : "out of memory",
                 eevee ? "\nEEVEE needs OpenGL on the node (Blender 4.x: libEGL and a GPU or "
                         "Mesa); allowed: \"engine\": \"cycles\", or a node with OpenGL"
                       : "");
        return BT_EXIT_INTERNAL;
    }
    /* where the time went: Blender's render, and its whole task */
    cJSON *e = batch_event("blender", T);
    cJSON_AddNumberToObject(e, "render_seconds", sec[0]);
    cJSON_AddNumberToObject(e, "seconds", sec[1]);
    batch_log_event(L, e);
    return 0;
}

int batch_run_task(const job *J, const task *T, const char *ident, const uint64_t scene_hash[2],
                   lb_scene *sc, logger *L, int threads) {
    lb_error e = {LB_OK, ""};
    lb_evaluator *ev = NULL;
    lb_status s = LB_OK;
    const int crc = bt_compile(CMD, J->scenes[T->scene], sc, &ev);
    if (crc) return crc;
    char names[BATCH_MAX_OUTPUTS][600], hexes[BATCH_MAX_OUTPUTS][33];
    const size_t n = batch_outputs_of(J, T, names);
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
        o.simplify = J->mesh_simplify;
        if (J->mesh_features) /* the formats with a normal per corner get them */
            o.flags = LB_MESH_FEATURES |
                      (J->mesh_fmt == LB_MESH_FORMAT_OBJ || J->mesh_fmt == LB_MESH_FORMAT_GLB
                           ? LB_MESH_CORNER_NORMALS
                           : 0u);
        if (J->mesh_merge_flat) o.flags |= LB_MESH_MERGE_FLAT;
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
        lb_pov_options o = {0, 0, (double)J->pov_w / (double)J->pov_h, 0.0, threads, 0, 0, 0.0, 0};
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
    if (!rc && J->vdb) {
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[k]);
        lb_level_set_options o;
        lb_level_set_options_init(&o);
        o.resolution = (unsigned)J->vdb_res;
        o.voxel_size = J->vdb_voxel;
        o.band = J->vdb_band;
        o.flags = J->vdb_grids;
        o.threads = threads;
        lb_level_set *ls = NULL;
        unsigned char *bytes = NULL;
        size_t len = 0;
        if (!lb_scene_bounds(sc, o.bmin, o.bmax)) {
            bt_error(CMD, "%s: the scene has no bounds; allowed: a scene with \"bounds\"",
                     J->scenes[T->scene]);
            rc = BT_EXIT_BAD_INPUT;
        } else if ((s = lb_level_set_create(ev, &o, &ls, &e))) {
            rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
        } else if (!(rc = bt_vdb_bytes(CMD, J->scenes[T->scene], ls, J->vdb_blender, scene_hash,
                                       T->sets, T->nsets, o.threads, &bytes, &len))) {
            rc = hashed_bytes(full, bytes, len, hexes[k]);
        }
        free(bytes);
        lb_level_set_free(ls);
        ++k;
    }
    if (!rc && J->image) {
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[k]);
        bt_render_dir R;
        if ((rc = bt_render_dir_open(&R)) == 0) {
            lb_pov_options o = {
                0, 0, (double)J->img_w / (double)J->img_h, 0.0, threads, J->img_mesh, 0, 0.0, 0};
            if (J->blender)
                rc = blender_render(J, T, &R, threads, L);
            else if ((s = lb_scene_write_pov(sc, ev, &o, R.pov, NULL, &e)))
                rc = bt_fail(CMD, J->scenes[T->scene], s, &e);
            const bt_pov_run P = {.width = J->img_w,
                                  .height = J->img_h,
                                  .threads = threads ? threads : 1,
                                  .quality = J->img_quality,
                                  .bits16 = J->img_plan.bits16,
                                  .alpha = J->img_plan.alpha,
                                  .quiet = 1,
                                  .antialias = J->img_antialias};
            if (!rc && !J->blender) rc = bt_povray(J->scenes[T->scene], &R, &P);
            if (!rc) {
                char hex[33], settings[256], err[1024] = "";
                bt_hash_hex(scene_hash, hex);
                char mb[40] = "";
                if (J->shutter > 0) snprintf(mb, sizeof mb, " motion_blur %.3g", J->shutter);
                if (J->blender)
                    snprintf(settings, sizeof settings, "%dx%d %s %s samples %d seed %d mesh %d%s",
                             J->img_w, J->img_h, J->blender_version, J->engine, J->samples, J->seed,
                             J->img_mesh, mb);
                else
                    bt_render_settings(settings, sizeof settings, &P, 0, J->img_mesh);
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
        cJSON *ev2 = batch_event("output", T);
        cJSON_AddStringToObject(ev2, "file", names[i]);
        cJSON_AddStringToObject(ev2, "hash", hexes[i]);
        batch_log_event(L, ev2);
    }
    if (!rc) { /* the manifest last: only a complete task has one */
        char mp[8192], *text = cJSON_Print(manifest), mhex[33];
        batch_manifest_path(J, T, mp, sizeof mp);
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
int batch_task_lock(const job *J, const task *T, int wait) {
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

int batch_mkdirs(const char *path) {
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

int batch_contact_sheet(const job *J, size_t ntasks, logger *L) {
    char **imgs = calloc(ntasks, sizeof *imgs), **labels = calloc(ntasks, sizeof *labels);
    int rc = imgs && labels ? 0 : BT_EXIT_INTERNAL;
    for (size_t i = 0; i < ntasks && !rc; ++i) {
        task T;
        if ((rc = batch_make_task(J, i, &T))) break;
        char names[BATCH_MAX_OUTPUTS][600], full[8192];
        const size_t n = batch_outputs_of(J, &T, names);
        snprintf(full, sizeof full, "%s/%s", J->outdir, names[n - 1]);
        imgs[i] = batch_dupstr(full);
        labels[i] = batch_dupstr(T.label);
        batch_task_free(&T);
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
            rc = batch_write_bytes(full, data, len);
            cJSON *e = batch_event("contact_sheet", NULL);
            cJSON_AddStringToObject(e, "file", full + strlen(J->outdir) + 1);
            if (!rc)
                batch_log_event(L, e);
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
