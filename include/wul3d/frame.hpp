#pragma once
/// @file frame.hpp
/// Images and the registered RGB-D frame that every later stage consumes.
#include <cstdint>
#include <string>
#include <vector>

#include "wul3d/camera.hpp"

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
