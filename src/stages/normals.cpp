#include "wul3d/normals.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "branch_free.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

void NormalParams::validate() const {
    if (radius_px < 1 || radius_px > 64) {
        std::ostringstream msg;
        msg << "normal radius = " << radius_px << " px: must be in [1, 64]";
        throw ParamError(msg.str());
    }
    if (!(max_depth_jump_rel > 0 && std::isfinite(max_depth_jump_rel))) {
        std::ostringstream msg;
        msg << "normal max_depth_jump_rel = " << max_depth_jump_rel << ": must be > 0";
        throw ParamError(msg.str());
    }
    if (!(max_tilt_noise_deg >= 0 && max_tilt_noise_deg < 90)) {
        std::ostringstream msg;
        msg << "normal max_tilt_noise_deg = " << max_tilt_noise_deg << ": must be in [0, 90)";
        throw ParamError(msg.str());
    }
}

float measure_depth_noise(const OrganizedCloud& cloud, float fx, std::vector<float>& scratch) {
    constexpr int kStep = 3;             // every third pixel of every third row
    constexpr int kSlope = 12;           // the surface's slope from the points this far either side
    constexpr float kMaxSlope2 = 33.0f;  // tan^2 of 80 degrees: steeper is an edge, not a surface
    constexpr double kKeep = 0.9;        // the largest tenth are edges
    // E|x| over the smallest 90% of |N(0, 1)|, times sqrt(6) (the second difference of three
    // independent samples has 6 times their variance): 0.6573 * 2.4495.
    constexpr double kGaussian = 1.6100;
    const int W = cloud.width, H = cloud.height;
    scratch.clear();
    if (!(fx > 0) || W <= 2 * kSlope || H <= 2 * kSlope) return 0.0f;
    const std::uint8_t* const ok = cloud.valid.data();
    const float* const z = cloud.z.data();
    const auto row = static_cast<std::size_t>(W);
    for (int v = kSlope; v + kSlope < H; v += kStep) {
        for (int u = kSlope; u + kSlope < W; u += kStep) {
            const std::size_t p = static_cast<std::size_t>(v) * row + static_cast<std::size_t>(u);
            const std::size_t du = kSlope, dv = kSlope * row;
            if (!(ok[p] & ok[p - 1] & ok[p + 1] & ok[p - row] & ok[p + row] & ok[p - du] & ok[p + du] &
                  ok[p - dv] & ok[p + dv]))
                continue;
            // The slope (depth per pixel footprint z / fx) in u and v, and the cos^2 of the
            // angle between the surface's normal and the view that it gives.
            const float footprint = z[p] / fx;
            const float gu = (z[p + du] - z[p - du]) / (2.0f * kSlope * footprint);
            const float gv = (z[p + dv] - z[p - dv]) / (2.0f * kSlope * footprint);
            const float slope2 = gu * gu + gv * gv;
            if (slope2 > kMaxSlope2) continue;
            const float cos2 = 1.0f / (1.0f + slope2);
            // |d2(1/z)| * z * fx: the noise of 1/z (which a plane keeps linear in u and v)
            // in pixel footprints (sigma_z = z^2 sigma(1/z)); times cos^2: along the
            // surface's normal (cos), over the distance between neighbours on it (1 / cos).
            const float scale = z[p] * fx * cos2;
            scratch.push_back(std::fabs(1.0f / z[p - 1] - 2.0f / z[p] + 1.0f / z[p + 1]) * scale);
            scratch.push_back(std::fabs(1.0f / z[p - row] - 2.0f / z[p] + 1.0f / z[p + row]) * scale);
        }
    }
    if (scratch.size() < 64) return 0.0f;
    const auto kept = static_cast<std::ptrdiff_t>(kKeep * static_cast<double>(scratch.size()));
    std::nth_element(scratch.begin(), scratch.begin() + kept, scratch.end());
    double sum = 0.0;
    for (auto it = scratch.begin(); it != scratch.begin() + kept; ++it) sum += *it;
    return static_cast<float>(sum / static_cast<double>(kept) / kGaussian);
}

int normal_radius_for(const NormalParams& params, float noise_px) {
    if (!(params.max_tilt_noise_deg > 0) || !(noise_px > 0)) return params.radius_px;
    const double tilt = std::tan(static_cast<double>(params.max_tilt_noise_deg) * std::numbers::pi / 180.0);
    const double r = std::round(static_cast<double>(noise_px) / (std::sqrt(2.0) * tilt));
    return static_cast<int>(std::clamp(r, static_cast<double>(params.radius_px), 64.0));
}

