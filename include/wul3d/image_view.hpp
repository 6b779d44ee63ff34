#pragma once
/// @file image_view.hpp
/// A frame in the caller's memory (a camera driver's buffer, an OpenCV Mat, a numpy array),
/// described rather than copied: pointer, size, row stride in bytes; colour RGB or BGR;
/// depth 16-bit with a scale or 32-bit float metres. Pipeline::process(const FrameView&)
/// reads it in place when its layout is the stages' own (RgbdView: packed rows, RGB, 16-bit
/// depth) and converts it once otherwise.
#include <cstddef>
#include <cstdint>
#include <string>

#include "wul3d/camera.hpp"
#include "wul3d/frame.hpp"

namespace wul3d {

enum class ColorOrder { RGB, BGR };  ///< byte order of a colour pixel (OpenCV's is BGR)

/// 8-bit colour, 3 bytes a pixel. `data` nullptr: a depth-only frame.
struct ColorView {
    const std::uint8_t* data = nullptr;
    int width = 0, height = 0;
    std::size_t stride_bytes = 0;  ///< from one row to the next; 0 = 3 * width (packed)
    ColorOrder order = ColorOrder::RGB;
};

enum class DepthFormat {
    U16,          ///< 16-bit units: metres = value * scale_m_per_unit; 0 = invalid
    F32Metres,    ///< 32-bit float metres; 0, negative, NaN or infinite = invalid
};

/// One depth value a pixel.
struct DepthView {
    const void* data = nullptr;
    int width = 0, height = 0;
    std::size_t stride_bytes = 0;  ///< from one row to the next; 0 = packed
    DepthFormat format = DepthFormat::U16;
    /// U16: metres per unit. F32Metres: the step the stages' 16-bit depth is quantized to
    /// (depth beyond 65535 steps is invalid); 1 mm by default, as in every reader.
    float scale_m_per_unit = 0.001f;
};

/// A registered frame (colour and depth pixel-aligned, one intrinsics) in the caller's memory.
struct FrameView {
    std::string name;  ///< used in error messages
    /// fx, fy, cx, cy in pixels; width and height 0 = the depth's size.
    PinholeIntrinsics intrinsics;
    DepthView depth;
    ColorView color;  ///< data nullptr: depth only
};

/// The frame as the stages read it: `view` itself when its layout is theirs (16-bit depth and
/// RGB colour with packed rows, depth 2-byte aligned), else a copy of it in that layout in
/// `staging` (buffers reused). Valid while `view`'s memory and `staging` are. Throws
/// InputError naming the frame for null data, a size <= 0, a stride shorter than a row,
/// colour of another size than the depth, intrinsics that are not finite with fx, fy > 0,
/// or a depth scale that is not finite and > 0.
RgbdView stage_view(const FrameView& view, RgbdFrame& staging);

}  // namespace wul3d
