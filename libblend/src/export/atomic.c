/* Output files that appear whole or not at all: a temporary file in the
 * target's folder, renamed over the target only when everything was written
 * and closed. Shared by every writer of the library. */
#define _POSIX_C_SOURCE 200809L
#include "atomic.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

FILE *lb__atomic_open(const char *fn, const char *path, lb__atomic *a, lb_error *err) {
    const size_t n = strlen(path) + 16;
    a->tmp = malloc(n);
    if (!a->tmp) {
        lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
        return NULL;
    }
    snprintf(a->tmp, n, "%s.tmp.XXXXXX", path);
    const int fd = mkstemp(a->tmp);
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!f) {
        const int e = errno;
        if (fd >= 0) {
            close(fd);
            unlink(a->tmp);
        }
        free(a->tmp);
        a->tmp = NULL;
        lb__fail(err, LB_ERR_IO, "%s: %s: cannot create a file there (%s)", fn, path, strerror(e));
    }
    return f;
}

lb_status lb__atomic_close(const char *fn, const char *path, FILE *f, int ok, lb__atomic *a,
                           lb_error *err) {
    ok = ok && fflush(f) == 0 && !ferror(f);
    errno = 0;
    ok = (fclose(f) == 0) && ok;
    if (ok && rename(a->tmp, path) != 0) ok = 0;
    const int e = errno;
    if (!ok) unlink(a->tmp);
    free(a->tmp);
    a->tmp = NULL;
    if (!ok)
        return lb__fail(err, LB_ERR_IO, "%s: %s: writing failed (%s); nothing was written", fn,
                        path, e ? strerror(e) : "short write");
    return LB_OK;
}
