// The neck rule of segment_objects (docs/DESIGN.md, "Necks"): a bottle's neck and cap, which
// the crease cuts part from its shoulder, stand on the axis of its round body: they are the
// bottle.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>

#include <Eigen/Core>

#include "../circle_fit.hpp"
#include "internal.hpp"

namespace wul3d::detail {
namespace {

/// Two segments touch in view where a pixel of one has one of the other to its right or
/// below, or past up to kReachPx unlabelled pixels (a depth edge's mixed points: a cap seen
/// from above stands in front of the shoulder round it), at kMinContacts such pairs or more.
constexpr int kReachPx = 3;
constexpr int kMinContacts = 6;
/// The upper segment stands on the lower: its mean height over the support at least the
/// lower's top less this (a neck rises from the shoulder's top).
constexpr float kAboveM = 0.01f;
/// The lower segment is round about an upright axis: its walls (pixels whose normal does not
/// face up: a body's sides, a shoulder) are kMinWalls or more and not a box's faces (kBoxAxes,
/// internal.hpp). The normals of a small box, smoothed across its edges, can pass that; then
/// only an upper object as narrow as a neck joins it. The axis is the centre of circles
/// fitted to the walls' points on the plane, one per layer of height (fit_coaxial, as the
/// round test's).
constexpr int kMinWalls = 20;
/// A neck: nine tenths of the upper segment's points within this of the axis on the
/// support plane. A bottle's neck and cap are 1-3 cm across in radius; a box or a can
/// standing on a can is wider.
constexpr double kNeckRadiusM = 0.03;
constexpr double kNeckShare = 0.9;
/// Or a shoulder with its neck: where the crease cuts the body below its shoulder (bottles in
/// the generated piles and floors, most under active stereo), the upper segment is wider
/// than a neck, but it lies within the body's radius, and its top, its points within this of
/// its highest, is the neck and cap (kNeckShare of them within kNeckRadiusM). A can or a box
/// on a can is as wide at its top as below. The generated caps are 1.5 cm tall; 1 and 3 cm
/// scored alike on the tune seeds (docs/ABLATION.md, "Necks").
constexpr float kNeckTopM = 0.02f;

/// The pairs of segments that touch in view into ws.neck_pairs: (lower label << 32 | higher,
/// contacts), sorted by pair, a pair's contacts over one entry or more; and the runs of one
/// label, row by row, into ws.neck_runs (label, first pixel, length). Cost: branch-free passes
/// over the rows with labels for where the label changes, then the runs and contacts from
/// those.
void find_contacts(const Ctx& x, SegmentBuffers& ws) {
    const int W = x.W, H = x.H;
    const int* const label = ws.label.data();
    auto& pairs = ws.neck_pairs;
    pairs.clear();
    auto touch = [&](int a, int b) {  // neighbouring contacts are mostly of one pair: counted in place
        const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
        const std::uint64_t key = (lo << 32) | hi;
        if (!pairs.empty() && pairs.back().first == key)
            ++pairs.back().second;
        else
            pairs.push_back({key, 1});
    };
    auto& outline = ws.neck_outline;
    outline.resize(2 * static_cast<std::size_t>(W));
    std::uint8_t* const edge = outline.data();
    std::uint8_t* const ends = edge + W;  // 1 where a run of one label ends
    auto& runs = ws.neck_runs;
    runs.clear();
    for (int v = 0; v < H; ++v) {
        const int* const row = label + static_cast<std::ptrdiff_t>(v) * W;
        if (!row_has_label(row, 0, W)) continue;
        // The row's runs of one label (0 left out), found where the label changes.
        for (int u = 0; u + 1 < W; ++u) ends[u] = static_cast<std::uint8_t>(row[u + 1] != row[u]);
        ends[W - 1] = 1;
        for (int u0 = 0; u0 < W;) {
            const auto* end = static_cast<const std::uint8_t*>(std::memchr(ends + u0, 1, static_cast<std::size_t>(W - u0)));
            const int u1 = static_cast<int>(end - ends) + 1;
            if (row[u0]) runs.push_back({row[u0], v * W + u0, u1 - u0});
            u0 = u1;
        }
        // The contacts start from the outline's pixels.
        const int* const below = v + 1 < H ? row + W : row;
        mark_outline_row(row, below, W, edge);
        for (int u = 0;; ++u) {
            const void* next = std::memchr(edge + u, 1, static_cast<std::size_t>(W - u));
            if (!next) break;
            u = static_cast<int>(static_cast<const std::uint8_t*>(next) - edge);
            const int a = row[u];
            if (u + 1 < W && row[u + 1] != a)
                for (int k = 1; k <= kReachPx + 1 && u + k < W; ++k)  // right
                    if (const int b = row[u + k]) {
                        if (b != a) touch(a, b);
                        break;
                    }
            if (v + 1 < H && below[u] != a)
                for (int k = 1; k <= kReachPx + 1 && v + k < H; ++k)  // down
                    if (const int b = row[static_cast<std::ptrdiff_t>(k) * W + u]) {
                        if (b != a) touch(a, b);
                        break;
                    }
        }
    }
    std::sort(pairs.begin(), pairs.end());
}

/// A segment's walls' normals laid on the support plane, for round_body: their directions at
/// four times their angle (c4, s4), the walls counted.
using WallSums = SegmentBuffers::NeckWallSums;
using Wall = SegmentBuffers::NeckWall;

/// The support plane's frame for add_wall, in floats: its axes (PlaneAxes) and its normal.
struct PlaneFrame {
    float e1[3], e2[3], up[3];
    explicit PlaneFrame(const Plane& pl) {
        const PlaneAxes axes(pl);
        for (int i = 0; i < 3; ++i) e1[i] = static_cast<float>(axes.e1[i]), e2[i] = static_cast<float>(axes.e2[i]);
        up[0] = pl.nx, up[1] = pl.ny, up[2] = pl.nz;
    }
    /// Point p's coordinates on the plane (PlaneAxes').
    std::array<double, 2> at(const OrganizedCloud& c, std::size_t p) const {
        return {c.x[p] * e1[0] + c.y[p] * e1[1] + c.z[p] * e1[2], c.x[p] * e2[0] + c.y[p] * e2[1] + c.z[p] * e2[2]};
    }
};

/// Adds pixel p of the segment in `slot` to `s` and to `walls` when it is a wall, a normal
/// that does not face up (a body's side, a shoulder): the angle doubled twice of the normal
/// laid on the plane, (nu, nv), from its squared length without a square root; the point on
/// the plane and its layer of height (round_layer). Cost: about 40 operations.
void add_wall(const Ctx& x, const Plane& pl, const PlaneFrame& f, float cos_up, std::size_t p, int slot, WallSums& s,
              std::vector<Wall>& walls) {
    if (!x.c.valid[p] || !x.n.valid[p]) return;
    const float nx = x.n.nx[p], ny = x.n.ny[p], nz = x.n.nz[p];
    if (nx * f.up[0] + ny * f.up[1] + nz * f.up[2] >= cos_up) return;  // faces up
    const float nu = nx * f.e1[0] + ny * f.e1[1] + nz * f.e1[2], nv = nx * f.e2[0] + ny * f.e2[1] + nz * f.e2[2];
    const double len2 = static_cast<double>(nu) * nu + static_cast<double>(nv) * nv;
    if (!(len2 > 0.1)) return;  // facing down: no direction on the plane
    const double inv = 1.0 / len2;
    const double cos2 = (nu * nu - nv * nv) * inv, sin2 = 2 * nu * nv * inv;  // the angle doubled
    s.c4 += cos2 * cos2 - sin2 * sin2;
    s.s4 += 2 * sin2 * cos2;
    ++s.walls;
    const auto [Pu, Pv] = f.at(x.c, p);
    walls.push_back({slot, round_layer(pl.height(x.c.x[p], x.c.y[p], x.c.z[p])), Pu, Pv});
}

/// Whether a segment's walls (WallSums) may be a round body: kMinWalls or more, their
/// directions not agreeing as a box's faces do (under kBoxAxes). O(1).
bool round_body(const WallSums& s) {
    return s.walls >= kMinWalls && std::hypot(s.c4, s.s4) < kBoxAxes * s.walls;
}

/// The upright axis of a round body on the support plane (PlaneAxes coordinates): the centre
/// of circles about one axis fitted to its walls' points, one per layer (fit_coaxial). The
/// normals' lines, which a solid of revolution's all cross at its axis, were the first way:
/// a noisy camera's normals, estimated over a wider radius, bend towards the camera at a
/// body's outline, and under active stereo they met 2-3 cm off a bottle's axis, where its
/// walls' points scatter either side of their circles. Its radius: the widest layer's (the
/// body, below its shoulder). Nothing where the fit fails. Cost: fit_coaxial's passes over the
/// walls.
std::optional<SegmentBuffers::BodyAxis> body_axis(const Wall* walls, std::size_t n) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();  // the fit's origin, for its conditioning
    for (std::size_t i = 0; i < n; ++i) mean += Eigen::Vector2d(walls[i].u, walls[i].v);
    mean /= static_cast<double>(n);
    const auto fit = fit_coaxial<kRoundLayers>([&](auto&& visit) {
        for (std::size_t i = 0; i < n; ++i)
            visit(Eigen::Vector2d(walls[i].u - mean.x(), walls[i].v - mean.y()), walls[i].layer);
    });
    if (!fit.fitted) return std::nullopt;
    SegmentBuffers::BodyAxis axis{fit.centre + mean, 0.0};
    for (int l = 0; l < kRoundLayers; ++l)
        if (fit.count[l] > 0) axis.radius = std::max(axis.radius, fit.radius[l]);
    return axis;
}

/// Calls visit(s, p, run) for each run label[p, p + run) of ws.neck_runs whose segment's slot
/// s is wanted (s >= 0, wanted[s] != 0). Cost: one pass over the runs.
template <class Visit>
void for_wanted_runs(const SegmentBuffers& ws, const int* slot, const std::uint8_t* wanted, Visit&& visit) {
    for (const auto& r : ws.neck_runs) {
        const int s = slot[r[0]];
        if (s >= 0 && wanted[s]) visit(s, static_cast<std::size_t>(r[1]), static_cast<std::size_t>(r[2]));
    }
}

/// The axis of each round body among the segments of ws.neck_segments whose slot is wanted:
/// their walls (add_wall) grouped by slot (a counting sort: raster order kept within a
/// slot), then, where round_body holds, body_axis. Out: ws.neck_axes per slot (none where
/// not round or not fitted). Cost: one pass over the wanted segments' runs, two over their walls, and
/// fit_coaxial's passes over each round one's.
void find_body_axes(const Ctx& x, const Plane& pl, SegmentBuffers& ws, const std::uint8_t* wanted) {
    const std::size_t S = ws.neck_segments.size();
    auto& sums = ws.neck_wall_sums;
    sums.assign(S, WallSums{});
    const PlaneFrame frame(pl);
    const float cos_up = std::cos(kUprightDeg * kDegToRad);
    auto& walls = ws.neck_walls;
    walls.clear();
    for_wanted_runs(ws, ws.neck_slot.data(), wanted, [&](int s, std::size_t p, std::size_t run) {
        auto& sum = sums[static_cast<std::size_t>(s)];
        for (std::size_t q = p; q < p + run; ++q) add_wall(x, pl, frame, cos_up, q, s, sum, walls);
    });
    auto& first_wall = ws.neck_first;  // reused: the upper segments' first pairs come later
    first_wall.assign(S + 1, 0);
    for (const Wall& w : walls) ++first_wall[static_cast<std::size_t>(w.slot) + 1];
    for (std::size_t s = 0; s < S; ++s) first_wall[s + 1] += first_wall[s];
    auto& by_slot = ws.neck_walls_by_slot;
    by_slot.resize(walls.size());
    for (const Wall& w : walls) by_slot[static_cast<std::size_t>(first_wall[static_cast<std::size_t>(w.slot)]++)] = w;
    auto& axes = ws.neck_axes;
    axes.assign(S, std::nullopt);
    for (std::size_t s = 0, begin = 0; s < S; begin = static_cast<std::size_t>(first_wall[s++])) {
        const auto end = static_cast<std::size_t>(first_wall[s]);  // placing moved it to the slot's end
        if (end == begin || !round_body(sums[s])) continue;
        axes[s] = body_axis(by_slot.data() + begin, end - begin);
    }
}

/// The neck rule's decisions (join_necks) on the segments of ws.neck_segments, slot s for
/// segment ws.neck_segments[s] (ws.neck_slot), and the pairs of ws.neck_touching in slots.
/// Returns the joins made in ws.parent.
int join_standing_necks(const Ctx& x, const Plane& pl, SegmentBuffers& ws) {
    const auto& segments = ws.neck_segments;
    const int* const slot = ws.neck_slot.data();
    const std::size_t S = segments.size();
    auto& wanted = ws.neck_wanted;
    wanted.assign(S, 1);
    // Each segment's heights over the support: summed, counted, greatest.
    auto& heights = ws.neck_heights;
    heights.assign(S, {0.0f, 0.0f, -1e9f});
    for_wanted_runs(ws, slot, wanted.data(), [&](int s, std::size_t p, std::size_t run) {
        // The run's, in four lanes (the additions do not wait on each other).
        float sum[4] = {0, 0, 0, 0}, count[4] = {0, 0, 0, 0}, top[4] = {-1e9f, -1e9f, -1e9f, -1e9f};
        for (std::size_t q = p; q < p + run; ++q) {
            const float z = pl.height(x.c.x[q], x.c.y[q], x.c.z[q]);
            const bool in = x.c.valid[q] != 0;
            const std::size_t k = q & 3;
            sum[k] += in ? z : 0.0f, count[k] += in ? 1.0f : 0.0f, top[k] = std::max(top[k], in ? z : -1e9f);
        }
        auto& h = heights[static_cast<std::size_t>(s)];
        h[0] += (sum[0] + sum[1]) + (sum[2] + sum[3]), h[1] += (count[0] + count[1]) + (count[2] + count[3]);
        h[2] = std::max({h[2], top[0], top[1], top[2], top[3]});
    });
    auto mean = [&](int s) {
        const auto& h = heights[static_cast<std::size_t>(s)];
        return h[1] > 0 ? h[0] / h[1] : 0.0f;
    };
    // The pairs whose upper segment stands on the lower.
    auto& stand = ws.neck_stand;
    stand.clear();
    for (const auto& [lo, hi] : ws.neck_touching) {
        const int a = mean(lo) > mean(hi) ? lo : hi, b = a == lo ? hi : lo;
        if (!(heights[static_cast<std::size_t>(a)][1] > 0 && mean(a) >= heights[static_cast<std::size_t>(b)][2] - kAboveM))
            continue;
        SegmentBuffers::NeckPair& pair = stand.emplace_back();
        pair.upper = a, pair.lower = b;
    }
    if (stand.empty()) return 0;
    // The lower segments' axes; the pairs whose lower one has none dropped.
    std::fill(wanted.begin(), wanted.end(), 0);
    for (const auto& pair : stand) wanted[static_cast<std::size_t>(pair.lower)] = 1;
    find_body_axes(x, pl, ws, wanted.data());
    const auto& axes = ws.neck_axes;
    std::size_t kept = 0;
    for (auto pair : stand) {
        const auto& axis = axes[static_cast<std::size_t>(pair.lower)];
        if (!axis) continue;
        pair.body = *axis;
        stand[kept++] = pair;
    }
    stand.resize(kept);
    if (stand.empty()) return 0;
    const PlaneFrame frame(pl);
    // The upper segments' points near the axis of each lower one they stand on, within its
    // radius, and at their own top, in one pass: the pairs sorted by upper segment, first[s]
    // its first pair.
    std::sort(stand.begin(), stand.end(),
              [](const auto& p, const auto& q) { return p.upper != q.upper ? p.upper < q.upper : p.lower < q.lower; });
    auto& first = ws.neck_first;
    first.assign(S, -1);
    std::fill(wanted.begin(), wanted.end(), 0);
    for (std::size_t k = stand.size(); k-- > 0;) {
        first[static_cast<std::size_t>(stand[k].upper)] = static_cast<int>(k);
        wanted[static_cast<std::size_t>(stand[k].upper)] = 1;
    }
    for_wanted_runs(ws, slot, wanted.data(), [&](int s, std::size_t p, std::size_t run) {
        for (std::size_t q = p; q < p + run; ++q) {
            if (!x.c.valid[q]) continue;
            const auto [u, v] = frame.at(x.c, q);
            const bool at_top =
                pl.height(x.c.x[q], x.c.y[q], x.c.z[q]) > heights[static_cast<std::size_t>(s)][2] - kNeckTopM;
            for (auto k = static_cast<std::size_t>(first[static_cast<std::size_t>(s)]); k < stand.size() && stand[k].upper == s;
                 ++k) {
                auto& pair = stand[k];
                const double du = u - pair.body.centre.x(), dv = v - pair.body.centre.y(), d2 = du * du + dv * dv;
                const bool near = d2 <= kNeckRadiusM * kNeckRadiusM;
                ++pair.points;
                pair.near += near;
                pair.in_body += d2 <= pair.body.radius * pair.body.radius;
                pair.top += at_top;
                pair.top_near += at_top && near;
            }
        }
    });
    // A neck and cap, or a shoulder within the body whose top is the neck (kNeckTopM). The
    // highest point is at the top, so `top` is at least 1 wherever `points` is.
    const auto neck = [](const SegmentBuffers::NeckPair& pair) {
        return pair.points > 0 &&
               (pair.near >= kNeckShare * pair.points ||
                (pair.in_body >= kNeckShare * pair.points && pair.top_near >= kNeckShare * pair.top));
    };
    int joins = 0;
    for (const auto& pair : stand)
        if (neck(pair) &&
            join_sets(ws.parent, segments[static_cast<std::size_t>(pair.upper)], segments[static_cast<std::size_t>(pair.lower)]))
            ++joins;
    return joins;
}

}  // namespace

