// The rules of segment_objects that go beyond components and the convexity merge: the
// container rule, floor gaps, the colour cue and the support's scope (docs/DESIGN.md,
// "Objects", 2). Each is a short driver over named phases; every phase states what it reads,
// what it writes and what it costs. Scratch lives in SegmentWorkspace: once its vectors have
// grown to a frame's size, a phase allocates nothing.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include "../circle_fit.hpp"
#include "internal.hpp"
#include "wul3d/clustering.hpp"  // ClusterParams: the colour cue's alpha and delta

namespace wul3d::detail {

// ---- containers ----------------------------------------------------------------------------

namespace {

constexpr std::uint64_t kPairMask = ~std::uint64_t{15};  ///< BoundaryStep::key's segment pair

/// One pass: the boundary pairs of two segments into ws.steps, keyed (lo, hi, depth step,
/// lo is nearer) with the nearer pixel, sorted by key; each segment's first and last row into
/// ws.rim_rows. In: ws.label (0..n). Cost: O(pixels), then a sort of the boundary pairs.
void collect_boundary_steps(const Ctx& x, SegmentWorkspace& ws, int n) {
    const int W = x.W, H = x.H;
    const auto& label = ws.label;
    ws.steps.clear();
    ws.rim_rows.assign(2 * (static_cast<std::size_t>(n) + 1), -1);
    for (int v = 0; v < H; ++v) {
        // Only labelled pixels add anything.
        if (!row_has_label(label.data() + static_cast<std::size_t>(v) * W, 0, W)) continue;
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            const int a = label[p];
            if (a == 0) continue;
            int* rows = ws.rim_rows.data() + 2 * static_cast<std::size_t>(a);
            if (rows[0] < 0) rows[0] = v;
            rows[1] = v;
            const std::size_t qs[2] = {u + 1 < W ? p + 1 : p, v + 1 < H ? p + static_cast<std::size_t>(W) : p};
            for (std::size_t q : qs) {
                const int b = label[q];
                if (b == 0 || b == a) continue;
                const bool step = !x.connected(p, q);
                const bool p_nearer = x.c.z[p] < x.c.z[q];
                const bool lo_nearer = (a < b) == p_nearer;
                const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 34) |
                                          (static_cast<std::uint64_t>(std::max(a, b)) << 4) |
                                          (std::uint64_t{step} << 1) | std::uint64_t{lo_nearer};
                ws.steps.push_back({key, static_cast<std::uint32_t>(p_nearer ? p : q)});
            }
        }
    }
    std::sort(ws.steps.begin(), ws.steps.end(),
              [](const BoundaryStep& l, const BoundaryStep& r) { return l.key < r.key; });
}

/// The points `for_pixels` visits (it calls its argument with each pixel) on the support
/// plane, less `mean` (for the circle fit's conditioning): what fit_circle takes.
template <class ForPixels>
auto on_plane(const Ctx& x, const PlaneAxes& plane_xy, const Eigen::Vector2d& mean, ForPixels& for_pixels) {
    return [&x, &plane_xy, &mean, &for_pixels](auto&& visit) {
        for_pixels([&](std::size_t p) { visit(Eigen::Vector2d(plane_xy(x.c, p) - mean)); });
    };
}

/// The RMS distance from a fitted circle that still counts as on it, for points at mean
/// depth z: rim_max_residual_m to 1 m (it was set on `osd_mosd`, whose objects lie 0.57-0.82
/// m away), then growing as z^2, as the sensor's depth noise does (a structured-light
/// sensor's depth step is z^2 / (f b)), which scatters the points along the rays. Only the
/// rims use it: the round test keeps rim_max_residual_m, since a looser bound there let more
/// segments pass as round, which the colour cue then leaves unsplit (docs/ABLATION.md,
/// "Circles").
double circle_tolerance(const SegmentParams& prm, double z) {
    return prm.rim_max_residual_m * std::max(1.0, z * z);
}

/// The front's extent across the line of sight, in radii of a circle fitted with the far
/// rim, at least: 1 (a container's outer wall spans 2, or less where something hides it).
/// 1.5 lost half the gain on the generated tune seeds (docs/ABLATION.md, "The far rim").
constexpr double kFarRimMinWidth = 1.0;

/// The front segment's extent on the plane across the line of sight through `centre` (the
/// camera lies at the plane's origin). Cost: one pass over the front's rows.
double front_width(const Ctx& x, const PlaneAxes& plane_xy, const SegmentWorkspace& ws, int front,
                   const Eigen::Vector2d& centre) {
    const Eigen::Vector2d across = Eigen::Vector2d(centre.y(), -centre.x()).normalized();
    const int r0 = ws.rim_rows[2 * static_cast<std::size_t>(front)];
    const int r1 = ws.rim_rows[2 * static_cast<std::size_t>(front) + 1];
    double lo = std::numeric_limits<double>::max(), hi = -lo;
    for (std::size_t p = static_cast<std::size_t>(r0) * x.W; p < static_cast<std::size_t>(r1 + 1) * x.W; ++p) {
        if (ws.label[p] != front) continue;
        const double t = plane_xy(x.c, p).dot(across);
        lo = std::min(lo, t);
        hi = std::max(hi, t);
    }
    return hi - lo;
}

/// A rim's circle on the support plane: its centre, radius and mean height over the plane.
struct RimCircle {
    Eigen::Vector2d centre;
    double radius = 0, height = 0;
};

/// A circle fitted to the rim points `for_rim` visits (it calls its argument with each
/// pixel), on the plane (fit_circle), when the points lie on it (circle_tolerance at their
/// depth) and span enough of it (rim_min_arc); nothing otherwise. Cost: three passes and
/// fit_circle's six over the points.
template <class ForRim>
std::optional<RimCircle> rim_circle(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, ForRim&& for_rim) {
    double m = 0, height = 0, z = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for_rim([&](std::size_t p) {
        ++m;
        mean += plane_xy(x.c, p);
        height += pl.height(x.c.x[p], x.c.y[p], x.c.z[p]);
        z += x.c.z[p];
    });
    if (m < 3) return std::nullopt;
    mean /= m;
    height /= m;
    z /= m;
    const Circle fit = fit_circle(on_plane(x, plane_xy, mean, for_rim));
    const Eigen::Vector2d centre = fit.centre;
    const double R = fit.radius;
    if (!std::isfinite(R)) return std::nullopt;
    // Geometric residual, and the widest chord: the farthest rim pixel from the mean, then
    // the farthest from that one.
    double res = 0, far_d = -1, chord = 0;
    Eigen::Vector2d far = Eigen::Vector2d::Zero();
    for_rim([&](std::size_t p) {
        const Eigen::Vector2d d = plane_xy(x.c, p) - mean;
        const double r = (d - centre).norm() - R;
        res += r * r;
        if (d.norm() > far_d) {
            far_d = d.norm();
            far = d;
        }
    });
    for_rim([&](std::size_t p) { chord = std::max(chord, (plane_xy(x.c, p) - mean - far).norm()); });
    if (std::sqrt(res / m) > circle_tolerance(x.prm, z) || chord < x.prm.rim_min_arc * 2 * R) return std::nullopt;
    return RimCircle{centre + mean, R, height};
}

/// The back segment's pixels on its far rim, into ws.rim_far_px: within rim_height_tol_m of
/// `rim_height` over the plane, and nearer across a depth step than a 4-neighbour that
/// belongs to neither segment (or has no depth). A container's inside, seen over its front
/// wall, ends there at the far half of the rim. Cost: one pass over the back's rows.
void collect_far_rim(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int front, int back, double rim_height) {
    const int W = x.W, H = x.H;
    const auto& label = ws.label;
    auto steps_to_farther = [&](std::size_t p, std::size_t q) {
        if (label[q] == back || label[q] == front) return false;
        const float zq = x.c.z[q];
        return !(zq > 0) || (zq > x.c.z[p] && !x.connected(p, q));
    };
    ws.rim_far_px.clear();
    const int v0 = ws.rim_rows[2 * static_cast<std::size_t>(back)], v1 = ws.rim_rows[2 * static_cast<std::size_t>(back) + 1];
    for (int v = std::max(v0, 0); v <= v1; ++v)
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (label[p] != back) continue;
            if (std::fabs(pl.height(x.c.x[p], x.c.y[p], x.c.z[p]) - rim_height) > x.prm.rim_height_tol_m) continue;
            const bool on_outline = (u > 0 && steps_to_farther(p, p - 1)) || (u + 1 < W && steps_to_farther(p, p + 1)) ||
                                    (v > 0 && steps_to_farther(p, p - W)) || (v + 1 < H && steps_to_farther(p, p + W));
            if (on_outline) ws.rim_far_px.push_back(static_cast<int>(p));
        }
}

