/* POV-Ray's own PNG, finished as blendtool's output when the image module
 * (OpenImageIO) cannot be loaded, as on a bare farm node: POV-Ray has
 * already written the final depth and channels (bt_povray with the plan's
 * bits and alpha), so the pixels stay as they are; what changes is the
 * chunk list. PNG is a signature followed by chunks (4-byte big-endian
 * length, 4-byte type, data, CRC-32 of type and data). POV-Ray writes a tIME
 * chunk and tEXt chunks with the render date and its own version; those
 * (and any zTXt/iTXt) are dropped, so the same scene gives the same bytes,
 * and the metadata is written as text chunks in front of the first IDAT,
 * where OpenImageIO puts it too. Every chunk's CRC is checked on the way
 * (zlib's crc32), so a damaged or truncated file is an error, never an
 * output. */
#include "blendtool.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#define PNG_MAX_FILE (1L << 30) /* POV-Ray's largest: LBI_MAX_PIXELS x 8 bytes and change */

static const unsigned char SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

static uint32_t be32(const unsigned char *p) {
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void put32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* one text chunk for key = value at out (NULL: only its size): tEXt when the
 * value is ASCII (Latin-1 by the PNG standard), else iTXt (UTF-8,
 * uncompressed, no language tag) */
static size_t text_chunk(const lbi_meta *m, unsigned char *out) {
    const size_t kl = strlen(m->key), vl = strlen(m->value);
    int ascii = 1;
    for (size_t i = 0; i < vl; ++i) ascii &= (unsigned char)m->value[i] < 0x80;
    const size_t dl = kl + 1 + (ascii ? 0 : 4) + vl;
    if (out) {
        put32(out, (uint32_t)dl);
        memcpy(out + 4, ascii ? "tEXt" : "iTXt", 4);
        unsigned char *d = out + 8;
        memcpy(d, m->key, kl + 1); /* with its NUL separator */
        d += kl + 1;
        if (!ascii) { /* compression flag, method, empty language, empty translated key */
            memset(d, 0, 4);
            d += 4;
        }
        memcpy(d, m->value, vl);
        put32(out + 8 + dl, (uint32_t)crc32(crc32(0L, Z_NULL, 0), out + 4, (uInt)(dl + 4)));
    }
    return 12 + dl;
}

static int dropped(const unsigned char *type) {
    return !memcmp(type, "tIME", 4) || !memcmp(type, "tEXt", 4) || !memcmp(type, "zTXt", 4) ||
           !memcmp(type, "iTXt", 4);
}

int bt_png_direct(const char *in, const lbi_meta *meta, size_t nmeta, unsigned char **data,
                  size_t *size, char *err, size_t errlen) {
    *data = NULL;
    *size = 0;
    for (size_t i = 0; i < nmeta; ++i) {
        const size_t kl = strlen(meta[i].key);
        if (kl < 1 || kl > 79) {
            snprintf(err, errlen, "metadata key '%s' is not 1 to 79 bytes long", meta[i].key);
            return -1;
        }
    }
    FILE *f = fopen(in, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: %s", in, strerror(errno));
        return -1;
    }
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0) n = ftell(f);
    rewind(f);
    unsigned char *src = n > 0 && n <= PNG_MAX_FILE ? malloc((size_t)n) : NULL;
    const int got = src && fread(src, 1, (size_t)n, f) == (size_t)n;
    fclose(f);
    if (!got) {
        free(src);
        snprintf(err, errlen, "%s: cannot read POV-Ray's image (%ld bytes)", in, n);
        return -1;
    }
    const size_t len = (size_t)n;
    size_t extra = 0;
    for (size_t i = 0; i < nmeta; ++i) extra += text_chunk(&meta[i], NULL);
    unsigned char *out = malloc(len + extra);
    int rc = -1;
    if (!out) {
        snprintf(err, errlen, "out of memory for a %zu-byte image", len + extra);
        goto done;
    }
    if (len < sizeof SIGNATURE || memcmp(src, SIGNATURE, sizeof SIGNATURE)) {
        snprintf(err, errlen, "%s: not a PNG file", in);
        goto done;
    }
    memcpy(out, SIGNATURE, sizeof SIGNATURE);
    size_t at = sizeof SIGNATURE, o = sizeof SIGNATURE, nchunk = 0;
    int wrote_meta = 0, ended = 0;
    while (!ended) {
        if (len - at < 12) {
            snprintf(err, errlen, "%s: truncated after %zu chunks (no IEND)", in, nchunk);
            goto done;
        }
        const uint32_t dl = be32(src + at);
        if (dl > 0x7fffffffu || dl > len - at - 12) {
            snprintf(err, errlen, "%s: chunk %zu runs past the end of the file", in, nchunk);
            goto done;
        }
        const unsigned char *type = src + at + 4;
        const uint32_t crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), type, dl + 4);
        if (crc != be32(src + at + 8 + dl)) {
            snprintf(err, errlen, "%s: chunk %zu (%.4s) fails its CRC", in, nchunk, type);
            goto done;
        }
        if (nchunk == 0 && memcmp(type, "IHDR", 4)) {
            snprintf(err, errlen, "%s: the first chunk is not IHDR", in);
            goto done;
        }
        if (!wrote_meta && (!memcmp(type, "IDAT", 4) || !memcmp(type, "IEND", 4))) {
            for (size_t i = 0; i < nmeta; ++i) o += text_chunk(&meta[i], out + o);
            wrote_meta = 1;
        }
        ended = !memcmp(type, "IEND", 4);
        if (!dropped(type)) {
            memcpy(out + o, src + at, 12 + (size_t)dl);
            o += 12 + (size_t)dl;
        }
        at += 12 + (size_t)dl;
        ++nchunk;
    }
    *data = out;
    *size = o;
    out = NULL;
    rc = 0;
done:
    free(out);
    free(src);
    return rc;
}
