/* A scratch folder for tests that write files, on POSIX and on Windows (the
 * cross-compiled tests run under Wine). POSIX users define _POSIX_C_SOURCE
 * 200809L before any include (mkdtemp). */
#ifndef LIBBLEND_TESTFS_H
#define LIBBLEND_TESTFS_H

#include <stdio.h>
#include <stdlib.h>

#ifdef _WIN32
#include <direct.h>
#include <process.h>
#else
#include <unistd.h>
#endif

/* A new empty folder for a test's files, its path in buf (0 on success):
 * mkdtemp on POSIX; on Windows a unique name in the temporary folder. */
static inline int test_mkdtemp(char *buf, size_t size, const char *stem) {
#ifdef _WIN32
    const char *tmp = getenv("TEMP");
    if (!tmp || !*tmp) tmp = ".";
    for (unsigned k = 0; k < 100; ++k) {
        snprintf(buf, size, "%s\\%s-%d-%u", tmp, stem, _getpid(), k);
        if (_mkdir(buf) == 0) return 0;
    }
    return -1;
#else
    snprintf(buf, size, "/tmp/%s-XXXXXX", stem);
    return mkdtemp(buf) ? 0 : -1;
#endif
}

/* Remove a test's folder once it is empty again. */
static inline void test_rmdir(const char *path) {
#ifdef _WIN32
    _rmdir(path);
#else
    rmdir(path);
#endif
}

#endif