/// The far rim's candidate (rim_far) for the pair (front, back), whose front edge
/// `for_edge` visits: a circle fitted to that edge and to the back's far rim
/// (collect_far_rim, at the edge's mean height). A small cup's front edge at --decimate 2
/// can be 6 pairs long, too short an arc to fit alone, or it fits a circle too small for the
/// inside; with the far half of the rim the circle spans the whole rim. Kept when
///  - the front spans a radius of it across the line of sight (kFarRimMinWidth): a
///    container's outer wall spans its diameter;
///  - the far rim alone fits a circle that agrees with it (rim_far_agree): it is the same
///    rim. This is what keeps an object behind a box out: its outline at the box's height
///    reaches "the rim" by how the far rim is chosen, but traces its own shape, not the
///    circle through the box's straight edge.
/// Cost: one pass over the back's rows and one over the front's; rim_circle's passes over
/// the edge and the far rim, twice. ws.rim_far_px keeps its capacity across frames.
template <class ForEdge>
std::optional<RimCircle> far_rim_circle(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentWorkspace& ws,
                                        ForEdge& for_edge, int front, int back) {
    double m = 0, rim_height = 0;
    for_edge([&](std::size_t p) {
        ++m;
        rim_height += pl.height(x.c.x[p], x.c.y[p], x.c.z[p]);
    });
    if (m < 3) return std::nullopt;
    collect_far_rim(x, pl, ws, front, back, rim_height / m);
    auto for_far = [&](auto&& visit) {
        for (const int p : ws.rim_far_px) visit(static_cast<std::size_t>(p));
    };
    auto for_rim = [&](auto&& visit) {
        for_edge(visit);
        for_far(visit);
    };
    const auto both = rim_circle(x, pl, plane_xy, for_rim);
    if (!both || front_width(x, plane_xy, ws, front, both->centre) < kFarRimMinWidth * both->radius)
        return std::nullopt;
    const auto far = rim_circle(x, pl, plane_xy, for_far);
    const double agree = x.prm.rim_far_agree * both->radius;
    if (!far || std::fabs(far->radius - both->radius) > agree || (far->centre - both->centre).norm() > agree)
        return std::nullopt;
    return both;
}

/// The rim of the pair (front, back) along the steps ws.steps[i0, i1): a circle fitted to
/// the front segment's edge there (the nearer pixels of the depth steps that lie in
/// `front`), and with rim_far a second one through the back's far rim too
/// (far_rim_circle). Appends each that passes to ws.rim_fits as {front, back, centre (2),
/// radius, rim height}; the inside test then judges each. Cost: rim_circle's passes over
/// the pair's boundary pairs, and far_rim_circle's; no allocation but the appends.
void fit_rim(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentWorkspace& ws,
             std::size_t i0, std::size_t i1, int front, int back) {
    auto for_edge = [&](auto&& visit) {
        for (std::size_t j = i0; j < i1; ++j)
            if (((ws.steps[j].key >> 1) & 1) && ws.label[ws.steps[j].near] == front) visit(ws.steps[j].near);
    };
    auto keep = [&](const RimCircle& c) {
        ws.rim_fits.push_back({static_cast<double>(front), static_cast<double>(back), c.centre.x(), c.centre.y(),
                               c.radius, c.height});
    };
    if (const auto edge = rim_circle(x, pl, plane_xy, for_edge)) keep(*edge);
    if (!x.prm.rim_far) return;
    if (const auto both = far_rim_circle(x, pl, plane_xy, ws, for_edge, front, back)) keep(*both);
}

/// Candidates: segment pairs that meet (almost) only across depth steps; the front is the
/// segment nearer along them, and its edge must be a circular arc (fit_rim). In: ws.steps,
/// sorted. Out: ws.rim_fits. Cost: one pass over the boundary pairs, then fit_rim's passes
/// over each candidate's.
void find_rims(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentWorkspace& ws) {
    const SegmentParams& prm = x.prm;
    ws.rim_fits.clear();
    for (std::size_t i = 0; i < ws.steps.size();) {
        const std::size_t i0 = i;
        const std::uint64_t k = ws.steps[i].key & kPairMask;
        int steps = 0, lo_nearer = 0;
        for (; i < ws.steps.size() && (ws.steps[i].key & kPairMask) == k; ++i) {
            if (!((ws.steps[i].key >> 1) & 1)) continue;
            ++steps;
            lo_nearer += static_cast<int>(ws.steps[i].key & 1);
        }
        const int pairs = static_cast<int>(i - i0);
        if (steps < prm.rim_min_boundary || 5 * steps < 4 * pairs) continue;
        const int lo = static_cast<int>(k >> 34), hi = static_cast<int>((k >> 4) & ((1u << 30) - 1));
        if (2 * lo_nearer == steps) continue;  // neither is in front
        const int front = 2 * lo_nearer > steps ? lo : hi, back = front == lo ? hi : lo;
        fit_rim(x, pl, plane_xy, ws, i0, i, front, back);
    }
}

/// The back segments' feet: per candidate the back's pixels, those inside the circle and the
/// back's top, into ws.rim_back. A back segment may sit behind several fronts: ws.remap holds
/// each segment's first candidate and ws.rim_next links the rest. Cost: one pass over the
/// rows the back segments span, O(candidates) per back pixel (one in practice).
void measure_insides(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentWorkspace& ws, int n) {
    const int W = x.W, H = x.H;
    const int C = static_cast<int>(ws.rim_fits.size());
    ws.remap.assign(static_cast<std::size_t>(n) + 1, -1);
    ws.rim_next.assign(static_cast<std::size_t>(C), -1);
    int v0 = H, v1 = -1;
    for (int c = C - 1; c >= 0; --c) {
        const int back = static_cast<int>(ws.rim_fits[static_cast<std::size_t>(c)][1]);
        int& head = ws.remap[static_cast<std::size_t>(back)];
        ws.rim_next[static_cast<std::size_t>(c)] = head;
        head = c;
        v0 = std::min(v0, ws.rim_rows[2 * static_cast<std::size_t>(back)]);
        v1 = std::max(v1, ws.rim_rows[2 * static_cast<std::size_t>(back) + 1]);
    }
    ws.rim_back.assign(static_cast<std::size_t>(C), {0, 0, -1e9});
    for (std::size_t p = static_cast<std::size_t>(v0) * W; p < static_cast<std::size_t>(v1 + 1) * W; ++p) {
        const int l = ws.label[p];
        if (l == 0) continue;
        int c = ws.remap[static_cast<std::size_t>(l)];
        if (c < 0) continue;
        const Eigen::Vector2d f = plane_xy(x.c, p);
        const double h = pl.height(x.c.x[p], x.c.y[p], x.c.z[p]);
        for (; c >= 0; c = ws.rim_next[static_cast<std::size_t>(c)]) {
            const auto& fit = ws.rim_fits[static_cast<std::size_t>(c)];
            auto& b = ws.rim_back[static_cast<std::size_t>(c)];
            b[0] += 1;
            b[1] += (f - Eigen::Vector2d(fit[2], fit[3])).norm() <= 1.1 * fit[4] + 0.01;
            b[2] = std::max(b[2], h);
        }
    }
}

/// Joins each candidate's back to its front when the back's feet lie inside the circle and
/// its top reaches the rim, and relabels. Returns the joins. Cost: O(candidates), then one
/// pass over the pixels when anything joined.
int join_insides(const Ctx& x, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    reset_sets(ws.parent, n);
    int joins = 0;
    for (std::size_t c = 0; c < ws.rim_fits.size(); ++c) {
        const auto& fit = ws.rim_fits[c];
        const auto& b = ws.rim_back[c];
        if (b[1] < prm.rim_inside_share * b[0] || std::fabs(b[2] - fit[5]) > prm.rim_height_tol_m) continue;
        joins += join_sets(ws.parent, static_cast<int>(fit[0]), static_cast<int>(fit[1]));
    }
    if (joins > 0) relabel_to_roots(ws);
    return joins;
}

