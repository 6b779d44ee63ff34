// The scope (Scope::Support, the default): whole frames show the floor, walls and furniture
// besides the table, and their segments are objects to the rules but not to the user, who
// asked what the table holds. A segment is kept when it lies within the support's volume
// (under the height limit, spanning no more than it on the support, not running on past the
// support's hull or out of view beyond its middle) and stands on the support, or hides its
// foot from the camera, or rests on a segment that is kept, unless it is a low support: a
// board or tray on the floor that holds other kept segments (docs/DESIGN.md, "Scope").
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <omp.h>

#include "../team_tasks.hpp"
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

/// Over pixels [p0, p1): the sum of the depths of the removed points on the support (in
/// pixel order), their count, least and greatest depth. Per chunk a branch-free loop that
/// tells the points on the support (vectorizes), then the sum over them.
struct DepthSum {
    double sum = 0, count = 0;
    float lo = std::numeric_limits<float>::max(), hi = 0;
};
DepthSum sum_support_depths(const Ctx& x, const Plane& plane, std::size_t p0, std::size_t p1) {
    const float *const xs = x.c.x.data(), *const ys = x.c.y.data(), *const zs = x.c.z.data();
    const std::uint8_t *const valid = x.c.valid.data(), *const cls = x.cls.data();
    const float jump_m = x.prm.depth_jump_m, jump_rel = x.prm.depth_jump_rel;
    constexpr std::size_t kChunk = 256;
    std::uint8_t on[kChunk];
    DepthSum d;
    for (std::size_t c0 = p0; c0 < p1; c0 += kChunk) {
        const std::size_t n = std::min(kChunk, p1 - c0);
        for (std::size_t j = 0; j < n; ++j) {
            const std::size_t p = c0 + j;
            const float z = zs[p];
            // `!(a > b)` as before.
            on[j] = (valid[p] != 0) & (cls[p] == kPlaneRemoved) &
                    !(std::fabs(plane.height(xs[p], ys[p], z)) > sensor_depth_step(jump_m, jump_rel, z));
        }
        for (std::size_t j = 0; j < n; ++j) {
            if (!on[j]) continue;
            const float z = zs[c0 + j];
            d.sum += z;
            d.count += 1;
            d.lo = std::min(d.lo, z);
            d.hi = std::max(d.hi, z);
        }
    }
    return d;
}

/// The support's middle in depth: the mean depth of the removed points on it. Walls and
/// furniture leave the volume beyond it; on the near half an object cut by the frame (at
/// the bottom or the sides of a tabletop view), or by the hull where the frame hides the
/// table's near edge, is still on the table. Summed in parts in parallel where the double
/// sum is exact (every depth a multiple of the float step at the least depth, the total
/// under 2^53 such steps: the sum in pixel order, whatever the parts), else again in pixel
/// order. Cost: one pass over the pixels, parts in parallel.
float support_middle_depth(const Ctx& x, const Plane& pl) {
    constexpr int kParts = 16;
    const std::size_t N = x.c.size();
    if (team_strips(x.H) == 1) {  // one thread: in pixel order
        const DepthSum d = sum_support_depths(x, pl, 0, N);
        return d.count > 0 ? static_cast<float>(d.sum / d.count) : 0.0f;
    }
    DepthSum part[kParts];
    for_each_part(kParts, Spread::kStatic, [&](std::ptrdiff_t k) {
        part[k] = sum_support_depths(x, pl, N * static_cast<std::size_t>(k) / kParts,
                                     N * static_cast<std::size_t>(k + 1) / kParts);
    });
    DepthSum all;
    for (const DepthSum& d : part) {
        all.sum += d.sum, all.count += d.count;
        all.lo = std::min(all.lo, d.lo), all.hi = std::max(all.hi, d.hi);
    }
    if (!(all.count > 0)) return 0.0f;
    const bool exact = all.lo > 0 && std::isfinite(all.hi) &&
                       all.count * all.hi < std::ldexp(1.0, std::ilogb(all.lo) - 23 + 53);
    if (!exact) all = sum_support_depths(x, pl, 0, N);
    return static_cast<float>(all.sum / all.count);
}

