// Single-file readers and the atomic writers of io.hpp: PNG and JPEG (JSON: io_json.cpp, PLY:
// io_ply.cpp).
#include <fcntl.h>
#include <libdeflate.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>  // before jpeglib.h, which needs FILE and size_t
#include <jpeglib.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csetjmp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "io_detail.hpp"
#include "png_format.hpp"
#include "png_encode.hpp"
#include "png_rows.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"

namespace wul3d {

namespace fs = std::filesystem;
using detail::ImageScratch;
using detail::kPngSignature;
using detail::read_be32;
using detail::size_str;

namespace {

// ---- reading bytes --------------------------------------------------------------------

std::atomic<std::uint64_t> g_max_image_pixels{kDefaultMaxImagePixels};

/// What stat() says a path is, for the message that refuses it.
const char* kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

std::string bytes_str(std::uint64_t n) {
    return n % (1u << 20) == 0 ? std::to_string(n >> 20) + " MiB" : std::to_string(n) + " bytes";
}

// ---- PNG integrity --------------------------------------------------------------------
// The chunk structure and every CRC are checked here first, so that a damaged file is
// reported with where it is damaged, and ancillary chunks (which the readers ignore) are
// stripped: libpng then never parses a text or colour profile chunk. libpng is told not to
// compute the CRCs again.

/// CRC-32 of the PNG specification (ISO 3309), over [data, data + n): libdeflate's, the
/// same polynomial with the CPU's carry-less multiply (a table lookup per byte cost a tenth
/// of a frame's read).
std::uint32_t png_crc(const unsigned char* data, std::size_t n) { return libdeflate_crc32(0, data, n); }

bool is_png(const std::vector<unsigned char>& b) {
    return b.size() >= kPngSignature.size() &&
           std::equal(kPngSignature.begin(), kPngSignature.end(), b.begin());
}

bool is_jpeg(const std::vector<unsigned char>& b) {
    return b.size() >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
}

/// Checks the chunk structure and CRCs of the PNG in `bytes`; returns the buffer to decode:
/// `bytes` itself, or `cleaned` (the critical chunks and tRNS only) when it had others.
const std::vector<unsigned char>& check_png(const std::string& path,
                                           const std::vector<unsigned char>& bytes,
                                           std::vector<unsigned char>& cleaned) {
    const std::size_t n = bytes.size();
    std::size_t pos = kPngSignature.size();
    bool ancillary = false, first = true;
    while (true) {
        if (pos + 12 > n) {
            throw InputError(path + ": cannot decode PNG (truncated: the file ends before its IEND chunk)");
        }
        const std::uint32_t len = read_be32(&bytes[pos]);
        if (len > 0x7fffffffu || pos + 12 + len > n) {
            throw InputError(path + ": cannot decode PNG (truncated or corrupt chunk at byte " +
                             std::to_string(pos) + ")");
        }
        const unsigned char* type = &bytes[pos + 4];
        const std::string name(reinterpret_cast<const char*>(type), 4);
        if (png_crc(type, 4 + std::size_t{len}) != read_be32(type + 4 + len)) {
            throw InputError(path + ": cannot decode PNG (CRC error in chunk at byte " +
                             std::to_string(pos) + ", the file is corrupt)");
        }
        if (first && name != "IHDR") {
            throw InputError(path + ": cannot decode PNG (first chunk is not IHDR)");
        }
        first = false;
        if (name != "IHDR" && name != "PLTE" && name != "IDAT" && name != "IEND" && name != "tRNS") {
            ancillary = true;
        }
        pos += 12 + std::size_t{len};
        if (name == "IEND") break;
    }
    if (!ancillary) return bytes;
    cleaned.assign(bytes.begin(), bytes.begin() + kPngSignature.size());
    for (std::size_t p = kPngSignature.size(); p < pos;) {
        const std::size_t chunk = 12 + std::size_t{read_be32(&bytes[p])};
        const std::string name(reinterpret_cast<const char*>(&bytes[p + 4]), 4);
        if (name == "IHDR" || name == "PLTE" || name == "IDAT" || name == "IEND" || name == "tRNS") {
            cleaned.insert(cleaned.end(), bytes.begin() + p, bytes.begin() + p + chunk);
        }
        p += chunk;
    }
    return cleaned;
}

/// A JPEG ends with an EOI marker (FF D9), possibly followed by a little padding.
void check_jpeg(const std::string& path, const std::vector<unsigned char>& bytes) {
    const std::size_t n = bytes.size();
    const std::size_t from = n > 1024 ? n - 1024 : 2;
    for (std::size_t i = n - 1; i > from; --i) {
        if (bytes[i - 1] == 0xff && bytes[i] == 0xd9) return;
    }
    throw InputError(path + ": cannot decode JPEG (truncated: no end-of-image marker)");
}

// ---- decoding: libpng and libjpeg-turbo -------------------------------------------------
// Both libraries report an error through a callback that must not return. Here it keeps the
// message and longjmps back to the setjmp of png_guarded / jpeg_guarded, which then return
// false and the caller throws one InputError naming the file. The frames a longjmp skips
// (the library's, the callback's, the step's lambda) hold no object with a destructor.
// Warnings are dropped, so nothing reaches stderr.
//
// The readers accept what OpenCV's imdecode(IMREAD_UNCHANGED) gave them before, and give
// the same pixels: see PixelFormat.

constexpr std::size_t kMessageSize = 256;

/// The sample depth and channel count of a file as the readers see it (OpenCV's
/// IMREAD_UNCHANGED rules): PNG: 16-bit if the file is, otherwise 8-bit (1, 2 and 4-bit grey
/// scaled to 8 bits); 1 channel for grey (with or without tRNS), 4 for grey + alpha, RGBA,
/// and RGB or palette with tRNS, otherwise 3. JPEG: 8-bit, 1 channel for grey, otherwise 3.
struct PixelFormat {
    int bits = 8;
    int channels = 1;
    bool palette = false;  ///< a PNG of palette indices (channels: what the palette expands to)
};

std::string describe(PixelFormat f) {
    return std::to_string(f.bits) + "-bit " + std::to_string(f.channels) + "-channel";
}

/// What a reader asks a decoder for: row after row, `width` pixels each, no padding.
enum class Layout {
    Gray8,   ///< 8-bit grey (files of 8 or fewer bits, 1 channel)
    Gray16,  ///< 16-bit grey in the host's byte order (16-bit files, 1 channel)
    Rgb8,    ///< 8-bit R, G, B (8-bit files, any channels: grey is copied, alpha dropped)
    Index8,  ///< a palette PNG's indices, one byte each, the palette not applied
};

std::size_t bytes_per_pixel(Layout layout) {
    return layout == Layout::Gray8 || layout == Layout::Index8 ? 1 : layout == Layout::Gray16 ? 2 : 3;
}

/// Points s.rows at the rows of `out`, an image of `width` x `height` in `layout`.
void point_rows(ImageScratch& s, unsigned char* out, std::size_t width, std::size_t height,
                Layout layout) {
    const std::size_t stride = width * bytes_per_pixel(layout);
    s.rows.resize(height);
    for (std::size_t y = 0; y < height; ++y) s.rows[y] = out + y * stride;
}

// -- libpng

/// libpng's error callback: keeps the message (its error pointer is the message buffer)
/// and jumps back to png_guarded.
void png_error_jump(png_structp png, png_const_charp message) {
    std::snprintf(static_cast<char*>(png_get_error_ptr(png)), kMessageSize, "%s", message);
    png_longjmp(png, 1);
}

void png_warning_drop(png_structp, png_const_charp) {}

/// Runs `step`, which calls libpng; false if libpng reported an error.
template <class Step>
bool png_guarded(png_structp png, Step&& step) {
    if (setjmp(png_jmpbuf(png)) != 0) return false;
    step();
    return true;
}

/// The PNG in memory that libpng reads.
struct PngInput {
    const unsigned char* data = nullptr;
    std::size_t size = 0;
    std::size_t pos = 0;
};

void png_read_memory(png_structp png, png_bytep out, std::size_t n) {
    auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
    // check_png saw every chunk up to IEND, where libpng stops: this should never be true,
    // and if it is, an error rather than a read past the buffer.
    if (n > in->size - in->pos) png_error(png, "read past the end of the file");
    std::memcpy(out, in->data + in->pos, n);
    in->pos += n;
}

/// A PNG from memory: its header read on construction, its pixels by read().
class PngDecoder {
public:
    /// `bytes` passed check_png; InputError if the header cannot be read.
    PngDecoder(const std::string& path, const std::vector<unsigned char>& bytes) : path_(path) {
        input_.data = bytes.data();
        input_.size = bytes.size();
        h_.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, message_, png_error_jump,
                                        png_warning_drop);
        if (h_.png != nullptr) h_.info = png_create_info_struct(h_.png);
        if (h_.png == nullptr || h_.info == nullptr) fail("cannot start libpng");
        png_structp png = h_.png;
        png_infop info = h_.info;
        const bool ok = png_guarded(png, [&] {
            png_set_read_fn(png, &input_, png_read_memory);
            // check_png has checked every CRC: libpng need not compute them again, nor zlib
            // the Adler-32 of the inflated pixels (the CRCs cover the bytes they come from).
            png_set_crc_action(png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);
            png_set_option(png, PNG_IGNORE_ADLER32, PNG_OPTION_ON);
            png_read_info(png, info);
            png_get_IHDR(png, info, &width_, &height_, &bit_depth_, &color_type_, &interlace_,
                         nullptr, nullptr);
            png_bytep trans = nullptr;
            png_color_16p trans_color = nullptr;
            if (png_get_tRNS(png, info, &trans, &num_trans_, &trans_color) == 0) num_trans_ = 0;
        });
        if (!ok) fail();
    }
    PngDecoder(const PngDecoder&) = delete;
    PngDecoder& operator=(const PngDecoder&) = delete;