/// Islands: connected components (4-neighbours, depth-continuous) of object pixels that no
/// segment reached, of min_seed_points or more, become segments n + 1, ... for the rim
/// test. At `--decimate 2` every pixel of a small cup's inside, or of a bowl's outer wall
/// seen at a steep angle, can lie within a crease step of a crease, so the region seeds no
/// segment, and the rim's depth step keeps reattachment out of it. ws.cut (the seeds, spent
/// by now) holds the pixels still open. Returns the islands added. Cost: one pass over the
/// pixels that vectorizes, a memchr for each island's first pixel, and a search over the
/// unreached object pixels.
int add_islands(const Ctx& x, SegmentWorkspace& ws, int n) {
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    std::uint8_t* const open = ws.cut.data();
    const int* const label = ws.label.data();
    const std::uint8_t* const cls = x.cls.data();
    for (std::size_t p = 0; p < N; ++p)
        open[p] = static_cast<std::uint8_t>((label[p] == 0) & (cls[p] == kPlaneObject));
    int added = 0;
    for (std::size_t seed = 0; seed < N; ++seed) {
        const void* const next = std::memchr(open + seed, 1, N - seed);
        if (!next) break;
        seed = static_cast<std::size_t>(static_cast<const std::uint8_t*>(next) - open);
        open[seed] = 0;
        const int size = flood_region(
            x, ws.queue, static_cast<int>(seed), [&](std::size_t q) { return open[q] != 0; },
            [&](std::size_t q) { open[q] = 0; });
        if (size < x.prm.min_seed_points) continue;
        const int id = n + (++added);
        for (int i = 0; i < size; ++i) ws.label[static_cast<std::size_t>(ws.queue[i])] = id;
    }
    return added;
}

/// The rim test over segments 1..n (with gaps): candidates, their circles, their insides,
/// the joins. Returns the joins. Cost: as join_containers', less the islands.
int join_rims(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    if (n < 2) return 0;
    collect_boundary_steps(x, ws, n);
    const PlaneAxes plane_xy(pl);
    find_rims(x, pl, plane_xy, ws);
    if (ws.rim_fits.empty()) return 0;
    measure_insides(x, pl, plane_xy, ws, n);
    return join_insides(x, ws, n);
}

}  // namespace

/// The container rule (SegmentParams, "Containers"): a segment seen over another's circular,
/// level edge across a depth step, lying inside that circle and reaching up to it, is the
/// other's inside (a bowl's or a cup's) and joins it. With rim_islands the regions no
/// segment reached take part as segments n + 1, ... (add_islands), and after the joins those
/// that joined no segment are lone objects or unlabelled again (keep_lone_islands): the root
/// of a joined set is its smallest label, so what is left above n joined only islands. In:
/// ws.label (1..n with gaps). Out: ws.label with the insides joined, within 1..n +
/// labels_added. Cost: one pass over the pixels and a sort of the boundary pairs; then per
/// candidate a few passes over its boundary, and one over the rows of the candidates'
/// insides; with islands, add_islands and keep_lone_islands.
ContainerJoins join_containers(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    if (x.prm.rim_min_boundary <= 0 || n < 1) return {};
    const int islands = x.prm.rim_islands ? add_islands(x, ws, n) : 0;
    ContainerJoins out;
    out.joins = join_rims(x, pl, ws, n + islands);
    if (islands > 0) {
        out.islands_kept = keep_lone_islands(x, ws, n, islands);
        out.labels_added = out.islands_kept > 0 ? islands : 0;
    }
    return out;
}

/// Why each test: an island that continues into a segment with continuous depth is a piece
/// of it that no crease test let grow (not an object); one nearer than a segment it meets
/// lies in depth between two surfaces, as the mixed pixels along an occluding edge and the
/// broken pieces of one surface do (osd_mosd test59 at --decimate 2: a 77-point piece of a
/// box's top, nearer than one neighbour and farther than the other); one narrower than
/// island_min_width_px is such a band of mixed pixels (a RealSense frame, image_0003: 1.7
/// points wide along the drill's top edge). What is left is seen past every segment it
/// meets: a bowl's inside whose rim fitted no circle, an object's top between nearer ones.
int keep_lone_islands(const Ctx& x, SegmentWorkspace& ws, int n, int islands) {
    int* const label = ws.label.data();
    const int W = x.W, H = x.H;
    const int min_width = x.prm.island_min_width_px;
    // Per island: its pixels, its outline pairs (to anything but itself; none past the frame)
    // and whether it is still lone.
    ws.island_pixels.assign(static_cast<std::size_t>(islands) + 1, 0);
    ws.island_outline.assign(static_cast<std::size_t>(islands) + 1, 0);
    ws.island_lone.assign(static_cast<std::size_t>(islands) + 1, 1);
    int first_row = H, last_row = -1;
    for (int v = 0; v < H; ++v) {
        const int* const row = label + static_cast<std::size_t>(v) * W;
        if (!row_has_label_over(row, 0, W, n)) continue;  // most rows hold no island
        first_row = std::min(first_row, v);
        last_row = v;
        if (min_width <= 0) continue;  // no island kept (none counts pixels): only the rows
        for (int u = 0; u < W; ++u) {
            const int l = row[u];
            if (l <= n) continue;
            const std::size_t i = static_cast<std::size_t>(l - n);
            ++ws.island_pixels[i];
            const int p = v * W + u;
            for (const int q : four_neighbours(p, u, v, W, H)) {
                if (q < 0 || label[q] == l) continue;  // past the frame, or itself
                ++ws.island_outline[i];
                const std::size_t a = static_cast<std::size_t>(p), b = static_cast<std::size_t>(q);
                if (label[q] > 0 && label[q] <= n && (x.connected(a, b) || x.c.z[a] <= x.c.z[b]))
                    ws.island_lone[i] = 0;
            }
        }
    }
    // Width 2 * pixels / outline pairs: a band w wide and L long has w L pixels and about 2 L
    // outline pairs. One smaller than an object is not kept: it could not be one, and its
    // pixels stay free for the floor gaps (fill_container_gaps).
    int kept = 0;
    for (std::size_t i = 1; i <= static_cast<std::size_t>(islands); ++i) {
        const long long pixels = ws.island_pixels[i];
        ws.island_lone[i] &= static_cast<std::uint8_t>(
            pixels >= x.prm.min_points && 2 * pixels >= static_cast<long long>(min_width) * ws.island_outline[i]);
        kept += ws.island_lone[i];
    }
    const std::uint8_t* const lone = ws.island_lone.data();
    for (int v = first_row; v <= last_row; ++v) {
        int* const row = label + static_cast<std::size_t>(v) * W;
        for (int u = 0; u < W; ++u)
            if (row[u] > n && !lone[row[u] - n]) row[u] = 0;
    }
    return kept;
}

// ---- floor gaps ----------------------------------------------------------------------------

/// Gaps in a container's floor (SegmentParams::gap_max_px): each patch of unlabelled pixels
/// beside a labelled kPlaneInside pixel is explored breadth-first; when it is enclosed by one
/// segment (no image border, no other segment) and small, its points join that segment.
/// Only the inside pixels are visited to find the patches, and the marks are cleared behind
/// each search: the cost follows the insides, not the image. Returns the points filled.
std::size_t fill_container_gaps(const Ctx& x, SegmentWorkspace& ws) {
    const int max_px = x.prm.gap_max_px;
    if (max_px <= 0) return 0;
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    ws.gap_seen.resize(N, 0);  // all 0 between calls
    std::uint8_t* const seen = ws.gap_seen.data();
    std::size_t filled = 0;
    // Explores the patch of unlabelled pixels holding `seed`; fills it when enclosed and small.
    auto explore = [&](std::size_t seed) {
        int head = 0, tail = 0, owner = 0;
        bool enclosed = true;
        ws.queue[tail++] = static_cast<int>(seed);
        seen[seed] = 1;
        while (head < tail && enclosed) {
            const int p = ws.queue[head++];
            const int pu = p % W, pv = p / W;
            if (pu == 0 || pv == 0 || pu == W - 1 || pv == H - 1) enclosed = false;
            for (int q : four_neighbours(p, pu, pv, W, H)) {
                if (q < 0) continue;
                const int l = ws.label[static_cast<std::size_t>(q)];
                if (l) {
                    if (owner == 0) owner = l;
                    else if (l != owner) enclosed = false;
                } else if (!seen[q]) {
                    seen[q] = 1;
                    ws.queue[tail++] = q;
                }
            }
            if (tail > max_px) enclosed = false;  // too large: the rest stays unexplored
        }
        for (int i = 0; i < tail; ++i) {
            const auto p = static_cast<std::size_t>(ws.queue[i]);
            // A patch that failed stays marked until the end (explored once); a point-less
            // pixel stays out of every object.
            if (!enclosed || owner == 0 || !x.c.valid[p]) continue;
            ws.label[p] = owner;
            seen[p] = 0;
            ++filled;
        }
        if (enclosed && owner != 0)
            for (int i = 0; i < tail; ++i) seen[static_cast<std::size_t>(ws.queue[i])] = 0;
        return tail;
    };
    ws.gap_touched.clear();  // seeds explored, to clear their marks at the end
    for (int v = 0; v < H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        const std::uint8_t* const cls = x.cls.data() + row;
        for (const std::uint8_t* c = std::find(cls, cls + W, kPlaneInside); c != cls + W;
             c = std::find(c + 1, cls + W, kPlaneInside)) {
            const int u = static_cast<int>(c - cls);
            const std::size_t p = row + static_cast<std::size_t>(u);
            if (!ws.label[p]) continue;
            const std::size_t nb[4] = {u > 0 ? p - 1 : p, u + 1 < W ? p + 1 : p, v > 0 ? p - W : p,
                                       v + 1 < H ? p + W : p};
            for (std::size_t q : nb) {
                if (q == p || ws.label[q] || seen[q]) continue;
                const int visited = explore(q);
                if (seen[q]) ws.gap_touched.insert(ws.gap_touched.end(), ws.queue.begin(), ws.queue.begin() + visited);
            }
        }
    }
    for (int p : ws.gap_touched) seen[static_cast<std::size_t>(p)] = 0;
    return filled;
}

