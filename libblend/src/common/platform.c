/* The calls of platform.h, per system. */
/* madvise and its MADV_HUGEPAGE (a BSD and Linux extension) */
#define _DEFAULT_SOURCE
#include "platform.h"

#include <errno.h>
#include <stdlib.h>

#ifdef _WIN32
#include <malloc.h>
#include <windows.h>

wchar_t *lb__wide(const char *s) {
    const int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, s, -1, NULL, 0);
    if (n <= 0) {
        errno = EILSEQ;
        return NULL;
    }
    wchar_t *w = malloc((size_t)n * sizeof *w);
    if (!w) {
        errno = ENOMEM;
        return NULL;
    }
    MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, s, -1, w, n);
    return w;
}

size_t lb__usable_size(void *p) {
    return p ? _msize(p) : 0;
}

void *lb__huge_alloc(size_t bytes) {
    return malloc(bytes ? bytes : 1);
}

void *lb__array_alloc(size_t bytes) {
    return malloc(bytes ? bytes : 1);
}

void lb__huge_free(void *p, size_t bytes) {
    (void)bytes;
    free(p);
}

size_t lb__cpu_count(void) {
    const DWORD n = GetActiveProcessorCount(ALL_PROCESSOR_GROUPS);
    return n > 0 ? (size_t)n : 1;
}

FILE *lb__fopen(const char *path, const char *mode) {
    wchar_t *wp = lb__wide(path), *wm = lb__wide(mode);
    FILE *f = wp && wm ? _wfopen(wp, wm) : NULL;
    const int e = errno;
    free(wp);
    free(wm);
    errno = e;
    return f;
}

int lb__is_directory(const char *path) {
    wchar_t *wp = lb__wide(path);
    const DWORD a = wp ? GetFileAttributesW(wp) : INVALID_FILE_ATTRIBUTES;
    free(wp);
    return a != INVALID_FILE_ATTRIBUTES && (a & FILE_ATTRIBUTE_DIRECTORY);
}

void lb__huge_pages(void *p, size_t bytes) {
    (void)p;
    (void)bytes;
}

#else
#include "glibc_compat.h"

#include <stdint.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

int lb__is_directory(const char *path) {
    struct stat st;
    return lb__stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

size_t lb__cpu_count(void) {
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (size_t)n : 1;
}

FILE *lb__fopen(const char *path, const char *mode) {
    return fopen(path, mode);
}

size_t lb__usable_size(void *p) {
#ifdef __GLIBC__
    return p ? malloc_usable_size(p) : 0;
#else
    (void)p;
    return 0;
#endif
}

#define HUGE_BYTES ((size_t)2 << 20)

void *lb__array_alloc(size_t bytes) {
#ifdef __GLIBC__
    if (bytes >= HUGE_BYTES) {
        void *p = NULL;
        if (posix_memalign(&p, HUGE_BYTES, bytes)) return NULL;
        lb__huge_pages(p, bytes);
        return p;
    }
#endif
    return malloc(bytes ? bytes : 1);
}

void *lb__huge_alloc(size_t bytes) {
    if (bytes < HUGE_BYTES) return malloc(bytes ? bytes : 1); /* too small for a huge page */
    bytes = (bytes + HUGE_BYTES - 1) & ~(HUGE_BYTES - 1);
    /* a mapping one huge page longer, its unaligned head and tail given back */
    unsigned char *m =
        mmap(NULL, bytes + HUGE_BYTES, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return NULL;
    unsigned char *p = m + ((HUGE_BYTES - ((uintptr_t)m & (HUGE_BYTES - 1))) & (HUGE_BYTES - 1));
    if (p > m) munmap(m, (size_t)(p - m));
    if (m + HUGE_BYTES > p) munmap(p + bytes, (size_t)(m + HUGE_BYTES - p));
#ifdef MADV_HUGEPAGE
    (void)madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}

void lb__huge_free(void *p, size_t bytes) {
    if (bytes < HUGE_BYTES) {
        free(p);
        return;
    }
    if (p) munmap(p, (bytes + HUGE_BYTES - 1) & ~(HUGE_BYTES - 1));
}

void lb__huge_pages(void *p, size_t bytes) {
#ifdef MADV_HUGEPAGE
    /* the whole pages the block lies on: a large block is a mapping of its
     * own, and advising all of it keeps it one mapping, which realloc can
     * then grow by moving pages (mremap) instead of copying them; the
     * system puts huge pages on its aligned 2 MiB parts */
    const uintptr_t P = (uintptr_t)sysconf(_SC_PAGESIZE), a = (uintptr_t)p & ~(P - 1),
                    b = ((uintptr_t)p + bytes + P - 1) & ~(P - 1);
    if (p && bytes >= ((size_t)2 << 20)) (void)madvise((void *)a, b - a, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}
#endif
