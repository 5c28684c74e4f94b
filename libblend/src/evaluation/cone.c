/* A child's cone reduced over a box, for the local unions' compile-time
 * evaluation (local_curves.c).
 *
 * A local_union of k children folds left, so the left child of the i-th
 * fold is a chain of i - 1 binary local unions: run as it stands, every
 * point of fold i costs i instructions and a flat union of k children costs
 * k^2 per point. Over a small box many links of the chain leave one
 * argument as it is: no blending volume of theirs reaches the box, and the
 * clean union is max there (its weight is 0: one argument at most 0 in
 * soft form; or one argument is inside, >= C, and the other outside) with
 * the same argument above the other over the whole box, so the link
 * returns that argument (the soft form in, the scene's form out: the same
 * value up to rounding of the linear change of form). Such a link is
 * dropped and its readers read its argument.
 *
 * Two arguments far from the box and from each other can each be on top
 * somewhere in it, so that test alone keeps every link whose two intervals
 * overlap. But where the weight is 0 the links of a chain are one max (of
 * soft forms, whatever each link's zero_scale): a max group, the links whose
 * one reader is a max link of the same chain. An argument below the group's
 * value over the whole box (the interval of the group's top link) is never
 * the maximum there, so the link that takes it passes its other argument.
 * Only the top link's value must be exact, and it is: every dropped leaf is
 * strictly below a kept one at every point. What remains is copied into a
 * sub-tape with its own registers, run by the ordinary runners.
 *
 * Invariant: at every point of the box the sub-tape's value equals the
 * cone's up to that rounding, so the curves found with it are the curves
 * of the full cone. */
#include "tape.h"

#include <stdlib.h>
#include <string.h>

void lb__cone_free(lb__cone *S) {
    free(S->ins);
    free(S->src);
    free(S->ivq);
    free(S->srcq);
    free(S->alias);
    free(S->need);
    free(S->reg);
    free(S->prod);
    free(S->last);
    free(S->grp);
    free(S->freel);
    free(S->R);
    memset(S, 0, sizeof *S);
}

/* source registers of an instruction: its arguments, then (bounded) their
 * bounding solids */
static size_t nsrc_of(const lb__instr *in) {
    if (in->code != LB__I_OP) return 0;
    return (lb__op_flags(in->op) & LB__R_BOUNDING) ? 2 * in->op->k : in->op->k;
}

/* the soft-form interval of a child interval f (zero: g = C (1 - f / s)) */
static lb__iv soft_iv(const lb__instr *in, lb_convention conv, lb__iv f) {
    double fl[2] = {f.lo, f.hi}, g[2];
    lb__local_in(in->op, conv, fl, g);
    lb__iv o = {g[0] < g[1] ? g[0] : g[1], g[0] < g[1] ? g[1] : g[0]};
    return o;
}

/* the soft forms (g) of a binary local or clean union's argument intervals
 * fa, fb, when the link is the clean union alone over the box (alpha 0, no
 * blending volume of its own reaching the box) and both are finite */
static int plain_link(const lb_evaluator *ev, const lb__instr *in, lb__iv fa, lb__iv fb,
                      const double bc[3], const double br[3], lb__iv g[2]) {
    if (in->code != LB__I_OP || (!(lb__op_flags(in->op) & LB__R_CLEAN_UNION))) return 0;
    if (in->op->lp.alpha[0] != 0.0 || in->op->lp.alpha[1] != 0.0) return 0;
    if ((lb__op_flags(in->op) & LB__R_CURVES) && lb__local_reaches(in->curves, bc, br)) return 0;
    g[0] = soft_iv(in, ev->conv, fa);
    g[1] = soft_iv(in, ev->conv, fb);
    for (int a = 0; a < 2; ++a)
        if (!(g[a].lo >= -LB_MAX_ABS_ARG && g[a].hi <= LB_MAX_ABS_ARG)) return 0;
    return 1;
}

/* what step 2 learns of a link (need[] meanwhile): plain_link holds, and
 * max_link too */
enum { LINK_PLAIN = 1, LINK_MAX = 2 };

/* which argument a plain link (its arguments' soft forms g) passes through
 * over the box, or -1 (see the head of the file) */
static int passes(const lb_evaluator *ev, const lb__iv g[2]) {
    for (int a = 0; a < 2; ++a) {
        const lb__iv me = g[a], other = g[1 - a];
        /* the clean union is max = me where the weight is 0 (either
         * argument at most LB_SOFT_MIN_FIELD), or where me is inside (>= C)
         * and the other outside (< C): there it is the union itself */
        const int zero_weight = me.hi <= LB_SOFT_MIN_FIELD || other.hi <= LB_SOFT_MIN_FIELD;
        const int inside_one = me.lo >= LB__LOCAL_ISO && other.hi < LB__LOCAL_ISO;
        /* max takes the first argument at ties (value and gradient) */
        const int above = a == 0 ? other.hi <= me.lo : other.hi < me.lo;
        if (above && (zero_weight || inside_one) &&
            (ev->conv == LB_CONVENTION_ZERO || me.lo >= 0.0))
            return a;
    }
    return -1;
}

