// The PNG encoder (src/io/png_encode.cpp), read back by libpng itself rather than by wul3d's
// reader (whose own decoder could share a mistake with the encoder): every kind wul3d writes,
// odd sizes, images whose stream spans many IDAT chunks.
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

}  // namespace

TEST(PngEncode, EveryKind_ReadBackByLibpng_TheSamePixels) {
    std::mt19937 rng(11);
    struct Kind {
        int bits, channels, color_type;
    };
    for (const Kind kind : {Kind{8, 1, PNG_COLOR_TYPE_GRAY}, Kind{8, 3, PNG_COLOR_TYPE_RGB},
                            Kind{16, 1, PNG_COLOR_TYPE_GRAY}}) {
        for (const auto& [w, h] : {std::pair{1, 1}, std::pair{1, 7}, std::pair{37, 1}, std::pair{67, 45},
                                   std::pair{300, 200}}) {
            SCOPED_TRACE(std::to_string(kind.bits) + "-bit, " + std::to_string(kind.channels) + " channels, " +
                         std::to_string(w) + "x" + std::to_string(h));
            const std::size_t samples = static_cast<std::size_t>(w) * h * kind.channels;
            // Noise over smooth ramps: runs for the run-length matches, and bytes they cannot take.
            std::vector<std::uint16_t> wide(samples);
            std::vector<unsigned char> narrow(samples);
            for (std::size_t i = 0; i < samples; ++i) {
                const auto noise = static_cast<unsigned>(rng() % 8 == 0 ? rng() : 0);
                wide[i] = static_cast<std::uint16_t>(i / 5 * 37 + noise);
                narrow[i] = static_cast<unsigned char>(i / 9 + noise);
            }
            const void* pixels = kind.bits == 16 ? static_cast<const void*>(wide.data()) : narrow.data();
            std::vector<unsigned char> png;
            wul3d::detail::encode_png(w, h, kind.bits, kind.channels, pixels, png);
            LibpngImage back;
            ASSERT_TRUE(read_with_libpng(png, back));
            EXPECT_EQ(back.width, static_cast<png_uint_32>(w));
            EXPECT_EQ(back.height, static_cast<png_uint_32>(h));
            EXPECT_EQ(back.bit_depth, kind.bits);
            EXPECT_EQ(back.color_type, kind.color_type);
            if (kind.bits == 16) {
                std::vector<std::uint16_t> got(samples);
                for (std::size_t i = 0; i < samples; ++i)
                    got[i] = static_cast<std::uint16_t>((back.rows[2 * i] << 8) | back.rows[2 * i + 1]);
                EXPECT_EQ(got, wide);
            } else {
                EXPECT_EQ(back.rows, narrow);
            }
        }
    }
}

// libpng cuts the zlib stream into IDAT chunks of 8192 bytes; so does the encoder, and a large
// noisy image spans many of them.
TEST(PngEncode, LargeImage_ManyIdatChunks) {
    std::mt19937 rng(5);
    const int w = 320, h = 240;
    std::vector<unsigned char> rgb(static_cast<std::size_t>(w) * h * 3);
    for (auto& b : rgb) b = static_cast<unsigned char>(rng());
    std::vector<unsigned char> png;
    wul3d::detail::encode_png(w, h, 8, 3, rgb.data(), png);
    EXPECT_GT(count_idat(png), 20);  // about 230 KB of noise: nearly no compression
    LibpngImage back;
    ASSERT_TRUE(read_with_libpng(png, back));
    EXPECT_EQ(back.rows, rgb);
}
