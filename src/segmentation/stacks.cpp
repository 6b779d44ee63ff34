// The stack rule of segment_objects (SegmentParams, "Stacks"): a segment whose upward faces
// lie at two heights over the support, with nothing facing up between them, is two objects,
// one resting on the other. Where they meet without a crease (a box too thin for its sides
// to show a fold under the sensor's noise) and the colour cue cannot part them (one colour,
// or a print that 2-means follows), the heights still tell them apart. Two boxes of two
// heights standing side by side show the same two layers; there the taller one's walls run
// on below the cut, and their colour sends them up with it, or, in one colour, the lower
// layer's top showing on one side of the upper object only (keep_walls).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "internal.hpp"

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

/// Calls visit(p, l) for each pixel p of a segment l (labels 1..), skipping the rows without
/// any (most rows above and below the objects). Cost: one pass over the rows with objects.
template <class Visit>
void for_segment_pixels(const Ctx& x, const SegmentBuffers& ws, Visit&& visit) {
    for (int v = 0; v < x.H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * static_cast<std::size_t>(x.W);
        if (!row_has_label(ws.label.data() + row, 0, x.W)) continue;
        for (std::size_t p = row; p < row + static_cast<std::size_t>(x.W); ++p)
            if (const int l = ws.label[p]; l > 0) visit(p, l);
    }
}

/// Per segment, how many of its pixels face up (within kUprightDeg of the support's normal)
/// at each height over the support (bins of kLayerBinM from 0 up to the scope's height
/// limit, above which nothing stands on the support) into ws.layer_hist, segment after
/// segment, and its size into ws.sizes. In: ws.label (0..n). Cost: one pass over the rows
/// with objects.
void count_layers(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n, int bins) {
    ws.layer_hist.assign(static_cast<std::size_t>(n + 1) * static_cast<std::size_t>(bins), 0);
    ws.sizes.assign(static_cast<std::size_t>(n) + 1, 0);
    const float cos_up = std::cos(kUprightDeg * kDegToRad);
    for_segment_pixels(x, ws, [&](std::size_t p, int l) {
        ++ws.sizes[static_cast<std::size_t>(l)];
        if (!faces_up(x, pl, p, cos_up)) return;
        const int b = static_cast<int>(std::floor(pl.height(x.c.x[p], x.c.y[p], x.c.z[p]) / kLayerBinM));
        if (b >= 0 && b < bins)
            ++ws.layer_hist[static_cast<std::size_t>(l) * static_cast<std::size_t>(bins) + static_cast<std::size_t>(b)];
    });
}

