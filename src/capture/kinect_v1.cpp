#include "wul3d/kinect_v1.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "wul3d/error.hpp"

namespace wul3d {

namespace {

/// raw -> millimetres, rounded; 0 where there is no reading. Built once.
const std::array<std::uint16_t, 2048>& raw_to_mm_table() {
    static const std::array<std::uint16_t, 2048> table = [] {
        std::array<std::uint16_t, 2048> t{};
        for (int d = 0; d < 2048; ++d) {
            const double mm = std::round(kinect_v1_raw_to_m(static_cast<std::uint16_t>(d)) * 1000.0);
            t[d] = static_cast<std::uint16_t>(std::min(mm, 65535.0));
        }
        return t;
    }();
    return table;
}

/// The RGB camera seen from the IR camera's side: the inverse extrinsic, with the roles of
/// the two cameras swapped, so that register_depth_to_color splats RGB-camera depth into
/// the IR camera.
StereoCalibration inverse(const StereoCalibration& c) {
    StereoCalibration inv = c;
    inv.depth = c.color;
    inv.color = c.depth;
    const auto& R = c.rotation;
    const auto& t = c.translation_m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) inv.rotation[3 * i + j] = R[3 * j + i];  // R^T
    for (int i = 0; i < 3; ++i)  // -R^T t
        inv.translation_m[i] = -(R[i] * t[0] + R[3 + i] * t[1] + R[6 + i] * t[2]);
    return inv;
}

}  // namespace

double kinect_v1_raw_to_m(std::uint16_t raw) {
    if (raw > kKinectV1MaxRaw) return 0.0;
    return 1.0 / (kKinectV1DispA * raw + kKinectV1DispB);
}

std::uint16_t kinect_v1_m_to_raw(double z_m) {
    if (!std::isfinite(z_m) || z_m <= 0.0) return kKinectV1NoDepth;
    const double d = std::round((1.0 / z_m - kKinectV1DispB) / kKinectV1DispA);
    if (d < 0.0 || d > kKinectV1MaxRaw) return kKinectV1NoDepth;
    return static_cast<std::uint16_t>(d);
}

double kinect_v1_step_m(double z_m) { return -kKinectV1DispA * z_m * z_m; }

StereoCalibration kinect_v1_calibration() {
    // N. Burrus, "Kinect calibration" (2011): IR camera fx_d, fy_d, cx_d, cy_d; RGB camera
    // fx_rgb, fy_rgb, cx_rgb, cy_rgb; R and T with P_rgb = R P_ir + T (metres). One device's
    // calibration, widely reused as the Kinect v1's typical values; see docs/CAMERAS.md.
    StereoCalibration c;
    c.depth = PinholeIntrinsics{kKinectV1Width, kKinectV1Height, 5.9421434211923247e+02,
                                5.9104053696870778e+02, 3.3930780975300314e+02,
                                2.4273913761751615e+02};
    c.color = PinholeIntrinsics{kKinectV1Width, kKinectV1Height, 5.2921508098293293e+02,
                                5.2556393630057437e+02, 3.2894272028759258e+02,
                                2.6748068171871557e+02};
    c.rotation = {9.9984628826577793e-01,  1.2635359098409581e-03, -1.7487233004436643e-02,
                  -1.4779096108364480e-03, 9.9992385683542895e-01, -1.2251380107679535e-02,
                  1.7470421412464927e-02,  1.2275341476520762e-02, 9.9977202419716948e-01};
    c.translation_m = {1.9985242312092553e-02, -7.4423738761617583e-04, -1.0916736334336222e-02};
    c.depth_scale_m_per_unit = 0.001f;
    return c;
}

void kinect_v1_raw_to_depth(const std::uint16_t* raw, DepthImage& out) {
    const std::size_t n = static_cast<std::size_t>(kKinectV1Width) * kKinectV1Height;
    out.width = kKinectV1Width;
    out.height = kKinectV1Height;
    out.scale_m_per_unit = 0.001f;
    out.data.resize(n);
    const auto& table = raw_to_mm_table();
    for (std::size_t p = 0; p < n; ++p) out.data[p] = table[raw[p] & 2047u];
}

void kinect_v1_depth_to_raw(const DepthImage& depth, RegistrationWorkspace& ws,
                            std::vector<std::uint16_t>& raw) {
    if (depth.width != kKinectV1Width || depth.height != kKinectV1Height)
        throw InputError("depth image is " + std::to_string(depth.width) + "x" +
                         std::to_string(depth.height) + ", a Kinect v1 frame is 640x480");
    static const StereoCalibration rgb_to_ir = inverse(kinect_v1_calibration());
    RawRgbdFrame in;
    in.depth = depth;
    RgbdFrame ir;
    register_depth_to_color(rgb_to_ir, in, ws, ir);
    // The z-buffer holds the IR camera's depth in metres before quantization to the input's
    // units (+inf where nothing landed): converting from it avoids rounding twice.
    raw.resize(ws.zbuffer.size());
    for (std::size_t p = 0; p < raw.size(); ++p) raw[p] = kinect_v1_m_to_raw(ws.zbuffer[p]);
}

}  // namespace wul3d
