#include "wul3d/segmentation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "param_check.hpp"
#include "wul3d/clustering.hpp"  // distance_f, ClusterParams: the kmeans segmenter
#include "wul3d/error.hpp"
#include "wul3d/normals.hpp"  // smooth_normals
#include "wul3d/plane.hpp"

namespace wul3d {

Scope parse_scope(const std::string& name) {
    if (name == "support") return Scope::Support;
    if (name == "scene") return Scope::Scene;
    throw ParamError("--scope '" + name + "': unknown (known: support, scene)");
}

const char* scope_name(Scope s) { return s == Scope::Support ? "support" : "scene"; }

Segmenter parse_segmenter(const std::string& name) {
    if (name == "geometric") return Segmenter::Geometric;
    if (name == "kmeans") return Segmenter::Kmeans;
    if (name == "hybrid") return Segmenter::Hybrid;
    throw ParamError("--segmenter '" + name + "': unknown (known: geometric, kmeans, hybrid)");
}

const char* segmenter_name(Segmenter s) {
    switch (s) {
        case Segmenter::Geometric: return "geometric";
        case Segmenter::Kmeans: return "kmeans";
        case Segmenter::Hybrid: return "hybrid";
    }
    return "?";
}

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "SegmentParams", name, value, range);
}
constexpr float kDegToRad = 3.14159265358979f / 180.0f;
}  // namespace

void SegmentParams::validate() const {
    if (min_points < 1) {
        std::ostringstream msg;
        msg << "--min-points " << min_points << ": must be >= 1";
        throw ParamError(msg.str());
    }
    require(depth_jump_m > 0, "depth_jump_m", depth_jump_m, "> 0");
    require(depth_jump_rel >= 0, "depth_jump_rel", depth_jump_rel, ">= 0");
    require(normal_smooth_px >= 0 && normal_smooth_px <= 16, "normal_smooth_px", normal_smooth_px, "in [0, 16]");
    require(crease_step_px >= 1 && crease_step_px <= 16, "crease_step_px", crease_step_px, "in [1, 16]");
    require(concavity > 0, "concavity", concavity, "> 0");
    require(reattach_px >= 0, "reattach_px", reattach_px, ">= 0");
    require(min_seed_points >= 1, "min_seed_points", min_seed_points, ">= 1");
    require(merge_max_concave >= 0 && merge_max_concave <= 1, "merge_max_concave", merge_max_concave, "in [0, 1]");
    require(merge_min_boundary >= 1, "merge_min_boundary", merge_min_boundary, ">= 1");
    require(color_alpha >= 0.002f && color_alpha <= 0.1f, "color_alpha", color_alpha,
            "in [0.002, 0.1] (the paper's range of alpha)");
    require(color_min_distance > 0, "color_min_distance", color_min_distance, "> 0");
    require(color_min_share > 0 && color_min_share <= 0.5f, "color_min_share", color_min_share, "in (0, 0.5]");
    require(color_max_boundary > 0 && color_max_boundary <= 1, "color_max_boundary", color_max_boundary, "in (0, 1]");
    require(color_max_crease_deg > 0, "color_max_crease_deg", color_max_crease_deg, "> 0");
    require(color_min_hue_deg > 0 && color_min_hue_deg < 90, "color_min_hue_deg", color_min_hue_deg, "in (0, 90)");
    require(rim_min_boundary == 0 || rim_min_boundary >= 3, "rim_min_boundary", rim_min_boundary, ">= 3, or 0 = off");
    require(rim_max_residual_m > 0, "rim_max_residual_m", rim_max_residual_m, "> 0");
    require(rim_min_arc > 0 && rim_min_arc <= 1, "rim_min_arc", rim_min_arc, "in (0, 1]");
    require(rim_inside_share > 0 && rim_inside_share <= 1, "rim_inside_share", rim_inside_share, "in (0, 1]");
    require(rim_height_tol_m > 0, "rim_height_tol_m", rim_height_tol_m, "> 0");
    require(gap_max_px >= 0, "gap_max_px", gap_max_px, ">= 0");
    require(scope_contact_m > 0, "scope_contact_m", scope_contact_m, "> 0");
    require(scope_max_height_m > 0, "scope_max_height_m", scope_max_height_m, "> 0");
    require(scope_max_outside >= 0 && scope_max_outside <= 1, "scope_max_outside", scope_max_outside, "in [0, 1]");
}

namespace {

struct Ctx {
    const SegmentParams& prm;
    const OrganizedCloud& c;
    const NormalMap& n;
    const std::vector<std::uint8_t>& cls;
    int W, H;

    bool connected(std::size_t p, std::size_t q, float steps = 1.0f) const {
        const float z = c.z[p];
        return std::fabs(z - c.z[q]) <= steps * (prm.depth_jump_m + prm.depth_jump_rel * z * z);
    }
    /// Paper-free LCCP test between two surface points: concave when the normals face
    /// each other across the step, (n_p - n_q) . (X_q - X_p) > 0.
    float concavity(std::size_t p, std::size_t q) const {
        const float dx = c.x[q] - c.x[p], dy = c.y[q] - c.y[p], dz = c.z[q] - c.z[p];
        const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(len > 1e-6f)) return 0.0f;
        return ((n.nx[p] - n.nx[q]) * dx + (n.ny[p] - n.ny[q]) * dy + (n.nz[p] - n.nz[q]) * dz) / len;
    }
};

