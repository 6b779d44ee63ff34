#include "wul3d/segmentation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "../param_check.hpp"
#include "internal.hpp"  // Ctx, union-find, the rules
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
    require(color_max_compact >= 0, "color_max_compact", color_max_compact, ">= 0");
    require(color_max_crease_deg > 0, "color_max_crease_deg", color_max_crease_deg, "> 0");
    require(color_min_hue_deg > 0 && color_min_hue_deg < 90, "color_min_hue_deg", color_min_hue_deg, "in (0, 90)");
    require(color_min_step >= 0 && color_min_step < 100, "color_min_step", color_min_step, "in [0, 100), <= 1 = off");
    require(color_round_deg >= 0 && color_round_deg < 90, "color_round_deg", color_round_deg, "in [0, 90)");
    require(color_round_max_radius_m > 0, "color_round_max_radius_m", color_round_max_radius_m, "> 0");
    require(stack_min_step_m >= 0 && stack_min_step_m <= 0.5f, "stack_min_step_m", stack_min_step_m,
            "in [0, 0.5], 0 = off");
    require(stack_min_share > 0 && stack_min_share <= 0.5f, "stack_min_share", stack_min_share, "in (0, 0.5]");
    require(rim_min_boundary == 0 || rim_min_boundary >= 3, "rim_min_boundary", rim_min_boundary, ">= 3, or 0 = off");
    require(rim_max_residual_m > 0, "rim_max_residual_m", rim_max_residual_m, "> 0");
    require(rim_min_arc > 0 && rim_min_arc <= 1, "rim_min_arc", rim_min_arc, "in (0, 1]");
    require(rim_inside_share > 0 && rim_inside_share <= 1, "rim_inside_share", rim_inside_share, "in (0, 1]");
    require(rim_height_tol_m > 0, "rim_height_tol_m", rim_height_tol_m, "> 0");
    require(rim_far_agree > 0, "rim_far_agree", rim_far_agree, "> 0");
    require(island_min_width_px >= 0, "island_min_width_px", island_min_width_px, ">= 0, 0 = off");
    require(gap_max_px >= 0, "gap_max_px", gap_max_px, ">= 0");
    require(occluded_min_lines >= 0, "occluded_min_lines", occluded_min_lines, ">= 0");
    require(occluded_max_offset > 0, "occluded_max_offset", occluded_max_offset, "> 0");
    require(occluded_max_gap_m > 0, "occluded_max_gap_m", occluded_max_gap_m, "> 0");
    require(occluded_max_deg > 0 && occluded_max_deg < 90, "occluded_max_deg", occluded_max_deg, "in (0, 90)");
    require(scope_contact_m > 0, "scope_contact_m", scope_contact_m, "> 0");
    require(scope_max_height_m > 0, "scope_max_height_m", scope_max_height_m, "> 0");
    require(scope_max_outside >= 0 && scope_max_outside <= 1, "scope_max_outside", scope_max_outside, "in [0, 1]");
    require(scope_upright_share >= 0 && scope_upright_share <= 1, "scope_upright_share", scope_upright_share, "in [0, 1]");
}

