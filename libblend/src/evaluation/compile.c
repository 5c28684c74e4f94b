/* Scene DAG -> instruction tape (see tape.h). */
#include "tape.h"

#include <stdlib.h>
#include <string.h>

/* A def compiled at a transform: the slot of an open-addressing table
 * (node NULL: empty); the transform is keys[key], stored once per entry
 * rather than once per slot. */
typedef struct memo_entry {
    const lb__node *node;
    uint32_t idx, key;
} memo_entry;

typedef struct cctx {
    lb_evaluator *ev;
    size_t cap;
    uint32_t *mark, *stack; /* cone search: a stamp per instruction, the DFS stack */
    size_t markcap;
    uint32_t stamp;
    size_t costliest; /* the instruction with the largest cost so far */
    memo_entry *memo;
    size_t mcap, mcount;
    lb__affine *keys; /* mcount of them */
    size_t kcap;
    lb_convention conv;
    lb_error *err;
} cctx;

static uint64_t memo_hash(const lb__node *n, const lb__affine *A) {
    uint64_t h = (uint64_t)(uintptr_t)n * 0x9E3779B97F4A7C15ull;
    const unsigned char *b = (const unsigned char *)A;
    for (size_t i = 0; i < sizeof *A; ++i) h = (h ^ b[i]) * 0x100000001B3ull;
    return h;
}

static memo_entry *memo_find(cctx *c, const lb__node *n, const lb__affine *A) {
    size_t i = (size_t)memo_hash(n, A) & (c->mcap - 1);
    while (c->memo[i].node) {
        if (c->memo[i].node == n && memcmp(&c->keys[c->memo[i].key], A, sizeof *A) == 0)
            return &c->memo[i];
        i = (i + 1) & (c->mcap - 1);
    }
    return &c->memo[i];
}

static lb_status memo_grow(cctx *c) {
    if (lb__grow((void **)&c->keys, &c->kcap, c->mcount + 1, sizeof *c->keys))
        return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
    if (2 * (c->mcount + 1) <= c->mcap) return LB_OK;
    const size_t ncap = c->mcap ? 2 * c->mcap : 256;
    memo_entry *old = c->memo;
    const size_t ocap = c->mcap;
    c->memo = calloc(ncap, sizeof *c->memo);
    if (!c->memo) {
        c->memo = old;
        return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
    }
    c->mcap = ncap;
    for (size_t i = 0; i < ocap; ++i)
        if (old[i].node) *memo_find(c, old[i].node, &c->keys[old[i].key]) = old[i];
    free(old);
    return LB_OK;
}

static lb_status push(cctx *c, const lb__node *n, lb__instr **out) {
    lb_evaluator *ev = c->ev;
    if (ev->n >= LB_SCENE_MAX_INSTRUCTIONS)
        return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the scene expands to more than %d instructions here (shared defs "
                        "under many different transforms each compile once per transform); "
                        "allowed: at most %d (docs/scene-format.md, \"Cost\"): fewer distinct "
                        "transformed copies",
                        n->o.path, LB_SCENE_MAX_INSTRUCTIONS, LB_SCENE_MAX_INSTRUCTIONS);
    if (ev->n == c->cap) {
        const size_t ncap = c->cap ? 2 * c->cap : 64;
        lb__instr *ni = realloc(ev->ins, ncap * sizeof *ni);
        if (!ni) return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
        ev->ins = ni;
        c->cap = ncap;
    }
    *out = &ev->ins[ev->n++];
    memset(*out, 0, sizeof **out);
    return LB_OK;
}