    std::size_t width() const { return width_; }
    std::size_t height() const { return height_; }

    PixelFormat format() const {
        PixelFormat f;
        f.bits = bit_depth_ == 16 ? 16 : 8;
        f.palette = color_type_ == PNG_COLOR_TYPE_PALETTE;
        switch (color_type_) {
            case PNG_COLOR_TYPE_RGB:
            case PNG_COLOR_TYPE_PALETTE: f.channels = num_trans_ > 0 ? 4 : 3; break;
            case PNG_COLOR_TYPE_GRAY_ALPHA:
            case PNG_COLOR_TYPE_RGB_ALPHA: f.channels = 4; break;
            default: f.channels = 1;
        }
        return f;
    }

    /// Decodes into `out` (width() x height() in `layout`, which fits format(): Gray16 for
    /// 16 bits and 1 channel, Gray8 for 8 bits and 1 channel, Rgb8 for 8 bits).
    void read(Layout layout, unsigned char* out, ImageScratch& s) {
        if (own_kind(layout) &&
            detail::decode_png_rows(input_.data, input_.size, width_, height_,
                                    static_cast<int>(bytes_per_pixel(layout)), out, s))
            return;
        point_rows(s, out, width_, height_, layout);
        const bool gray = (color_type_ & PNG_COLOR_MASK_COLOR) == 0;
        const std::size_t row_bytes = width_ * bytes_per_pixel(layout);
        png_structp png = h_.png;
        png_infop info = h_.info;
        const bool ok = png_guarded(png, [&] {
            if (layout == Layout::Index8) {
                if (bit_depth_ < 8) png_set_packing(png);  // 1, 2 or 4 bits: one byte each
            } else if (color_type_ == PNG_COLOR_TYPE_PALETTE) {
                png_set_palette_to_rgb(png);
            }
            if (gray && bit_depth_ < 8) png_set_expand_gray_1_2_4_to_8(png);
            if (gray && layout == Layout::Rgb8) png_set_gray_to_rgb(png);
            png_set_strip_alpha(png);  // also the alpha that palette expansion makes of tRNS
            if (bit_depth_ == 16 && std::endian::native == std::endian::little) png_set_swap(png);
            png_set_interlace_handling(png);
            png_read_update_info(png, info);
            if (png_get_rowbytes(png, info) != row_bytes) {
                png_error(png, "unexpected row size after conversion");  // a bug, not a file
            }
            png_read_image(png, s.rows.data());
            png_read_end(png, nullptr);
        });
        if (!ok) fail();
    }

private:
    [[noreturn]] void fail(const char* why = nullptr) const {
        throw InputError(path_ + ": cannot decode PNG (" + (why ? why : message_) + ")");
    }