using ScopeCounts = SegmentBuffers::ScopeCounts;

/// A removed point no higher over a low support than this many depth steps at its depth
/// (Ctx::depth_step) lies on it. The plane stage removes the low support's band (about a
/// depth step, widened up to 1.5 times with the frame's noise), and with it the strip of
/// what stands on the board within that band, whose noisy points reach higher: a box's
/// strip on a floor tune frame lay 30-33 mm over the board's top, two steps there. The
/// floor tune seeds score alike from 3 to 100 steps, a little lower at 1 and 2
/// (docs/ABLATION.md, "Scope").
constexpr float kLowSupportSteps = 3.0f;

/// measure_scope's counts of the segments' pixels in rows [v0, v1) into cnt[0, n], the
/// touching pairs into `edges` (not unique), and with `sums` (one strip: the whole frame)
/// the sums of the points into sums[0][l], sums[1][l], sums[2][l]. Writes nothing else:
/// strips of rows run in parallel (without sums).
void measure_strip(const Ctx& x, const Plane& pl, const FrameEdge& fe, float far_z, const int* label, int v0,
                   int v1, ScopeCounts* cnt, std::vector<std::uint64_t>& edges, double* const* sums) {
    const int W = x.W;
    const SegmentParams& prm = x.prm;
    auto height = [&](std::size_t p) { return pl.height(x.c.x[p], x.c.y[p], x.c.z[p]); };
    // A removed point clearly above the support (by more than the depth noise at its depth)
    // was removed for lying off the support's hull: the segment that runs on into it, with
    // continuous depth, continues beyond the support's volume. Unless it lies on a low
    // support (kLowSupportSteps): a board's top, or the band of it that its removal took off
    // an object standing on it, is inside the volume.
    auto beyond = [&](std::size_t q, std::size_t p) {
        if (!x.c.valid[q] || x.cls[q] != kPlaneRemoved || !x.connected(p, q)) return false;
        const float z = x.c.z[q];
        if (x.low_support &&
            x.low_support->height(x.c.x[q], x.c.y[q], z) <= kLowSupportSteps * x.depth_step(z))
            return false;
        return height(q) > x.depth_step(z);
    };
    // Outline pairs: touching segment pairs, and the pairs that lead out of the volume.
    auto pair = [&](std::size_t p, std::size_t q) {
        const int a = label[p], b = label[q];
        if (a == b) return;
        if (a) ++cnt[a].outline;
        if (b) ++cnt[b].outline;
        if (a && b) {
            edges.push_back(static_cast<std::uint64_t>(std::min(a, b)) << 33 |
                            static_cast<std::uint64_t>(std::max(a, b)) << 1);
        } else if (a) {
            cnt[a].outside += x.c.z[p] > far_z && beyond(q, p);
        } else {
            cnt[b].outside += x.c.z[q] > far_z && beyond(p, q);
        }
    };
    // A row without a label whose next row has none either adds nothing (every pair in it
    // and down from it joins two unlabelled pixels), and is skipped.
    auto labelled_row = [&](int v) {
        return row_has_label(label + static_cast<std::size_t>(v) * W, fe.left, fe.right);
    };
    bool next_has_label = v0 < v1 && labelled_row(v0);
    for (int v = v0; v < v1; ++v) {
        const bool has_label = next_has_label;
        next_has_label = v + 1 < fe.bottom && labelled_row(v + 1);
        if (!has_label && !next_has_label) continue;
        for (int u = fe.left; u < fe.right; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (const int l = label[p]) {
                const float h = height(p);
                ScopeCounts& c = cnt[l];
                c.lo = std::min(c.lo, h);
                c.any_px = static_cast<int>(p);
                if (sums) sums[0][l] += x.c.x[p], sums[1][l] += x.c.y[p], sums[2][l] += x.c.z[p];
                c.hi = std::max(c.hi, h);
                c.high += h > prm.scope.max_height_m;
                ++c.size;
                // On the frame's edge, beyond the support's middle.
                const int on_edge = x.c.z[p] > far_z ? (v == fe.edge_top) + (u == fe.edge_left) +
                                                           (u == fe.edge_right) + (v == fe.edge_bottom)
                                                     : 0;
                c.outline += on_edge;
                c.frame += on_edge;
            }
            // Most pairs join equal labels and add nothing: that test stays here, in line
            // (GCC does not inline `pair`, called twice).
            if (u + 1 < fe.right && label[p] != label[p + 1]) pair(p, p + 1);
            if (v + 1 < fe.bottom && label[p] != label[p + W]) pair(p, p + static_cast<std::size_t>(W));
        }
    }
}

