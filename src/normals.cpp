#include "wul3d/normals.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

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

}  // namespace

void estimate_normals(const NormalParams& params, const OrganizedCloud& cloud, NormalMap& out) {
    const int W = cloud.width, H = cloud.height, r = params.radius_px;
    out.resize(W, H);
    const float jump_per_m = params.max_depth_jump_rel * static_cast<float>(r);

#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            out.nx[p] = out.ny[p] = out.nz[p] = 0.0f;
            out.valid[p] = 0;
            if (!cloud.valid[p]) continue;
            const float max_jump = jump_per_m * cloud.z[p];
            Vec3 du, dv;
            if (!tangent(cloud, p, p - r, p + r, u - r >= 0, u + r < W, max_jump, du)) continue;
            if (!tangent(cloud, p, p - static_cast<std::size_t>(r) * W,
                         p + static_cast<std::size_t>(r) * W, v - r >= 0, v + r < H, max_jump,
                         dv))
                continue;
            // n = dv x du points towards the camera for a surface facing it (x right, y down).
            Vec3 n{dv.y * du.z - dv.z * du.y, dv.z * du.x - dv.x * du.z,
                   dv.x * du.y - dv.y * du.x};
            const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
            if (!(len > 1e-12f)) continue;
            float s = 1.0f / len;
            // Orient towards the camera: the normal and the ray to the point are opposed.
            if (n.x * cloud.x[p] + n.y * cloud.y[p] + n.z * cloud.z[p] > 0) s = -s;
            out.nx[p] = n.x * s;
            out.ny[p] = n.y * s;
            out.nz[p] = n.z * s;
            out.valid[p] = 1;
        }
    }
}

void smooth_normals(const NormalMap& in, int radius_px, std::vector<float>& scratch, NormalMap& out) {
    if (radius_px < 1 || radius_px > 64) {
        std::ostringstream msg;
        msg << "normal smoothing radius = " << radius_px << " px: must be in [1, 64]";
        throw ParamError(msg.str());
    }
    const int W = in.width, H = in.height, r = radius_px;
    const std::size_t N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
    out.resize(W, H);
    // Horizontal running sums of (nx, ny, nz) into scratch (3 planes), then vertical ones.
    scratch.resize(3 * N);
    float* hx = scratch.data();
    float* hy = hx + N;
    float* hz = hy + N;
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        float sx = 0, sy = 0, sz = 0;
        auto add = [&](int u, float sign) {
            const std::size_t p = row + u;
            if (!in.valid[p]) return;
            sx += sign * in.nx[p];
            sy += sign * in.ny[p];
            sz += sign * in.nz[p];
        };
        for (int u = 0; u < std::min(r, W); ++u) add(u, 1.0f);
        for (int u = 0; u < W; ++u) {
            if (u + r < W) add(u + r, 1.0f);
            if (u - r - 1 >= 0) add(u - r - 1, -1.0f);
            hx[row + u] = sx;
            hy[row + u] = sy;
            hz[row + u] = sz;
        }
    }
    // Vertical pass by column blocks, so that each thread walks rows contiguously.
    constexpr int kBlock = 64;
    const int blocks = (W + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static)
    for (int b = 0; b < blocks; ++b) {
        const int u0 = b * kBlock, u1 = std::min(W, u0 + kBlock);
        float sx[kBlock] = {}, sy[kBlock] = {}, sz[kBlock] = {};
        auto add = [&](int v, float sign) {
            const std::size_t row = static_cast<std::size_t>(v) * W;
            for (int u = u0; u < u1; ++u) {
                sx[u - u0] += sign * hx[row + u];
                sy[u - u0] += sign * hy[row + u];
                sz[u - u0] += sign * hz[row + u];
            }
        };
        for (int v = 0; v < std::min(r, H); ++v) add(v, 1.0f);
        for (int v = 0; v < H; ++v) {
            if (v + r < H) add(v + r, 1.0f);
            if (v - r - 1 >= 0) add(v - r - 1, -1.0f);
            const std::size_t row = static_cast<std::size_t>(v) * W;
            for (int u = u0; u < u1; ++u) {
                const std::size_t p = row + u;
                const float x = sx[u - u0], y = sy[u - u0], z = sz[u - u0];
                const float len = std::sqrt(x * x + y * y + z * z);
                const bool ok = in.valid[p] && len > 1e-6f;
                const float s = ok ? 1.0f / len : 0.0f;
                out.nx[p] = x * s;
                out.ny[p] = y * s;
                out.nz[p] = z * s;
                out.valid[p] = ok;
            }
        }
    }
}

}  // namespace wul3d
