#include "wul3d/normals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "wul3d/camera.hpp"
#include "wul3d/error.hpp"

using namespace wul3d;

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
const PinholeIntrinsics kK{320, 240, 280.0, 280.0, 159.5, 119.5};

// An exact organized cloud: hit(dx, dy) returns the ray parameter t (= depth) or +inf.
OrganizedCloud cast(const std::function<float(float, float)>& hit) {
    OrganizedCloud c;
    c.resize(kK.width, kK.height);
    for (int v = 0; v < kK.height; ++v)
        for (int u = 0; u < kK.width; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * kK.width + u;
            const float dx = static_cast<float>((u - kK.cx) / kK.fx);
            const float dy = static_cast<float>((v - kK.cy) / kK.fy);
            const float t = hit(dx, dy);
            c.valid[p] = std::isfinite(t) ? 1 : 0;
            if (!c.valid[p]) continue;
            c.x[p] = dx * t;
            c.y[p] = dy * t;
            c.z[p] = t;
        }
    return c;
}

double angle_deg(float ax, float ay, float az, double bx, double by, double bz) {
    const double dot = ax * bx + ay * by + az * bz;
    const double nb = std::sqrt(bx * bx + by * by + bz * bz);
    return std::acos(std::clamp(dot / nb, -1.0, 1.0)) * 180.0 / M_PI;
}
}  // namespace

TEST(Normals, TiltedPlaneWithin2Degrees) {
    // Plane n . P = d with n facing the camera (tilted 30 deg about x and 20 about y).
    const double nx = -0.30, ny = -0.45, nz = -0.84;
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    const double d = nz / len * 1.5;  // passes through (0, 0, 1.5)
    const OrganizedCloud c = cast([&](float dx, float dy) {
        const double denom = (nx * dx + ny * dy + nz) / len;
        const double t = d / denom;
        return t > 0 ? static_cast<float>(t) : kInf;
    });
    NormalMap n;
    estimate_normals(NormalParams{}, c, n);
    std::size_t checked = 0;
    for (std::size_t p = 0; p < c.size(); ++p) {
        if (!c.valid[p]) continue;
        ASSERT_TRUE(n.valid[p]) << p;
        EXPECT_LT(angle_deg(n.nx[p], n.ny[p], n.nz[p], nx, ny, nz), 2.0) << p;
        ++checked;
    }
    EXPECT_GT(checked, c.size() / 2);
}

TEST(Normals, SphereWithin2Degrees) {
    const double cz = 1.0, r = 0.3;
    const OrganizedCloud c = cast([&](float dx, float dy) {
        // |t (dx, dy, 1) - (0, 0, cz)|^2 = r^2, nearest root
        const double a = dx * dx + dy * dy + 1.0, b = -2.0 * cz, cc = cz * cz - r * r;
        const double disc = b * b - 4 * a * cc;
        if (disc < 0) return kInf;
        return static_cast<float>((-b - std::sqrt(disc)) / (2 * a));
    });
    NormalMap n;
    estimate_normals(NormalParams{}, c, n);
    std::size_t checked = 0, interior = 0;
    for (std::size_t p = 0; p < c.size(); ++p) {
        if (!c.valid[p]) continue;
        const double ex = c.x[p] / r, ey = c.y[p] / r, ez = (c.z[p] - cz) / r;
        const double ray = std::sqrt(c.x[p] * c.x[p] + c.y[p] * c.y[p] + c.z[p] * c.z[p]);
        const double facing = -(ex * c.x[p] + ey * c.y[p] + ez * c.z[p]) / ray;
        if (facing < 0.5) continue;  // within 60 degrees of grazing: the rim, left out
        ++interior;
        if (!n.valid[p]) continue;
        EXPECT_LT(angle_deg(n.nx[p], n.ny[p], n.nz[p], ex, ey, ez), 2.0) << p;
        ++checked;
    }
    EXPECT_GT(interior, 5000u);
    EXPECT_EQ(checked, interior);
}

TEST(Normals, NoneAcrossADepthStep) {
    // Left half at 1.0 m, right half at 1.5 m: every normal must face straight back.
    const OrganizedCloud c = cast([](float dx, float) { return dx < 0 ? 1.0f : 1.5f; });
    NormalMap n;
    estimate_normals(NormalParams{}, c, n);
    std::size_t valid = 0;
    for (std::size_t p = 0; p < c.size(); ++p) {
        if (!n.valid[p]) continue;
        ++valid;
        EXPECT_LT(angle_deg(n.nx[p], n.ny[p], n.nz[p], 0, 0, -1), 0.1) << p;  // float rounding
    }
    EXPECT_EQ(valid, c.size());  // one-sided differences keep the pixels at the step
}

