#include "wul3d/plane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "branch_free.hpp"
#include "param_check.hpp"
#include "plane_internal.hpp"
#include "point_moments.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

PlaneWorkspace::PlaneWorkspace() : b_(std::make_unique<Buffers>()) {}
PlaneWorkspace::~PlaneWorkspace() = default;
PlaneWorkspace::PlaneWorkspace(PlaneWorkspace&&) noexcept = default;
PlaneWorkspace& PlaneWorkspace::operator=(PlaneWorkspace&&) noexcept = default;
PlaneWorkspace::Buffers& PlaneWorkspace::buffers() {
    if (!b_) b_ = std::make_unique<Buffers>();
    return *b_;
}

using PlaneBuffers = PlaneWorkspace::Buffers;
using detail::Band;
using detail::Grid;
using detail::HullMask;
using detail::InlierTest;
using detail::make_grid;
using detail::make_hull_mask;

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "PlaneParams", name, value, range);
}
constexpr float kDegToRad = 3.14159265358979f / 180.0f;
// Per-region sums: the point moments (point_moments.hpp), then nx, ny, nz.
constexpr int kSums = detail::kMoments + 3;
}  // namespace

void PlaneParams::validate() const {
    require(grid_stride_px >= 1 && grid_stride_px <= 32, "grid_stride_px", grid_stride_px, "in [1, 32]");
    require(grow_angle_deg > 0 && grow_angle_deg < 90, "grow_angle_deg", grow_angle_deg, "in (0, 90)");
    require(grow_dist_m > 0, "grow_dist_m", grow_dist_m, "> 0");
    require(min_region_points >= 3, "min_region_points", min_region_points, ">= 3");
    require(merge_angle_deg > 0 && merge_angle_deg < 90, "merge_angle_deg", merge_angle_deg, "in (0, 90)");
    require(merge_dist_m > 0, "merge_dist_m", merge_dist_m, "> 0");
    require(on_plane_m > 0, "on_plane_m", on_plane_m, "> 0");
    require(on_plane_rel >= 0, "on_plane_rel", on_plane_rel, ">= 0");
    require(inlier_angle_deg > 0 && inlier_angle_deg < 90, "inlier_angle_deg", inlier_angle_deg, "in (0, 90)");
    require(min_extent > 0 && min_extent <= 1, "min_extent", min_extent, "in (0, 1]");
    require(min_up >= -1 && min_up <= 1, "min_up", min_up, "in [-1, 1]");
    require(max_object_height_m > 0, "max_object_height_m", max_object_height_m, "> 0");
    require(hull_margin_px >= 0, "hull_margin_px", hull_margin_px, ">= 0");
    require(island_min_height_m > 0, "island_min_height_m", island_min_height_m, "> 0");
    require(island_max_share >= 0 && island_max_share <= 1, "island_max_share", island_max_share, "in [0, 1]");
}

