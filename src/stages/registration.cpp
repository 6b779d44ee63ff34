#include "wul3d/registration.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "wul3d/error.hpp"

namespace wul3d {

namespace {

std::string size_str(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// A footprint wider than this (colour pixels) only comes from a point almost on the colour
// camera's plane (z_c -> 0); splatting it would paint a large part of the image.
constexpr double kMaxFootprintPx = 256.0;
// Points nearer than this to the colour camera's plane are not projected.
constexpr double kMinZ_m = 1e-3;

/// The raw sizes must be the calibration's sizes; colour may be absent (depth-only).
void check_sizes(const StereoCalibration& calib, const RawRgbdFrame& raw) {
    const DepthImage& d = raw.depth;
    if (!calib.depth.same_size(d.width, d.height) ||
        d.data.size() != static_cast<std::size_t>(d.width) * d.height) {
        throw InputError(raw.name + ": depth image is " + size_str(d.width, d.height) +
                         " but the calibration's depth camera is " +
                         size_str(calib.depth.width, calib.depth.height));
    }
    const ColorImage& c = raw.color;
    if (!c.empty() && (!calib.color.same_size(c.width, c.height) ||
                       c.rgb.size() != 3 * static_cast<std::size_t>(c.width) * c.height)) {
        throw InputError(raw.name + ": colour image is " + size_str(c.width, c.height) +
                         " but the calibration's colour camera is " +
                         size_str(calib.color.width, calib.color.height));
    }
    if (!(d.scale_m_per_unit > 0.0f) || !std::isfinite(d.scale_m_per_unit)) {
        throw InputError(raw.name + ": depth scale " + std::to_string(d.scale_m_per_unit) +
                         " m/unit must be positive");
    }
}

/// Depth camera pixel (u, v) at depth z (metres) in colour-camera coordinates:
/// P_c = R z K_d^-1 (u, v, 1) + t.
struct Rigid {
    double r[9];
    double t[3];
    double fx_d, fy_d, cx_d, cy_d;
    double fx_c, fy_c, cx_c, cy_c;

    explicit Rigid(const StereoCalibration& c) {
        std::copy(c.rotation.begin(), c.rotation.end(), r);
        std::copy(c.translation_m.begin(), c.translation_m.end(), t);
        fx_d = c.depth.fx, fy_d = c.depth.fy, cx_d = c.depth.cx, cy_d = c.depth.cy;
        fx_c = c.color.fx, fy_c = c.color.fy, cx_c = c.color.cx, cy_c = c.color.cy;
    }

    void to_color(double u, double v, double z, double& xc, double& yc, double& zc) const {
        const double xd = (u - cx_d) * z / fx_d;
        const double yd = (v - cy_d) * z / fy_d;
        xc = r[0] * xd + r[1] * yd + r[2] * z + t[0];
        yc = r[3] * xd + r[4] * yd + r[5] * z + t[1];
        zc = r[6] * xd + r[7] * yd + r[8] * z + t[2];
    }
};

/// Atomic minimum on a float cell: positive z values only, +inf = empty. The result does not
/// depend on the order of the writes, so the splat is deterministic under any thread count.
inline void atomic_min(float& cell, float z) {
    std::atomic_ref<float> ref(cell);
    float cur = ref.load(std::memory_order_relaxed);
    while (z < cur && !ref.compare_exchange_weak(cur, z, std::memory_order_relaxed)) {
    }
}

/// Z-buffer splat: every valid depth pixel's footprint (corners u +- 0.5, v +- 0.5 at the
/// pixel's depth) is projected into the colour camera and the colour pixels whose centres lie
/// in the bounding box of the four projected corners take z_c if it is the nearest so far.
/// A footprint that covers no pixel centre (colour coarser than depth) writes the colour
/// pixel nearest its projected centre. zbuffer: metres, colour resolution, +inf = empty.
void splat_depth(const StereoCalibration& calib, const DepthImage& depth,
                 std::vector<float>& zbuffer) {
    const int wd = depth.width, hd = depth.height;
    const int wc = calib.color.width, hc = calib.color.height;
    const std::size_t nc = static_cast<std::size_t>(wc) * hc;
    zbuffer.resize(nc);  // no allocation once the size is known
    std::fill(zbuffer.begin(), zbuffer.end(), std::numeric_limits<float>::infinity());
    const Rigid rig(calib);
    const double scale = depth.scale_m_per_unit;
    float* zb = zbuffer.data();

#pragma omp parallel for schedule(static)
    for (int v = 0; v < hd; ++v) {
        const std::uint16_t* row = depth.data.data() + static_cast<std::size_t>(v) * wd;
        for (int u = 0; u < wd; ++u) {
            if (row[u] == 0) continue;
            const double z = row[u] * scale;
            double xc, yc, zc;
            rig.to_color(u, v, z, xc, yc, zc);
            if (zc < kMinZ_m) continue;
            double umin = std::numeric_limits<double>::infinity(), umax = -umin;
            double vmin = umin, vmax = -umin;
            bool ok = true;
            for (int corner = 0; corner < 4; ++corner) {
                const double du = (corner & 1) ? 0.5 : -0.5;
                const double dv = (corner & 2) ? 0.5 : -0.5;
                double x, y, zz;
                rig.to_color(u + du, v + dv, z, x, y, zz);
                if (zz < kMinZ_m) {
                    ok = false;
                    break;
                }
                const double pu = rig.fx_c * x / zz + rig.cx_c;
                const double pv = rig.fy_c * y / zz + rig.cy_c;
                umin = std::min(umin, pu), umax = std::max(umax, pu);
                vmin = std::min(vmin, pv), vmax = std::max(vmax, pv);
            }
            if (!ok || umax - umin > kMaxFootprintPx || vmax - vmin > kMaxFootprintPx) continue;
            // Colour pixel (i, j) is centred on (i, j): it is covered when umin <= i <= umax.
            double i0 = std::ceil(umin), i1 = std::floor(umax);
            double j0 = std::ceil(vmin), j1 = std::floor(vmax);
            if (i0 > i1 || j0 > j1) {
                i0 = i1 = std::round(rig.fx_c * xc / zc + rig.cx_c);
                j0 = j1 = std::round(rig.fy_c * yc / zc + rig.cy_c);
            }
            i0 = std::max(i0, 0.0), j0 = std::max(j0, 0.0);
            i1 = std::min(i1, wc - 1.0), j1 = std::min(j1, hc - 1.0);
            if (i0 > i1 || j0 > j1) continue;  // outside the colour image
            const float zf = static_cast<float>(zc);
            for (int j = static_cast<int>(j0); j <= static_cast<int>(j1); ++j) {
                float* zrow = zb + static_cast<std::size_t>(j) * wc;
                for (int i = static_cast<int>(i0); i <= static_cast<int>(i1); ++i)
                    atomic_min(zrow[i], zf);
            }
        }
    }
}

std::uint16_t quantize(float z_m, double inv_scale) {
    if (!std::isfinite(z_m)) return 0;
    const double units = std::round(z_m * inv_scale);
    if (units < 1.0) return 0;
    return static_cast<std::uint16_t>(std::min(units, 65535.0));
}

}  // namespace

void StereoCalibration::validate() const {
    depth.validate("calibration depth camera");
    color.validate("calibration colour camera");
    const auto& R = rotation;
    double worst = 0.0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            double dot = 0.0;  // (R^T R)_ij = column i . column j
            for (int k = 0; k < 3; ++k) dot += R[3 * k + i] * R[3 * k + j];
            const double e = std::abs(dot - (i == j ? 1.0 : 0.0));
            worst = std::isfinite(e) ? std::max(worst, e) : std::numeric_limits<double>::infinity();
        }
    }
    const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                       R[2] * (R[3] * R[7] - R[4] * R[6]);
    if (worst > 1e-3 || !(det > 0.0)) {
        std::ostringstream msg;
        msg << "StereoCalibration.rotation is not a rotation (|R^T R - I| = " << worst
            << ", det = " << det << "; need |R^T R - I| <= 1e-3 and det > 0)";
        throw ParamError(msg.str());
    }
    // Two cameras of one sensor: at most 10 m apart.
    for (double t : translation_m) {
        if (!(std::abs(t) <= 10.0))
            throw ParamError("StereoCalibration.translation_m = " + std::to_string(t) +
                             ": each component must be finite and in [-10, 10] metres");
    }
    if (!(depth_scale_m_per_unit >= 1e-6f && depth_scale_m_per_unit <= 1.0f)) {
        throw ParamError("StereoCalibration.depth_scale_m_per_unit = " +
                         std::to_string(depth_scale_m_per_unit) + ": must be in [1e-6, 1]");
    }
}

