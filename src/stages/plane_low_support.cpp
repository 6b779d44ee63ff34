// 8. A low support (plane_internal.hpp): a board or tray lying on the support, the objects on
// it. Its top is a layer of points facing up a little above the support's band, larger than
// an object; it is background as the support is, and the objects on it stand apart on it as
// on a table.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "plane_axes.hpp"
#include "plane_internal.hpp"

namespace wul3d::detail {

namespace {

/// A low support's top lies at most this far over the support: a board, a tray's bottom, a
/// mat (the floor family's boards are 1-3 cm thick, on carpets of up to 1.2 cm). Boxes lying
/// flat are taller, or smaller than kMinArea.
constexpr float kMaxHeightM = 0.05f;
/// ... and spans at least this area (its visible top's convex hull on the plane): more than
/// a book or a box lying flat, less than a board that holds several objects (the floor
/// family's are 0.12-0.48 m^2).
constexpr float kMinAreaM2 = 0.1f;
/// The low support's extent in the image: the convex hull of its top's visible piece on the
/// grid, this many cells wider (its edge).
constexpr int kRimCells = 2;
/// A tray's rim stands round its bottom: up to kMaxHeightM over the bottom, its foot within
/// this of the convex hull of the bottom's visible piece on the plane (a rim is 1.6 cm wide,
/// and a noisy camera's piece stops short of it). On the plane, not in the image: a camera
/// looking down sees a rim's outer wall spread in the image by its height, over more than
/// kRimCells in front (active stereo's holes then broke it into pieces too small for the
/// scope's low supports), while an object on the floor has its foot off the tray. The same
/// 5 cm as the height (first 60 floor tune seeds: 3, 4, 5 and 7 cm tried, 5 best, 4 close).
constexpr float kRimM = kMaxHeightM;
/// The layer counts points from this share of the support's band over it, not from the band
/// itself: the band is the noise's tolerance at a point's depth (17 mm at 1.5 m), and a board
/// 1.5-2 cm thick seen that far has its top in the band's upper part, too few of its points
/// over the band to make a layer (generated floor tune seeds: 0.75 scored above 0.5 and 1;
/// docs/ABLATION.md, "Low supports in the plane stage").
constexpr float kLayerFromBand = 0.75f;
/// A piece of the low plane's inliers lies on it when its points' mean height over it is
/// within this share of their mean band. A board's pieces straddle the plane (means of
/// 0.00-0.04 band on the floor family's boards); another surface's sit off it: the floor's
/// noise over a thin board's band (-0.5 to -0.8), a book of another thickness (0.4 and more,
/// `osd_mosd` test58).
constexpr float kOnPlaneShare = 0.25f;
/// The layer's histogram: bins of 2 mm over (0, kMaxHeightM], windows of 5 bins.
constexpr float kBinM = 0.002f;
constexpr int kBins = static_cast<int>(kMaxHeightM / kBinM), kWindow = 2;

/// The height of the densest layer of grid points facing like `pl` between its band and
/// kMaxHeightM over it (`h` per grid point, NaN where not a candidate), or NaN under
/// `min_points` in the layer. O(G) and O(bins).
float densest_layer(const float* h, int G, int min_points) {
    int histogram[kBins] = {};
    for (int g = 0; g < G; ++g)
        if (h[g] > 0.0f && h[g] <= kMaxHeightM) ++histogram[std::min(kBins - 1, static_cast<int>(h[g] / kBinM))];
    int best = -1, best_count = min_points - 1;
    for (int c = 0; c < kBins; ++c) {
        int count = 0;
        for (int b = std::max(0, c - kWindow); b <= std::min(kBins - 1, c + kWindow); ++b) count += histogram[b];
        if (count > best_count) {
            best_count = count;
            best = c;
        }
    }
    return best < 0 ? std::nanf("") : (static_cast<float>(best) + 0.5f) * kBinM;
}

/// Calls f(q) for each of grid point g's 8 neighbours q inside the grid.
template <class F>
void for_each_neighbour(const Grid& grid, int g, F&& f) {
    const int gu = g % grid.w, gv = g / grid.w;
    for (int v = std::max(0, gv - 1); v <= std::min(grid.h - 1, gv + 1); ++v)
        for (int u = std::max(0, gu - 1); u <= std::min(grid.w - 1, gu + 1); ++u)
            if (u != gu || v != gv) f(v * grid.w + u);
}

/// The largest 8-connected piece of the grid points with in[g] != 0: its points' indices
/// into `piece`. `label` (G): each point's piece, -1 outside `in`; `stack` is scratch.
/// Returns the number of pieces. O(G).
int largest_piece(const Grid& grid, const std::vector<std::uint8_t>& in, std::vector<int>& label,
                  std::vector<int>& stack, std::vector<int>& piece) {
    const int G = grid.size();
    label.assign(static_cast<std::size_t>(G), -1);
    piece.clear();
    std::vector<int>& current = stack;  // reused: the flood's stack holds each piece's points
    int id = 0;
    for (int seed = 0; seed < G; ++seed) {
        if (!in[seed] || label[seed] >= 0) continue;
        current.clear();
        current.push_back(seed);
        label[seed] = id;
        for (std::size_t k = 0; k < current.size(); ++k)
            for_each_neighbour(grid, current[k], [&](int q) {
                if (!in[q] || label[q] >= 0) return;
                label[q] = id;
                current.push_back(q);
            });
        if (current.size() > piece.size()) piece = current;
        ++id;
    }
    return id;
}

/// A board's top, parted in the image by the objects standing on it: adds to `piece` (one of
/// the `pieces` pieces of `in`, as largest_piece labelled them in `label`) every other piece
/// that it reaches across points for which `stands(g)` holds, and that lies on `low`
/// (kOnPlaneShare). `sums` (3 per piece) and `stack` are scratch; `label` is spent. O(G).
template <class Stands>
void join_across_objects(const Grid& grid, const PlaneWorkspace::Buffers::GridPoints& gp,
                         const InlierTest& inliers, const Plane& low, Stands&& stands, int pieces,
                         std::vector<int>& label, std::vector<double>& sums, std::vector<int>& stack,
                         std::vector<int>& piece) {
    const int G = grid.size();
    if (piece.empty()) return;
    // Each piece's count, summed height over `low` and summed band.
    sums.assign(3 * static_cast<std::size_t>(pieces), 0.0);
    for (int g = 0; g < G; ++g) {
        if (label[g] < 0) continue;
        double* const s = &sums[3 * static_cast<std::size_t>(label[g])];
        s[0] += 1;
        s[1] += low.height(gp.x[g], gp.y[g], gp.z[g]);
        s[2] += inliers.band(gp.z[g]);
    }
    const auto on_plane = [&](int id) {
        const double* const s = &sums[3 * static_cast<std::size_t>(id)];
        return std::fabs(s[1]) <= kOnPlaneShare * s[2];
    };
    // A flood from the piece over standing points and the pieces on the plane; a point seen
    // is labelled -2.
    const int own = label[piece.front()];
    stack.clear();
    for (const int g : piece) {
        label[g] = -2;
        stack.push_back(g);
    }
    for (std::size_t k = 0; k < stack.size(); ++k)
        for_each_neighbour(grid, stack[k], [&](int q) {
            const int id = label[q];
            if (id == -2) return;
            const bool joins = id >= 0 && (id == own || on_plane(id));
            if (!joins && !(id == -1 && stands(q))) return;
            label[q] = -2;
            stack.push_back(q);
            if (joins) piece.push_back(q);
        });
}

/// A point's foot on the plane of `axes`, in floats for OpenCV's polygons.
cv::Point2f foot(const PlaneAxes& axes, float x, float y, float z) {
    const Eigen::Vector2d q = axes(x, y, z);
    return {static_cast<float>(q.x()), static_cast<float>(q.y())};
}

/// The convex hull of `piece`'s points moved onto the plane `pl` (PlaneAxes' coordinates);
/// empty under three points.
std::vector<cv::Point2f> hull_on_plane(const PlaneWorkspace::Buffers::GridPoints& gp, const std::vector<int>& piece,
                                       const Plane& pl) {
    const PlaneAxes axes(pl);
    std::vector<cv::Point2f> points, hull;
    points.reserve(piece.size());
    for (const int g : piece) points.push_back(foot(axes, gp.x[g], gp.y[g], gp.z[g]));
    if (points.size() >= 3) cv::convexHull(points, hull);
    return hull;
}

/// The area of the convex hull of `piece`'s points moved onto the plane `pl`, in m^2.
double area_on_plane(const PlaneWorkspace::Buffers::GridPoints& gp, const std::vector<int>& piece,
                     const Plane& pl) {
    const std::vector<cv::Point2f> hull = hull_on_plane(gp, piece, pl);
    return hull.size() < 3 ? 0.0 : cv::contourArea(hull);
}

/// A convex polygon and its edges' lines (outward unit normal and offset), to tell cheaply
/// whether a point lies within a distance of it.
struct Outline {
    std::vector<cv::Point2f> corners;
    std::vector<cv::Point3f> edges;  ///< (nx, ny, offset): n . q - offset is q's signed distance