void NormalMap::resize(int w, int h) {
    width = w;
    height = h;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    nx.resize(n);
    ny.resize(n);
    nz.resize(n);
    valid.resize(n);
}

namespace {

struct Vec3 {
    float x, y, z;
};

// Tangent along one image axis: central difference when both neighbours lie on the
// pixel's surface, one-sided when only one does (so no tangent ever spans a depth step).
inline bool tangent(const OrganizedCloud& c, std::size_t p, std::size_t lo, std::size_t hi,
                    bool lo_in, bool hi_in, float max_jump, Vec3& t) {
    const float zp = c.z[p];
    const bool lo_ok = lo_in && c.valid[lo] && std::fabs(c.z[lo] - zp) <= max_jump;
    const bool hi_ok = hi_in && c.valid[hi] && std::fabs(c.z[hi] - zp) <= max_jump;
    std::size_t a, b;
    if (lo_ok && hi_ok) {
        a = lo;
        b = hi;
    } else if (hi_ok) {
        a = p;
        b = hi;
    } else if (lo_ok) {
        a = lo;
        b = p;
    } else {
        return false;
    }
    t = {c.x[b] - c.x[a], c.y[b] - c.y[a], c.z[b] - c.z[a]};
    return true;
}

using detail::pick;

/// The normal of each pixel of [p0, p1), pixels of one row whose neighbours `du` and `dv`
/// away (r columns, r rows) all lie in the frame: the arithmetic of tangent() and of
/// estimate_normals' pixel loop, with selects in place of branches so that the loop
/// vectorizes. Same operations on each pixel, hence the same bits. Built for AVX2 and for
/// baseline x86-64, picked at load time (as assign_block in clustering.cpp; AVX2 brings no
/// FMA, so the same bits). Cost: one pass.
WUL3D_AVX2_CLONES
void interior_normals(const float* __restrict x, const float* __restrict y, const float* __restrict z,
                      const std::uint8_t* __restrict valid, std::size_t p0, std::size_t p1, std::size_t du,
                      std::size_t dv, float jump_per_m, float* __restrict nx, float* __restrict ny,
                      float* __restrict nz, std::uint8_t* __restrict valid_out) {
    for (std::size_t p = p0; p < p1; ++p) {
        const float xp = x[p], yp = y[p], zp = z[p], max_jump = jump_per_m * zp;
        // `&`, not `&&`, and every load done whatever the selects pick (all lie in the
        // frame): a branch would stop vectorization.
        auto near = [&](std::size_t q) { return (valid[q] != 0) & (std::fabs(z[q] - zp) <= max_jump); };
        const bool left = near(p - du), right = near(p + du), up = near(p - dv), down = near(p + dv);
        // tangent(): from the near neighbour below (else the pixel) to the one above (else
        // the pixel), i.e. hi - lo, hi - p or p - lo.
        auto tangent_part = [](bool lo_ok, float lo, bool hi_ok, float hi, float at_p) {
            return pick(hi_ok, hi, at_p) - pick(lo_ok, lo, at_p);
        };
        const float ux = tangent_part(left, x[p - du], right, x[p + du], xp);
        const float uy = tangent_part(left, y[p - du], right, y[p + du], yp);
        const float uz = tangent_part(left, z[p - du], right, z[p + du], zp);
        const float vx = tangent_part(up, x[p - dv], down, x[p + dv], xp);
        const float vy = tangent_part(up, y[p - dv], down, y[p + dv], yp);
        const float vz = tangent_part(up, z[p - dv], down, z[p + dv], zp);
        const float cx = vy * uz - vz * uy, cy = vz * ux - vx * uz, cz = vx * uy - vy * ux;
        const float len = std::sqrt(cx * cx + cy * cy + cz * cz);
        const bool ok = (valid[p] != 0) & (left | right) & (up | down) & (len > 1e-12f);
        const float s = 1.0f / len;
        const float sc = pick(cx * xp + cy * yp + cz * zp > 0, -s, s);
        nx[p] = pick(ok, cx * sc, 0.0f);
        ny[p] = pick(ok, cy * sc, 0.0f);
        nz[p] = pick(ok, cz * sc, 0.0f);
        valid_out[p] = ok;
    }
}

/// The normal at pixel (u, v) of any row and column, bounds checked: tangents along both
/// axes (tangent()), their cross product, oriented towards the camera. The kernel of the
/// pixels near the frame's border (interior_normals does the others). Cost: O(1).
void edge_normal(const OrganizedCloud& cloud, int u, int v, int r, float jump_per_m, NormalMap& out) {
    const int W = cloud.width, H = cloud.height;
    const std::size_t p = static_cast<std::size_t>(v) * W + u;
    out.nx[p] = out.ny[p] = out.nz[p] = 0.0f;
    out.valid[p] = 0;
    if (!cloud.valid[p]) return;
    const float max_jump = jump_per_m * cloud.z[p];
    Vec3 du, dv;
    if (!tangent(cloud, p, p - r, p + r, u - r >= 0, u + r < W, max_jump, du)) return;
    if (!tangent(cloud, p, p - static_cast<std::size_t>(r) * W, p + static_cast<std::size_t>(r) * W, v - r >= 0,
                 v + r < H, max_jump, dv))
        return;
    // n = dv x du points towards the camera for a surface facing it (x right, y down).
    Vec3 n{dv.y * du.z - dv.z * du.y, dv.z * du.x - dv.x * du.z, dv.x * du.y - dv.y * du.x};
    const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (!(len > 1e-12f)) return;
    float s = 1.0f / len;
    // Orient towards the camera: the normal and the ray to the point are opposed.
    if (n.x * cloud.x[p] + n.y * cloud.y[p] + n.z * cloud.z[p] > 0) s = -s;
    out.nx[p] = n.x * s;
    out.ny[p] = n.y * s;
    out.nz[p] = n.z * s;
    out.valid[p] = 1;
}

/// o[u] = the sum of h[u - r .. u + r] (the part inside [0, W)), added left to right from
/// 0 (the sum's order fixes its bits). With SSE2, blocks of 16 columns keep their sums in
/// four registers while the window slides over them: one load and one add per 4 columns
/// and window pixel, where a pass per shifted row also loads and stores the sums (and
/// GCC, given the block as a loop, keeps the sums in memory). Cost: O(W r).
void row_window_sums(const float* h, int W, int r, float* o) {
    auto one = [&](int u) {
        float sum = 0.0f;
        for (int k = std::max(-r, -u); k <= std::min(r, W - 1 - u); ++k) sum += h[u + k];
        o[u] = sum;
    };
    int u = 0;
    for (; u < std::min(r, W); ++u) one(u);
#if defined(__SSE2__)
    for (; u + 16 <= W - r; u += 16) {
        __m128 s0 = _mm_setzero_ps(), s1 = s0, s2 = s0, s3 = s0;
        for (const float* q = h + u - r; q <= h + u + r; ++q) {
            s0 = _mm_add_ps(s0, _mm_loadu_ps(q));
            s1 = _mm_add_ps(s1, _mm_loadu_ps(q + 4));
            s2 = _mm_add_ps(s2, _mm_loadu_ps(q + 8));
            s3 = _mm_add_ps(s3, _mm_loadu_ps(q + 12));
        }
        _mm_storeu_ps(o + u, s0);
        _mm_storeu_ps(o + u + 4, s1);
        _mm_storeu_ps(o + u + 8, s2);
        _mm_storeu_ps(o + u + 12, s3);
    }
#endif
    for (; u < W; ++u) one(u);
}

/// (x, y, z)[u] scaled to unit length where `valid` and the length exceeds 1e-6 (valid_out
/// = 1), else to 0 (valid_out = 0). A multiply by the picked scale, never a branch: the
/// loop vectorizes; built for AVX2 and baseline x86-64 (no FMA either way: the same bits).
/// Cost: one pass over the row.
WUL3D_AVX2_CLONES
void renormalize_row(const std::uint8_t* __restrict valid, int W, float* __restrict x, float* __restrict y,
                     float* __restrict z, std::uint8_t* __restrict valid_out) {
    for (int u = 0; u < W; ++u) {
        const float len = std::sqrt(x[u] * x[u] + y[u] * y[u] + z[u] * z[u]);
        const bool ok = (valid[u] != 0) & (len > 1e-6f);
        const float sc = pick(ok, 1.0f / len, 0.0f);
        x[u] *= sc;
        y[u] *= sc;
        z[u] *= sc;
        valid_out[u] = ok;
    }
}

}  // namespace

