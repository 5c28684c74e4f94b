/* What every system's output files share (output_posix.c, output_win32.c
 * implement the rest of libblend/output.h): a whole buffer to a path. */
#include "libblend/output.h"

#include "../common/internal.h"

#include <errno.h>
#include <string.h>

static const char FN[] = "lb_output";

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
