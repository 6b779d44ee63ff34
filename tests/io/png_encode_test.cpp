// The PNG encoder (src/io/png_encode.cpp), read back by libpng itself rather than by wul3d's
// reader (whose own decoder could share a mistake with the encoder): every kind wul3d writes,
// both ways to compress, odd sizes, runs of every length.
#include <gtest/gtest.h>
#include <png.h>

#include <csetjmp>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "io/png_encode.hpp"
#include "wul3d/error.hpp"

namespace {

/// The PNG in `bytes` as libpng reads it, untransformed: width, height, bit depth, colour
/// type, and the rows as the file holds them (16-bit samples big-endian).
struct LibpngImage {
    png_uint_32 width = 0, height = 0;
    int bit_depth = 0, color_type = 0;
    std::vector<unsigned char> rows;
};

struct Reader {
    const std::vector<unsigned char>* bytes;
    std::size_t pos = 0;
};

void read_fn(png_structp png, png_bytep out, png_size_t n) {
    auto* r = static_cast<Reader*>(png_get_io_ptr(png));
    if (r->pos + n > r->bytes->size()) png_error(png, "read past the end");
    std::memcpy(out, r->bytes->data() + r->pos, n);
    r->pos += n;
}

bool read_with_libpng(const std::vector<unsigned char>& bytes, LibpngImage& image) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    Reader reader{&bytes};
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return false;
    }
    png_set_read_fn(png, &reader, read_fn);
    png_read_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    png_get_IHDR(png, info, &image.width, &image.height, &image.bit_depth, &image.color_type, nullptr, nullptr,
                 nullptr);
    const std::size_t row_bytes = png_get_rowbytes(png, info);
    png_bytepp rows = png_get_rows(png, info);
    image.rows.clear();
    for (png_uint_32 y = 0; y < image.height; ++y) image.rows.insert(image.rows.end(), rows[y], rows[y] + row_bytes);
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
}

/// The IDAT chunks of `bytes`.
int count_idat(const std::vector<unsigned char>& bytes) {
    int n = 0;
    for (std::size_t pos = 8; pos + 8 <= bytes.size();) {
        const std::size_t len = (std::size_t{bytes[pos]} << 24) | (std::size_t{bytes[pos + 1]} << 16) |
                                (std::size_t{bytes[pos + 2]} << 8) | bytes[pos + 3];
        n += std::memcmp(&bytes[pos + 4], "IDAT", 4) == 0;
        pos += 12 + len;
    }
    return n;
}

using wul3d::detail::PngContent;
using wul3d::detail::PngEncoder;

/// An image's samples, 8- or 16-bit, and what libpng reads back for them.
struct Samples {
    int bits = 8;
    std::vector<unsigned char> narrow;
    std::vector<std::uint16_t> wide;
    const void* data() const { return bits == 16 ? static_cast<const void*>(wide.data()) : narrow.data(); }
    /// The rows as the file holds them (16-bit big-endian).
    std::vector<unsigned char> file_rows() const {
        if (bits != 16) return narrow;
        std::vector<unsigned char> rows;
        for (const std::uint16_t v : wide) {
            rows.push_back(static_cast<unsigned char>(v >> 8));
            rows.push_back(static_cast<unsigned char>(v));
        }
        return rows;
    }
};

/// Encodes `image` (w x h, `channels`) with `encoder` and reads it back with libpng: the same
/// size, kind and samples, in one IDAT chunk. Returns the file.
std::vector<unsigned char> round_trip(PngEncoder& encoder, const Samples& image, int w, int h, int channels,
                                      PngContent content) {
    std::vector<unsigned char> png;
    encoder.encode(w, h, image.bits, channels, image.data(), content, png);
    LibpngImage back;
    EXPECT_TRUE(read_with_libpng(png, back));
    EXPECT_EQ(back.width, static_cast<png_uint_32>(w));
    EXPECT_EQ(back.height, static_cast<png_uint_32>(h));
    EXPECT_EQ(back.bit_depth, image.bits);
    EXPECT_EQ(back.color_type, channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY);
    EXPECT_EQ(back.rows, image.file_rows());
    EXPECT_EQ(count_idat(png), 1);
    return png;
}

}  // namespace