/// The strips' counts into ws.scope_* and ws.sizes (minima, maxima, the last pixel, sums of
/// counts: the same in any order of the strips), their touching pairs into ws.edges, once
/// each.
void gather_strips(SegmentBuffers& ws, int strips, std::size_t L) {
    ws.scope_lo.resize(L);
    ws.scope_hi.resize(L);
    ws.scope_any_px.resize(L);
    ws.scope_high.resize(L);
    ws.scope_outline.resize(L);
    ws.scope_outside.resize(L);
    ws.scope_frame.resize(L);
    ws.sizes.resize(L);
    for (std::size_t l = 0; l < L; ++l) {
        ScopeCounts t = ws.scope_strips[l];
        for (int s = 1; s < strips; ++s) {
            const ScopeCounts& c = ws.scope_strips[static_cast<std::size_t>(s) * L + l];
            t.lo = std::min(t.lo, c.lo), t.hi = std::max(t.hi, c.hi), t.any_px = std::max(t.any_px, c.any_px);
            t.high += c.high, t.outline += c.outline, t.outside += c.outside, t.frame += c.frame, t.size += c.size;
        }
        ws.scope_lo[l] = t.lo, ws.scope_hi[l] = t.hi, ws.scope_any_px[l] = t.any_px, ws.scope_high[l] = t.high;
        ws.scope_outline[l] = t.outline, ws.scope_outside[l] = t.outside, ws.scope_frame[l] = t.frame;
        ws.sizes[l] = t.size;
    }
    ws.edges.clear();
    for (int s = 0; s < strips; ++s) {
        const auto& e = ws.strip_pairs[static_cast<std::size_t>(s)];
        ws.edges.insert(ws.edges.end(), e.begin(), e.end());
    }
    std::sort(ws.edges.begin(), ws.edges.end());
    ws.edges.erase(std::unique(ws.edges.begin(), ws.edges.end()), ws.edges.end());
}

/// ws.scope_sx, sy, sz (zeroed): the sums of each segment's points inside the frame's edge,
/// in raster order (a double sum in another order would round otherwise). Cost: a pass over
/// the rows with labels.
void sum_points(const Ctx& x, const FrameEdge& fe, SegmentBuffers& ws) {
    const int* const label = ws.label.data();
    for (int v = fe.top; v < fe.bottom; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * x.W;
        if (!row_has_label(label + row, fe.left, fe.right)) continue;
        for (int u = fe.left; u < fe.right; ++u) {
            const std::size_t p = row + u;
            if (const int l = label[p]) {
                ws.scope_sx[static_cast<std::size_t>(l)] += x.c.x[p];
                ws.scope_sy[static_cast<std::size_t>(l)] += x.c.y[p];
                ws.scope_sz[static_cast<std::size_t>(l)] += x.c.z[p];
            }
        }
    }
}