TEST(Normals, InvalidPixelsGetNoNormal) {
    OrganizedCloud c = cast([](float, float) { return 2.0f; });
    // An isolated valid pixel surrounded by holes has no neighbour: no normal.
    for (int v = 100; v < 110; ++v)
        for (int u = 100; u < 110; ++u) c.valid[static_cast<std::size_t>(v) * kK.width + u] = 0;
    const std::size_t lone = static_cast<std::size_t>(105) * kK.width + 105;
    c.valid[lone] = 1;
    NormalMap n;
    estimate_normals(NormalParams{}, c, n);
    EXPECT_EQ(n.valid[lone], 0);
    EXPECT_EQ(n.valid[static_cast<std::size_t>(101) * kK.width + 101], 0);
    EXPECT_EQ(n.valid[static_cast<std::size_t>(50) * kK.width + 50], 1);
}

TEST(NormalParams, Validate) {
    NormalParams p;
    EXPECT_NO_THROW(p.validate());
    p.radius_px = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p.radius_px = 2;
    p.max_depth_jump_rel = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p.max_depth_jump_rel = 0.02f;
    p.max_tilt_noise_deg = 90;
    EXPECT_THROW(p.validate(), ParamError);
    p.max_tilt_noise_deg = -1;
    EXPECT_THROW(p.validate(), ParamError);
    p.max_tilt_noise_deg = 0;  // off
    EXPECT_NO_THROW(p.validate());
}

namespace {

constexpr double kTilted[3] = {-0.30, -0.45, -0.84};  // TiltedPlaneWithin2Degrees' plane
constexpr double kFacing[3] = {0.0, 0.0, -1.0};       // a plane facing the camera

// A plane of normal n through (0, 0, 1.5) with two boxes 10 cm before it (their edges are no
// noise), its depth off by Gaussian noise of `noise_px` pixel footprints (z / fx).
OrganizedCloud noisy_plane(const double (&n)[3], double noise_px, std::uint32_t seed) {
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double d = n[2] / len * 1.5;
    OrganizedCloud c = cast([&](float dx, float dy) {
        const double t = d / ((n[0] * dx + n[1] * dy + n[2]) / len);
        const bool box = (std::fabs(dx - 0.1f) < 0.05f || std::fabs(dx + 0.2f) < 0.04f) && std::fabs(dy) < 0.1f;
        return t > 0 ? static_cast<float>(t - (box ? 0.1 : 0.0)) : kInf;
    });
    std::mt19937 rng(seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (std::size_t p = 0; p < c.size(); ++p) {
        if (!c.valid[p]) continue;
        const double z = c.z[p], z_noisy = z + gauss(rng) * noise_px * z / kK.fx;
        const double k = z_noisy / z;
        c.x[p] = static_cast<float>(c.x[p] * k);
        c.y[p] = static_cast<float>(c.y[p] * k);
        c.z[p] = static_cast<float>(z_noisy);
    }
    return c;
}

// cos^2 of the angle between the plane's normal and the view axis.
double cos2(const double (&n)[3]) { return n[2] * n[2] / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); }

double median_tilt_deg(const OrganizedCloud& c, int radius_px, const double (&n)[3]) {
    NormalParams p;
    p.radius_px = radius_px;
    p.max_tilt_noise_deg = 0;
    NormalMap normals;
    estimate_normals(p, c, normals);
    std::vector<double> tilt;
    for (std::size_t q = 0; q < c.size(); ++q)
        if (normals.valid[q]) tilt.push_back(angle_deg(normals.nx[q], normals.ny[q], normals.nz[q], n[0], n[1], n[2]));
    if (tilt.empty()) return 180.0;
    std::nth_element(tilt.begin(), tilt.begin() + static_cast<std::ptrdiff_t>(tilt.size() / 2), tilt.end());
    return tilt[tilt.size() / 2];
}

}  // namespace

// measure_depth_noise gives back the noise put on a plane with box edges on it, whatever its
// level, seen along the plane's normal over the neighbours' distance on it: noise x cos^2 of
// the plane's tilt from the view (1 facing the camera, 0.71 for the tilted plane). An exact
// plane measures nothing: its slope and the boxes' edges are not noise.
TEST(DepthNoise, MeasuresTheGaussianNoiseOnPlanesWithEdges) {
    std::vector<float> scratch;
    const auto fx = static_cast<float>(kK.fx);
    EXPECT_LT(measure_depth_noise(noisy_plane(kTilted, 0.0, 1), fx, scratch), 0.02f);
    for (const double noise : {0.3, 1.0, 2.5}) {
        EXPECT_NEAR(measure_depth_noise(noisy_plane(kFacing, noise, 7), fx, scratch), noise, 0.12 * noise)
            << "facing, noise " << noise << " px";
        const double expect = noise * cos2(kTilted);
        EXPECT_NEAR(measure_depth_noise(noisy_plane(kTilted, noise, 7), fx, scratch), expect, 0.12 * expect)
            << "tilted, noise " << noise << " px";
    }
    // Too few samples to say: 0.
    OrganizedCloud empty;
    empty.resize(kK.width, kK.height);
    EXPECT_EQ(measure_depth_noise(empty, fx, scratch), 0.0f);
    EXPECT_EQ(measure_depth_noise(noisy_plane(kFacing, 1.0, 7), 0.0f, scratch), 0.0f);
}

