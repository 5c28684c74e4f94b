// lbimageio: blendtool's images through OpenImageIO (lbimageio.h).
#include "lbimageio.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace OIIO;

namespace {

int fail(char *err, size_t errlen, const std::string &msg) {
    if (err && errlen) std::snprintf(err, errlen, "%s", msg.c_str());
    return -1;
}

const char *ext_of(lbi_format f) {
    return f == LBI_PNG8 || f == LBI_PNG16 ? "out.png" : "out.exr";
}

// write buf as format into a malloc'd buffer
int write_buf(const ImageBuf &buf, lbi_format format, const lbi_meta *meta, size_t nmeta,
              unsigned char **data, size_t *size, char *err, size_t errlen) {
    const TypeDesc type = format == LBI_PNG8       ? TypeDesc::UINT8
                          : format == LBI_PNG16    ? TypeDesc::UINT16
                          : format == LBI_EXR_HALF ? TypeDesc::HALF
                                                   : TypeDesc::FLOAT;
    const ImageSpec &src = buf.spec();
    // a fresh spec: no metadata from the input (POV-Ray's PNGs carry a date)
    ImageSpec spec(src.width, src.height, src.nchannels, type);
    spec.channelnames = src.channelnames;
    spec.alpha_channel = src.alpha_channel;
    if (format == LBI_EXR_HALF || format == LBI_EXR_FLOAT) {
        spec.attribute("compression", "zip");
        // OpenImageIO's EXR writer stamps the current time as capDate unless
        // DateTime is set: an empty one keeps the bytes the same every run
        spec.attribute("DateTime", "");
    }
    if (format == LBI_PNG8 || format == LBI_PNG16) spec.attribute("png:compressionLevel", 9);
    spec.attribute("Software", "libblend");
    for (size_t i = 0; i < nmeta; ++i)
        if (meta[i].key && meta[i].value) spec.attribute(meta[i].key, meta[i].value);
    std::vector<unsigned char> bytes;
    Filesystem::IOVecOutput proxy(bytes);
    auto out = ImageOutput::create(ext_of(format));
    if (!out)
        return fail(err, errlen, "OpenImageIO has no writer for " + std::string(ext_of(format)));
    if (!out->supports("ioproxy"))
        return fail(err, errlen, "OpenImageIO's writer cannot write to memory");
    out->set_ioproxy(&proxy);
    if (!out->open(ext_of(format), spec))
        return fail(err, errlen, "OpenImageIO: " + out->geterror());
    std::vector<float> px((size_t)src.width * src.height * src.nchannels);
    if (!buf.get_pixels(buf.roi(), TypeDesc::FLOAT, px.data()) ||
        !out->write_image(TypeDesc::FLOAT, px.data()) || !out->close())
        return fail(err, errlen, "OpenImageIO: " + out->geterror());
    *size = bytes.size();
    *data = static_cast<unsigned char *>(std::malloc(bytes.size() ? bytes.size() : 1));
    if (!*data) return fail(err, errlen, "out of memory");
    if (!bytes.empty()) std::memcpy(*data, bytes.data(), bytes.size());
    return 0;
}

// RGB, or RGBA when keep_alpha and the image has a fourth channel
int read_rgb(const char *path, bool keep_alpha, ImageBuf &out, char *err, size_t errlen) {
    ImageBuf in(path);
    if (!in.read(0, 0, true, TypeDesc::FLOAT))
        return fail(err, errlen, std::string(path) + ": " + in.geterror());
    const int nc = in.spec().nchannels;
    const int want = keep_alpha && nc >= 4 ? 4 : 3;
    if (nc == want) {
        out = in;
    } else {
        int order[4] = {0, nc > 1 ? 1 : 0, nc > 2 ? 2 : 0, nc > 3 ? 3 : -1};
        float fill[4] = {0, 0, 0, 1};
        out = ImageBufAlgo::channels(in, want, order, fill);
        if (out.has_error()) return fail(err, errlen, std::string(path) + ": " + out.geterror());
    }
    return 0;
}

} // namespace