void estimate_normals(const NormalParams& params, const OrganizedCloud& cloud, NormalMap& out) {
    const int W = cloud.width, H = cloud.height, r = params.radius_px;
    out.resize(W, H);
    const float jump_per_m = params.max_depth_jump_rel * static_cast<float>(r);

#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        // The pixels whose neighbours r columns and r rows away all lie in the frame take
        // the vectorized kernel, those nearer the border the bounds-checked one.
        const bool inner_row = v >= r && v + r < H && W > 2 * r;
        if (!inner_row) {
            for (int u = 0; u < W; ++u) edge_normal(cloud, u, v, r, jump_per_m, out);
            continue;
        }
        for (int u = 0; u < r; ++u) edge_normal(cloud, u, v, r, jump_per_m, out);
        const std::size_t row = static_cast<std::size_t>(v) * W;
        interior_normals(cloud.x.data(), cloud.y.data(), cloud.z.data(), cloud.valid.data(), row + r, row + W - r,
                         static_cast<std::size_t>(r), static_cast<std::size_t>(r) * W, jump_per_m, out.nx.data(),
                         out.ny.data(), out.nz.data(), out.valid.data());
        for (int u = W - r; u < W; ++u) edge_normal(cloud, u, v, r, jump_per_m, out);
    }
}

