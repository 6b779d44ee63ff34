// The container rule: a bowl or a cup seen from above shows its outer wall and, over the
// front rim, its inside; the rim hides the inside's lower part, so the two meet only across
// a depth step, where neither the crease test nor the merge can join them. Where the front
// segment's edge along the step is a level circular arc on the support (circle_fit.hpp) and
// the back segment stands inside that circle and reaches up to it, the back is the front's
// inside and joins it.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "../circle_fit.hpp"
#include "internal.hpp"

namespace wul3d::detail {
namespace {

constexpr std::uint64_t kPairMask = ~std::uint64_t{15};  ///< BoundaryStep::key's segment pair

/// The boundary pairs of two segments in rows [v0, v1) into `steps` in raster order, keyed
/// (lo, hi, depth step, lo is nearer) with the nearer pixel; each segment's first and last
/// row there into rows[2 l], rows[2 l + 1] (-1: none). Reads only the frame and the labels:
/// strips run in parallel.
void strip_boundary_steps(const Ctx& x, const int* label, int v0, int v1, std::vector<BoundaryStep>& steps,
                          int* rim_rows) {
    const int W = x.W, H = x.H;
    for (int v = v0; v < v1; ++v) {
        // Only labelled pixels add anything.
        if (!row_has_label(label + static_cast<std::size_t>(v) * W, 0, W)) continue;
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            const int a = label[p];
            if (a == 0) continue;
            int* rows = rim_rows + 2 * static_cast<std::size_t>(a);
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
                steps.push_back({key, static_cast<std::uint32_t>(p_nearer ? p : q)});
            }
        }
    }
}

/// One pass: the boundary pairs of two segments into ws.steps, keyed (lo, hi, depth step,
/// lo is nearer) with the nearer pixel, sorted by key; each segment's first and last row into
/// ws.rim_rows. In: ws.label (0..n). Cost: O(pixels) in strips of rows in parallel (their
/// pairs joined in strip order: the raster order of one pass), then a sort of the boundary
/// pairs.
void collect_boundary_steps(const Ctx& x, SegmentBuffers& ws, int n) {
    const int strips = row_strips(x.H);
    const std::size_t rows_size = 2 * (static_cast<std::size_t>(n) + 1);
    auto by_key = [](const BoundaryStep& l, const BoundaryStep& r) { return l.key < r.key; };
    ws.steps.clear();
    ws.rim_rows.assign(rows_size, -1);
    if (strips == 1) {  // one pass straight into ws.steps and ws.rim_rows
        strip_boundary_steps(x, ws.label.data(), 0, x.H, ws.steps, ws.rim_rows.data());
        std::sort(ws.steps.begin(), ws.steps.end(), by_key);
        return;
    }
    ws.strip_steps.resize(static_cast<std::size_t>(strips));
    ws.strip_rows.assign(static_cast<std::size_t>(strips) * rows_size, -1);
    const int* const label = ws.label.data();
#pragma omp parallel for schedule(static)
    for (int t = 0; t < strips; ++t) {
        auto& steps = ws.strip_steps[static_cast<std::size_t>(t)];
        steps.clear();
        strip_boundary_steps(x, label, x.H * t / strips, x.H * (t + 1) / strips, steps,
                             ws.strip_rows.data() + static_cast<std::size_t>(t) * rows_size);
    }
    for (const auto& st : ws.strip_steps) ws.steps.insert(ws.steps.end(), st.begin(), st.end());
    // First row: the first strip's that has one; last row: the last strip's.
    for (int t = 0; t < strips; ++t) {
        const int* const rows = ws.strip_rows.data() + static_cast<std::size_t>(t) * rows_size;
        for (std::size_t i = 0; i < rows_size; i += 2) {
            if (rows[i] < 0) continue;
            if (ws.rim_rows[i] < 0) ws.rim_rows[i] = rows[i];
            ws.rim_rows[i + 1] = rows[i + 1];
        }
    }
    std::sort(ws.steps.begin(), ws.steps.end(), by_key);
}

/// The RMS distance from a fitted circle that still counts as on it, for points at mean
/// depth z: containers.max_residual_m to 1 m (it was set on `osd_mosd`, whose objects lie 0.57-0.82
/// m away), then growing as z^2, as the sensor's depth noise does (a structured-light
/// sensor's depth step is z^2 / (f b)), which scatters the points along the rays. Only the
/// rims use it: the round test keeps containers.max_residual_m, since a looser bound there let more
/// segments pass as round, which the colour cue then leaves unsplit (docs/ABLATION.md,
/// "Containers").
double circle_tolerance(const SegmentParams& prm, double z) {
    return prm.containers.max_residual_m * std::max(1.0, z * z);
}

/// The front's extent across the line of sight, in radii of a circle fitted with the far
/// rim, at least: 1 (a container's outer wall spans 2, or less where something hides it).
/// 1.5 lost half the gain on the generated tune seeds (docs/ABLATION.md, "Containers").
constexpr double kFarRimMinWidth = 1.0;

/// The front segment's extent on the plane across the line of sight through `centre` (the
/// camera lies at the plane's origin). Cost: one pass over the front's rows.
double front_width(const Ctx& x, const PlaneAxes& plane_xy, const SegmentBuffers& ws, int front,
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
/// depth) and span enough of it (containers.min_arc); nothing otherwise. Cost: three passes and
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
    if (std::sqrt(res / m) > circle_tolerance(x.prm, z) || chord < x.prm.containers.min_arc * 2 * R) return std::nullopt;
    return RimCircle{centre + mean, R, height};
}

