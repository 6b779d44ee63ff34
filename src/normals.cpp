#include "wul3d/normals.hpp"

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

}  // namespace wul3d