/// Connected components of the pixels with `seedable[p]`, 4-connected where depth is
/// continuous; `ws.label` gets 1..n, returns n. Sizes in ws.sizes[1..n].
int components(const Ctx& x, const std::vector<std::uint8_t>& seedable, SegmentWorkspace& ws) {
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    std::fill(ws.label.begin(), ws.label.end(), 0);
    ws.sizes.assign(1, 0);
    int n = 0;
    for (std::size_t seed = 0; seed < N; ++seed) {
        if (!seedable[seed] || ws.label[seed]) continue;
        const int id = ++n;
        int head = 0, tail = 0;
        ws.queue[tail++] = static_cast<int>(seed);
        ws.label[seed] = id;
        while (head < tail) {
            const int p = ws.queue[head++];
            const int u = p % W, v = p / W;
            const int nb[4] = {u > 0 ? p - 1 : -1, u + 1 < W ? p + 1 : -1, v > 0 ? p - W : -1,
                               v + 1 < H ? p + W : -1};
            for (int q : nb) {
                if (q < 0 || !seedable[q] || ws.label[q]) continue;
                if (!x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) continue;
                ws.label[q] = id;
                ws.queue[tail++] = q;
            }
        }
        ws.sizes.push_back(tail);
    }
    return n;
}

/// Grows the labelled pixels into unlabelled foreground (cut pixels, feet, pixels without a
/// normal, dropped fragments) breadth-first, up to `max_steps`, where depth is continuous.
/// With `inside_only`, grows only into kPlaneInside pixels (a container's inside joins the
/// container, however wide).
std::size_t reattach(const Ctx& x, SegmentWorkspace& ws, int max_steps, bool inside_only = false) {
    const int W = x.W, H = x.H;
    int head = 0, tail = 0;
    // Only labelled pixels with a neighbour they may grow into start the search, in raster
    // order: the others would find nothing to label, so leaving them out changes no label.
    // Found per band of rows in parallel (each band's seeds at its own rows' offset in the
    // queue), then packed in band order.
    auto grows_into = [&](std::size_t q) {
        return !ws.label[q] && x.cls[q] != kPlaneRemoved && (!inside_only || x.cls[q] == kPlaneInside);
    };
    constexpr int kBands = 8;
    int band_seeds[kBands];
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        const int v0 = H * band / kBands, v1 = H * (band + 1) / kBands;
        int* const seeds = ws.queue.data() + static_cast<std::size_t>(v0) * W;
        int count = 0;
        for (int v = v0; v < v1; ++v)
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                ws.dist[p] = ws.label[p] ? 0 : -1;
                if (!ws.label[p]) continue;
                if ((u > 0 && grows_into(p - 1)) || (u + 1 < W && grows_into(p + 1)) ||
                    (v > 0 && grows_into(p - W)) || (v + 1 < H && grows_into(p + W)))
                    seeds[count++] = static_cast<int>(p);
            }
        band_seeds[band] = count;
    }
    for (int band = 0; band < kBands; ++band) {
        // Packed forwards: the destination never lies past the source.
        const int* const seeds = ws.queue.data() + static_cast<std::size_t>(H * band / kBands) * W;
        if (seeds != ws.queue.data() + tail) std::copy(seeds, seeds + band_seeds[band], ws.queue.data() + tail);
        tail += band_seeds[band];
    }
    std::size_t added = 0;
    while (head < tail) {
        const int p = ws.queue[head++];
        if (ws.dist[p] >= max_steps) continue;
        const int u = p % W, v = p / W;
        const int nb[4] = {u > 0 ? p - 1 : -1, u + 1 < W ? p + 1 : -1, v > 0 ? p - W : -1,
                           v + 1 < H ? p + W : -1};
        for (int q : nb) {
            if (q < 0 || ws.label[q] || x.cls[q] == kPlaneRemoved) continue;
            if (inside_only && x.cls[q] != kPlaneInside) continue;
            // The inside is enclosed by the object, whatever the depth step at its edge.
            if (!inside_only && !x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) continue;
            ws.label[q] = ws.label[p];
            ws.dist[q] = ws.dist[p] + 1;
            ws.queue[tail++] = q;
            ++added;
        }
    }
    return added;
}

/// Drops labels with fewer than min_points pixels and writes the rest to `out` renumbered
/// 1..n in order of first appearance (raster order); ws.label keeps the old numbers. Returns
/// n. Each half of the image (in parallel) counts its labels' pixels and first pixel, the
/// labels are numbered, then `out` is written in parallel. Two halves only: the labels run
/// up to the number of components, tiny fragments included, and each half keeps a row of
/// them.
int compact(SegmentWorkspace& ws, int n, int min_points, std::uint16_t* out) {
    constexpr int kBands = 2;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const std::size_t B = (L + 15) / 16 * 16;  // a band's row, whole cache lines (no false sharing)
    const auto N = static_cast<std::ptrdiff_t>(ws.label.size());
    ws.sizes.assign(kBands * B, 0);  // per band: pixels
    ws.offsets.resize(kBands * B);   // per band: first pixel, valid where it has pixels
    int* const label = ws.label.data();
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        int* const count = ws.sizes.data() + static_cast<std::size_t>(band) * B;
        int* const first = ws.offsets.data() + static_cast<std::size_t>(band) * B;
        for (std::ptrdiff_t p = N * band / kBands; p < N * (band + 1) / kBands; ++p) {
            const auto l = static_cast<std::size_t>(label[p]);
            if (count[l]++ == 0) first[l] = static_cast<int>(p);
        }
    }
    // Labels in order of their first pixel; the large enough ones numbered in that order.
    ws.order.clear();
    for (std::size_t l = 1; l < L; ++l) {
        int size = 0, first = std::numeric_limits<int>::max();
        for (int band = 0; band < kBands; ++band) {
            const int count = ws.sizes[static_cast<std::size_t>(band) * B + l];
            if (count == 0) continue;
            size += count;
            first = std::min(first, ws.offsets[static_cast<std::size_t>(band) * B + l]);
        }
        ws.sizes[l] = size;  // band 0's row now holds the totals
        ws.offsets[l] = first;
        if (size >= min_points) ws.order.push_back(static_cast<int>(l));
    }
    std::sort(ws.order.begin(), ws.order.end(), [&](int a, int b) {
        return ws.offsets[static_cast<std::size_t>(a)] < ws.offsets[static_cast<std::size_t>(b)];
    });
    ws.remap.assign(L, 0);
    int next = 0;
    for (const int l : ws.order) ws.remap[static_cast<std::size_t>(l)] = ++next;
    const int* const remap = ws.remap.data();
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < N; ++p) out[p] = static_cast<std::uint16_t>(std::min(remap[label[p]], 65535));
    return next;
}

