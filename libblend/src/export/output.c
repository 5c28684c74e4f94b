/* What every system's output files share (output_posix.c, output_win32.c
 * implement the rest of libblend/output.h): the stream and temporary name
 * of an output, the messages, a whole buffer to a path. */
#include "output_internal.h"

#include <errno.h>
#include <string.h>

static const char FN[] = "lb_output";

/* (each system's struct lb_output starts with an lb__output_head) */
FILE *lb_output_stream(lb_output *o) {
    return o ? ((const lb__output_head *)(const void *)o)->f : NULL;
}

const char *lb_output_temp_name(const lb_output *o) {
    return o ? ((const lb__output_head *)(const void *)o)->temp : NULL;
}

lb_status lb__output_open_failed(lb_error *err, const char *path, const char *why) {
    return lb__fail(err, LB_ERR_IO,
                    "%s: cannot create the output file there (%s); allowed: a path in a "
                    "writable folder",
                    path, why);
}

lb_status lb__output_write_failed(lb_error *err, const char *path, const char *why, int direct) {
    return lb__fail(err, LB_ERR_IO, "%s: writing the output failed (%s); %s", path, why,
                    direct ? "what was written before stays on the device" : "nothing was written");
}

lb_status lb_output_write_file(const char *path, const void *data, size_t len, lb_error *err) {
    if (!data && len)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s_write_file: data is NULL", FN);
    lb_output *o = NULL;
    lb_status s = lb_output_open(path, &o, err);
    if (s) return s;
    if (len && fwrite(data, 1, len, lb_output_stream(o)) != len) {
        const int e = errno;
        lb__fail(err, LB_ERR_IO, "%s: writing the output failed (%s); nothing was written", path,
                 strerror(e));
        lb_output_discard(o);
        return LB_ERR_IO;
    }
    return lb_output_commit(o, err);
}