namespace {

/// Least-squares plane of a region's sums: the normal is the eigenvector of the smallest
/// eigenvalue of the scatter matrix, oriented towards the camera (d > 0).
Plane fit(const double* s) {
    Eigen::Vector3d c;
    Eigen::Matrix3d m;
    detail::mean_and_covariance(s, c, m);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
    Eigen::Vector3d normal = eig.eigenvectors().col(0);
    double d = -normal.dot(c);
    if (d < 0) {
        normal = -normal;
        d = -d;
    }
    Plane p;
    p.nx = static_cast<float>(normal.x());
    p.ny = static_cast<float>(normal.y());
    p.nz = static_cast<float>(normal.z());
    p.d = static_cast<float>(d);
    p.up = -p.ny;
    return p;
}

// ---------------------------------------------------------------------------------------
// The phases of remove_support_plane, in their order. Costs: N pixels, G = N / s^2 grid
// points (s = grid_stride_px), B regions worth fitting, C candidates. Scratch lives in the
// PlaneWorkspace; "no allocation" means none once the workspace has seen a frame of this
// size.
// ---------------------------------------------------------------------------------------

/// Gather: every grid point once, so that every later pass over the grid reads contiguous
/// arrays. In: the cloud, normals and active mask (N). Out: `gp`, G points; a point without
/// a usable normal (inactive, or no normal) gets the zero normal. O(G), one parallel pass,
/// no allocation.
void gather_grid(const Grid& grid, const OrganizedCloud& cloud, const NormalMap& normals,
                 const std::vector<std::uint8_t>& active, PlaneBuffers::GridPoints& gp) {
    const int W = grid.W;
    const auto G = static_cast<std::size_t>(grid.size());
    for (auto* a : {&gp.x, &gp.y, &gp.z, &gp.nx, &gp.ny, &gp.nz}) a->resize(G);
    gp.active.resize(G);
    gp.usable.resize(G);
#pragma omp parallel for schedule(static)
    for (int gv = 0; gv < grid.h; ++gv) {
        for (int gu = 0; gu < grid.w; ++gu) {
            const std::size_t g = static_cast<std::size_t>(gv) * grid.w + gu;
            const std::size_t p = static_cast<std::size_t>(gv) * grid.s * W + static_cast<std::size_t>(gu) * grid.s;
            gp.x[g] = cloud.x[p];
            gp.y[g] = cloud.y[p];
            gp.z[g] = cloud.z[p];
            // A point without a usable normal gets the zero normal: it then fails every
            // normal test (cos >= a positive threshold) with no branch (InlierTest).
            const bool use = active[p] && normals.valid[p];
            gp.nx[g] = use ? normals.nx[p] : 0.0f;
            gp.ny[g] = use ? normals.ny[p] : 0.0f;
            gp.nz[g] = use ? normals.nz[p] : 0.0f;
            gp.active[g] = active[p];
            gp.usable[g] = use;
        }
    }
}

struct GrownRegions {
    int regions = 0;              ///< regions grown, ids [0, regions)
    std::size_t with_normal = 0;  ///< usable grid points (all of them join a region)
};

/// 1. Region growing on the grid: a neighbour joins when its normal agrees with the
/// region's mean normal and it lies on the region's mean plane. In: `ws.grid`. Out:
/// `ws.region` (G: region id per point, -1 none), `ws.sums` (kSums per region: moments,
/// then summed normal). O(G), sequential flood fill on `ws.stack`; `ws.sums` grows by
/// kSums per region (no allocation once its capacity suffices).
GrownRegions grow_regions(const PlaneParams& params, const Grid& grid, PlaneBuffers& ws) {
    const int G = grid.size();
    ws.region.assign(static_cast<std::size_t>(G), -1);
    ws.stack.resize(static_cast<std::size_t>(G));
    ws.sums.clear();
    const float cos_grow = std::cos(params.grow_angle_deg * kDegToRad);
    const auto& gp = ws.grid;
    auto usable = [&](int g) { return gp.usable[static_cast<std::size_t>(g)] != 0; };
    GrownRegions grown;
    int& regions = grown.regions;
    for (int seed = 0; seed < G; ++seed) {
        if (ws.region[seed] != -1 || !usable(seed)) continue;
        const int id = regions++;
        ws.sums.resize(static_cast<std::size_t>(regions) * kSums, 0.0);
        double* s = ws.sums.data() + static_cast<std::size_t>(id) * kSums;
        int top = 0;
        ws.stack[top++] = seed;
        ws.region[seed] = id;
        while (top > 0) {
            const int g = ws.stack[--top];
            const std::size_t p = static_cast<std::size_t>(g);
            detail::add_moments(s, gp.x[p], gp.y[p], gp.z[p]);
            s[10] += gp.nx[p]; s[11] += gp.ny[p]; s[12] += gp.nz[p];
            const int gu = g % grid.w, gv = g / grid.w;
            const int nb[4] = {gu > 0 ? g - 1 : -1, gu + 1 < grid.w ? g + 1 : -1,
                               gv > 0 ? g - grid.w : -1, gv + 1 < grid.h ? g + grid.w : -1};
            // Most points popped have no free neighbour left: the region's mean is only
            // worked out when one has.
            int free_nb[4], n_free = 0;
            for (int q : nb)
                if (q >= 0 && ws.region[q] == -1 && usable(q)) free_nb[n_free++] = q;
            if (n_free == 0) continue;
            // Two divisions, not six: they were most of this loop's time.
            const double inv_nlen = 1.0 / std::sqrt(s[10] * s[10] + s[11] * s[11] + s[12] * s[12]);
            const double inv_count = 1.0 / s[0];
            const float mnx = static_cast<float>(s[10] * inv_nlen), mny = static_cast<float>(s[11] * inv_nlen),
                        mnz = static_cast<float>(s[12] * inv_nlen);
            const float cx = static_cast<float>(s[1] * inv_count), cy = static_cast<float>(s[2] * inv_count),
                        cz = static_cast<float>(s[3] * inv_count);
            for (int i = 0; i < n_free; ++i) {
                const int q = free_nb[i];
                const std::size_t pq = static_cast<std::size_t>(q);
                const float cosq = gp.nx[pq] * mnx + gp.ny[pq] * mny + gp.nz[pq] * mnz;
                if (cosq < cos_grow) continue;
                const float dist = std::fabs(mnx * (gp.x[pq] - cx) + mny * (gp.y[pq] - cy) +
                                             mnz * (gp.z[pq] - cz));
                if (dist > params.grow_dist_m + params.on_plane_rel * gp.z[pq] * gp.z[pq])
                    continue;
                ws.region[q] = id;
                ws.stack[top++] = q;
            }
        }
        grown.with_normal += static_cast<std::size_t>(s[0]);
    }
    return grown;
}

/// 2. Merge: fit the regions of at least min_region_points, and merge coplanar ones (a
/// table cut in pieces by the objects on it is one plane). In: `ws.sums` of `regions`.
/// Out: the merged regions' ids (their roots); each root's sums in `ws.sums` now hold its
/// whole merged set. O(B^2) plane pairs per pass for B regions worth fitting, two passes,
/// plus B eigen-solves (3x3) per pass; a few small vectors per frame.
std::vector<int> merge_coplanar(const PlaneParams& params, int regions, PlaneBuffers& ws) {
    std::vector<int> big;
    std::vector<Plane> fits(static_cast<std::size_t>(regions));
    for (int r = 0; r < regions; ++r) {
        const double* s = ws.sums.data() + static_cast<std::size_t>(r) * kSums;
        if (s[0] < params.min_region_points) continue;
        fits[r] = fit(s);
        big.push_back(r);
    }
    std::vector<int> parent(static_cast<std::size_t>(regions));
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
    };
    const float cos_merge = std::cos(params.merge_angle_deg * kDegToRad);
    std::vector<int> roots = big;
    // Two passes: pieces too noisy to match pairwise often match once merged (a slightly
    // warped table top seen in pieces between objects).
    for (int pass = 0; pass < 2; ++pass) {
        for (std::size_t i = 0; i < roots.size(); ++i)
            for (std::size_t j = i + 1; j < roots.size(); ++j) {
                const Plane &a = fits[roots[i]], &b = fits[roots[j]];
                if (a.nx * b.nx + a.ny * b.ny + a.nz * b.nz < cos_merge) continue;
                if (std::fabs(a.d - b.d) > params.merge_dist_m) continue;
                const int ra = find(roots[i]), rb = find(roots[j]);
                if (ra != rb) parent[rb] = ra;
            }
        std::vector<int> next;
        for (int r : roots) {
            const int root = find(r);
            if (root != r) {
                double* dst = ws.sums.data() + static_cast<std::size_t>(root) * kSums;
                const double* src = ws.sums.data() + static_cast<std::size_t>(r) * kSums;
                for (int q = 0; q < kSums; ++q) dst[q] += src[q];
            } else {
                next.push_back(r);
            }
        }
        roots = next;
        for (int r : roots) fits[r] = fit(ws.sums.data() + static_cast<std::size_t>(r) * kSums);
    }
    return roots;
}