    /// Whether `layout` is the file's own kind, one decode_png_rows takes: 8-bit grey, 16-bit
    /// grey or 8-bit RGB, not interlaced (a frame's colour, depth and labels).
    bool own_kind(Layout layout) const {
        if (interlace_ != PNG_INTERLACE_NONE) return false;
        if (color_type_ == PNG_COLOR_TYPE_GRAY)
            return (bit_depth_ == 8 && layout == Layout::Gray8) || (bit_depth_ == 16 && layout == Layout::Gray16);
        return color_type_ == PNG_COLOR_TYPE_RGB && bit_depth_ == 8 && layout == Layout::Rgb8;
    }

    struct Handles {
        png_structp png = nullptr;
        png_infop info = nullptr;
        ~Handles() { png_destroy_read_struct(&png, &info, nullptr); }
    };

    const std::string& path_;
    PngInput input_;
    char message_[kMessageSize] = "";
    Handles h_;
    png_uint_32 width_ = 0, height_ = 0;
    int bit_depth_ = 0, color_type_ = 0, interlace_ = 0, num_trans_ = 0;
};

// -- libjpeg-turbo

/// libjpeg's error manager with where to jump back to and the message.
struct JpegErrors {
    jpeg_error_mgr mgr;  // first: libjpeg hands &mgr to the callbacks
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

void jpeg_error_jump(j_common_ptr cinfo) {
    auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, errors->message);
    std::longjmp(errors->jump, 1);
}

void jpeg_message_drop(j_common_ptr) {}

/// Runs `step`, which calls libjpeg; false if libjpeg reported an error.
template <class Step>
bool jpeg_guarded(JpegErrors& errors, Step&& step) {
    if (setjmp(errors.jump) != 0) return false;
    step();
    return true;
}

/// CMYK as libjpeg gives it (Adobe's inverted CMYK, as Photoshop writes it) to RGB, with
/// the arithmetic OpenCV used: R = K - (255 - C) K / 256, G from M, B from Y likewise.
void cmyk_to_rgb(const unsigned char* cmyk, unsigned char* rgb, std::size_t width) {
    for (std::size_t x = 0; x < width; ++x, cmyk += 4, rgb += 3) {
        const int k = cmyk[3];
        for (int c = 0; c < 3; ++c) rgb[c] = static_cast<unsigned char>(k - (((255 - cmyk[c]) * k) >> 8));
    }
}

/// A JPEG from memory: its header read on construction, its pixels by read_rgb().
class JpegDecoder {
public:
    /// `bytes` passed check_jpeg; InputError if the header cannot be read.
    JpegDecoder(const std::string& path, const std::vector<unsigned char>& bytes) : path_(path) {
        jpeg_decompress_struct& cinfo = h_.cinfo;
        cinfo.err = jpeg_std_error(&h_.errors.mgr);
        h_.errors.mgr.error_exit = jpeg_error_jump;
        h_.errors.mgr.output_message = jpeg_message_drop;
        const bool ok = jpeg_guarded(h_.errors, [&] {
            jpeg_create_decompress(&cinfo);
            jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
            jpeg_read_header(&cinfo, TRUE);
        });
        if (!ok) fail(h_.errors.message);
        // The header's values, kept: a second frame header met while finishing the decode
        // rewrites cinfo's (a fuzzed file gave 0 x 55296 after a 80 x 60 decode).
        width_ = cinfo.image_width;
        height_ = cinfo.image_height;
        components_ = cinfo.num_components;
    }
    JpegDecoder(const JpegDecoder&) = delete;
    JpegDecoder& operator=(const JpegDecoder&) = delete;

