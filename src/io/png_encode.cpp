// The PNG encoder (png_encode.hpp). Two ways to deflate, by what the image holds: labels and
// masks by a run-length deflate of wul3d's own (one fixed-Huffman block, matches one byte
// back only: RFC 1951, sections 3.2.5-3.2.6), colours and depth by libdeflate. The file:
// signature, IHDR, one IDAT chunk, IEND (PNG specification, sections 5, 11); the zlib
// wrapper's Adler-32 and the chunks' CRCs are libdeflate's.
#include "png_encode.hpp"

#include <libdeflate.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "png_format.hpp"
#include "wul3d/error.hpp"

namespace wul3d::detail {

namespace {

/// A Huffman code as deflate writes it: `n` bits, the first to go in bit 0.
struct Code {
    std::uint32_t bits = 0;
    int n = 0;
};

constexpr std::uint32_t reversed(std::uint32_t code, int n) {
    std::uint32_t r = 0;
    for (int i = 0; i < n; ++i, code >>= 1) r = (r << 1) | (code & 1);
    return r;
}

/// Deflate's fixed code of literal byte v (RFC 1951, 3.2.6): 0-143 in 8 bits from 0x30,
/// 144-255 in 9 bits from 0x190. Huffman codes go most significant bit first.
constexpr std::array<Code, 256> kLiteral = [] {
    std::array<Code, 256> t{};
    for (std::uint32_t v = 0; v < 256; ++v)
        t[v] = v < 144 ? Code{reversed(0x30 + v, 8), 8} : Code{reversed(0x190 + v - 144, 9), 9};
    return t;
}();

/// A match of `length` (3-258) bytes one byte back: its length symbol (257-285: 7 bits from
/// 0 up to 279, 8 bits from 0xc0 after), the symbol's extra bits, and distance code 0
/// (distance 1: five zero bits, no extra bits).
constexpr std::array<Code, 259> kRun = [] {
    constexpr int base[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                              31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    constexpr int extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    std::array<Code, 259> t{};
    int s = 0;
    for (int length = 3; length <= 258; ++length) {
        while (s < 28 && base[s + 1] <= length) ++s;
        const auto symbol = static_cast<std::uint32_t>(257 + s);
        Code c = symbol < 280 ? Code{reversed(symbol - 256, 7), 7} : Code{reversed(0xc0 + symbol - 280, 8), 8};
        c.bits |= static_cast<std::uint32_t>(length - base[s]) << c.n;
        c.n += extra[s] + 5;
        t[length] = c;
    }
    return t;
}();

constexpr Code kEndOfBlock{0, 7};  ///< symbol 256
constexpr Code kFinalFixedBlock{0b011, 3};  ///< BFINAL 1, then BTYPE 01 (fixed codes)

/// Bits into bytes, least significant first (RFC 1951, 3.1.1), 32 at a time.
class BitWriter {
public:
    explicit BitWriter(unsigned char* out) : out_(out) {}
    void put(Code c) {
        pending_ |= std::uint64_t{c.bits} << filled_;
        filled_ += c.n;
        if (filled_ >= 32) {
            for (int i = 0; i < 4; ++i) out_[i] = static_cast<unsigned char>(pending_ >> (8 * i));
            out_ += 4;
            pending_ >>= 32;
            filled_ -= 32;
        }
    }
    /// Pads the last byte with zeros; returns the end of the bytes written.
    unsigned char* finish() {
        for (; filled_ > 0; filled_ -= 8, pending_ >>= 8) *out_++ = static_cast<unsigned char>(pending_);
        filled_ = 0;
        return out_;
    }

private:
    unsigned char* out_;
    std::uint64_t pending_ = 0;
    int filled_ = 0;
};

/// The end of the run of bytes equal to v that starts at p[i] (n at most), 8 bytes a step.
std::size_t run_end(const unsigned char* p, std::size_t i, std::size_t n, unsigned char v) {
    const std::uint64_t pattern = 0x0101010101010101ULL * v;
    for (; i + 8 <= n; i += 8) {
        std::uint64_t x = 0;
        std::memcpy(&x, p + i, 8);
        if ((x ^= pattern) != 0)
            return i + static_cast<std::size_t>(std::endian::native == std::endian::little ? std::countr_zero(x)
                                                                                             : std::countl_zero(x)) / 8;
    }
    while (i < n && p[i] == v) ++i;
    return i;
}

/// Bytes p[0, n) after `previous` (the stream's byte before them; -1 for none): each run of
/// 3 or more bytes equal to the byte before as matches one byte back, the rest as literals.
void deflate_runs(const unsigned char* p, std::size_t n, int& previous, BitWriter& w) {
    for (std::size_t i = 0; i < n;) {
        const unsigned char v = p[i];
        if (v != previous) {
            w.put(kLiteral[v]);
            previous = v;
            ++i;
            continue;
        }
        const std::size_t end = run_end(p, i, n, v);
        std::size_t run = end - i;
        while (run >= 3) {
            std::size_t length = run < 258 ? run : 258;
            if (run - length > 0 && run - length < 3) length = run - 3;  // leave a match, not 1-2 literals
            w.put(kRun[length]);
            run -= length;
        }
        for (; run > 0; --run) w.put(kLiteral[v]);
        i = end;
    }
}

/// Row `y` of the image as PNG stores it with the Up filter (2: each byte less the byte above
/// it), into `out` (1 + row_bytes). 16-bit samples go big-endian. The loops vectorize.
void up_filter_row(std::size_t y, std::size_t row_bytes, int bits, const void* pixels, unsigned char* out) {
    out[0] = 2;
    if (bits == 16) {
        const std::size_t w = row_bytes / 2;
        const auto* const row = static_cast<const std::uint16_t*>(pixels) + y * w;
        const std::uint16_t* const above = y > 0 ? row - w : nullptr;
        for (std::size_t x = 0; x < w; ++x) {
            const unsigned up = above ? above[x] : 0;
            out[1 + 2 * x] = static_cast<unsigned char>((row[x] >> 8) - (up >> 8));
            out[2 + 2 * x] = static_cast<unsigned char>(row[x] - up);
        }
        return;
    }
    const auto* const row = static_cast<const unsigned char*>(pixels) + y * row_bytes;
    if (y == 0) {
        std::memcpy(out + 1, row, row_bytes);
        return;
    }
    const unsigned char* const above = row - row_bytes;
    for (std::size_t i = 0; i < row_bytes; ++i) out[1 + i] = static_cast<unsigned char>(row[i] - above[i]);
}

/// The chunk whose data (`n` bytes) follows its length and type at `chunk`: both written, and
/// its CRC after the data. Returns the end of the chunk.
unsigned char* close_chunk(unsigned char* chunk, const char* type, std::size_t n) {
    write_be32(chunk, static_cast<std::uint32_t>(n));
    std::memcpy(chunk + 4, type, 4);
    write_be32(chunk + 8 + n, libdeflate_crc32(0, chunk + 4, 4 + n));
    return chunk + 12 + n;
}

}  // namespace

PngEncoder::~PngEncoder() {
    if (compressor_) libdeflate_free_compressor(compressor_);
}

void PngEncoder::deflate_regions(std::size_t height, std::size_t row_bytes, int bits, const void* pixels) {
    // At most 9 bits a byte (a literal past 143), the headers and the Adler-32 after.
    const std::size_t worst = 2 + (height * (row_bytes + 1) * 9 + 3 + 7 + 7) / 8 + 4 + 8;
    if (stream_.size() < worst) stream_.resize(worst);
    rows_.resize(1 + row_bytes);
    stream_[0] = 0x78;  // zlib: deflate, 32 KiB window
    stream_[1] = 0x01;  // fastest level; header check bits
    BitWriter w(stream_.data() + 2);
    w.put(kFinalFixedBlock);
    std::uint32_t adler = 1;
    int previous = -1;
    for (std::size_t y = 0; y < height; ++y) {
        up_filter_row(y, row_bytes, bits, pixels, rows_.data());
        adler = libdeflate_adler32(adler, rows_.data(), rows_.size());
        deflate_runs(rows_.data(), rows_.size(), previous, w);
    }
    w.put(kEndOfBlock);
    unsigned char* end = w.finish();
    write_be32(end, adler);
    stream_bytes_ = static_cast<std::size_t>(end + 4 - stream_.data());
}

void PngEncoder::deflate_picture(std::size_t height, std::size_t row_bytes, int bits, const void* pixels) {
    const std::size_t stride = 1 + row_bytes;
    rows_.resize(height * stride);
    for (std::size_t y = 0; y < height; ++y) {
        unsigned char* const out = rows_.data() + y * stride;
        out[0] = 0;  // filter None
        if (bits == 16) {
            const auto* const row = static_cast<const std::uint16_t*>(pixels) + y * (row_bytes / 2);
            for (std::size_t x = 0; x < row_bytes / 2; ++x) {
                out[1 + 2 * x] = static_cast<unsigned char>(row[x] >> 8);
                out[2 + 2 * x] = static_cast<unsigned char>(row[x]);
            }
        } else {
            std::memcpy(out + 1, static_cast<const unsigned char*>(pixels) + y * row_bytes, row_bytes);
        }
    }
    if (!compressor_ && !(compressor_ = libdeflate_alloc_compressor(1)))
        throw IoError("cannot encode PNG (out of memory)");
    const std::size_t bound = libdeflate_zlib_compress_bound(compressor_, rows_.size());
    if (stream_.size() < bound) stream_.resize(bound);
    stream_bytes_ = libdeflate_zlib_compress(compressor_, rows_.data(), rows_.size(), stream_.data(), stream_.size());
    if (stream_bytes_ == 0) throw IoError("cannot encode PNG (libdeflate failed)");
}

void PngEncoder::encode(int width, int height, int bits, int channels, const void* pixels, PngContent content,
                        std::vector<unsigned char>& out) {
    if (width <= 0 || height <= 0)
        throw IoError("cannot encode PNG (an image of " + std::to_string(width) + "x" + std::to_string(height) +
                      " pixels is empty)");
    const std::size_t row_bytes = static_cast<std::size_t>(width) * channels * (bits / 8);
    const auto rows = static_cast<std::size_t>(height);
    if (content == PngContent::Regions)
        deflate_regions(rows, row_bytes, bits, pixels);
    else
        deflate_picture(rows, row_bytes, bits, pixels);
    constexpr std::size_t kMaxChunk = std::numeric_limits<std::int32_t>::max();  // PNG's limit (5.3)
    if (stream_bytes_ > kMaxChunk)
        throw IoError("cannot encode PNG (an image of " + std::to_string(width) + "x" + std::to_string(height) +
                      " pixels is too large)");

    out.resize(kPngSignature.size() + (12 + 13) + (12 + stream_bytes_) + 12);
    unsigned char* const p = out.data();
    std::memcpy(p, kPngSignature.data(), kPngSignature.size());
    unsigned char* chunk = p + kPngSignature.size();
    write_be32(chunk + 8, static_cast<std::uint32_t>(width));
    write_be32(chunk + 12, static_cast<std::uint32_t>(height));
    chunk[16] = static_cast<unsigned char>(bits);
    chunk[17] = channels == 3 ? 2 : 0;      // colour type: RGB or grey
    chunk[18] = chunk[19] = chunk[20] = 0;  // deflate, adaptive filtering, not interlaced
    chunk = close_chunk(chunk, "IHDR", 13);
    std::memcpy(chunk + 8, stream_.data(), stream_bytes_);
    chunk = close_chunk(chunk, "IDAT", stream_bytes_);
    close_chunk(chunk, "IEND", 0);
}

}  // namespace wul3d::detail