StereoCalibration kinect_v2_default_calibration() {
    // Typical Kinect v2 values, not the calibration of any one device: the depth (IR)
    // camera's focal length as Kinect v2 drivers commonly report it (fx = fy ~ 365.5 px,
    // 512x424) with the principal point put at the image centre, the colour camera's widely
    // used default (fx = fy = 1081.37 px, cx = 959.5, cy = 539.5, 1920x1080), no rotation and
    // a 5.2 cm baseline along x: t = (0.052, 0, 0) puts the colour camera's centre at
    // x = -5.2 cm in depth-camera coordinates (which side that is on the device depends on
    // whether the driver mirrors the images). Lens distortion is ignored. Real devices
    // differ by a few pixels and millimetres; see docs/INPUTS.md.
    StereoCalibration c;
    c.depth = PinholeIntrinsics{512, 424, 365.5, 365.5, 255.5, 211.5};
    c.color = PinholeIntrinsics{1920, 1080, 1081.37, 1081.37, 959.5, 539.5};
    c.rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    c.translation_m = {0.052, 0.0, 0.0};
    c.depth_scale_m_per_unit = 0.001f;
    return c;
}

void register_depth_to_color(const StereoCalibration& calib, const RawRgbdFrame& raw,
                             RegistrationWorkspace& ws, RgbdFrame& out) {
    check_sizes(calib, raw);
    splat_depth(calib, raw.depth, ws.zbuffer);

    const int wc = calib.color.width, hc = calib.color.height;
    out.name = raw.name;
    out.intrinsics = calib.color;
    out.depth.width = wc;
    out.depth.height = hc;
    out.depth.scale_m_per_unit = raw.depth.scale_m_per_unit;
    out.depth.data.resize(static_cast<std::size_t>(wc) * hc);
    const double inv_scale = 1.0 / raw.depth.scale_m_per_unit;
    const float* zb = ws.zbuffer.data();
    std::uint16_t* dst = out.depth.data.data();
#pragma omp parallel for schedule(static)
    for (int j = 0; j < hc; ++j) {
        const std::size_t row = static_cast<std::size_t>(j) * wc;
        for (int i = 0; i < wc; ++i) dst[row + i] = quantize(zb[row + i], inv_scale);
    }

    // Colour passes through; vector assignment reuses the capacity of `out`.
    out.color.width = raw.color.width;
    out.color.height = raw.color.height;
    out.color.rgb = raw.color.rgb;
}