// ---- the colour cue ------------------------------------------------------------------------

namespace {

/// Counting sort of the segments' pixels by segment (background left out): segment l's
/// pixels are ws.order[ws.offsets[l], ws.offsets[l + 1]), in raster order. Per fixed band of
/// rows in parallel: counts per band, then each band writes from its own start (segment by
/// segment, bands in order). In: ws.label (0..n). Cost: two parallel passes over the pixels,
/// O(8 n) between them.
void sort_pixels_by_segment(const Ctx& x, SegmentWorkspace& ws, int n) {
    const int W = x.W;
    constexpr int kSortBands = 8;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    ws.remap.assign(kSortBands * L, 0);  // per band: counts, then write positions
    const int H = x.H;
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kSortBands; ++band) {
        int* const count = ws.remap.data() + static_cast<std::size_t>(band) * L;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kSortBands) * W;
        for (std::size_t p = static_cast<std::size_t>(H * band / kSortBands) * W; p < p1; ++p)
            ++count[static_cast<std::size_t>(ws.label[p])];
    }
    ws.offsets.assign(L + 1, 0);  // segment l's pixels: order[offsets[l], offsets[l + 1])
    int position = 0;
    for (std::size_t l = 1; l < L; ++l) {
        ws.offsets[l] = position;
        for (int band = 0; band < kSortBands; ++band) {
            int& slot = ws.remap[static_cast<std::size_t>(band) * L + l];
            const int count = slot;
            slot = position;
            position += count;
        }
    }
    ws.offsets[L] = position;
    ws.order.resize(static_cast<std::size_t>(position));
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kSortBands; ++band) {
        int* const next = ws.remap.data() + static_cast<std::size_t>(band) * L;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kSortBands) * W;
        for (std::size_t p = static_cast<std::size_t>(H * band / kSortBands) * W; p < p1; ++p) {
            const int l = ws.label[p];
            if (l) ws.order[static_cast<std::size_t>(next[l]++)] = static_cast<int>(p);
        }
    }
}

int segment_size(const SegmentWorkspace& ws, int l) {
    return ws.offsets[static_cast<std::size_t>(l) + 1] - ws.offsets[static_cast<std::size_t>(l)];
}

/// One plane, for the brightness step (judge_split): the normals a crease step either side
/// of the boundary within this angle. The smallest that gains on the generated tune seeds
/// (3 degrees left out their boxes' faces), well under the smooth test's 15, which took in
/// a white bowl's lit and shaded sides on the RealSense frames (docs/ABLATION.md).
constexpr float kStepPlaneDeg = 5.0f;

/// The 2-means features of the segments' pixels, one plane each in segment order so that
/// every pass over a segment reads contiguous memory.
struct ColourFeatures {
    const float* f[6];  ///< delta x, y, z, then alpha times the chromaticity r, g, b
    int first;          ///< the position in ws.order of every plane's element 0
};

/// Gathers ColourFeatures into ws.feature, scaled by the paper's delta and alpha (eq. 4) so
/// that a squared distance is a sum. Only the segments' pixels (order positions first..last)
/// are gathered: plane q holds position i at f[q][i - first], sized by the object pixels, not
/// the image. In: ws.order, ws.offsets. Cost: one parallel pass over the object pixels.
ColourFeatures gather_features(const Ctx& x, const ClusterParams& cp, SegmentWorkspace& ws, int n) {
    const int first = ws.offsets[1], last = ws.offsets[static_cast<std::size_t>(n) + 1];
    const std::size_t M = static_cast<std::size_t>(last - first);
    ws.feature.resize(6 * M);
    float* f[6];
    for (int q = 0; q < 6; ++q) f[q] = ws.feature.data() + static_cast<std::size_t>(q) * M;
    // The colour term is the chromaticity (chromaticity()): light falling on two faces of
    // one box at other angles scales their colour and leaves it, so the two parts are two
    // materials, not a lit face and a shaded one.
#pragma omp parallel for schedule(static)
    for (int i = first; i < last; ++i) {
        const std::size_t p = static_cast<std::size_t>(ws.order[static_cast<std::size_t>(i)]);
        f[0][i - first] = cp.delta * x.c.x[p];
        f[1][i - first] = cp.delta * x.c.y[p];
        f[2][i - first] = cp.delta * x.c.z[p];
        float c[3];
        chromaticity(x.c, p, c);
        f[3][i - first] = cp.alpha * c[0];
        f[4][i - first] = cp.alpha * c[1];
        f[5][i - first] = cp.alpha * c[2];
    }
    return {{f[0], f[1], f[2], f[3], f[4], f[5]}, first};
}

/// The segments of this round (ws.to_try) large enough to split (2 x min_points), largest
/// first, into ws.by_size: tried in parallel, no thread is left with a big one at the end.
/// Cost: O(n log n).
void order_by_size(const SegmentParams& prm, SegmentWorkspace& ws, int n) {
    ws.by_size.clear();
    for (int l = 1; l <= n; ++l)
        if (ws.to_try[static_cast<std::size_t>(l)] && segment_size(ws, l) >= 2 * prm.min_points)
            ws.by_size.push_back(l);
    std::stable_sort(ws.by_size.begin(), ws.by_size.end(),
                     [&](int a, int b) { return segment_size(ws, a) > segment_size(ws, b); });
}

/// The position among the m pixels of one segment's planes `f` farthest in colour from
/// (r, g, b); the first on ties.
int farthest_colour(const float* const* f, int m, double r, double g, double b) {
    const float *const cr = f[3], *const cg = f[4], *const cb = f[5];
    int best = 0;
    double bd = -1;
    for (int i = 0; i < m; ++i) {
        const double dr = cr[i] - r, dg = cg[i] - g, db = cb[i] - b;
        const double d = dr * dr + dg * dg + db * db;
        if (d > bd) { bd = d; best = i; }
    }
    return best;
}

/// The principal axis of a 3 x 3 covariance (unit length) and its variance, by power
/// iteration from the axis of the largest diagonal entry. Cost: O(1).
double principal_axis(const double (&cov)[3][3], double (&e)[3]) {
    e[0] = e[1] = e[2] = 0;
    e[cov[0][0] >= cov[1][1] && cov[0][0] >= cov[2][2] ? 0 : cov[1][1] >= cov[2][2] ? 1 : 2] = 1;
    double variance = 0;
    for (int it = 0; it < 20; ++it) {
        double next[3];
        for (int a = 0; a < 3; ++a) next[a] = cov[a][0] * e[0] + cov[a][1] * e[1] + cov[a][2] * e[2];
        const double len = std::sqrt(next[0] * next[0] + next[1] * next[1] + next[2] * next[2]);
        if (!(len > 0)) break;
        for (int a = 0; a < 3; ++a) e[a] = next[a] / len;
        variance = len;
    }
    return variance;
}

