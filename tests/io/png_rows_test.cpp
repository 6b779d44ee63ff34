// The PNG decoder of the common kinds (src/io/png_rows.cpp): PNGs filtered here row by row
// with each of the five filter types, as the specification writes them, decoded to the
// pixels they were made of, directly and through the readers; and the files it leaves to
// libpng (bad filter types, too little or too much data, a wrong Adler-32) read as libpng
// reads them.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "io/io_detail.hpp"
#include "io/png_rows.hpp"
#include "io_expect.hpp"
#include "png_bytes.hpp"
#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::expect_input_error;
using wul3d::test::TempDir;
using wul3d::test::write_text;
using namespace wul3d::test::png_bytes;

/// Paeth's predictor as the specification writes it (9.4), with its branches.
int paeth_reference(int a, int b, int c) {
    const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
    if (pa <= pb && pa <= pc) return a;
    if (pb <= pc) return b;
    return c;
}

/// `rows` (each the file's bytes of one row, bpp bytes a pixel) filtered: row y with filter
/// filters[y % size], its type byte first.
std::string filter_rows(const std::vector<std::string>& rows, int bpp, const std::vector<int>& filters) {
    std::string out;
    std::string prior(rows.front().size(), '\0');
    for (std::size_t y = 0; y < rows.size(); ++y) {
        const int f = filters[y % filters.size()];
        const std::string& row = rows[y];
        out += static_cast<char>(f);
        for (std::size_t i = 0; i < row.size(); ++i) {
            const int x = static_cast<unsigned char>(row[i]), b = static_cast<unsigned char>(prior[i]);
            const int a = i >= static_cast<std::size_t>(bpp) ? static_cast<unsigned char>(row[i - bpp]) : 0;
            const int c = i >= static_cast<std::size_t>(bpp) ? static_cast<unsigned char>(prior[i - bpp]) : 0;
            const int predicted = f == 0 ? 0 : f == 1 ? a : f == 2 ? b : f == 3 ? (a + b) / 2 : paeth_reference(a, b, c);
            out += static_cast<char>((x - predicted) & 0xff);
        }
        prior = row;
    }
    return out;
}

/// zlib's deflate of `raw` (Huffman-coded blocks, where zlib_stored keeps them as they are).
std::string deflated(const std::string& raw) {
    uLongf n = compressBound(static_cast<uLong>(raw.size()));
    std::string z(n, '\0');
    compress2(reinterpret_cast<Bytef*>(z.data()), &n, reinterpret_cast<const Bytef*>(raw.data()),
              static_cast<uLong>(raw.size()), 6);
    z.resize(n);
    return z;
}

/// A PNG whose zlib stream `z` is cut into `parts` IDAT chunks.
std::string png_parts(std::uint32_t w, std::uint32_t h, int bit_depth, int color_type, const std::string& z,
                      int parts) {
    std::vector<std::string> idats;
    const std::size_t step = z.size() / parts + 1;
    for (std::size_t pos = 0; pos < z.size(); pos += step) idats.push_back(z.substr(pos, step));
    return png_with_idats(w, h, bit_depth, color_type, idats);
}

/// Random rows of `width` pixels of bpp bytes, with runs of 0 and 255 among them (the edges of
/// Paeth's choices).
std::vector<std::string> random_rows(int width, int height, int bpp, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<std::string> rows(static_cast<std::size_t>(height));
    for (int y = 0; y < height; ++y)
        for (int i = 0; i < width * bpp; ++i) {
            const auto r = static_cast<unsigned>(rng());
            rows[static_cast<std::size_t>(y)] += static_cast<char>(y % 7 == 3 ? (r % 2 ? 255 : 0) : r % 256);
        }
    return rows;
}

/// decode_png_rows on `png`: whether it took the file, and the pixels it wrote.
bool decode_direct(const std::string& png, int width, int height, int bpp, std::vector<unsigned char>& out) {
    wul3d::detail::ImageScratch s;
    out.assign(static_cast<std::size_t>(width) * height * bpp, 0);
    return wul3d::detail::decode_png_rows(reinterpret_cast<const unsigned char*>(png.data()), png.size(),
                                          static_cast<std::size_t>(width), static_cast<std::size_t>(height),
                                          bpp, out.data(), s);
}

/// The rows' bytes as pixels: 8-bit bytes as they are; 16-bit big-endian samples as numbers.
std::vector<std::uint16_t> samples16(const std::vector<std::string>& rows) {
    std::vector<std::uint16_t> v;
    for (const std::string& r : rows)
        for (std::size_t i = 0; i + 1 < r.size(); i += 2)
            v.push_back(static_cast<std::uint16_t>((static_cast<unsigned char>(r[i]) << 8) |
                                                   static_cast<unsigned char>(r[i + 1])));
    return v;
}

std::vector<std::uint8_t> bytes8(const std::vector<std::string>& rows) {
    std::vector<std::uint8_t> v;
    for (const std::string& r : rows) v.insert(v.end(), r.begin(), r.end());
    return v;
}

}  // namespace