/// The height that cuts one segment between two layers of its upward faces (hist: its
/// bins, size: its pixels), or a negative value when it has no two. A layer is a local peak
/// of the counts over three bins that holds stacks.min_share of the segment and min_points;
/// the lower stands stacks.min_step_m or more above the support (a box's top, not the table
/// or a bowl's floor); the two lie stacks.min_step_m or more apart, with a valley between
/// them (kValleyDivisor). Of several pairs, the one whose smaller layer is largest; the cut
/// lies kCutOverLowerM over its lower layer. Cost: O(bins^2), a hundred bins.
float cut_height(const int* hist, int bins, int size, const SegmentParams& prm) {
    auto window = [&](int b) { return (b > 0 ? hist[b - 1] : 0) + hist[b] + (b + 1 < bins ? hist[b + 1] : 0); };
    auto peak = [&](int b) {
        const int c = window(b);
        return c >= window(b - 1) && (b + 1 >= bins || c >= window(b + 1));
    };
    const int min_layer = std::max(prm.min_points, static_cast<int>(prm.stacks.min_share * static_cast<float>(size)));
    const int step = static_cast<int>(std::ceil(prm.stacks.min_step_m / kLayerBinM));
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
int find_cuts(const Ctx& x, SegmentBuffers& ws, int n, int bins) {
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

/// Calls visit(p, l, h) for each pixel p of a cut segment l, h its height over the support.
/// Cost: one pass over the rows with objects.
template <class Visit>
void for_cut_pixels(const Ctx& x, const Plane& pl, const SegmentBuffers& ws, Visit&& visit) {
    for_segment_pixels(x, ws, [&](std::size_t p, int l) {
        if (ws.stack_cut[static_cast<std::size_t>(l)] >= 0) visit(p, l, pl.height(x.c.x[p], x.c.y[p], x.c.z[p]));
    });
}

/// Where the upper object's walls stand is mapped in cells of this size on the support
/// plane, and a wall below the cut counts as under them within one cell: a wall's points
/// scatter by the sensor's noise, 3-7 mm at 1-1.5 m.
constexpr float kWallCellM = 0.01f;
/// A grid that would exceed this many cells a side (2.56 m) is not drawn: no object is that
/// large, and it bounds the memory.
constexpr int kMaxWallCells = 256;

/// The upper objects' walls: the pixels of each cut segment above its cut that face
/// sideways, with where they stand on the support plane, into ws.stack_walls. Cost: one pass
/// over the rows with objects.
void collect_upper_walls(const Ctx& x, const Plane& pl, const PlaneAxes& axes, float sin_wall, SegmentBuffers& ws) {
    ws.stack_walls.clear();
    for_cut_pixels(x, pl, ws, [&](std::size_t p, int l, float h) {
        if (h <= ws.stack_cut[static_cast<std::size_t>(l)] || !faces_sideways(x, pl, p, sin_wall)) return;
        const Eigen::Vector2d q = axes(x.c, p);
        ws.stack_walls.push_back({l, static_cast<float>(q.x()), static_cast<float>(q.y())});
    });
}

/// Per segment, a map of where its upper object's walls stand (ws.stack_walls) in
/// ws.wall_maps, its cells in ws.wall_cells. Cost: two passes over the walls.
void draw_wall_maps(SegmentBuffers& ws, int n) {
    // The walls' box on the plane per segment, then its cells.
    const float big = std::numeric_limits<float>::max();
    std::vector<std::array<float, 4>>& box = ws.wall_box;  // u0, v0, u1, v1
    box.assign(static_cast<std::size_t>(n) + 1, {big, big, -big, -big});
    for (const SegmentBuffers::WallPoint& w : ws.stack_walls) {
        std::array<float, 4>& b = box[static_cast<std::size_t>(w.segment)];
        b = {std::min(b[0], w.u), std::min(b[1], w.v), std::max(b[2], w.u), std::max(b[3], w.v)};
    }
    ws.wall_maps.assign(static_cast<std::size_t>(n) + 1, {});
    std::size_t cells = 0;
    for (int l = 1; l <= n; ++l) {
        const std::array<float, 4>& b = box[static_cast<std::size_t>(l)];
        if (b[2] < b[0]) continue;  // no walls
        const int cols = static_cast<int>((b[2] - b[0]) / kWallCellM) + 1;
        const int rows = static_cast<int>((b[3] - b[1]) / kWallCellM) + 1;
        if (cols > kMaxWallCells || rows > kMaxWallCells) continue;
        ws.wall_maps[static_cast<std::size_t>(l)] = {b[0], b[1], cols, rows, cells};
        cells += static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
    }
    ws.wall_cells.assign(cells, 0);
    for (const SegmentBuffers::WallPoint& w : ws.stack_walls) {
        const SegmentBuffers::WallMap& m = ws.wall_maps[static_cast<std::size_t>(w.segment)];
        if (m.cols == 0) continue;
        const auto cu = static_cast<std::size_t>((w.u - m.u0) / kWallCellM);
        const auto cv = static_cast<std::size_t>((w.v - m.v0) / kWallCellM);
        ws.wall_cells[m.at + cv * static_cast<std::size_t>(m.cols) + cu] = 1;
    }
}

/// Whether point q of segment l (on the plane) stands where its upper object's walls stand:
/// in a cell of its map or a neighbour. Cost: nine lookups.
bool under_upper_walls(const SegmentBuffers& ws, int l, const Eigen::Vector2d& q) {
    const SegmentBuffers::WallMap& m = ws.wall_maps[static_cast<std::size_t>(l)];
    if (m.cols == 0) return false;
    const int cu = static_cast<int>(std::floor((static_cast<float>(q.x()) - m.u0) / kWallCellM));
    const int cv = static_cast<int>(std::floor((static_cast<float>(q.y()) - m.v0) / kWallCellM));
    const std::uint8_t* cells = ws.wall_cells.data() + m.at;
    for (int v = std::max(cv - 1, 0); v <= std::min(cv + 1, m.rows - 1); ++v)
        for (int u = std::max(cu - 1, 0); u <= std::min(cu + 1, m.cols - 1); ++u)
            if (cells[v * m.cols + u]) return true;
    return false;
}

/// Where a pixel of a cut segment goes: above the cut, to the upper object (its walls,
/// kUpperWall, or the rest, kUpper); below it, to the lower object, but for the walls that
/// stand under the upper object's walls (kUnderUpperWalls), which go up when their colour
/// or the lower layer's place says so (keep_walls). The first three index ws.wall_colour.
enum Piece : int { kUpperWall = 0, kUnderUpperWalls = 1, kLower = 2, kUpper = 3 };

/// The piece of pixel p (height h) of cut segment l. Cost: O(1).
Piece piece_of(const Ctx& x, const Plane& pl, const PlaneAxes& axes, float sin_wall, const SegmentBuffers& ws,
               std::size_t p, int l, float h) {
    const bool wall = faces_sideways(x, pl, p, sin_wall);
    if (h > ws.stack_cut[static_cast<std::size_t>(l)]) return wall ? kUpperWall : kUpper;
    return wall && under_upper_walls(ws, l, axes(x.c, p)) ? kUnderUpperWalls : kLower;
}

/// The distance between the mean chromaticities of two sums (r, g, b, count).
double colour_distance(const std::array<double, 4>& a, const std::array<double, 4>& b) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
        const double d = a[static_cast<std::size_t>(i)] / a[3] - b[static_cast<std::size_t>(i)] / b[3];
        d2 += d * d;
    }
    return std::sqrt(d2);
}