namespace detail {
namespace {

/// Connected components of the pixels with `seedable[p]` = 1 (else 0, as ws.cut holds),
/// 4-connected where depth is continuous; `ws.label` gets 1..n, returns n. Sizes in
/// ws.sizes[1..n]. Cost: a memchr over the pixels for the seeds and a breadth-first search
/// over the seedable ones (ws.queue).
int components(const Ctx& x, const std::vector<std::uint8_t>& seedable, SegmentWorkspace& ws) {
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    std::fill(ws.label.begin(), ws.label.end(), 0);
    ws.sizes.assign(1, 0);
    int n = 0;
    const std::uint8_t* const seeds = seedable.data();
    for (std::size_t seed = 0; seed < N; ++seed) {
        if (!seeds[seed]) {
            // The next seedable pixel: memchr skips the run of others (most of the frame).
            const void* const next = std::memchr(seeds + seed, 1, N - seed);
            if (!next) break;
            seed = static_cast<std::size_t>(static_cast<const std::uint8_t*>(next) - seeds);
        }
        if (ws.label[seed]) continue;
        const int id = ++n;
        ws.label[seed] = id;
        ws.sizes.push_back(flood_region(
            x, ws.queue, static_cast<int>(seed), [&](std::size_t q) { return seedable[q] && !ws.label[q]; },
            [&](std::size_t q) { ws.label[q] = id; }));
    }
    return n;
}

/// Grows the labelled pixels into unlabelled foreground (cut pixels, feet, pixels without a
/// normal, dropped fragments) breadth-first, up to `max_steps`, where depth is continuous.
/// With `inside_only`, grows only into kPlaneInside pixels (a container's inside joins the
/// container, however wide). Returns the pixels added. Cost: one parallel pass over the
/// pixels for the search's start, then the search over the pixels it reaches.
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
        for (int v = v0; v < v1; ++v) {
            const std::size_t row = static_cast<std::size_t>(v) * W;
            const int* const label = ws.label.data() + row;
            // The distances first, in a loop of their own that vectorizes; it also tells a
            // row without labels, which has no seed.
            int* const dist = ws.dist.data() + row;
            int any = 0;
            for (int u = 0; u < W; ++u) {
                dist[u] = label[u] ? 0 : -1;
                any |= label[u];
            }
            if (!any) continue;
            for (int u = 0; u < W; ++u) {
                if (!label[u]) continue;
                const std::size_t p = row + u;
                if ((u > 0 && grows_into(p - 1)) || (u + 1 < W && grows_into(p + 1)) ||
                    (v > 0 && grows_into(p - W)) || (v + 1 < H && grows_into(p + W)))
                    seeds[count++] = static_cast<int>(p);
            }
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
        for (int q : four_neighbours(p, p % W, p / W, W, H)) {
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
/// them. Cost: two parallel passes over the pixels, O(n log n) between them.
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

/// Joins segments that touch along a boundary that is mostly not concave. Each 4-neighbour
/// pair (p, q) of two segments with continuous depth is tested for a crease between the
/// pixels a crease step away on either side, inside their own segments; the pair of
/// segments (a, b) merges when enough pairs were tested, few were concave and may_join(a,
/// b). Returns the merges. Cost: one pass over the pixels, a sort of the boundary pairs, one
/// more pass to relabel when anything merged.
template <class MayJoin>
int merge_convex(const Ctx& x, SegmentWorkspace& ws, int n, MayJoin&& may_join) {
    const SegmentParams& prm = x.prm;
    if (prm.merge_max_concave <= 0 || n < 2) return 0;
    const int W = x.W, H = x.H, s = prm.crease_step_px;
    ws.edges.clear();
    const int* const label = ws.label.data();
    // The pair (p, q = p + d) of segments a and b, q right of or below p.
    auto boundary_pair = [&](int u, int v, int a, int b, const int (&d)[2]) {
        const int p = v * W + u, q = p + d[0] + d[1] * W;
        if (!x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) return;
        const int pu = u - s * d[0], pv = v - s * d[1];
        const int qu = u + d[0] + s * d[0], qv = v + d[1] + s * d[1];
        std::uint64_t tested = 0, concave = 0;
        if (pu >= 0 && pv >= 0 && qu < W && qv < H) {
            const std::size_t pp = static_cast<std::size_t>(pv) * W + pu;
            const std::size_t qq = static_cast<std::size_t>(qv) * W + qu;
            if (label[pp] == a && label[qq] == b && x.n.valid[pp] && x.n.valid[qq]) {
                tested = 1;
                concave = x.concavity(pp, qq) > prm.concavity;
            }
        }
        const auto lo = static_cast<std::uint64_t>(std::min(a, b));
        const auto hi = static_cast<std::uint64_t>(std::max(a, b));
        ws.edges.push_back((lo << 34) | (hi << 4) | (tested << 1) | concave);
    };
    static constexpr int kRight[2] = {1, 0}, kDown[2] = {0, 1};
    for (int v = 0; v < H; ++v) {
        const int* const row = label + static_cast<std::ptrdiff_t>(v) * W;
        if (!row_has_label(row, 0, W)) continue;  // a row without labels has no pair
        for (int u = 0; u < W; ++u) {
            const int a = row[u];
            if (a == 0) continue;
            // Right, then down, as before; most neighbours are unlabelled or of segment a.
            if (u + 1 < W && row[u + 1] != 0 && row[u + 1] != a) boundary_pair(u, v, a, row[u + 1], kRight);
            if (v + 1 < H && row[u + W] != 0 && row[u + W] != a) boundary_pair(u, v, a, row[u + W], kDown);
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
        const int a = static_cast<int>(key >> 30), b = static_cast<int>(key & ((1u << 30) - 1));
        if (tested < prm.merge_min_boundary ||
            static_cast<float>(concave) > prm.merge_max_concave * static_cast<float>(tested) || !may_join(a, b))
            continue;
        merges += join_sets(ws.parent, a, b);
    }
    if (merges > 0) relabel_to_roots(ws);
    return merges;
}

/// The convexity merge again after the colour cue (color_rejoin), between segments that
/// came from different segments before it (ws.origin: what the cue parted stays parted)
/// and are one material by the cue's measures: the chromaticities of their mean colours
/// within color_min_distance and, with the brightness step on, their mean brightness within
/// color_min_step. A box with another lying on it can come out of the crease cuts in two
/// pieces, and the first merge kept them apart because the upper box's wall, a concave
/// crease, ran along their boundary too; once the cue has made the upper box a segment of
/// its own, the pieces' boundary is their own convex edge. Returns the merges. Cost: one
/// pass over the rows with labels for the segments' mean colours, then merge_convex's.
int rejoin_materials(const Ctx& x, SegmentWorkspace& ws, int n) {
    const SegmentParams& prm = x.prm;
    ws.material.assign(static_cast<std::size_t>(n) + 1, {0, 0, 0, 0});
    for (int v = 0; v < x.H; ++v) {
        const int* const row = ws.label.data() + static_cast<std::ptrdiff_t>(v) * x.W;
        if (!row_has_label(row, 0, x.W)) continue;
        for (int u = 0; u < x.W; ++u) {
            if (row[u] == 0) continue;
            const std::size_t p = static_cast<std::size_t>(v) * x.W + u;
            std::array<double, 4>& m = ws.material[static_cast<std::size_t>(row[u])];
            m[0] += x.c.r[p], m[1] += x.c.g[p], m[2] += x.c.b[p], m[3] += 1;
        }
    }
    // The mean colour's chromaticity and brightness.
    auto material = [&](int l, double (&c)[3]) {
        const std::array<double, 4>& m = ws.material[static_cast<std::size_t>(l)];
        const double r = m[0] / m[3], g = m[1] / m[3], b = m[2] / m[3];
        chromaticity(r, g, b, c);
        return r + g + b + kDark;
    };
    return merge_convex(x, ws, n, [&](int a, int b) {
        if (ws.origin[static_cast<std::size_t>(a)] == ws.origin[static_cast<std::size_t>(b)]) return false;
        double ca[3], cb[3];
        const double ba = material(a, ca), bb = material(b, cb);
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += (ca[k] - cb[k]) * (ca[k] - cb[k]);
        if (d2 >= static_cast<double>(prm.color_min_distance) * prm.color_min_distance) return false;
        const bool brightness_step = prm.color_min_step > 1 &&
                                     std::max(ba, bb) >= static_cast<double>(prm.color_min_step) * std::min(ba, bb);
        return !brightness_step;
    });
}

// ---- the basic phases of segment_objects -------------------------------------------------

/// Milliseconds since the last call (or the construction), for SegmentStats::ms.
class Lap {
    using Clock = std::chrono::steady_clock;
    Clock::time_point t_ = Clock::now();

public:
    double operator()() {
        const auto now = Clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - t_).count();
        t_ = now;
        return ms;
    }
};

/// The normals of the crease tests: `normals` smoothed over normal_smooth_px into ws.smooth,
/// or `normals` themselves when normal_smooth_px is 0. Smoothed normals are read at segment
/// pixels (never removed ones) and a crease step away from them: only those rows are
/// smoothed. Cost: a scan of the classes for the rows with objects, then running sums over
/// those rows (smooth_normals); no allocation once ws.smooth has the frame's size.
const NormalMap& crease_normals(const SegmentParams& params, const NormalMap& normals,
                                const std::vector<std::uint8_t>& classes, int W, int H, SegmentWorkspace& ws) {
    if (params.normal_smooth_px <= 0) return normals;
    int first = H, last = -1;
    for (int v = 0; v < H; ++v) {
        const auto row = classes.begin() + static_cast<std::ptrdiff_t>(v) * W;
        if (std::any_of(row, row + W, [](std::uint8_t c) { return c != kPlaneRemoved; })) {
            first = std::min(first, v);
            last = v;
        }
    }
    const int margin = params.crease_step_px + 1;
    smooth_normals(normals, params.normal_smooth_px, ws.smooth_scratch, ws.smooth, std::max(0, first - margin),
                   std::min(H, last + 1 + margin));
    return ws.smooth;
}

/// Seeds of the kmeans segmenter into ws.cut: the object pixels, less those whose right or
/// lower neighbour lies in another of the paper's clusters, so that a component never
/// crosses a cluster boundary (cheaper than labelling cluster by cluster). InputError when
/// `clusters` is not the frame's. Cost: two passes over the pixels.
void seeds_in_clusters(const Ctx& x, const LabelImage& clusters, SegmentWorkspace& ws) {
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    if (clusters.labels.size() != N)
        throw InputError("segmentation: the kmeans segmenter needs the cluster labels of the frame");
    for (std::size_t p = 0; p < N; ++p) ws.cut[p] = x.cls[p] == kPlaneObject;
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (!ws.cut[p]) continue;
            const auto l = clusters.labels[p];
            if ((u + 1 < W && clusters.labels[p + 1] != l) ||
                (v + 1 < H && clusters.labels[p + static_cast<std::size_t>(W)] != l))
                ws.cut[p] = 0;
        }
}

/// Concave pairs into ws.crease: bit 0 when (p, p + s) along u is a concave crease (both
/// object pixels with a normal, depth-continuous over the s pixels, Ctx::concavity above
/// SegmentParams::concavity), bit 1 for (p, p + s W) along v. `has_normal`: the raw normals'
/// validity. Cost: one parallel pass over the pixels, two tests each.
void find_concave_pairs(const Ctx& x, const std::uint8_t* has_normal, SegmentWorkspace& ws) {
    const int W = x.W, H = x.H, s = x.prm.crease_step_px;
    // Raw pointers and plain values: the byte stores would otherwise make the compiler
    // reload every container's data pointer and every parameter on each pixel.
    const std::uint8_t* const cls = x.cls.data();
    const float *const cx = x.c.x.data(), *const cy = x.c.y.data(), *const cz = x.c.z.data();
    const float *const nx = x.n.nx.data(), *const ny = x.n.ny.data(), *const nz = x.n.nz.data();
    ws.crease.resize(static_cast<std::size_t>(W) * H);
    std::uint8_t* const crease = ws.crease.data();
    const float jump_m = x.prm.depth_jump_m, jump_rel = x.prm.depth_jump_rel;
    const float concavity = x.prm.concavity, steps = static_cast<float>(s);
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        // Only the columns from the row's first object pixel (memchr) to its last can hold
        // a pair; the others get no bits.
        const std::uint8_t* const cls_row = cls + static_cast<std::size_t>(v) * W;
        std::uint8_t* const crease_row = crease + static_cast<std::size_t>(v) * W;
        const void* const first = std::memchr(cls_row, kPlaneObject, static_cast<std::size_t>(W));
        if (!first) {
            std::memset(crease_row, 0, static_cast<std::size_t>(W));
            continue;
        }
        const int u0 = static_cast<int>(static_cast<const std::uint8_t*>(first) - cls_row);
        int u1 = W;
        while (cls_row[u1 - 1] != kPlaneObject) --u1;
        std::memset(crease_row, 0, static_cast<std::size_t>(u0));
        std::memset(crease_row + u1, 0, static_cast<std::size_t>(W - u1));
        for (int u = u0; u < u1; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            std::uint8_t bits = 0;
            if (cls[p] == kPlaneObject && has_normal[p]) {
                const std::size_t qs[2] = {u + s < W ? p + s : p, v + s < H ? p + static_cast<std::size_t>(s) * W : p};
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
}

/// Seeds of the geometric segmenters into ws.cut: object pixels with a normal on no concave
/// crease, i.e. no concave pair of ws.crease spans them (a second pass, so that no two
/// threads write one byte). Cost: one parallel pass over the pixels, up to 2 (s + 1) reads
/// each; no allocation.
void seeds_off_creases(const Ctx& x, const std::uint8_t* has_normal, SegmentWorkspace& ws) {
    const int W = x.W, H = x.H, s = x.prm.crease_step_px;
    const std::uint8_t* const cls = x.cls.data();
    const std::uint8_t* const crease = ws.crease.data();
    std::uint8_t* const seedable_out = ws.cut.data();
    // A seed: an object pixel with a normal, and no crease between it and any of the s
    // pixels on its left (bit 0) or above it (bit 1). Row by row, one offset k at a time:
    // plain passes over the row that vectorize, instead of a search per pixel.
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        std::uint8_t* const seed = seedable_out + row;
        for (int u = 0; u < W; ++u)
            seed[u] = static_cast<std::uint8_t>((cls[row + u] == kPlaneObject) & (has_normal[row + u] != 0));
        for (int k = 0; k <= s; ++k) {
            for (int u = k; u < W; ++u) seed[u] &= static_cast<std::uint8_t>((crease[row + u - k] & 1) == 0);
            if (v - k < 0) continue;
            const std::uint8_t* const above = crease + (row - static_cast<std::size_t>(k) * W);
            for (int u = 0; u < W; ++u) seed[u] &= static_cast<std::uint8_t>((above[u] & 2) == 0);
        }
    }
}

/// Fragments too small to seed an object (min_seed_points) go back to the unassigned pool:
/// their labels in ws.label become 0. In: ws.sizes from components. Cost: one parallel pass
/// over the pixels.
void drop_small_components(SegmentWorkspace& ws, int min_seed) {
    int* const label = ws.label.data();
    const int* const sizes = ws.sizes.data();
    const auto n_px = static_cast<std::ptrdiff_t>(ws.label.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p)
        if (label[p] && sizes[label[p]] < min_seed) label[p] = 0;
}

}  // namespace
}  // namespace detail

/// The phases in order, each timed into stats.ms. Labels stay in 1..n with gaps (dropped
/// fragments, merged or joined segments) until `compact`: every phase between works per
/// pixel, per pair or per segment, whatever the numbers. Rules that add segments number
/// them n + 1, ... and add them to n.
SegmentStats segment_objects(const SegmentParams& params, const OrganizedCloud& cloud,
                             const NormalMap& normals, const std::vector<std::uint8_t>& classes,
                             const Plane* support, const LabelImage& clusters,
                             SegmentWorkspace& ws, LabelImage& out) {
    using namespace detail;
    const int W = cloud.width, H = cloud.height;
    const std::size_t N = cloud.size();
    const bool kmeans = params.segmenter == Segmenter::Kmeans;
    SegmentStats stats;
    Lap ms_since;
    const Ctx x{params, cloud, crease_normals(params, normals, classes, W, H, ws), classes, W, H};
    stats.ms.smoothing = ms_since();
    ws.cut.resize(N);
    ws.label.resize(N);
    ws.queue.resize(N);
    ws.dist.resize(N);
    // Seeds (ws.cut): object pixels off concave creases (kmeans: off cluster boundaries).
    if (kmeans) {
        seeds_in_clusters(x, clusters, ws);
    } else {
        find_concave_pairs(x, normals.valid.data(), ws);
        seeds_off_creases(x, normals.valid.data(), ws);
    }
    stats.ms.cuts = ms_since();
    int n = components(x, ws.cut, ws);
    drop_small_components(ws, params.min_seed_points);
    stats.ms.components = ms_since();
    // Cut pixels, feet and dropped fragments, then containers' insides, join what they touch.
    stats.reattached = reattach(x, ws, params.reattach_px);
    stats.reattached += reattach(x, ws, W + H, true);
    stats.ms.reattach = ms_since();
    // The rules on segments (docs/DESIGN.md, "Objects", 2), in this order.
    if (!kmeans) {
        stats.merges = merge_convex(x, ws, n, [](int, int) { return true; });
        stats.ms.merge = ms_since();
        if (support) {
            const ContainerJoins c = join_containers(x, *support, ws, n);
            stats.containers = c.joins;
            stats.islands_kept = c.islands_kept;
            n += c.labels_added;
        }
        stats.ms.containers = ms_since();
    }
    if (params.segmenter == Segmenter::Hybrid) {
        stats.color_splits = color_splits(x, support, ws, n, stats.texture_splits);
        n += stats.color_splits;
        if (stats.color_splits > 0 && params.color_rejoin) stats.merges += rejoin_materials(x, ws, n);
        stats.ms.color = ms_since();
    }
    if (!kmeans && support) {
        stats.stack_splits = split_stacks(x, *support, ws, n);
        n += stats.stack_splits;
        stats.ms.stacks = ms_since();
    }
    if (!kmeans) {
        stats.gaps_filled = fill_container_gaps(x, ws);
        stats.ms.gaps = ms_since();
        stats.occluded = join_occluded(x, ws, n);
        stats.ms.occluded = ms_since();
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
