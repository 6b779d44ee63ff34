// Islands: regions of object pixels that no segment reached (at --decimate 2 every pixel of
// a small cup's inside can lie within a crease step of a crease, and the rim's depth step
// keeps reattachment out). They take part in the container rule's rim test as segments
// (containers.cpp), and those it joins to nothing are dropped: mixed pixels along occluding
// edges, broken pieces of one surface. (Keeping the lone ones as objects was a rule once:
// docs/ABLATION.md, "Every rule, switched off", says why it went.)
#include <algorithm>
#include <cstring>

#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {

/// Islands: connected components (4-neighbours, depth-continuous) of object pixels that no
/// segment reached, of cuts.min_seed_points or more, become segments n + 1, ... for the rim
/// test. At `--decimate 2` every pixel of a small cup's inside, or of a bowl's outer wall
/// seen at a steep angle, can lie within a crease step of a crease, so the region seeds no
/// segment, and the rim's depth step keeps reattachment out of it. ws.cut (the seeds, spent
/// by now) holds the pixels still open. Returns the islands added. Cost: one pass over the
/// pixels that vectorizes, a memchr for each island's first pixel, and a search over the
/// unreached object pixels.
int add_islands(const Ctx& x, SegmentBuffers& ws, int n) {
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
        if (size < x.prm.cuts.min_seed_points) continue;
        const int id = n + (++added);
        for (int i = 0; i < size; ++i) ws.label[static_cast<std::size_t>(ws.queue[i])] = id;
    }
    return added;
}

void drop_islands(const Ctx& x, SegmentBuffers& ws, int n) {
    int* const label = ws.label.data();
    const int W = x.W;
    for (int v = 0; v < x.H; ++v) {
        int* const row = label + static_cast<std::size_t>(v) * W;
        if (!row_has_label_over(row, 0, W, n)) continue;  // most rows hold no island
        for (int u = 0; u < W; ++u)
            if (row[u] > n) row[u] = 0;
    }
}

}  // namespace wul3d::detail
