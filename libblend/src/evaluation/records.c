/* Instruction records (records.h). */
#include "records.h"

#include "../operators/registry.h"

#include <stdlib.h>
#include <string.h>

static void put(lb__rbuf *b, const void *x, size_t n) {
    if (b->oom || !n) return;
    if (b->n + n > b->cap) {
        size_t c = b->cap ? b->cap : 1024;
        while (c < b->n + n) c *= 2;
        uint8_t *q = realloc(b->p, c);
        if (!q) {
            b->oom = 1;
            return;
        }
        b->p = q;
        b->cap = c;
    }
    memcpy(b->p + b->n, x, n);
    b->n += n;
}

static void put_i(lb__rbuf *b, long long v) {
    put(b, &v, sizeof v);
}

static void put_d(lb__rbuf *b, const double *v, size_t n) {
    put(b, v, n * sizeof *v);
}

/* An argument: its match (map) or its own index (map NULL); 0 when it has
 * no match. */
static int put_ref(lb__rbuf *b, const uint32_t *map, uint32_t j) {
    const uint32_t r = map ? map[j] : j;
    put(b, &r, sizeof r);
    return r != LB__RNONE;
}

static void put_curves(lb__rbuf *b, const struct lb__curves *c) {
    put_i(b, c != NULL);
    if (!c) return;
    put_i(b, (long long)c->nv);
    put_i(b, (long long)c->ncomp);
    put_i(b, (long long)c->nseg);
    put_i(b, (long long)c->nnodes);
    put_d(b, c->pts, 3 * c->nv);
    for (size_t i = 0; i < c->ncomp; ++i) {
        const lb__component *q = &c->comp[i];
        put_i(b, (long long)q->first);
        put_i(b, (long long)q->count);
        put_i(b, q->closed);
        const double v[] = {q->length, q->diameter, q->R, q->v1, q->v2, q->d1, q->d2, q->p, q->q};
        put_d(b, v, sizeof v / sizeof *v);
    }
    put(b, c->seg, 2 * c->nseg * sizeof *c->seg);
    put(b, c->segc, c->nseg * sizeof *c->segc);
    for (size_t i = 0; i < c->nnodes; ++i) {
        const bvh_node *q = &c->bvh[i];
        put_d(b, q->lo, 3);
        put_d(b, q->hi, 3);
        put(b, &q->left, sizeof q->left);
        put(b, &q->right, sizeof q->right);
        put_i(b, q->leaf);
    }
    put_d(b, &c->rmax, 1);
    put_d(b, &c->scene_size, 1);
}

/* (records.h) Registers, the node identity, aoff and the path are left out:
 * they differ between evaluators without changing a single result. */
int lb__record(const lb_evaluator *ev, uint32_t i, const uint32_t *map, int args, int curves,
               lb__rbuf *b) {
    const lb__instr *in = &ev->ins[i];
    put_i(b, in->code);
    put_i(b, in->identity);
    put_i(b, in->fast);
    put_i(b, in->mode);
    put_d(b, &in->lip, 1);
    put_d(b, &in->cost, 1);
    put_d(b, in->ia, 3);
    const lb_primitive *P = &in->prim;
    put_i(b, P->kind);
    put_i(b, P->kernel);
    put_d(b, P->c, 3);
    put_d(b, P->a, 3);
    put_d(b, P->n, 3);
    put_d(b, P->q, 3);
    put_d(b, &P->s0, 1);
    put_d(b, &P->s1, 1);
    put_d(b, in->A.M, 9);
    put_d(b, in->A.t, 3);
    if (in->code != LB__I_OP) return 1;
    const lb__op *o = in->op;
    put_i(b, o->family);
    put_i(b, o->op);
    put_i(b, (long long)o->k);
    const double *arr[3] = {o->r, o->p, o->m};
    for (int a = 0; a < 3; ++a) {
        put_i(b, arr[a] != NULL);
        if (arr[a]) put_d(b, arr[a], o->k);
    }
    put_d(b, &o->shape, 1);
    put_i(b, o->bulge);
    const lb_bulge_params *bp = &o->bp;
    put_d(b, bp->r, 2);
    put_d(b, bp->p, 2);
    put_d(b, &bp->conic_p, 1);
    put_d(b, bp->m, 2);
    put_d(b, &bp->omega, 1);
    put_i(b, bp->flags);
    const lb__local_params *lp = &o->lp;
    put_i(b, lp->has_feature);
    put_d(b, lp->feature, 2);
    put_i(b, lp->has_limits);
    put_d(b, lp->limits, 2);
    put_d(b, &lp->radius, 1);
    put_i(b, lp->feature_support);
    const double lv[] = {lp->support, lp->exponent, lp->alpha[0], lp->alpha[1], lp->zero_scale};
    put_d(b, lv, sizeof lv / sizeof *lv);
    int ok = 1;
    if (args)
        for (size_t a = 0; a < o->k; ++a) ok &= put_ref(b, map, in->srci[a]);
    put_i(b, in->srcb != NULL);
    if (in->srcb)
        for (size_t a = 0; a < o->k; ++a) ok &= put_ref(b, map, in->srcb[a]);
    put_i(b, in->ncone[0]);
    put_i(b, in->ncone[1]);
    if (in->cone)
        for (uint32_t q = 0; q < in->ncone[0] + in->ncone[1]; ++q)
            ok &= put_ref(b, map, in->cone[q]);
    put_curves(b, curves ? in->curves : NULL);
    return ok;
}