/// 2-means seeds for one segment (planes `f`, m pixels) in `cen`: the mean colour plus and
/// minus one standard deviation along the colours' principal axis, both at the mean
/// position. Seeds at the farthest colours (the pixel farthest from the mean, then the one
/// farthest from it) let a few outlying pixels, the feet a segment took from the table or
/// a line of mixed colour at an edge, pull 2-means into a part of their own, which the
/// share test then rejects; they move the principal axis little (generated tune seeds
/// 88.5 -> 89.8 Overlap F, docs/ABLATION.md). False, and no seeds, when the colour spread
/// cannot hold parts `min_spread` apart (feature units). `total`: the planes' sums (in
/// double, pixel order), which two_means needs too. Cost: three passes over the segment's
/// planes.
bool seed_centres(const float* const* f, int m, float min_spread, float (&cen)[2][6], double (&total)[6]) {
    double mean[6];
    for (int q = 0; q < 6; ++q) {
        total[q] = 0;
        for (int i = 0; i < m; ++i) total[q] += f[q][i];
        mean[q] = total[q] / m;
    }
    const float *const cr = f[3], *const cg = f[4], *const cb = f[5];
    // The parts' mean colours lie among the segment's colours, so they are at most the
    // segment's colour diameter apart, at most twice the farthest colour from the mean:
    // below the minimum distance no split can be kept.
    {
        const int a0 = farthest_colour(f, m, mean[3], mean[4], mean[5]);
        const double dr = cr[a0] - mean[3], dg = cg[a0] - mean[4], db = cb[a0] - mean[5];
        if (2 * std::sqrt(dr * dr + dg * dg + db * db) < min_spread) return false;
    }
    double cov[3][3] = {};
    for (int i = 0; i < m; ++i) {
        const double d[3] = {cr[i] - mean[3], cg[i] - mean[4], cb[i] - mean[5]};
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) cov[a][b] += d[a] * d[b];
    }
    double e[3];
    const double sd = std::sqrt(principal_axis(cov, e) / m);
    for (int q = 0; q < 6; ++q) {
        const double step = q < 3 ? 0.0 : sd * e[q - 3];
        cen[0][q] = static_cast<float>(mean[q] + step);
        cen[1][q] = static_cast<float>(mean[q] - step);
    }
    return true;
}

/// 2-means (eq. 4 squared) on one segment's feature planes, m pixels, from the centres `cen`:
/// side[i] gets pixel i's part, `cen` the parts' means and `count` their sizes (the last
/// iteration's; a part may be empty). `total`: the planes' sums (seed_centres'); part 0's
/// sums are the totals minus part 1's. Cost: at most 6 passes over the 6 planes, stopping
/// when no pixel changes part; float sums per block of 1024, added up in double; no
/// allocation.
void two_means(const float* const* planes, int m, const double (&total)[6], std::uint8_t* side, float (&cen)[2][6],
               int (&count)[2]) {
    const float* f[6];  // a local copy: the stores to `side` cannot alias it
    for (int q = 0; q < 6; ++q) f[q] = planes[q];
    for (int it = 0; it < 6; ++it) {
        // Nearer centre 1 than centre 0 (eq. 4 squared): |f - c1|^2 < |f - c0|^2, i.e.
        // 2 f . (c0 - c1) < |c0|^2 - |c1|^2, a linear test per pixel.
        float w[6], bias = 0;
        for (int q = 0; q < 6; ++q) {
            w[q] = 2.0f * (cen[0][q] - cen[1][q]);
            bias += cen[0][q] * cen[0][q] - cen[1][q] * cen[1][q];
        }
        double sum1[6] = {};
        int ones = 0, changed = 0;
        constexpr int kBlock = 1024;  // float partial sums per block, added up in double
        for (int i0 = 0; i0 < m; i0 += kBlock) {
            const int i1 = std::min(m, i0 + kBlock);
            float block[6] = {};
            int block_ones = 0, block_changed = 0;
            // The sides first, in a loop that vectorizes (one pixel per lane, each dot in
            // the same order); then the sums, pixel after pixel as before (a float sum
            // reordered would round otherwise).
            for (int i = i0; i < i1; ++i) {
                float dot = 0;
                for (int q = 0; q < 6; ++q) dot += w[q] * f[q][i];
                const std::uint8_t j = dot < bias;
                block_changed += j != side[i];
                side[i] = j;
                block_ones += j;
            }
            // Part 1's pixels only: a pixel of part 0 would add 0 * f = +-0, which changes
            // no sum (the features are finite).
            for (int i = i0; i < i1; ++i)
                if (side[i])
                    for (int q = 0; q < 6; ++q) block[q] += f[q][i];
            for (int q = 0; q < 6; ++q) sum1[q] += block[q];
            ones += block_ones;
            changed += block_changed;
        }
        count[1] = ones;
        count[0] = m - ones;
        if (count[0] == 0 || count[1] == 0) break;
        for (int q = 0; q < 6; ++q) {
            cen[1][q] = static_cast<float>(sum1[q] / count[1]);
            cen[0][q] = static_cast<float>((total[q] - sum1[q]) / count[0]);
        }
        if (it > 0 && changed == 0) break;  // converged: further iterations repeat this one
    }
}

/// Where the parts of a split segment meet.
struct SplitBoundary {
    int boundary = 0;       ///< 4-neighbour pairs inside the segment with different parts
    int with_normals = 0;   ///< ... with normals a crease step away on either side
    int smooth = 0;         ///< ... whose normals lie within color_max_crease_deg
    int on_plane = 0;       ///< ... of those, on one plane (kStepPlaneDeg)
    int steps[2] = {0, 0};  ///< ... of those, where part 0's side (steps[0]) or part 1's
                            ///< is color_min_step times brighter a crease step away
    int small_outline = 0;  ///< 4-neighbour pairs from the smaller part to anything else
};

/// Calls visit(q, du, dv) for each 4-neighbour q of pixel p to its right (du = 1) or below
/// (dv = 1) that lies in segment l in another part (ws.part): each boundary pair inside the
/// segment once. Cost: two lookups.
template <class Visit>
void for_part_boundary_pairs(const Ctx& x, const SegmentWorkspace& ws, int l, int p, Visit&& visit) {
    const int W = x.W, u = p % W, v = p / W;
    const std::uint8_t* const part = ws.part.data();
    if (u + 1 < W && ws.label[static_cast<std::size_t>(p) + 1] == l && part[p + 1] != part[p]) visit(p + 1, 1, 0);
    if (v + 1 < x.H && ws.label[static_cast<std::size_t>(p + W)] == l && part[p + W] != part[p]) visit(p + W, 0, 1);
}

/// The boundary between the parts of segment l (pixels px[0, m), parts in ws.part), its
/// brightness steps on one plane, and the smaller part's outline. Cost: one pass over the
/// segment's pixels and their neighbours.
SplitBoundary split_boundary(const Ctx& x, const SegmentWorkspace& ws, int l, const int* px, int m,
                             std::uint8_t small_part, float cos_crease) {
    const int W = x.W, s = x.prm.crease_step_px;
    const std::uint8_t* const part = ws.part.data();
    // One plane: within kStepPlaneDeg, and smooth whatever color_max_crease_deg says.
    const float cos_plane = std::max(std::cos(kStepPlaneDeg * kDegToRad), cos_crease);
    auto brightness = [&](int p) { return static_cast<float>(x.c.r[p] + x.c.g[p] + x.c.b[p]) + kDark; };
    SplitBoundary sb;
    for (int i = 0; i < m; ++i) {
        const int p = px[i];
        const int u = p % W, v = p / W;
        if (part[p] == small_part) {
            for (const int q : four_neighbours(p, u, v, W, x.H))
                sb.small_outline += q < 0 || ws.label[q] != l || part[q] != small_part;
        }
        for_part_boundary_pairs(x, ws, l, p, [&](int q, int du, int dv) {
            ++sb.boundary;
            const int pu = u - s * du, pv = v - s * dv;
            const int qu = u + du + s * du, qv = v + dv + s * dv;
            if (pu < 0 || pv < 0 || qu >= W || qv >= x.H) return;
            const int a = pv * W + pu, b = qv * W + qu;
            if (!x.n.valid[a] || !x.n.valid[b]) return;
            const float cos_ab = x.n.nx[a] * x.n.nx[b] + x.n.ny[a] * x.n.ny[b] + x.n.nz[a] * x.n.nz[b];
            sb.smooth += cos_ab >= cos_crease;
            ++sb.with_normals;
            // A step in brightness counts on one plane only (a lies on p's side, b on q's):
            // light falls alike there, while a curved surface turns from it (a bowl's lit
            // and shaded sides).
            if (cos_ab < cos_plane) return;
            ++sb.on_plane;
            const float ia = brightness(a), ib = brightness(b);
            sb.steps[part[p]] += ia >= x.prm.color_min_step * ib;
            sb.steps[part[q]] += ib >= x.prm.color_min_step * ia;
        });
    }
    return sb;
}

