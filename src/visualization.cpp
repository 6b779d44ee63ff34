#include "wul3d/visualization.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace wul3d {

std::array<std::uint8_t, 3> cluster_color(int j) {
    // Distinct, saturated colours first (readable next to each other), then hues spaced
    // by the golden ratio.
    static constexpr std::uint8_t kFixed[12][3] = {
        {230, 25, 75},  {60, 180, 75},  {255, 225, 25}, {0, 130, 200},
        {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230},
        {210, 245, 60}, {250, 190, 212}, {0, 128, 128}, {170, 110, 40}};
    if (j >= 0 && j < 12) return {kFixed[j][0], kFixed[j][1], kFixed[j][2]};
    const double h = std::fmod(0.1 + 0.618033988749895 * j, 1.0) * 6.0;
    const double s = 0.75, v = 0.95;
    const int sector = static_cast<int>(h);
    const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double r = v, g = t, b = p;
    switch (sector) {
        case 1: r = q; g = v; b = p; break;
        case 2: r = p; g = v; b = t; break;
        case 3: r = p; g = q; b = v; break;
        case 4: r = t; g = p; b = v; break;
        case 5: r = v; g = p; b = q; break;
        default: break;
    }
    auto byte = [](double x) { return static_cast<std::uint8_t>(std::lround(x * 255.0)); };
    return {byte(r), byte(g), byte(b)};
}

void render_weight_colors(const ClusterState& state, const LabelImage& labels,
                          const RgbdView& frame, ColorImage& out) {
    const int W = labels.width, H = labels.height, k = state.params().k;
    out.width = W;
    out.height = H;
    out.rgb.resize(static_cast<std::size_t>(W) * H * 3);
    std::vector<float> C(static_cast<std::size_t>(k) * 3);
    for (int j = 0; j < k; ++j) {
        const auto c = cluster_color(j);
        for (int q = 0; q < 3; ++q) C[3 * j + q] = c[q] / PixelWeights::kOne;
    }
    const bool grey_ok = frame.has_color() && frame.color_width == W && frame.color_height == H;
    const std::uint8_t* rgb = grey_ok ? frame.rgb : nullptr;

#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        const int grid_row = state.grid_index(0, v);
        const int stride = state.params().stride;
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            std::uint8_t* o = out.rgb.data() + 3 * p;
            if (labels.labels[p] != 0) {
                // Paper eq. (9): C_p = sum_j C_j mu_j, over the kept weights (the others
                // are 0 or negligible, see PixelWeights).
                const PixelWeights& w = state.weights(grid_row + (stride == 1 ? u : u / stride));
                float acc[3] = {0, 0, 0};
                for (int s = 0; s < PixelWeights::kSlots; ++s) {
                    if (w.mu[s] == 0) continue;  // most slots of a still scene are empty
                    const float m = static_cast<float>(w.mu[s]);
                    const float* c = &C[3 * w.cluster[s]];
                    acc[0] += c[0] * m;
                    acc[1] += c[1] * m;
                    acc[2] += c[2] * m;
                }
                for (int q = 0; q < 3; ++q)
                    o[q] = static_cast<std::uint8_t>(std::min(255.0f, acc[q] + 0.5f));
            } else if (rgb) {
                o[0] = o[1] = o[2] = dimmed_grey(rgb + 3 * p);
            } else {
                o[0] = o[1] = o[2] = 0;
            }
        }
    }
}

}  // namespace wul3d