/// 3. Candidates: the merged planes, fitted, that cover min_extent of the grid points with a
/// normal. Inliers are counted over the whole grid (distance and normal agree), the planes
/// split across cores and kept in order. In: `roots` and their `ws.sums`. Out: `ws.fitted`
/// (every root's plane), `candidates` appended. O(G) per root, parallel over roots; no
/// allocation but the candidates.
void fit_candidates(const PlaneParams& params, const std::vector<int>& roots, std::size_t with_normal,
                    const InlierTest& inliers, PlaneBuffers& ws, std::vector<Plane>& candidates) {
    auto& fitted = ws.fitted;
    fitted.resize(roots.size());
    const auto n_roots = static_cast<std::ptrdiff_t>(roots.size());
#pragma omp parallel for schedule(dynamic)
    for (std::ptrdiff_t i = 0; i < n_roots; ++i) {
        Plane& pl = fitted[static_cast<std::size_t>(i)];
        pl = fit(ws.sums.data() + static_cast<std::size_t>(roots[static_cast<std::size_t>(i)]) * kSums);
        pl.inliers = inliers.count(pl);
    }
    for (const Plane& pl : fitted)
        if (static_cast<double>(pl.inliers) >= params.min_extent * static_cast<double>(with_normal))
            candidates.push_back(pl);
}

