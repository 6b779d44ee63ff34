#pragma once
/// @file visualization.hpp
/// Step 8 of the paper: colour each point by its weights, C_p = sum_j C_j mu_pj (eq. 9);
/// and the pictures of objects (objects.hpp): tinted, outlined and numbered over the colour
/// image (`wul3d run --overlay`, the viewer's and the video's objects panels).
#include <array>
#include <cstdint>
#include <vector>

#include "wul3d/camera.hpp"
#include "wul3d/frame.hpp"
#include "wul3d/image.hpp"

namespace wul3d {

class ClusterState;     // clustering.hpp
struct DetectedObject;  // objects.hpp

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

/// The display colour of the object with track id `track_id` (>= 1): fixed for the id, so an
/// object keeps its colour while it is tracked; golden-ratio hues, bright and saturated so
/// that a white outline and white text stay readable next to it.
std::array<std::uint8_t, 3> object_color(int track_id);

/// How render_object_overlay draws.
struct OverlayStyle {
    float tint = 0.55f;        ///< share of the object's colour in its pixels; [0, 1]
    bool outline = true;       ///< white outline on each object's border pixels
    bool ids = true;           ///< the track id, white on a dark tag, at the object's 2D box
    bool boxes = false;        ///< the oriented 3D box (DetectedObject::obb_*) projected
    int selected = 0;          ///< a track id drawn as selected: the other pixels darkened
                               ///< to a quarter; 0 none
};

/// The picture objects are drawn over: the frame's colour, or for a depth-only frame its
/// depth in grey over the depth's own range (near bright, no depth black).
void render_frame_picture(const RgbdFrame& frame, ColorImage& out);

/// Objects over a picture: each pixel of object i (objects.labels == track id) takes
/// (1 - tint) of `base` and tint of object_color(i); border pixels (a 4-neighbour with another
/// label) white; then the ids and boxes of `list`. `base` (the frame's colour, usually) and
/// `objects` must have the same size, and `intrinsics` their pixels (used for the boxes);
/// throws ParamError otherwise. Pixels of no object keep `base`.
void render_object_overlay(const ColorImage& base, const LabelImage& objects,
                           const std::vector<DetectedObject>& list,
                           const PinholeIntrinsics& intrinsics, ColorImage& out,
                           const OverlayStyle& style = {});

}  // namespace wul3d
