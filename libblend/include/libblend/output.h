/* libblend — output files: how every file libblend writes reaches its path
 * (lb_mesh_write, lb_scene_write_pov, and callers such as blendtool that
 * write their own bytes through lb_output).
 *
 * Contract (stated once for the header):
 *  - A regular file appears whole or not at all. The bytes go to an unnamed
 *    temporary file in the target's folder (O_TMPFILE), linked into place
 *    by lb_output_commit; where the file system has no unnamed files, to a
 *    hidden temporary file named ".NAME.lbtmp.PID.XXXXXX" in that folder,
 *    renamed into place. A process killed before commit leaves nothing but,
 *    on the fallback only, such a hidden file; the next lb_output_open of
 *    the same path removes those whose process is gone. The environment
 *    variable LIBBLEND_OUTPUT_NAMED=1 takes the fallback everywhere (tests).
 *  - A symbolic link is followed: the file it points to is replaced, the
 *    link stays. A character or block device, or a FIFO, is written to
 *    directly (no atomicity: what was written before a failure stays; a
 *    FIFO blocks until a reader opens it). A folder, a socket or an empty
 *    path is refused (LB_ERR_INVALID_ARGUMENT).
 *  - A new file gets mode 0666 less the umask, like any Unix tool; an
 *    existing file keeps its mode.
 *  - No global state: any number of outputs may be open at once, from any
 *    thread. An lb_output belongs to one thread at a time. */
#ifndef LIBBLEND_OUTPUT_H
#define LIBBLEND_OUTPUT_H

#include "common.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lb_output lb_output;

/* Start writing path. On success *out owns the output and its stream;
 * finish with lb_output_commit or lb_output_discard (either frees it). */
LB_API lb_status lb_output_open(const char *path, lb_output **out, lb_error *err);

/* The stream to write to (binary). Do not fclose it. NULL for NULL. */
LB_API FILE *lb_output_stream(lb_output *output);

/* The named temporary file behind the output, or NULL when there is none
 * (unnamed temporary file, or a device / FIFO written directly). A signal
 * handler may unlink() it (the string stays valid until commit or discard)
 * so that even the fallback leaves nothing behind. */
LB_API const char *lb_output_temp_name(const lb_output *output);

/* Flush and close; when every write succeeded, put the file in place
 * (link or rename), else remove it and fail with LB_ERR_IO naming the path
 * and the reason. Frees output; NULL is refused. Like free(), a second
 * commit or discard of the same output is misuse that cannot be detected
 * (the handle is gone): set your copy to NULL after either call. */
LB_API lb_status lb_output_commit(lb_output *output, lb_error *err);

/* Close and remove the temporary file; nothing reaches the path (a device
 * or FIFO keeps what was already written). Frees output; NULL is a no-op. */
LB_API void lb_output_discard(lb_output *output);

/* Write len bytes to path through an lb_output (open, write, commit). */
LB_API lb_status lb_output_write_file(const char *path, const void *data, size_t len,
                                      lb_error *err);

#ifdef __cplusplus
}
#endif

#endif
