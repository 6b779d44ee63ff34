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

std::size_t back_project(const RgbdFrame& frame, OrganizedCloud& cloud) {
    const int W = frame.width(), H = frame.height();
    if (frame.has_color() && (frame.color.width != W || frame.color.height != H))
        throw InputError(frame.name + ": colour is " + std::to_string(frame.color.width) + "x" +
                         std::to_string(frame.color.height) + " but depth is " +
                         std::to_string(W) + "x" + std::to_string(H));
    cloud.resize(W, H);
    cloud.has_color = frame.has_color();

    const auto& K = frame.intrinsics;
    const float scale = frame.depth.scale_m_per_unit;
    const float inv_fx = static_cast<float>(1.0 / K.fx), inv_fy = static_cast<float>(1.0 / K.fy);
    const float cx = static_cast<float>(K.cx), cy = static_cast<float>(K.cy);
    const std::uint16_t* depth = frame.depth.data.data();
    const std::uint8_t* rgb = frame.has_color() ? frame.color.rgb.data() : nullptr;

    std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (int v = 0; v < H; ++v) {
        const float yv = (static_cast<float>(v) - cy) * inv_fy;
        const std::size_t row = static_cast<std::size_t>(v) * W;
        for (int u = 0; u < W; ++u) {
            const std::size_t p = row + u;
            const float z = static_cast<float>(depth[p]) * scale;
            const bool ok = depth[p] != 0;
            cloud.valid[p] = ok ? 1 : 0;
            count += ok;
            cloud.z[p] = ok ? z : 0.0f;
            cloud.x[p] = ok ? (static_cast<float>(u) - cx) * inv_fx * z : 0.0f;
            cloud.y[p] = ok ? yv * z : 0.0f;
            if (rgb) {
                cloud.r[p] = rgb[3 * p];
                cloud.g[p] = rgb[3 * p + 1];
                cloud.b[p] = rgb[3 * p + 2];
            } else {
                cloud.r[p] = cloud.g[p] = cloud.b[p] = 0;
            }
        }
    }
    return count;
}

}  // namespace wul3d
