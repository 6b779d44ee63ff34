// Registration against a synthetic two-camera scene whose answer is known analytically:
// a wall, a tilted panel and a box, seen by a 512x424 depth camera and a 1920x1080 colour
// camera rotated by a few degrees and shifted by about 5 cm. The colour image encodes each
// colour pixel's own (u, v), so a sampled colour says exactly where it came from.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/registration.hpp"

namespace {

using wul3d::ColorImage;
using wul3d::DepthImage;
using wul3d::PinholeIntrinsics;
using wul3d::RawRgbdFrame;
using wul3d::RgbdFrame;
using wul3d::StereoCalibration;

struct Vec3 {
    double x = 0, y = 0, z = 0;
};
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Surface ids of the scene; each box face has its own so that grazing side faces can be
// told apart from the front face.
enum Surface : int {
    kNone = 0,
    kWall = 1,       // z = 3 m, facing the cameras
    kPanel = 2,      // tilted 30 degrees about y, at about 2 m
    kBoxFront = 3,   // z = 1.2 m face of the box
    kBoxOther = 4,   // any other face of the box (grazing from these cameras)
};

struct Hit {
    double s = std::numeric_limits<double>::infinity();  // ray parameter
    int id = kNone;
};

/// The scene in depth-camera coordinates (metres, x right, y down, z forward).
/// `dir` need not be unit length: s is in units of dir.
Hit cast(Vec3 o, Vec3 dir) {
    Hit best;
    auto plane = [&](Vec3 point, Vec3 normal, int id, auto inside) {
        const double den = dot(normal, dir);
        if (std::abs(den) < 1e-12) return;
        const double s = dot(normal, point - o) / den;
        if (s <= 0 || s >= best.s) return;
        if (!inside(o + s * dir)) return;
        best = {s, id};
    };
    plane({0, 0, 3.0}, {0, 0, -1}, kWall, [](Vec3) { return true; });
    const double a = 30.0 * M_PI / 180.0;
    plane({-0.55, 0, 2.0}, {std::sin(a), 0, -std::cos(a)}, kPanel,
          [](Vec3 p) { return p.x >= -1.0 && p.x <= -0.1 && p.y >= -0.5 && p.y <= 0.5; });
    // Box: slab method.
    const Vec3 lo{0.1, -0.25, 1.2}, hi{0.5, 0.25, 1.5};
    double t_near = -std::numeric_limits<double>::infinity();
    double t_far = std::numeric_limits<double>::infinity();
    int axis_near = -1;
    const double os[3] = {o.x, o.y, o.z}, ds[3] = {dir.x, dir.y, dir.z};
    const double los[3] = {lo.x, lo.y, lo.z}, his[3] = {hi.x, hi.y, hi.z};
    bool miss = false;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(ds[k]) < 1e-15) {
            if (os[k] < los[k] || os[k] > his[k]) miss = true;
            continue;
        }
        double t0 = (los[k] - os[k]) / ds[k], t1 = (his[k] - os[k]) / ds[k];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > t_near) t_near = t0, axis_near = k;
        t_far = std::min(t_far, t1);
    }
    if (!miss && t_near <= t_far && t_near > 0 && t_near < best.s) {
        best = {t_near, axis_near == 2 ? kBoxFront : kBoxOther};
    }
    return best;
}

/// Rotation from small angles about x, y, z (degrees): R = Rz Ry Rx, row-major.
std::array<double, 9> rotation_deg(double ax, double ay, double az) {
    const double cx = std::cos(ax * M_PI / 180), sx = std::sin(ax * M_PI / 180);
    const double cy = std::cos(ay * M_PI / 180), sy = std::sin(ay * M_PI / 180);
    const double cz = std::cos(az * M_PI / 180), sz = std::sin(az * M_PI / 180);
    const double Rx[9] = {1, 0, 0, 0, cx, -sx, 0, sx, cx};
    const double Ry[9] = {cy, 0, sy, 0, 1, 0, -sy, 0, cy};
    const double Rz[9] = {cz, -sz, 0, sz, cz, 0, 0, 0, 1};
    auto mul = [](const double* A, const double* B, double* C) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                C[3 * i + j] = 0;
                for (int k = 0; k < 3; ++k) C[3 * i + j] += A[3 * i + k] * B[3 * k + j];
            }
    };
    double T[9];
    std::array<double, 9> R{};
    mul(Ry, Rx, T);
    mul(Rz, T, R.data());
    return R;
}