/* Is a plain link (its arguments' soft forms g) exactly the max of them
 * over the box, and the scene's form of that max again (so a chain of such
 * links is one max, whatever their zero_scale)? The clean union's weight is
 * 0 there, and in the soft convention both arguments are >= 0 (no clamp at
 * 0). */
static int max_link(const lb_evaluator *ev, const lb__iv g[2]) {
    if (!(g[0].hi <= LB_SOFT_MIN_FIELD || g[1].hi <= LB_SOFT_MIN_FIELD)) return 0;
    return ev->conv == LB_CONVENTION_ZERO || (g[0].lo >= 0.0 && g[1].lo >= 0.0);
}

/* Which argument a max link passes through because the other is below the
 * value of its whole max group over the box (root: the interval of the
 * group's top link), or -1. Each argument, a leaf of the group or a part of
 * it, is a max of some of the group's leaves; one that stays below the
 * group's lower bound is never the maximum anywhere in the box, so the
 * group's value is the same without it (and at ties, which only leaves at
 * the maximum can have, the same leaf is first). */
static int under_group(const lb_evaluator *ev, const lb__instr *in, const lb__iv g[2],
                       lb__iv root) {
    const lb__iv top = soft_iv(in, ev->conv, root);
    if (g[1].hi < top.lo) return 0;
    if (g[0].hi < top.lo) return 1;
    return -1;
}

