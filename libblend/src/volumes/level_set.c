/* Narrow-band level sets (volume.h is the contract; docs/volumes.md the
 * method).
 *
 * Two phases, as in the mesher. The leaf selection descends an octree over
 * the region's leaves (8^3 voxels each, aligned to multiples of 8 in index
 * space): a box of leaves is kept while phi's interval bound over its
 * voxels' box grown by the band contains 0, each box's interval pass
 * running under its parent's plan, and a kept leaf leaves with its own
 * plan. A voxel whose estimate |phi| / |grad phi| is under the band lies
 * within the band of the surface when phi is distance-like (|grad phi| <= 1
 * everywhere), so no leaf that holds such a voxel is skipped; for other
 * fields the band is the bounds' grown box, which is what the contract
 * says. Then the leaves are evaluated in parallel (any thread takes the
 * next leaf; each writes only its own slot), each under its plan, and the
 * leaves without an active voxel are dropped in order: the output does not
 * depend on which thread did what. */
#include "../common/boxtree.h"
#include "../common/platform.h"
#include "../evaluation/tape.h"

#include <libblend/volume.h>

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

static const char FN[] = "lb_level_set_create";
#define LEAF LB_LEVEL_SET_LEAF
#define NV LB_LEVEL_SET_LEAF_VOXELS

void lb_level_set_options_init(lb_level_set_options *opt) {
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->resolution = LB_LEVEL_SET_DEFAULT_RESOLUTION;
    opt->band = LB_LEVEL_SET_DEFAULT_BAND;
}

void lb_level_set_free(lb_level_set *ls) {
    if (!ls) return;
    free(ls->origins);
    free(ls->values);
    free(ls->active);
    free(ls->fields);
    free(ls->gradients);
    free(ls);
}

/* floor(a / b) for b > 0 */
static int64_t floor_div(int64_t a, int64_t b) {
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}

typedef struct cand {
    uint64_t key;   /* (x, y, z) order of the leaf, x slowest */
    int32_t org[3]; /* its first voxel */
    lb__cplan plan; /* its grown box's plan */
} cand;

typedef struct lsel {
    const lb_evaluator *ev;
    int64_t L0[3];  /* the first leaf's coordinates (in leaves) */
    uint32_t nb[3]; /* leaves per axis */
    int32_t imin[3], imax[3];
    double h, grow; /* voxel size, band in world units */
    int soft;
    cand *c;
    size_t n, cap, max;
    lb__plan *pool;
    lb__iv *R;
    lb_error *err;
} lsel;

/* The voxels of leaves [r0, r1) inside the region, as an index range;
 * 0 when none. */
static int leaf_voxels(const lsel *S, const uint32_t r0[3], const uint32_t r1[3], int64_t v0[3],
                       int64_t v1[3]) {
    for (int d = 0; d < 3; ++d) {
        v0[d] = (S->L0[d] + r0[d]) * LEAF;
        v1[d] = (S->L0[d] + r1[d]) * LEAF - 1;
        if (v0[d] < S->imin[d]) v0[d] = S->imin[d];
        if (v1[d] > S->imax[d]) v1[d] = S->imax[d];
        if (v0[d] > v1[d]) return 0;
    }
    return 1;
}

