#pragma once
/// @file frame.hpp
/// The registered RGB-D frame that every later stage consumes, and the raw frame of a
/// two-camera sensor.
#include <cstdint>
#include <string>
#include <string_view>

#include "wul3d/camera.hpp"
#include "wul3d/image.hpp"

namespace wul3d {

/// A registered RGB-D frame in memory someone else owns: what the stages read. Rows packed
/// (pixel p = v * width + u), colour RGB, depth 16-bit with its scale; valid while that memory
/// is. RgbdFrame::view() gives one without copying, and so does a caller's FrameView of this
/// layout (image_view.hpp).
struct RgbdView {
    std::string_view name;
    PinholeIntrinsics intrinsics;
    int width = 0, height = 0;                 ///< the depth image's size
    const std::uint16_t* depth = nullptr;      ///< width * height; 0 = invalid
    float depth_scale_m_per_unit = 0.001f;     ///< metres = value * scale
    const std::uint8_t* rgb = nullptr;         ///< 3 * color_width * color_height; nullptr: none
    int color_width = 0, color_height = 0;

    bool has_color() const { return rgb != nullptr; }
    /// Colour of the depth's size (what every stage needs of a frame with colour).
    bool color_matches() const { return color_width == width && color_height == height; }
};

/// A registered RGB-D frame: colour and depth pixel-aligned, one intrinsics for both.
/// A depth-only frame has an empty `color`. Unregistered input becomes this shape
/// through registration.hpp first.
struct RgbdFrame {
    std::string name;  ///< used for output folder names: OUT/<name>/
    PinholeIntrinsics intrinsics;
    DepthImage depth;
    ColorImage color;  ///< empty for depth-only frames

    int width() const { return depth.width; }
    int height() const { return depth.height; }
    bool has_color() const { return !color.empty(); }
    /// This frame as the stages read it; no copy.
    RgbdView view() const {
        return {name,        intrinsics,          depth.width, depth.height, depth.data.data(),
                depth.scale_m_per_unit, has_color() ? color.rgb.data() : nullptr, color.width,
                color.height};
    }
};

/// Unregistered colour + depth of a two-camera sensor (e.g. Kinect v2: colour 1920x1080,
/// depth 512x424); becomes an RgbdFrame through register_depth_to_color or
/// register_color_to_depth (registration.hpp).
struct RawRgbdFrame {
    std::string name;
    DepthImage depth;
    ColorImage color;
};

}  // namespace wul3d