/// Per segment, over the frame inside its edge: the lowest and highest point over the
/// support (ws.scope_lo, scope_hi), points over the height limit (scope_high), pixels
/// (ws.sizes), the sums of its points (scope_sx, sy, sz), outline pairs (scope_outline) and
/// those that lead out of the volume (scope_outside: into removed points above the support,
/// beyond the support's middle `far_z`) or into the frame's edges there (scope_frame); the
/// touching segment pairs, once each, into ws.edges. In: ws.label (1..n with gaps). Cost: one
/// pass over the pixels in strips of rows, a strip per thread, the counts gathered (O(strips
/// n)), a sort of the pairs, and with more than one strip a pass over the labelled rows for
/// the sums.
void measure_scope(const Ctx& x, const Plane& pl, const FrameEdge& fe, float far_z, SegmentBuffers& ws,
                   int n) {
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const int rows = std::max(fe.bottom - fe.top, 0);
    const int strips = team_strips(rows);
    constexpr float kMax = std::numeric_limits<float>::max();
    ws.scope_strips.assign(static_cast<std::size_t>(strips) * L, ScopeCounts{kMax, -kMax, -1, 0, 0, 0, 0, 0});
    ws.strip_pairs.resize(static_cast<std::size_t>(strips));
    ws.scope_sx.assign(L, 0.0);
    ws.scope_sy.assign(L, 0.0);
    ws.scope_sz.assign(L, 0.0);
    double* const sums[3] = {ws.scope_sx.data(), ws.scope_sy.data(), ws.scope_sz.data()};
    const int* const label = ws.label.data();
    auto strip = [&](std::ptrdiff_t s) {
        auto& edges = ws.strip_pairs[static_cast<std::size_t>(s)];
        edges.clear();
        const int v0 = fe.top + rows * static_cast<int>(s) / strips, v1 = fe.top + rows * static_cast<int>(s + 1) / strips;
        measure_strip(x, pl, fe, far_z, label, v0, v1, ws.scope_strips.data() + static_cast<std::size_t>(s) * L, edges,
                      strips == 1 ? sums : nullptr);
    };
    if (strips == 1)
        strip(0);
    else
        for_each_part(strips, Spread::kStatic, strip);
    gather_strips(ws, strips, L);
    if (strips > 1) sum_points(x, fe, ws);
}

/// ws.scope_upright: per segment that runs into the frame's edges (scope_frame),
/// its pixels facing sideways (normals within kUprightDeg of the support plane); 0 for the
/// others. Cost: none when no segment does (most tabletop frames), else one pass over the
/// pixels.
void count_upright(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
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

/// The organized grid's scale at pixel p: pixels per unit of x/z (fx) and of y/z (fy), from
/// a neighbour with depth on either side; false where p has none. Cost: a few reads.
bool grid_scale(const Ctx& x, int p, float& fx, float& fy) {
    const int W = x.W, u = p % W, v = p / W;
    const auto P = static_cast<std::size_t>(p);
    auto scale = [&](int du, int dv) -> float {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || uu >= W || vv < 0 || vv >= x.H) return 0.0f;
        const auto q = static_cast<std::size_t>(vv) * W + uu;
        if (!x.c.valid[q]) return 0.0f;
        const float d = du ? x.c.x[q] / x.c.z[q] - x.c.x[P] / x.c.z[P] : x.c.y[q] / x.c.z[q] - x.c.y[P] / x.c.z[P];
        return std::fabs(d) > 1e-9f ? static_cast<float>(du + dv) / d : 0.0f;
    };
    fx = scale(1, 0);
    fy = scale(0, 1);
    if (!(fx > 0.0f)) fx = scale(-1, 0);
    if (!(fy > 0.0f)) fy = scale(0, -1);
    return fx > 0.0f && fy > 0.0f;
}

/// The foot's pixel within this many pixels of the segment's own is hidden by its body: a ball
/// seen from above hangs over the support round its contact, and the foot under its middle
/// falls at its lowest outline, where the outline lies nearer than the support by less than
/// a depth step (a ball 10 cm across on the floor under active stereo, floor tune 20047). An
/// object over the support on a shelf or a hand shows the support under its middle away
/// from its outline. 1 px missed that ball; 2 and 3 score the same.
constexpr int kFootNearPx = 2;

/// Whether a pixel of segment l lies within kFootNearPx of pixel (fu, fv). Cost: 25 reads.
bool borders_own_pixels(const Ctx& x, const SegmentBuffers& ws, std::size_t l, long fu, long fv) {
    for (long v = std::max(0L, fv - kFootNearPx); v <= std::min<long>(x.H - 1, fv + kFootNearPx); ++v)
        for (long u = std::max(0L, fu - kFootNearPx); u <= std::min<long>(x.W - 1, fu + kFootNearPx); ++u)
            if (ws.label[static_cast<std::size_t>(v * x.W + u)] == static_cast<int>(l)) return true;
    return false;
}

