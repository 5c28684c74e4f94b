/* SplitMix64, the one pseudo-random generator of the project's own random
 * cases: the tests (tests/testlib.h), the POV-Ray agreement test and povgen's
 * check of its SDL recurrences against the C library. Not used by the
 * library at run time. Each generator is its own state (no global): the same
 * seed gives the same sequence on every platform.
 *
 * Each call adds the golden-ratio increment to the state and returns the
 * state passed through SplitMix64's finaliser (two xor-shift-multiply
 * rounds and a final xor-shift), which is a bijection of 64-bit words. */
#ifndef LB_SPLITMIX_H
#define LB_SPLITMIX_H

#include <stdint.h>

typedef struct lb__splitmix {
    uint64_t s;
} lb__splitmix;

static inline uint64_t lb__splitmix_next(lb__splitmix *r) {
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* uniform in [0, 1): the top 53 bits */
static inline double lb__splitmix_unit(lb__splitmix *r) {
    return (double)(lb__splitmix_next(r) >> 11) * 0x1.0p-53;
}

#endif