static lb_status sel_visit(void *ctx, const uint32_t r0[3], const uint32_t r1[3], int depth,
                           int cell, int *split) {
    lsel *S = ctx;
    int64_t v0[3], v1[3];
    if (!leaf_voxels(S, r0, r1, v0, v1)) return LB_OK;
    double bl[3], bh[3], bc[3], br[3];
    for (int d = 0; d < 3; ++d) {
        bl[d] = (double)v0[d] * S->h - S->grow;
        bh[d] = (double)v1[d] * S->h + S->grow;
    }
    lb__box_centre(bl, bh, bc, br);
    lb__plan *own = &S->pool[depth];
    if (depth)
        lb__bounds_pass_sub(S->ev, &S->pool[depth - 1], bc, br, S->R, own);
    else
        lb__bounds_pass(S->ev, bc, br, S->R, own);
    const lb__iv f = S->R[S->ev->out];
    const double lo = S->soft ? 0.5 - f.hi : f.lo, hi = S->soft ? 0.5 - f.lo : f.hi;
    if (lo > 0.0 || hi < 0.0) return LB_OK; /* no surface within the band */
    if (!cell) {
        *split = 1;
        return LB_OK;
    }
    if (S->n >= S->max)
        return lb__fail(S->err, LB_ERR_INVALID_ARGUMENT,
                        "%s: more than %zu leaves near the surface exceed the memory cap "
                        "(max_memory); allowed: a larger voxel size, a narrower band or "
                        "region, or a larger max_memory",
                        FN, S->max);
    if (S->n == S->cap) {
        const size_t nc = S->cap ? 2 * S->cap : 256;
        cand *q = realloc(S->c, nc * sizeof *q);
        if (!q) return lb__fail(S->err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        S->c = q;
        S->cap = nc;
    }
    cand *C = &S->c[S->n];
    memset(C, 0, sizeof *C);
    lb_status s = lb__cplan_make(S->ev, own, &C->plan, S->err);
    if (s) return s;
    ++S->n;
    for (int d = 0; d < 3; ++d) C->org[d] = (int32_t)((S->L0[d] + r0[d]) * LEAF);
    C->key = ((uint64_t)r0[0] * S->nb[1] + r0[1]) * S->nb[2] + r0[2];
    return LB_OK;
}

static int cmp_cand(const void *a, const void *b) {
    const uint64_t x = ((const cand *)a)->key, y = ((const cand *)b)->key;
    return x < y ? -1 : x > y;
}

/* ---- the leaves' values, in parallel ---- */

typedef struct lrun {
    const lb_evaluator *ev;
    const lsel *S;
    lb_level_set *L; /* arrays sized for every candidate */
    unsigned flags;
    const volatile int *cancel;
    pthread_mutex_t lock;
    size_t next;
    lb_status status;
    lb_error err;
    uint8_t *kept; /* per candidate: an active voxel */
} lrun;

typedef struct lscratch {
    lb__boxeval E;
    double *x, *y, *z, *v, *gx, *gy, *gz;
    uint16_t *at;
} lscratch;

static lb_status leaf_run(lrun *R, lscratch *T, size_t i, lb_error *err) {
    const lsel *S = R->S;
    const cand *C = &S->c[i];
    lb_level_set *L = R->L;
    float *val = L->values + i * NV;
    uint64_t *act = L->active + i * 8;
    const float bg = L->background;
    size_t m = 0;
    for (int a = 0; a < LEAF; ++a)
        for (int b = 0; b < LEAF; ++b)
            for (int c = 0; c < LEAF; ++c) {
                const int64_t I[3] = {(int64_t)C->org[0] + a, (int64_t)C->org[1] + b,
                                      (int64_t)C->org[2] + c};
                const int n = a * 64 + b * 8 + c;
                int in = 1;
                for (int d = 0; d < 3; ++d) in &= I[d] >= S->imin[d] && I[d] <= S->imax[d];
                val[n] = bg; /* outside the region: not evaluated, inactive */
                if (!in) continue;
                T->x[m] = (double)I[0] * S->h;
                T->y[m] = (double)I[1] * S->h;
                T->z[m] = (double)I[2] * S->h;
                T->at[m++] = (uint16_t)n;
            }
    memset(act, 0, 8 * sizeof *act);
    if (R->flags & LB_LEVEL_SET_FIELD) memset(L->fields + i * NV, 0, NV * sizeof(float));
    if (R->flags & LB_LEVEL_SET_GRADIENT)
        memset(L->gradients + i * 3 * NV, 0, 3 * NV * sizeof(float));
    lb__boxeval_load(R->ev, &C->plan, &T->E);
    lb_status s =
        lb__boxeval_run(R->ev, &T->E, m, T->x, T->y, T->z, T->v, T->gx, T->gy, T->gz, err);
    if (s) return s;
    int any = 0;
    for (size_t q = 0; q < m; ++q) {
        const int n = T->at[q];
        const double phi = S->soft ? 0.5 - T->v[q] : T->v[q];
        const double g = sqrt(T->gx[q] * T->gx[q] + T->gy[q] * T->gy[q] + T->gz[q] * T->gz[q]);
        double d = phi > 0.0 ? HUGE_VAL : phi < 0.0 ? -HUGE_VAL : 0.0;
        if (g > 0.0 && isfinite(g) && isfinite(phi)) d = phi / g;
        if (d < (double)bg && d > -(double)bg) {
            act[n / 64] |= (uint64_t)1 << (n % 64);
            val[n] = (float)d;
            /* rounding to float must not reach the background or flip the sign */
            if (!(fabsf(val[n]) < bg))
                val[n] = d > 0 ? nextafterf(bg, 0.0f) : -nextafterf(bg, 0.0f);
            if (d != 0.0 && (val[n] > 0) != (d > 0)) val[n] = d > 0 ? 1e-30f : -1e-30f;
            any = 1;
        } else {
            val[n] = phi < 0.0 ? -bg : bg;
        }
        if (R->flags & LB_LEVEL_SET_FIELD) L->fields[i * NV + n] = (float)T->v[q];
        if (R->flags & LB_LEVEL_SET_GRADIENT) {
            float *G = L->gradients + (i * NV + n) * 3;
            G[0] = (float)T->gx[q];
            G[1] = (float)T->gy[q];
            G[2] = (float)T->gz[q];
        }
    }
    R->kept[i] = (uint8_t)any;
    return LB_OK;
}

static void *worker(void *arg) {
    lrun *R = arg;
    lscratch T;
    memset(&T, 0, sizeof T);
    lb_error err = {0};
    lb_status s = lb__boxeval_alloc(R->ev, &T.E, &err);
    double *buf = malloc(7 * NV * sizeof *buf);
    T.at = malloc(NV * sizeof *T.at);
    if (!s && (!buf || !T.at)) s = lb__fail(&err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    if (buf) {
        T.x = buf;
        T.y = T.x + NV;
        T.z = T.y + NV;
        T.v = T.z + NV;
        T.gx = T.v + NV;
        T.gy = T.gx + NV;
        T.gz = T.gy + NV;
    }
    for (;;) {
        size_t i = 0;
        pthread_mutex_lock(&R->lock);
        if (s && !R->status) {
            R->status = s;
            R->err = err;
        }
        if (!R->status && R->cancel && *R->cancel) {
            R->status = lb__fail(&R->err, LB_ERR_CANCELLED, "%s: cancelled", FN);
        }
        const int more = !R->status && R->next < R->S->n;
        if (more) i = R->next++;
        pthread_mutex_unlock(&R->lock);
        if (!more) break;
        s = leaf_run(R, &T, i, &err);
    }
    lb__boxeval_free(&T.E);
    free(buf);
    free(T.at);
    return NULL;
}

/* ---- the options ---- */

static lb_status check_options(const lb_level_set_options *o, double *h, lb_error *err) {
    double longest = 0.0;
    for (int d = 0; d < 3; ++d) {
        if (!isfinite(o->bmin[d]) || !isfinite(o->bmax[d]) ||
            fabs(o->bmin[d]) > LB_SCENE_MAX_COORD || fabs(o->bmax[d]) > LB_SCENE_MAX_COORD)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: region [%g, %g] on axis %d; allowed: finite, |value| <= %g", FN,
                            o->bmin[d], o->bmax[d], d, LB_SCENE_MAX_COORD);
        if (!(o->bmin[d] < o->bmax[d]))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: region min[%d] = %g is not below max[%d] = %g; allowed: min < "
                            "max on every axis",
                            FN, d, o->bmin[d], d, o->bmax[d]);
        if (o->bmax[d] - o->bmin[d] > longest) longest = o->bmax[d] - o->bmin[d];
    }
    if (!(o->band >= 1.0 && o->band <= LB_LEVEL_SET_MAX_BAND))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: band = %g voxels; allowed: 1 to %g voxels", FN, o->band,
                        LB_LEVEL_SET_MAX_BAND);
    if (o->flags & ~(unsigned)(LB_LEVEL_SET_FIELD | LB_LEVEL_SET_GRADIENT))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: flags = %#x; allowed: LB_LEVEL_SET_FIELD | LB_LEVEL_SET_GRADIENT", FN,
                        o->flags);
    if (o->voxel_size != 0.0) {
        if (!(o->voxel_size > 0.0) || !isfinite(o->voxel_size))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: voxel_size = %g; allowed: a positive number (or 0 to use the "
                            "resolution)",
                            FN, o->voxel_size);
        *h = o->voxel_size;
    } else {
        if (o->resolution < 1 || o->resolution > LB_LEVEL_SET_MAX_VOXELS_PER_AXIS)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: resolution = %u; allowed: 1 to %d voxels along the longest side",
                            FN, o->resolution, LB_LEVEL_SET_MAX_VOXELS_PER_AXIS);
        *h = longest / o->resolution;
    }
    for (int d = 0; d < 3; ++d) {
        /* voxel indices are 32-bit (OpenVDB's too) */
        const double lo = o->bmin[d] / *h, hi = o->bmax[d] / *h;
        if (!(fabs(lo) <= LB_LEVEL_SET_MAX_INDEX && fabs(hi) <= LB_LEVEL_SET_MAX_INDEX))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: the region [%g, %g] on axis %d is %.3g voxels of %g from the "
                            "origin; allowed: at most %d (voxel indices are 32-bit): a larger "
                            "voxel size or a region nearer the origin",
                            FN, o->bmin[d], o->bmax[d], d, fmax(fabs(lo), fabs(hi)), *h,
                            LB_LEVEL_SET_MAX_INDEX);
        const double nv = floor(hi) - ceil(lo) + 1.0;
        if (!(nv <= LB_LEVEL_SET_MAX_VOXELS_PER_AXIS))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: %.0f voxels along axis %d (voxel size %g); allowed: at most %d "
                            "voxels per axis (a voxel size of at least %g)",
                            FN, nv, d, *h, LB_LEVEL_SET_MAX_VOXELS_PER_AXIS,
                            longest / (LB_LEVEL_SET_MAX_VOXELS_PER_AXIS - 1));
        if (!(nv >= 1.0))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: no voxel inside the region on axis %d (voxel size %g, region "
                            "[%g, %g]); allowed: a voxel size at most the region's side",
                            FN, d, *h, o->bmin[d], o->bmax[d]);
    }
    return LB_OK;
}