/// Whether the pixels px[0, m) of one segment stand round on the support pl: a quarter of
/// them or more are walls (normals within color_round_deg of the plane), the walls lie on
/// one upright circle (fit_circle on the plane, as the containers' rims: RMS within
/// rim_max_residual_m at any depth, spanning rim_min_arc of the diameter, radius up to
/// color_round_max_radius_m) and three quarters of them face within color_round_deg of its
/// radii. A can, a bottle or a cup is one solid of revolution; two objects flush in view
/// show flat faces. Cost: two passes and fit_circle's six over the m pixels.
bool stands_round(const Ctx& x, const PlaneAxes& plane_xy, const Plane& pl, const int* px, int m) {
    const SegmentParams& prm = x.prm;
    const float sin_wall = std::sin(prm.color_round_deg * kDegToRad);
    auto for_walls = [&](auto&& visit) {
        for (int i = 0; i < m; ++i) {
            const auto p = static_cast<std::size_t>(px[i]);
            if (faces_sideways(x, pl, p, sin_wall)) visit(p);
        }
    };
    double walls = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for_walls([&](std::size_t p) {
        ++walls;
        mean += plane_xy(x.c, p);
    });
    if (walls < 3 || 4 * walls < m) return false;
    mean /= walls;
    const Circle fit = fit_circle(on_plane(x, plane_xy, mean, for_walls));
    const Eigen::Vector2d centre = fit.centre;
    const double R = fit.radius;
    if (!std::isfinite(R) || R > prm.color_round_max_radius_m) return false;
    const double cos_radial = std::cos(prm.color_round_deg * kDegToRad);
    // Residual, the walls' extent (the diagonal of their box on the plane) and how many
    // face along a radius (either way: a cup's inside faces in).
    double res = 0, radial = 0;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for_walls([&](std::size_t p) {
        const Eigen::Vector2d d = plane_xy(x.c, p) - mean - centre;
        const double r = d.norm();
        res += (r - R) * (r - R);
        const Eigen::Vector3d nrm(x.n.nx[p], x.n.ny[p], x.n.nz[p]);
        const Eigen::Vector2d n2(nrm.dot(plane_xy.e1), nrm.dot(plane_xy.e2));  // the normal on the plane
        radial += std::fabs(n2.dot(d)) >= cos_radial * n2.norm() * r;
        lo = lo.cwiseMin(d);
        hi = hi.cwiseMax(d);
    });
    return std::sqrt(res / walls) <= prm.rim_max_residual_m && (hi - lo).norm() >= prm.rim_min_arc * 2 * R &&
           4 * radial >= 3 * walls;
}

/// Boundary pairs on one plane that a brightness step needs: as many as the convexity
/// merge tests.
constexpr int kMinStepPairs = 6;

/// What the colour cue's tests say of a split.
enum class Verdict {
    kKept,
    kTexture,  ///< the boundary runs round many pieces: the parts follow a texture
    kRejected,
};

/// The colour cue's tests (SegmentParams, "Colour cue") of a split of segment l: pixels
/// px[0, m), parts in ws.part, part sizes `count` and means `cen` (feature units). Cost: one
/// pass over the segment's pixels for the boundary; the round test's three more, on a
/// support, when every other test passed.
Verdict judge_split(const Ctx& x, const Plane* support, const PlaneAxes* plane_xy, const ClusterParams& cp,
                    float cos_crease, const SegmentWorkspace& ws, int l, const int* px, int m, const int (&count)[2],
                    const float (&cen)[2][6]) {
    const SegmentParams& prm = x.prm;
    const int small = std::min(count[0], count[1]);
    if (small < prm.min_points || static_cast<float>(small) < prm.color_min_share * static_cast<float>(m))
        return Verdict::kRejected;
    const float dr = (cen[0][3] - cen[1][3]) / cp.alpha, dg = (cen[0][4] - cen[1][4]) / cp.alpha,
                db = (cen[0][5] - cen[1][5]) / cp.alpha;
    const bool far_in_colour = std::sqrt(dr * dr + dg * dg + db * db) >= prm.color_min_distance;
    if (!far_in_colour && !(prm.color_min_step > 1)) return Verdict::kRejected;
    // Boundary: 4-neighbour pairs inside the segment with different parts; the normals a
    // crease step away on either side tell a smooth surface from a fold.
    const std::uint8_t small_part = count[0] < count[1] ? 0 : 1;
    const SplitBoundary sb = split_boundary(x, ws, l, px, m, small_part, cos_crease);
    // A contact between two objects is one side of the smaller one's outline, or, where the
    // larger one encloses it in view (a box lying on a box, seen from above), the whole
    // outline of a compact piece: 4 sqrt(pixels) for a square, 6 for a 6:1 rectangle. A
    // split along a texture (stripes, checks, print) runs round most of each of its many
    // pieces, far longer than either.
    const bool one_side = static_cast<float>(sb.boundary) <= prm.color_max_boundary * static_cast<float>(sb.small_outline);
    const bool compact = static_cast<double>(sb.boundary) <= prm.color_max_compact * std::sqrt(static_cast<double>(small));
    if (!one_side && !compact) return Verdict::kTexture;
    // Most of the boundary must cross a smooth surface (a few pairs near a box's corner
    // straddle its edge), or the parts must differ in chromaticity: light falling on two
    // faces of one box at other angles scales their colour, it does not turn it, so
    // across a fold (a flat box on another, flush boxes of two heights) only a change of
    // material turns the mean colour by color_min_hue_deg. Or, either way, a step in
    // brightness along the boundary where it crosses one plane: light falls alike on both
    // sides there, so only a change of material (two flush boxes of one hue, a light and a
    // dark one, which the chromaticity cannot tell apart) makes one side brighter, along
    // most of the crossing, in one direction. Most: half the smooth crossing or more lies on
    // one plane (a curved surface's does not: a white bowl's shaded floor, 6 of 52), and 70 %
    // of that steps (DESIGN.md, "The brightness step").
    const bool brightness_step = prm.color_min_step > 1 && sb.on_plane >= kMinStepPairs &&
                                 2 * sb.on_plane >= sb.smooth &&
                                 10 * std::max(sb.steps[0], sb.steps[1]) >= 7 * sb.on_plane;
    if (!far_in_colour && !brightness_step) return Verdict::kRejected;
    const bool across_smooth = sb.with_normals > 0 && 10 * sb.smooth >= 7 * sb.with_normals;
    if (!across_smooth && !brightness_step) {
        const float r0 = cen[0][3], g0 = cen[0][4], b0c = cen[0][5];
        const float r1 = cen[1][3], g1 = cen[1][4], b1c = cen[1][5];
        const float dot = r0 * r1 + g0 * g1 + b0c * b1c;
        const float norms = std::sqrt((r0 * r0 + g0 * g0 + b0c * b0c) * (r1 * r1 + g1 * g1 + b1c * b1c));
        if (!(norms > 0) || dot >= std::cos(prm.color_min_hue_deg * kDegToRad) * norms) return Verdict::kRejected;
    }
    // Last, as it is the rarest to fail: a round thing's colours are print.
    if (support && prm.color_round_deg > 0 && stands_round(x, *plane_xy, *support, px, m)) return Verdict::kRejected;
    return Verdict::kKept;
}

// ---- the colour cue's materials ------------------------------------------------------------
//
// 2-means follows a texture when one object of the segment is textured: stripes of two
// colours beside a plain box put the stripes in two parts and the box with one of them.
// More colours then: the texture's two, the plain one's, and one for the rest. Two colours
// whose contact is far longer than any two objects' (they interleave) are one material; the
// split is between the materials.

/// Colours per segment when 2-means followed a texture: a textured object's two, a plain
/// one's beside it, and one more for what fits none (mixed pixels along edges, a third
/// colour). Chosen on the generated tune seeds: 3, 4 and 5 colours scored 92.8, 93.1 and
/// 92.9 Overlap F, learnt from every pixel (docs/ABLATION.md, "Textures").
constexpr int kTextureColours = 4;

/// k-means learns the colours from at most this many pixels per colour (every stride-th
/// pixel), then gives every pixel its nearest once: FAISS's Clustering subsamples its
/// training set the same way (max_points_per_centroid, 256 by default).
constexpr int kSamplesPerColour = 256;

