/* Values and gradients of point batches on the compiled tape (tape.h).
 * Each chunk of LB__CHUNK points runs the whole tape; threads take blocks of
 * chunks from a shared counter, so the result never depends on the thread
 * count. */
#include "tape.h"
#include "../primitives/rho.h"
#include "../operators/bt_two.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "../common/platform.h"

/* ---- primitives ---- */

/* The coordinates and the four output columns never overlap (points and
 * registers are separate arrays): restrict lets the loop be vectorised
 * without a run-time check per pair. */
LB_VECTOR_CLONES static void run_ellipsoid(const lb__instr *in, size_t n, const double *restrict x,
                                           const double *restrict y, const double *restrict z,
                                           double *restrict v, double *restrict gx,
                                           double *restrict gy, double *restrict gz) {
    const double c0 = in->prim.c[0], c1 = in->prim.c[1], c2 = in->prim.c[2];
    /* reciprocals once per chunk: one division per point (1/f), and a
     * branch-free body the compiler vectorises */
    const double i0 = 1.0 / in->prim.a[0], i1 = 1.0 / in->prim.a[1], i2 = 1.0 / in->prim.a[2];
    for (size_t j = 0; j < n; ++j) {
        const double u0 = (x[j] - c0) * i0, u1 = (y[j] - c1) * i1, u2 = (z[j] - c2) * i2;
        const double f = sqrt(u0 * u0 + u1 * u1 + u2 * u2);
        /* at the centre u = 0, so any finite 1/f gives the gradient 0 there;
         * f + (f == 0) is f elsewhere, bit for bit, and a quiet comparison
         * added in keeps the loop branch-free (GCC vectorises it; a select
         * on f > 0, a signalling comparison, it does not) */
        const double inv = 1.0 / (f + (double)(f == 0.0));
        v[j] = f - 1.0;
        gx[j] = u0 * i0 * inv;
        gy[j] = u1 * i1 * inv;
        gz[j] = u2 * i2 * inv;
    }
}

#if defined(__GNUC__)
#define LB__INLINE static inline __attribute__((always_inline))
#else
#define LB__INLINE static inline
#endif

/* One primitive kind over a chunk: the affine map, rho and the kernel
 * inline, so each kind gets its own specialised loop. */
LB__INLINE void prim_loop(lb_primitive_kind kind, const lb__instr *in, size_t n, const double *x,
                          const double *y, const double *z, double *v, double *gx, double *gy,
                          double *gz) {
    const lb_primitive *P = &in->prim;
    const double *M = in->A.M, *t = in->A.t;
    const int ident = in->identity, zero = P->kernel == LB_KERNEL_NONE;
    for (size_t j = 0; j < n; ++j) {
        double L[3], gl[3], df = 1.0;
        if (ident) {
            L[0] = x[j];
            L[1] = y[j];
            L[2] = z[j];
        } else {
            for (int i = 0; i < 3; ++i)
                L[i] = M[3 * i] * x[j] + M[3 * i + 1] * y[j] + M[3 * i + 2] * z[j] + t[i];
        }
        const double rho = lb__rho(kind, P, L, gl);
        v[j] = zero ? rho - 1.0 : lb__kernel(P->kernel, rho, &df);
        if (ident) {
            gx[j] = df * gl[0];
            gy[j] = df * gl[1];
            gz[j] = df * gl[2];
        } else {
            gx[j] = df * (M[0] * gl[0] + M[3] * gl[1] + M[6] * gl[2]);
            gy[j] = df * (M[1] * gl[0] + M[4] * gl[1] + M[7] * gl[2]);
            gz[j] = df * (M[2] * gl[0] + M[5] * gl[1] + M[8] * gl[2]);
        }
    }
}

/* Zero-convention slab or half-space: |n . (M X + t - c)| / w - 1 is one
 * affine function of X, a . X + b, so the map and 1/w fold into a and b once
 * per chunk and the loop is branch-free (the compiler vectorises it). */
LB_VECTOR_CLONES static void run_plane(const lb__instr *in, size_t n, const double *restrict x,
                                       const double *restrict y, const double *restrict z,
                                       double *restrict v, double *restrict gx, double *restrict gy,
                                       double *restrict gz) {
    const lb_primitive *P = &in->prim;
    const double iw = 1.0 / P->s0, *M = in->A.M, *t = in->A.t;
    double a[3], b = 0.0;
    for (int j = 0; j < 3; ++j)
        a[j] = in->identity ? P->n[j] * iw
                            : (P->n[0] * M[j] + P->n[1] * M[3 + j] + P->n[2] * M[6 + j]) * iw;
    for (int i = 0; i < 3; ++i) b += P->n[i] * ((in->identity ? 0.0 : t[i]) - P->c[i]) * iw;
    const double a0 = a[0], a1 = a[1], a2 = a[2];
    /* one loop per kind, the sign as arithmetic on the comparison: GCC
     * vectorises these, not a select (d < 0 ? neg : 1) */
    if (P->kind == LB_PRIM_SLAB) {
        for (size_t j = 0; j < n; ++j) {
            const double d = a0 * x[j] + a1 * y[j] + a2 * z[j] + b;
            const double sg = 1.0 - 2.0 * (double)(d < 0.0); /* -1 below, 1 above */
            v[j] = sg * d - 1.0;
            gx[j] = sg * a0;
            gy[j] = sg * a1;
            gz[j] = sg * a2;
        }
    } else {
        for (size_t j = 0; j < n; ++j) {
            const double d = a0 * x[j] + a1 * y[j] + a2 * z[j] + b;
            /* 1 above, 0 below (the field is -1 there) from the sign bit: GCC
             * vectorises this, not 1 - (d < 0) (at d = -0 the value is the
             * same -1, the gradient that of the flat side) */
            const double sg = 0.5 + 0.5 * copysign(1.0, d);
            v[j] = sg * d - 1.0;
            gx[j] = sg * a0;
            gy[j] = sg * a1;
            gz[j] = sg * a2;
        }
    }
}

