// The PNG encoder (png_encode.hpp). zlib deflates the filtered rows as a raw stream, with
// the settings libpng was given before; the zlib wrapper's Adler-32 and the chunks' CRCs are
// libdeflate's (zlib's own Adler-32 and libpng's row copies and filtering took a fifth of an
// encode). The file: signature, IHDR, IDAT chunks, IEND (PNG specification, sections 5, 11).
#include "png_encode.hpp"

#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "png_format.hpp"
#include "wul3d/error.hpp"

namespace wul3d::detail {

namespace {

constexpr std::size_t kIdatBytes = 8192;  ///< libpng's IDAT size (PNG_ZBUF_SIZE)

/// The chunk whose data (`n` bytes) follows its length and type at `chunk`: both written, and
/// its CRC after the data. Returns the end of the chunk.
unsigned char* close_chunk(unsigned char* chunk, const char* type, std::size_t n) {
    write_be32(chunk, static_cast<std::uint32_t>(n));
    std::memcpy(chunk + 4, type, 4);
    write_be32(chunk + 8 + n, libdeflate_crc32(0, chunk + 4, 4 + n));
    return chunk + 12 + n;
}

/// Row y of the image as PNG stores it: its filter type (1, Sub: each byte less the byte one
/// pixel to its left) and its bytes, into `out` (1 + row bytes). 16-bit samples go
/// big-endian. The loops vectorize.
void filter_row(int width, int y, int bits, int channels, const void* pixels, unsigned char* out) {
    const std::size_t w = static_cast<std::size_t>(width);
    out[0] = 1;
    if (bits == 16) {
        const std::uint16_t* const row = static_cast<const std::uint16_t*>(pixels) + static_cast<std::size_t>(y) * w;
        out[1] = static_cast<unsigned char>(row[0] >> 8);
        out[2] = static_cast<unsigned char>(row[0]);
        for (std::size_t x = 1; x < w; ++x) {
            out[1 + 2 * x] = static_cast<unsigned char>((row[x] >> 8) - (row[x - 1] >> 8));
            out[2 + 2 * x] = static_cast<unsigned char>(row[x] - row[x - 1]);
        }
        return;
    }
    const std::size_t n = w * static_cast<std::size_t>(channels), bpp = static_cast<std::size_t>(channels);
    const unsigned char* const row = static_cast<const unsigned char*>(pixels) + static_cast<std::size_t>(y) * n;
    std::memcpy(out + 1, row, bpp);
    for (std::size_t i = bpp; i < n; ++i) out[1 + i] = static_cast<unsigned char>(row[i] - row[i - bpp]);
}

/// zlib's deflate stream, ended whatever happens.
struct Deflater {
    z_stream z{};
    bool started = false;
    ~Deflater() {
        if (started) deflateEnd(&z);
    }
};

}  // namespace

void encode_png(int width, int height, int bits, int channels, const void* pixels, std::vector<unsigned char>& out) {
    if (width <= 0 || height <= 0)
        throw IoError("cannot encode PNG (an image of " + std::to_string(width) + "x" + std::to_string(height) +
                      " pixels is empty)");
    const std::size_t row_bytes = static_cast<std::size_t>(width) * channels * (bits / 8);
    if (row_bytes >= std::numeric_limits<uInt>::max())  // zlib takes a row in one piece
        throw IoError("cannot encode PNG (rows of " + std::to_string(width) + " pixels are too long)");
    Deflater d;
    // Raw deflate (negative window bits): the zlib wrapper is written here, its Adler-32 by
    // libdeflate. Level 1 (fastest), run-length matches only.
    if (deflateInit2(&d.z, Z_BEST_SPEED, Z_DEFLATED, -15, 8, Z_RLE) != Z_OK)
        throw IoError("cannot encode PNG (zlib cannot start)");
    d.started = true;
    // The zlib stream: header, deflate's raw stream, Adler-32 of the filtered rows.
    std::vector<unsigned char> zlib_stream = {0x78, 0x01};  // 32 KiB window, fastest level
    // Row by row through one row's buffer, out through a piece of kIdatBytes: the whole
    // filtered image, or a buffer for the worst case, would be megabytes of fresh pages a
    // frame. deflate's output does not depend on how its input or output are cut.
    std::vector<unsigned char> row(1 + row_bytes), piece(kIdatBytes);
    std::uint32_t adler = 1;
    for (int y = 0; y < height; ++y) {
        filter_row(width, y, bits, channels, pixels, row.data());
        adler = libdeflate_adler32(adler, row.data(), row.size());
        d.z.next_in = row.data();
        d.z.avail_in = static_cast<uInt>(row.size());
        const bool last = y + 1 == height;
        int status = Z_OK;
        do {  // until deflate has taken the row (and, after the last, written its end)
            d.z.next_out = piece.data();
            d.z.avail_out = static_cast<uInt>(piece.size());
            status = deflate(&d.z, last ? Z_FINISH : Z_NO_FLUSH);
            if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR)
                throw IoError("cannot encode PNG (zlib failed)");
            zlib_stream.insert(zlib_stream.end(), piece.data(), d.z.next_out);
        } while (d.z.avail_in != 0 || (last && status != Z_STREAM_END));
    }
    for (int shift = 24; shift >= 0; shift -= 8) zlib_stream.push_back(static_cast<unsigned char>(adler >> shift));

    // The file: signature, IHDR, the stream in IDAT chunks of kIdatBytes (as libpng cuts it:
    // the same file as libpng's with these settings), IEND.
    const std::size_t n_idat = (zlib_stream.size() + kIdatBytes - 1) / kIdatBytes;
    out.resize(kPngSignature.size() + (12 + 13) + 12 * n_idat + zlib_stream.size() + 12);
    unsigned char* const p = out.data();
    std::memcpy(p, kPngSignature.data(), kPngSignature.size());
    unsigned char* chunk = p + kPngSignature.size();
    write_be32(chunk + 8, static_cast<std::uint32_t>(width));
    write_be32(chunk + 12, static_cast<std::uint32_t>(height));
    chunk[16] = static_cast<unsigned char>(bits);
    chunk[17] = channels == 3 ? 2 : 0;    // colour type: RGB or grey
    chunk[18] = chunk[19] = chunk[20] = 0;  // deflate, adaptive filtering, not interlaced
    chunk = close_chunk(chunk, "IHDR", 13);
    for (std::size_t at = 0; at < zlib_stream.size(); at += kIdatBytes) {
        const std::size_t n = std::min(kIdatBytes, zlib_stream.size() - at);
        std::memcpy(chunk + 8, zlib_stream.data() + at, n);
        chunk = close_chunk(chunk, "IDAT", n);
    }
    close_chunk(chunk, "IEND", 0);
}

}  // namespace wul3d::detail
