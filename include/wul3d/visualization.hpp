#pragma once
/// @file visualization.hpp
/// Step 8 of the paper: colour each point by its weights, C_p = sum_j C_j mu_pj (eq. 9).
#include <array>
#include <cstdint>

#include "wul3d/clustering.hpp"
#include "wul3d/frame.hpp"

namespace wul3d {

/// The fixed display colour C_j of cluster j (0-based): 12 hand-picked distinct colours,
/// then golden-ratio hues.
std::array<std::uint8_t, 3> cluster_color(int j);

/// Eq. (9) over the scene: pixels with a label take sum_j C_j mu_j of their grid point;
/// other pixels show the frame's own colour as dim grey (black for depth-only frames), so
/// the clusters stay readable in context. `out` gets the labels' resolution.
void render_weight_colors(const ClusterState& state, const LabelImage& labels,
                          const RgbdView& frame, ColorImage& out);
inline void render_weight_colors(const ClusterState& state, const LabelImage& labels,
                                 const RgbdFrame& frame, ColorImage& out) {
    render_weight_colors(state, labels, frame.view(), out);
}

/// The dim grey shown for a pixel without a label, from its R, G, B.
inline std::uint8_t dimmed_grey(const std::uint8_t* rgb) {
    const float grey = 0.299f * rgb[0] + 0.587f * rgb[1] + 0.114f * rgb[2];
    return static_cast<std::uint8_t>(grey * 0.35f);
}

}  // namespace wul3d