/// Colour of colour pixel (u, v): its own coordinates, 11 bits each.
void encode_uv(int u, int v, std::uint8_t* rgb) {
    rgb[0] = static_cast<std::uint8_t>(u & 0xff);
    rgb[1] = static_cast<std::uint8_t>(v & 0xff);
    rgb[2] = static_cast<std::uint8_t>((u >> 8) | ((v >> 8) << 4));
}
void decode_uv(const std::uint8_t* rgb, int& u, int& v) {
    u = rgb[0] | ((rgb[2] & 0x0f) << 8);
    v = rgb[1] | ((rgb[2] >> 4) << 8);
}

/// Square dilation of a 0/1 mask by radius r (separable max filter).
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& m, int w, int h, int r) {
    std::vector<std::uint8_t> tmp(m.size(), 0), out(m.size(), 0);
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            std::uint8_t any = 0;
            for (int du = std::max(0, u - r); du <= std::min(w - 1, u + r) && !any; ++du)
                any = m[static_cast<std::size_t>(v) * w + du];
            tmp[static_cast<std::size_t>(v) * w + u] = any;
        }
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            std::uint8_t any = 0;
            for (int dv = std::max(0, v - r); dv <= std::min(h - 1, v + r) && !any; ++dv)
                any = tmp[static_cast<std::size_t>(dv) * w + u];
            out[static_cast<std::size_t>(v) * w + u] = any;
        }
    return out;
}

/// Marks pixels whose id differs from a 4-neighbour's, or that are flagged bad.
std::vector<std::uint8_t> edges(const std::vector<int>& id, const std::vector<std::uint8_t>& bad,
                                int w, int h) {
    std::vector<std::uint8_t> e(id.size(), 0);
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * w + u;
            bool edge = bad[p] != 0;
            if (u + 1 < w && id[p + 1] != id[p]) edge = true;
            if (u > 0 && id[p - 1] != id[p]) edge = true;
            if (v + 1 < h && id[p + w] != id[p]) edge = true;
            if (v > 0 && id[p - w] != id[p]) edge = true;
            e[p] = edge ? 1 : 0;
        }
    return e;
}

/// The two-camera rig and the analytic renders of the scene.
struct Scene {
    StereoCalibration calib;
    Vec3 color_origin;  // colour camera centre in depth coordinates: -R^T t
    RawRgbdFrame raw;
    std::vector<double> depth_z;  // exact z of each depth pixel (inf = nothing)
    std::vector<int> depth_id;

    Scene() {
        calib = wul3d::kinect_v2_default_calibration();
        calib.rotation = rotation_deg(1.0, -3.0, 0.5);
        calib.translation_m = {0.052, -0.004, 0.003};
        const auto& R = calib.rotation;
        const auto& t = calib.translation_m;
        color_origin = {-(R[0] * t[0] + R[3] * t[1] + R[6] * t[2]),
                        -(R[1] * t[0] + R[4] * t[1] + R[7] * t[2]),
                        -(R[2] * t[0] + R[5] * t[1] + R[8] * t[2])};

        const PinholeIntrinsics& Kd = calib.depth;
        raw.name = "synthetic";
        raw.depth.width = Kd.width;
        raw.depth.height = Kd.height;
        raw.depth.scale_m_per_unit = 0.001f;
        const std::size_t nd = static_cast<std::size_t>(Kd.width) * Kd.height;
        raw.depth.data.assign(nd, 0);
        depth_z.assign(nd, std::numeric_limits<double>::infinity());
        depth_id.assign(nd, kNone);
        for (int v = 0; v < Kd.height; ++v)
            for (int u = 0; u < Kd.width; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * Kd.width + u;
                const Hit hit = cast({0, 0, 0}, depth_ray(u, v));
                depth_z[p] = hit.s;
                depth_id[p] = hit.id;
                if (hit.id != kNone) {
                    raw.depth.data[p] = static_cast<std::uint16_t>(std::lround(hit.s / 0.001));
                }
            }

        const PinholeIntrinsics& Kc = calib.color;
        raw.color.width = Kc.width;
        raw.color.height = Kc.height;
        raw.color.rgb.resize(3 * static_cast<std::size_t>(Kc.width) * Kc.height);
        for (int v = 0; v < Kc.height; ++v)
            for (int u = 0; u < Kc.width; ++u)
                encode_uv(u, v, &raw.color.rgb[3 * (static_cast<std::size_t>(v) * Kc.width + u)]);
    }