/// The back segment's pixels on its far rim, into ws.rim_far_px: within containers.height_tol_m of
/// `rim_height` over the plane, and nearer across a depth step than a 4-neighbour that
/// belongs to neither segment (or has no depth). A container's inside, seen over its front
/// wall, ends there at the far half of the rim. Cost: one pass over the back's rows.
void collect_far_rim(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int front, int back, double rim_height) {
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
            if (std::fabs(pl.height(x.c.x[p], x.c.y[p], x.c.z[p]) - rim_height) > x.prm.containers.height_tol_m) continue;
            const bool on_outline = (u > 0 && steps_to_farther(p, p - 1)) || (u + 1 < W && steps_to_farther(p, p + 1)) ||
                                    (v > 0 && steps_to_farther(p, p - W)) || (v + 1 < H && steps_to_farther(p, p + W));
            if (on_outline) ws.rim_far_px.push_back(static_cast<int>(p));
        }
}

/// The far rim's candidate (containers.far_rim) for the pair (front, back), whose front edge
/// `for_edge` visits: a circle fitted to that edge and to the back's far rim
/// (collect_far_rim, at the edge's mean height). A small cup's front edge at --decimate 2
/// can be 6 pairs long, too short an arc to fit alone, or it fits a circle too small for the
/// inside; with the far half of the rim the circle spans the whole rim. Kept when
///  - the front spans a radius of it across the line of sight (kFarRimMinWidth): a
///    container's outer wall spans its diameter;
///  - the far rim alone fits a circle that agrees with it (containers.far_agree): it is the same
///    rim. This is what keeps an object behind a box out: its outline at the box's height
///    reaches "the rim" by how the far rim is chosen, but traces its own shape, not the
///    circle through the box's straight edge.
/// Cost: one pass over the back's rows and one over the front's; rim_circle's passes over
/// the edge and the far rim, twice. ws.rim_far_px keeps its capacity across frames.
template <class ForEdge>
std::optional<RimCircle> far_rim_circle(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentBuffers& ws,
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
    const double agree = x.prm.containers.far_agree * both->radius;
    if (!far || std::fabs(far->radius - both->radius) > agree || (far->centre - both->centre).norm() > agree)
        return std::nullopt;
    return both;
}

/// The rim of the pair (front, back) along the steps ws.steps[i0, i1): a circle fitted to
/// the front segment's edge there (the nearer pixels of the depth steps that lie in
/// `front`), and with containers.far_rim a second one through the back's far rim too
/// (far_rim_circle). Appends each that passes to ws.rim_fits as {front, back, centre (2),
/// radius, rim height}; the inside test then judges each. Cost: rim_circle's passes over
/// the pair's boundary pairs, and far_rim_circle's; no allocation but the appends.
void fit_rim(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentBuffers& ws,
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
    if (!x.prm.containers.far_rim) return;
    if (const auto both = far_rim_circle(x, pl, plane_xy, ws, for_edge, front, back)) keep(*both);
}

/// Candidates: segment pairs that meet (almost) only across depth steps; the front is the
/// segment nearer along them, and its edge must be a circular arc (fit_rim). In: ws.steps,
/// sorted. Out: ws.rim_fits. Cost: one pass over the boundary pairs, then fit_rim's passes
/// over each candidate's.
void find_rims(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentBuffers& ws) {
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
        if (steps < prm.containers.min_boundary || 5 * steps < 4 * pairs) continue;
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
void measure_insides(const Ctx& x, const Plane& pl, const PlaneAxes& plane_xy, SegmentBuffers& ws, int n) {
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
int join_insides(const Ctx& x, SegmentBuffers& ws, int n) {
    const SegmentParams& prm = x.prm;
    reset_sets(ws.parent, n);
    int joins = 0;
    for (std::size_t c = 0; c < ws.rim_fits.size(); ++c) {
        const auto& fit = ws.rim_fits[c];
        const auto& b = ws.rim_back[c];
        if (b[1] < prm.containers.inside_share * b[0] || std::fabs(b[2] - fit[5]) > prm.containers.height_tol_m) continue;
        joins += join_sets(ws.parent, static_cast<int>(fit[0]), static_cast<int>(fit[1]));
    }
    if (joins == 0) return 0;
    relabel_to_roots(ws);
    // The joined containers stay whole through the pieces phase: the rim hides what joins
    // the inside to the wall, and pixels cut along it can leave them apart in the image.
    ws.rim_joined.assign(static_cast<std::size_t>(n) + 1, 0);
    for (int l = 1; l <= n; ++l)
        if (const int root = find_root(ws.parent, l); root != l) ws.rim_joined[static_cast<std::size_t>(root)] = 1;
    return joins;
}

/// The rim test over segments 1..n (with gaps): candidates, their circles, their insides,
/// the joins. Returns the joins. Cost: as join_containers'.
int join_rims(const Ctx& x, const Plane& pl, SegmentBuffers& ws, int n) {
    if (n < 2) return 0;
    collect_boundary_steps(x, ws, n);
    const PlaneAxes plane_xy(pl);
    find_rims(x, pl, plane_xy, ws);
    if (ws.rim_fits.empty()) return 0;
    measure_insides(x, pl, plane_xy, ws, n);
    return join_insides(x, ws, n);
}

}  // namespace

/// The container rule (SegmentParams, "Containers"), on a support: a segment seen over
/// another's circular, level edge across a depth step, lying inside that circle and reaching
/// up to it, is the other's inside (a bowl's or a cup's) and joins it. In: ws.label (1..n
/// with gaps). Out: ws.label with the insides joined. Cost: one pass over the pixels and a
/// sort of the boundary pairs; then per candidate a few passes over its boundary, and one
/// over the rows of the candidates' insides.
void join_containers(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    ws.rim_joined.clear();
    if (!support || x.prm.containers.min_boundary <= 0 || n < 1) return;
    stats.containers.joins = join_rims(x, *support, ws, n);
}

}  // namespace wul3d::detail