/// The neck rule: of two segments that touch in view, the upper, standing on the lower
/// (kAboveM), joins it when the lower is round about an upright axis (round_body, body_axis) and
/// kNeckShare of the upper's points lie within kNeckRadiusM of that axis, or within the body's
/// radius with kNeckShare of its top's (kNeckTopM) within kNeckRadiusM. In: ws.label (1..n
/// with gaps). Out: ws.label with the pairs joined; stats.necks.joins. Cost: find_contacts'
/// passes over the rows with labels; where some pairs touch, three passes over the runs of
/// their segments (heights, the lower ones' walls, the upper ones' points near the axes), and
/// fit_coaxial's over each round lower one's walls.
void join_necks(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    if (!support || n < 2) return;
    find_contacts(x, ws);
    // The pairs that touch at kMinContacts pairs or more, their segments given slots (-1 for
    // the others, and again for these once done: no pass over every label number).
    auto& slot = ws.neck_slot;
    if (slot.size() < static_cast<std::size_t>(n) + 1) slot.resize(static_cast<std::size_t>(n) + 1, -1);
    auto& segments = ws.neck_segments;
    segments.clear();
    auto slot_of = [&](int l) {
        int& s = slot[static_cast<std::size_t>(l)];
        if (s < 0) {
            s = static_cast<int>(segments.size());
            segments.push_back(l);
        }
        return s;
    };
    auto& touching = ws.neck_touching;
    touching.clear();
    const auto& pairs = ws.neck_pairs;
    for (std::size_t i = 0; i < pairs.size();) {
        std::size_t j = i;
        int contacts = 0;
        for (; j < pairs.size() && pairs[j].first == pairs[i].first; ++j) contacts += pairs[j].second;
        if (contacts >= kMinContacts)
            touching.push_back({slot_of(static_cast<int>(pairs[i].first >> 32)),
                                slot_of(static_cast<int>(pairs[i].first & 0xffffffffu))});
        i = j;
    }
    int joins = 0;
    if (!touching.empty()) {
        reset_sets(ws.parent, n);
        joins = join_standing_necks(x, *support, ws);
    }
    for (const int l : segments) slot[static_cast<std::size_t>(l)] = -1;
    if (joins > 0) relabel_to_roots(ws);
    stats.necks.joins = joins;
}

}  // namespace wul3d::detail