/// Whether the camera could see the support under segment l's middle: F, the foot of the
/// segment's mean point on the support, is placed in the image by the local scale of the
/// organized grid (the pitch of the points beside one of the segment's pixels), and the
/// pixel there shows something nearer than F (the segment itself, or an object in front),
/// shows nothing (no depth: the sensor's shadow beside an object), lies out of the frame, or
/// borders the segment's own pixels (borders_own_pixels).
/// A box seen from steeply above shows its top alone, its sides in shadow or edge-on, and
/// its body hides its foot. A box hanging over the table, seen obliquely, shows the table
/// under its middle. Cost: a few reads per segment.
bool foot_hidden(const Ctx& x, const Plane& pl, const SegmentBuffers& ws, std::size_t l) {
    const int p = ws.scope_any_px[l];
    if (p < 0 || ws.sizes[l] == 0) return false;
    const int W = x.W, u = p % W, v = p / W;
    const auto P = static_cast<std::size_t>(p);
    float fx = 0.0f, fy = 0.0f;
    if (!grid_scale(x, p, fx, fy)) return false;
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
    return x.c.z[f] < fzw - x.depth_step(fzw) || borders_own_pixels(x, ws, l, fu, fv);
}

/// Each end of a direction leaves out this share of a segment's positions when its span is
/// measured: pixels mixed across a depth edge lie metres behind an object in a RealSense
/// frame, and with them a canister 10 cm wide spanned 0.83 m.
constexpr float kSpanTrim = 0.05f;

/// Pixel p's positions on the support along four directions 45 degrees apart, metres.
void positions_along(const Ctx& x, const PlaneAxes& axes, std::size_t p, float (&along)[4]) {
    constexpr float kHalfRoot2 = 0.70710678f;
    const Eigen::Vector2d q = axes(x.c, p);
    const auto a = static_cast<float>(q.x()), b = static_cast<float>(q.y());
    along[0] = a;
    along[1] = b;
    along[2] = kHalfRoot2 * (a + b);
    along[3] = kHalfRoot2 * (a - b);
}