    std::size_t width() const { return width_; }
    std::size_t height() const { return height_; }
    PixelFormat format() const { return {8, components_ > 1 ? 3 : 1}; }

    /// Decodes into `out`, width() x height() RGB: grey copied to the three channels, CMYK
    /// converted.
    void read_rgb(unsigned char* out, ImageScratch& s) {
        jpeg_decompress_struct& cinfo = h_.cinfo;
        const bool cmyk = components_ == 4;
        const std::size_t w = width(), h = height();
        point_rows(s, out, w, h, Layout::Rgb8);
        if (cmyk) s.pixels.resize(4 * w);
        unsigned char* const cmyk_row = s.pixels.data();
        const char* why = nullptr;
        const bool ok = jpeg_guarded(h_.errors, [&] {
            cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_RGB;
            jpeg_start_decompress(&cinfo);
            if (cinfo.output_width != w || cinfo.output_height != h ||
                cinfo.output_components != (cmyk ? 4 : 3)) {
                why = "unexpected output size";  // a bug, not a file
                return;
            }
            while (cinfo.output_scanline < h) {
                const std::size_t y = cinfo.output_scanline;
                JDIMENSION got;
                if (cmyk) {
                    JSAMPROW row = cmyk_row;
                    got = jpeg_read_scanlines(&cinfo, &row, 1);
                    if (got == 1) cmyk_to_rgb(cmyk_row, s.rows[y], w);
                } else {
                    got = jpeg_read_scanlines(&cinfo, s.rows.data() + y, static_cast<JDIMENSION>(h - y));
                }
                if (got == 0) {
                    why = "no progress in the image data";  // only a suspending source stops
                    return;
                }
            }
        });
        if (!ok) fail(h_.errors.message);
        if (why != nullptr) fail(why);
        // What follows the last row (up to the end-of-image marker) does not change the
        // pixels: an error there is ignored, as OpenCV did.
        jpeg_guarded(h_.errors, [&] { jpeg_finish_decompress(&cinfo); });
    }

private:
    [[noreturn]] void fail(const char* why) const {
        throw InputError(path_ + ": cannot decode JPEG (" + why + ")");
    }