extern "C" int lbi_convert(const char *in, lbi_format format, int alpha, const lbi_meta *meta,
                           size_t nmeta, unsigned char **data, size_t *size, char *err,
                           size_t errlen) {
    if (!in || !data || !size) return fail(err, errlen, "lbi_convert: NULL argument");
    ImageBuf buf;
    if (read_rgb(in, alpha != 0, buf, err, errlen)) return -1;
    if (format == LBI_EXR_HALF || format == LBI_EXR_FLOAT) {
        // EXR holds linear light: POV-Ray's PNG is sRGB-encoded
        ImageBuf lin = ImageBufAlgo::colorconvert(buf, "sRGB", "linear", true);
        if (lin.has_error()) return fail(err, errlen, "OpenImageIO: " + lin.geterror());
        return write_buf(lin, format, meta, nmeta, data, size, err, errlen);
    }
    return write_buf(buf, format, meta, nmeta, data, size, err, errlen);
}

extern "C" int lbi_contact_sheet(const char *const *images, const char *const *labels, size_t n,
                                 int columns, int cell_w, int cell_h, lbi_format format,
                                 const lbi_meta *meta, size_t nmeta, unsigned char **data,
                                 size_t *size, char *err, size_t errlen) {
    if (!images || !data || !size || n == 0 || columns < 1 || cell_w < 8 || cell_h < 8)
        return fail(err, errlen, "lbi_contact_sheet: no images or a bad grid");
    const int pad = 4, label_h = 18;
    const int rows = (int)((n + (size_t)columns - 1) / (size_t)columns);
    const int cols = n < (size_t)columns ? (int)n : columns;
    const int W = pad + cols * (cell_w + pad), H = pad + rows * (cell_h + label_h + pad);
    ImageBuf sheet(ImageSpec(W, H, 3, TypeDesc::FLOAT));
    const float ground[3] = {0.12f, 0.12f, 0.12f};
    ImageBufAlgo::fill(sheet, ground);
    const char *font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    for (size_t i = 0; i < n; ++i) {
        ImageBuf img;
        if (read_rgb(images[i], false, img, err, errlen)) return -1;
        // the sheet is an sRGB-encoded image: linear light (EXR outputs)
        // is encoded as sRGB first, or it shows far too dark
        const std::string cs = img.spec().get_string_attribute("oiio:ColorSpace");
        if (Strutil::iequals(cs, "linear") || Strutil::iequals(cs, "lin_srgb") ||
            Strutil::iequals(cs, "scene_linear") ||
            (cs.empty() && Strutil::iequals(img.file_format_name(), "openexr"))) {
            img = ImageBufAlgo::colorconvert(img, "linear", "sRGB", true);
            if (img.has_error())
                return fail(err, errlen, images[i] + std::string(": ") + img.geterror());
        }
        ImageBuf cell = ImageBufAlgo::resize(img, "", 0.0f, ROI(0, cell_w, 0, cell_h, 0, 1, 0, 3));
        if (cell.has_error())
            return fail(err, errlen, images[i] + std::string(": ") + cell.geterror());
        const int x = pad + (int)(i % (size_t)columns) * (cell_w + pad);
        const int y = pad + (int)(i / (size_t)columns) * (cell_h + label_h + pad);
        if (!ImageBufAlgo::paste(sheet, x, y, 0, 0, cell))
            return fail(err, errlen, "OpenImageIO: " + sheet.geterror());
        if (labels && labels[i] && *labels[i]) {
            const float white[3] = {0.9f, 0.9f, 0.9f};
            if (!ImageBufAlgo::render_text(sheet, x + 2, y + cell_h + 14, labels[i], 12, font,
                                           white))
                return fail(err, errlen,
                            "OpenImageIO text (font " + std::string(font) +
                                ", Debian package fonts-dejavu-core): " + sheet.geterror());
        }
    }
    return write_buf(sheet, format, meta, nmeta, data, size, err, errlen);
}

extern "C" void lbi_set_threads(int n) {
    // OpenImageIO's pool: the caller plus n - 1 workers (0: one per CPU)
    OIIO::attribute("threads", n);
    // OpenEXR's pool: -1 none (the calling thread), 0 one per CPU, else n
    OIIO::attribute("exr_threads", n == 1 ? -1 : n);
}

