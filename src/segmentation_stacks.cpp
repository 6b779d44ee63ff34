// The stack rule of segment_objects (SegmentParams, "Stacks"): a segment whose upward faces
// lie at two heights over the support, with nothing facing up between them, is two objects,
// one resting on the other. Where they meet without a crease (a box too thin for its sides
// to show a fold under the sensor's noise) and the colour cue cannot part them (one colour,
// or a print that 2-means follows), the heights still tell them apart.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "segmentation_internal.hpp"

namespace wul3d::detail {
namespace {

/// Heights of upward faces are counted in bins of this size, and a layer is three bins
/// (1.5 cm): a horizontal face seen at 1-1.5 m by a structured-light sensor spreads its
/// heights over a few millimetres (disparity steps of 3-6 mm, seen at an angle).
constexpr float kLayerBinM = 0.005f;
/// Between two layers, at every height fewer than this share of the smaller layer's count
/// face up: a stack leaves no upward face between its tops, a tilted or curved face spreads
/// its heights evenly (generated tune seeds: 1/2 to 1/8 scored the same).
constexpr int kValleyDivisor = 4;
/// The cut lies this far over the lower layer's middle: past the layer's own spread (half
/// its 1.5 cm window), under the bottom of the upper object, which rests on that layer
/// (generated tune seeds: 0.75 and 1 cm scored the same, 1.5 cm and half way between the
/// layers lower; docs/ABLATION.md).
constexpr float kCutOverLowerM = 0.01f;

/// Per segment, how many of its pixels face up (within kUprightDeg of the support's normal)
/// at each height over the support (bins of kLayerBinM from 0 up to the scope's height
/// limit, above which nothing stands on the support) into ws.layer_hist, segment after
/// segment, and its size into ws.sizes. In: ws.label (0..n). Cost: one pass over the rows
/// with objects.
void count_layers(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n, int bins) {
    ws.layer_hist.assign(static_cast<std::size_t>(n + 1) * static_cast<std::size_t>(bins), 0);
    ws.sizes.assign(static_cast<std::size_t>(n) + 1, 0);
    const float cos_up = std::cos(kUprightDeg * kDegToRad);
    for (int v = 0; v < x.H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * static_cast<std::size_t>(x.W);
        if (!row_has_label(ws.label.data() + row, 0, x.W)) continue;
        for (std::size_t p = row; p < row + static_cast<std::size_t>(x.W); ++p) {
            const int l = ws.label[p];
            if (l <= 0) continue;
            ++ws.sizes[static_cast<std::size_t>(l)];
            if (!faces_up(x, pl, p, cos_up)) continue;
            const int b = static_cast<int>(std::floor(pl.height(x.c.x[p], x.c.y[p], x.c.z[p]) / kLayerBinM));
            if (b >= 0 && b < bins)
                ++ws.layer_hist[static_cast<std::size_t>(l) * static_cast<std::size_t>(bins) + static_cast<std::size_t>(b)];
        }
    }
}

/// The height that cuts one segment between two layers of its upward faces (hist: its
/// bins, size: its pixels), or a negative value when it has no two. A layer is a local peak
/// of the counts over three bins that holds stack_min_share of the segment and min_points;
/// the lower stands stack_min_step_m or more above the support (a box's top, not the table
/// or a bowl's floor); the two lie stack_min_step_m or more apart, with a valley between
/// them (kValleyDivisor). Of several pairs, the one whose smaller layer is largest; the cut
/// lies kCutOverLowerM over its lower layer. Cost: O(bins^2), a hundred bins.
float cut_height(const int* hist, int bins, int size, const SegmentParams& prm) {
    auto window = [&](int b) { return (b > 0 ? hist[b - 1] : 0) + hist[b] + (b + 1 < bins ? hist[b + 1] : 0); };
    auto peak = [&](int b) {
        const int c = window(b);
        return c >= window(b - 1) && (b + 1 >= bins || c >= window(b + 1));
    };
    const int min_layer = std::max(prm.min_points, static_cast<int>(prm.stack_min_share * static_cast<float>(size)));
    const int step = static_cast<int>(std::ceil(prm.stack_min_step_m / kLayerBinM));
    auto middle = [](int b) { return (static_cast<float>(b) + 0.5f) * kLayerBinM; };
    float cut = -1.0f;
    int best_count = 0;
    for (int lo = std::max(step, 1); lo < bins; ++lo) {
        const int a = window(lo);
        if (a < min_layer || !peak(lo)) continue;
        int valley = a;  // the fewest upward pixels at any height between lo and hi
        for (int hi = lo + 1; hi < bins; ++hi) {
            const int c = window(hi), smaller = std::min(a, c);
            if (hi - lo >= step && c >= min_layer && peak(hi) && kValleyDivisor * valley < smaller &&
                smaller > best_count) {
                best_count = smaller;
                cut = middle(lo) + kCutOverLowerM;
            }
            valley = std::min(valley, c);
        }
    }
    return cut;
}

/// The cut of every segment of 2 x min_points or more into ws.stack_cut (< 0: none).
/// Returns how many have one. Cost: O(n bins^2).
int find_cuts(const Ctx& x, SegmentWorkspace& ws, int n, int bins) {
    ws.stack_cut.assign(static_cast<std::size_t>(n) + 1, -1.0f);
    int found = 0;
    for (int l = 1; l <= n; ++l) {
        const int size = ws.sizes[static_cast<std::size_t>(l)];
        if (size < 2 * x.prm.min_points) continue;
        const int* hist = ws.layer_hist.data() + static_cast<std::size_t>(l) * static_cast<std::size_t>(bins);
        ws.stack_cut[static_cast<std::size_t>(l)] = cut_height(hist, bins, size, x.prm);
        found += ws.stack_cut[static_cast<std::size_t>(l)] >= 0;
    }
    return found;
}

/// Cuts each layered segment: its pixels above the cut take a new label n + 1, n + 2, ... in
/// segment order. Returns the cuts. Cost: one pass over the rows with objects.
int cut_layers(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    ws.remap.assign(static_cast<std::size_t>(n) + 1, 0);
    int next = n;
    for (int l = 1; l <= n; ++l)
        if (ws.stack_cut[static_cast<std::size_t>(l)] >= 0) ws.remap[static_cast<std::size_t>(l)] = ++next;
    for (int v = 0; v < x.H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * static_cast<std::size_t>(x.W);
        if (!row_has_label(ws.label.data() + row, 0, x.W)) continue;
        for (std::size_t p = row; p < row + static_cast<std::size_t>(x.W); ++p) {
            const int l = ws.label[p];
            if (l <= 0 || ws.remap[static_cast<std::size_t>(l)] == 0) continue;
            if (pl.height(x.c.x[p], x.c.y[p], x.c.z[p]) > ws.stack_cut[static_cast<std::size_t>(l)])
                ws.label[p] = ws.remap[static_cast<std::size_t>(l)];
        }
    }
    return next - n;
}

}  // namespace

int split_stacks(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    if (x.prm.stack_min_step_m <= 0) return 0;
    const int bins = static_cast<int>(std::ceil(x.prm.scope_max_height_m / kLayerBinM));
    count_layers(x, pl, ws, n, bins);
    if (find_cuts(x, ws, n, bins) == 0) return 0;
    return cut_layers(x, pl, ws, n);
}

}  // namespace wul3d::detail
