/* Local blending's segment hierarchy (evaluation/local_curves.c finds the
 * segments): a bounding-volume hierarchy over every segment of a
 * local_union's intersection curves, and the queries on it, the nearest
 * blending volume to a point and whether any reaches a box. */
#include "local_internal.h"

#include <stdlib.h>
#include <string.h>

/* ---- step 6: the segment hierarchy ---- */

static void seg_box(const struct lb__curves *C, uint32_t s, double lo[3], double hi[3]) {
    const double *a = C->pts + 3 * C->seg[2 * s], *b = C->pts + 3 * C->seg[2 * s + 1];
    for (int d = 0; d < 3; ++d) {
        lo[d] = a[d] < b[d] ? a[d] : b[d];
        hi[d] = a[d] < b[d] ? b[d] : a[d];
    }
}

static uint32_t build(struct lb__curves *C, uint32_t *order, uint32_t first, uint32_t count) {
    const uint32_t id = (uint32_t)C->nnodes++;
    bvh_node *N = &C->bvh[id];
    for (int d = 0; d < 3; ++d) {
        N->lo[d] = INFINITY;
        N->hi[d] = -INFINITY;
    }
    for (uint32_t i = 0; i < count; ++i) {
        double lo[3], hi[3];
        seg_box(C, order[first + i], lo, hi);
        for (int d = 0; d < 3; ++d) {
            if (lo[d] < N->lo[d]) N->lo[d] = lo[d];
            if (hi[d] > N->hi[d]) N->hi[d] = hi[d];
        }
    }
    if (count <= 4) {
        N->leaf = 1;
        N->left = first;
        N->right = count;
        return id;
    }
    int axis = 0;
    for (int d = 1; d < 3; ++d)
        if (N->hi[d] - N->lo[d] > N->hi[axis] - N->lo[axis]) axis = d;
    /* partial sort by the segments' centres along the axis: median split */
    const double cut = 0.5 * (N->lo[axis] + N->hi[axis]);
    uint32_t l = first, r = first + count;
    while (l < r) {
        const uint32_t s = order[l];
        const double c =
            0.5 * (C->pts[3 * C->seg[2 * s] + axis] + C->pts[3 * C->seg[2 * s + 1] + axis]);
        if (c < cut)
            ++l;
        else {
            order[l] = order[--r];
            order[r] = s;
        }
    }
    uint32_t half = l - first;
    if (half == 0 || half == count) half = count / 2;
    N->leaf = 0;
    const uint32_t left = build(C, order, first, half);
    const uint32_t right = build(C, order, first + half, count - half);
    C->bvh[id].left = left;
    C->bvh[id].right = right;
    return id;
}

lb_status lb__local_bvh(struct lb__curves *C, const char *path, lb_error *err) {
    size_t ns = 0;
    for (size_t c = 0; c < C->ncomp; ++c) ns += C->comp[c].count - (C->comp[c].closed ? 0 : 1);
    C->nseg = ns;
    if (!ns) return LB_OK;
    C->seg = malloc(2 * ns * sizeof *C->seg);
    C->segc = malloc(ns * sizeof *C->segc);
    C->bvh = malloc(2 * ns * sizeof *C->bvh);
    uint32_t *order = malloc(ns * sizeof *order);
    if (!C->seg || !C->segc || !C->bvh || !order) {
        free(order);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    size_t q = 0;
    for (size_t c = 0; c < C->ncomp; ++c) {
        const lb__component *K = &C->comp[c];
        for (size_t i = 0; i + 1 < K->count || (K->closed && i < K->count); ++i) {
            C->seg[2 * q] = (uint32_t)(K->first + i);
            C->seg[2 * q + 1] = (uint32_t)(K->first + (i + 1) % K->count);
            C->segc[q] = (uint32_t)c;
            order[q] = (uint32_t)q;
            ++q;
        }
    }
    C->nnodes = 0;
    build(C, order, 0, (uint32_t)ns);
    /* leaves refer to the order: store the segments in that order */
    uint32_t *seg = malloc(2 * ns * sizeof *seg), *segc = malloc(ns * sizeof *segc);
    if (!seg || !segc) {
        free(seg);
        free(segc);
        free(order);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    for (size_t i = 0; i < ns; ++i) {
        seg[2 * i] = C->seg[2 * order[i]];
        seg[2 * i + 1] = C->seg[2 * order[i] + 1];
        segc[i] = C->segc[order[i]];
    }
    free(C->seg);
    free(C->segc);
    C->seg = seg;
    C->segc = segc;
    free(order);
    return LB_OK;
}

/* ---- queries ---- */

static double box_dist2(const double lo[3], const double hi[3], const double X[3]) {
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        const double e = X[d] < lo[d] ? lo[d] - X[d] : X[d] > hi[d] ? X[d] - hi[d] : 0.0;
        s += e * e;
    }
    return s;
}

/* the component with the smallest d / R near X (a < 1), the distance and
 * the closest point; returns a = d / R (>= 1: outside every volume) */
double lb__local_nearest(const struct lb__curves *C, const double X[3], uint32_t *comp, double Q[3],
                         double *dist) {
    double best = 1.0;
    if (!C || !C->nseg) return best;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top) {
        const bvh_node *N = &C->bvh[stack[--top]];
        if (box_dist2(N->lo, N->hi, X) >= C->rmax * C->rmax * best * best) continue;
        if (!N->leaf) {
            if (top + 2 <= 128) {
                stack[top++] = N->left;
                stack[top++] = N->right;
            }
            continue;
        }
        for (uint32_t i = 0; i < N->right; ++i) {
            const uint32_t s = N->left + i;
            const double *a = C->pts + 3 * C->seg[2 * s], *b = C->pts + 3 * C->seg[2 * s + 1];
            double ab[3], ax[3], ll = 0.0, t = 0.0;
            for (int d = 0; d < 3; ++d) {
                ab[d] = b[d] - a[d];
                ax[d] = X[d] - a[d];
                ll += ab[d] * ab[d];
                t += ab[d] * ax[d];
            }
            t = ll > 0.0 ? t / ll : 0.0;
            if (t < 0.0) t = 0.0;
            if (t > 1.0) t = 1.0;
            double P[3], dd = 0.0;
            for (int d = 0; d < 3; ++d) {
                P[d] = a[d] + t * ab[d];
                dd += (X[d] - P[d]) * (X[d] - P[d]);
            }
            const double R = C->comp[C->segc[s]].R, aa = sqrt(dd) / R;
            if (aa < best) {
                best = aa;
                *comp = C->segc[s];
                memcpy(Q, P, sizeof P);
                *dist = sqrt(dd);
            }
        }
    }
    return best;
}

/* does any blending volume reach the box? (conservative) */
int lb__local_reaches(const struct lb__curves *C, const double bc[3], const double br[3]) {
    if (!C || !C->nseg) return 0;
    const bvh_node *N = &C->bvh[0];
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        const double lo = bc[d] - br[d], hi = bc[d] + br[d];
        const double e = hi < N->lo[d] ? N->lo[d] - hi : lo > N->hi[d] ? lo - N->hi[d] : 0.0;
        s += e * e;
    }
    return s < C->rmax * C->rmax;
}
