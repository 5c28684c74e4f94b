/* povgen's shared parts: the include's documented ranges, the writer and
 * the SDL parameter lists (povgen.c), the Newton step counts checked
 * against the C library (povgen_steps.c), the macros of the zero
 * convention and the primitives (povgen_zero.c), of the soft convention
 * (povgen_soft.c). */
#ifndef POVGEN_H
#define POVGEN_H

#include <libblend/libblend.h>

#include <stdio.h>

#define KMAX 16    /* arguments of a k-ary macro */
#define TOL 1e-10  /* early exit: the Newton step below TOL (1 + abs(h)); the exit takes it */
#define P_MIN 1.05 /* documented ranges of the root-solved macros */
#define P_MAX 16.0
#define M_MIN LB_SOFT_MIN_SLOPE /* the library's soft slope range */
#define M_MAX LB_SOFT_MAX_SLOPE
#define LTOL 1e-13 /* |Newton step| in lambda (= relative in h) */
#define LN2 0.69314718055994530942

/* ---- povgen_steps.c: unrolled Newton steps that cover every case ---- */
int choose_steps(void);
int choose_soft_steps(void);
int choose_sconic_steps(void);

/* ---- povgen.c: writing ---- */
/* printf-style text to the include being written */
void w(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void dlist(void);
void check_r(const char *mac, const char *k, double rmax);
void unpack(const char *v, const char *name);
void vlist(void);
void ylist(const char *sign);
void qlist(const char *fmt);
void alist(void);
void bracket_args(void);
void blist(void);
void wt(const char *t, int var, const char *pre);

/* ---- the include's sections, in the order main writes them ---- */
void header(void);
void primitives(void);
void primitives2(void);
void classic(void);
void displacement(int steps);
void conic(void);
void scale(int steps);
void bounded(int steps);
void soft_hyper(int steps);
void soft_conic(int steps);
void bulge(int steps);
void local_blend(void);

#endif