// Every kind wul3d writes, both ways to compress, odd sizes: noise over smooth ramps (runs,
// and bytes no run takes), through one encoder reused from image to image.
TEST(PngEncode, EveryKind_ReadBackByLibpng_TheSamePixels) {
    std::mt19937 rng(11);
    PngEncoder encoder;
    for (const auto& [bits, channels] : {std::pair{8, 1}, std::pair{8, 3}, std::pair{16, 1}}) {
        for (const PngContent content : {PngContent::Regions, PngContent::Picture}) {
            for (const auto& [w, h] : {std::pair{1, 1}, std::pair{1, 7}, std::pair{37, 1}, std::pair{67, 45},
                                       std::pair{300, 200}}) {
                SCOPED_TRACE(std::to_string(bits) + "-bit, " + std::to_string(channels) + " channels, " +
                             (content == PngContent::Regions ? "regions, " : "picture, ") + std::to_string(w) +
                             "x" + std::to_string(h));
                const std::size_t samples = static_cast<std::size_t>(w) * h * channels;
                Samples image{bits, std::vector<unsigned char>(samples), std::vector<std::uint16_t>(samples)};
                for (std::size_t i = 0; i < samples; ++i) {
                    const auto noise = static_cast<unsigned>(rng() % 8 == 0 ? rng() : 0);
                    image.wide[i] = static_cast<std::uint16_t>(i / 5 * 37 + noise);
                    image.narrow[i] = static_cast<unsigned char>(i / 9 + noise);
                }
                round_trip(encoder, image, w, h, channels, content);
            }
        }
    }
}

// The run-length deflate: runs of every length from 1 to past two maximal matches (258
// bytes), of zeros and of other bytes, across rows (a match reaches back into the row above),
// and bytes that differ each from the next.
TEST(PngEncode, Regions_RunsOfEveryLength) {
    const int w = 619, h = 300;  // runs of 1 to 600 bytes, most across a row's end
    Samples image{8, std::vector<unsigned char>(static_cast<std::size_t>(w) * h), {}};
    std::size_t at = 0;
    for (int length = 1; at < image.narrow.size(); ++length)
        for (int k = 0; k < length % 600 + 1 && at < image.narrow.size(); ++k)
            image.narrow[at++] = static_cast<unsigned char>(length % 3 == 0 ? 0 : length * 7);
    PngEncoder encoder;
    round_trip(encoder, image, w, h, 1, PngContent::Regions);
    for (std::size_t i = 0; i < image.narrow.size(); ++i) image.narrow[i] = static_cast<unsigned char>(i * 131 + i / 7);
    round_trip(encoder, image, w, h, 1, PngContent::Regions);
}

// Labels are what Regions is for: a frame of a few areas is a small fraction of its samples,
// and a reused encoder writes the same file as a fresh one.
TEST(PngEncode, Regions_AreasCompress_ReuseChangesNothing) {
    const int w = 640, h = 480;
    Samples labels{16, {}, std::vector<std::uint16_t>(static_cast<std::size_t>(w) * h)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            labels.wide[static_cast<std::size_t>(y) * w + x] =
                static_cast<std::uint16_t>((x - 320) * (x - 320) + (y - 240) * (y - 240) < 150 * 150 ? 3 + x / 100 : 0);
    PngEncoder reused;
    Samples noise{8, std::vector<unsigned char>(300 * 3 * 7), {}};
    std::mt19937 rng(5);
    for (auto& b : noise.narrow) b = static_cast<unsigned char>(rng());
    round_trip(reused, noise, 300, 7, 3, PngContent::Picture);
    round_trip(reused, noise, 300, 7, 3, PngContent::Regions);
    const std::vector<unsigned char> png = round_trip(reused, labels, w, h, 1, PngContent::Regions);
    EXPECT_LT(png.size(), labels.wide.size() * 2 / 50);
    PngEncoder fresh;
    EXPECT_EQ(round_trip(fresh, labels, w, h, 1, PngContent::Regions), png);
}

TEST(PngEncode, EmptyImage_IoError) {
    PngEncoder encoder;
    std::vector<unsigned char> png;
    const unsigned char pixel = 0;
    EXPECT_THROW(encoder.encode(0, 5, 8, 1, &pixel, PngContent::Regions, png), wul3d::IoError);
    EXPECT_THROW(encoder.encode(5, 0, 8, 3, &pixel, PngContent::Picture, png), wul3d::IoError);
}
