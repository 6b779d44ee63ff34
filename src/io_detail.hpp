#pragma once
// Private to src/io_*.cpp: image readers that reuse the caller's buffers, so that a
// FrameSource allocates nothing per frame once the first frame has been read.
#include <cstdint>
#include <string>
#include <vector>

#include "wul3d/clustering.hpp"
#include "wul3d/frame.hpp"

namespace wul3d::detail {

/// Scratch of the image readers. The pixels are decoded straight into the image read, so
/// no decoded copy of the image is kept here.
struct ImageScratch {
    std::vector<unsigned char> bytes;
    std::vector<unsigned char> cleaned;  ///< PNG without ancillary chunks, when it had any
    std::vector<unsigned char*> rows;    ///< where each image row goes, for libpng / libjpeg
    std::vector<unsigned char> pixels;   ///< 8-bit labels before widening; a CMYK JPEG row
};

/// The whole of the regular file `path` into `bytes` (capacity reused). InputError naming the
/// file if it is missing, not a regular file (a FIFO, device or folder is refused by its type
/// before it is opened), larger than `max_bytes`, or unreadable.
void read_regular_file(const std::string& path, std::uint64_t max_bytes,
                       std::vector<unsigned char>& bytes);

/// As read_depth_png / read_color_image / read_label_png, into `out` (buffers reused).
void read_depth_png_into(const std::string& path, float scale_m_per_unit, ImageScratch& scratch,
                         DepthImage& out);
void read_color_image_into(const std::string& path, ImageScratch& scratch, ColorImage& out);
/// As read_color_image_into, of the PNG or JPEG already in `scratch.bytes` (a bag's
/// CompressedImage); `what` names it in errors.
void decode_color_image_into(const std::string& what, ImageScratch& scratch, ColorImage& out);
void read_label_png_into(const std::string& path, ImageScratch& scratch, LabelImage& out);

/// "WxH".
inline std::string size_str(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace wul3d::detail