int find_root(std::vector<int>& parent, int a) {
    while (parent[static_cast<std::size_t>(a)] != a) {
        parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
        a = parent[static_cast<std::size_t>(a)];
    }
    return a;
}

/// Union-find over segments 0..n, each its own set.
void reset_sets(std::vector<int>& parent, int n) {
    parent.resize(static_cast<std::size_t>(n) + 1);
    for (int l = 0; l <= n; ++l) parent[static_cast<std::size_t>(l)] = l;
}

/// Joins the sets of segments a and b (the smaller root stays root); false when already one.
bool join_sets(std::vector<int>& parent, int a, int b) {
    const int ra = find_root(parent, a), rb = find_root(parent, b);
    if (ra == rb) return false;
    parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    return true;
}

/// Every labelled pixel takes its set's root.
void relabel_to_roots(SegmentWorkspace& ws) {
    for (int& l : ws.label)
        if (l) l = find_root(ws.parent, l);
}

/// Joins segments that touch along a boundary that is mostly not concave. Each 4-neighbour
/// pair (p, q) of two segments with continuous depth is tested for a crease between the
/// pixels a crease step away on either side, inside their own segments; the pair of
/// segments merges when enough pairs were tested and few were concave. Returns the merges.
int merge_convex(const Ctx& x, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    if (prm.merge_max_concave <= 0 || n < 2) return 0;
    const int W = x.W, H = x.H, s = prm.crease_step_px;
    ws.edges.clear();
    for (int v = 0; v < H; ++v) {
        for (int u = 0; u < W; ++u) {
            const int p = v * W + u;
            const int a = ws.label[static_cast<std::size_t>(p)];
            if (a == 0) continue;
            const int dirs[2][2] = {{1, 0}, {0, 1}};
            for (const auto& d : dirs) {
                if (u + d[0] >= W || v + d[1] >= H) continue;
                const int q = p + d[0] + d[1] * W;
                const int b = ws.label[static_cast<std::size_t>(q)];
                if (b == 0 || b == a) continue;
                if (!x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) continue;
                const int pu = u - s * d[0], pv = v - s * d[1];
                const int qu = u + d[0] + s * d[0], qv = v + d[1] + s * d[1];
                std::uint64_t tested = 0, concave = 0;
                if (pu >= 0 && pv >= 0 && qu < W && qv < H) {
                    const std::size_t pp = static_cast<std::size_t>(pv) * W + pu;
                    const std::size_t qq = static_cast<std::size_t>(qv) * W + qu;
                    if (ws.label[pp] == a && ws.label[qq] == b && x.n.valid[pp] && x.n.valid[qq]) {
                        tested = 1;
                        concave = x.concavity(pp, qq) > prm.concavity;
                    }
                }
                const auto lo = static_cast<std::uint64_t>(std::min(a, b));
                const auto hi = static_cast<std::uint64_t>(std::max(a, b));
                ws.edges.push_back((lo << 34) | (hi << 4) | (tested << 1) | concave);
            }
        }
    }
    std::sort(ws.edges.begin(), ws.edges.end());
    reset_sets(ws.parent, n);
    int merges = 0;
    for (std::size_t i = 0; i < ws.edges.size();) {
        const std::uint64_t key = ws.edges[i] >> 4;
        int tested = 0, concave = 0;
        for (; i < ws.edges.size() && (ws.edges[i] >> 4) == key; ++i) {
            tested += static_cast<int>((ws.edges[i] >> 1) & 1);
            concave += static_cast<int>(ws.edges[i] & 1);
        }
        if (tested < prm.merge_min_boundary ||
            static_cast<float>(concave) > prm.merge_max_concave * static_cast<float>(tested))
            continue;
        merges += join_sets(ws.parent, static_cast<int>(key >> 30), static_cast<int>(key & ((1u << 30) - 1)));
    }
    if (merges > 0) relabel_to_roots(ws);
    return merges;
}

