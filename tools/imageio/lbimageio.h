/* lbimageio: the images of blendtool through OpenImageIO, behind a plain C
 * interface (OpenImageIO has no C API). C++ lives here, in tools/, never in
 * libblend.so: the core stays C for ctypes and Blender.
 *
 * Every writer returns the file's bytes in a malloc'd buffer the caller
 * frees (so the caller puts them in place atomically, through lb_output).
 * Nothing carries a time stamp: the same pixels and metadata give the same
 * bytes on every run and machine. Functions return 0, or -1 with a message
 * in err (always NUL-terminated when errlen > 0). */
#ifndef LBIMAGEIO_H
#define LBIMAGEIO_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lbi_format {
    LBI_PNG8 = 0,  /* 8 bits per channel PNG */
    LBI_PNG16,     /* 16 bits per channel PNG */
    LBI_EXR_HALF,  /* OpenEXR, half floats, zip compression */
    LBI_EXR_FLOAT, /* OpenEXR, 32-bit floats, zip compression */
} lbi_format;

/* The threads OpenImageIO and OpenEXR may use for the process's later calls
 * (their pools are the process's): 0 one per CPU (their default), 1 the
 * calling thread alone, n at most n. Call before the first image. */
void lbi_set_threads(int n);

/* one metadata entry: PNG text chunks, EXR string attributes */
typedef struct lbi_meta {
    const char *key, *value;
} lbi_meta;

/* Read the image at `in` (any format OpenImageIO reads) and write it as
 * `format`: RGB, or RGBA when alpha is nonzero and the input has alpha.
 * Only the given metadata is written. */
int lbi_convert(const char *in, lbi_format format, int alpha, const lbi_meta *meta, size_t nmeta,
                unsigned char **data, size_t *size, char *err, size_t errlen);

/* A contact sheet: the n images in a grid of `columns`, each scaled to
 * cell_w x cell_h and labelled underneath with labels[i] (DejaVu Sans),
 * on a dark grey ground, written as format. */
int lbi_contact_sheet(const char *const *images, const char *const *labels, size_t n, int columns,
                      int cell_w, int cell_h, lbi_format format, const lbi_meta *meta, size_t nmeta,
                      unsigned char **data, size_t *size, char *err, size_t errlen);

/* A text drawn onto an image: its baseline starts at (x, y) in pixels,
 * size in pixels, colour sRGB-encoded in [0, 1]. */
typedef struct lbi_text {
    const char *text;
    int x, y, size;
    float rgb[3];
} lbi_text;

/* An image from the caller's pixels: w x h RGB, row by row from the top,
 * sRGB-encoded values in [0, 1], with the texts drawn on it (DejaVu Sans),
 * written as format (PNG; EXR stores the same encoded values). */
int lbi_write_pixels(const float *rgb, int w, int h, const lbi_text *texts, size_t ntexts,
                     lbi_format format, const lbi_meta *meta, size_t nmeta, unsigned char **data,
                     size_t *size, char *err, size_t errlen);

/* Compare two images channel by channel (OpenImageIO's compare): *max_error
 * the largest difference, *fail_percent the share of pixels with a channel
 * differing by more than fail. Different sizes or channel counts are an
 * error (-1). The headers are read first: an image declaring more than
 * LBI_MAX_PIXELS pixels or LBI_MAX_CHANNELS channels is an error before any
 * pixel is decoded (the caller refuses what is not a regular file). */
#define LBI_MAX_PIXELS (1L << 26) /* 8192 x 8192: 1 GiB as 4 float channels */
#define LBI_MAX_CHANNELS 16
int lbi_compare(const char *a, const char *b, double fail, double *max_error, double *mean_error,
                double *fail_percent, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
