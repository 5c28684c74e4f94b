/* blendtool compare: two images within thresholds (regression checks),
 * through OpenImageIO's compare. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* the input rules of scene files: a regular file (no FIFO or device that
 * could block or never end), of a bounded size */
#define BT_MAX_IMAGE_BYTES ((off_t)1 << 30)
static int image_file_ok(const char *path) {
    struct stat st;
    if (stat(path, &st) != 0) {
        bt_error("compare", "%s: cannot open the image (%s)", path, strerror(errno));
        return 0;
    }
    if (!S_ISREG(st.st_mode)) {
        bt_error("compare", "%s: not a regular file; allowed: an image file (PNG, EXR, TIFF, ...)",
                 path);
        return 0;
    }
    if (st.st_size > BT_MAX_IMAGE_BYTES) {
        bt_error("compare", "%s: %lld bytes; allowed: image files of at most %lld bytes", path,
                 (long long)st.st_size, (long long)BT_MAX_IMAGE_BYTES);
        return 0;
    }
    return 1;
}

static int number(const char *opt, const char *v, double lo, double hi, double *out) {
    char *end = NULL;
    const double x = strtod(v, &end);
    if (!end || *end || end == v || !(x >= lo && x <= hi)) {
        bt_error("compare", "%s %s: expected a number from %g to %g", opt, v, lo, hi);
        return -1;
    }
    *out = x;
    return 0;
}

static int run(int argc, char **argv) {
    const char *a = NULL, *b = NULL, *v = NULL;
    double fail = 0.004, percent = 0.0;
    for (int i = 1; i < argc; ++i) {
        int r;
        if ((r = bt_option("compare", argc, argv, &i, "--fail", &v))) {
            if (r < 0 || number("--fail", v, 0.0, 1e30, &fail)) return BT_EXIT_BAD_INPUT;
        } else if ((r = bt_option("compare", argc, argv, &i, "--fail-percent", &v))) {
            if (r < 0 || number("--fail-percent", v, 0.0, 100.0, &percent))
                return BT_EXIT_BAD_INPUT;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            bt_error("compare", "unknown option %s; see blendtool compare --help", argv[i]);
            return BT_EXIT_BAD_INPUT;
        } else if (!a) {
            a = argv[i];
        } else if (!b) {
            b = argv[i];
        } else {
            bt_error("compare", "more than two images (%s); allowed: two", argv[i]);
            return BT_EXIT_BAD_INPUT;
        }
    }
    if (!a || !b) {
        bt_error("compare", "two images needed; usage: blendtool compare A B");
        return BT_EXIT_BAD_INPUT;
    }
    if (!image_file_ok(a) || !image_file_ok(b)) return BT_EXIT_BAD_INPUT;
    double mx = 0.0, mean = 0.0, pct = 0.0;
    char err[1024] = "the image writer is not available (above)";
    const bt_imageio *io = NULL;
    if (!(io = bt_imageio_get("compare")) ||
        io->compare(a, b, fail, &mx, &mean, &pct, err, sizeof err)) {
        bt_error("compare", "%s", err);
        return BT_EXIT_BAD_INPUT;
    }
    const int differ = pct > percent;
    printf("%s: max difference %.6g, mean %.6g, %.4g %% of pixels over %g (allowed %g %%)\n",
           differ ? "DIFFER" : "MATCH", mx, mean, pct, fail, percent);
    return differ ? 3 : BT_EXIT_OK;
}

const bt_command bt_cmd_compare = {
    "compare", "compare two images within thresholds (regression checks)",
    "usage: blendtool compare A B [--fail T] [--fail-percent P]\n\n"
    "Compares two images of the same size channel by channel (OpenImageIO): a pixel\n"
    "fails when a channel differs by more than T (default 0.004, about one step of\n"
    "an 8-bit image); the images match when at most P % of the pixels fail\n"
    "(default 0). Prints MATCH or DIFFER with the largest and mean differences.\n"
    "The headers are read first: sizes are compared, and an image of more than\n"
    "67108864 pixels (8192 x 8192) or 16 channels refused, before any pixel is\n"
    "decoded; an image must be a regular file of at most 1 GiB.\n"
    "Exit status: 0 match, 3 the images differ, 2 an image cannot be read, the sizes\n"
    "differ, an image over a limit or bad options.\n",
    run};
