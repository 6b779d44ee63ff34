#pragma once
/// @file frame.hpp
/// The registered RGB-D frame that every later stage consumes, and the raw frame of a
/// two-camera sensor.
#include <string>

#include "wul3d/camera.hpp"
#include "wul3d/image.hpp"

namespace wul3d {

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