/* bytes one candidate leaf takes while the level set is built */
static size_t leaf_bytes(unsigned flags) {
    size_t b = NV * sizeof(float) + 8 * sizeof(uint64_t) + 3 * sizeof(int32_t) + sizeof(cand) + 1;
    if (flags & LB_LEVEL_SET_FIELD) b += NV * sizeof(float);
    if (flags & LB_LEVEL_SET_GRADIENT) b += 3 * NV * sizeof(float);
    return b;
}

lb_status lb_level_set_create(const lb_evaluator *ev, const lb_level_set_options *opt,
                              lb_level_set **out, lb_error *err) {
    if (out) *out = NULL;
    if (!ev || !opt || !out)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: %s is NULL; allowed: non-NULL", FN,
                        !ev    ? "ev"
                        : !opt ? "opt"
                               : "out");
    double h = 0.0;
    lb_status s = check_options(opt, &h, err);
    if (s) return s;
    lsel S;
    memset(&S, 0, sizeof S);
    S.ev = ev;
    S.h = h;
    S.grow = opt->band * h;
    S.soft = lb_evaluator_convention(ev) == LB_CONVENTION_SOFT;
    S.err = err;
    for (int d = 0; d < 3; ++d) {
        S.imin[d] = (int32_t)ceil(opt->bmin[d] / h);
        S.imax[d] = (int32_t)floor(opt->bmax[d] / h);
        S.L0[d] = floor_div(S.imin[d], LEAF);
        S.nb[d] = (uint32_t)(floor_div(S.imax[d], LEAF) - S.L0[d] + 1);
    }
    const size_t cap = opt->max_memory ? opt->max_memory : LB_LEVEL_SET_DEFAULT_MAX_MEMORY;
    S.max = cap / leaf_bytes(opt->flags);
    const int depth = lb__box_depths(S.nb);
    S.pool = calloc((size_t)depth, sizeof *S.pool);
    S.R = malloc(lb__ivs_len(ev) * sizeof *S.R);
    if (!S.pool || !S.R) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    for (int d = 0; d < depth && !s; ++d) s = lb__plan_alloc(ev, &S.pool[d], err);
    const uint32_t zero[3] = {0, 0, 0};
    if (!s) s = lb__box_descend(&S, sel_visit, zero, S.nb, 0);
    for (int d = 0; d < depth && S.pool; ++d) lb__plan_free(&S.pool[d]);
    free(S.pool);
    free(S.R);
    if (!s && S.n) qsort(S.c, S.n, sizeof *S.c, cmp_cand);

    lb_level_set *L = calloc(1, sizeof *L);
    lrun R;
    memset(&R, 0, sizeof R);
    if (!s && !L) s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    if (!s) {
        const size_t n = S.n ? S.n : 1;
        L->voxel_size = h;
        L->band = opt->band;
        L->background = (float)(opt->band * h);
        for (int d = 0; d < 3; ++d) {
            L->imin[d] = S.imin[d];
            L->imax[d] = S.imax[d];
        }
        L->values = malloc(n * NV * sizeof *L->values);
        L->active = malloc(n * 8 * sizeof *L->active);
        L->origins = malloc(n * 3 * sizeof *L->origins);
        if (opt->flags & LB_LEVEL_SET_FIELD) L->fields = malloc(n * NV * sizeof *L->fields);
        if (opt->flags & LB_LEVEL_SET_GRADIENT)
            L->gradients = malloc(n * 3 * NV * sizeof *L->gradients);
        R.kept = calloc(n, 1);
        if (!L->values || !L->active || !L->origins || !R.kept ||
            ((opt->flags & LB_LEVEL_SET_FIELD) && !L->fields) ||
            ((opt->flags & LB_LEVEL_SET_GRADIENT) && !L->gradients))
            s = lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory for %zu leaves", FN, S.n);
    }
    if (!s && S.n) {
        R.ev = ev;
        R.S = &S;
        R.L = L;
        R.flags = opt->flags;
        R.cancel = opt->cancel;
        size_t nt = opt->threads > 0 ? (size_t)opt->threads : lb__cpu_count();
        if (nt > S.n) nt = S.n;
        if (nt < 1) nt = 1;
        pthread_mutex_init(&R.lock, NULL);
        pthread_t *tid = nt > 1 ? malloc((nt - 1) * sizeof *tid) : NULL;
        size_t started = 0;
        for (size_t t = 0; tid && t + 1 < nt; ++t, ++started)
            if (pthread_create(&tid[t], NULL, worker, &R)) break;
        worker(&R);
        for (size_t t = 0; t < started; ++t) pthread_join(tid[t], NULL);
        free(tid);
        pthread_mutex_destroy(&R.lock);
        s = R.status;
        if (s && err) *err = R.err;
    }
    if (!s) { /* the leaves with an active voxel, in order */
        size_t k = 0;
        for (size_t i = 0; i < S.n; ++i) {
            if (!R.kept[i]) continue;
            if (k != i) {
                memcpy(L->values + k * NV, L->values + i * NV, NV * sizeof *L->values);
                memcpy(L->active + k * 8, L->active + i * 8, 8 * sizeof *L->active);
                if (L->fields) memcpy(L->fields + k * NV, L->fields + i * NV, NV * sizeof(float));
                if (L->gradients)
                    memcpy(L->gradients + k * 3 * NV, L->gradients + i * 3 * NV,
                           3 * NV * sizeof(float));
            }
            for (int d = 0; d < 3; ++d) L->origins[3 * k + d] = S.c[i].org[d];
            for (int w = 0; w < 8; ++w)
                L->nactive += (size_t)__builtin_popcountll(L->active[8 * k + w]);
            ++k;
        }
        L->nleaves = k;
    }
    if (!s) { /* voxels evaluated: those of the candidates inside the region */
        for (size_t i = 0; i < S.n; ++i) {
            uint32_t r0[3], r1[3];
            for (int d = 0; d < 3; ++d) {
                r0[d] = (uint32_t)(S.c[i].org[d] / LEAF - S.L0[d]);
                r1[d] = r0[d] + 1;
            }
            int64_t v0[3], v1[3];
            if (leaf_voxels(&S, r0, r1, v0, v1))
                L->nevaluated +=
                    (size_t)((v1[0] - v0[0] + 1) * (v1[1] - v0[1] + 1) * (v1[2] - v0[2] + 1));
        }
    }
    for (size_t i = 0; i < S.n; ++i) lb__cplan_free(&S.c[i].plan);
    free(S.c);
    free(R.kept);
    if (s) {
        lb_level_set_free(L);
        return s;
    }
    *out = L;
    return LB_OK;
}
