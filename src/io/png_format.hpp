#pragma once
// Private to src/io/: the bytes of the PNG format that the checks, the decoder of the common
// kinds and the encoder share (PNG specification, section 5).
#include <array>
#include <cstdint>

namespace wul3d::detail {

/// The eight bytes every PNG file starts with.
inline constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

/// The big-endian 32-bit number at p (a chunk's length, its CRC, IHDR's sizes).
inline std::uint32_t read_be32(const unsigned char* p) {
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
           std::uint32_t{p[3]};
}

/// v at p, big-endian.
inline void write_be32(unsigned char* p, std::uint32_t v) {
    p[0] = static_cast<unsigned char>(v >> 24);
    p[1] = static_cast<unsigned char>(v >> 16);
    p[2] = static_cast<unsigned char>(v >> 8);
    p[3] = static_cast<unsigned char>(v);
}

}  // namespace wul3d::detail