static int cmp_u32(const void *a, const void *b) {
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The scene costs too much per point: name the node that makes it so. */
static lb_status cost_error(cctx *c) {
    const lb_evaluator *ev = c->ev;
    const lb__instr *in = &ev->ins[c->costliest];
    return lb__fail(c->err, LB_ERR_INVALID_ARGUMENT,
                    "%s: the scene costs %.0f instruction runs per point on its %zu-instruction "
                    "tape, %.0f of them for this bulge-eliminated blend (it re-runs its "
                    "arguments' %u instructions twice each); allowed: at most %d times the "
                    "tape size and %d in all (docs/scene-format.md, \"Cost\"): bulge fewer "
                    "blends, or blend fewer or smaller arguments",
                    in->code == LB__I_OP ? in->op->path : "$.root", ev->cost, ev->n, in->cost,
                    in->ncone[0] + in->ncone[1], LB_SCENE_MAX_COST_FACTOR, LB_SCENE_MAX_COST);
}

static double *dup_array(const double *v, size_t k, int *fail) {
    if (!v) return NULL;
    double *o = malloc(k * sizeof *o);
    if (!o) {
        *fail = 1;
        return NULL;
    }
    memcpy(o, v, k * sizeof *o);
    return o;
}

/* Lipschitz factor of rho in its own frame, for the cylinder / capsule /
 * torus interval bounds (eval_bounds.c). */
static double rho_lipschitz(const lb_primitive *P) {
    switch (P->kind) {
    case LB_PRIM_CYLINDER:
    case LB_PRIM_CAPSULE:
        return 1.0 / P->s0;
    case LB_PRIM_TORUS:
        return 1.0 / P->s1;
    default:
        return 0.0; /* other kinds have exact interval formulas */
    }
}

/* Per-node precomputation, once per (node, world -> local map): whatever an
 * operator can decide before seeing a point goes into its instruction here.
 * Today that is the fast kernel and its exponent mode, and whether the tape
 * can cull arguments per box. The map A (and the already compiled argument
 * instructions, c->ev->ins[in->srci[i]]) is what a node that depends on its
 * children's geometry needs: the local blend of the Bernhardt paper computes
 * its children's intersection curves here, stores them in the instruction,
 * and lb_evaluator_free releases them with the instruction. */
static lb_status precompute_op(cctx *c, lb__instr *in, const lb__node *n, const lb__affine *A) {
    (void)A;
    if (!n->o.bulge && n->o.family == LB__F_DISPLACEMENT) {
        in->fast = LB__FAST_DISPLACEMENT;
        in->mode = lb__exponent_mode(n->o.k, n->o.p);
    } else if (!n->o.bulge && n->o.family == LB__F_CONIC) {
        in->fast = LB__FAST_CONIC;
    } else if (!n->o.bulge && n->o.family == LB__F_SCALE) {
        in->fast = LB__FAST_SCALE;
        in->mode = lb__exponent_mode(n->o.k, n->o.p);
    } else if (n->o.family == LB__F_MIN || n->o.family == LB__F_MAX) {
        in->fast = LB__FAST_MINMAX;
    }
    if (n->o.k >= 2 && (in->fast == LB__FAST_DISPLACEMENT || in->fast == LB__FAST_CONIC ||
                        in->fast == LB__FAST_MINMAX))
        c->ev->cullable = 1;
    return LB_OK;
}

/* The instructions that instruction `root` depends on, itself included, in
 * tape order, appended to *list (grown as needed); returns their cost sum.
 * The work is the cone's size, which the cost model already charges. */
static lb_status cone_of(cctx *c, uint32_t root, uint32_t **list, size_t *len, size_t *cap,
                         double *cost) {
    lb_evaluator *ev = c->ev;
    if (c->markcap < ev->n) {
        size_t ncap = c->markcap ? c->markcap : 256;
        while (ncap < ev->n) ncap *= 2;
        uint32_t *m = realloc(c->mark, ncap * sizeof *m);
        if (m) c->mark = m;
        uint32_t *st = m ? realloc(c->stack, ncap * sizeof *st) : NULL;
        if (st) c->stack = st;
        if (!m || !st)
            return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
        memset(c->mark + c->markcap, 0, (ncap - c->markcap) * sizeof *c->mark);
        c->markcap = ncap;
    }
    if (++c->stamp == 0) { /* wrapped: clear the stamps */
        memset(c->mark, 0, c->markcap * sizeof *c->mark);
        c->stamp = 1;
    }
    const size_t start = *len;
    size_t top = 0;
    c->stack[top++] = root;
    c->mark[root] = c->stamp;
    *cost = 0.0;
    while (top) {
        const uint32_t i = c->stack[--top];
        if (*len == *cap) {
            const size_t ncap = *cap ? 2 * *cap : 64;
            uint32_t *nl = realloc(*list, ncap * sizeof *nl);
            if (!nl)
                return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
            *list = nl;
            *cap = ncap;
        }
        (*list)[(*len)++] = i;
        const lb__instr *in = &ev->ins[i];
        *cost += in->cost;
        if (in->code != LB__I_OP) continue;
        for (size_t a = 0; a < in->op->k; ++a)
            for (int b = 0; b < 2; ++b) {
                const uint32_t *from = b ? in->srcb : in->srci;
                if (!from || c->mark[from[a]] == c->stamp) continue;
                c->mark[from[a]] = c->stamp;
                c->stack[top++] = from[a];
            }
    }
    qsort(*list + start, *len - start, sizeof **list, cmp_u32);
    return LB_OK;
}

/* The cost model (scene.h, docs/scene-format.md "Cost"): one run per
 * instruction; a bulge-eliminated blend also re-runs each argument's cone
 * twice (central differences of its gradient). Checked as the tape grows,
 * so compiling a scene that is refused costs no more than the limit. */
static lb_status charge(cctx *c, uint32_t idx) {
    lb_evaluator *ev = c->ev;
    lb__instr *in = &ev->ins[idx];
    in->cost = 1.0;
    const int local = in->code == LB__I_OP && (lb__op_flags(in->op) & LB__R_CURVES);
    if (in->code == LB__I_OP && (in->op->bulge || local)) {
        size_t len = 0, cap = 0;
        uint32_t *list = NULL;
        double w[2] = {0.0, 0.0};
        for (int a = 0; a < 2; ++a) {
            const size_t before = len;
            lb_status s = cone_of(c, in->srci[a], &list, &len, &cap, &w[a]);
            if (s) {
                free(list);
                return s;
            }
            in->ncone[a] = (uint32_t)(len - before);
        }
        in = &ev->ins[idx];
        in->cone = list;
        /* a local blend runs its cones at compile time only */
        if (!local) in->cost += 2.0 * (w[0] + w[1]);
    }
    if (in->cost > ev->ins[c->costliest].cost) c->costliest = idx;
    ev->cost += in->cost;
    return ev->cost > LB_SCENE_MAX_COST ? cost_error(c) : LB_OK;
}

static lb_status compile_node(cctx *c, const lb__node *n, const lb__affine *Ap, uint32_t *out) {
    lb__affine A = *Ap;
    if (n->has_transform) lb__affine_compose(n->to_local, Ap, &A);
    if (n->o.family == LB__F_GROUP) return compile_node(c, n->args[0], &A, out);
    lb_status s;
    /* Only a def's node has more than one parent (every other node is
     * reached through its one parent, once per distinct transform of the
     * nearest def above it): only defs are looked up and remembered, so the
     * table stays small beside a tape of many primitives. */
    const int shared = n->def_name != NULL;
    memo_entry *e = NULL;
    if (shared && ((s = memo_grow(c)) || (e = memo_find(c, n, &A), e->node))) {
        if (!s) *out = e->idx;
        return s;
    }
    uint32_t *src = NULL, *srci = NULL, *srcb = NULL;
    if (n->o.family != LB__F_PRIMITIVE) {
        const size_t ns = n->o.k * (n->bounds ? 2 : 1);
        src = malloc(ns * sizeof *src);
        srci = malloc(n->o.k * sizeof *srci);
        srcb = n->bounds ? malloc(n->o.k * sizeof *srcb) : NULL;
        if (!src || !srci || (n->bounds && !srcb)) {
            free(src);
            free(srci);
            free(srcb);
            return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
        }
        for (size_t i = 0; i < n->o.k && !s; ++i) {
            s = compile_node(c, n->args[i], &A, &srci[i]);
            src[i] = srci[i];
            if (!s && n->bounds) {
                s = compile_node(c, n->bounds[i], &A, &srcb[i]);
                src[n->o.k + i] = srcb[i];
            }
        }
        if (s) {
            free(src);
            free(srci);
            free(srcb);
            return s;
        }
    }
    lb__instr *in = NULL;
    if ((s = push(c, n, &in))) {
        free(src);
        free(srci);
        free(srcb);
        return s;
    }
    const uint32_t idx = (uint32_t)(c->ev->n - 1);
    if (n->o.family == LB__F_PRIMITIVE) {
        in->prim = n->prim;
        in->A = A;
        in->lip = rho_lipschitz(&n->prim);
        static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        const int linear_id = memcmp(A.M, id, sizeof id) == 0;
        in->identity = linear_id && A.t[0] == 0.0 && A.t[1] == 0.0 && A.t[2] == 0.0;
        in->code = LB__I_PRIM;
        if (linear_id && n->prim.kind == LB_PRIM_ELLIPSOID && n->prim.kernel == LB_KERNEL_NONE) {
            /* local = X + t, so rho(local - c) = rho(X - (c - t)) */
            for (int i = 0; i < 3; ++i) in->prim.c[i] -= A.t[i];
            lb__affine_identity(&in->A);
            in->identity = 1;
            in->code = LB__I_ELLIPSOID;
            for (int i = 0; i < 3; ++i) in->ia[i] = 1.0 / in->prim.a[i];
        }
    } else {
        int fail = 0;
        in->code = LB__I_OP;
        in->A = A; /* world -> this node's frame (the POV-Ray export of local blends) */
        in->node = n;
        /* operators carry their own copy of the operator (a primitive's
         * instruction stays small: large scenes are mostly primitives) */
        in->op = malloc(sizeof *in->op);
        if (!in->op)
            return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
        *in->op = n->o;
        in->op->r = dup_array(n->o.r, n->o.k, &fail);
        in->op->p = dup_array(n->o.p, n->o.k, &fail);
        in->op->m = dup_array(n->o.m, n->o.k, &fail);
        in->op->path = malloc(strlen(n->o.path) + 1);
        if (in->op->path)
            strcpy(in->op->path, n->o.path);
        else
            fail = 1;
        in->src = src;
        in->srci = srci;
        in->srcb = srcb;
        if (fail) return lb__fail(c->err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
        if ((s = precompute_op(c, in, n, &A))) return s;
    }
    if ((s = charge(c, idx))) return s;
    if (shared) {
        if ((s = memo_grow(c))) return s; /* room for this entry after the recursion's */
        e = memo_find(c, n, &A);
        c->keys[c->mcount] = A;
        e->node = n;
        e->idx = idx;
        e->key = (uint32_t)c->mcount++;
    }
    *out = idx;
    return LB_OK;
}

/* Registers by last use: an instruction's output register is released after
 * its last reader; a reader never writes into one of its own sources. */
static lb_status allocate_registers(lb_evaluator *ev, uint32_t root, lb_error *err) {
    const size_t n = ev->n;
    uint32_t *last = malloc(n * sizeof *last);
    uint32_t *freelist = malloc(n * sizeof *freelist);
    if (!last || !freelist) {
        free(last);
        free(freelist);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
    }
    for (size_t i = 0; i < n; ++i) last[i] = (uint32_t)i;
    last[root] = UINT32_MAX; /* the result lives to the end */
    for (size_t i = 0; i < n; ++i) {
        const lb__instr *in = &ev->ins[i];
        if (in->code != LB__I_OP) continue;
        const size_t ns = in->op->k * (lb__op_flags(in->op) & LB__R_BOUNDING ? 2 : 1);
        for (size_t j = 0; j < ns; ++j)
            if (last[in->src[j]] != UINT32_MAX) last[in->src[j]] = (uint32_t)i;
    }
    size_t nfree = 0, nregs = 0;
    uint32_t *reg_of = malloc(n * sizeof *reg_of);
    if (!reg_of) {
        free(last);
        free(freelist);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
    }
    for (size_t i = 0; i < n; ++i) {
        lb__instr *in = &ev->ins[i];
        reg_of[i] = nfree ? freelist[--nfree] : (uint32_t)nregs++;
        in->dst = reg_of[i];
        in->aoff = ev->total_k;
        if (in->code == LB__I_OP) ev->total_k += in->op->k;
        if (in->code == LB__I_OP && in->op->k > ev->kmax) ev->kmax = in->op->k;
        if (in->code == LB__I_OP) {
            const size_t ns = in->op->k * (lb__op_flags(in->op) & LB__R_BOUNDING ? 2 : 1);
            for (size_t j = 0; j < ns; ++j) {
                const uint32_t a = in->src[j];
                /* an argument used twice (a def as two arguments of one
                 * operator) is released once: src[q] < j already holds
                 * registers, so compare registers, not instruction indices
                 * (comparing a register with an index released it twice,
                 * and two live values then shared one register) */
                int dup = 0;
                for (size_t q = 0; q < j; ++q) dup |= in->src[q] == reg_of[a];
                if (!dup && last[a] == i) freelist[nfree++] = reg_of[a];
                in->src[j] = reg_of[a];
            }
        }
    }
    ev->nregs = nregs;
    ev->out = reg_of[root];
    free(last);
    free(freelist);
    free(reg_of);
    return LB_OK;
}

void lb_evaluator_free(lb_evaluator *ev) {
    if (!ev) return;
    for (size_t i = 0; i < ev->n; ++i) {
        lb__instr *in = &ev->ins[i];
        if (in->code != LB__I_OP) continue;
        free(in->src);
        free(in->srci);
        free(in->srcb);
        free(in->cone);
        lb__curves_free(in->curves);
        if (!in->op) continue;
        free(in->op->r);
        free(in->op->p);
        free(in->op->m);
        free(in->op->path);
        free(in->op);
    }
    free(ev->ins);
    free(ev);
}

size_t lb_evaluator_size(const lb_evaluator *ev) {
    return ev ? ev->n : 0;
}

lb_status lb_evaluator_create(const lb_scene *scene, lb_evaluator **out, lb_error *err) {
    return lb_evaluator_create_reusing(scene, NULL, out, NULL, err);
}

lb_status lb_evaluator_create_reusing(const lb_scene *scene, const lb_evaluator *previous,
                                      lb_evaluator **out, size_t *reused, lb_error *err) {
    if (reused) *reused = 0;
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_evaluator_create: out is NULL");
    *out = NULL;
    if (!scene || !scene->root)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "lb_evaluator_create: scene is NULL");
    lb_evaluator *ev = calloc(1, sizeof *ev);
    if (!ev) return lb__fail(err, LB_ERR_NO_MEMORY, "lb_evaluator_create: out of memory");
    ev->conv = scene->convention;
    cctx c;
    memset(&c, 0, sizeof c);
    c.ev = ev;
    c.conv = scene->convention;
    c.err = err;
    lb__affine id;
    lb__affine_identity(&id);
    uint32_t root = 0;
    lb_status s = compile_node(&c, scene->root, &id, &root);
    if (!s && ev->cost > (double)LB_SCENE_MAX_COST_FACTOR * (double)ev->n) s = cost_error(&c);
    free(c.memo);
    free(c.keys);
    free(c.mark);
    free(c.stack);
    if (!s) s = allocate_registers(ev, root, err);
    if (!s) s = lb__local_prepare(ev, scene, previous, reused, err);
    if (s) {
        lb_evaluator_free(ev);
        return s;
    }
    *out = ev;
    return LB_OK;
}

lb_convention lb_evaluator_convention(const lb_evaluator *ev) {
    return ev ? ev->conv : LB_CONVENTION_ZERO;
}

double lb_evaluator_cost(const lb_evaluator *ev) {
    return ev ? ev->cost : 0.0;
}

double lb_evaluator_compile_cost(const lb_evaluator *ev) {
    return ev ? ev->compile_cost : 0.0;
}
