/* OpenImageIO is loaded when an image is written, not when blendtool
 * starts: the C++ library and its dependencies take about 0.1 s to map,
 * and blendtool must install its signal handlers at once (a signal in the
 * first milliseconds still gets the documented exit status). The module
 * (liblbimageio.so, tools/imageio) is looked up in $LIBBLEND_IMAGEIO, next to
 * the blendtool executable (the build tree), then in the installed libdir
 * relative to it (lib/libblend beside bin/): an installed prefix works
 * wherever it is copied. */
#define _GNU_SOURCE
#include "blendtool.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef LIBBLEND_IMAGEIO_REL
#define LIBBLEND_IMAGEIO_REL "../lib/libblend"
#endif

static bt_imageio api; /* one process, loaded once */
static int loaded;

const bt_imageio *bt_imageio_get(const char *cmd) {
    if (loaded) return &api;
    char path[PATH_MAX + 64];
    const char *env = getenv("LIBBLEND_IMAGEIO");
    void *h = NULL;
    char tried[3 * (PATH_MAX + 64)] = "";
    if (env && *env) {
        h = dlopen(env, RTLD_NOW | RTLD_LOCAL);
        snprintf(tried, sizeof tried, "%s", env);
    }
    char self[PATH_MAX];
    /* next to the executable (the build tree), then the installed layout's
     * libdir relative to it */
    const int have_self = !h && bt_self_dir(self, sizeof self) == 0;
    for (int k = 0; k < 2 && !h && have_self; ++k) {
        snprintf(path, sizeof path,
                 k ? "%s/" LIBBLEND_IMAGEIO_REL "/liblbimageio.so" : "%s/liblbimageio.so", self);
        h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        size_t l = strlen(tried);
        snprintf(tried + l, sizeof tried - l, "%s%s", l ? ", " : "", path);
    }
    if (!h) {
        bt_error(cmd,
                 "cannot load the image writer (tried %s): %s; allowed: build blendtool with "
                 "OpenImageIO (Debian package libopenimageio-dev) or set LIBBLEND_IMAGEIO",
                 tried, dlerror());
        return NULL;
    }
    api.convert = (int (*)(const char *, lbi_format, int, const lbi_meta *, size_t,
                           unsigned char **, size_t *, char *, size_t))dlsym(h, "lbi_convert");
    api.contact_sheet = (int (*)(const char *const *, const char *const *, size_t, int, int, int,
                                 lbi_format, const lbi_meta *, size_t, unsigned char **, size_t *,
                                 char *, size_t))dlsym(h, "lbi_contact_sheet");
    api.compare = (int (*)(const char *, const char *, double, double *, double *, double *, char *,
                           size_t))dlsym(h, "lbi_compare");
    if (!api.convert || !api.contact_sheet || !api.compare) {
        bt_error(cmd,
                 "the image writer %s lacks its functions; allowed: the liblbimageio.so "
                 "built with this blendtool",
                 tried);
        return NULL;
    }
    loaded = 1;
    return &api;
}