    struct Handles {
        jpeg_decompress_struct cinfo{};
        JpegErrors errors{};
        ~Handles() { jpeg_destroy_decompress(&cinfo); }
    };

    const std::string& path_;
    Handles h_;
    std::size_t width_ = 0, height_ = 0;
    int components_ = 0;
};

// -- the file

/// The image limits (io.hpp), checked from the header, before the pixels are allocated.
void check_size(const std::string& path, std::size_t w, std::size_t h) {
    if (w == 0 || h == 0) {
        throw InputError(path + ": cannot decode (an image of " + std::to_string(w) + "x" +
                         std::to_string(h) + " pixels is empty)");
    }
    const std::uint64_t limit = max_image_pixels();
    if (w > kMaxImageSide || h > kMaxImageSide || std::uint64_t{w} * h > limit) {
        throw InputError(path + ": image of " + std::to_string(w) + "x" + std::to_string(h) +
                         " pixels is larger than the limit of " + std::to_string(limit) +
                         " pixels and " + std::to_string(kMaxImageSide) +
                         " a side (--max-pixels raises it)");
    }
}

/// A PNG or JPEG file read and checked, its header decoded; its pixels by read().
class ImageFile {
public:
    /// PNG only unless allow_jpeg. InputError if missing, not a PNG (or JPEG), damaged.
    ImageFile(const std::string& path, ImageScratch& s, bool allow_jpeg) : path_(path), s_(s) {
        detail::read_regular_file(path, max_image_file_bytes(), s.bytes);
        open(allow_jpeg);
    }
    /// An image already in `s.bytes` (a compressed image of a bag); `path` names it in errors.
    struct InMemory {};
    ImageFile(const std::string& path, ImageScratch& s, bool allow_jpeg, InMemory)
        : path_(path), s_(s) {
        if (s.bytes.size() > max_image_file_bytes())
            throw InputError(path + ": compressed image of " + bytes_str(s.bytes.size()) +
                             " is over the limit of " + bytes_str(max_image_file_bytes()));
        open(allow_jpeg);
    }