/// The frame's bottom and side edges on the grid: the last row and the first and last
/// columns that hold an active point, where the band beyond is at most 1/8 of the image (a
/// Kinect v1's registration border without depth, a dataset's crop); -1 where it is wider,
/// a view past the depth range, which is no edge of the frame. As the scope's frame edge
/// (segmentation). Cost: the rows and columns of those bands, most frames a few.
struct GridEdges {
    int bottom = -1, left = -1, right = -1;
};
GridEdges find_grid_edges(const Grid& grid, const std::vector<std::uint8_t>& active) {
    auto row_active = [&](int gv) {
        const auto* row = active.data() + static_cast<std::size_t>(gv) * grid.w;
        return std::any_of(row, row + grid.w, [](std::uint8_t a) { return a != 0; });
    };
    auto col_active = [&](int gu) {
        for (int gv = 0; gv < grid.h; ++gv)
            if (active[static_cast<std::size_t>(gv) * grid.w + gu]) return true;
        return false;
    };
    GridEdges e;
    for (int k = 0; k <= grid.h / 8 && e.bottom < 0; ++k)
        if (row_active(grid.h - 1 - k)) e.bottom = grid.h - 1 - k;
    for (int k = 0; k <= grid.w / 8 && e.left < 0; ++k)
        if (col_active(k)) e.left = k;
    for (int k = 0; k <= grid.w / 8 && e.right < 0; ++k)
        if (col_active(grid.w - 1 - k)) e.right = grid.w - 1 - k;
    return e;
}

/// Where the support's inliers (`hull_points`, each row's outermost) reach the frame's
/// bottom edge and one of its sides (within a grid cell), the corner between them joins
/// the hull's points. The table runs out of the frame on both, toward the camera, and an
/// object standing in that corner hides whether the table's own corner lies there; its
/// feet had fallen off the hull (the books in the bottom-right corner of OSD's cluttered
/// frames). Not the top corners: beyond them lie the table's far side and the walls, and
/// with them the extent took in the lower halves of boards hanging on the wall. O(rows).
void add_near_corners(const GridEdges& e, std::vector<int>& hull_points) {
    if (e.bottom < 0) return;
    bool bottom = false, left = false, right = false;
    for (std::size_t i = 0; i + 3 < hull_points.size(); i += 4) {
        const int first = hull_points[i], gv = hull_points[i + 1], last = hull_points[i + 2];
        bottom |= gv >= e.bottom - 1;
        left |= e.left >= 0 && first <= e.left + 1;
        right |= e.right >= 0 && last >= e.right - 1;
    }
    if (!bottom) return;
    if (left) hull_points.insert(hull_points.end(), {e.left, e.bottom, e.left, e.bottom});
    if (right) hull_points.insert(hull_points.end(), {e.right, e.bottom, e.right, e.bottom});
}

/// The support's extent: the image-space convex hull of `pl`'s inliers on the grid, widened
/// by hull_margin_px, with the frame's near corners where the inliers reach them
/// (add_near_corners, the frame's `edges`); a point belongs over the support when its foot
/// (the point moved down the normal onto the plane) projects into it (HullMask). Out: `ws.hull` (G, 1 = inside;
/// all 0 when fewer than 3 rows hold inliers), `ws.hull_points`. O(G) for the inlier test,
/// then the hull of at most 2 grid.h points and a dilation over G; OpenCV allocates the
/// hull's corners and the kernel.
void build_hull(const PlaneParams& params, const Grid& grid, const GridEdges& edges,
                const InlierTest& is_inlier, const Plane& pl, PlaneBuffers& ws) {
    ws.hull.assign(static_cast<std::size_t>(grid.size()), 0);
    ws.hull_points.clear();
    // The hull of a set is the hull of each row's leftmost and rightmost members.
    for (int gv = 0; gv < grid.h; ++gv) {
        int first = -1, last = -1;
        for (int gu = 0; gu < grid.w; ++gu) {
            if (!is_inlier(pl, gv * grid.w + gu)) continue;
            if (first < 0) first = gu;
            last = gu;
        }
        if (first < 0) continue;
        ws.hull_points.insert(ws.hull_points.end(), {first, gv, last, gv});
    }
    if (ws.hull_points.size() < 6) return;
    add_near_corners(edges, ws.hull_points);
    cv::Mat pts(static_cast<int>(ws.hull_points.size() / 2), 1, CV_32SC2, ws.hull_points.data());
    std::vector<cv::Point> hull;
    cv::convexHull(pts, hull);
    cv::Mat mask(grid.h, grid.w, CV_8U, ws.hull.data());
    cv::fillConvexPoly(mask, hull, cv::Scalar(1));
    const int m = (params.hull_margin_px + grid.s - 1) / grid.s;
    if (m > 0) {
        const cv::Mat kernel =
            cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * m + 1, 2 * m + 1));
        cv::dilate(mask, mask, kernel);
    }
}