extern "C" int lbi_write_pixels(const float *rgb, int w, int h, const lbi_text *texts,
                                size_t ntexts, lbi_format format, const lbi_meta *meta,
                                size_t nmeta, unsigned char **data, size_t *size, char *err,
                                size_t errlen) {
    if (!rgb || !data || !size || w < 1 || h < 1 || (double)w * (double)h > (double)LBI_MAX_PIXELS)
        return fail(err, errlen, "lbi_write_pixels: no pixels or a bad size");
    ImageBuf buf(ImageSpec(w, h, 3, TypeDesc::FLOAT), (void *)rgb);
    ImageBuf img(buf.spec());
    if (!ImageBufAlgo::copy(img, buf)) return fail(err, errlen, "OpenImageIO: " + img.geterror());
    const char *font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    for (size_t i = 0; i < ntexts; ++i) {
        if (!texts || !texts[i].text || !*texts[i].text) continue;
        if (!ImageBufAlgo::render_text(img, texts[i].x, texts[i].y, texts[i].text, texts[i].size,
                                       font, texts[i].rgb))
            return fail(err, errlen,
                        "OpenImageIO text (font " + std::string(font) +
                            ", Debian package fonts-dejavu-core): " + img.geterror());
    }
    return write_buf(img, format, meta, nmeta, data, size, err, errlen);
}

extern "C" int lbi_compare(const char *a, const char *b, double failv, double *max_error,
                           double *mean_error, double *fail_percent, char *err, size_t errlen) {
    if (!a || !b) return fail(err, errlen, "lbi_compare: NULL argument");
    // the headers first: sizes checked before any pixel is decoded, so a
    // small file declaring a huge image costs nothing
    ImageSpec ha, hb;
    for (int i = 0; i < 2; ++i) {
        const char *path = i ? b : a;
        auto in = ImageInput::open(path);
        if (!in) return fail(err, errlen, std::string(path) + ": " + OIIO::geterror());
        (i ? hb : ha) = in->spec();
        in->close();
        const ImageSpec &h = i ? hb : ha;
        const double px = (double)h.width * (double)h.height * (double)(h.depth > 0 ? h.depth : 1);
        if (h.width < 1 || h.height < 1 || px > (double)LBI_MAX_PIXELS || h.nchannels < 1 ||
            h.nchannels > LBI_MAX_CHANNELS)
            return fail(err, errlen,
                        std::string(path) + ": declares " + std::to_string(h.width) + "x" +
                            std::to_string(h.height) + " pixels of " + std::to_string(h.nchannels) +
                            " channels; allowed: at most " + std::to_string(LBI_MAX_PIXELS) +
                            " pixels and " + std::to_string(LBI_MAX_CHANNELS) + " channels");
    }
    if (ha.width != hb.width || ha.height != hb.height || ha.nchannels != hb.nchannels)
        return fail(err, errlen,
                    std::string("the images differ in size: ") + a + " is " +
                        std::to_string(ha.width) + "x" + std::to_string(ha.height) + "x" +
                        std::to_string(ha.nchannels) + ", " + b + " is " +
                        std::to_string(hb.width) + "x" + std::to_string(hb.height) + "x" +
                        std::to_string(hb.nchannels));
    ImageBuf A(a), B(b);
    if (!A.read(0, 0, true, TypeDesc::FLOAT))
        return fail(err, errlen, std::string(a) + ": " + A.geterror());
    if (!B.read(0, 0, true, TypeDesc::FLOAT))
        return fail(err, errlen, std::string(b) + ": " + B.geterror());
    const ImageSpec &sa = A.spec(), &sb = B.spec();
    if (sa.width != sb.width || sa.height != sb.height || sa.nchannels != sb.nchannels)
        return fail(err, errlen,
                    std::string("the images differ in size: ") + a + " is " +
                        std::to_string(sa.width) + "x" + std::to_string(sa.height) + "x" +
                        std::to_string(sa.nchannels) + ", " + b + " is " +
                        std::to_string(sb.width) + "x" + std::to_string(sb.height) + "x" +
                        std::to_string(sb.nchannels));
    // (r.error also marks a comparison with failures: the counts are what matter)
    const auto r = ImageBufAlgo::compare(A, B, (float)failv, (float)failv);
    if (max_error) *max_error = r.maxerror;
    if (mean_error) *mean_error = r.meanerror;
    if (fail_percent)
        *fail_percent = 100.0 * (double)r.nfail / ((double)sa.width * (double)sa.height);
    return 0;
}
