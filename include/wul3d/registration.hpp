#pragma once
/// @file registration.hpp
/// Step 2 of the paper: map colour and depth of a two-camera sensor into one frame.
///
/// A depth pixel (u_d, v_d) with depth z back-projects with the depth intrinsics to
/// P_d = z K_d^-1 (u_d, v_d, 1); the colour camera sees P_c = R P_d + t and projects it with
/// the colour intrinsics: (u_c, v_c, 1) ~ K_c P_c. R and t take depth-camera coordinates to
/// colour-camera coordinates (metres).
#include <vector>

#include "wul3d/calibration.hpp"
#include "wul3d/frame.hpp"

namespace wul3d {

/// Reusable buffers so that registration allocates nothing after the first frame.
struct RegistrationWorkspace {
    std::vector<float> zbuffer;  ///< metres, colour resolution
};

/// Depth into the colour camera with a z-buffer: each depth pixel's footprint (its four
/// corners projected) is splatted to the colour pixels it covers, nearest surface wins.
/// The result has the colour resolution and intrinsics; colour is passed through.
void register_depth_to_color(const StereoCalibration& calib, const RawRgbdFrame& raw,
                             RegistrationWorkspace& ws, RgbdFrame& out);

/// Colour into the depth camera: each depth pixel takes the colour at its projection.
/// Depth pixels that project outside the colour image, or are hidden there behind a nearer
/// surface (z-buffer test, 2 cm + 1 % tolerance), have no colour and are dropped (depth 0).
/// The result has the depth resolution and intrinsics.
void register_color_to_depth(const StereoCalibration& calib, const RawRgbdFrame& raw,
                             RegistrationWorkspace& ws, RgbdFrame& out);

}  // namespace wul3d