/// Slivers: candidates most of whose inliers (over half) are also the inliers of a larger
/// candidate. Such a plane cuts through the larger surface at a small angle (fitted to a few
/// points at an object's foot, or to noise on a carpet), and counting the points above it
/// would count half of that surface as standing on it: it won the support from the table it
/// cuts. `ws.sliver[rank]` for the candidates in ws.by_extent order (largest first; the 32
/// largest are tested: each covers min_extent of the grid, so there are rarely more than a
/// few). Inlier sets are one bit per candidate per grid point (`ws.candidate_bits`, G).
/// O(C x G) for the bits, O(G x C^2) at worst for the shared counts (points on two or more
/// candidates only); no allocation.
void mark_slivers(const std::vector<Plane>& candidates, const InlierTest& inliers, PlaneBuffers& ws) {
    const int G = inliers.G;
    const std::size_t C = std::min<std::size_t>(ws.by_extent.size(), 32);
    ws.sliver.assign(C, 0);
    if (C < 2) return;
    ws.candidate_bits.assign(static_cast<std::size_t>(G), 0);
    std::uint32_t* const bits = ws.candidate_bits.data();
    for (std::size_t rank = 0; rank < C; ++rank) {
        const Plane& pl = candidates[static_cast<std::size_t>(ws.by_extent[rank])];
        inliers.for_each(pl, [&](int g, bool in) { bits[g] |= static_cast<std::uint32_t>(in) << rank; });
    }
    // shared[i * C + j]: inliers of rank i that are also inliers of rank j < i.
    ws.shared.assign(C * C, 0);
    for (int g = 0; g < G; ++g) {
        const std::uint32_t b = bits[g];
        if ((b & (b - 1)) == 0) continue;  // on at most one candidate
        for (std::size_t i = 1; i < C; ++i) {
            if (!(b >> i & 1u)) continue;
            for (std::size_t j = 0; j < i; ++j) ws.shared[i * C + j] += b >> j & 1u;
        }
    }
    for (std::size_t i = 1; i < C; ++i) {
        const std::size_t inliers_i = candidates[static_cast<std::size_t>(ws.by_extent[i])].inliers;
        for (std::size_t j = 0; j < i; ++j)
            if (2 * static_cast<std::size_t>(ws.shared[i * C + j]) > inliers_i) ws.sliver[i] = 1;
    }
}

struct SupportChoice {
    int best = -1;     ///< index in the candidates, -1: no support
    int hull_of = -1;  ///< the candidate whose extent ws.hull holds, -1 none
};

/// 4. The support: among planes that face up (any way, with `any_facing`, but then holding
/// min_region_points at least), the one that carries most: score = points
/// standing on it (at most its extent; none where something taller than an object rises from
/// the same foot) + 0.1 x its extent. A candidate scores at most
/// 1.1 x its extent, so once one scores more, smaller candidates are not counted (each
/// count builds a hull and passes over the grid). Largest first; ties go to the lower
/// index, as in index order. In: `candidates`, `ws.grid`, the frame's `edges`. Out: the
/// choice; each counted candidate's `above`; `ws.by_extent`, `ws.sliver`, `ws.hull` of the last one counted.
/// O(C log C) to rank, mark_slivers, then O(G) (a hull, a pass and a parallel pass) per
/// candidate counted, usually one or two.
SupportChoice choose_support(const PlaneParams& params, const PinholeIntrinsics& K, const Grid& grid,
                             const GridEdges& edges, const InlierTest& inliers, bool any_facing, PlaneBuffers& ws,
                             std::vector<Plane>& candidates) {
    const int G = grid.size();
    const auto& gp = ws.grid;
    const Band on_band = inliers.band;
    SupportChoice choice;
    double best_score = -1;
    int& best = choice.best;
    ws.by_extent.resize(candidates.size());
    std::iota(ws.by_extent.begin(), ws.by_extent.end(), 0);
    std::stable_sort(ws.by_extent.begin(), ws.by_extent.end(), [&](int a, int b) {
        return candidates[static_cast<std::size_t>(a)].inliers >
               candidates[static_cast<std::size_t>(b)].inliers;
    });
    mark_slivers(candidates, inliers, ws);
    for (std::size_t rank = 0; rank < ws.by_extent.size(); ++rank) {
        const int c = ws.by_extent[rank];
        Plane& pl = candidates[static_cast<std::size_t>(c)];
        if ((!any_facing && pl.up < params.min_up) || (rank < ws.sliver.size() && ws.sliver[rank])) continue;
        const double extent = static_cast<double>(pl.inliers);
        if (extent + 0.1 * extent < best_score) break;  // the score's largest value, as computed
        build_hull(params, grid, edges, inliers, pl, ws);
        choice.hull_of = c;
        const HullMask hull = make_hull_mask(grid, K, pl, ws.hull);
        // What rises from its foot higher than anything standing on the plane is not an
        // object on it: a wall, or a table over the floor (its top over the cells its legs
        // and what lies under it stand on). Points whose foot shares a grid cell with such
        // a point's foot do not count: they made the floor of a room carry more than the
        // table with the objects (the feet of the walls and the table's legs). One thread:
        // an O(G) pass of byte stores.
        ws.tall_foot.assign(static_cast<std::size_t>(G), 0);
        for (int p = 0; p < G; ++p) {
            if (!gp.active[p]) continue;
            const float h = pl.height(gp.x[p], gp.y[p], gp.z[p]);
            if (h <= params.max_object_height_m) continue;
            const std::ptrdiff_t cell = hull.foot_cell(gp.x[p], gp.y[p], gp.z[p], h);
            if (cell >= 0) ws.tall_foot[static_cast<std::size_t>(cell)] = 1;
        }
        const std::uint8_t* const tall = ws.tall_foot.data();
        std::size_t above = 0;
#pragma omp parallel for schedule(static) reduction(+ : above)
        for (int p = 0; p < G; ++p) {
            if (!gp.active[p]) continue;
            const float h = pl.height(gp.x[p], gp.y[p], gp.z[p]);
            if (h <= on_band(gp.z[p]) || h > params.max_object_height_m) continue;
            const std::ptrdiff_t cell = hull.foot_cell(gp.x[p], gp.y[p], gp.z[p], h);
            above += cell >= 0 && hull.mask[cell] != 0 && tall[cell] == 0;
        }
        pl.above = above;
        if (any_facing && above < static_cast<std::size_t>(params.min_region_points)) continue;
        // Points standing on a plane count up to its own extent (a small tilted plane, a box
        // top, has half the room "above" it); extent alone breaks ties (the floor of an
        // uncropped scene is often larger than the table, but little stands on it).
        const double score = static_cast<double>(std::min(above, pl.inliers)) +
                             0.1 * static_cast<double>(pl.inliers);
        if (score > best_score || (score == best_score && c < best)) {
            best_score = score;
            best = c;
        }
    }
    return choice;
}

