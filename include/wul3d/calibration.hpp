#pragma once
/// @file calibration.hpp
/// A two-camera sensor's calibration and the direction of registration: the types that the
/// readers (io.hpp), the cameras (capture.hpp) and registration (registration.hpp, step 2 of
/// the paper) share. Defined in registration.cpp.
#include <array>
#include <string>

#include "wul3d/camera.hpp"

namespace wul3d {

/// Intrinsics of both cameras and the depth-to-colour extrinsic.
struct StereoCalibration {
    PinholeIntrinsics depth;
    PinholeIntrinsics color;
    std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< R, row-major, depth -> colour
    std::array<double, 3> translation_m{0, 0, 0};                ///< t, metres, depth -> colour
    float depth_scale_m_per_unit = 0.001f;

    /// Throws ParamError if an intrinsics is invalid or R is not a rotation (|R^T R - I| > 1e-3).
    void validate() const;
};

/// Typical Kinect v2 values (depth 512x424, colour 1920x1080, colour camera 5.2 cm along
/// the depth camera's x axis). A per-device calibration is better: see docs/INPUTS.md.
StereoCalibration kinect_v2_default_calibration();

/// Which way registration goes.
enum class RegistrationMode {
    DepthToColor,  ///< one point per colour pixel (the paper's choice): depth splatted with a z-buffer
    ColorToDepth,  ///< one point per depth pixel: colour sampled where the depth pixel projects
};

/// "depth-to-color" / "color-to-depth"; throws ParamError otherwise.
RegistrationMode parse_registration_mode(const std::string& name);

}  // namespace wul3d