    Vec3 depth_ray(double u, double v) const {
        const PinholeIntrinsics& K = calib.depth;
        return {(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0};
    }
    /// Direction, in depth coordinates, of colour pixel (u, v)'s ray; its parameter is z_c.
    Vec3 color_ray(double u, double v) const {
        const PinholeIntrinsics& K = calib.color;
        const Vec3 dc{(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0};
        const auto& R = calib.rotation;  // R^T dc
        return {R[0] * dc.x + R[3] * dc.y + R[6] * dc.z, R[1] * dc.x + R[4] * dc.y + R[7] * dc.z,
                R[2] * dc.x + R[5] * dc.y + R[8] * dc.z};
    }
    /// A depth-camera point in colour-camera coordinates: R P + t.
    Vec3 to_color(Vec3 P) const {
        const auto& R = calib.rotation;
        const auto& t = calib.translation_m;
        return {R[0] * P.x + R[1] * P.y + R[2] * P.z + t[0],
                R[3] * P.x + R[4] * P.y + R[5] * P.z + t[1],
                R[6] * P.x + R[7] * P.y + R[8] * P.z + t[2]};
    }
};

const Scene& scene() {
    static const Scene s;
    return s;
}

TEST(RegisterColorToDepth, EachDepthPixelSamplesItsAnalyticProjection) {
    const Scene& sc = scene();
    const PinholeIntrinsics& Kd = sc.calib.depth;
    const PinholeIntrinsics& Kc = sc.calib.color;
    wul3d::RegistrationWorkspace ws;
    RgbdFrame out;
    wul3d::register_color_to_depth(sc.calib, sc.raw, ws, out);

    ASSERT_EQ(out.width(), Kd.width);
    ASSERT_EQ(out.height(), Kd.height);
    ASSERT_EQ(out.color.width, Kd.width);
    EXPECT_EQ(out.intrinsics.fx, Kd.fx);
    EXPECT_EQ(out.name, "synthetic");
    EXPECT_FLOAT_EQ(out.depth.scale_m_per_unit, 0.001f);

    // Analytic visibility of each depth pixel's point from the colour camera.
    const std::size_t nd = static_cast<std::size_t>(Kd.width) * Kd.height;
    std::vector<int> state(nd, 0);  // 0 nothing, 1 seen by colour, 2 hidden, 3 outside colour
    std::vector<std::uint8_t> no_bad(nd, 0);
    int checked = 0, wrong_uv = 0;
    for (int v = 0; v < Kd.height; ++v)
        for (int u = 0; u < Kd.width; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * Kd.width + u;
            if (sc.depth_id[p] == kNone) continue;
            const Vec3 P = sc.depth_z[p] * sc.depth_ray(u, v);
            const Vec3 Pc = sc.to_color(P);
            const double uc = Kc.fx * Pc.x / Pc.z + Kc.cx, vc = Kc.fy * Pc.y / Pc.z + Kc.cy;
            if (uc < -0.5 || uc > Kc.width - 0.5 || vc < -0.5 || vc > Kc.height - 0.5) {
                state[p] = 3;
            } else {
                const Hit first = cast(sc.color_origin, sc.color_ray(uc, vc));
                state[p] = first.s < Pc.z - 0.005 ? 2 : 1;
            }
            if (out.depth.data[p] == 0) continue;
            // A kept pixel's colour encodes the colour pixel it came from: its projection.
            int su = 0, sv = 0;
            decode_uv(&out.color.rgb[3 * p], su, sv);
            ++checked;
            if (std::abs(su - uc) > 1.0 || std::abs(sv - vc) > 1.0) ++wrong_uv;
            EXPECT_EQ(out.depth.data[p], sc.raw.depth.data[p]);
        }
    EXPECT_GT(checked, 100000);
    EXPECT_EQ(wrong_uv, 0);

    // Away from edges (2 px) of surfaces and of visibility classes, visibility must be exact.
    std::vector<int> classes(nd);
    for (std::size_t p = 0; p < nd; ++p) classes[p] = 16 * state[p] + sc.depth_id[p];
    const std::vector<std::uint8_t> near_edge =
        dilate(edges(classes, no_bad, Kd.width, Kd.height), Kd.width, Kd.height, 2);
    int seen = 0, hidden = 0, outside = 0, bad = 0;
    for (std::size_t p = 0; p < nd; ++p) {
        if (near_edge[p] || state[p] == 0) continue;
        const bool kept = out.depth.data[p] != 0;
        if (state[p] == 1) ++seen, bad += kept ? 0 : 1;
        if (state[p] == 2) ++hidden, bad += kept ? 1 : 0;
        if (state[p] == 3) ++outside, bad += kept ? 1 : 0;
        if (!kept) {
            EXPECT_EQ(out.color.rgb[3 * p] | out.color.rgb[3 * p + 1] | out.color.rgb[3 * p + 2], 0);
        }
    }
    EXPECT_GT(seen, 100000);
    EXPECT_GT(hidden, 300) << "the scene must exercise the occlusion test";
    EXPECT_GT(outside, 1000) << "the scene must exercise the image-bounds test";
    EXPECT_EQ(bad, 0) << "seen " << seen << ", hidden " << hidden << ", outside " << outside;
}

TEST(RegisterDepthToColor, DepthAtColourPixelsMatchesTheirRays_NearerSurfaceWins) {
    const Scene& sc = scene();
    const PinholeIntrinsics& Kd = sc.calib.depth;
    const PinholeIntrinsics& Kc = sc.calib.color;
    wul3d::RegistrationWorkspace ws;
    RgbdFrame out;
    wul3d::register_depth_to_color(sc.calib, sc.raw, ws, out);

    ASSERT_EQ(out.width(), Kc.width);
    ASSERT_EQ(out.height(), Kc.height);
    EXPECT_EQ(out.intrinsics.fx, Kc.fx);
    EXPECT_EQ(out.intrinsics.cx, Kc.cx);
    EXPECT_FLOAT_EQ(out.depth.scale_m_per_unit, 0.001f);
    EXPECT_EQ(out.color.rgb, sc.raw.color.rgb);

    // Analytic render of the colour camera, and whether the depth camera sees each point.
    const std::size_t nc = static_cast<std::size_t>(Kc.width) * Kc.height;
    std::vector<int> id(nc);
    std::vector<double> z(nc);
    std::vector<std::uint8_t> unseen(nc, 0);
    for (int v = 0; v < Kc.height; ++v)
        for (int u = 0; u < Kc.width; ++u) {
            const std::size_t q = static_cast<std::size_t>(v) * Kc.width + u;
            const Vec3 dir = sc.color_ray(u, v);
            const Hit hit = cast(sc.color_origin, dir);
            id[q] = hit.id;
            z[q] = hit.s;
            if (hit.id == kNone) continue;
            const Vec3 P = sc.color_origin + hit.s * dir;
            const double ud = Kd.fx * P.x / P.z + Kd.cx, vd = Kd.fy * P.y / P.z + Kd.cy;
            const bool in_depth = ud >= 0 && ud <= Kd.width - 1 && vd >= 0 && vd <= Kd.height - 1;
            const Hit from_depth = cast({0, 0, 0}, (1.0 / P.z) * P);
            unseen[q] = (!in_depth || from_depth.s < P.z - 0.005) ? 1 : 0;
        }
    // 4 colour px is more than one depth pixel's footprint (about 3 colour px).
    const std::vector<std::uint8_t> near_edge =
        dilate(edges(id, unseen, Kc.width, Kc.height), Kc.width, Kc.height, 4);

    int checked = 0, holes = 0, off = 0, overlap = 0, overlap_wrong = 0;
    double worst = 0;
    for (int v = 0; v < Kc.height; ++v)
        for (int u = 0; u < Kc.width; ++u) {
            const std::size_t q = static_cast<std::size_t>(v) * Kc.width + u;
            if (near_edge[q] || unseen[q]) continue;
            if (id[q] != kWall && id[q] != kPanel && id[q] != kBoxFront) continue;
            ++checked;
            const std::uint16_t d = out.depth.data[q];
            if (d == 0) {
                ++holes;
                continue;
            }
            const double err = std::abs(d * 0.001 - z[q]);
            worst = std::max(worst, err);
            if (err > 0.005) ++off;
            if (id[q] == kBoxFront) {
                // Where the depth camera also sees the wall behind this box pixel, both
                // surfaces were splatted here: the z-buffer must have kept the box.
                const Vec3 dir = sc.color_ray(u, v);
                const double s_wall = (3.0 - sc.color_origin.z) / dir.z;
                const Vec3 W = sc.color_origin + s_wall * dir;
                const double ud = Kd.fx * W.x / W.z + Kd.cx, vd = Kd.fy * W.y / W.z + Kd.cy;
                const long iu = std::lround(ud), iv = std::lround(vd);
                bool wall_seen = iu >= 2 && iu < Kd.width - 2 && iv >= 2 && iv < Kd.height - 2;
                for (long dv = -2; dv <= 2 && wall_seen; ++dv)
                    for (long du = -2; du <= 2 && wall_seen; ++du)
                        wall_seen = sc.depth_id[(iv + dv) * Kd.width + iu + du] == kWall;
                if (wall_seen) {
                    ++overlap;
                    if (std::abs(d * 0.001 - z[q]) > 0.005) ++overlap_wrong;
                }
            }
        }
    EXPECT_GT(checked, 1000000);
    EXPECT_EQ(holes, 0);
    EXPECT_EQ(off, 0) << "worst error " << worst << " m";
    EXPECT_GT(overlap, 1000) << "the scene must make the two surfaces overlap";
    EXPECT_EQ(overlap_wrong, 0);
}

TEST(RegisterDepthToColor, SameResultForAnyThreadCount_AndReusesBuffers) {
    const Scene& sc = scene();
    wul3d::RegistrationWorkspace ws;
    RgbdFrame a, b;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    wul3d::register_depth_to_color(sc.calib, sc.raw, ws, a);
    omp_set_num_threads(std::max(2, threads));
    const float* zbuffer = ws.zbuffer.data();
    const std::uint16_t* depth = a.depth.data.data();
    wul3d::register_depth_to_color(sc.calib, sc.raw, ws, b);
    omp_set_num_threads(threads);
    EXPECT_EQ(a.depth.data, b.depth.data);
    EXPECT_EQ(ws.zbuffer.data(), zbuffer) << "the workspace was re-allocated";
    wul3d::register_depth_to_color(sc.calib, sc.raw, ws, a);
    EXPECT_EQ(a.depth.data.data(), depth) << "the output was re-allocated";
    EXPECT_EQ(a.depth.data, b.depth.data);
}

TEST(RegisterDepthToColor, RejectsSizesThatDifferFromTheCalibration) {
    const StereoCalibration calib = wul3d::kinect_v2_default_calibration();
    RawRgbdFrame raw;
    raw.name = "f0";
    raw.depth.width = 640;
    raw.depth.height = 480;
    raw.depth.data.assign(640 * 480, 1000);
    raw.color.width = 1920;
    raw.color.height = 1080;
    raw.color.rgb.assign(3 * 1920 * 1080, 0);
    wul3d::RegistrationWorkspace ws;
    RgbdFrame out;
    for (int direction = 0; direction < 2; ++direction) {
        try {
            if (direction == 0) wul3d::register_depth_to_color(calib, raw, ws, out);
            else wul3d::register_color_to_depth(calib, raw, ws, out);
            ADD_FAILURE() << "no InputError";
        } catch (const wul3d::InputError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find("640x480"), std::string::npos) << msg;
            EXPECT_NE(msg.find("512x424"), std::string::npos) << msg;
        }
    }
    raw.depth.width = 512;
    raw.depth.height = 424;
    raw.depth.data.assign(512 * 424, 1000);
    raw.color.width = 1280;
    raw.color.height = 720;
    raw.color.rgb.assign(3 * 1280 * 720, 0);
    try {
        wul3d::register_depth_to_color(calib, raw, ws, out);
        ADD_FAILURE() << "no InputError";
    } catch (const wul3d::InputError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("1280x720"), std::string::npos) << msg;
        EXPECT_NE(msg.find("1920x1080"), std::string::npos) << msg;
    }
}