/// The container rule (SegmentParams, "Containers"): a segment seen over another's circular,
/// level edge across a depth step, lying inside that circle and reaching up to it, is the
/// other's inside (a bowl's or a cup's) and joins it. Returns the joins.
int join_containers(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    if (prm.rim_min_boundary <= 0 || n < 2) return 0;
    const int W = x.W, H = x.H;
    const auto& label = ws.label;
    // One pass: the boundary pairs of two segments, keyed (lo, hi, depth step, lo is nearer)
    // with the nearer pixel, and each segment's rows.
    constexpr std::uint64_t kPairMask = ~std::uint64_t{15};
    ws.steps.clear();
    ws.rim_rows.assign(2 * (static_cast<std::size_t>(n) + 1), -1);
    for (int v = 0; v < H; ++v)
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
    std::sort(ws.steps.begin(), ws.steps.end(),
              [](const BoundaryStep& l, const BoundaryStep& r) { return l.key < r.key; });
    // Coordinates on the support plane: e1, e2 orthogonal to its normal (a foot's position
    // is the point's).
    const Eigen::Vector3d nrm(pl.nx, pl.ny, pl.nz);
    int least = 0;  // the axis least aligned with the normal: a well-conditioned cross product
    nrm.cwiseAbs().minCoeff(&least);
    const Eigen::Vector3d e1 = nrm.cross(Eigen::Vector3d::Unit(least)).normalized(), e2 = nrm.cross(e1);
    auto plane_xy = [&](std::size_t p) {
        const Eigen::Vector3d X(x.c.x[p], x.c.y[p], x.c.z[p]);
        return Eigen::Vector2d(X.dot(e1), X.dot(e2));
    };
    // Candidates: pairs that meet (almost) only across depth steps; the front is the segment
    // nearer along them. A circle is fitted to the front's edge pixels along the steps
    // (algebraic least squares, Kasa, centred on the edge's mean for conditioning) and kept
    // when the edge lies on it and spans enough of it. rim_fits per candidate: front, back,
    // centre (2), radius, rim height.
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
        // The edge: nearer pixels of the steps that lie in the front.
        auto for_edge = [&](auto&& visit) {
            for (std::size_t j = i0; j < i; ++j)
                if (((ws.steps[j].key >> 1) & 1) && label[ws.steps[j].near] == front) visit(ws.steps[j].near);
        };
        double m = 0, height = 0;
        Eigen::Vector2d mean = Eigen::Vector2d::Zero();
        for_edge([&](std::size_t p) {
            ++m;
            mean += plane_xy(p);
            height += pl.height(x.c.x[p], x.c.y[p], x.c.z[p]);
        });
        if (m < 3) continue;
        mean /= m;
        height /= m;
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
        Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
        for_edge([&](std::size_t p) {
            const Eigen::Vector2d d = plane_xy(p) - mean;
            const Eigen::Vector3d row(d.x(), d.y(), 1.0);
            A += row * row.transpose();
            rhs -= row * d.squaredNorm();
        });
        const Eigen::Vector3d sol = A.ldlt().solve(rhs);
        const Eigen::Vector2d centre(-sol.x() / 2, -sol.y() / 2);
        const double R2 = centre.squaredNorm() - sol.z();
        if (!(R2 > 0) || !std::isfinite(R2)) continue;
        const double R = std::sqrt(R2);
        // Geometric residual, and the widest chord: the farthest edge pixel from the mean,
        // then the farthest from that one.
        double res = 0, far_d = -1, chord = 0;
        Eigen::Vector2d far = Eigen::Vector2d::Zero();
        for_edge([&](std::size_t p) {
            const Eigen::Vector2d d = plane_xy(p) - mean;
            const double r = (d - centre).norm() - R;
            res += r * r;
            if (d.norm() > far_d) {
                far_d = d.norm();
                far = d;
            }
        });
        for_edge([&](std::size_t p) { chord = std::max(chord, (plane_xy(p) - mean - far).norm()); });
        if (std::sqrt(res / m) > prm.rim_max_residual_m || chord < prm.rim_min_arc * 2 * R) continue;
        ws.rim_fits.push_back({static_cast<double>(front), static_cast<double>(back), centre.x() + mean.x(),
                               centre.y() + mean.y(), R, height});
    }
    const int C = static_cast<int>(ws.rim_fits.size());
    if (C == 0) return 0;
    // The back segments' feet: the share inside the circle, and their top, over the rows the
    // back segments span. A back segment may sit behind several fronts: rim_next links its
    // candidates. rim_back per candidate: pixels, inside, top.
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
        const int l = label[p];
        if (l == 0) continue;
        int c = ws.remap[static_cast<std::size_t>(l)];
        if (c < 0) continue;
        const Eigen::Vector2d f = plane_xy(p);
        const double h = pl.height(x.c.x[p], x.c.y[p], x.c.z[p]);
        for (; c >= 0; c = ws.rim_next[static_cast<std::size_t>(c)]) {
            const auto& fit = ws.rim_fits[static_cast<std::size_t>(c)];
            auto& b = ws.rim_back[static_cast<std::size_t>(c)];
            b[0] += 1;
            b[1] += (f - Eigen::Vector2d(fit[2], fit[3])).norm() <= 1.1 * fit[4] + 0.01;
            b[2] = std::max(b[2], h);
        }
    }
    reset_sets(ws.parent, n);
    int joins = 0;
    for (int c = 0; c < C; ++c) {
        const auto& fit = ws.rim_fits[static_cast<std::size_t>(c)];
        const auto& b = ws.rim_back[static_cast<std::size_t>(c)];
        if (b[1] < prm.rim_inside_share * b[0] || std::fabs(b[2] - fit[5]) > prm.rim_height_tol_m) continue;
        joins += join_sets(ws.parent, static_cast<int>(fit[0]), static_cast<int>(fit[1]));
    }
    if (joins > 0) relabel_to_roots(ws);
    return joins;
}

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
            const int nb[4] = {pu > 0 ? p - 1 : -1, pu + 1 < W ? p + 1 : -1, pv > 0 ? p - W : -1,
                               pv + 1 < H ? p + W : -1};
            for (int q : nb) {
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

/// The colour cue: tries to split each segment in two by 2-means under the paper's
/// distance (eq. 4, 6) with a colour-heavy alpha; keeps a split only when the parts differ
/// in colour, are large, meet along a short boundary across a smooth surface.
int color_splits(const Ctx& x, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    const int W = x.W;
    const std::size_t N = static_cast<std::size_t>(W) * x.H;
    // Counting sort of the segments' pixels by segment (background left out), per fixed
    // band of rows in parallel: counts per band, then each band writes from its own start
    // (segment by segment, bands in order), so every segment lists its pixels in raster order.
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
    // part is written for a segment's pixels before anything reads them: no clearing.
    ws.part.resize(N);
    ws.part_in_order.resize(static_cast<std::size_t>(position));
    ws.split.assign(static_cast<std::size_t>(n) + 1, 0);
    // Features gathered in segment order, one plane each: every pass below reads contiguous
    // memory. Scaled by the paper's delta and alpha (eq. 4) so a squared distance is a sum.
    // Only the segments' pixels (order positions first..last) are gathered: plane q holds
    // position i at f[q][i - first], sized by the object pixels, not the image.
    ClusterParams cp;
    cp.alpha = prm.color_alpha;
    cp.delta = 1.0f - prm.color_alpha;
    const int first = ws.offsets[1], last = ws.offsets[static_cast<std::size_t>(n) + 1];
    const std::size_t M = static_cast<std::size_t>(last - first);
    ws.feature.resize(6 * M);
    float* f[6];
    for (int q = 0; q < 6; ++q) f[q] = ws.feature.data() + static_cast<std::size_t>(q) * M;
    // The colour term is the chromaticity, rgb / (r + g + b), at the scale of 8-bit colour
    // (a grey pixel of any brightness: 85, 85, 85): light falling on two faces of one box at
    // other angles scales their colour and leaves it, so the two parts are two materials,
    // not a lit face and a shaded one. kDark keeps the chromaticity of dark, noisy pixels
    // near grey.
    constexpr float kDark = 30.0f;
    auto chroma = [&](std::size_t p, float* out) {
        const float r = x.c.r[p], g = x.c.g[p], b = x.c.b[p];
        const float k = 255.0f / (r + g + b + kDark);
        out[0] = k * (r + kDark / 3), out[1] = k * (g + kDark / 3), out[2] = k * (b + kDark / 3);
    };
#pragma omp parallel for schedule(static)
    for (int i = first; i < last; ++i) {
        const std::size_t p = static_cast<std::size_t>(ws.order[static_cast<std::size_t>(i)]);
        f[0][i - first] = cp.delta * x.c.x[p];
        f[1][i - first] = cp.delta * x.c.y[p];
        f[2][i - first] = cp.delta * x.c.z[p];
        float c[3];
        chroma(p, c);
        f[3][i - first] = cp.alpha * c[0];
        f[4][i - first] = cp.alpha * c[1];
        f[5][i - first] = cp.alpha * c[2];
    }
    const float cos_crease = std::cos(prm.color_max_crease_deg * kDegToRad);
    const int s = prm.crease_step_px;
    // Each segment large enough to split is tried on its own (in parallel, the largest
    // first so that no thread is left with a big one at the end); split ids are given out
    // in segment order afterwards so the labels do not depend on the threads.
    auto size_of = [&](int l) {
        return ws.offsets[static_cast<std::size_t>(l) + 1] - ws.offsets[static_cast<std::size_t>(l)];
    };
    ws.by_size.clear();
    for (int l = 1; l <= n; ++l)
        if (size_of(l) >= 2 * prm.min_points) ws.by_size.push_back(l);
    std::stable_sort(ws.by_size.begin(), ws.by_size.end(), [&](int a, int b) { return size_of(a) > size_of(b); });
    const auto n_tried = static_cast<std::ptrdiff_t>(ws.by_size.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::ptrdiff_t t = 0; t < n_tried; ++t) {
        const int l = ws.by_size[static_cast<std::size_t>(t)];
        const int o = ws.offsets[static_cast<std::size_t>(l)];
        const int* px = ws.order.data() + o;
        const int m = size_of(l);
        const int fo = o - first;  // the segment's first position in the feature planes
        std::uint8_t* part = ws.part.data();
        // Seeds: the pixel farthest in colour (the feature's) from the mean, then the one
        // farthest from it.
        const float *const cr = f[3] + fo, *const cg = f[4] + fo, *const cb = f[5] + fo;
        double mr = 0, mg = 0, mb = 0;
        for (int i = 0; i < m; ++i) {
            mr += cr[i]; mg += cg[i]; mb += cb[i];
        }
        mr /= m; mg /= m; mb /= m;
        auto farthest = [&](double r, double g, double b) {
            int best = 0;
            double bd = -1;
            for (int i = 0; i < m; ++i) {
                const double dr = cr[i] - r, dg = cg[i] - g, db = cb[i] - b;
                const double d = dr * dr + dg * dg + db * db;
                if (d > bd) { bd = d; best = i; }
            }
            return best;
        };
        const int a0 = farthest(mr, mg, mb);
        // The parts' mean colours lie among the segment's colours, so they are at most the
        // segment's colour diameter apart, at most twice the farthest colour from the mean:
        // below the minimum distance no split can be kept.
        {
            const double dr = cr[a0] - mr, dg = cg[a0] - mg, db = cb[a0] - mb;
            if (2 * std::sqrt(dr * dr + dg * dg + db * db) < prm.color_min_distance * cp.alpha) continue;
        }
        const int b0 = farthest(cr[a0], cg[a0], cb[a0]);
        float cen[2][6];
        for (int q = 0; q < 6; ++q) {
            cen[0][q] = f[q][fo + a0];
            cen[1][q] = f[q][fo + b0];
        }
        // Totals once: part 0's sums are the totals minus part 1's.
        double total[6] = {};
        for (int q = 0; q < 6; ++q)
            for (int i = 0; i < m; ++i) total[q] += f[q][fo + i];
        std::uint8_t* const side = ws.part_in_order.data() + o;
        int count[2] = {0, 0};
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
                for (int i = i0; i < i1; ++i) {
                    float dot = 0;
                    for (int q = 0; q < 6; ++q) dot += w[q] * f[q][fo + i];
                    const std::uint8_t j = dot < bias;
                    block_changed += j != side[i];
                    side[i] = j;
                    block_ones += j;
                    const float mask = j;
                    for (int q = 0; q < 6; ++q) block[q] += mask * f[q][fo + i];
                }
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
        for (int i = 0; i < m; ++i) part[px[i]] = side[i];
        const int small = std::min(count[0], count[1]);
        if (small < prm.min_points || static_cast<float>(small) < prm.color_min_share * static_cast<float>(m)) continue;
        const float dr = (cen[0][3] - cen[1][3]) / cp.alpha, dg = (cen[0][4] - cen[1][4]) / cp.alpha,
                    db = (cen[0][5] - cen[1][5]) / cp.alpha;
        if (std::sqrt(dr * dr + dg * dg + db * db) < prm.color_min_distance) continue;
        // Boundary: 4-neighbour pairs inside the segment with different parts; the normals a
        // crease step away on either side tell a smooth surface from a fold.
        // The smaller part's outline: 4-neighbour pairs from it to anything else.
        const std::uint8_t small_part = count[0] < count[1] ? 0 : 1;
        int boundary = 0, with_normals = 0, smooth = 0, small_outline = 0;
        for (int i = 0; i < m; ++i) {
            const int p = px[i];
            const int u = p % W, v = p / W;
            if (part[p] == small_part) {
                const int nb[4] = {u > 0 ? p - 1 : -1, u + 1 < W ? p + 1 : -1, v > 0 ? p - W : -1,
                                   v + 1 < x.H ? p + W : -1};
                for (const int q : nb)
                    small_outline += q < 0 || ws.label[q] != l || part[q] != small_part;
            }
            const int dirs[2][2] = {{1, 0}, {0, 1}};
            for (const auto& dd : dirs) {
                if (u + dd[0] >= W || v + dd[1] >= x.H) continue;
                const int q = p + dd[0] + dd[1] * W;
                if (ws.label[q] != l || part[q] == part[p]) continue;
                ++boundary;
                const int pu = u - s * dd[0], pv = v - s * dd[1];
                const int qu = u + dd[0] + s * dd[0], qv = v + dd[1] + s * dd[1];
                if (pu < 0 || pv < 0 || qu >= W || qv >= x.H) continue;
                const int a = pv * W + pu, b = qv * W + qu;
                if (!x.n.valid[a] || !x.n.valid[b]) continue;
                smooth += x.n.nx[a] * x.n.nx[b] + x.n.ny[a] * x.n.ny[b] + x.n.nz[a] * x.n.nz[b] >= cos_crease;
                ++with_normals;
            }
        }
        // A contact between two objects is one side of the smaller one's outline; a split
        // along a texture (stripes, print) runs round most of each piece.
        if (static_cast<float>(boundary) > prm.color_max_boundary * static_cast<float>(small_outline)) continue;
        // Most of the boundary must cross a smooth surface (a few pairs near a box's corner
        // straddle its edge), or the parts must differ in chromaticity: light falling on two
        // faces of one box at other angles scales their colour, it does not turn it, so
        // across a fold (a flat box on another, flush boxes of two heights) only a change of
        // material turns the mean colour by color_min_hue_deg.
        const bool across_smooth = with_normals > 0 && 10 * smooth >= 7 * with_normals;
        if (!across_smooth) {
            const float r0 = cen[0][3], g0 = cen[0][4], b0c = cen[0][5];
            const float r1 = cen[1][3], g1 = cen[1][4], b1c = cen[1][5];
            const float dot = r0 * r1 + g0 * g1 + b0c * b1c;
            const float norms = std::sqrt((r0 * r0 + g0 * g0 + b0c * b0c) * (r1 * r1 + g1 * g1 + b1c * b1c));
            if (!(norms > 0) || dot >= std::cos(prm.color_min_hue_deg * kDegToRad) * norms) continue;
        }
        ws.split[static_cast<std::size_t>(l)] = 1;
    }
    int splits = 0, next = n;
    for (int l = 1; l <= n; ++l) {
        if (!ws.split[static_cast<std::size_t>(l)]) continue;
        const int id = ++next;
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

/// Scope::Support (docs/DESIGN.md, "Scope"): keeps the segments the support holds and
/// clears the others' labels in ws.label. In: ws.label (1..n with gaps), the support, the
/// plane's classes. Out: the number of segments of min_points or more left out. Cost: one
/// pass over the pixels (heights, outlines, touching pairs), then a few passes over the
/// touching pairs until "rests on" stops spreading.
int restrict_to_support(const Ctx& x, const Plane& pl, SegmentWorkspace& ws, int n) {
    const int W = x.W, H = x.H;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    ws.scope_lo.assign(L, std::numeric_limits<float>::max());
    ws.scope_hi.assign(L, -std::numeric_limits<float>::max());
    ws.scope_high.assign(L, 0);
    ws.scope_outline.assign(L, 0);
    ws.scope_outside.assign(L, 0);
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
        return height(q) > prm.depth_jump_m + prm.depth_jump_rel * z * z;
    };
    // The frame's edge: the image border and the rows and columns with no depth at all that
    // reach it, when they are a narrow band (a sensor's registration border: 48 rows and 63
    // columns of a Kinect v1's 640x480). A segment cut there goes on out of view. A wider
    // band without depth is a view past the depth range or a crop, which says nothing of
    // what the segment does there.
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
    // The support's middle in depth: the mean depth of the removed points on it. Walls and
    // furniture leave the volume beyond it; on the near half an object cut by the frame (at
    // the bottom or the sides of a tabletop view), or by the hull where the frame hides the
    // table's near edge, is still on the table.
    double table_z = 0, table_n = 0;
    for (std::size_t p = 0; p < x.c.size(); ++p) {
        if (!x.c.valid[p] || x.cls[p] != kPlaneRemoved) continue;
        const float z = x.c.z[p];
        if (std::fabs(height(p)) > prm.depth_jump_m + prm.depth_jump_rel * z * z) continue;
        table_z += z;
        table_n += 1;
    }
    const float far_z = table_n > 0 ? static_cast<float>(table_z / table_n) : 0.0f;
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
    for (int v = top; v < bottom; ++v)
        for (int u = left; u < right; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (const int l = label[p]) {
                const float h = height(p);
                const auto li = static_cast<std::size_t>(l);
                ws.scope_lo[li] = std::min(ws.scope_lo[li], h);
                ws.scope_hi[li] = std::max(ws.scope_hi[li], h);
                ws.scope_high[li] += h > prm.scope_max_height_m;
                ++ws.sizes[li];
                // On the frame's edge, beyond the support's middle.
                const int on_edge = x.c.z[p] > far_z ? (v == edge_top) + (u == edge_left) +
                                                           (u == edge_right) + (v == edge_bottom)
                                                     : 0;
                ws.scope_outline[li] += on_edge;
                ws.scope_outside[li] += on_edge;
            }
            if (u + 1 < right) pair(p, p + 1);
            if (v + 1 < bottom) pair(p, p + static_cast<std::size_t>(W));
        }
    std::sort(ws.edges.begin(), ws.edges.end());
    ws.edges.erase(std::unique(ws.edges.begin(), ws.edges.end()), ws.edges.end());
    // Inside the volume: under the height limit (2 % of the points may be noise) and not
    // running on past the hull or out of view. Stands: the lowest point touches the support.
    // scope_keep: bit 0 inside, bit 1 kept.
    auto& keep = ws.scope_keep;
    keep.assign(L, 0);
    for (std::size_t l = 1; l < L; ++l) {
        if (ws.sizes[l] == 0) continue;
        const bool inside = 50 * ws.scope_high[l] <= ws.sizes[l] &&
                            static_cast<float>(ws.scope_outside[l]) <=
                                prm.scope_max_outside * static_cast<float>(ws.scope_outline[l]);
        keep[l] = static_cast<std::uint8_t>(inside ? (ws.scope_lo[l] <= prm.scope_contact_m ? 3 : 1) : 0);
    }
    // Rests on: touches a kept segment in the image (a box on a box, a lid on a tin, an
    // object behind another with its foot hidden). No height test: a supported object's
    // visible bottom can lie well above its supporter's visible top (a tin's lid overhangs
    // what it stands on), and what hangs or is fixed to a wall has already left the volume.
    // Spreads until nothing changes.
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
    int left_out = 0;
    for (std::size_t l = 1; l < L; ++l)
        left_out += keep[l] != 3 && ws.sizes[l] >= prm.min_points;
    for (int& l : ws.label)
        if (l && keep[static_cast<std::size_t>(l)] != 3) l = 0;
    return left_out;
}

}  // namespace

SegmentStats segment_objects(const SegmentParams& params, const OrganizedCloud& cloud,
                             const NormalMap& normals, const std::vector<std::uint8_t>& classes,
                             const Plane* support, const LabelImage& clusters,
                             SegmentWorkspace& ws, LabelImage& out) {
    const int W = cloud.width, H = cloud.height;
    const std::size_t N = cloud.size();
    SegmentStats stats;
    using Clock = std::chrono::steady_clock;
    auto t = Clock::now();
    auto ms_since = [&t] {
        const auto now = Clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - t).count();
        t = now;
        return ms;
    };
    const NormalMap* crease_normals = &normals;
    if (params.normal_smooth_px > 0) {
        // Smoothed normals are read at segment pixels (never removed ones) and a crease step
        // away from them: only those rows are smoothed.
        int first = H, last = -1;
        for (int v = 0; v < H; ++v) {
            const auto row = classes.begin() + static_cast<std::ptrdiff_t>(v) * W;
            if (std::any_of(row, row + W, [](std::uint8_t c) { return c != kPlaneRemoved; })) {
                first = std::min(first, v);
                last = v;
            }
        }
        const int margin = params.crease_step_px + 1;
        smooth_normals(normals, params.normal_smooth_px, ws.smooth_scratch, ws.smooth,
                       std::max(0, first - margin), std::min(H, last + 1 + margin));
        crease_normals = &ws.smooth;
    }
    stats.ms.smoothing = ms_since();
    const Ctx x{params, cloud, *crease_normals, classes, W, H};
    ws.cut.resize(N);
    ws.label.resize(N);
    ws.queue.resize(N);
    ws.dist.resize(N);

    if (params.segmenter == Segmenter::Kmeans) {
        // The paper's clusters on the object points: pixels are seedable, and a component
        // never crosses a cluster boundary (the cut marks pixels whose right or lower
        // neighbour lies in another cluster).
        if (clusters.labels.size() != N)
            throw InputError("segmentation: the kmeans segmenter needs the cluster labels of the frame");
        for (std::size_t p = 0; p < N; ++p) ws.cut[p] = classes[p] == kPlaneObject;
        // Components per cluster: run the BFS with a cluster check folded into `seedable`
        // by labelling cluster by cluster is costly; instead split by marking boundaries.
        for (int v = 0; v < H; ++v)
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                if (!ws.cut[p]) continue;
                const auto l = clusters.labels[p];
                if ((u + 1 < W && clusters.labels[p + 1] != l) ||
                    (v + 1 < H && clusters.labels[p + static_cast<std::size_t>(W)] != l))
                    ws.cut[p] = 0;
            }
    } else {
        // Seedable pixels: object points with a normal that sit on no concave crease. First
        // each pixel tests the pair (p, p + s) along u and v; then a pixel is on a crease
        // when any pair spanning it is concave (two passes: no two threads write one byte).
        const int s = params.crease_step_px;
        ws.crease.resize(N);
        // Raw pointers and plain values: the byte stores would otherwise make the compiler
        // reload every container's data pointer and every parameter on each pixel.
        const std::uint8_t *const cls = classes.data(), *const has_normal = normals.valid.data();
        const float *const cx = cloud.x.data(), *const cy = cloud.y.data(), *const cz = cloud.z.data();
        const NormalMap& cn = *crease_normals;
        const float *const nx = cn.nx.data(), *const ny = cn.ny.data(), *const nz = cn.nz.data();
        std::uint8_t* const crease = ws.crease.data();
        std::uint8_t* const seedable_out = ws.cut.data();
        const float jump_m = params.depth_jump_m, jump_rel = params.depth_jump_rel;
        const float concavity = params.concavity, steps = static_cast<float>(s);
#pragma omp parallel for schedule(static)
        for (int v = 0; v < H; ++v) {
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                std::uint8_t bits = 0;
                if (cls[p] == kPlaneObject && has_normal[p]) {
                    const std::size_t qs[2] = {u + s < W ? p + s : p,
                                               v + s < H ? p + static_cast<std::size_t>(s) * W : p};
                    const float z = cz[p];
                    for (int k = 0; k < 2; ++k) {
                        const std::size_t q = qs[k];
                        if (q == p || cls[q] != kPlaneObject || !has_normal[q]) continue;
                        // Ctx::connected over s pixels, then Ctx::concavity, on values.
                        if (!(std::fabs(z - cz[q]) <= steps * (jump_m + jump_rel * z * z))) continue;
                        const float dx = cx[q] - cx[p], dy = cy[q] - cy[p], dz = cz[q] - z;
                        const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
                        if (!(len > 1e-6f)) continue;
                        const float c = ((nx[p] - nx[q]) * dx + (ny[p] - ny[q]) * dy + (nz[p] - nz[q]) * dz) / len;
                        if (c > concavity) bits |= static_cast<std::uint8_t>(1 << k);
                    }
                }
                crease[p] = bits;
            }
        }