void smooth_normals(const NormalMap& in, int radius_px, std::vector<float>& scratch, NormalMap& out,
                    int row_begin, int row_end) {
    if (radius_px < 1 || radius_px > 64) {
        std::ostringstream msg;
        msg << "normal smoothing radius = " << radius_px << " px: must be in [1, 64]";
        throw ParamError(msg.str());
    }
    const int W = in.width, H = in.height, r = radius_px;
    const std::size_t N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
    out.resize(W, H);
    const int rb = std::clamp(row_begin, 0, H), re = row_end < 0 ? H : std::clamp(row_end, rb, H);
    // Rows outside the range: no normal (n = 0, NormalMap's contract).
    for (auto* a : {&out.nx, &out.ny, &out.nz}) {
        std::fill(a->begin(), a->begin() + static_cast<std::ptrdiff_t>(rb) * W, 0.0f);
        std::fill(a->begin() + static_cast<std::ptrdiff_t>(re) * W, a->end(), 0.0f);
    }
    std::fill(out.valid.begin(), out.valid.begin() + static_cast<std::ptrdiff_t>(rb) * W, 0);
    std::fill(out.valid.begin() + static_cast<std::ptrdiff_t>(re) * W, out.valid.end(), 0);
    // Vertical window sums of (nx, ny, nz) into scratch (3 planes), then horizontal ones.
    // A pixel without a normal holds n = 0 (NormalMap's contract), so it adds nothing and
    // the sums need no branch: whole rows add up contiguously, which vectorizes.
    scratch.resize(3 * N + static_cast<std::size_t>(W));
    std::fill(scratch.begin() + static_cast<std::ptrdiff_t>(3 * N), scratch.end(), 0.0f);
    float* const planes[3] = {scratch.data(), scratch.data() + N, scratch.data() + 2 * N};
    const float* const src[3] = {in.nx.data(), in.ny.data(), in.nz.data()};
    // Fixed bands of the rows, each starting with a full window: the same sums (hence the
    // same result) whatever the number of threads.
    constexpr int kBands = 4;
    const float* const zeros = scratch.data() + 3 * N;  // a row of zeros
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        const int v0 = rb + (re - rb) * band / kBands, v1 = rb + (re - rb) * (band + 1) / kBands;
        for (int c = 0; c < 3; ++c) {
            float* const dst = planes[c];
            for (int v = v0; v < v1; ++v) {
                float* const out_row = dst + static_cast<std::size_t>(v) * W;
                auto add_row = [&](int k, float sign) {
                    const float* const in_row = src[c] + static_cast<std::size_t>(k) * W;
                    for (int u = 0; u < W; ++u) out_row[u] += sign * in_row[u];
                };
                if (v == v0) {
                    std::fill(out_row, out_row + W, 0.0f);
                    for (int k = std::max(0, v - r); k <= std::min(H - 1, v + r); ++k) add_row(k, 1.0f);
                } else {
                    // The window slides one row: previous sum + entering row - leaving row
                    // (a row of zeros past either edge), in one pass.
                    const float* const prev = out_row - W;
                    const float* const enter = v + r < H ? src[c] + static_cast<std::size_t>(v + r) * W : zeros;
                    const float* const leave = v - r - 1 >= 0 ? src[c] + static_cast<std::size_t>(v - r - 1) * W : zeros;
                    for (int u = 0; u < W; ++u) out_row[u] = prev[u] + enter[u] - leave[u];
                }
            }
        }
    }
    // Horizontal window sums straight into the output, then renormalized.
#pragma omp parallel for schedule(static)
    for (int v = rb; v < re; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        float* const dst[3] = {out.nx.data() + row, out.ny.data() + row, out.nz.data() + row};
        for (int c = 0; c < 3; ++c) row_window_sums(planes[c] + row, W, r, dst[c]);
        renormalize_row(in.valid.data() + row, W, dst[0], dst[1], dst[2], out.valid.data() + row);
    }
}

}  // namespace wul3d