lb_status lb__cone_reduce(const lb_evaluator *ev, const uint32_t *list, size_t n,
                          const double bc[3], const double br[3], lb__cone *S, lb_error *err) {
    const lb__instr *top = n ? &ev->ins[list ? list[n - 1] : n - 1] : NULL;
    const char *path = top && top->op ? top->op->path : "local_union";
    if (lb__grow((void **)&S->ivq, &S->cap_q, n, sizeof *S->ivq) ||
        lb__grow((void **)&S->alias, &S->cap_alias, n, sizeof *S->alias) ||
        lb__grow((void **)&S->need, &S->cap_need, n, sizeof *S->need) ||
        lb__grow((void **)&S->reg, &S->cap_reg, n, sizeof *S->reg) ||
        lb__grow((void **)&S->last, &S->cap_last, n, sizeof *S->last) ||
        lb__grow((void **)&S->grp, &S->cap_grp, n, sizeof *S->grp) ||
        lb__grow((void **)&S->freel, &S->cap_freel, n, sizeof *S->freel) ||
        lb__grow((void **)&S->prod, &S->cap_prod, ev->nregs, sizeof *S->prod) ||
        lb__grow((void **)&S->R, &S->cap_R, lb__ivs_len(ev), sizeof *S->R))
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", path);
    /* the instructions' sources as positions in the list (2 per argument:
     * arguments, then bounding solids) */
    size_t nsrc = 0;
    for (size_t q = 0; q < n; ++q) {
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        nsrc += nsrc_of(in);
        /* bulge elimination re-runs its cone by the evaluator's indices: no reduction */
        if (in->code == LB__I_OP && in->cone && !(lb__op_flags(in->op) & LB__R_CURVES)) {
            S->reduced = 0;
            return LB_OK;
        }
    }
    if (lb__grow((void **)&S->srcq, &S->cap_srcq, nsrc, sizeof *S->srcq))
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", path);
    /* 1. the interval pass, instruction by instruction, recording each
     * instruction's interval and which instruction each source is */
    size_t so = 0;
    for (size_t q = 0; q < n; ++q) {
        const uint32_t i = list ? list[q] : (uint32_t)q;
        const lb__instr *in = &ev->ins[i];
        const size_t ns = nsrc_of(in);
        for (size_t a = 0; a < ns; ++a) S->srcq[so + a] = S->prod[in->src[a]];
        lb__bounds_pass_list(ev, &i, 1, bc, br, S->R);
        S->ivq[q] = S->R[in->dst];
        S->prod[in->dst] = (uint32_t)q;
        S->last[q] = (uint32_t)so; /* the sources' offset, for the steps below */
        so += ns;
    }
    /* 2. max groups: a max link whose one reader is a max link belongs to
     * its reader's group; grp[q] is the group's top link (backwards, so a
     * reader is placed before its sources). need[] holds LINK_* and reg[]
     * the readers' count meanwhile. */
    for (size_t q = 0; q < n; ++q) S->reg[q] = 0;
    for (size_t q = 0; q < n; ++q) {
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        const size_t ns = nsrc_of(in);
        for (size_t a = 0; a < ns; ++a) ++S->reg[S->srcq[S->last[q] + a]];
        lb__iv g[2];
        S->need[q] = 0;
        if (ns == 2 && plain_link(ev, in, S->ivq[S->srcq[S->last[q]]],
                                  S->ivq[S->srcq[S->last[q] + 1]], bc, br, g))
            S->need[q] = LINK_PLAIN | (max_link(ev, g) ? LINK_MAX : 0);
        S->grp[q] = UINT32_MAX;
    }
    for (size_t q = n; q-- > 0;) {
        if (!(S->need[q] & LINK_MAX)) continue;
        if (S->grp[q] == UINT32_MAX) S->grp[q] = (uint32_t)q;
        for (size_t a = 0; a < 2; ++a) {
            const uint32_t p = S->srcq[S->last[q] + a];
            if ((S->need[p] & LINK_MAX) && S->reg[p] == 1) S->grp[p] = S->grp[q];
        }
    }
    /* 3. pass-through: alias[q] is the list position whose value q takes */
    for (size_t q = 0; q < n; ++q) {
        S->alias[q] = (uint32_t)q;
        if (!(S->need[q] & LINK_PLAIN)) continue;
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        const uint32_t off = S->last[q];
        const lb__iv g[2] = {soft_iv(in, ev->conv, S->ivq[S->srcq[off]]),
                             soft_iv(in, ev->conv, S->ivq[S->srcq[off + 1]])};
        int a = passes(ev, g);
        if (a < 0 && (S->need[q] & LINK_MAX)) a = under_group(ev, in, g, S->ivq[S->grp[q]]);
        if (a >= 0) S->alias[q] = S->alias[S->srcq[off + a]];
    }
    if (n) S->root = S->ivq[n - 1];
    /* 4. what the root needs, backwards */
    memset(S->need, 0, n);
    if (n) S->need[S->alias[n - 1]] = 1;
    for (size_t q = n; q-- > 0;) {
        if (!S->need[q]) continue;
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        const size_t ns = nsrc_of(in);
        for (size_t a = 0; a < ns; ++a) S->need[S->alias[S->srcq[S->last[q] + a]]] = 1;
    }
    /* 5. copy what is needed; registers by last use (reg[q] = last reader
     * first, then the register). Not when more than three quarters of the
     * instructions are kept: the copy would cost more than it saves (the
     * caller runs the source; the pass's interval stands) */
    size_t m = 0, msrc = 0;
    for (size_t q = 0; q < n; ++q) m += S->need[q];
    S->reduced = 1;
    S->copied = 4 * m < 3 * n;
    if (!S->copied) return LB_OK;
    m = 0;
    for (size_t q = 0; q < n; ++q) S->reg[q] = UINT32_MAX; /* last reader, as a position */
    for (size_t q = 0; q < n; ++q) {
        if (!S->need[q]) continue;
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        const size_t ns = nsrc_of(in);
        for (size_t a = 0; a < ns; ++a) S->reg[S->alias[S->srcq[S->last[q] + a]]] = (uint32_t)q;
        ++m;
        msrc += ns;
    }
    if (lb__grow((void **)&S->ins, &S->cap_ins, m, sizeof *S->ins) ||
        lb__grow((void **)&S->src, &S->cap_src, msrc, sizeof *S->src))
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", path);
    uint32_t nfree = 0, nregs = 0, *freel = S->freel; /* free registers, a stack */
    /* the register of each needed position, kept in last[] (the offsets
     * are read before being replaced: a position's own entry is written
     * when it runs, after its sources were read) */
    size_t k = 0, ko = 0;
    double weight = 0.0;
    for (size_t q = 0; q < n; ++q) {
        if (!S->need[q]) continue;
        const lb__instr *in = &ev->ins[list ? list[q] : q];
        const size_t ns = nsrc_of(in);
        lb__instr *c = &S->ins[k];
        *c = *in;
        c->src = ns ? S->src + ko : NULL;
        const uint32_t off = S->last[q];
        for (size_t a = 0; a < ns; ++a) c->src[a] = S->last[S->alias[S->srcq[off + a]]];
        /* the output first (a reader never writes into one of its sources),
         * then the sources read for the last time are free (once each) */
        c->dst = nfree ? freel[--nfree] : nregs++;
        S->last[q] = c->dst;
        for (size_t a = 0; a < ns; ++a) {
            const uint32_t p = S->alias[S->srcq[off + a]];
            if (S->reg[p] == (uint32_t)q) {
                S->reg[p] = UINT32_MAX - 1; /* freed */
                freel[nfree++] = c->src[a];
            }
        }
        weight += in->code == LB__I_OP && (lb__op_flags(in->op) & LB__R_CURVES)
                      ? LB_LOCAL_RUN_WEIGHT
                      : 1.0;
        ko += ns;
        ++k;
    }
    S->ev = *ev;
    S->ev.ins = S->ins;
    S->ev.n = m;
    S->ev.nregs = nregs ? nregs : 1;
    S->ev.cullable = 0;
    S->out = n ? S->last[S->alias[n - 1]] : 0;
    S->ev.out = S->out;
    S->weight = weight;
    return LB_OK;
}