/// The least-squares plane (as `fit`) of the grid points that in(g) takes, into `out`;
/// false (and `out` unchanged) under min_points. Split across cores in a fixed number of
/// blocks added up in order, so the sums, and the plane, are the same bits on any number
/// of threads (an OpenMP reduction adds in the threads' order, and the pipeline runs this
/// stage on one thread or two from frame to frame). In a block, detail::add_moments spelled
/// out as masked sums, in its layout, so that they vectorize. O(G), one parallel pass, no
/// allocation.
template <class Take>
bool fit_grid_subset(const InlierTest& grid, int min_points, Take&& in, Plane& out) {
    const float *const gx = grid.x, *const gy = grid.y, *const gz = grid.z;
    const int G = grid.G;
    constexpr int kBlocks = 16, kMoments = detail::kMoments;  // n, x, y, z, xx, ... zz
    double block_sums[kBlocks][kMoments];
#pragma omp parallel for schedule(static)
    for (int b = 0; b < kBlocks; ++b) {
        const int g0 = static_cast<int>(static_cast<long long>(G) * b / kBlocks);
        const int g1 = static_cast<int>(static_cast<long long>(G) * (b + 1) / kBlocks);
        double n = 0, x = 0, y = 0, z = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
#pragma omp simd reduction(+ : n, x, y, z, xx, xy, xz, yy, yz, zz)
        for (int g = g0; g < g1; ++g) {
            const double m = in(g) ? 1.0 : 0.0;
            const double px = m * gx[g], py = m * gy[g], pz = m * gz[g];
            n += m;
            x += px; y += py; z += pz;
            xx += px * gx[g]; xy += px * gy[g]; xz += px * gz[g];
            yy += py * gy[g]; yz += py * gz[g]; zz += pz * gz[g];
        }
        const double sums[kMoments] = {n, x, y, z, xx, xy, xz, yy, yz, zz};
        std::copy(sums, sums + kMoments, block_sums[b]);
    }
    double s[kSums] = {};
    for (int b = 0; b < kBlocks; ++b)
        for (int k = 0; k < kMoments; ++k) s[k] += block_sums[b][k];
    if (s[0] < min_points) return false;
    out = fit(s);
    return true;
}