#pragma omp parallel for schedule(static)
        for (int v = 0; v < H; ++v) {
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                bool seed = cls[p] == kPlaneObject && has_normal[p];
                for (int k = 0; k <= s && seed; ++k) {
                    if (u - k >= 0 && (crease[p - k] & 1)) seed = false;
                    if (v - k >= 0 && (crease[p - static_cast<std::size_t>(k) * W] & 2)) seed = false;
                }
                seedable_out[p] = seed;
            }
        }
    }
    // ws.cut now holds "seedable"; components of it.
    std::vector<std::uint8_t>& seedable = ws.cut;
    stats.ms.cuts = ms_since();
    int n = components(x, seedable, ws);
    // Fragments too small to seed an object go back to the unassigned pool.
    {
        int* const label = ws.label.data();
        const int* const sizes = ws.sizes.data();
        const int min_seed = params.min_seed_points;
        const auto n_px = static_cast<std::ptrdiff_t>(N);
#pragma omp parallel for schedule(static)
        for (std::ptrdiff_t p = 0; p < n_px; ++p)
            if (label[p] && sizes[label[p]] < min_seed) label[p] = 0;
    }
    stats.ms.components = ms_since();
    stats.reattached = reattach(x, ws, params.reattach_px);
    stats.reattached += reattach(x, ws, W + H, true);
    stats.ms.reattach = ms_since();
    // Labels stay in 1..n with gaps (dropped fragments, merged segments) until the last
    // renumbering: every step below works per pair or per segment, whatever the numbers.
    if (params.segmenter != Segmenter::Kmeans) {
        stats.merges = merge_convex(x, ws, n);
        stats.ms.merge = ms_since();
        if (support) stats.containers = join_containers(x, *support, ws, n);
        stats.ms.containers = ms_since();
    }
    if (params.segmenter == Segmenter::Hybrid) {
        stats.color_splits = color_splits(x, ws, n);
        n += stats.color_splits;
        stats.ms.color = ms_since();
    }
    if (params.segmenter != Segmenter::Kmeans) {
        stats.gaps_filled = fill_container_gaps(x, ws);
        stats.ms.gaps = ms_since();
    }
    if (support && params.scope == Scope::Support) {
        stats.support_scope = true;
        stats.out_of_scope = restrict_to_support(x, *support, ws, n);
        stats.ms.scope = ms_since();
    }
    out.width = W;
    out.height = H;
    out.labels.resize(N);
    n = compact(ws, n, params.min_points, out.labels.data());
    stats.segments = n;
    stats.ms.compact += ms_since();
    return stats;
}

}  // namespace wul3d
