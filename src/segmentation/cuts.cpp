// The crease cuts: where two object pixels a crease step apart face each other across a
// concave fold (LCCP's test, docs/DESIGN.md, "Cuts"), the pixels between are cut, so
// that objects touching each other, or standing on each other, seed apart. The kmeans
// segmenter cuts along the paper's cluster boundaries instead. The seeds go to the
// components (components.cpp).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "internal.hpp"
#include "wul3d/error.hpp"
#include "wul3d/normals.hpp"  // smooth_normals
#include "wul3d/plane.hpp"

namespace wul3d::detail {

/// The normals of the crease tests: `normals` smoothed over cuts.normal_smooth_px into ws.smooth,
/// or `normals` themselves when cuts.normal_smooth_px is 0. Smoothed normals are read at segment
/// pixels (never removed ones) and a crease step away from them: only those rows are
/// smoothed. Cost: a scan of the classes for the rows with objects, then running sums over
/// those rows (smooth_normals); no allocation once ws.smooth has the frame's size.
const NormalMap& crease_normals(const SegmentParams& params, const NormalMap& normals,
                                const std::vector<std::uint8_t>& classes, int W, int H, SegmentBuffers& ws) {
    if (params.cuts.normal_smooth_px <= 0) return normals;
    int first = H, last = -1;
    for (int v = 0; v < H; ++v) {
        const auto row = classes.begin() + static_cast<std::ptrdiff_t>(v) * W;
        if (std::any_of(row, row + W, [](std::uint8_t c) { return c != kPlaneRemoved; })) {
            first = std::min(first, v);
            last = v;
        }
    }
    const int margin = params.cuts.crease_step_px + 1;
    smooth_normals(normals, params.cuts.normal_smooth_px, ws.smooth_scratch, ws.smooth, std::max(0, first - margin),
                   std::min(H, last + 1 + margin));
    return ws.smooth;
}

namespace {

/// Seeds of the kmeans segmenter into ws.cut: the object pixels, less those whose right or
/// lower neighbour lies in another of the paper's clusters, so that a component never
/// crosses a cluster boundary (cheaper than labelling cluster by cluster). InputError when
/// `clusters` is not the frame's. Cost: two passes over the pixels.
void seeds_in_clusters(const Ctx& x, const LabelImage& clusters, SegmentBuffers& ws) {
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
void find_concave_pairs(const Ctx& x, const std::uint8_t* has_normal, SegmentBuffers& ws) {
    const int W = x.W, H = x.H, s = x.prm.cuts.crease_step_px;
    // Raw pointers and plain values: the byte stores would otherwise make the compiler
    // reload every container's data pointer and every parameter on each pixel.
    const std::uint8_t* const cls = x.cls.data();
    const float *const cx = x.c.x.data(), *const cy = x.c.y.data(), *const cz = x.c.z.data();
    const float *const nx = x.n.nx.data(), *const ny = x.n.ny.data(), *const nz = x.n.nz.data();
    ws.crease.resize(static_cast<std::size_t>(W) * H);
    std::uint8_t* const crease = ws.crease.data();
    const float jump_m = x.prm.depth_jump_m, jump_rel = x.prm.depth_jump_rel;
    const float concavity = x.prm.cuts.concavity, steps = static_cast<float>(s);
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
void seeds_off_creases(const Ctx& x, const std::uint8_t* has_normal, SegmentBuffers& ws) {
    const int W = x.W, H = x.H, s = x.prm.cuts.crease_step_px;
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

}  // namespace

void find_seeds(const Ctx& x, const std::uint8_t* has_normal, const LabelImage& clusters, SegmentBuffers& ws) {
    const std::size_t N = static_cast<std::size_t>(x.W) * x.H;
    ws.cut.resize(N);
    ws.label.resize(N);
    ws.queue.resize(N);
    ws.dist.resize(N);
    if (x.prm.segmenter == Segmenter::Kmeans) {
        seeds_in_clusters(x, clusters, ws);
    } else {
        find_concave_pairs(x, has_normal, ws);
        seeds_off_creases(x, has_normal, ws);
    }
}

}  // namespace wul3d::detail