/// The lower layer's top shows on one side of the upper object when this share of its
/// upward pixels or more lies beyond one side of the upper object's footprint: a taller box
/// beside a lower one shows the lower one's top beside one of its sides, in front, behind or
/// to one side; a box resting on a larger one shows the larger one's top round two sides or
/// more (on a corner, flush with two of its edges: beside one side and behind). Chosen on
/// the generated tune seeds (docs/ABLATION.md, "Stacks").
constexpr double kOneSideShare = 0.9;

/// Per cut segment whose footprint is wanted (colour cannot tell: keep_walls), into
/// ws.footprints: its upper object's (above the cut) mean point on the support plane, its
/// axes (from its walls' normals on the plane: a box's sides face along two axes, four
/// times their angle one direction), its extent along them, and its lower layer's upward
/// pixels (the layer's three bins, kCutOverLowerM under the cut) counted beyond each of the
/// footprint's four sides (the side the pixel lies beyond relative to the footprint's
/// half-extent that way). Cost: one pass over the rows with objects to gather those
/// segments' pixels, then three over them.
void measure_footprints(const Ctx& x, const Plane& pl, const PlaneAxes& axes, float sin_wall, SegmentBuffers& ws) {
    using Footprint = SegmentBuffers::Footprint;
    ws.footprint_px.clear();
    for_segment_pixels(x, ws, [&](std::size_t p, int l) {
        if (ws.footprints[static_cast<std::size_t>(l)].wanted) ws.footprint_px.push_back(static_cast<int>(p));
    });
    // Calls visit(p, l, h) for each gathered pixel p, l its segment, h its height over the
    // support.
    auto for_gathered = [&](auto&& visit) {
        for (const int q : ws.footprint_px) {
            const auto p = static_cast<std::size_t>(q);
            const auto l = static_cast<std::size_t>(ws.label[p]);
            visit(p, l, pl.height(x.c.x[p], x.c.y[p], x.c.z[p]));
        }
    };
    for_gathered([&](std::size_t p, std::size_t l, float h) {
        if (h <= ws.stack_cut[l]) return;
        Footprint& f = ws.footprints[l];
        const Eigen::Vector2d q = axes(x.c, p);
        f.su += q.x(), f.sv += q.y(), f.n += 1;
        if (!faces_sideways(x, pl, p, sin_wall)) return;
        // The normal on the plane, (a, b) = r (cos t, sin t): cos 4t and sin 4t from
        // (a + ib)^4 / r^4, without trigonometry.
        const Eigen::Vector3d nrm(x.n.nx[p], x.n.ny[p], x.n.nz[p]);
        const double a = nrm.dot(axes.e1), b = nrm.dot(axes.e2), r2 = a * a + b * b;
        if (!(r2 > 0)) return;
        const double c2 = (a * a - b * b) / r2, s2 = 2 * a * b / r2;
        f.c4 += c2 * c2 - s2 * s2, f.s4 += 2 * c2 * s2, f.walls += 1;
    });
    for (Footprint& f : ws.footprints) {
        if (f.n == 0) continue;
        const double t = std::atan2(f.s4, f.c4) / 4;
        f.axis[0][0] = std::cos(t), f.axis[0][1] = std::sin(t);
        f.axis[1][0] = -std::sin(t), f.axis[1][1] = std::cos(t);
    }
    auto along = [&](const Footprint& f, std::size_t p, double (&s)[2]) {
        const Eigen::Vector2d q = axes(x.c, p);
        const double du = q.x() - f.su / f.n, dv = q.y() - f.sv / f.n;
        for (int k = 0; k < 2; ++k) s[k] = du * f.axis[k][0] + dv * f.axis[k][1];
    };
    for_gathered([&](std::size_t p, std::size_t l, float h) {
        Footprint& f = ws.footprints[l];
        if (f.n == 0 || h <= ws.stack_cut[l]) return;
        double s[2];
        along(f, p, s);
        for (int k = 0; k < 2; ++k) f.lo[k] = std::min(f.lo[k], s[k]), f.hi[k] = std::max(f.hi[k], s[k]);
    });
    const float cos_up = std::cos(kUprightDeg * kDegToRad);
    constexpr float kHalfLayer = 1.5f * kLayerBinM;
    for_gathered([&](std::size_t p, std::size_t l, float h) {
        Footprint& f = ws.footprints[l];
        const float layer = ws.stack_cut[l] - kCutOverLowerM;
        if (f.n == 0 || std::fabs(h - layer) > kHalfLayer || !faces_up(x, pl, p, cos_up)) return;
        double s[2], reach[2];
        along(f, p, s);
        for (int k = 0; k < 2; ++k) {
            const double half = s[k] > 0 ? f.hi[k] : -f.lo[k];
            reach[k] = half > 0 ? std::fabs(s[k]) / half : 0.0;
        }
        const int k = reach[0] >= reach[1] ? 0 : 1;
        ++f.side[2 * k + (s[k] > 0 ? 0 : 1)];
    });
}

