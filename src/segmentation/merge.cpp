// The convexity merge (LCCP's): segments that meet along a depth-continuous boundary that
// is mostly not concave are one object. Noise cuts an object along creases it does not have
// (a box's front face from its top, a tin's rim); two objects meet at a concave fold, or
// (with colour, the hybrid segmenter) where one's outline lies over the other: either is a
// junction pair, and a boundary of more than merge.max_concave junction pairs stays.
#include <algorithm>
#include <array>
#include <cmath>

#include "internal.hpp"

namespace wul3d::detail {
namespace {

/// A boundary pair is a silhouette pair when the depth steps between its two pixels by this
/// share of the step that disconnects them (Ctx::depth_step) and the colours a crease step
/// either side differ by colour.min_distance: one object's outline over another that it
/// touches (a ball against a lying can), whose step the sensor's noise and the decimation's
/// blocks smear below a full one. A noise cut through one surface, or print on one face,
/// steps no more than the surface's slope between neighbours. What it cannot tell: a face
/// seen nearly edge-on steps as much, so a box whose top and front differ in colour, seen
/// steeply, keeps them apart. A smaller share gained the generated families no more and parted
/// `ocid_sample`'s coffee can from its lid; a larger one, or a step measured against each
/// side's own slope, gained less (docs/ABLATION.md, "Merge", has the variants).
constexpr float kSilhouetteStep = 0.25f;

/// Whether the boundary pair (p, q), tested at pp and qq a crease step either side, is a
/// silhouette pair (kSilhouetteStep). The depth step first: the chromaticities only for a
/// pair that steps.
bool silhouette_pair(const Ctx& x, std::size_t p, std::size_t q, std::size_t pp, std::size_t qq,
                     float min_distance2) {
    const float z = x.c.z[p];
    if (!(std::fabs(z - x.c.z[q]) > kSilhouetteStep * x.depth_step(z))) return false;
    float ca[3], cb[3];
    chromaticity(x.c, pp, ca);
    chromaticity(x.c, qq, cb);
    const float d0 = ca[0] - cb[0], d1 = ca[1] - cb[1], d2 = ca[2] - cb[2];
    return d0 * d0 + d1 * d1 + d2 * d2 > min_distance2;
}

/// The boundary pairs of rows [v0, v1) into `edges`: each 4-neighbour pair (p, q) of two
/// segments a, b with continuous depth, q right of or below p, keyed (lo, hi, tested,
/// junction): whether the pixels a crease step away on either side, inside their own
/// segments, were tested, and found concave or (with colour, `colour`) a silhouette pair
/// (kSilhouetteStep): where two objects meet. Reads only: strips run in parallel.
void boundary_pairs(const Ctx& x, const int* label, int v0, int v1, bool colour, std::vector<std::uint64_t>& edges) {
    const SegmentParams& prm = x.prm;
    const int W = x.W, H = x.H, s = prm.cuts.crease_step_px;
    const float min_distance2 = prm.colour.min_distance * prm.colour.min_distance;
    // The pair (p, q = p + d) of segments a and b, q right of or below p.
    auto boundary_pair = [&](int u, int v, int a, int b, const int (&d)[2]) {
        const int p = v * W + u, q = p + d[0] + d[1] * W;
        if (!x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) return;
        const int pu = u - s * d[0], pv = v - s * d[1];
        const int qu = u + d[0] + s * d[0], qv = v + d[1] + s * d[1];
        std::uint64_t tested = 0, junction = 0;
        if (pu >= 0 && pv >= 0 && qu < W && qv < H) {
            const std::size_t pp = static_cast<std::size_t>(pv) * W + pu;
            const std::size_t qq = static_cast<std::size_t>(qv) * W + qu;
            if (label[pp] == a && label[qq] == b && x.n.valid[pp] && x.n.valid[qq]) {
                tested = 1;
                junction = x.concavity(pp, qq) > prm.cuts.concavity ||
                           (colour && silhouette_pair(x, static_cast<std::size_t>(p), static_cast<std::size_t>(q),
                                                      pp, qq, min_distance2));
            }
        }
        const auto lo = static_cast<std::uint64_t>(std::min(a, b));
        const auto hi = static_cast<std::uint64_t>(std::max(a, b));
        edges.push_back((lo << 34) | (hi << 4) | (tested << 1) | junction);
    };
    static constexpr int kRight[2] = {1, 0}, kDown[2] = {0, 1};
    for (int v = v0; v < v1; ++v) {
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
}

/// Joins segments that touch along a boundary that is mostly not a junction: the segments
/// (a, b) of the boundary pairs (boundary_pairs) merge when enough pairs were tested, few
/// were junction pairs (concave, or silhouette pairs), and may_join(a, b). Returns the
/// merges. Cost: one pass over the pixels in strips of rows (in parallel), a sort of the
/// boundary pairs (the order they come in does not matter), one more parallel pass to
/// relabel when anything merged.
template <class MayJoin>
int merge_convex(const Ctx& x, SegmentBuffers& ws, int n, MayJoin&& may_join) {
    const SegmentParams& prm = x.prm;
    if (prm.merge.max_concave <= 0 || n < 2) return 0;
    const int strips = row_strips(x.H);
    const int* const label = ws.label.data();
    const bool colour = prm.segmenter == Segmenter::Hybrid && x.c.has_color;
    ws.edges.clear();
    if (strips == 1) {
        boundary_pairs(x, label, 0, x.H, colour, ws.edges);
    } else {
        ws.strip_pairs.resize(static_cast<std::size_t>(strips));
#pragma omp parallel for schedule(static)
        for (int t = 0; t < strips; ++t) {
            auto& edges = ws.strip_pairs[static_cast<std::size_t>(t)];
            edges.clear();
            boundary_pairs(x, label, x.H * t / strips, x.H * (t + 1) / strips, colour, edges);
        }
        for (const auto& e : ws.strip_pairs) ws.edges.insert(ws.edges.end(), e.begin(), e.end());
    }
    std::sort(ws.edges.begin(), ws.edges.end());
    reset_sets(ws.parent, n);
    int merges = 0;
    for (std::size_t i = 0; i < ws.edges.size();) {
        const std::uint64_t key = ws.edges[i] >> 4;
        int tested = 0, junction = 0;
        for (; i < ws.edges.size() && (ws.edges[i] >> 4) == key; ++i) {
            tested += static_cast<int>((ws.edges[i] >> 1) & 1);
            junction += static_cast<int>(ws.edges[i] & 1);
        }
        const int a = static_cast<int>(key >> 30), b = static_cast<int>(key & ((1u << 30) - 1));
        if (tested < prm.merge.min_boundary ||
            static_cast<float>(junction) > prm.merge.max_concave * static_cast<float>(tested) || !may_join(a, b))
            continue;
        merges += join_sets(ws.parent, a, b);
    }
    if (merges > 0) relabel_to_roots(ws);
    return merges;
}

}  // namespace

void merge_segments(const Ctx& x, const Plane*, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    stats.merge.joins = merge_convex(x, ws, n, [](int, int) { return true; });
}

}  // namespace wul3d::detail
