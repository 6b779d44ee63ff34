#pragma once
/// @file image.hpp
/// The image types every stage reads and writes: depth, colour, labels and masks. Row-major,
/// pixel p = v * width + u, no padding (a caller's strided or BGR memory comes in through
/// image_view.hpp).
#include <cstdint>
#include <vector>

namespace wul3d {

/// 16-bit depth, row-major. metres = value * scale_m_per_unit; 0 = invalid.
struct DepthImage {
    int width = 0;
    int height = 0;
    float scale_m_per_unit = 0.001f;
    std::vector<std::uint16_t> data;  ///< width * height

    bool empty() const { return data.empty(); }
};

/// 8-bit colour, row-major, interleaved R, G, B (not OpenCV's BGR).
struct ColorImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;  ///< 3 * width * height

    bool empty() const { return rgb.empty(); }
};

/// Per-pixel labels, 16-bit: clusters (0 = no point, 1..k), segments or objects (0 =
/// background), ground truth.
struct LabelImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint16_t> labels;
};

/// A per-pixel mask of an image's size: 255 = in, 0 = out (selected.png, the followed
/// object); width and height are the image's.
using Mask = std::vector<std::uint8_t>;

}  // namespace wul3d
