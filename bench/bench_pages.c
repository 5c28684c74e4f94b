/* bench_pages: what touching memory again costs after an unmapping, with
 * small pages and with huge ones (Linux). It explains the incremental
 * remesher's slab storage (docs/meshing.md, Incremental remeshing): on a
 * hypervisor with shadow page tables (this project's build machine is a
 * PVM guest), an munmap anywhere in the process makes every small page
 * touched afterwards fault in the host.
 *
 * For small pages, then huge ones: a buffer is written, copied into once
 * (mapped: "warm"), a second buffer of the same size is allocated, written
 * and freed (unmapped), and the copy into the first buffer is timed again
 * ("after unmap"). ROUNDS rounds, each time printed; a line per kind says
 * how much of the buffer the system put on huge pages (AnonHugePages of
 * /proc/self/smaps_rollup, before the second buffer).
 *
 * usage: bench_pages [MiB]   (default 115, about a 3-million-triangle
 * mesh's arrays; at least 33, above glibc's largest mmap threshold, so
 * that the free unmaps) */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#define ROUNDS 4
#define HUGE_BYTES ((size_t)2 << 20)

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static long huge_kib(void) {
    FILE *f = fopen("/proc/self/smaps_rollup", "r");
    char line[256];
    long v = -1;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "AnonHugePages:", 14)) v = atol(line + 14);
    if (f) fclose(f);
    return v;
}

/* bytes at a 2 MiB boundary, advised to huge pages or not */
static unsigned char *map(size_t bytes, int huge) {
    unsigned char *m =
        mmap(NULL, bytes + HUGE_BYTES, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) {
        perror("bench_pages: mmap");
        exit(1);
    }
    unsigned char *p = m + ((HUGE_BYTES - ((uintptr_t)m & (HUGE_BYTES - 1))) & (HUGE_BYTES - 1));
    (void)madvise(p, bytes, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
    return p;
}

int main(int argc, char **argv) {
    const size_t mib = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 115;
    if (mib < 33 || mib > 4096) {
        fprintf(stderr, "usage: bench_pages [MiB] (33 to 4096)\n");
        return 2;
    }
    const size_t bytes = mib << 20;
    unsigned char *src = malloc(bytes);
    if (!src) return 1;
    memset(src, 1, bytes);
    for (int huge = 0; huge <= 1; ++huge) {
        unsigned char *dst = map(bytes, huge);
        memset(dst, 2, bytes);
        printf("%s pages: %ld MiB of the process on huge pages\n", huge ? "huge" : "small",
               huge_kib() >> 10);
        for (int r = 0; r < ROUNDS; ++r) {
            double t = now();
            memcpy(dst, src, bytes);
            const double warm = now() - t;
            unsigned char *other = malloc(bytes);
            if (!other) return 1;
            memset(other, 3, bytes);
            free(other); /* glibc unmaps a block this large */
            t = now();
            memcpy(dst, src, bytes);
            const double after = now() - t;
            printf("  copy of %zu MiB: warm %.1f ms, after an unmap %.1f ms (checksum %u)\n", mib,
                   1e3 * warm, 1e3 * after, (unsigned)dst[bytes / 2]);
        }
    }
    return 0;
}