    std::size_t width() const { return png_ ? png_->width() : jpeg_->width(); }
    std::size_t height() const { return png_ ? png_->height() : jpeg_->height(); }
    std::size_t pixels() const { return width() * height(); }
    PixelFormat format() const { return png_ ? png_->format() : jpeg_->format(); }

    /// Decodes into `out` (pixels() in `layout`, which must fit format(); a JPEG gives Rgb8).
    void read(Layout layout, unsigned char* out) {
        if (png_) {
            png_->read(layout, out, s_);
        } else if (layout == Layout::Rgb8) {
            jpeg_->read_rgb(out, s_);
        } else {
            throw std::logic_error(path_ + ": a JPEG is decoded to RGB only");
        }
    }

private:
    void open(bool allow_jpeg) {
        const std::string& path = path_;
        ImageScratch& s = s_;
        if (is_png(s.bytes)) {
            png_.emplace(path, check_png(path, s.bytes, s.cleaned));
        } else if (allow_jpeg && is_jpeg(s.bytes)) {
            check_jpeg(path, s.bytes);
            jpeg_.emplace(path, s.bytes);
        } else {
            throw InputError(path + (allow_jpeg ? ": cannot decode (not a PNG or JPEG file)"
                                                : ": cannot decode (not a PNG file)"));
        }
        check_size(path, width(), height());
    }

    const std::string& path_;
    ImageScratch& s_;
    std::optional<PngDecoder> png_;
    std::optional<JpegDecoder> jpeg_;
};

/// Runs `decode`, which fills `data`; if it throws, the image is left empty (rather than
/// half of the new frame under the old size) and the error goes on.
template <class Image, class Data, class Decode>
void decode_or_clear(Image& image, Data& data, Decode&& decode) {
    try {
        decode();
    } catch (...) {
        image.width = image.height = 0;
        data.clear();
        throw;
    }
}

// ---- writing ------------------------------------------------------------------------

/// Encodes `height` rows of `width` pixels at `pixels`, each 8-bit grey, 8-bit RGB
/// (channels 3) or 16-bit grey in the host's byte order (bits 16), to PNG with `encoder`,
/// and writes `path` atomically. IoError names the path.
void write_png(const std::string& path, int width, int height, int bits, int channels, const void* pixels,
               detail::PngContent content, detail::PngEncoder& encoder) {
    std::vector<unsigned char> encoded;
    try {
        encoder.encode(width, height, bits, channels, pixels, content, encoded);
    } catch (const IoError& e) {
        throw IoError(path + ": " + e.what());
    }
    write_file_atomic(path, encoded.data(), encoded.size());
}

void check_buffer(const std::string& path, const char* what, int w, int h, std::size_t have,
                  std::size_t per_pixel) {
    if (w <= 0 || h <= 0 || have != static_cast<std::size_t>(w) * h * per_pixel) {
        throw IoError(path + ": cannot write " + what + " of " + size_str(w, h) + " from " +
                      std::to_string(have) + " values");
    }
}

}  // namespace