void register_color_to_depth(const StereoCalibration& calib, const RawRgbdFrame& raw,
                             RegistrationWorkspace& ws, RgbdFrame& out) {
    check_sizes(calib, raw);
    const int wd = calib.depth.width, hd = calib.depth.height;
    const int wc = calib.color.width, hc = calib.color.height;
    const std::size_t nd = static_cast<std::size_t>(wd) * hd;

    out.name = raw.name;
    out.intrinsics = calib.depth;
    out.depth.width = wd;
    out.depth.height = hd;
    out.depth.scale_m_per_unit = raw.depth.scale_m_per_unit;
    if (raw.color.empty()) {
        // Depth-only input: nothing to sample, the depth is already in the depth camera.
        out.depth.data = raw.depth.data;
        out.color.width = out.color.height = 0;
        out.color.rgb.clear();
        return;
    }
    // What the colour camera sees: a dense z-buffer of the depth, used for the occlusion test.
    splat_depth(calib, raw.depth, ws.zbuffer);

    out.depth.data.resize(nd);
    out.color.width = wd;
    out.color.height = hd;
    out.color.rgb.resize(3 * nd);
    const Rigid rig(calib);
    const double scale = raw.depth.scale_m_per_unit;
    const float* zb = ws.zbuffer.data();
    const std::uint8_t* src = raw.color.rgb.data();
    const std::uint16_t* din = raw.depth.data.data();
    std::uint16_t* dout = out.depth.data.data();
    std::uint8_t* cdst = out.color.rgb.data();

#pragma omp parallel for schedule(static)
    for (int v = 0; v < hd; ++v) {
        for (int u = 0; u < wd; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * wd + u;
            std::uint16_t d = din[p];
            std::uint8_t rgb[3] = {0, 0, 0};
            if (d != 0) {
                double xc, yc, zc;
                rig.to_color(u, v, d * scale, xc, yc, zc);
                bool seen = zc >= kMinZ_m;
                long i = 0, j = 0;
                if (seen) {
                    i = std::lround(rig.fx_c * xc / zc + rig.cx_c);
                    j = std::lround(rig.fy_c * yc / zc + rig.cy_c);
                    seen = i >= 0 && i < wc && j >= 0 && j < hc;
                }
                if (seen) {
                    // Hidden when the colour camera sees a surface nearer than this point by
                    // more than the tolerance (2 cm + 1 % of the nearer depth).
                    const std::size_t q = static_cast<std::size_t>(j) * wc + i;
                    const double z_seen = zb[q];
                    seen = zc <= z_seen + 0.02 + 0.01 * z_seen;
                    if (seen) {
                        rgb[0] = src[3 * q], rgb[1] = src[3 * q + 1], rgb[2] = src[3 * q + 2];
                    }
                }
                if (!seen) d = 0;
            }
            dout[p] = d;
            cdst[3 * p] = rgb[0], cdst[3 * p + 1] = rgb[1], cdst[3 * p + 2] = rgb[2];
        }
    }
}

RegistrationMode parse_registration_mode(const std::string& name) {
    if (name == "depth-to-color") return RegistrationMode::DepthToColor;
    if (name == "color-to-depth") return RegistrationMode::ColorToDepth;
    throw ParamError("unknown registration mode '" + name +
                     "' (known: depth-to-color, color-to-depth)");
}

}  // namespace wul3d
