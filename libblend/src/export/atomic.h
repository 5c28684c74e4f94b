/* Atomic output files (atomic.c). */
#ifndef LIBBLEND_ATOMIC_H
#define LIBBLEND_ATOMIC_H

#include "../common/internal.h"

#include <stdio.h>

typedef struct lb__atomic {
    char *tmp;
} lb__atomic;

/* A stream on a new temporary file next to path; NULL (err set) on failure. */
LB_INTERNAL FILE *lb__atomic_open(const char *fn, const char *path, lb__atomic *a, lb_error *err);
/* Close it; when ok and every write succeeded, rename it over path, else
 * remove it. Either way the temporary file is gone afterwards. */
LB_INTERNAL lb_status lb__atomic_close(const char *fn, const char *path, FILE *f, int ok,
                                       lb__atomic *a, lb_error *err);

#endif