uint64_t lb__rhash(const uint8_t *p, size_t n) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

void lb__recs_free(lb__recs *R) {
    free(R->p);
    free(R->off);
    free(R->h);
    free(R->bad);
    memset(R, 0, sizeof *R);
}

/* ev's records (args: with arguments; map: names through it, else as
 * ev's own indices). 0 when out of memory. */
int lb__recs_make(const lb_evaluator *ev, const uint32_t *map, int args, int curves, lb__recs *R) {
    lb__rbuf b = {NULL, 0, 0, 0};
    R->off = malloc((ev->n + 1) * sizeof *R->off);
    R->h = malloc((ev->n ? ev->n : 1) * sizeof *R->h);
    R->bad = calloc(ev->n ? ev->n : 1, 1);
    if (!R->off || !R->h || !R->bad) {
        lb__recs_free(R);
        return 0;
    }
    for (size_t i = 0; i < ev->n && !b.oom; ++i) {
        R->off[i] = b.n;
        R->bad[i] = !lb__record(ev, (uint32_t)i, map, args, curves, &b);
        if (!b.oom) R->h[i] = lb__rhash(b.p + R->off[i], b.n - R->off[i]);
    }
    R->off[ev->n] = b.n;
    R->p = b.p;
    if (b.oom) {
        lb__recs_free(R);
        return 0;
    }
    return 1;
}

/* Are record i of A and record j of B the same bytes? */
int lb__recs_equal(const lb__recs *A, size_t i, const lb__recs *B, size_t j) {
    const size_t la = A->off[i + 1] - A->off[i], lb = B->off[j + 1] - B->off[j];
    return !A->bad[i] && !B->bad[j] && A->h[i] == B->h[j] && la == lb &&
           !memcmp(A->p + A->off[i], B->p + B->off[j], la);
}

size_t lb__recs_table_cap(size_t n) {
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    return cap;
}

void lb__recs_table_fill(const lb__recs *R, size_t n, uint32_t *tab, size_t tcap) {
    for (size_t i = 0; i < n; ++i) {
        size_t s = R->h[i] & (tcap - 1);
        while (tab[s]) s = (s + 1) & (tcap - 1);
        tab[s] = (uint32_t)i + 1;
    }
}

uint32_t lb__recs_find(const lb__recs *R, const uint32_t *tab, size_t tcap, const uint8_t *p,
                       size_t len) {
    const uint64_t h = lb__rhash(p, len);
    for (size_t s = h & (tcap - 1); tab[s]; s = (s + 1) & (tcap - 1)) {
        const uint32_t j = tab[s] - 1;
        if (R->h[j] == h && !R->bad[j] && R->off[j + 1] - R->off[j] == len &&
            !memcmp(R->p + R->off[j], p, len))
            return j;
    }
    return LB__RNONE;
}