TEST(PngRows, EveryFilterType_EveryKind_ThePixelsTheyWereMadeOf) {
    TempDir tmp;
    const int w = 37, h = 23;  // odd: no row a multiple of 4 bytes
    // Each filter on its own, then all five in turn (each row's prior filtered otherwise).
    const std::vector<std::vector<int>> filter_sets = {{0}, {1}, {2}, {3}, {4}, {0, 1, 2, 3, 4}, {4, 3, 2, 1}};
    struct Kind {
        int bits, color_type, bpp;
    };
    for (const Kind kind : {Kind{8, 0, 1}, Kind{16, 0, 2}, Kind{8, 2, 3}}) {
        for (std::size_t f = 0; f < filter_sets.size(); ++f) {
            for (const int parts : {1, 3}) {
                SCOPED_TRACE("bits " + std::to_string(kind.bits) + ", colour type " + std::to_string(kind.color_type) +
                             ", filters " + std::to_string(f) + ", IDAT chunks " + std::to_string(parts));
                const auto rows = random_rows(w, h, kind.bpp, static_cast<unsigned>(100 * f + parts));
                const std::string raw = filter_rows(rows, kind.bpp, filter_sets[f]);
                const std::string png = png_parts(w, h, kind.bits, kind.color_type,
                                                  parts == 1 ? deflated(raw) : zlib_stored(raw), parts);
                std::vector<unsigned char> direct;
                ASSERT_TRUE(decode_direct(png, w, h, kind.bpp, direct));
                const fs::path path = tmp / "image.png";
                write_text(path, png);
                if (kind.bits == 16) {
                    const std::vector<std::uint16_t> expect = samples16(rows);
                    std::vector<std::uint16_t> got(expect.size());
                    std::memcpy(got.data(), direct.data(), 2 * got.size());  // the host's order
                    EXPECT_EQ(got, expect);
                    EXPECT_EQ(wul3d::read_depth_png(path.string(), 0.001f).data, expect);
                    EXPECT_EQ(wul3d::read_label_png(path.string()).labels, expect);
                } else {
                    const std::vector<std::uint8_t> expect = bytes8(rows);
                    EXPECT_EQ(std::vector<std::uint8_t>(direct.begin(), direct.end()), expect);
                    if (kind.bpp == 3) {
                        EXPECT_EQ(wul3d::read_color_image(path.string()).rgb, expect);
                    } else {
                        const std::vector<std::uint16_t> labels(expect.begin(), expect.end());
                        EXPECT_EQ(wul3d::read_label_png(path.string()).labels, labels);
                    }
                }
            }
        }
    }
}

// And rows too short for the lower of two rows to trail the upper by its 4 pixels (3, 5).
TEST(PngRows, OnePixelWideAndOneRowHigh) {
    for (const auto& [w, h] : {std::pair{1, 9}, std::pair{9, 1}, std::pair{1, 1}, std::pair{3, 6}, std::pair{5, 5}}) {
        for (const int bpp : {1, 2, 3}) {
            const auto rows = random_rows(w, h, bpp, static_cast<unsigned>(w * 10 + h + bpp));
            const std::string png = png_file(w, h, bpp == 2 ? 16 : 8, bpp == 3 ? 2 : 0,
                                             deflated(filter_rows(rows, bpp, {4, 3, 1, 2, 0})));
            std::vector<unsigned char> direct;
            ASSERT_TRUE(decode_direct(png, w, h, bpp, direct)) << w << "x" << h << ", " << bpp;
            if (bpp == 2)
                for (std::size_t i = 0; i < direct.size(); i += 2) std::swap(direct[i], direct[i + 1]);
            EXPECT_EQ(std::vector<std::uint8_t>(direct.begin(), direct.end()), bytes8(rows)) << w << "x" << h;
        }
    }
}

// What the decoder does not take as it is, it leaves to libpng, which decides as it always
// has: an error naming the file, or the pixels.
TEST(PngRows, FilesLeftToLibpng_ReadAsLibpngReadsThem) {
    TempDir tmp;
    const int w = 5, h = 4;
    const auto rows = random_rows(w, h, 2, 7);
    const std::string raw = filter_rows(rows, 2, {1, 4});
    std::vector<unsigned char> direct;
    auto write = [&](const std::string& name, const std::string& png) {
        const fs::path path = tmp / name;
        write_text(path, png);
        EXPECT_FALSE(decode_direct(png, w, h, 2, direct)) << name;
        return path.string();
    };

    std::string bad_filter = raw;
    bad_filter[2 * (2 * w + 1)] = 5;  // row 2's type
    const std::string bad = write("bad_filter.png", png_file(w, h, 16, 0, deflated(bad_filter)));
    expect_input_error([&] { wul3d::read_depth_png(bad, 0.001f); }, {bad, "cannot decode PNG"});

    const std::string short_data = write("short.png", png_file(w, h, 16, 0, deflated(raw.substr(0, raw.size() - 3))));
    expect_input_error([&] { wul3d::read_depth_png(short_data, 0.001f); }, {short_data, "cannot decode PNG"});

    // A row more than the header says: libpng reads the rows it has and lets the rest be.
    const std::string extra = raw + raw.substr(0, 2 * w + 1);
    const std::string longer = write("long.png", png_file(w, h, 16, 0, deflated(extra)));
    EXPECT_EQ(wul3d::read_depth_png(longer, 0.001f).data, samples16(rows));

    // A wrong Adler-32: the chunk's CRC covers the stream, libpng is told not to check it.
    std::string z = deflated(raw);
    z.back() = static_cast<char>(z.back() ^ 0x5a);
    const std::string adler = write("adler.png", png_file(w, h, 16, 0, z));
    EXPECT_EQ(wul3d::read_depth_png(adler, 0.001f).data, samples16(rows));
}
