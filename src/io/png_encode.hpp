#pragma once
// Private to src/io/: the PNG encoder of what wul3d writes (labels, colours, masks, depth).
#include <vector>

namespace wul3d::detail {

/// `height` rows of `width` pixels at `pixels` (8-bit grey, 8-bit RGB with channels 3, or
/// 16-bit grey in the host's byte order with bits 16; no padding) as a PNG file in `out`:
/// every row with the Sub filter, zlib's fastest level with run-length matches only (the
/// settings OpenCV used), the stream in IDAT chunks of 8192 bytes: for a frame's images, the
/// same file libpng writes with those settings. Throws IoError (without a path: the caller
/// adds it) if zlib fails. Cost: one pass to filter, one deflate, no image-sized scratch.
void encode_png(int width, int height, int bits, int channels, const void* pixels, std::vector<unsigned char>& out);

}  // namespace wul3d::detail
