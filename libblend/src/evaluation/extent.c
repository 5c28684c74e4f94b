/* The solid's extent: a box that contains every point of the solid inside a
 * search box, found by interval bounds alone (lb_evaluator_extent).
 *
 * Each of the six faces is a branch-and-bound search of its own. For the
 * +x face: a max-heap of boxes keyed by their upper x, starting from the
 * search box; pop the box reaching farthest; if its interval proves the
 * field outside there, drop it; if it proves it inside, or the box is at
 * most tol across, its upper x is the answer (every box left reaches less
 * far, and together the boxes cover every part of the solid not yet
 * dropped); else push its eight halves. The other faces negate or swap the
 * key. Each search does about a few boxes per level near the solid's
 * extreme point on that side, not its whole surface, when the extreme is a
 * point; where it is a ridge or a flat face (a capsule's side, a box's
 * face) every box along it is split down to tol, about (extent / tol)^1.5
 * or (extent / tol)^2 passes, so callers pick tol for what they need (the
 * Blender add-on: a mesh cell). The interval passes are capped
 * (LB_EXTENT_MAX_BOXES / 6 per face); a search that reaches the cap answers
 * with the key of the box it holds, still a sound bound (flag
 * LB_EXTENT_COARSE). Once a face's answer is the search box's own face the
 * solid is unbounded for the caller's purpose: the faces not searched yet
 * keep the search box's faces (sound) and the work stops. */
#include "tape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double lo[3], hi[3];
    double key;
} box;

typedef struct {
    box *a;
    size_t n, cap;
} heap;

static int heap_push(heap *h, const box *b) {
    if (h->n == h->cap) {
        const size_t c = h->cap ? 2 * h->cap : 256;
        box *g = realloc(h->a, c * sizeof *g);
        if (!g) return -1;
        h->a = g;
        h->cap = c;
    }
    size_t i = h->n++;
    while (i > 0 && h->a[(i - 1) / 2].key < b->key) {
        h->a[i] = h->a[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->a[i] = *b;
    return 0;
}

static box heap_pop(heap *h) {
    const box top = h->a[0], last = h->a[--h->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n) break;
        if (c + 1 < h->n && h->a[c + 1].key > h->a[c].key) ++c;
        if (!(h->a[c].key > last.key)) break;
        h->a[i] = h->a[c];
        i = c;
    }
    if (h->n) h->a[i] = last;
    return top;
}

/* how far box b reaches towards face (axis d = face / 2, upper when face is odd) */
static double reach(const box *b, int face) {
    return face & 1 ? b->hi[face / 2] : -b->lo[face / 2];
}

/* One face's search: *answer is the farthest reach of the solid (as
 * reach() measures it); returns 1 when the solid is not in the box at all,
 * -1 when memory is short, else 0. */
static int face_search(const lb_evaluator *ev, lb__iv *R, heap *h, const box *search, double tol,
                       int face, double *answer, int *flags) {
    const int soft = ev->conv == LB_CONVENTION_SOFT;
    size_t passes = 0;
    box b = *search;
    b.key = reach(&b, face);
    h->n = 0;
    if (heap_push(h, &b)) return -1;
    while (h->n) {
        b = heap_pop(h);
        if (passes >= LB_EXTENT_MAX_BOXES / 6) { /* this face's share: sound, not tight */
            *flags |= LB_EXTENT_COARSE;
            *answer = b.key;
            return 0;
        }
        double bc[3], br[3], size = 0.0;
        lb__box_centre(b.lo, b.hi, bc, br);
        for (int d = 0; d < 3; ++d) size = fmax(size, b.hi[d] - b.lo[d]);
        lb__bounds_pass(ev, bc, br, R, NULL);
        ++passes;
        const lb__iv v = R[ev->out];
        if (soft ? v.hi < 0.5 : v.lo > 0.0) continue; /* outside (NaN: not proven) */
        if ((soft ? v.lo > 0.5 : v.hi < 0.0) || size <= tol) {
            *answer = b.key;
            return 0;
        }
        for (int c = 0; c < 8; ++c) {
            box k;
            for (int d = 0; d < 3; ++d) {
                const int upper = (c >> d) & 1;
                k.lo[d] = upper ? bc[d] : b.lo[d];
                k.hi[d] = upper ? b.hi[d] : bc[d];
            }
            k.key = reach(&k, face);
            if (heap_push(h, &k)) return -1;
        }
    }
    return 1;
}

lb_status lb_evaluator_extent(const lb_evaluator *ev, const double smin[3], const double smax[3],
                              double tol, double out_min[3], double out_max[3], int *flags,
                              lb_error *err) {
    static const char fn[] = "lb_evaluator_extent";
    if (!ev || !smin || !smax || !out_min || !out_max || !flags)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: every pointer must be non-NULL", fn);
    for (int d = 0; d < 3; ++d) {
        if (!(fabs(smin[d]) <= LB_SCENE_MAX_COORD) || !(fabs(smax[d]) <= LB_SCENE_MAX_COORD) ||
            !(smin[d] < smax[d]))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: search box %c range [%g, %g]; allowed: min < max, finite, "
                            "|coordinate| <= %g",
                            fn, "xyz"[d], smin[d], smax[d], LB_SCENE_MAX_COORD);
    }
    double longest = 0.0;
    for (int d = 0; d < 3; ++d) longest = fmax(longest, smax[d] - smin[d]);
    if (!(tol > 0.0) || !(tol >= longest * 1e-12))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: tol = %g; allowed: > 0 and at least 1e-12 of the search box's "
                        "longest side (%g)",
                        fn, tol, longest);
    heap h = {NULL, 0, 0};
    lb__iv *R = malloc(lb__ivs_len(ev) * sizeof *R);
    if (!R) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
    int f = 0, rc = 0;
    box search;
    memcpy(search.lo, smin, sizeof search.lo);
    memcpy(search.hi, smax, sizeof search.hi);
    double far[6]; /* each face's answer; until searched, the search box's own */
    for (int face = 0; face < 6; ++face) far[face] = reach(&search, face);
    for (int face = 0; face < 6 && !rc; ++face) {
        const double edge = far[face];
        rc = face_search(ev, R, &h, &search, tol, face, &far[face], &f);
        /* it reaches the search box: unbounded for the caller's purpose; the
         * faces not searched yet keep the search box's (sound) */
        if (!rc && far[face] >= edge) break;
    }
    free(h.a);
    free(R);
    if (rc < 0) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
    if (rc > 0) {
        f |= LB_EXTENT_EMPTY;
        memcpy(out_min, smin, 3 * sizeof *out_min);
        memcpy(out_max, smin, 3 * sizeof *out_max);
    } else {
        for (int d = 0; d < 3; ++d) {
            out_min[d] = -far[2 * d];
            out_max[d] = far[2 * d + 1];
            if (out_min[d] <= smin[d] || out_max[d] >= smax[d]) f |= LB_EXTENT_TOUCHES;
        }
    }
    *flags = f;
    return LB_OK;
}
