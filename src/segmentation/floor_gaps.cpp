// Floor gaps: the plane step gives a container's floor back only in patches whose mean
// height clears its threshold, so noise leaves small holes in the inside the container rule
// joined. A small patch of unlabelled pixels beside a container's inside, enclosed by one
// segment, is that segment's and joins it; a hole that touches no inside (a mug's handle,
// the table seen through it) stays a hole, as the ground truth keeps it.
#include <algorithm>

#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {
namespace {

/// Gaps in a container's floor (ContainerParams::gap_max_px): each patch of unlabelled pixels
/// beside a labelled kPlaneInside pixel is explored breadth-first; when it is enclosed by one
/// segment (no image border, no other segment) and small, its points join that segment.
/// Only the inside pixels are visited to find the patches, and the marks are cleared behind
/// each search: the cost follows the insides, not the image. Returns the points filled.
std::size_t fill_container_gaps(const Ctx& x, SegmentBuffers& ws) {
    const int max_px = x.prm.containers.gap_max_px;
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

}  // namespace

void fill_floor_gaps(const Ctx& x, const Plane*, SegmentBuffers& ws, int&, SegmentStats& stats) {
    stats.containers.gaps_filled = fill_container_gaps(x, ws);
}

}  // namespace wul3d::detail