/// The lowest layer of the heights `t` (G of them, in half bands) that holds many points:
/// a histogram binned kPerBand to the half band over [-kRange, kRange), each bin's window
/// of one half band either side summed, and the lowest window with kLayerShare of the
/// densest one's points. Returns that window's centre, in half bands. O(G), one
/// sequential pass, then O(bins x window); no allocation.
float lowest_dense_layer(const float* t, int G) {
    constexpr int kPerBand = 8, kRange = 6, kBins = 2 * kRange * kPerBand;
    int histogram[kBins] = {};
    for (int g = 0; g < G; ++g) {
        const float bin = (t[g] + kRange) * kPerBand;
        if (bin >= 0.0f && bin < static_cast<float>(kBins)) ++histogram[static_cast<int>(bin)];
    }
    int window[kBins], most = 0;
    for (int c = 0; c < kBins; ++c) {
        window[c] = 0;
        for (int b = std::max(0, c - kPerBand); b < std::min(kBins, c + kPerBand); ++b)
            window[c] += histogram[b];
        most = std::max(most, window[c]);
    }
    constexpr float kLayerShare = 0.3f;
    int best_bin = 0;
    while (best_bin + 1 < kBins && static_cast<float>(window[best_bin]) < kLayerShare * static_cast<float>(most))
        ++best_bin;
    return static_cast<float>(best_bin) / kPerBand - kRange;
}

/// 5. The chosen plane, refined. Merges chain (each pair within merge_dist_m) from a
/// table's pieces to the tops of flat objects lying on it (books, magazines), and the
/// plane fitted to them all lies between the layers: 6 mm above the table on a cluttered
/// OSD frame, 7.6 mm in a synthetic scene of books, where half the books' points fell
/// into its band. On a band half as wide the layers part (a histogram of heights over
/// the chosen plane, in half bands, as the band widens with depth). The support is the
/// lowest layer that holds many points, not the densest: what lies on the table is
/// above it, and when the chain also tilts the plane the table's points spread over
/// several bands, where the densest can be a ramp from the table to the books' tops
/// (OSD's test59 at half resolution: 10 mm off the table). Least squares on that layer's
/// points, then on the points on the new plane's half band, fit it alone.
/// In: `chosen`, the gathered grid. Out: the support, its inliers counted (`above` is the
/// chosen one's); `ws.layer_t` (G). O(G): four passes (heights, histogram, two fits) and an
/// inlier count; no allocation.
Plane refine_support(const PlaneParams& params, const InlierTest& is_inlier, PlaneBuffers& ws,
                     const Plane& chosen) {
    const int G = is_inlier.G;
    const float *const gx = is_inlier.x, *const gy = is_inlier.y, *const gz = is_inlier.z;
    const float *const gnx = is_inlier.nx, *const gny = is_inlier.ny, *const gnz = is_inlier.nz;
    const float cos_inlier = is_inlier.cos_inlier;
    const Band on_band = is_inlier.band;
    // Heights over the chosen plane in half bands (far off lowest_dense_layer's histogram
    // where the normal does not face like the plane's).
    ws.layer_t.resize(static_cast<std::size_t>(G));
    float* const t = ws.layer_t.data();
    const float cnx = chosen.nx, cny = chosen.ny, cnz = chosen.nz, cd = chosen.d;
#pragma omp parallel for simd schedule(static)
    for (int g = 0; g < G; ++g) {
        const float h = cnx * gx[g] + cny * gy[g] + cnz * gz[g] + cd;
        const bool facing = gnx[g] * cnx + gny[g] * cny + gnz[g] * cnz >= cos_inlier;
        t[g] = facing ? h / (0.5f * on_band(gz[g])) : 1e9f;
    }
    const float layer = lowest_dense_layer(t, G);
    // First the histogram's window, then the new plane's half band.
    Plane pl = chosen;
    if (fit_grid_subset(is_inlier, params.min_region_points,
                        [=](int g) { return std::fabs(t[g] - layer) <= 1.0f; }, pl)) {
        const Plane first = pl;
        fit_grid_subset(is_inlier, params.min_region_points,
                        [=](int g) { return is_inlier(first, g, 0.5f); }, pl);
    }
    pl.inliers = is_inlier.count(pl);
    pl.above = chosen.above;
    return pl;
}

/// The refinement moved the plane enough that the chosen plane's extent no longer serves
/// (most frames it moves by under a millimetre). O(1).
bool support_moved(const PlaneParams& params, const Plane& chosen, const Plane& pl) {
    const float cos_moved = pl.nx * chosen.nx + pl.ny * chosen.ny + pl.nz * chosen.nz;
    return std::fabs(pl.d - chosen.d) > 0.25f * params.on_plane_m || cos_moved < std::cos(1.0f * kDegToRad);
}

/// No support: every active point is kept as object. Out: `classes` (N); returns the
/// points kept. O(N), two passes, no allocation.
std::size_t keep_all_active(const std::vector<std::uint8_t>& active, std::vector<std::uint8_t>& classes) {
    for (std::size_t p = 0; p < classes.size(); ++p) classes[p] = active[p] ? kPlaneObject : kPlaneRemoved;
    return static_cast<std::size_t>(std::count(classes.begin(), classes.end(), kPlaneObject));
}

