/* Instruction records (records.c): an instruction's content written out
 * field by field, so that two evaluators' instructions can be compared for
 * "computes the same bits at every point" without a hash deciding it. Used
 * by the mesh cache (meshing/cache.c: which blocks may be reused) and by
 * compiling against a previous evaluator (local_curves.c: which local
 * unions' curves may be copied). Not installed. */
#ifndef LIBBLEND_RECORDS_H
#define LIBBLEND_RECORDS_H

#include "tape.h"

#include <stdint.h>

#define LB__RNONE UINT32_MAX /* no match */

/* A growing byte buffer; oom is set (and nothing more written) when an
 * allocation fails. */
typedef struct lb__rbuf {
    uint8_t *p;
    size_t n, cap;
    int oom;
} lb__rbuf;

/* Instruction i's record into b (from b->n on): every field evaluation
 * reads, field by field (no padding bytes); registers, the exports' node
 * identity, the plan offset and the messages' path are not. Arguments
 * (args: its srci; always its bounding solids and cones) are named through
 * map (an index of another evaluator; LB__RNONE: no match, and then 0 is
 * returned) or, map NULL, by ev's own indices. curves: a local union's
 * curves are written (0: written as absent, for matching before they are
 * found). */
LB_INTERNAL int lb__record(const lb_evaluator *ev, uint32_t i, const uint32_t *map, int args,
                           int curves, lb__rbuf *b);
/* FNV-1a over a record: for tables and quick rejection only (equality is
 * decided on the bytes). */
LB_INTERNAL uint64_t lb__rhash(const uint8_t *p, size_t n);

/* A set of records, one per instruction: record i is p[off[i], off[i + 1]),
 * h[i] its hash; bad[i]: it names an instruction without a match (equal
 * to none). */
typedef struct lb__recs {
    uint8_t *p;
    size_t *off;
    uint64_t *h;
    uint8_t *bad;
} lb__recs;

LB_INTERNAL void lb__recs_free(lb__recs *R);
/* ev's records, one per instruction (args, map, curves as for
 * lb__record). 0 when out of memory. */
LB_INTERNAL int lb__recs_make(const lb_evaluator *ev, const uint32_t *map, int args, int curves,
                              lb__recs *R);
/* Are record i of A and record j of B the same bytes (neither naming an
 * instruction without a match)? */
LB_INTERNAL int lb__recs_equal(const lb__recs *A, size_t i, const lb__recs *B, size_t j);

/* An open-addressing table over the n records of R by their hashes, for
 * finding an instruction by its record: tcap slots (lb__recs_table_cap(n),
 * a power of 2, zeroed by the caller), each 0 (empty) or instruction + 1. */
LB_INTERNAL size_t lb__recs_table_cap(size_t n);
LB_INTERNAL void lb__recs_table_fill(const lb__recs *R, size_t n, uint32_t *tab, size_t tcap);
/* The instruction of R whose record is the bytes p[0, len), through R's
 * table, or LB__RNONE (never one that names an instruction without a
 * match). */
LB_INTERNAL uint32_t lb__recs_find(const lb__recs *R, const uint32_t *tab, size_t tcap,
                                   const uint8_t *p, size_t len);

#endif