TEST(RegisterColorToDepth, DepthOnlyInputPassesThrough) {
    const StereoCalibration calib = wul3d::kinect_v2_default_calibration();
    RawRgbdFrame raw;
    raw.depth.width = 512;
    raw.depth.height = 424;
    raw.depth.data.assign(512 * 424, 1500);
    wul3d::RegistrationWorkspace ws;
    RgbdFrame out;
    wul3d::register_color_to_depth(calib, raw, ws, out);
    EXPECT_FALSE(out.has_color());
    EXPECT_EQ(out.depth.data, raw.depth.data);
}

TEST(StereoCalibration, Validate) {
    StereoCalibration c = wul3d::kinect_v2_default_calibration();
    EXPECT_NO_THROW(c.validate());
    c.rotation = rotation_deg(10, -20, 30);
    EXPECT_NO_THROW(c.validate());

    StereoCalibration scaled = c;
    for (double& r : scaled.rotation) r *= 1.01;
    EXPECT_THROW(scaled.validate(), wul3d::ParamError);

    StereoCalibration mirrored = wul3d::kinect_v2_default_calibration();
    mirrored.rotation = {-1, 0, 0, 0, 1, 0, 0, 0, 1};  // orthogonal but a reflection
    EXPECT_THROW(mirrored.validate(), wul3d::ParamError);

    StereoCalibration bad_k = wul3d::kinect_v2_default_calibration();
    bad_k.color.fx = 0;
    EXPECT_THROW(bad_k.validate(), wul3d::ParamError);

    StereoCalibration bad_t = wul3d::kinect_v2_default_calibration();
    bad_t.translation_m[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(bad_t.validate(), wul3d::ParamError);

    StereoCalibration bad_scale = wul3d::kinect_v2_default_calibration();
    bad_scale.depth_scale_m_per_unit = 0;
    EXPECT_THROW(bad_scale.validate(), wul3d::ParamError);
}

TEST(StereoCalibration, KinectV2PresetHasTheTypicalValues) {
    const StereoCalibration c = wul3d::kinect_v2_default_calibration();
    EXPECT_EQ(c.depth.width, 512);
    EXPECT_EQ(c.depth.height, 424);
    EXPECT_NEAR(c.depth.fx, 365.5, 1.0);
    EXPECT_EQ(c.color.width, 1920);
    EXPECT_EQ(c.color.height, 1080);
    EXPECT_NEAR(c.color.fx, 1081.37, 0.01);
    EXPECT_NEAR(c.translation_m[0], 0.052, 1e-9);
}

TEST(ParseRegistrationMode, KnownNamesAndError) {
    EXPECT_EQ(wul3d::parse_registration_mode("depth-to-color"),
              wul3d::RegistrationMode::DepthToColor);
    EXPECT_EQ(wul3d::parse_registration_mode("color-to-depth"),
              wul3d::RegistrationMode::ColorToDepth);
    EXPECT_THROW(wul3d::parse_registration_mode("depth2color"), wul3d::ParamError);
}

}  // namespace
