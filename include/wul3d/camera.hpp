#pragma once
/// @file camera.hpp
/// Camera models: the pinhole model and the paper's field-of-view model (appendix,
/// eq. 10-14), which is a pinhole camera with fx = width / (2 tan(fov_x / 2)), cx = width / 2.
#include <string>

namespace wul3d {

inline constexpr int kMaxSidePx = 65536;        ///< the longest image side of any intrinsics
inline constexpr double kMinFocalPx = 0.01;     ///< bounds of validate_unsized
inline constexpr double kMaxFocalPx = 1e8;

/// Pinhole intrinsics of an undistorted camera, in pixels.
/// Projection: u = fx * x / z + cx, v = fy * y / z + cy (x right, y down, z forward, metres).
struct PinholeIntrinsics {
    int width = 0;
    int height = 0;
    double fx = 0, fy = 0, cx = 0, cy = 0;

    /// Throws ParamError (one line starting with `what`) unless every value is finite and in
    /// its physical range (docs/INPUTS.md, "Limits"): width and height in [1, 65536]; fx in
    /// [width / 20, 1000 max(width, height)], fy likewise with height (a field of view from
    /// about 170 down to 0.06 degrees); cx in [-width, 2 width], cy in [-height, 2 height].
    void validate(const std::string& what = "intrinsics") const;
    /// The checks that need no image size, for intrinsics given before the frames' sizes are
    /// known: finite, fx and fy in [0.01, 1e8], |cx| and |cy| <= 1e8.
    void validate_unsized(const std::string& what = "intrinsics") const;
    bool sized() const { return width != 0 || height != 0; }
    bool same_size(int w, int h) const { return width == w && height == h; }
};

/// The paper's field-of-view camera (appendix eq. 10-14). fov in radians.
/// scale_x = 2 tan(fov_x / 2) (eq. 10), W_x = P_z * scale_x * (P_x / R_w - 0.5) (eq. 12);
/// y likewise with R_h (the paper's R_w in eq. 13 is a typo, see ALGORITHM.md step 3).
struct FovCamera {
    int width = 0;
    int height = 0;
    double fov_x_rad = 0;
    double fov_y_rad = 0;

    /// Eq. 12-14: the 3D point (metres) seen at pixel (px, py) with depth z.
    void back_project(double px, double py, double z, double& x, double& y) const;
    /// The equivalent pinhole camera: fx = R_w / scale_x, cx = R_w / 2 (and y alike).
    PinholeIntrinsics to_pinhole() const;
};

/// Kinect v2 colour camera as the paper models it: 1920x1080, fov 70 x 60 degrees.
FovCamera kinect_v2_color_fov();

/// Pinhole back-projection of one pixel: x = (u - cx) z / fx, y = (v - cy) z / fy.
inline void back_project(const PinholeIntrinsics& K, double u, double v, double z, double& x,
                         double& y) {
    x = (u - K.cx) * z / K.fx;
    y = (v - K.cy) * z / K.fy;
}

/// Pinhole projection of a 3D point (z > 0) to pixel coordinates.
inline void project(const PinholeIntrinsics& K, double x, double y, double z, double& u,
                    double& v) {
    u = K.fx * x / z + K.cx;
    v = K.fy * y / z + K.cy;
}

/// Named intrinsics presets. Known names: "kinect_v1" (fx = fy = 525, cx = 319.5,
/// cy = 239.5, 640x480: the OpenNI default, also TUM's "ROS default"), "tum_fr1",
/// "tum_fr2", "tum_fr3" (TUM RGB-D's published colour calibrations, 640x480),
/// "kinect_v2_color" (pinhole equivalent of the paper's FOV model, 1920x1080).
/// Throws ParamError for an unknown name.
PinholeIntrinsics intrinsics_preset(const std::string& name);

}  // namespace wul3d
