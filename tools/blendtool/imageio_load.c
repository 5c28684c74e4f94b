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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef LIBBLEND_IMAGEIO_REL
#define LIBBLEND_IMAGEIO_REL "../lib/libblend"
#endif

static bt_imageio api; /* one process, loaded once */
static int loaded;

void *bt_module_open(const char *env_var, const char *file, const char *what, char *why,
                     size_t whylen) {
    char path[PATH_MAX + 64];
    const char *env = getenv(env_var);
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
        snprintf(path, sizeof path, k ? "%s/" LIBBLEND_IMAGEIO_REL "/%s" : "%s/%s", self, file);
        h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        size_t l = strlen(tried);
        snprintf(tried + l, sizeof tried - l, "%s%s", l ? ", " : "", path);
    }
    if (!h) snprintf(why, whylen, "cannot load the %s (tried %s): %s", what, tried, dlerror());
    return h;
}

const bt_imageio *bt_imageio_try(char *why, size_t whylen) {
    if (loaded) return &api;
    void *h = bt_module_open("LIBBLEND_IMAGEIO", "liblbimageio.so", "image module", why, whylen);
    if (!h) return NULL;
    api.convert = (int (*)(const char *, lbi_format, int, const lbi_meta *, size_t,
                           unsigned char **, size_t *, char *, size_t))dlsym(h, "lbi_convert");
    api.contact_sheet = (int (*)(const char *const *, const char *const *, size_t, int, int, int,
                                 lbi_format, const lbi_meta *, size_t, unsigned char **, size_t *,
                                 char *, size_t))dlsym(h, "lbi_contact_sheet");
    api.compare = (int (*)(const char *, const char *, double, double *, double *, double *, char *,
                           size_t))dlsym(h, "lbi_compare");
    api.write_pixels =
        (int (*)(const float *, int, int, const lbi_text *, size_t, lbi_format, const lbi_meta *,
                 size_t, unsigned char **, size_t *, char *, size_t))dlsym(h, "lbi_write_pixels");
    api.set_threads = (void (*)(int))dlsym(h, "lbi_set_threads");
    if (!api.convert || !api.contact_sheet || !api.compare || !api.write_pixels ||
        !api.set_threads) {
        snprintf(why, whylen,
                 "the image module liblbimageio.so lacks its functions (not the one built "
                 "with this blendtool)");
        dlclose(h);
        return NULL;
    }
    /* the command's --threads binds OpenImageIO's and OpenEXR's pools too */
    api.set_threads(bt_threads_asked());
    loaded = 1;
    return &api;
}

/* room for why the module did not load: three tried paths and their errors */
#define WHY_SIZE (3 * (PATH_MAX + 64) + 512)

const bt_imageio *bt_imageio_get(const char *cmd) {
    char why[WHY_SIZE];
    const bt_imageio *io = bt_imageio_try(why, sizeof why);
    if (!io)
        bt_error(cmd,
                 "%s; allowed: install OpenImageIO 2.4 (Debian package libopenimageio2.4, "
                 "or libopenimageio-dev to build blendtool) or set LIBBLEND_IMAGEIO",
                 why);
    return io;
}

int bt_image_plan_for(const char *cmd, const char *out, int fmt, int alpha, bt_image_plan *p) {
    static int noted; /* one note per process, not one per batch task */
    char why[WHY_SIZE];
    p->io = bt_imageio_try(why, sizeof why);
    p->out_alpha = alpha;
    p->alpha = p->io ? 1 : alpha;
    p->bits16 = p->io ? 1 : fmt == LBI_PNG16;
    if (!p->io && fmt != LBI_PNG8 && fmt != LBI_PNG16) {
        bt_error(cmd,
                 "%s: OpenEXR needs the image module: %s; allowed: a .png output, or install "
                 "OpenImageIO 2.4 (Debian package libopenimageio2.4)",
                 out, why);
        return BT_EXIT_INTERNAL;
    }
    if (!p->io && !noted) {
        fprintf(stderr,
                "blendtool %s: note: %s; POV-Ray writes the PNG itself (its own %d-bit "
                "quantisation, the same metadata; OpenEXR, contact sheets and compare need "
                "OpenImageIO 2.4)\n",
                cmd, why, p->bits16 ? 16 : 8);
        noted = 1;
    }
    return BT_EXIT_OK;
}

int bt_image_finish(const bt_image_plan *p, const char *png, int fmt, const lbi_meta *meta,
                    size_t nmeta, unsigned char **data, size_t *size, char *err, size_t errlen) {
    if (p->io)
        return p->io->convert(png, (lbi_format)fmt, p->out_alpha, meta, nmeta, data, size, err,
                              errlen);
    return bt_png_direct(png, meta, nmeta, data, size, err, errlen);
}