/// The centre nearest pixel i's features (eq. 4 squared): |f - c_k|^2 less |f|^2, i.e.
/// |c_k|^2 - 2 f . c_k, from `w` = 2 c_k and `bias` = |c_k|^2. Branch-free, so that a loop
/// over pixels vectorizes.
inline std::uint8_t nearest_colour(const float* const* f, int i, const float (&w)[kTextureColours][6],
                                   const float (&bias)[kTextureColours]) {
    std::uint8_t best = 0;
    float best_d = 0;
    for (int k = 0; k < kTextureColours; ++k) {
        float d = bias[k];
        for (int q = 0; q < 6; ++q) d -= w[k][q] * f[q][i];
        const bool nearer = k == 0 || d < best_d;
        best_d = nearer ? d : best_d;
        best = nearer ? static_cast<std::uint8_t>(k) : best;
    }
    return best;
}

/// k-means (eq. 4 squared, on the 2-means features `f` of the m pixels) with
/// kTextureColours centres, seeded at the two 2-means parts' means `two` and then, one by
/// one, at the colour farthest from the centres so far; learnt from every stride-th pixel
/// (at most kSamplesPerColour per colour, copied together). cluster[i] gets pixel i's
/// colour, `cen` and `count` the colours' means (of the samples) and sizes (of all pixels).
/// Cost: at most 8 passes over the samples (the nearest colours vectorized), then one over
/// the m pixels; 28 KB of stack, no allocation.
void texture_colours(const float* const* f, int m, const float (&two)[2][6], std::uint8_t* cluster,
                     float (&cen)[kTextureColours][6], int (&count)[kTextureColours]) {
    constexpr int K = kTextureColours, kMaxSamples = kSamplesPerColour * kTextureColours;
    const int stride = (m + kMaxSamples - 1) / kMaxSamples;
    float samples[6][kMaxSamples];
    std::uint8_t nearest[kMaxSamples];
    int n = 0;
    for (int i = 0; i < m; i += stride, ++n)
        for (int q = 0; q < 6; ++q) samples[q][n] = f[q][i];
    const float* const s[6] = {samples[0], samples[1], samples[2], samples[3], samples[4], samples[5]};
    auto colour_distance = [&](int j, const float* c) {
        float d = 0;
        for (int q = 3; q < 6; ++q) d += (s[q][j] - c[q]) * (s[q][j] - c[q]);
        return d;
    };
    for (int q = 0; q < 6; ++q) cen[0][q] = two[0][q], cen[1][q] = two[1][q];
    float nearest_d[kMaxSamples];  // each sample's colour distance to the nearest centre so far
    for (int j = 0; j < n; ++j) nearest_d[j] = std::min(colour_distance(j, cen[0]), colour_distance(j, cen[1]));
    for (int k = 2; k < K; ++k) {
        const int farthest = static_cast<int>(std::max_element(nearest_d, nearest_d + n) - nearest_d);
        for (int q = 0; q < 6; ++q) cen[k][q] = s[q][farthest];
        for (int j = 0; j < n; ++j) nearest_d[j] = std::min(nearest_d[j], colour_distance(j, cen[k]));
    }
    float w[K][6], bias[K];
    auto set_weights = [&] {
        for (int k = 0; k < K; ++k) {
            bias[k] = 0;
            for (int q = 0; q < 6; ++q) w[k][q] = 2 * cen[k][q], bias[k] += cen[k][q] * cen[k][q];
        }
    };
    for (int it = 0; it < 8; ++it) {
        set_weights();
        int changed = 0;
        for (int j = 0; j < n; ++j) {
            const std::uint8_t k = nearest_colour(s, j, w, bias);
            changed += it == 0 || nearest[j] != k;
            nearest[j] = k;
        }
        float sum[K][6] = {};
        int n_k[K] = {};
        for (int j = 0; j < n; ++j) {
            const int k = nearest[j];
            ++n_k[k];
            for (int q = 0; q < 6; ++q) sum[k][q] += s[q][j];
        }
        for (int k = 0; k < K; ++k)
            if (n_k[k] > 0)
                for (int q = 0; q < 6; ++q) cen[k][q] = sum[k][q] / static_cast<float>(n_k[k]);
        if (changed == 0) break;
    }
    set_weights();
    // Local copies of the plane pointers: a byte store may alias anything, and the loop
    // would load them again for every pixel instead of vectorizing.
    const float* const planes[6] = {f[0], f[1], f[2], f[3], f[4], f[5]};
    for (int i = 0; i < m; ++i) cluster[i] = nearest_colour(planes, i, w, bias);
    for (int k = 0; k < K; ++k) count[k] = 0;
    for (int i = 0; i < m; ++i) ++count[cluster[i]];
}

/// The materials of segment l's colours (ws.part at its pixels px[0, m), sizes `count`):
/// per pair of colours their contact, the 4-neighbour pairs between them, over the square
/// root of the smaller's size. Above color_max_compact (longer than the outline of any
/// compact piece) they interleave: one material. At most color_max_boundary x that (one side
/// of a compact piece) they lie apart. Between the two the pair is neither: no split. True,
/// with `material` (0 or 1 per colour), when the colours make exactly two materials. Cost:
/// one pass over the segment's pixels.
bool texture_materials(const Ctx& x, const SegmentWorkspace& ws, int l, const int* px, int m,
                       const int (&count)[kTextureColours], std::uint8_t (&material)[kTextureColours]) {
    constexpr int K = kTextureColours;
    const SegmentParams& prm = x.prm;
    const std::uint8_t* const part = ws.part.data();
    int contact[K][K] = {};  // symmetric
    for (int i = 0; i < m; ++i)
        for_part_boundary_pairs(x, ws, l, px[i], [&](int q, int, int) {
            ++contact[part[px[i]]][part[q]];
            ++contact[part[q]][part[px[i]]];
        });
    int root[K];  // union-find over the colours
    for (int k = 0; k < K; ++k) root[k] = k;
    auto find = [&](int k) {
        while (root[k] != k) k = root[k];
        return k;
    };
    int materials = K;
    auto join = [&](int a, int b) {
        if (const int ra = find(a), rb = find(b); ra != rb) root[rb] = ra, --materials;
    };
    // A colour too small for an object (mixed pixels along an edge, a sticker) is part of
    // the material it touches most.
    auto tiny = [&](int k) { return count[k] < prm.min_points; };
    for (int k = 0; k < K; ++k) {
        if (!tiny(k)) continue;
        int most = k == 0 ? 1 : 0;
        for (int j = 0; j < K; ++j)
            if (j != k && contact[k][j] > contact[k][most]) most = j;
        join(most, k);
    }
    for (int a = 0; a < K; ++a)
        for (int b = a + 1; b < K; ++b) {
            if (tiny(a) || tiny(b)) continue;
            const double c = contact[a][b];
            const double unit = std::sqrt(static_cast<double>(std::min(count[a], count[b])));
            if (c > prm.color_max_compact * unit) {
                join(a, b);
            } else if (c > prm.color_max_boundary * prm.color_max_compact * unit) {
                return false;
            }
        }
    if (materials != 2) return false;
    const int first = find(0);
    for (int k = 0; k < K; ++k) material[k] = find(k) == first ? 0 : 1;
    return true;
}

/// Segment l's split into two materials, when 2-means followed a texture: texture_colours,
/// texture_materials, then ws.part, side, `count` and `cen` say the materials (cen: their
/// means). False, and ws.part not a split, when the colours are not two materials. Cost:
/// texture_colours' passes and two more over the segment's pixels.
bool split_by_materials(const Ctx& x, SegmentWorkspace& ws, int l, const int* px, const float* const* f, int m,
                        std::uint8_t* side, float (&cen)[2][6], int (&count)[2]) {
    float colour[kTextureColours][6];
    int colour_count[kTextureColours];
    texture_colours(f, m, cen, side, colour, colour_count);
    for (const int c : colour_count)
        if (c == 0) return false;
    std::uint8_t* const part = ws.part.data();
    for (int i = 0; i < m; ++i) part[px[i]] = side[i];
    std::uint8_t material[kTextureColours];
    if (!texture_materials(x, ws, l, px, m, colour_count, material)) return false;
    double sum[2][6] = {};
    count[0] = count[1] = 0;
    for (int i = 0; i < m; ++i) {
        const std::uint8_t j = material[side[i]];
        side[i] = j;
        part[px[i]] = j;
        ++count[j];
        for (int q = 0; q < 6; ++q) sum[j][q] += f[q][i];
    }
    // Each material large enough to be tried again (as order_by_size asks of a segment):
    // grouping colours is weaker evidence than 2-means' own parts, and a print's block of
    // min_points split off a box seen in two pieces on osd_mosd's learn18 (docs/ABLATION.md,
    // "Textures").
    if (std::min(count[0], count[1]) < 2 * x.prm.min_points) return false;
    for (int j = 0; j < 2; ++j)
        for (int q = 0; q < 6; ++q) cen[j][q] = static_cast<float>(sum[j][q] / count[j]);
    return true;
}

