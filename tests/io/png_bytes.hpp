#pragma once
// PNG files made byte by byte for the io tests (images_test.cpp, png_rows_test.cpp): chunks
// with their CRCs, zlib streams of stored blocks, the IHDR of any kind.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace wul3d::test::png_bytes {

/// CRC-32 of the PNG specification, to build chunks by hand.
inline std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffu;
}

inline std::string be32(std::uint32_t v) {
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
            static_cast<char>(v)};
}

/// Adler-32, the checksum that ends a zlib stream.
inline std::uint32_t adler32(const std::string& bytes) {
    std::uint32_t a = 1, b = 0;
    for (unsigned char c : bytes) {
        a = (a + c) % 65521u;
        b = (b + a) % 65521u;
    }
    return (b << 16) | a;
}

/// A zlib stream holding `raw` uncompressed (stored deflate blocks), as a PNG's IDAT data.
inline std::string zlib_stored(const std::string& raw) {
    std::string z = "\x78\x01";
    std::size_t pos = 0;
    do {
        const std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
        const bool last = pos + n == raw.size();
        const auto len = static_cast<std::uint16_t>(n), nlen = static_cast<std::uint16_t>(~n);
        z += static_cast<char>(last ? 1 : 0);
        z += {static_cast<char>(len & 0xff), static_cast<char>(len >> 8),
              static_cast<char>(nlen & 0xff), static_cast<char>(nlen >> 8)};
        z += raw.substr(pos, n);
        pos += n;
    } while (pos < raw.size());
    return z + be32(adler32(raw));
}

inline std::string png_chunk(const std::string& type, const std::string& data) {
    return be32(static_cast<std::uint32_t>(data.size())) + type + data + be32(crc32(type + data));
}

/// A PNG file: the IHDR of the arguments, `chunks` (PLTE, tRNS), and an IDAT chunk for each
/// of `idats` (pieces of one zlib stream, in order).
inline std::string png_with_idats(std::uint32_t w, std::uint32_t h, int bit_depth, int color_type,
                                  const std::vector<std::string>& idats, const std::string& chunks = "",
                                  bool interlaced = false) {
    const std::string ihdr = be32(w) + be32(h) +
                             std::string{static_cast<char>(bit_depth), static_cast<char>(color_type),
                                         0, 0, static_cast<char>(interlaced ? 1 : 0)};
    std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + chunks;
    for (const std::string& idat : idats) png += png_chunk("IDAT", idat);
    return png + png_chunk("IEND", "");
}

/// The same with one IDAT holding the zlib stream `idat`.
inline std::string png_file(std::uint32_t w, std::uint32_t h, int bit_depth, int color_type,
                            const std::string& idat, const std::string& chunks = "", bool interlaced = false) {
    return png_with_idats(w, h, bit_depth, color_type, {idat}, chunks, interlaced);
}

/// Scanlines with filter type 0 (None): each of `rows` prefixed by a zero byte.
inline std::string unfiltered(const std::vector<std::string>& rows) {
    std::string raw;
    for (const auto& r : rows) raw += '\0' + r;
    return raw;
}

inline std::string be16(std::uint16_t v) { return {static_cast<char>(v >> 8), static_cast<char>(v & 0xff)}; }

}  // namespace wul3d::test::png_bytes