/// Whether segment l's upper object is box-like, its walls facing along two axes
/// (kBoxAxes), and its lower layer shows beyond one side of it only (kOneSideShare).
bool lower_top_beside(const SegmentBuffers& ws, int l) {
    const SegmentBuffers::Footprint& f = ws.footprints[static_cast<std::size_t>(l)];
    const int total = f.side[0] + f.side[1] + f.side[2] + f.side[3];
    const int most = std::max(std::max(f.side[0], f.side[1]), std::max(f.side[2], f.side[3]));
    return f.walls > 0 && std::hypot(f.c4, f.s4) >= kBoxAxes * f.walls && total > 0 && most >= kOneSideShare * total;
}

/// Two boxes of two heights flush side by side are one segment with two layers too, and the
/// cut halves the taller one: its walls run on below the cut, under its walls above it.
/// Geometry alone cannot tell them from a box resting flush on the edge of a larger one
/// (whose walls below the cut are the lower box's). Colour decides first: they go up when
/// their mean chromaticity lies colour.min_distance or more from the rest of the lower piece
/// (another material) and nearer the upper object's walls. Where all three are within
/// colour.min_distance of each other (one material: colour cannot tell), they go up when the
/// upper object is box-like and the lower layer's top shows beyond one side of it only
/// (lower_top_beside): a box resting on a larger one shows the larger one's top beyond two
/// sides or more. Otherwise the pair stays cut by height. Clears the map of every segment
/// whose walls stay. Cost: one pass over the rows with objects, and measure_footprints' where
/// a segment asks it (none on most frames).
void keep_walls(const Ctx& x, const Plane& pl, const PlaneAxes& axes, float sin_wall, SegmentBuffers& ws, int n) {
    ws.wall_colour.assign(static_cast<std::size_t>(n + 1) * 3, {0.0, 0.0, 0.0, 0.0});
    for_cut_pixels(x, pl, ws, [&](std::size_t p, int l, float h) {
        const Piece k = piece_of(x, pl, axes, sin_wall, ws, p, l, h);
        if (k == kUpper) return;
        // Chromaticity, 255 rgb / (r + g + b + 30): light falling at other angles on two faces
        // of one object scales their colour and leaves it. The colour cue's adds 10 to each
        // channel first, pulling dark pixels towards grey; this rule was measured without
        // that (with it, report scene 01051's printed pair falls under colour.min_distance:
        // docs/ABLATION.md).
        const double r = x.c.r[p], g = x.c.g[p], b = x.c.b[p], scale = 255.0 / (r + g + b + 30.0);
        std::array<double, 4>& sum = ws.wall_colour[3 * static_cast<std::size_t>(l) + static_cast<std::size_t>(k)];
        sum[0] += r * scale;
        sum[1] += g * scale;
        sum[2] += b * scale;
        sum[3] += 1;
    });
    // Colour first; the footprints only of the segments whose three pieces are one material.
    ws.footprints.assign(static_cast<std::size_t>(n) + 1, SegmentBuffers::Footprint{});
    bool ask = false;
    for (int l = 1; l <= n; ++l) {
        const std::array<double, 4>* sums = ws.wall_colour.data() + 3 * static_cast<std::size_t>(l);
        if (sums[kUpperWall][3] == 0 || sums[kUnderUpperWalls][3] == 0 || sums[kLower][3] == 0) continue;
        const double min_distance = x.prm.colour.min_distance;
        const double to_lower = colour_distance(sums[kUnderUpperWalls], sums[kLower]);
        const double to_upper = colour_distance(sums[kUnderUpperWalls], sums[kUpperWall]);
        SegmentBuffers::Footprint& f = ws.footprints[static_cast<std::size_t>(l)];
        f.up_by_colour = to_lower >= min_distance && to_upper < to_lower;
        f.wanted = to_lower < min_distance && to_upper < min_distance &&
                   colour_distance(sums[kUpperWall], sums[kLower]) < min_distance;
        ask = ask || f.wanted;
    }
    if (ask) measure_footprints(x, pl, axes, sin_wall, ws);
    for (int l = 1; l <= n; ++l) {
        const SegmentBuffers::Footprint& f = ws.footprints[static_cast<std::size_t>(l)];
        const bool up = f.up_by_colour || (f.wanted && lower_top_beside(ws, l));
        if (!up) ws.wall_maps[static_cast<std::size_t>(l)].cols = 0;  // no map: the walls stay
    }
}

