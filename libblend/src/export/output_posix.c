/* Output files on POSIX (libblend/output.h): unnamed temporary file linked into place,
 * a hidden named one as the fallback, symlinks followed, devices and FIFOs
 * written directly, modes like any Unix tool. Shared by every writer. */
#define _GNU_SOURCE /* O_TMPFILE, AT_EMPTY_PATH */
#include "output_internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "../common/glibc_compat.h"
#include <time.h>
#include <unistd.h>

static const char FN[] = "lb_output";

enum { OUT_UNNAMED = 0, OUT_NAMED, OUT_DIRECT };

struct lb_output {
    lb__output_head h; /* h.temp: OUT_NAMED's hidden temporary file */
    int how;
    char *path; /* the target, symbolic links resolved */
    char *dir;  /* the target's folder */
    char *base; /* the target's name in it */
};

static char *dup_str(const char *s, size_t n) {
    char *o = malloc(n + 1);
    if (o) {
        memcpy(o, s, n);
        o[n] = '\0';
    }
    return o;
}

static void output_free(lb_output *o) {
    if (!o) return;
    free(o->path);
    free(o->h.temp);
    free(o->dir);
    free(o->base);
    free(o);
}

/* Follow symbolic links from path to the file they name (which need not
 * exist). *exists says whether it does, *st is its lstat then. */
static lb_status resolve(const char *path, char **target, int *exists, struct stat *st,
                         lb_error *err) {
    char *cur = dup_str(path, strlen(path));
    if (!cur) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    for (int hops = 0;; ++hops) {
        if (lb__lstat(cur, st) != 0) {
            if (errno != ENOENT) {
                const int e = errno;
                lb__fail(err, LB_ERR_IO, "%s: cannot look at the output path (%s)", cur,
                         strerror(e));
                free(cur);
                return LB_ERR_IO;
            }
            *exists = 0;
            break;
        }
        if (!S_ISLNK(st->st_mode)) {
            *exists = 1;
            break;
        }
        if (hops >= 40) {
            lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                     "%s: more than 40 symbolic links in a row; allowed: a path that leads to a "
                     "file",
                     path);
            free(cur);
            return LB_ERR_INVALID_ARGUMENT;
        }
        char buf[4096];
        const ssize_t n = readlink(cur, buf, sizeof buf - 1);
        if (n < 0 || (size_t)n >= sizeof buf - 1) {
            lb__fail(err, LB_ERR_IO, "%s: cannot read the symbolic link (%s)", cur,
                     n < 0 ? strerror(errno) : "target too long");
            free(cur);
            return LB_ERR_IO;
        }
        buf[n] = '\0';
        const char *slash = strrchr(cur, '/');
        char *next;
        if (buf[0] == '/' || !slash) {
            next = dup_str(buf, (size_t)n);
        } else {
            const size_t dl = (size_t)(slash - cur) + 1;
            next = malloc(dl + (size_t)n + 1);
            if (next) {
                memcpy(next, cur, dl);
                memcpy(next + dl, buf, (size_t)n + 1);
            }
        }
        free(cur);
        if (!next) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        cur = next;
    }
    *target = cur;
    return LB_OK;
}

/* ".NAME.lbtmp." + pid + "." + 12 hex digits */
static int temp_name(const lb_output *o, unsigned attempt, char *buf, size_t size) {
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    uint64_t h = (uint64_t)t.tv_nsec * 0x9E3779B97F4A7C15ull ^ (uint64_t)(uintptr_t)o ^
                 ((uint64_t)attempt << 40) ^ (uint64_t)t.tv_sec;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    const int w = snprintf(buf, size, "%s/.%s.lbtmp.%ld.%012llx", o->dir, o->base, (long)getpid(),
                           (unsigned long long)(h & 0xffffffffffffull));
    return w > 0 && (size_t)w < size;
}

/* Remove hidden temporary files of the same output left by processes that
 * are gone (killed while writing on the fallback path). */
static void remove_stale(const lb_output *o) {
    DIR *d = opendir(o->dir);
    if (!d) return;
    char prefix[512];
    const int pl = snprintf(prefix, sizeof prefix, ".%s.lbtmp.", o->base);
    if (pl <= 0 || (size_t)pl >= sizeof prefix) {
        closedir(d);
        return;
    }
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, prefix, (size_t)pl) != 0) continue;
        char *end = NULL;
        const long pid = strtol(e->d_name + pl, &end, 10);
        if (pid <= 0 || !end || *end != '.') continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue; /* its writer may be alive */
        unlinkat(dirfd(d), e->d_name, 0);
    }
    closedir(d);
}

/* A hidden temporary file in the target's folder, created 0666 less the
 * umask. Returns the descriptor or -1 (errno set). */
