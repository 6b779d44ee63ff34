#include "wul3d/backprojection.hpp"

#include <string>

#include "wul3d/error.hpp"

namespace wul3d {

void OrganizedCloud::resize(int w, int h) {
    width = w;
    height = h;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    for (auto* a : {&x, &y, &z}) a->resize(n);
    for (auto* a : {&r, &g, &b}) a->resize(n);
    valid.resize(n);
}

std::size_t back_project(const RgbdView& frame, OrganizedCloud& cloud) {
    const int W = frame.width, H = frame.height;
    if (frame.has_color() && !frame.color_matches())
        throw InputError(std::string(frame.name) + ": colour is " + std::to_string(frame.color_width) + "x" +
                         std::to_string(frame.color_height) + " but depth is " +
                         std::to_string(W) + "x" + std::to_string(H));
    cloud.resize(W, H);
    cloud.has_color = frame.has_color();

    const auto& K = frame.intrinsics;
    const float scale = frame.depth_scale_m_per_unit;
    const float inv_fx = static_cast<float>(1.0 / K.fx), inv_fy = static_cast<float>(1.0 / K.fy);
    const float cx = static_cast<float>(K.cx), cy = static_cast<float>(K.cy);
    const std::uint16_t* depth = frame.depth;
    const std::uint8_t* rgb = frame.rgb;

    // Raw pointers: a byte store (valid, colour) may alias anything, so through the vectors
    // the compiler would reload every data pointer per pixel and not vectorize.
    float* const xs = cloud.x.data();
    float* const ys = cloud.y.data();
    float* const zs = cloud.z.data();
    std::uint8_t* const valid = cloud.valid.data();
    std::uint8_t* const rs = cloud.r.data();
    std::uint8_t* const gs = cloud.g.data();
    std::uint8_t* const bs = cloud.b.data();
    std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (int v = 0; v < H; ++v) {
        const float yv = (static_cast<float>(v) - cy) * inv_fy;
        const std::size_t row = static_cast<std::size_t>(v) * W;
        int row_count = 0;
        for (int u = 0; u < W; ++u) {
            const std::size_t p = row + u;
            const float z = static_cast<float>(depth[p]) * scale;  // 0 where there is no depth
            const std::uint8_t ok = depth[p] != 0;
            valid[p] = ok;
            row_count += ok;
            zs[p] = z;
            // + 0: a point without depth gets x = y = +0, never -0 (no branch: vectorizes).
            xs[p] = (static_cast<float>(u) - cx) * inv_fx * z + 0.0f;
            ys[p] = yv * z + 0.0f;
        }
        count += static_cast<std::size_t>(row_count);
        if (rgb) {
            for (int u = 0; u < W; ++u) {
                const std::size_t p = row + u;
                rs[p] = rgb[3 * p];
                gs[p] = rgb[3 * p + 1];
                bs[p] = rgb[3 * p + 2];
            }
        } else {
            std::fill(rs + row, rs + row + W, 0);
            std::fill(gs + row, gs + row + W, 0);
            std::fill(bs + row, bs + row + W, 0);
        }
    }
    return count;
}

}  // namespace wul3d