// ---- limits -------------------------------------------------------------------------

void set_max_image_pixels(std::uint64_t pixels) {
    if (pixels < 1 || pixels > kMaxImagePixelsCeiling)
        throw ParamError("--max-pixels " + std::to_string(pixels) + ": must be in [1, " +
                         std::to_string(kMaxImagePixelsCeiling) + "]");
    g_max_image_pixels.store(pixels, std::memory_order_relaxed);
}

std::uint64_t max_image_pixels() { return g_max_image_pixels.load(std::memory_order_relaxed); }

std::uint64_t max_image_file_bytes() { return (std::uint64_t{64} << 20) + 8 * max_image_pixels(); }

// ---- detail: readers into reused buffers ---------------------------------------------

namespace detail {

void read_regular_file(const std::string& path, std::uint64_t max_bytes,
                       std::vector<unsigned char>& bytes) {
    // The type first, by stat(), so that a FIFO or device is never opened: opening a FIFO
    // for reading blocks until a writer comes. O_NONBLOCK and fstat() then close the race of
    // a path replaced between the two calls.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw InputError(path + ": no such file");
        throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
    }
    if (!S_ISREG(st.st_mode))
        throw InputError(path + ": is " + kind_of(st.st_mode) + ", expected a regular file");
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        throw InputError(path + ": is " + kind_of(st.st_mode) + ", expected a regular file");
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size > max_bytes)
        throw InputError(path + ": is " + bytes_str(size) + ", more than the " +
                         bytes_str(max_bytes) + " accepted for this file");
    bytes.resize(static_cast<std::size_t>(size));
    std::size_t got = 0;
    while (got < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
        if (n == 0) throw InputError(path + ": cannot read (the file shrank while read)");
        got += static_cast<std::size_t>(n);
    }
}

void read_depth_png_into(const std::string& path, float scale_m_per_unit, ImageScratch& s,
                         DepthImage& out, const HeaderCheck& check) {
    ImageFile file(path, s, false);
    const PixelFormat f = file.format();
    if (f.bits != 16 || f.channels != 1) {
        throw InputError(path + ": depth must be 16-bit single-channel PNG, got " + describe(f) +
                         " (8-bit depth has no known units)");
    }
    if (check) check(static_cast<int>(file.width()), static_cast<int>(file.height()));
    out.data.resize(file.pixels());
    decode_or_clear(out, out.data, [&] {
        file.read(Layout::Gray16, reinterpret_cast<unsigned char*>(out.data.data()));
    });
    out.width = static_cast<int>(file.width());
    out.height = static_cast<int>(file.height());
    out.scale_m_per_unit = scale_m_per_unit;
}

namespace {

/// Colour of an opened PNG or JPEG: 8-bit grey, RGB or RGBA, into RGB; `check` sees its size
/// before anything is decoded.
void decode_color(const std::string& path, ImageFile& file, ColorImage& out,
                  const HeaderCheck& check) {
    const PixelFormat f = file.format();
    if (f.bits != 8 || (f.channels != 1 && f.channels != 3 && f.channels != 4)) {
        throw InputError(path + ": colour must be 8-bit grey, RGB or RGBA, got " + describe(f));
    }
    if (check) check(static_cast<int>(file.width()), static_cast<int>(file.height()));
    out.rgb.resize(3 * file.pixels());
    decode_or_clear(out, out.rgb, [&] { file.read(Layout::Rgb8, out.rgb.data()); });
    out.width = static_cast<int>(file.width());
    out.height = static_cast<int>(file.height());
}

}  // namespace

void read_color_image_into(const std::string& path, ImageScratch& s, ColorImage& out,
                           const HeaderCheck& check) {
    ImageFile file(path, s, true);
    decode_color(path, file, out, check);
}

void decode_color_image_into(const std::string& what, ImageScratch& s, ColorImage& out) {
    ImageFile file(what, s, true, ImageFile::InMemory{});
    decode_color(what, file, out, {});
}

