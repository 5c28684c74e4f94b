/* What differs between the systems libblend runs on (POSIX, Windows), behind
 * two calls; the rest of the library is ISO C plus pthreads (on Windows,
 * mingw-w64's winpthreads, linked in statically). Output files have their
 * own implementation per system (export/output_posix.c, output_win32.c). */
#ifndef LIBBLEND_PLATFORM_H
#define LIBBLEND_PLATFORM_H

#include "internal.h"

#include <stddef.h>
#include <stdio.h>

/* The number of CPUs online (at least 1): the thread count 0 means. */
LB_INTERNAL size_t lb__cpu_count(void);

/* fopen for a UTF-8 path: on Windows through the wide API, so that a path
 * with non-ASCII letters works whatever the code page; elsewhere fopen.
 * NULL with errno set on failure (EILSEQ: not UTF-8). */
LB_INTERNAL FILE *lb__fopen(const char *path, const char *mode);

/* Advice that the memory at p (bytes long; the caller's, e.g. a large
 * malloc block) be backed by huge pages where the system offers them
 * (Linux's transparent huge pages in madvise mode): a mesh's arrays are
 * written once, page by page, and a fault per 4 KiB page cost more than the
 * writing (docs/meshing.md, Incremental remeshing). Nothing elsewhere. */
LB_INTERNAL void lb__huge_pages(void *p, size_t bytes);

/* bytes from malloc's heap (freed with free, resized with realloc) for an
 * array written once, page by page (a mesh's output): on glibc, from 2 MiB
 * on, aligned to 2 MiB and advised as lb__huge_pages, so that its first
 * byte already lies on a huge page (a block from malloc starts wherever
 * its mapping does: up to 2 MiB of small pages, a fault each, before the
 * first whole huge page; 40 to 295 faults for the first 3 MiB in one test
 * against 4); else malloc. NULL when out of memory. */
LB_INTERNAL void *lb__array_alloc(size_t bytes);

/* bytes of memory on huge pages where the system offers them (on Linux,
 * from 2 MiB on, an anonymous mapping aligned to 2 MiB and advised so, its
 * pages then faulted 2 MiB at a time; else malloc), for large long-lived buffers read
 * over and over (the mesh cache's slabs). NULL when out of memory. Free it
 * with lb__huge_free and the same bytes. */
LB_INTERNAL void *lb__huge_alloc(size_t bytes);
LB_INTERNAL void lb__huge_free(void *p, size_t bytes);

/* The bytes usable at p, a block from malloc, calloc or realloc (at least
 * the size asked for), or 0 where the C runtime does not say (then the
 * caller assumes the size it asked for). */
LB_INTERNAL size_t lb__usable_size(void *p);

/* Whether a UTF-8 path names a folder. */
LB_INTERNAL int lb__is_directory(const char *path);

#ifdef _WIN32
#include <wchar.h>
/* UTF-8 to a new UTF-16 string (free it), or NULL with errno set (EILSEQ:
 * not UTF-8). */
LB_INTERNAL wchar_t *lb__wide(const char *s);
#endif

#endif
