#pragma once
// Private to src/io_*.cpp: image readers that reuse the caller's buffers, so that a
// FrameSource allocates nothing per frame once the first frame has been read.
#include <cstdint>
#include <cstdio>
#include <functional>
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

/// Called with an image's width and height from its header, before its pixels are
/// allocated: throws to refuse a size the caller already knows is wrong (a 32768 x 32768
/// depth.png beside a 640 x 480 intrinsics.json is refused without its 2 GB).
using HeaderCheck = std::function<void(int width, int height)>;

/// As read_depth_png / read_color_image / read_label_png, into `out` (buffers reused);
/// `check`, if given, sees the header's size first.
void read_depth_png_into(const std::string& path, float scale_m_per_unit, ImageScratch& scratch,
                         DepthImage& out, const HeaderCheck& check = {});
void read_color_image_into(const std::string& path, ImageScratch& scratch, ColorImage& out,
                           const HeaderCheck& check = {});
/// As read_color_image_into, of the PNG or JPEG already in `scratch.bytes` (a bag's
/// CompressedImage); `what` names it in errors.
void decode_color_image_into(const std::string& what, ImageScratch& scratch, ColorImage& out);
void read_label_png_into(const std::string& path, ImageScratch& scratch, LabelImage& out);

/// "WxH".
inline std::string size_str(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

/// A number for a message, short whatever its size ("1e+300", "1e-300", "0.001"), where
/// std::to_string prints 300 digits or "0.000000".
inline std::string number_str(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

}  // namespace wul3d::detail
