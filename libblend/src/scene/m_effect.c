/* Where a subsequent-blend parameter m can change nothing.
 *
 * A blend's m never moves its own surface: away from its blending region it
 * divides the blend's values by m, and only an operator above it that uses
 * values (a blend, a level, a local union) turns that into a different
 * surface (docs/operators.md, section 4). Operators whose surface depends
 * only on where their arguments are inside (the registry's
 * LB__R_ZERO_SETS_ONLY rows: min, max, complement, transforms,
 * R-functions, clean unions) pass the values up unchanged in this respect,
 * so the question is whether some path from the root reaches the node
 * through a value-using operator. Shared defs are reached along several
 * paths: one such path is enough. Each node is visited at most twice (once
 * per answer), so the cost is linear in the scene's edges. */
#include "scene_internal.h"

#include <stdlib.h>
#include <string.h>

static int cmp_ptr(const void *a, const void *b) {
    const uintptr_t x = (uintptr_t) * (const lb__node *const *)a;
    const uintptr_t y = (uintptr_t) * (const lb__node *const *)b;
    return x < y ? -1 : x > y;
}

static size_t index_of(const lb__node **sorted, size_t n, const lb__node *v) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if ((uintptr_t)sorted[mid] < (uintptr_t)v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static int sets_m(const lb__node *n) {
    if (!n->o.m) return 0;
    for (size_t i = 0; i < n->o.k; ++i)
        if (n->o.m[i] != 1.0) return 1;
    return 0;
}

/* one DFS entry: a node and whether a value-using operator is above it */
typedef struct {
    const lb__node *n;
    int used;
} visit;

size_t lb_scene_unused_m(const lb_scene *s, const char **paths, size_t max) {
    if (!s || !s->root || !s->nnodes) return 0;
    const size_t n = s->nnodes;
    const lb__node **sorted = malloc(n * sizeof *sorted);
    unsigned char *seen = calloc(n, 1); /* bit 0: reached unused, bit 1: reached used */
    size_t cap = 64, top = 0, count = 0;
    visit *stack = malloc(cap * sizeof *stack);
    if (!sorted || !seen || !stack) goto out;
    memcpy(sorted, s->nodes, n * sizeof *sorted);
    qsort(sorted, n, sizeof *sorted, cmp_ptr);
    stack[top++] = (visit){s->root, 0};
    while (top) {
        const visit v = stack[--top];
        const size_t i = index_of(sorted, n, v.n);
        const unsigned char bit = v.used ? 2u : 1u;
        if (i >= n || sorted[i] != v.n || (seen[i] & bit)) continue;
        seen[i] |= bit;
        const lb__family_row *row = lb__family_info(v.n->o.family);
        const int used_below =
            v.used || (v.n->o.family != LB__F_PRIMITIVE && !(row->flags & LB__R_ZERO_SETS_ONLY));
        for (size_t a = 0; a < v.n->o.k && v.n->args; ++a) {
            if (top == cap) {
                visit *g = realloc(stack, 2 * cap * sizeof *stack);
                if (!g) goto out;
                stack = g;
                cap *= 2;
            }
            stack[top++] = (visit){v.n->args[a], used_below};
        }
    }
    /* scene order, so the list is the same every run */
    for (size_t j = 0; j < n; ++j) {
        const lb__node *v = s->nodes[j];
        const size_t i = index_of(sorted, n, v);
        if (seen[i] == 1u && sets_m(v)) {
            if (paths && count < max) paths[count] = v->o.path;
            ++count;
        }
    }
out:
    free(stack);
    free(seen);
    free(sorted);
    return count;
}
