// The scope (Scope::Support, the default): whole frames show the floor, walls and furniture
// besides the table, and their segments are objects to the rules but not to the user, who
// asked what the table holds. A segment is kept when it lies within the support's volume
// (under the height limit, not running on past the support's hull or out of view beyond
// its middle) and stands on the support, or hides its foot from the camera, or rests on a
// segment that is kept (docs/DESIGN.md, "Scope").
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {

namespace {

/// The frame's edge: the image border and the rows and columns with no depth at all that
/// reach it, when they are a narrow band (a sensor's registration border: 48 rows and 63
/// columns of a Kinect v1's 640x480). A segment cut there goes on out of view. A wider band
/// without depth is a view past the depth range or a crop, which says nothing of what the
/// segment does there.
struct FrameEdge {
    int top, bottom, left, right;  ///< the rows [top, bottom) and columns [left, right) with depth
    int edge_top, edge_bottom, edge_left, edge_right;  ///< the edge's rows and columns; -1: none
};

/// FrameEdge of the frame. Cost: a pass over each row and column without depth at the
/// border, and over the first one with depth.
FrameEdge find_frame_edge(const Ctx& x) {
    const int W = x.W, H = x.H;
    int top = 0, bottom = H, left = 0, right = W;
    auto row_empty = [&](int v) {
        for (int u = 0; u < W; ++u)
            if (x.c.valid[static_cast<std::size_t>(v) * W + u]) return false;
        return true;
    };
    auto col_empty = [&](int u) {
        for (int v = 0; v < H; ++v)
            if (x.c.valid[static_cast<std::size_t>(v) * W + u]) return false;
        return true;
    };
    while (top < H && row_empty(top)) ++top;
    while (bottom > top && row_empty(bottom - 1)) --bottom;
    while (left < W && col_empty(left)) ++left;
    while (right > left && col_empty(right - 1)) --right;
    const int band_rows = H / 8, band_cols = W / 8;
    const int edge_top = top <= band_rows ? top : -1, edge_bottom = H - bottom <= band_rows ? bottom - 1 : -1;
    const int edge_left = left <= band_cols ? left : -1, edge_right = W - right <= band_cols ? right - 1 : -1;
    return {top, bottom, left, right, edge_top, edge_bottom, edge_left, edge_right};
}

/// The support's middle in depth: the mean depth of the removed points on it. Walls and
/// furniture leave the volume beyond it; on the near half an object cut by the frame (at
/// the bottom or the sides of a tabletop view), or by the hull where the frame hides the
/// table's near edge, is still on the table. Cost: one pass over the pixels, per chunk a
/// branch-free loop that tells the points on the support (vectorizes), then the sum over
/// them in pixel order (a double sum in another order would round otherwise).
float support_middle_depth(const Ctx& x, const Plane& pl) {
    const float *const xs = x.c.x.data(), *const ys = x.c.y.data(), *const zs = x.c.z.data();
    const std::uint8_t *const valid = x.c.valid.data(), *const cls = x.cls.data();
    const float jump_m = x.prm.depth_jump_m, jump_rel = x.prm.depth_jump_rel;
    const Plane plane = pl;
    constexpr std::size_t kChunk = 256;
    std::uint8_t on[kChunk];
    double table_z = 0, table_n = 0;
    for (std::size_t p0 = 0; p0 < x.c.size(); p0 += kChunk) {
        const std::size_t n = std::min(kChunk, x.c.size() - p0);
        for (std::size_t j = 0; j < n; ++j) {
            const std::size_t p = p0 + j;
            const float z = zs[p];
            // `!(a > b)` as before.
            on[j] = (valid[p] != 0) & (cls[p] == kPlaneRemoved) &
                    !(std::fabs(plane.height(xs[p], ys[p], z)) > sensor_depth_step(jump_m, jump_rel, z));
        }
        for (std::size_t j = 0; j < n; ++j) {
            if (!on[j]) continue;
            table_z += zs[p0 + j];
            table_n += 1;
        }
    }
    return table_n > 0 ? static_cast<float>(table_z / table_n) : 0.0f;
}

/// Per segment, over the frame inside its edge: the lowest and highest point over the
/// support (ws.scope_lo, scope_hi), points over the height limit (scope_high), pixels
/// (ws.sizes), outline pairs (scope_outline) and those that lead out of the volume
/// (scope_outside: into removed points above the support, or into the frame's top edge,
/// beyond the support's middle `far_z`) or into its other edges there (scope_frame); the
/// touching segment pairs, once each, into ws.edges. In:
/// ws.label (1..n with gaps). Cost: one pass over the pixels, then a sort of the pairs.
void measure_scope(const Ctx& x, const Plane& pl, const FrameEdge& fe, float far_z, SegmentWorkspace& ws,
                   int n) {
    const int W = x.W;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    ws.scope_lo.assign(L, std::numeric_limits<float>::max());
    ws.scope_any_px.assign(L, -1);
    ws.scope_sx.assign(L, 0.0);
    ws.scope_sy.assign(L, 0.0);
    ws.scope_sz.assign(L, 0.0);
    ws.scope_hi.assign(L, -std::numeric_limits<float>::max());
    ws.scope_high.assign(L, 0);
    ws.scope_outline.assign(L, 0);
    ws.scope_outside.assign(L, 0);
    ws.scope_frame.assign(L, 0);
    ws.sizes.assign(L, 0);
    ws.edges.clear();
    const int* const label = ws.label.data();
    const SegmentParams& prm = x.prm;
    auto height = [&](std::size_t p) { return pl.height(x.c.x[p], x.c.y[p], x.c.z[p]); };
    // A removed point clearly above the support (by more than the depth noise at its depth)
    // was removed for lying off the support's hull: the segment that runs on into it, with
    // continuous depth, continues beyond the support's volume.
    auto beyond = [&](std::size_t q, std::size_t p) {
        if (!x.c.valid[q] || x.cls[q] != kPlaneRemoved || !x.connected(p, q)) return false;
        const float z = x.c.z[q];
        return height(q) > x.depth_step(z);
    };
    // Outline pairs: touching segment pairs, and the pairs that lead out of the volume.
    auto pair = [&](std::size_t p, std::size_t q) {
        const int a = label[p], b = label[q];
        if (a == b) return;
        if (a) ++ws.scope_outline[static_cast<std::size_t>(a)];
        if (b) ++ws.scope_outline[static_cast<std::size_t>(b)];
        if (a && b) {
            ws.edges.push_back(static_cast<std::uint64_t>(std::min(a, b)) << 33 |
                               static_cast<std::uint64_t>(std::max(a, b)) << 1);
        } else if (a) {
            ws.scope_outside[static_cast<std::size_t>(a)] += x.c.z[p] > far_z && beyond(q, p);
        } else {
            ws.scope_outside[static_cast<std::size_t>(b)] += x.c.z[q] > far_z && beyond(p, q);
        }
    };
    // A row without a label whose next row has none either adds nothing (every pair in it
    // and down from it joins two unlabelled pixels), and is skipped.
    auto labelled_row = [&](int v) {
        return row_has_label(label + static_cast<std::size_t>(v) * W, fe.left, fe.right);
    };
    bool next_has_label = fe.top < fe.bottom && labelled_row(fe.top);
    for (int v = fe.top; v < fe.bottom; ++v) {
        const bool has_label = next_has_label;
        next_has_label = v + 1 < fe.bottom && labelled_row(v + 1);
        if (!has_label && !next_has_label) continue;
        for (int u = fe.left; u < fe.right; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (const int l = label[p]) {
                const float h = height(p);
                const auto li = static_cast<std::size_t>(l);
                ws.scope_lo[li] = std::min(ws.scope_lo[li], h);
                ws.scope_any_px[li] = static_cast<int>(p);
                ws.scope_sx[li] += x.c.x[p];
                ws.scope_sy[li] += x.c.y[p];
                ws.scope_sz[li] += x.c.z[p];
                ws.scope_hi[li] = std::max(ws.scope_hi[li], h);
                ws.scope_high[li] += h > prm.scope_max_height_m;
                ++ws.sizes[li];
                // On the frame's edge, beyond the support's middle.
                const int on_edge = x.c.z[p] > far_z ? (v == fe.edge_top) + (u == fe.edge_left) +
                                                           (u == fe.edge_right) + (v == fe.edge_bottom)
                                                     : 0;
                const int on_top = x.c.z[p] > far_z && v == fe.edge_top;
                ws.scope_outline[li] += on_edge;
                ws.scope_outside[li] += on_top;
                ws.scope_frame[li] += on_edge - on_top;
            }
            // Most pairs join equal labels and add nothing: that test stays here, in line
            // (GCC does not inline `pair`, called twice).
            if (u + 1 < fe.right && label[p] != label[p + 1]) pair(p, p + 1);
            if (v + 1 < fe.bottom && label[p] != label[p + W]) pair(p, p + static_cast<std::size_t>(W));
        }
    }
    std::sort(ws.edges.begin(), ws.edges.end());
    ws.edges.erase(std::unique(ws.edges.begin(), ws.edges.end()), ws.edges.end());
}

/// ws.scope_upright: per segment that runs into the frame's sides or bottom (scope_frame),
/// its pixels facing sideways (normals within kUprightDeg of the support plane); 0 for the
/// others. Cost: none when no segment does (most tabletop frames), else one pass over the
/// pixels.
void count_upright(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    ws.scope_upright.assign(L, 0);
    if (std::all_of(ws.scope_frame.begin(), ws.scope_frame.end(), [](int f) { return f == 0; })) return;
    const float sin_upright = std::sin(kUprightDeg * kDegToRad);
    for (std::size_t p = 0; p < x.c.size(); ++p) {
        const auto l = static_cast<std::size_t>(ws.label[p]);
        if (l == 0 || ws.scope_frame[l] == 0) continue;
        ws.scope_upright[l] += faces_sideways(x, pl, p, sin_upright);
    }
}

/// Whether the camera could see the support under segment l's middle: F, the foot of the
/// segment's mean point on the support, is placed in the image by the local scale of the
/// organized grid (the pitch of the points beside one of the segment's pixels), and the
/// pixel there shows something nearer than F (the segment itself, or an object in front),
/// shows nothing (no depth: the sensor's shadow beside an object) or lies out of the frame.
/// A box seen from steeply above shows its top alone, its sides in shadow or edge-on, and
/// its body hides its foot. A box hanging over the table, seen obliquely, shows the table
/// under its middle. Cost: a few reads per segment.
bool foot_hidden(const Ctx& x, const Plane& pl, const SegmentWorkspace& ws, std::size_t l) {
    const int p = ws.scope_any_px[l];
    if (p < 0 || ws.sizes[l] == 0) return false;
    const int W = x.W, u = p % W, v = p / W;
    const auto P = static_cast<std::size_t>(p);
    // The grid's scale at p: pixels per unit of x/z (y/z), from a neighbour with depth.
    auto scale = [&](int du, int dv) -> float {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || uu >= W || vv < 0 || vv >= x.H) return 0.0f;
        const auto q = static_cast<std::size_t>(vv) * W + uu;
        if (!x.c.valid[q]) return 0.0f;
        const float d = du ? x.c.x[q] / x.c.z[q] - x.c.x[P] / x.c.z[P] : x.c.y[q] / x.c.z[q] - x.c.y[P] / x.c.z[P];
        return std::fabs(d) > 1e-9f ? static_cast<float>(du + dv) / d : 0.0f;
    };
    float fx = scale(1, 0), fy = scale(0, 1);
    if (!(fx > 0.0f)) fx = scale(-1, 0);
    if (!(fy > 0.0f)) fy = scale(0, -1);
    if (!(fx > 0.0f) || !(fy > 0.0f)) return false;
    const double m = ws.sizes[l];
    const auto cx = static_cast<float>(ws.scope_sx[l] / m), cy = static_cast<float>(ws.scope_sy[l] / m),
               cz = static_cast<float>(ws.scope_sz[l] / m);
    const float h = pl.height(cx, cy, cz);
    const float fxw = cx - h * pl.nx, fyw = cy - h * pl.ny, fzw = cz - h * pl.nz;
    if (!(fzw > 0.0f)) return true;
    const long fu = u + std::lround(fx * (fxw / fzw - x.c.x[P] / x.c.z[P]));
    const long fv = v + std::lround(fy * (fyw / fzw - x.c.y[P] / x.c.z[P]));
    if (fu < 0 || fu >= W || fv < 0 || fv >= x.H) return true;
    const auto f = static_cast<std::size_t>(fv) * W + static_cast<std::size_t>(fu);
    if (!x.c.valid[f]) return true;
    return x.c.z[f] < fzw - x.depth_step(fzw);
}

/// ws.scope_keep per segment, from measure_scope's counts: bit 0 inside the volume, bit 1
/// kept. Inside: under the height limit (2 % of the points may be noise) and not running on
/// past the hull or out of view. Kept: stands (the lowest point touches the support, or the
/// camera cannot see the support under the segment's middle: foot_hidden), or
/// rests on a kept segment: touches it in the image (a box on a box, a lid on a tin, an
/// object behind another with its foot hidden). No height test: a supported object's visible
/// bottom can lie well above its supporter's visible top (a tin's lid overhangs what it
/// stands on), and what hangs or is fixed to a wall has already left the volume. Cost: O(n),
/// then passes over ws.edges until "rests on" stops spreading.
void decide_scope(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    auto& keep = ws.scope_keep;
    keep.assign(L, 0);
    for (std::size_t l = 1; l < L; ++l) {
        if (ws.sizes[l] == 0) continue;
        // The frame's sides and bottom cut walls and the sides of furniture, and objects on
        // the table too; only an upright segment (a wall) leaves the volume there.
        const bool upright =
            static_cast<float>(ws.scope_upright[l]) >= prm.scope_upright_share * static_cast<float>(ws.sizes[l]);
        const int outside = ws.scope_outside[l] + (upright ? ws.scope_frame[l] : 0);
        const bool inside = 50 * ws.scope_high[l] <= ws.sizes[l] &&
                            static_cast<float>(outside) <=
                                prm.scope_max_outside * static_cast<float>(ws.scope_outline[l]);
        const bool stands = ws.scope_lo[l] <= prm.scope_contact_m ||
                            foot_hidden(x, pl, ws, l);
        keep[l] = static_cast<std::uint8_t>(inside ? (stands ? 3 : 1) : 0);
    }
    for (bool grew = true; grew;) {
        grew = false;
        for (const std::uint64_t e : ws.edges) {
            const auto a = static_cast<std::size_t>(e >> 33), b = static_cast<std::size_t>((e >> 1) & 0xffffffffu);
            for (const auto& [s, t] : {std::pair{a, b}, std::pair{b, a}}) {
                if (keep[s] != 3 || keep[t] != 1) continue;
                keep[t] = 3;
                grew = true;
            }
        }
    }
}

/// Clears the labels of the segments not kept. Returns those of min_points or more (within
/// the frame's edge). Cost: one pass over the pixels.
int clear_out_of_scope(const SegmentParams& prm, SegmentWorkspace& ws, int n) {
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const auto& keep = ws.scope_keep;
    int left_out = 0;
    for (std::size_t l = 1; l < L; ++l)
        left_out += keep[l] != 3 && ws.sizes[l] >= prm.min_points;
    for (int& l : ws.label)
        if (l && keep[static_cast<std::size_t>(l)] != 3) l = 0;
    return left_out;
}

/// Scope::Support (docs/DESIGN.md, "Scope"): keeps the segments the support holds and
/// clears the others' labels in ws.label. In: ws.label (1..n with gaps), the support, the
/// plane's classes. Out: the number of segments of min_points or more left out. Cost: one
/// pass over the pixels (heights, outlines, touching pairs) and one over the depths, then a
/// few passes over the touching pairs until "rests on" stops spreading.
int keep_held(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const FrameEdge edge = find_frame_edge(x);
    const float far_z = support_middle_depth(x, pl);
    measure_scope(x, pl, edge, far_z, ws, n);
    count_upright(x, pl, ws, n);
    decide_scope(x, pl, ws, n);
    return clear_out_of_scope(x.prm, ws, n);
}

}  // namespace

void restrict_to_support(const Ctx& x, const Plane* support, SegmentWorkspace& ws, int& n, SegmentStats& stats) {
    stats.support_scope = true;
    stats.out_of_scope = keep_held(x, *support, ws, n);
}

}  // namespace wul3d::detail
