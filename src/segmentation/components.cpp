// Components: the seeds (cuts.cpp) grow into segments, 4-connected where depth is
// continuous; fragments too small to seed an object go back to the pool, and the pixels
// no segment took (cut pixels, feet, containers' insides) join the segment they touch. At
// the end, after the rules, the segments are renumbered 1..n into the output. Segments are
// the unit every rule works on.
#include <algorithm>
#include <cstring>
#include <limits>

#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {
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

int seed_components(const Ctx& x, SegmentWorkspace& ws) {
    const int n = components(x, ws.cut, ws);
    drop_small_components(ws, x.prm.min_seed_points);
    return n;
}

std::size_t reattach_foreground(const Ctx& x, SegmentWorkspace& ws) {
    // Cut pixels, feet and dropped fragments, then containers' insides, join what they touch.
    const std::size_t near = reattach(x, ws, x.prm.reattach_px);
    return near + reattach(x, ws, x.W + x.H, true);
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

}  // namespace wul3d::detail
