#include "wul3d/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "wul3d/error.hpp"

namespace wul3d {

namespace {

[[noreturn]] void invalid(const std::string& what, const PinholeIntrinsics& K, const char* why) {
    std::ostringstream msg;
    msg << what << ": invalid intrinsics (width " << K.width << ", height " << K.height
        << ", fx " << K.fx << ", fy " << K.fy << ", cx " << K.cx << ", cy " << K.cy << "): " << why;
    throw ParamError(msg.str());
}

}  // namespace

void PinholeIntrinsics::validate_unsized(const std::string& what) const {
    const bool finite = std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy);
    if (!finite) invalid(what, *this, "every value must be a finite number");
    if (!(fx >= kMinFocalPx && fy >= kMinFocalPx && fx <= kMaxFocalPx && fy <= kMaxFocalPx))
        invalid(what, *this, "fx and fy must be in [0.01, 1e8] pixels");
    if (!(std::abs(cx) <= kMaxFocalPx && std::abs(cy) <= kMaxFocalPx))
        invalid(what, *this, "cx and cy must be in [-1e8, 1e8] pixels");
}

void PinholeIntrinsics::validate(const std::string& what) const {
    if (!(width > 0 && height > 0 && width <= kMaxSidePx && height <= kMaxSidePx))
        invalid(what, *this, "width and height must be in [1, 65536]");
    validate_unsized(what);
    // A field of view between about 170 and 0.06 degrees: fx = W / (2 tan(fov / 2)).
    const double w = width, h = height, side = std::max(w, h);
    if (!(fx >= w / 20 && fy >= h / 20 && fx <= 1000 * side && fy <= 1000 * side))
        invalid(what, *this,
                "fx must be in [width / 20, 1000 max(width, height)] and fy in [height / 20, "
                "1000 max(width, height)] (a field of view of 170 down to 0.06 degrees)");
    // The principal point lies in the image or at most one image size beyond its edges.
    if (!(cx >= -w && cx <= 2 * w && cy >= -h && cy <= 2 * h))
        invalid(what, *this, "cx must be in [-width, 2 width] and cy in [-height, 2 height]");
}

void FovCamera::back_project(double px, double py, double z, double& x, double& y) const {
    const double scale_x = 2.0 * std::tan(fov_x_rad / 2.0);  // eq. (10)
    const double scale_y = 2.0 * std::tan(fov_y_rad / 2.0);  // eq. (11)
    x = z * scale_x * (px / width - 0.5);                    // eq. (12)
    y = z * scale_y * (py / height - 0.5);                   // eq. (13), R_h (typo fixed)
}

PinholeIntrinsics FovCamera::to_pinhole() const {
    PinholeIntrinsics K;
    K.width = width;
    K.height = height;
    K.fx = width / (2.0 * std::tan(fov_x_rad / 2.0));
    K.fy = height / (2.0 * std::tan(fov_y_rad / 2.0));
    K.cx = width / 2.0;
    K.cy = height / 2.0;
    return K;
}

FovCamera kinect_v2_color_fov() {
    // The paper's values (appendix): 1.22173047 rad = 70 deg, 1.0471975511 rad = 60 deg.
    return FovCamera{1920, 1080, 1.22173047, 1.0471975511};
}

PinholeIntrinsics intrinsics_preset(const std::string& name) {
    auto make = [](double fx, double fy, double cx, double cy) {
        return PinholeIntrinsics{640, 480, fx, fy, cx, cy};
    };
    if (name == "kinect_v1") return make(525.0, 525.0, 319.5, 239.5);
    // TUM RGB-D benchmark, published colour calibrations of the three Freiburg sensors.
    if (name == "tum_fr1") return make(517.3, 516.5, 318.6, 255.3);
    if (name == "tum_fr2") return make(520.9, 521.0, 325.1, 249.7);
    if (name == "tum_fr3") return make(535.4, 539.2, 320.1, 247.6);
    if (name == "kinect_v2_color") return kinect_v2_color_fov().to_pinhole();
    throw ParamError("unknown camera preset '" + name +
                     "' (known: kinect_v1, tum_fr1, tum_fr2, tum_fr3, kinect_v2_color)");
}

}  // namespace wul3d