/// The parameters for a camera `noise_widening` times noisier than `given` assume: the grow
/// angle (below 90 degrees), the band and the regions' distance (its z^2 term) widened.
PlaneParams widened_for_noise(const PlaneParams& given, float noise_widening) {
    if (!(noise_widening >= 1.0f) || !std::isfinite(noise_widening)) {
        std::ostringstream msg;
        msg << "plane noise widening = " << noise_widening << ": must be finite and >= 1";
        throw ParamError(msg.str());
    }
    PlaneParams params = given;
    params.grow_angle_deg = std::min(given.grow_angle_deg * noise_widening, std::max(given.grow_angle_deg, 89.0f));
    params.on_plane_m *= noise_widening;
    params.on_plane_rel *= noise_widening;
    return params;
}

}  // namespace

bool detail::fit_grid_points(const InlierTest& grid, int min_points, const std::uint8_t* take, Plane& out) {
    return fit_grid_subset(grid, min_points, [=](int g) { return take[g] != 0; }, out);
}

PlaneResult remove_support_plane(const PlaneParams& given, const PinholeIntrinsics& K,
                                 const OrganizedCloud& cloud, const NormalMap& normals,
                                 const std::vector<std::uint8_t>& active, PlaneWorkspace& workspace,
                                 std::vector<std::uint8_t>& classes, float noise_widening) {
    const PlaneParams params = widened_for_noise(given, noise_widening);
    PlaneBuffers& ws = workspace.buffers();
    classes.resize(cloud.size());
    PlaneResult result;
    const Grid grid = make_grid(cloud.width, cloud.height, params.grid_stride_px);
    gather_grid(grid, cloud, normals, active, ws.grid);
    const GridEdges edges = find_grid_edges(grid, ws.grid.active);  // the same for every hull
    const Band band{params.on_plane_m, params.on_plane_rel};
    const float cos_inlier = std::cos(params.inlier_angle_deg * kDegToRad);
    const auto& gp = ws.grid;
    const InlierTest inliers{gp.x.data(),  gp.y.data(),  gp.z.data(), gp.nx.data(), gp.ny.data(),
                             gp.nz.data(), grid.size(), band,        cos_inlier};

    // 1-3: planar regions, merged, fitted; those large enough are the candidates.
    const GrownRegions grown = grow_regions(params, grid, ws);
    const std::vector<int> roots = merge_coplanar(params, grown.regions, ws);
    fit_candidates(params, roots, grown.with_normal, inliers, ws, result.candidates);

    // 4-5: the support among them, refined.
    // Among the planes that face up in the image; when none does (a camera looking straight
    // down, to which the table faces as a wall would), among those that hold objects.
    SupportChoice choice = choose_support(params, K, grid, edges, inliers, false, ws, result.candidates);
    if (choice.best < 0) choice = choose_support(params, K, grid, edges, inliers, true, ws, result.candidates);
    if (choice.best < 0) {
        result.kept = keep_all_active(active, classes);
        return result;
    }
    result.found = true;
    const Plane& chosen = result.candidates[static_cast<std::size_t>(choice.best)];
    result.support = refine_support(params, inliers, ws, chosen);
    const Plane pl = result.support;
    // The support's extent: the chosen plane's serves unless the refinement moved the plane.
    if (choice.hull_of != choice.best || support_moved(params, chosen, pl))
        build_hull(params, grid, edges, inliers, pl, ws);

    // 6-7: every pixel classified; enclosed on-plane patches given back to the objects.
    std::size_t kept = detail::classify_pixels(grid, K, cloud, normals, active, pl, band, cos_inlier, ws, classes);
    kept += detail::restore_islands(params, cloud, active, pl, ws, classes);

    // 8: a board or tray lying on the support, the objects on it: background, as the support is.
    // Its layer keeps the given band: a board's top stands 1-5 cm over the support, within
    // the band of a noisy camera (an active-stereo one at 1.5 m: 2.5 cm). Its pixels take the
    // frame's band, as the support's do: that camera scatters them past the given one.
    InlierTest given_band = inliers;
    given_band.band = Band{given.on_plane_m, given.on_plane_rel};
    const std::size_t low_removed =
        detail::remove_low_support(params, grid, cloud, normals, given_band, pl, ws, classes, result.low_support, band);
    result.low_found = low_removed > 0;
    result.kept = kept - low_removed;
    return result;
}

}  // namespace wul3d