void read_label_png_into(const std::string& path, ImageScratch& s, LabelImage& out) {
    ImageFile file(path, s, false);
    const PixelFormat f = file.format();
    // 8-bit labels are accepted too: ids, unlike depth, have no units to get wrong. So are a
    // palette PNG's indices (PASCAL VOC's and many datasets' annotations): the index is the id,
    // the palette only shows it.
    if (!f.palette && ((f.bits != 16 && f.bits != 8) || f.channels != 1)) {
        throw InputError(path + ": labels must be 16-bit single-channel PNG, got " + describe(f));
    }
    out.labels.resize(file.pixels());
    decode_or_clear(out, out.labels, [&] {
        if (f.bits == 16) {
            file.read(Layout::Gray16, reinterpret_cast<unsigned char*>(out.labels.data()));
        } else {
            s.pixels.resize(file.pixels());
            file.read(f.palette ? Layout::Index8 : Layout::Gray8, s.pixels.data());
            std::copy(s.pixels.begin(), s.pixels.end(), out.labels.begin());
        }
    });
    out.width = static_cast<int>(file.width());
    out.height = static_cast<int>(file.height());
}

}  // namespace detail

// ---- single files -------------------------------------------------------------------

DepthImage read_depth_png(const std::string& path, float scale_m_per_unit) {
    ImageScratch s;
    DepthImage out;
    detail::read_depth_png_into(path, scale_m_per_unit, s, out);
    return out;
}

ColorImage read_color_image(const std::string& path) {
    ImageScratch s;
    ColorImage out;
    detail::read_color_image_into(path, s, out);
    return out;
}

LabelImage read_label_png(const std::string& path) {
    ImageScratch s;
    LabelImage out;
    detail::read_label_png_into(path, s, out);
    return out;
}

// ---- outputs ------------------------------------------------------------------------

namespace detail {

void write_label_png(const std::string& path, const LabelImage& labels, PngEncoder& encoder) {
    check_buffer(path, "labels", labels.width, labels.height, labels.labels.size(), 1);
    write_png(path, labels.width, labels.height, 16, 1, labels.labels.data(), PngContent::Regions, encoder);
}

void write_color_png(const std::string& path, const ColorImage& image, PngEncoder& encoder) {
    check_buffer(path, "a colour image", image.width, image.height, image.rgb.size(), 3);
    write_png(path, image.width, image.height, 8, 3, image.rgb.data(), PngContent::Picture, encoder);
}

void write_mask_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& mask,
                    PngEncoder& encoder) {
    check_buffer(path, "a mask", width, height, mask.size(), 1);
    // Any non-zero entry is written as 255, so the mask is visible in an image viewer.
    std::vector<std::uint8_t> visible(mask.size());
    std::transform(mask.begin(), mask.end(), visible.begin(),
                   [](std::uint8_t m) { return static_cast<std::uint8_t>(m ? 255 : 0); });
    write_png(path, width, height, 8, 1, visible.data(), PngContent::Regions, encoder);
}

}  // namespace detail

void write_label_png(const std::string& path, const LabelImage& labels) {
    detail::PngEncoder encoder;
    detail::write_label_png(path, labels, encoder);
}

void write_color_png(const std::string& path, const ColorImage& image) {
    detail::PngEncoder encoder;
    detail::write_color_png(path, image, encoder);
}

void write_mask_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& mask) {
    detail::PngEncoder encoder;
    detail::write_mask_png(path, width, height, mask, encoder);
}

void write_depth_png(const std::string& path, const DepthImage& depth) {
    check_buffer(path, "a depth image", depth.width, depth.height, depth.data.size(), 1);
    detail::PngEncoder encoder;
    write_png(path, depth.width, depth.height, 16, 1, depth.data.data(), detail::PngContent::Picture, encoder);
}

void write_text_file(const std::string& path, const std::string& text) {
    write_file_atomic(path, text.data(), text.size());
}

}  // namespace wul3d
