/* What every system's output files share (output_posix.c, output_win32.c):
 * the head of struct lb_output, which output.c reads, and the two messages
 * both give. */
#ifndef LIBBLEND_OUTPUT_INTERNAL_H
#define LIBBLEND_OUTPUT_INTERNAL_H

#include "libblend/output.h"

#include "../common/internal.h"

#include <stdio.h>

/* The first member of each system's struct lb_output. */
typedef struct lb__output_head {
    FILE *f;    /* the stream the caller writes */
    char *temp; /* the temporary file (UTF-8), or NULL when written directly */
} lb__output_head;

/* "PATH: cannot create the output file there (WHY); allowed: ..." */
LB_INTERNAL lb_status lb__output_open_failed(lb_error *err, const char *path, const char *why);
/* "PATH: writing the output failed (WHY); ..." and what is left (direct:
 * written to a device, so what was written stays). */
LB_INTERNAL lb_status lb__output_write_failed(lb_error *err, const char *path, const char *why,
                                              int direct);

#endif