/// Cuts each layered segment: its upper object (above the cut, and the walls under its walls
/// where a map is kept) takes a new label n + 1, n + 2, ... in segment order. Returns the
/// cuts. Cost: one pass over the rows with objects.
int cut_layers(const Ctx& x, const Plane& pl, const PlaneAxes& axes, float sin_wall, SegmentBuffers& ws, int n) {
    ws.remap.assign(static_cast<std::size_t>(n) + 1, 0);
    int next = n;
    for (int l = 1; l <= n; ++l)
        if (ws.stack_cut[static_cast<std::size_t>(l)] >= 0) ws.remap[static_cast<std::size_t>(l)] = ++next;
    for_cut_pixels(x, pl, ws, [&](std::size_t p, int l, float h) {
        if (piece_of(x, pl, axes, sin_wall, ws, p, l, h) != kLower) ws.label[p] = ws.remap[static_cast<std::size_t>(l)];
    });
    return next - n;
}

/// The stack rule over segments 1..n (with gaps): the layers of each segment's upward faces,
/// where to cut, which walls go up with the upper object (hybrid), then the cuts. Returns
/// the cuts.
int split_by_height(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
    if (x.prm.stacks.min_step_m <= 0) return 0;
    const int bins = static_cast<int>(std::ceil(x.prm.scope.max_height_m / kLayerBinM));
    count_layers(x, pl, ws, n, bins);
    if (find_cuts(x, ws, n, bins) == 0) return 0;
    // Which walls below the cut stand under the upper object's walls, and whether their
    // colour sends them up (hybrid only: without colour, a cut by height).
    const PlaneAxes axes(pl);
    const float sin_wall = std::sin(kUprightDeg * kDegToRad);
    if (x.prm.segmenter == Segmenter::Hybrid && x.c.has_color) {
        collect_upper_walls(x, pl, axes, sin_wall, ws);
        draw_wall_maps(ws, n);
        keep_walls(x, pl, axes, sin_wall, ws, n);
    } else {
        ws.wall_maps.assign(static_cast<std::size_t>(n) + 1, {});  // no maps
    }
    return cut_layers(x, pl, axes, sin_wall, ws, n);
}

}  // namespace

void split_stacks(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    stats.stacks.splits = split_by_height(x, *support, ws, n);
    n += stats.stacks.splits;
}

}  // namespace wul3d::detail