/// How a segment was split by the colour cue (ws.split).
enum Split : std::uint8_t { kNotSplit = 0, kSplitByColour = 1, kSplitByMaterial = 2 };

/// Tries to split segment l in two: 2-means, then the tests of the colour cue (SegmentParams,
/// "Colour cue"); where 2-means followed a texture, the segment's materials
/// (split_by_materials) and the same tests. Writes ws.part at the segment's pixels once
/// 2-means ran. Cost: O(segment pixels) per 2-means iteration and for the boundary, the
/// materials' passes when 2-means followed a texture; no allocation (called in parallel, one
/// segment per call).
Split try_colour_split(const Ctx& x, const Plane* support, const PlaneAxes* plane_xy, const ColourFeatures& ft,
                       const ClusterParams& cp, float cos_crease, SegmentWorkspace& ws, int l) {
    const SegmentParams& prm = x.prm;
    const int o = ws.offsets[static_cast<std::size_t>(l)];
    const int* px = ws.order.data() + o;
    const int m = segment_size(ws, l);
    const float* f[6];  // the segment's features
    for (int q = 0; q < 6; ++q) f[q] = ft.f[q] + (o - ft.first);
    float cen[2][6];
    double total[6];
    if (!seed_centres(f, m, prm.color_min_distance * cp.alpha, cen, total)) return kNotSplit;
    std::uint8_t* const side = ws.part_in_order.data() + o;
    int count[2] = {0, 0};
    two_means(f, m, total, side, cen, count);
    std::uint8_t* part = ws.part.data();
    for (int i = 0; i < m; ++i) part[px[i]] = side[i];
    const Verdict verdict = judge_split(x, support, plane_xy, cp, cos_crease, ws, l, px, m, count, cen);
    if (verdict == Verdict::kKept) return kSplitByColour;
    // kTexture: both parts passed the share test, so both hold pixels.
    if (verdict != Verdict::kTexture || !prm.color_textures || !split_by_materials(x, ws, l, px, f, m, side, cen, count))
        return kNotSplit;
    return judge_split(x, support, plane_xy, cp, cos_crease, ws, l, px, m, count, cen) == Verdict::kKept
               ? kSplitByMaterial
               : kNotSplit;
}

/// Part 1 of each split segment takes a new label, n + 1, n + 2, ... in segment order (not
/// thread order), with the split segment's ws.origin. Returns the splits, and adds those by
/// material to `by_material`. Cost: one pass over the split segments' pixels.
int number_splits(SegmentWorkspace& ws, int n, int& by_material) {
    int splits = 0, next = n;
    for (int l = 1; l <= n; ++l) {
        if (ws.split[static_cast<std::size_t>(l)] == kNotSplit) continue;
        by_material += ws.split[static_cast<std::size_t>(l)] == kSplitByMaterial;
        const int id = ++next;
        ws.origin[static_cast<std::size_t>(id)] = ws.origin[static_cast<std::size_t>(l)];
        const int o = ws.offsets[static_cast<std::size_t>(l)];
        const int m = ws.offsets[static_cast<std::size_t>(l) + 1] - o;
        for (int i = 0; i < m; ++i) {
            const std::size_t p = static_cast<std::size_t>(ws.order[static_cast<std::size_t>(o + i)]);
            if (ws.part[p] == 1) ws.label[p] = id;
        }
        ++splits;
    }
    return splits;
}

/// One round of the colour cue over the segments marked in ws.to_try (1..n): tries to split
/// each in two, then numbers part 1 of each split segment n + 1, n + 2, ... in segment order.
/// Returns the splits, and adds those by material to `by_material`. Cost: a counting sort
/// and a gather of the object pixels (parallel passes), then O(segment pixels) per 2-means
/// iteration per segment tried, segments in parallel.
int split_round(const Ctx& x, const Plane* support, SegmentWorkspace& ws, int n, int& by_material) {
    const SegmentParams& prm = x.prm;
    sort_pixels_by_segment(x, ws, n);
    // part is written for a segment's pixels before anything reads them: no clearing.
    ws.part.resize(static_cast<std::size_t>(x.W) * x.H);
    ws.part_in_order.resize(static_cast<std::size_t>(ws.offsets[static_cast<std::size_t>(n) + 1]));
    ws.split.assign(static_cast<std::size_t>(n) + 1, kNotSplit);
    ClusterParams cp;
    cp.alpha = prm.color_alpha;
    cp.delta = 1.0f - prm.color_alpha;
    const ColourFeatures features = gather_features(x, cp, ws, n);
    const float cos_crease = std::cos(prm.color_max_crease_deg * kDegToRad);
    std::optional<PlaneAxes> plane_xy;
    if (support) plane_xy.emplace(*support);
    // Each segment is tried on its own; split ids are given out in segment order afterwards
    // so that the labels do not depend on the threads.
    order_by_size(prm, ws, n);
    const auto n_tried = static_cast<std::ptrdiff_t>(ws.by_size.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::ptrdiff_t t = 0; t < n_tried; ++t) {
        const int l = ws.by_size[static_cast<std::size_t>(t)];
        const PlaneAxes* axes = plane_xy ? &*plane_xy : nullptr;
        ws.split[static_cast<std::size_t>(l)] = try_colour_split(x, support, axes, features, cp, cos_crease, ws, l);
    }
    return number_splits(ws, n, by_material);
}

}  // namespace

/// The colour cue: tries to split each segment in two by 2-means under the paper's distance
/// (eq. 4, 6) with a colour-heavy alpha; keeps a split only when the parts differ in colour,
/// are large, and meet along one side of the smaller part or round a compact piece, across
/// a smooth surface or with a turn of colour, and the segment does not stand round on the
/// support (stands_round: a can's label is print). Where 2-means followed a texture, the
/// same tests judge a split between the segment's materials (split_by_materials). A second
/// round tries the two parts of each split segment again: three flush boxes of three colours
/// need two cuts. In: ws.label (1..n with gaps). Out: ws.label with the new parts numbered
/// n + 1, n + 2, ... (round 1's in segment order, then round 2's), and ws.origin, each
/// label's segment before the cue; `by_material` counts the splits between materials. Cost:
/// split_round once, twice when it split anything.
int color_splits(const Ctx& x, const Plane* support, SegmentWorkspace& ws, int n, int& by_material) {
    by_material = 0;
    // Each label's segment before the cue; a round adds at most one label per segment.
    ws.origin.resize(4 * static_cast<std::size_t>(n) + 1);
    for (int l = 0; l <= n; ++l) ws.origin[static_cast<std::size_t>(l)] = l;
    ws.to_try.assign(static_cast<std::size_t>(n) + 1, 1);
    const int first = split_round(x, support, ws, n, by_material);
    if (first == 0) return 0;
    // Round 2: the segments split in round 1 (part 0 kept their label) and their new parts.
    // A third round split nothing more on the tune seeds (docs/ABLATION.md).
    ws.to_try.assign(static_cast<std::size_t>(n + first) + 1, 0);
    for (int l = 1; l <= n; ++l) ws.to_try[static_cast<std::size_t>(l)] = ws.split[static_cast<std::size_t>(l)] != kNotSplit;
    for (int l = n + 1; l <= n + first; ++l) ws.to_try[static_cast<std::size_t>(l)] = 1;
    return first + split_round(x, support, ws, n + first, by_material);
}

// ---- scope ---------------------------------------------------------------------------------

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


}  // namespace

/// Scope::Support (docs/DESIGN.md, "Scope"): keeps the segments the support holds and
/// clears the others' labels in ws.label. In: ws.label (1..n with gaps), the support, the
/// plane's classes. Out: the number of segments of min_points or more left out. Cost: one
/// pass over the pixels (heights, outlines, touching pairs) and one over the depths, then a
/// few passes over the touching pairs until "rests on" stops spreading.
int restrict_to_support(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const FrameEdge edge = find_frame_edge(x);
    const float far_z = support_middle_depth(x, pl);
    measure_scope(x, pl, edge, far_z, ws, n);
    count_upright(x, pl, ws, n);
    decide_scope(x, pl, ws, n);
    return clear_out_of_scope(x.prm, ws, n);
}


}  // namespace wul3d::detail