static int open_named(lb_output *o) {
    char name[4096 + 600];
    for (unsigned attempt = 0; attempt < 64; ++attempt) {
        if (!temp_name(o, attempt, name, sizeof name)) {
            errno = ENAMETOOLONG;
            return -1;
        }
        const int fd = open(name, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            o->h.temp = dup_str(name, strlen(name));
            if (!o->h.temp) {
                close(fd);
                unlink(name);
                errno = ENOMEM;
                return -1;
            }
            return fd;
        }
        if (errno != EEXIST) return -1;
    }
    return -1;
}

lb_status lb_output_open(const char *path, lb_output **out, lb_error *err) {
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s_open: out is NULL", FN);
    *out = NULL;
    if (!path || !*path)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s_open: no output path given; allowed: a file path", FN);
    lb_output *o = calloc(1, sizeof *o);
    if (!o) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    int exists = 0;
    struct stat st;
    lb_status s = resolve(path, &o->path, &exists, &st, err);
    if (s) {
        free(o);
        return s;
    }
    if (exists && (S_ISDIR(st.st_mode) || S_ISSOCK(st.st_mode))) {
        lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: is a %s; allowed: a file path", path,
                 S_ISDIR(st.st_mode) ? "folder" : "socket");
        output_free(o);
        return LB_ERR_INVALID_ARGUMENT;
    }
    int fd = -1;
    if (exists && (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) || S_ISFIFO(st.st_mode))) {
        o->how = OUT_DIRECT;
        fd = open(o->path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    } else {
        const char *slash = strrchr(o->path, '/');
        o->dir = slash ? dup_str(o->path, slash == o->path ? 1 : (size_t)(slash - o->path))
                       : dup_str(".", 1);
        o->base = dup_str(slash ? slash + 1 : o->path, strlen(slash ? slash + 1 : o->path));
        if (!o->dir || !o->base) {
            output_free(o);
            return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        }
        o->how = OUT_UNNAMED;
        /* LIBBLEND_OUTPUT_NAMED=1 takes the fallback on any file system
         * (the tests exercise it where O_TMPFILE works) */
        const char *named = getenv("LIBBLEND_OUTPUT_NAMED");
        if (named && strcmp(named, "1") == 0) {
            fd = -1;
            errno = EOPNOTSUPP;
        } else {
            fd = open(o->dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
        }
        if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
            o->how = OUT_NAMED;
            remove_stale(o);
            fd = open_named(o);
        }
        if (fd >= 0 && exists && fchmod(fd, st.st_mode & 07777) != 0) {
            const int e = errno;
            close(fd);
            if (o->h.temp) unlink(o->h.temp);
            errno = e;
            fd = -1;
        }
    }
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!f) {
        const int e = errno;
        if (fd >= 0) close(fd);
        if (o->h.temp) unlink(o->h.temp);
        output_free(o);
        return lb__output_open_failed(err, path, strerror(e));
    }
    o->h.f = f;
    *out = o;
    return LB_OK;
}

/* Link the unnamed file into place: directly when nothing is there, else
 * through a hidden name renamed over the target (atomic replacement). */
static int link_unnamed(lb_output *o) {
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fileno(o->h.f));
    if (linkat(AT_FDCWD, proc, AT_FDCWD, o->path, AT_SYMLINK_FOLLOW) == 0) return 1;
    if (errno == ENOENT && linkat(fileno(o->h.f), "", AT_FDCWD, o->path, AT_EMPTY_PATH) == 0)
        return 1;
    if (errno != EEXIST) return 0;
    char name[4096 + 600];
    for (unsigned attempt = 0; attempt < 64; ++attempt) {
        if (!temp_name(o, attempt, name, sizeof name)) return 0;
        if (linkat(AT_FDCWD, proc, AT_FDCWD, name, AT_SYMLINK_FOLLOW) != 0 &&
            !(errno == ENOENT && linkat(fileno(o->h.f), "", AT_FDCWD, name, AT_EMPTY_PATH) == 0)) {
            if (errno == EEXIST) continue;
            return 0;
        }
        if (rename(name, o->path) == 0) return 1;
        const int e = errno;
        unlink(name);
        errno = e;
        return 0;
    }
    return 0;
}

lb_status lb_output_commit(lb_output *o, lb_error *err) {
    if (!o) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s_commit: output is NULL", FN);
    errno = 0;
    int ok = fflush(o->h.f) == 0 && !ferror(o->h.f);
    int e = errno;
    if (ok && o->how == OUT_UNNAMED) {
        ok = link_unnamed(o);
        e = errno;
    }
    errno = 0;
    if (fclose(o->h.f) != 0 && ok) {
        ok = 0;
        e = errno;
    }
    if (ok && o->how == OUT_NAMED) {
        ok = rename(o->h.temp, o->path) == 0;
        e = errno;
    }
    if (!ok && o->h.temp) unlink(o->h.temp);
    lb_status s = LB_OK;
    if (!ok)
        s = lb__output_write_failed(err, o->path, e ? strerror(e) : "short write",
                                    o->how == OUT_DIRECT);
    output_free(o);
    return s;
}

void lb_output_discard(lb_output *o) {
    if (!o) return;
    fclose(o->h.f);
    if (o->h.temp) unlink(o->h.temp);
    output_free(o);
}