    explicit Outline(std::vector<cv::Point2f> polygon) : corners(std::move(polygon)) {
        cv::Point2f centre(0, 0);
        for (const cv::Point2f& q : corners) centre += q;
        centre *= 1.0f / static_cast<float>(corners.size());
        for (std::size_t i = 0; i < corners.size(); ++i) {
            const cv::Point2f a = corners[i], b = corners[(i + 1) % corners.size()];
            cv::Point2f n(b.y - a.y, a.x - b.x);
            const float length = std::hypot(n.x, n.y);
            if (length <= 0.0f) continue;
            n *= 1.0f / length;
            if (n.dot(centre - a) > 0.0f) n = -n;
            edges.emplace_back(n.x, n.y, n.dot(a));
        }
    }
    /// Whether `q` lies within `r` of the polygon. More than `r` beyond one edge's line, it does
    /// not (most points far from it stop there); otherwise the exact distance. O(edges).
    bool within(cv::Point2f q, float r) const {
        float beyond = -1e30f;
        for (const cv::Point3f& e : edges) beyond = std::max(beyond, e.x * q.x + e.y * q.y - e.z);
        if (beyond > r) return false;
        return beyond <= 0.0f || cv::pointPolygonTest(corners, q, true) >= -r;
    }
};

}  // namespace

std::size_t remove_low_support(const PlaneParams& params, const Grid& grid, const OrganizedCloud& cloud,
                               const NormalMap& normals, const InlierTest& inliers, const Plane& pl,
                               PlaneWorkspace::Buffers& ws, std::vector<std::uint8_t>& classes, Plane& low,
                               const Band& removal_band) {
    const int G = grid.size();
    const auto& gp = ws.grid;
    // 1. The layer: grid points facing like the support, over kLayerFromBand of its band, up
    // to kMaxHeightM.
    ws.layer_t.resize(static_cast<std::size_t>(G));
    float* const h = ws.layer_t.data();
    for (int g = 0; g < G; ++g) {
        const float height = pl.height(gp.x[g], gp.y[g], gp.z[g]);
        const bool facing = gp.nx[g] * pl.nx + gp.ny[g] * pl.ny + gp.nz[g] * pl.nz >= inliers.cos_inlier;
        h[g] = facing && gp.usable[g] && height > kLayerFromBand * inliers.band(gp.z[g]) ? height : std::nanf("");
    }
    const float layer = densest_layer(h, G, params.min_region_points);
    if (std::isnan(layer)) return 0;
    // 2. Its largest piece, with the pieces of the layer that it reaches across the objects
    // standing on it (they part a board's top in the image), large enough on the plane.
    // Until its own plane is fitted, `board` is the layer's: parallel to the support.
    Plane board = pl;
    board.d -= layer;
    const auto stands = [&](int g) {  // a grid point of an object standing on `board`
        const float hl = board.height(gp.x[g], gp.y[g], gp.z[g]);
        return gp.active[g] && hl > 2.0f * inliers.band(gp.z[g]) && hl <= params.max_object_height_m;
    };
    ws.low_mask.assign(static_cast<std::size_t>(G), 0);
    for (int g = 0; g < G; ++g)
        ws.low_mask[static_cast<std::size_t>(g)] = std::fabs(h[g] - layer) <= inliers.band(gp.z[g]);
    int pieces = largest_piece(grid, ws.low_mask, ws.region, ws.stack, ws.low_piece);
    join_across_objects(grid, gp, inliers, board, stands, pieces, ws.region, ws.low_sums, ws.stack, ws.low_piece);
    if (static_cast<int>(ws.low_piece.size()) < params.min_region_points ||
        area_on_plane(gp, ws.low_piece, pl) < kMinAreaM2)
        return 0;
    // 3. Its plane, fitted to the piece, then again to the largest piece of that plane's
    // inliers (the layer's heights were over the support, which need not be quite parallel)
    // with the pieces of them that it reaches as above.
    for (int round = 0; round < 2; ++round) {
        ws.low_mask.assign(static_cast<std::size_t>(G), 0);
        for (const int g : ws.low_piece) ws.low_mask[static_cast<std::size_t>(g)] = 1;
        if (!fit_grid_points(inliers, params.min_region_points, ws.low_mask.data(), board)) return 0;
        if (round == 1) break;
        for (int g = 0; g < G; ++g) ws.low_mask[static_cast<std::size_t>(g)] = gp.usable[g] && inliers(board, g);
        pieces = largest_piece(grid, ws.low_mask, ws.region, ws.stack, ws.low_piece);
        join_across_objects(grid, gp, inliers, board, stands, pieces, ws.region, ws.low_sums, ws.stack,
                            ws.low_piece);
    }
    low = board;
    // Its extent in the image: the piece's convex hull on the grid, a cell wider.
    std::vector<cv::Point> cells;
    cells.reserve(ws.low_piece.size());
    for (const int g : ws.low_piece) cells.emplace_back(g % grid.w, g / grid.w);
    std::vector<cv::Point> corners;
    cv::convexHull(cells, corners);
    cv::Mat hull = cv::Mat::zeros(grid.h, grid.w, CV_8U), extent;
    cv::fillConvexPoly(hull, corners, cv::Scalar(1));
    cv::dilate(hull, extent, cv::Mat::ones(2 * kRimCells + 1, 2 * kRimCells + 1, CV_8U));
    // ... and on the plane, where a tray's rim stands round it.
    const Outline outline(hull_on_plane(gp, ws.low_piece, low));
    if (outline.corners.size() < 3) return 0;
    const PlaneAxes axes(low);
    // 4. It holds objects: min_region_points grid points stand over its extent, clear of its
    // band (books lying side by side, with nothing on them, are objects, not a support).
    int standing = 0;
    for (int g = 0; g < G; ++g) standing += extent.data[g] && stands(g);
    if (standing < params.min_region_points) return 0;
    // 5. Every object pixel over that extent that is not above the low support's band: its
    // top (facing like it), its sides and what lies between it and the support are removed;
    // on its band but facing otherwise, a candidate foot, as on the support. The band is the
    // frame's, widened with its noise as the support's pixels' is (`removal_band`): the
    // layer and its plane were found on the given band, but a noisy camera scatters the
    // board's points past it, and those left as objects grew into one with the objects on
    // the board (a tray under active stereo at 1.5 m). So is every pixel the support's
    // classes took for a container's inside there: a board whose top lies in the support's
    // band, enclosed by its own edge, looks like one, and the segmentation would join it to
    // that edge, the objects on it with it. Off the hull, a tray's rim is removed whole
    // (kRimM).
    const int W = cloud.width, H = cloud.height;
    std::size_t removed = 0;
    for (int v = 0; v < H; ++v) {
        const std::uint8_t* const cell_row = extent.ptr<std::uint8_t>(v / grid.s);
        const std::uint8_t* const hull_row = hull.ptr<std::uint8_t>(v / grid.s);
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (classes[p] != kPlaneObject && classes[p] != kPlaneInside) continue;
            const float z = cloud.z[p], hl = low.height(cloud.x[p], cloud.y[p], z);
            const bool rim = !hull_row[u / grid.s] && hl <= kMaxHeightM &&  // round the bottom: a tray's rim
                             outline.within(foot(axes, cloud.x[p], cloud.y[p], z), kRimM);
            if (!rim && !cell_row[u / grid.s]) continue;
            const float band = removal_band(z);
            if (!rim && hl > band) continue;
            const bool facing = normals.valid[p] &&
                                normals.nx[p] * low.nx + normals.ny[p] * low.ny + normals.nz[p] * low.nz >=
                                    inliers.cos_inlier;
            if (!rim && hl >= -band && !facing && normals.valid[p]) {
                classes[p] = kPlaneFoot;
                continue;
            }
            classes[p] = kPlaneRemoved;
            ++removed;
        }
    }
    return removed;
}

}  // namespace wul3d::detail
