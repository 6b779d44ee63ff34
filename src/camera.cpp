#include "wul3d/camera.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "wul3d/error.hpp"

namespace wul3d {

void PinholeIntrinsics::validate(const std::string& what) const {
    const bool ok = width > 0 && height > 0 && std::isfinite(fx) && std::isfinite(fy) &&
                    std::isfinite(cx) && std::isfinite(cy) && fx > 0 && fy > 0;
    if (!ok) {
        std::ostringstream msg;
        msg << what << ": invalid intrinsics (width " << width << ", height " << height
            << ", fx " << fx << ", fy " << fy << ", cx " << cx << ", cy " << cy
            << "): sizes and focal lengths must be positive";
        throw ParamError(msg.str());
    }
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