/// ws.scope_wide per segment: 1 when it spans more than `limit` on the support, its span the
/// widest of four directions 45 degrees apart (within 8 % of its diameter), each from the
/// kSpanTrim quantile to the 1 - kSpanTrim one and scaled back to the whole; never for a
/// segment under 20 pixels. The trimmed range is within the whole range, so only a segment
/// whose whole range, scaled alike, passes the limit is sorted out and selected on (few: a
/// wall, furniture). Cost: a pass over the rows with segments; for those few, a counting sort
/// of the pixels and a selection per direction. No allocation once sized.
void measure_spans(const Ctx& x, const Plane& pl, float limit, SegmentBuffers& ws, int n) {
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const PlaneAxes axes(pl);
    constexpr float kKept = 1.0f - 2.0f * kSpanTrim;
    // 1. Each segment's pixels and its whole range along each direction.
    ws.scope_span_pixels.assign(L, 0);
    ws.scope_span_range.assign(8 * L, 0.0f);
    float* const range = ws.scope_span_range.data();  // per segment: lo[4], hi[4]
    for (int v = 0; v < x.H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * static_cast<std::size_t>(x.W);
        if (!row_has_label(ws.label.data() + row, 0, x.W)) continue;
        for (std::size_t p = row; p < row + static_cast<std::size_t>(x.W); ++p) {
            const auto l = static_cast<std::size_t>(ws.label[p]);
            if (l == 0) continue;
            float along[4];
            positions_along(x, axes, p, along);
            float* const lo = range + 8 * l;
            float* const hi = lo + 4;
            const bool first = ws.scope_span_pixels[l]++ == 0;
            for (int k = 0; k < 4; ++k) {
                lo[k] = first ? along[k] : std::min(lo[k], along[k]);
                hi[k] = first ? along[k] : std::max(hi[k], along[k]);
            }
        }
    }
    // 2. The candidates: 20 pixels or more, a whole range over the limit once scaled.
    ws.scope_wide.assign(L, 0);
    bool any = false;
    for (std::size_t l = 1; l < L; ++l) {
        if (ws.scope_span_pixels[l] < 20) continue;
        for (int k = 0; k < 4; ++k)
            if ((range[8 * l + 4 + static_cast<std::size_t>(k)] - range[8 * l + static_cast<std::size_t>(k)]) / kKept >
                limit) {
                ws.scope_wide[l] = 1;  // a candidate, decided below
                any = true;
            }
    }
    if (!any) return;
    // 3. Their trimmed spans, from their pixels sorted out.
    sort_pixels_by_segment(x, ws, n);
    for (std::size_t l = 1; l < L; ++l) {
        if (!ws.scope_wide[l]) continue;
        const int first = ws.offsets[l], m = ws.offsets[l + 1] - first;
        ws.scope_along.resize(4 * static_cast<std::size_t>(m));
        float* const along[4] = {ws.scope_along.data(), ws.scope_along.data() + m, ws.scope_along.data() + 2 * m,
                                 ws.scope_along.data() + 3 * m};
        for (int i = 0; i < m; ++i) {
            float at[4];
            positions_along(x, axes, static_cast<std::size_t>(ws.order[static_cast<std::size_t>(first + i)]), at);
            for (int k = 0; k < 4; ++k) along[k][i] = at[k];
        }
        const int cut = static_cast<int>(kSpanTrim * static_cast<float>(m));
        float span = 0.0f;
        for (float* const positions : along) {
            std::nth_element(positions, positions + cut, positions + m);
            const float lo = positions[cut];
            std::nth_element(positions, positions + (m - 1 - cut), positions + m);
            span = std::max(span, (positions[m - 1 - cut] - lo) / kKept);
        }
        ws.scope_wide[l] = span > limit;
    }
}