// The radius: radius_px for a quiet camera, wider with the noise so that the tilt it causes
// (noise / (sqrt(2) r) radians) stays under max_tilt_noise_deg, capped at 64; fixed when off.
// On a noisy plane the radius chosen keeps the normals' tilt near that bound.
TEST(DepthNoise, NormalRadiusGrowsWithTheNoiseFromTheLeastRadius) {
    NormalParams p;  // radius 2, 7 degrees
    EXPECT_EQ(normal_radius_for(p, 0.0f), 2);
    EXPECT_EQ(normal_radius_for(p, 0.2f), 2);  // a Kinect v1 measures 0.1-0.2
    EXPECT_EQ(normal_radius_for(p, 1.0f), 6);  // 1.0 / (sqrt(2) tan 7 deg) = 5.76
    EXPECT_EQ(normal_radius_for(p, 1000.0f), 64);
    p.radius_px = 8;
    EXPECT_EQ(normal_radius_for(p, 1.0f), 8);
    p.radius_px = 2;
    p.max_tilt_noise_deg = 0;
    EXPECT_EQ(normal_radius_for(p, 1.0f), 2);

    p.max_tilt_noise_deg = 7;
    std::vector<float> scratch;
    for (const auto* n : {&kFacing, &kTilted}) {
        const OrganizedCloud c = noisy_plane(*n, 1.5, 3);
        const int r = normal_radius_for(p, measure_depth_noise(c, static_cast<float>(kK.fx), scratch));
        EXPECT_GT(r, 4);
        // The median of a tilt whose two components have 7 degrees' spread: 8.2 degrees.
        EXPECT_LT(median_tilt_deg(c, r, *n), 10.0) << "radius " << r;
        EXPECT_GT(median_tilt_deg(c, 2, *n), 20.0) << "radius 2 (test premise)";
    }
}

// Smoothing: on a noisy plane the averaged normals lie closer to the true one than the raw
// ones; a pixel without a normal stays without one; the radius is checked.
TEST(SmoothNormals, NoisyPlane_CloserToTheTruth_InvalidStaysInvalid) {
    NormalMap raw;
    raw.resize(64, 48);
    std::uint32_t state = 12345;
    auto noise = [&] {
        state = state * 1664525u + 1013904223u;
        return (static_cast<float>(state >> 8) / 16777216.0f - 0.5f) * 0.6f;
    };
    for (std::size_t p = 0; p < raw.valid.size(); ++p) {
        const float x = noise(), y = noise(), z = -1.0f;
        const float len = std::sqrt(x * x + y * y + z * z);
        raw.nx[p] = x / len;
        raw.ny[p] = y / len;
        raw.nz[p] = z / len;
        raw.valid[p] = p % 97 != 0;
    }
    NormalMap smooth;
    std::vector<float> scratch;
    smooth_normals(raw, 3, scratch, smooth);
    double raw_err = 0, smooth_err = 0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < raw.valid.size(); ++p) {
        EXPECT_EQ(smooth.valid[p], raw.valid[p]);
        if (!raw.valid[p]) continue;
        EXPECT_NEAR(smooth.nx[p] * smooth.nx[p] + smooth.ny[p] * smooth.ny[p] + smooth.nz[p] * smooth.nz[p], 1.0f, 1e-4f);
        raw_err += std::acos(std::min(1.0f, -raw.nz[p]));
        smooth_err += std::acos(std::min(1.0f, -smooth.nz[p]));
        ++n;
    }
    EXPECT_LT(smooth_err, 0.35 * raw_err);
    EXPECT_THROW(smooth_normals(raw, 0, scratch, smooth), ParamError);

    // A row range: those rows as over the whole image (up to the running sums' rounding),
    // the others without a normal, even where the whole-image pass had one.
    NormalMap part = smooth;  // stale values outside the range must be cleared
    smooth_normals(raw, 3, scratch, part, 10, 30);
    for (int v = 0; v < raw.height; ++v)
        for (int u = 0; u < raw.width; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * raw.width + u;
            if (v < 10 || v >= 30) {
                EXPECT_EQ(part.valid[p], 0) << v;
                EXPECT_EQ(part.nx[p], 0.0f);
                EXPECT_EQ(part.nz[p], 0.0f);
                continue;
            }
            EXPECT_EQ(part.valid[p], smooth.valid[p]);
            EXPECT_NEAR(part.nx[p], smooth.nx[p], 1e-5f);
            EXPECT_NEAR(part.ny[p], smooth.ny[p], 1e-5f);
            EXPECT_NEAR(part.nz[p], smooth.nz[p], 1e-5f);
        }
}
