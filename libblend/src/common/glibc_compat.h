/* Old glibc symbol versions for a libblend.so that loads on glibc 2.28.
 *
 * Blender's Linux builds and the studio farms they run on (the VFX Reference
 * Platform's Rocky/Alma 8) have glibc 2.28, but this project builds on a
 * newer Debian. Linking against a newer glibc binds some functions to
 * versions that older ones do not have: hypot@GLIBC_2.35,
 * pthread_create/join/mutex_trylock@GLIBC_2.34 (moved from libpthread into
 * libc), stat/fstat/lstat@GLIBC_2.33 (before it, inline wrappers of __xstat,
 * __fxstat and __lxstat), exp/log/pow@GLIBC_2.29 (new implementations without the SVID
 * error wrapper). Every one of them still exists under its x86-64 base
 * version GLIBC_2.2.5 in today's glibc, with the same results for the
 * arguments libblend passes (libblend never reads errno), so the build binds
 * to those instead.
 *
 * This header is forced in front of every libblend source file (and of the
 * JSON libraries built by scripts/third-party.sh) when LB_GLIBC_BASELINE is
 * defined: CMake does so on x86-64 glibc for every build except the
 * sanitizer ones (their runtimes intercept pthread_create by its default
 * version). tests/portability/test_glibc_baseline.sh checks the result with
 * objdump: no symbol version newer than GLIBC_2.28 and no NEEDED entry
 * beyond the C runtime. Other systems (Windows, macOS, musl) define nothing
 * here and use the plain calls.
 */
#ifndef LB_GLIBC_COMPAT_H
#define LB_GLIBC_COMPAT_H

#if defined(LB_GLIBC_BASELINE) && defined(__x86_64__) && defined(__linux__)

__asm__(".symver hypot,hypot@GLIBC_2.2.5");
__asm__(".symver exp,exp@GLIBC_2.2.5");
__asm__(".symver log,log@GLIBC_2.2.5");
__asm__(".symver pow,pow@GLIBC_2.2.5");
__asm__(".symver pthread_create,pthread_create@GLIBC_2.2.5");
__asm__(".symver pthread_join,pthread_join@GLIBC_2.2.5");
__asm__(".symver pthread_mutex_trylock,pthread_mutex_trylock@GLIBC_2.2.5");

/* fstat and lstat: their pre-2.33 form, through the stat ABI version 1
 * (_STAT_VER_LINUX on x86-64). */
struct stat;
extern int __fxstat(int ver, int fd, struct stat *st);
extern int __lxstat(int ver, const char *path, struct stat *st);
extern int __xstat(int ver, const char *path, struct stat *st);
#define lb__fstat(fd, st) __fxstat(1, (fd), (st))
#define lb__stat(path, st) __xstat(1, (path), (st))
#define lb__lstat(path, st) __lxstat(1, (path), (st))

#else

#define lb__fstat(fd, st) fstat((fd), (st))
#define lb__stat(path, st) stat((path), (st))
#define lb__lstat(path, st) lstat((path), (st))

#endif

#endif