/// ws.scope_keep per segment, from measure_scope's counts and measure_spans: bit 0 inside the
/// volume, bit 1 kept. Inside: under the height limit (2 % of the points may be noise),
/// spanning no more than that limit on the support (a cabinet, a chair, a wall the frame cuts
/// before it rises past the limit), and not running on past the hull or out of view. Kept:
/// stands (the lowest point touches the support, or the camera cannot see the support under
/// the segment's middle: foot_hidden), or
/// rests on a kept segment: touches it in the image (a box on a box, a lid on a tin, an
/// object behind another with its foot hidden). No height test: a supported object's visible
/// bottom can lie well above its supporter's visible top (a tin's lid overhangs what it
/// stands on), and what hangs or is fixed to a wall has already left the volume. Cost: O(n),
/// then passes over ws.edges until "rests on" stops spreading.
void decide_scope(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
    const SegmentParams& prm = x.prm;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    auto& keep = ws.scope_keep;
    keep.assign(L, 0);
    for (std::size_t l = 1; l < L; ++l) {
        if (ws.sizes[l] == 0) continue;
        // The frame's edges cut walls and the sides of furniture, and objects on the table
        // too (at the top, on its far half); only an upright segment (a wall) leaves the
        // volume there.
        const bool upright =
            static_cast<float>(ws.scope_upright[l]) >= prm.scope.upright_share * static_cast<float>(ws.sizes[l]);
        const int outside = ws.scope_outside[l] + (upright ? ws.scope_frame[l] : 0);
        const bool inside = 50 * ws.scope_high[l] <= ws.sizes[l] && !ws.scope_wide[l] &&
                            static_cast<float>(outside) <=
                                prm.scope.max_outside * static_cast<float>(ws.scope_outline[l]);
        const bool stands = ws.scope_lo[l] <= prm.scope.contact_m ||
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

/// Segment l's area on the support, square metres: its pixels times the area one pixel covers
/// at its mean point, a plane parallel to the support seen along the ray to that point.
/// 0 where the grid's scale is unknown. Cost: a few reads.
double area_on_support(const Ctx& x, const Plane& pl, const SegmentBuffers& ws, std::size_t l) {
    float fx = 0.0f, fy = 0.0f;
    if (ws.sizes[l] == 0 || ws.scope_any_px[l] < 0 || !grid_scale(x, ws.scope_any_px[l], fx, fy)) return 0.0;
    const double m = ws.sizes[l];
    const double cx = ws.scope_sx[l] / m, cy = ws.scope_sy[l] / m, cz = ws.scope_sz[l] / m;
    const double ray = std::sqrt(cx * cx + cy * cy + cz * cz);
    const double cos_view = std::fabs(pl.nx * cx + pl.ny * cy + pl.nz * cz) / ray;
    if (!(cos_view > 0.05)) return 0.0;
    return m * (cz / fx) * (cz / fy) / cos_view;
}

/// Low supports (ScopeParams::low_support_max_m): kept segments that lie low, cover
/// scope.low_support_min_area_m2 of the support and hold two kept segments or more (that touch
/// them and rise scope.contact_m higher) are left out, keep 0: a board or a tray on the
/// floor. What they hold stays kept. Cost: O(n) and one pass over ws.edges.
void drop_low_supports(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
    const SegmentParams& prm = x.prm;
    if (!(prm.scope.low_support_max_m > 0)) return;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    auto& keep = ws.scope_keep;
    std::vector<int>& held = ws.scope_held;
    held.assign(L, 0);
    for (const std::uint64_t e : ws.edges) {
        const auto a = static_cast<std::size_t>(e >> 33), b = static_cast<std::size_t>((e >> 1) & 0xffffffffu);
        if (keep[a] != 3 || keep[b] != 3) continue;
        // The lower of two kept segments holds the other when that one rises over it.
        const auto [lo, hi] = ws.scope_hi[a] <= ws.scope_hi[b] ? std::pair{a, b} : std::pair{b, a};
        if (ws.scope_hi[lo] <= prm.scope.low_support_max_m && ws.scope_hi[hi] > ws.scope_hi[lo] + prm.scope.contact_m)
            ++held[lo];
    }
    for (std::size_t l = 1; l < L; ++l)
        if (held[l] >= 2 && area_on_support(x, pl, ws, l) >= prm.scope.low_support_min_area_m2) keep[l] = 0;
}

/// Clears the labels of the segments not kept. Returns those of min_points or more (within
/// the frame's edge). Cost: one parallel pass over the pixels.
int clear_out_of_scope(const SegmentParams& prm, SegmentBuffers& ws, int n) {
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const auto& keep = ws.scope_keep;
    int left_out = 0;
    for (std::size_t l = 1; l < L; ++l)
        left_out += keep[l] != 3 && ws.sizes[l] >= prm.min_points;
    int* const label = ws.label.data();
    const std::uint8_t* const kept = keep.data();
    const auto n_px = static_cast<std::ptrdiff_t>(ws.label.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p)
        if (label[p] && kept[label[p]] != 3) label[p] = 0;
    return left_out;
}

/// Scope::Support (docs/DESIGN.md, "Scope"): keeps the segments the support holds and
/// clears the others' labels in ws.label. In: ws.label (1..n with gaps), the support, the
/// plane's classes. Out: the number of segments of min_points or more left out. Cost: one
/// pass over the pixels (heights, outlines, touching pairs) and one over the depths, the
/// spans (measure_spans), then a few passes over the touching pairs until "rests on" stops
/// spreading.
int keep_held(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
    const FrameEdge edge = find_frame_edge(x);
    const float far_z = support_middle_depth(x, pl);
    measure_scope(x, pl, edge, far_z, ws, n);
    count_upright(x, pl, ws, n);
    measure_spans(x, pl, x.prm.scope.max_height_m, ws, n);
    decide_scope(x, pl, ws, n);
    drop_low_supports(x, pl, ws, n);
    return clear_out_of_scope(x.prm, ws, n);
}

}  // namespace

void restrict_to_support(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    stats.scope.applied = true;
    stats.scope.out_of_scope = keep_held(x, *support, ws, n);
}

}  // namespace wul3d::detail