static void run_prim(const lb__instr *in, size_t n, const double *x, const double *y,
                     const double *z, double *v, double *gx, double *gy, double *gz) {
    if ((in->prim.kind == LB_PRIM_SLAB || in->prim.kind == LB_PRIM_HALFSPACE) &&
        in->prim.kernel == LB_KERNEL_NONE) {
        run_plane(in, n, x, y, z, v, gx, gy, gz);
        return;
    }
    switch (in->prim.kind) {
    case LB_PRIM_ELLIPSOID:
        prim_loop(LB_PRIM_ELLIPSOID, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_LP:
        prim_loop(LB_PRIM_LP, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_SUPERQUADRIC:
        prim_loop(LB_PRIM_SUPERQUADRIC, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_SLAB:
        prim_loop(LB_PRIM_SLAB, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_HALFSPACE:
        prim_loop(LB_PRIM_HALFSPACE, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_CYLINDER:
        prim_loop(LB_PRIM_CYLINDER, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_CAPSULE:
        prim_loop(LB_PRIM_CAPSULE, in, n, x, y, z, v, gx, gy, gz);
        break;
    case LB_PRIM_TORUS:
        prim_loop(LB_PRIM_TORUS, in, n, x, y, z, v, gx, gy, gz);
        break;
    }
}

/* ---- operators ---- */

/* The fast kernels: the same arithmetic as the public functions, without
 * re-validating parameters the compiler already checked. x, r, p, m hold the
 * k active arguments (all of them unless a plan culled some); ws is 6k
 * doubles of scratch. */
static double fast_op(const lb__instr *in, size_t k, const uint16_t *act, const double *x,
                      const double *r, const double *p, const double *m, const double *ir,
                      const double *im, double *dx, double *ws) {
    const lb__op *n = in->op;
    double *xt = ws, *sg = ws + k;
    ws += 2 * k;
    switch (in->fast) {
    case LB__FAST_MINMAX: {
        size_t j = 0;
        const int mn = n->family == LB__F_MIN;
        for (size_t i = 1; i < k; ++i)
            if (mn ? x[i] < x[j] : x[i] > x[j]) j = i;
        for (size_t i = 0; i < k; ++i) dx[i] = i == j;
        return x[j];
    }
    case LB__FAST_DISPLACEMENT:
    case LB__FAST_CONIC: {
        const int disp = in->fast == LB__FAST_DISPLACEMENT;
        const double *u = x;
        if (n->op != LB_UNION) {
            /* the duals by original argument index (culling may have removed
             * argument 0 of a difference) */
            for (size_t i = 0; i < k; ++i) {
                sg[i] = n->op == LB_INTERSECTION || act[i] == 0 ? -1.0 : 1.0;
                xt[i] = sg[i] * x[i];
            }
            u = xt;
        }
        double h;
        if (k == 1) { /* BT_1 = u / m: one active argument (the others culled) */
            h = u[0] / m[0];
            dx[0] = 1.0 / m[0];
        } else if (disp && ir)
            h = lb__bt_two_union_recip(k, u, r, m, ir, im, dx, ws);
        else if (disp)
            h = lb__bt_union_ws(k, u, r, p, m, in->mode, dx, NULL, NULL, ws);
        else
            h = lb__conic_union(u, r, n->shape, m, dx, NULL, NULL);
        if (n->op == LB_UNION) return h;
        for (size_t i = 0; i < k; ++i) dx[i] *= -sg[i];
        return -h;
    }
    case LB__FAST_SCALE:
        return lb__scale_setop(n->op, k, x, r, p, in->mode, dx, NULL);
    }
    return NAN;
}

static int point_ok(const double *x, size_t k) {
    int ok = 1;
    for (size_t i = 0; i < k; ++i) ok &= fabs(x[i]) <= LB_MAX_ABS_ARG;
    return ok;
}

/* A displacement blend of K (small, a constant after inlining) arguments,
 * every p = 2, over a chunk: fast_op's arithmetic (duals, lb__bt_two_union)
 * and run_op's gradient sum, one loop with fixed-size arrays, so each K
 * gets its own specialised code. Same operations, same results. */
LB__INLINE void bt_two_loop(const size_t K, const lb__instr *in, const uint16_t *act, size_t n,
                            const double *const *vs, const double *const *gxs,
                            const double *const *gys, const double *const *gzs, const double *r,
                            const double *m, double *ov, double *ox, double *oy, double *oz) {
    const lb_setop op = in->op->op;
    double sg[4];
    for (size_t i = 0; i < K; ++i)
        sg[i] = op == LB_UNION ? 1.0 : op == LB_INTERSECTION || act[i] == 0 ? -1.0 : 1.0;
    /* the reciprocals of r and m once for the chunk (the same bits) */
    double ir[4], im[4];
    lb__bt_recip(K, r, m, ir, im);
    for (size_t j = 0; j < n; ++j) {
        double u[4], dx[4], ws[8];
        for (size_t i = 0; i < K; ++i) u[i] = op == LB_UNION ? vs[i][j] : sg[i] * vs[i][j];
        double v = lb__bt_two_union_recip(K, u, r, m, ir, im, dx, ws);
        if (op != LB_UNION) {
            for (size_t i = 0; i < K; ++i) dx[i] *= -sg[i];
            v = -v;
        }
        double g0 = 0.0, g1 = 0.0, g2 = 0.0;
        for (size_t i = 0; i < K; ++i) {
            g0 += dx[i] * gxs[i][j];
            g1 += dx[i] * gys[i][j];
            g2 += dx[i] * gzs[i][j];
        }
        ov[j] = v;
        ox[j] = g0;
        oy[j] = g1;
        oz[j] = g2;
    }
}

/* 1 when the chunk can take bt_two_loop: p = 2, 2 to 4 arguments in use,
 * every argument value within the fast kernels' range */
static int bt_two_chunk(const lb__instr *in, size_t k, size_t n, const double *const *vs) {
    if (in->fast != LB__FAST_DISPLACEMENT || in->mode != LB__P_TWO || k < 2 || k > 4 ||
        in->op->bulge)
        return 0;
    int ok = 1;
    for (size_t i = 0; i < k; ++i)
        for (size_t j = 0; j < n; ++j) ok &= fabs(vs[i][j]) <= LB_MAX_ABS_ARG;
    return ok;
}

static lb_status bulge_hvp(const lb_evaluator *ev, const lb__instr *in, size_t n, const double *x,
                           const double *y, const double *z, const double *dg, double *G,
                           size_t *count, lb_error *err);

LB_VECTOR_CLONES static lb_status run_op(const lb_evaluator *ev, const lb__instr *in,
                                         const lb__plan *plan, size_t n, const double *px,
                                         const double *py, const double *pz, double *regs,
                                         size_t *count, lb_error *err) {
    const lb__op *nd = in->op;
    if ((lb__op_flags(nd) & LB__R_CLEAN_UNION))
        return lb__local_run(ev, in, n, px, py, pz, regs, err);
    const size_t kf = nd->k;
    const int bounded = (lb__op_flags(nd) & LB__R_BOUNDING);
    /* per-argument arrays in the scratch after the registers (tape.h): the
     * argument indices, values, bounding values and their derivatives, the
     * parameters, the reciprocals, fast_op's 6, the registers' columns */
    double *S = lb__op_scratch(ev, regs);
    uint16_t *all = (uint16_t *)(void *)S;
    double *x = S + kf, *c = x + kf, *dx = c + kf, *dc = dx + kf, *r = dc + kf, *p = r + kf,
           *m = p + kf, *irb = m + kf, *imb = irb + kf, *fws = imb + kf;
    const double **vs = (const double **)(void *)(fws + 6 * kf), **gxs = vs + kf, **gys = gxs + kf,
                 **gzs = gys + kf;
    /* the active arguments: all, or those the plan kept (fast kernels only) */
    const uint16_t *act = all;
    size_t k = kf;
    if (plan && in->fast) {
        act = plan->act + in->aoff;
        k = plan->nact[in - ev->ins];
    } else {
        for (size_t i = 0; i < kf; ++i) all[i] = (uint16_t)i;
    }
    for (size_t i = 0; i < k; ++i) {
        const uint16_t a = act[i];
        vs[i] = lb__reg(regs, in->src[a], 0);
        gxs[i] = lb__reg(regs, in->src[a], 1);
        gys[i] = lb__reg(regs, in->src[a], 2);
        gzs[i] = lb__reg(regs, in->src[a], 3);
        r[i] = nd->r ? nd->r[a] : 0.0;
        p[i] = nd->p ? nd->p[a] : 0.0;
        m[i] = nd->m ? nd->m[a] : 1.0;
    }
    double *ov = lb__reg(regs, in->dst, 0), *ox = lb__reg(regs, in->dst, 1),
           *oy = lb__reg(regs, in->dst, 2), *oz = lb__reg(regs, in->dst, 3);
    if (k == 1 && (in->fast == LB__FAST_DISPLACEMENT || in->fast == LB__FAST_CONIC ||
                   in->fast == LB__FAST_MINMAX)) {
        /* one argument left (the plan culled the others): BT_1 is u / m, min
         * and max the argument itself; a difference that kept only a
         * subtracted argument negates it (fast_op's duals). One vector loop. */
        const double sgn = nd->op == LB_DIFFERENCE && act[0] != 0 ? -1.0 : 1.0;
        const double w = in->fast == LB__FAST_MINMAX ? 1.0 : sgn / m[0];
        for (size_t j = 0; j < n; ++j) {
            ov[j] = w * vs[0][j];
            ox[j] = w * gxs[0][j];
            oy[j] = w * gys[0][j];
            oz[j] = w * gzs[0][j];
        }
        return LB_OK;
    }
    if (bt_two_chunk(in, k, n, vs)) {
        if (k == 2)
            bt_two_loop(2, in, act, n, vs, gxs, gys, gzs, r, m, ov, ox, oy, oz);
        else if (k == 3)
            bt_two_loop(3, in, act, n, vs, gxs, gys, gzs, r, m, ov, ox, oy, oz);
        else
            bt_two_loop(4, in, act, n, vs, gxs, gys, gzs, r, m, ov, ox, oy, oz);
        return LB_OK;
    }
    double ga[6], dg[6];
    double *dgall = NULL;
    if (nd->bulge) {
        dgall = malloc(6 * LB__CHUNK * sizeof *dgall);
        if (!dgall) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", nd->path);
    }
    /* every p = 2 displacement: the reciprocals of r and m once for the chunk */
    const int recip = in->fast == LB__FAST_DISPLACEMENT && in->mode == LB__P_TWO && k > 1;
    if (recip) lb__bt_recip(k, r, m, irb, imb);
    for (size_t j = 0; j < n; ++j) {
        for (size_t i = 0; i < k; ++i) x[i] = vs[i][j];
        double v;
        if (in->fast && point_ok(x, k)) {
            v = fast_op(in, k, act, x, r, p, m, recip ? irb : NULL, imb, dx, fws);
        } else {
            if (bounded)
                for (size_t i = 0; i < k; ++i) c[i] = lb__reg(regs, in->src[k + i], 0)[j];
            if (nd->bulge)
                for (size_t i = 0; i < 2; ++i)
                    for (int d = 0; d < 3; ++d) ga[3 * i + d] = lb__reg(regs, in->src[i], 1 + d)[j];
            lb_status s = lb__op_apply(nd, ev->conv, x, c, ga, &v, dx, dc, dg, err);
            if (s) {
                free(dgall);
                if (err) {
                    char msg[LB_ERROR_MESSAGE_SIZE];
                    snprintf(msg, sizeof msg, "%s", err->message);
                    return lb__fail(err, s, "at (%.17g, %.17g, %.17g): node %s: %s", px[j], py[j],
                                    pz[j], nd->path, msg);
                }
                return s;
            }
            if (nd->bulge) memcpy(dgall + 6 * j, dg, sizeof dg);
        }
        double g0 = 0.0, g1 = 0.0, g2 = 0.0;
        for (size_t i = 0; i < k; ++i) {
            g0 += dx[i] * gxs[i][j];
            g1 += dx[i] * gys[i][j];
            g2 += dx[i] * gzs[i][j];
        }
        if (bounded)
            for (size_t i = 0; i < k; ++i) {
                const uint32_t rg = in->src[k + i];
                g0 += dc[i] * lb__reg(regs, rg, 1)[j];
                g1 += dc[i] * lb__reg(regs, rg, 2)[j];
                g2 += dc[i] * lb__reg(regs, rg, 3)[j];
            }
        ov[j] = v;
        ox[j] = g0;
        oy[j] = g1;
        oz[j] = g2;
    }
    lb_status s = LB_OK;
    if (nd->bulge) {
        double G[3 * LB__CHUNK];
        s = bulge_hvp(ev, in, n, px, py, pz, dgall, G, count, err);
        for (size_t j = 0; j < n && !s; ++j) {
            ox[j] += G[3 * j];
            oy[j] += G[3 * j + 1];
            oz[j] += G[3 * j + 2];
        }
    }
    free(dgall);
    return s;
}

/* The Hessian-vector terms of bulge elimination (the operator depends on the
 * argument gradients): each argument's analytic gradient is differenced
 * along d value / d g_i, re-running only the instructions that argument
 * depends on (its cone, listed at compile time), so the work is the cost
 * model's (tape.h) and never compounds across siblings. */
static lb_status run_list(const lb_evaluator *ev, const lb__plan *plan, const uint32_t *list,
                          size_t upto, size_t n, const double *x, const double *y, const double *z,
                          double *regs, size_t *count, lb_error *err);

static lb_status bulge_hvp(const lb_evaluator *ev, const lb__instr *in, size_t n, const double *x,
                           const double *y, const double *z, const double *dg, double *G,
                           size_t *count, lb_error *err) {
    memset(G, 0, 3 * n * sizeof *G);
    double *regs = malloc(lb__regs_len(ev) * sizeof *regs);
    if (!regs) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", in->op->path);
    double sx[LB__CHUNK], sy[LB__CHUNK], sz[LB__CHUNK], eps[LB__CHUNK], len[LB__CHUNK];
    lb_status s = LB_OK;
    for (int i = 0; i < 2 && !s; ++i) {
        const uint32_t reg = in->src[i];
        const uint32_t *cone = in->cone + (i ? in->ncone[0] : 0);
        double gp[3][LB__CHUNK];
        for (int sign = 1; sign >= -1 && !s; sign -= 2) {
            for (size_t j = 0; j < n; ++j) {
                const double *d = dg + 6 * j + 3 * i;
                len[j] = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                eps[j] = 1e-5 * (1.0 + fabs(x[j]) + fabs(y[j]) + fabs(z[j]));
                const double f = len[j] > 0.0 ? sign * eps[j] / len[j] : 0.0;
                sx[j] = x[j] + f * d[0];
                sy[j] = y[j] + f * d[1];
                sz[j] = z[j] + f * d[2];
            }
            s = run_list(ev, NULL, cone, in->ncone[i] - 1, n, sx, sy, sz, regs, count, err);
            for (size_t j = 0; j < n && !s; ++j)
                for (int d = 0; d < 3; ++d) {
                    const double gv = lb__reg(regs, reg, 1 + d)[j];
                    if (sign > 0)
                        gp[d][j] = gv;
                    else if (len[j] > 0.0)
                        G[3 * j + d] += (gp[d][j] - gv) / (2.0 * eps[j]) * len[j];
                }
        }
    }
    free(regs);
    return s;
}

/* Instructions list[0..upto] (list NULL: 0..upto) in tape order, skipping
 * what the plan does not need; count (may be NULL) adds one per
 * instruction run. */
static lb_status run_list(const lb_evaluator *ev, const lb__plan *plan, const uint32_t *list,
                          size_t upto, size_t n, const double *x, const double *y, const double *z,
                          double *regs, size_t *count, lb_error *err) {
    for (size_t q = 0; q <= upto; ++q) {
        const size_t i = list ? list[q] : q;
        if (plan && !plan->need[i]) continue;
        const lb__instr *in = &ev->ins[i];
        if (count) ++*count;
        double *v = lb__reg(regs, in->dst, 0), *gx = lb__reg(regs, in->dst, 1),
               *gy = lb__reg(regs, in->dst, 2), *gz = lb__reg(regs, in->dst, 3);
        switch (in->code) {
        case LB__I_ELLIPSOID:
            run_ellipsoid(in, n, x, y, z, v, gx, gy, gz);
            break;
        case LB__I_PRIM:
            run_prim(in, n, x, y, z, v, gx, gy, gz);
            break;
        default: {
            lb_status s = run_op(ev, in, plan, n, x, y, z, regs, count, err);
            if (s) return s;
        }
        }
    }
    return LB_OK;
}

lb_status lb__tape_run_list(const lb_evaluator *ev, const uint32_t *list, size_t nlist, size_t n,
                            const double *x, const double *y, const double *z, double *regs,
                            lb_error *err) {
    return nlist ? run_list(ev, NULL, list, nlist - 1, n, x, y, z, regs, NULL, err) : LB_OK;
}

lb_status lb__tape_run_counted(const lb_evaluator *ev, size_t n, const double *x, const double *y,
                               const double *z, double *regs, size_t *count, lb_error *err) {
    return run_list(ev, NULL, NULL, ev->n - 1, n, x, y, z, regs, count, err);
}

lb_status lb__tape_run_plan(const lb_evaluator *ev, const lb__plan *plan, size_t n, const double *x,
                            const double *y, const double *z, double *regs, lb_error *err) {
    if (!plan->nlist) return LB_OK;
    return run_list(ev, plan, plan->list, plan->nlist - 1, n, x, y, z, regs, NULL, err);
}

/* ---- batches and threads ----
 * Points are visited in Morton (Z-curve) order of their position in the
 * batch's bounding box, so each chunk is spatially compact; each chunk gets
 * an interval pass over its own box that culls arguments and subtrees that
 * cannot contribute there (lb__bounds_pass), then runs what is left. Results
 * go back to the caller's order. The order, the chunks and the plans depend
 * only on the points, never on the thread count. */

#define BLOCK_CHUNKS 16

typedef struct job {
    const lb_evaluator *ev;
    size_t n;
    const double *x, *y, *z;
    double *v, *gx, *gy, *gz;
    const uint32_t *order; /* visiting order (NULL: input order) */
    atomic_size_t next;
    pthread_mutex_t lock;
    size_t err_block; /* smallest failing block, SIZE_MAX if none */
    lb_error err;
} job;

static uint32_t spread3(uint32_t v) { /* 6 bits -> every third bit */
    v &= 0x3fu;
    v = (v | (v << 8)) & 0x0000f00fu;
    v = (v | (v << 4)) & 0x000c30c3u;
    v = (v | (v << 2)) & 0x00249249u;
    return v;
}

/* Morton order of the points (a stable LSD radix sort on 18-bit codes, two
 * passes of 9 bits: 64 cells per axis already make chunks of 64 points
 * compact for any batch worth sorting, and each pass is a full scatter).
 * Returns NULL when memory is short: the input order is then used. */
static uint32_t *morton_order(size_t n, const double *x, const double *y, const double *z) {
    if (n > UINT32_MAX) return NULL;
    uint32_t *key = malloc(2 * n * sizeof *key), *idx = malloc(2 * n * sizeof *idx);
    if (!key || !idx) {
        free(key);
        free(idx);
        return NULL;
    }
    double lo[3] = {x[0], y[0], z[0]}, hi[3] = {x[0], y[0], z[0]};
    const double *P[3] = {x, y, z};
    for (int d = 0; d < 3; ++d)
        for (size_t i = 1; i < n; ++i) {
            if (P[d][i] < lo[d]) lo[d] = P[d][i];
            if (P[d][i] > hi[d]) hi[d] = P[d][i];
        }
    double sc[3];
    for (int d = 0; d < 3; ++d) sc[d] = hi[d] > lo[d] ? 63.999 / (hi[d] - lo[d]) : 0.0;
    for (size_t i = 0; i < n; ++i) {
        key[i] = spread3((uint32_t)((x[i] - lo[0]) * sc[0])) |
                 spread3((uint32_t)((y[i] - lo[1]) * sc[1])) << 1 |
                 spread3((uint32_t)((z[i] - lo[2]) * sc[2])) << 2;
        idx[i] = (uint32_t)i;
    }
    uint32_t *k0 = key, *k1 = key + n, *i0 = idx, *i1 = idx + n;
    for (int shift = 0; shift < 18; shift += 9) {
        size_t count[513] = {0};
        for (size_t i = 0; i < n; ++i) count[((k0[i] >> shift) & 0x1ffu) + 1]++;
        for (int b = 0; b < 512; ++b) count[b + 1] += count[b];
        for (size_t i = 0; i < n; ++i) {
            const size_t dst = count[(k0[i] >> shift) & 0x1ffu]++;
            k1[dst] = k0[i];
            i1[dst] = i0[i];
        }
        uint32_t *t = k0;
        k0 = k1;
        k1 = t;
        t = i0;
        i0 = i1;
        i1 = t;
    }
    /* two passes: the sorted order is back in the first half */
    if (i0 != idx) memmove(idx, i0, n * sizeof *idx);
    free(key);
    return idx;
}

/* The box of n points (centre, half-size): branch-free min / max (the
 * coordinates were checked finite), which the compiler turns into minsd /
 * maxsd. */
static void point_box(const double *x, const double *y, const double *z, size_t n, double bc[3],
                      double br[3]) {
    double lo[3] = {x[0], y[0], z[0]}, hi[3] = {x[0], y[0], z[0]};
    const double *C[3] = {x, y, z};
    for (int d = 0; d < 3; ++d)
        for (size_t j = 1; j < n; ++j) {
            const double q = C[d][j];
            lo[d] = q < lo[d] ? q : lo[d];
            hi[d] = q > hi[d] ? q : hi[d];
        }
    lb__box_centre(lo, hi, bc, br);
}

static void run_blocks(job *J) {
    const lb_evaluator *ev = J->ev;
    double *regs = malloc(lb__regs_len(ev) * sizeof *regs);
    lb__iv *R = malloc(lb__ivs_len(ev) * sizeof *R);
    /* the block's plan (one pass over the whole tape), then each chunk's
     * under it: a chunk looks only at what reaches its block, so a blend
     * of thousands of arguments is scanned once per block, not per chunk */
    lb__plan plan, bplan;
    lb__plan_alloc(ev, &plan, NULL);
    lb__plan_alloc(ev, &bplan, NULL);
    /* a block's points gathered into visiting order, and its results: the
     * random reads and writes of a Morton order happen in two tight loops
     * (many loads in flight) instead of between chunks */
    double *buf = J->order ? malloc(7 * BLOCK_CHUNKS * LB__CHUNK * sizeof *buf) : NULL;
    const int ok = regs && R && plan.need && bplan.need && (buf || !J->order);
    const size_t nblocks = (J->n + BLOCK_CHUNKS * LB__CHUNK - 1) / (BLOCK_CHUNKS * LB__CHUNK);
    for (;;) {
        const size_t b = atomic_fetch_add(&J->next, 1);
        if (b >= nblocks) break;
        lb_error e = {LB_OK, ""};
        lb_status s = LB_OK;
        if (!ok) s = lb__fail(&e, LB_ERR_NO_MEMORY, "lb_evaluator_eval: out of memory");
        const size_t begin = b * BLOCK_CHUNKS * LB__CHUNK;
        const size_t end =
            (b + 1) * BLOCK_CHUNKS * LB__CHUNK < J->n ? (b + 1) * BLOCK_CHUNKS * LB__CHUNK : J->n;
        const size_t nb = end - begin;
        /* coordinates and outputs of this block, in visiting order */
        const double *bx = J->x + begin, *by = J->y + begin, *bz = J->z + begin;
        double *ov = J->v + begin, *ogx = J->gx ? J->gx + begin : NULL,
               *ogy = J->gy ? J->gy + begin : NULL, *ogz = J->gz ? J->gz + begin : NULL;
        if (J->order && ok) {
            const uint32_t *ord = J->order + begin;
            double *gxb = buf, *gyb = buf + nb, *gzb = buf + 2 * nb;
            for (size_t j = 0; j < nb; ++j) gxb[j] = J->x[ord[j]];
            for (size_t j = 0; j < nb; ++j) gyb[j] = J->y[ord[j]];
            for (size_t j = 0; j < nb; ++j) gzb[j] = J->z[ord[j]];
            bx = gxb;
            by = gyb;
            bz = gzb;
            ov = buf + 3 * nb;
            ogx = J->gx ? buf + 4 * nb : NULL;
            ogy = J->gy ? buf + 5 * nb : NULL;
            ogz = J->gz ? buf + 6 * nb : NULL;
        }
        if (ok && nb > LB__CHUNK) {
            double bc[3], br[3];
            point_box(bx, by, bz, nb, bc, br);
            lb__bounds_pass(ev, bc, br, R, &bplan);
        }
        for (size_t o = 0; o < nb && !s; o += LB__CHUNK) {
            const size_t m = nb - o < LB__CHUNK ? nb - o : LB__CHUNK;
            const double *cx = bx + o, *cy = by + o, *cz = bz + o;
            double bc[3], br[3];
            point_box(cx, cy, cz, m, bc, br);
            if (nb > LB__CHUNK)
                lb__bounds_pass_sub(ev, &bplan, bc, br, R, &plan);
            else
                lb__bounds_pass(ev, bc, br, R, &plan);
            s = lb__tape_run_plan(ev, &plan, m, cx, cy, cz, regs, &e);
            if (s) break;
            const double *rv = lb__reg(regs, ev->out, 0), *rx = lb__reg(regs, ev->out, 1),
                         *ry = lb__reg(regs, ev->out, 2), *rz = lb__reg(regs, ev->out, 3);
            memcpy(ov + o, rv, m * sizeof *rv);
            if (ogx) memcpy(ogx + o, rx, m * sizeof *rx);
            if (ogy) memcpy(ogy + o, ry, m * sizeof *ry);
            if (ogz) memcpy(ogz + o, rz, m * sizeof *rz);
        }
        if (J->order && ok && !s) {
            const uint32_t *ord = J->order + begin;
            if (ogx && ogy && ogz) /* one pass: four stores per index in flight */
                for (size_t j = 0; j < nb; ++j) {
                    const uint32_t q = ord[j];
                    J->v[q] = ov[j];
                    J->gx[q] = ogx[j];
                    J->gy[q] = ogy[j];
                    J->gz[q] = ogz[j];
                }
            else {
                for (size_t j = 0; j < nb; ++j) J->v[ord[j]] = ov[j];
                if (ogx)
                    for (size_t j = 0; j < nb; ++j) J->gx[ord[j]] = ogx[j];
                if (ogy)
                    for (size_t j = 0; j < nb; ++j) J->gy[ord[j]] = ogy[j];
                if (ogz)
                    for (size_t j = 0; j < nb; ++j) J->gz[ord[j]] = ogz[j];
            }
        }
        if (s) {
            pthread_mutex_lock(&J->lock);
            if (b < J->err_block) {
                J->err_block = b;
                J->err = e;
            }
            pthread_mutex_unlock(&J->lock);
            atomic_store(&J->next, nblocks); /* stop handing out work */
        }
    }
    free(regs);
    free(R);
    free(buf);
    lb__plan_free(&plan);
    lb__plan_free(&bplan);
}

static void *worker(void *arg) {
    run_blocks(arg);
    return NULL;
}

lb_status lb__eval_few(const lb_evaluator *ev, lb__boxeval *E, lb__plan *outer, size_t n,
                       const double *x, const double *y, const double *z, double *v, double *gx,
                       double *gy, double *gz, lb_error *err) {
    /* run_blocks for one block of points in their given order */
    if (n > LB__FEW) return lb__fail(err, LB_ERR_INTERNAL, "lb__eval_few: %zu points", n);
    if (n > LB__CHUNK) {
        double bc[3], br[3];
        point_box(x, y, z, n, bc, br);
        lb__bounds_pass(ev, bc, br, E->iv, outer);
    }
    for (size_t o = 0; o < n; o += LB__CHUNK) {
        const size_t m = n - o < LB__CHUNK ? n - o : LB__CHUNK;
        double bc[3], br[3];
        point_box(x + o, y + o, z + o, m, bc, br);
        if (n > LB__CHUNK)
            lb__bounds_pass_sub(ev, outer, bc, br, E->iv, &E->plan);
        else
            lb__bounds_pass(ev, bc, br, E->iv, &E->plan);
        const lb_status s = lb__tape_run_plan(ev, &E->plan, m, x + o, y + o, z + o, E->regs, err);
        if (s) return s;
        memcpy(v + o, lb__reg(E->regs, ev->out, 0), m * sizeof *v);
        memcpy(gx + o, lb__reg(E->regs, ev->out, 1), m * sizeof *gx);
        memcpy(gy + o, lb__reg(E->regs, ev->out, 2), m * sizeof *gy);
        memcpy(gz + o, lb__reg(E->regs, ev->out, 3), m * sizeof *gz);
    }
    return LB_OK;
}

lb_status lb_evaluator_eval(const lb_evaluator *ev, size_t n, const double *x, const double *y,
                            const double *z, double *value, double *gx, double *gy, double *gz,
                            int threads, lb_error *err) {
    static const char fn[] = "lb_evaluator_eval";
    if (!ev || !value || (n && (!x || !y || !z)))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: ev, value and the coordinate arrays must be non-NULL", fn);
    if (threads < 0)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: threads = %d; allowed: 0 (one per CPU) or a positive count", fn,
                        threads);
    for (size_t i = 0; i < n; ++i) {
        const double p[3] = {x[i], y[i], z[i]};
        for (int d = 0; d < 3; ++d)
            if (!(fabs(p[d]) <= LB_SCENE_MAX_COORD))
                return lb__fail(err, isfinite(p[d]) ? LB_ERR_INVALID_ARGUMENT : LB_ERR_NOT_FINITE,
                                "%s: point %zu has %c = %g; allowed: finite, |coordinate| <= %g",
                                fn, i, "xyz"[d], p[d], LB_SCENE_MAX_COORD);
    }
    if (n == 0) return LB_OK;
    job J;
    memset(&J, 0, sizeof J);
    J.ev = ev;
    J.n = n;
    J.x = x;
    J.y = y;
    J.z = z;
    J.v = value;
    J.gx = gx;
    J.gy = gy;
    J.gz = gz;
    /* spatial order pays off only when there is something to cull */
    uint32_t *order = n > 4 * LB__CHUNK && ev->cullable ? morton_order(n, x, y, z) : NULL;
    J.order = order;
    atomic_init(&J.next, 0);
    J.err_block = SIZE_MAX;
    pthread_mutex_init(&J.lock, NULL);
    size_t nt = threads == 0 ? lb__cpu_count() : (size_t)threads;
    const size_t nblocks = (n + BLOCK_CHUNKS * LB__CHUNK - 1) / (BLOCK_CHUNKS * LB__CHUNK);
    if (nt < 1) nt = 1;
    if (nt > nblocks) nt = nblocks;
    if (nt > 256) nt = 256;
    pthread_t tid[256];
    size_t started = 0;
    for (size_t t = 1; t < nt; ++t) {
        if (pthread_create(&tid[started], NULL, worker, &J) != 0) break;
        ++started;
    }
    run_blocks(&J); /* the caller's thread works too */
    for (size_t t = 0; t < started; ++t) pthread_join(tid[t], NULL);
    pthread_mutex_destroy(&J.lock);
    free(order);
    if (J.err_block != SIZE_MAX) {
        if (err) *err = J.err;
        return J.err.status;
    }
    return LB_OK;
}

lb_status lb__boxeval_alloc(const lb_evaluator *ev, lb__boxeval *E, lb_error *err) {
    memset(E, 0, sizeof *E);
    E->regs = malloc(lb__regs_len(ev) * sizeof *E->regs);
    E->iv = malloc(lb__ivs_len(ev) * sizeof *E->iv);
    if (!E->regs || !E->iv || lb__plan_alloc(ev, &E->plan, NULL)) {
        lb__boxeval_free(E);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_evaluator_eval: out of memory");
    }
    return LB_OK;
}

/* Forget P's list (need marks exactly the listed instructions: clearing
 * those clears it). */
static void plan_clear(lb__plan *P) {
    for (uint32_t q = 0; q < P->nlist; ++q) P->need[P->list[q]] = 0;
    P->nlist = 0;
}

void lb__boxeval_load(const lb_evaluator *ev, const lb__cplan *C, lb__boxeval *E) {
    plan_clear(&E->plan);
    const uint16_t *a = C->act;
    for (uint32_t q = 0; q < C->nlist; ++q) {
        const uint32_t i = C->list[q];
        E->plan.need[i] = 1;
        E->plan.list[q] = i;
        if (ev->ins[i].code != LB__I_OP) continue;
        const uint16_t na = *a++;
        E->plan.nact[i] = na;
        memcpy(E->plan.act + ev->ins[i].aoff, a, na * sizeof *a);
        a += na;
    }
    E->plan.nlist = C->nlist;
}

/* A compact plan's sizes: listed instructions, and argument-list entries
 * (each operator's count, then its arguments). */
static void cplan_sizes(const lb_evaluator *ev, const lb__plan *P, size_t *nl, size_t *na) {
    size_t a = 0;
    for (uint32_t q = 0; q < P->nlist; ++q)
        if (ev->ins[P->list[q]].code == LB__I_OP) a += 1u + P->nact[P->list[q]];
    *nl = P->nlist;
    *na = a;
}

/* P written compactly into list and act (sized by cplan_sizes). */
static void cplan_fill(const lb_evaluator *ev, const lb__plan *P, uint32_t *list, uint16_t *act) {
    for (uint32_t q = 0; q < P->nlist; ++q) {
        const uint32_t i = P->list[q];
        list[q] = i;
        if (ev->ins[i].code != LB__I_OP) continue;
        *act++ = P->nact[i];
        memcpy(act, P->act + ev->ins[i].aoff, P->nact[i] * sizeof *act);
        act += P->nact[i];
    }
}

lb_status lb__cplan_make(const lb_evaluator *ev, const lb__plan *P, lb__cplan *C, lb_error *err) {
    size_t nl, na;
    cplan_sizes(ev, P, &nl, &na);
    C->nlist = (uint32_t)nl;
    C->nact_total = (uint32_t)na;
    /* one allocation, the arguments after the list (a mesh keeps one plan
     * per block: tens of thousands of allocations per run) */
    C->list = malloc((nl ? nl : 1) * sizeof *C->list + (na ? na : 1) * sizeof *C->act);
    if (!C->list) {
        C->act = NULL;
        C->nlist = C->nact_total = 0;
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    }
    C->act = (uint16_t *)(void *)(C->list + (nl ? nl : 1));
    cplan_fill(ev, P, C->list, C->act);
    return LB_OK;
}

void *lb__cplan_pack(const lb_evaluator *ev, const lb__plan *P, size_t n, lb__cplan *C) {
    size_t tl = 0, ta = 0;
    for (size_t k = 0; k < n; ++k) {
        size_t nl, na;
        cplan_sizes(ev, &P[k], &nl, &na);
        tl += nl;
        ta += na;
    }
    void *mem = malloc(tl * sizeof(uint32_t) + (ta ? ta : 1) * sizeof(uint16_t));
    if (!mem) return NULL;
    uint32_t *list = mem;
    uint16_t *act = (uint16_t *)(void *)(list + tl);
    for (size_t k = 0; k < n; ++k) {
        size_t nl, na;
        cplan_sizes(ev, &P[k], &nl, &na);
        C[k].nlist = (uint32_t)nl;
        C[k].nact_total = (uint32_t)na;
        C[k].list = list;
        C[k].act = act;
        cplan_fill(ev, &P[k], list, act);
        list += nl;
        act += na;
    }
    return mem;
}

void lb__cplan_free(lb__cplan *C) {
    free(C->list); /* act lies in the same allocation */
    C->list = NULL;
    C->act = NULL;
    C->nlist = C->nact_total = 0;
}

lb_status lb__boxeval_run(const lb_evaluator *ev, lb__boxeval *E, size_t n, const double *x,
                          const double *y, const double *z, double *v, double *gx, double *gy,
                          double *gz, lb_error *err) {
    lb_status s = LB_OK;
    for (size_t o = 0; o < n && !s; o += LB__CHUNK) {
        const size_t m = n - o < LB__CHUNK ? n - o : LB__CHUNK;
        s = lb__tape_run_plan(ev, &E->plan, m, x + o, y + o, z + o, E->regs, err);
        if (s) break;
        memcpy(v + o, lb__reg(E->regs, ev->out, 0), m * sizeof *v);
        memcpy(gx + o, lb__reg(E->regs, ev->out, 1), m * sizeof *gx);
        memcpy(gy + o, lb__reg(E->regs, ev->out, 2), m * sizeof *gy);
        memcpy(gz + o, lb__reg(E->regs, ev->out, 3), m * sizeof *gz);
    }
    return s;
}

void lb__boxeval_narrow(const lb_evaluator *ev, lb__boxeval *E, const lb__plan *outer,
                        const double bmin[3], const double bmax[3]) {
    double bc[3], br[3];
    lb__box_centre(bmin, bmax, bc, br);
    lb__bounds_pass_sub(ev, outer, bc, br, E->iv, &E->plan);
}

size_t lb__plan_prims(const lb_evaluator *ev, const lb__plan *P) {
    size_t c = 0;
    for (uint32_t q = 0; q < P->nlist; ++q) c += ev->ins[P->list[q]].code != LB__I_OP;
    return c;
}

lb_status lb__plan_alloc(const lb_evaluator *ev, lb__plan *P, lb_error *err) {
    const size_t nk = ev->total_k ? ev->total_k : 1;
    P->need = calloc(ev->n, 1);
    P->nact = malloc(ev->n * sizeof *P->nact);
    P->act = malloc(nk * sizeof *P->act);
    P->list = malloc(ev->n * sizeof *P->list);
    P->nlist = 0;
    if (!P->need || !P->nact || !P->act || !P->list) {
        lb__plan_free(P);
        return lb__fail(err, LB_ERR_NO_MEMORY, "lb_mesh_create: out of memory");
    }
    return LB_OK;
}

void lb__plan_load(const lb_evaluator *ev, const lb__plan *from, lb__plan *P) {
    plan_clear(P);
    /* only what the plan lists: its cost, not the tape's */
    for (uint32_t q = 0; q < from->nlist; ++q) {
        const uint32_t i = from->list[q];
        P->need[i] = 1;
        P->list[q] = i;
        if (ev->ins[i].code != LB__I_OP) continue;
        P->nact[i] = from->nact[i];
        memcpy(P->act + ev->ins[i].aoff, from->act + ev->ins[i].aoff,
               from->nact[i] * sizeof *P->act);
    }
    P->nlist = from->nlist;
}

void lb__plan_free(lb__plan *P) {
    free(P->need);
    free(P->nact);
    free(P->act);
    free(P->list);
    P->need = NULL;
    P->nact = P->act = NULL;
    P->list = NULL;
    P->nlist = 0;
}

void lb__boxeval_free(lb__boxeval *E) {
    free(E->regs);
    free(E->iv);
    lb__plan_free(&E->plan);
    memset(E, 0, sizeof *E);
}
