// Islands: regions of object pixels that no segment reached (at --decimate 2 every pixel of
// a small cup's inside can lie within a crease step of a crease, and the rim's depth step
// keeps reattachment out). They take part in the container rule's rim test as segments
// (containers.cpp), and those it joins to nothing are kept as objects only when they lie
// behind every segment they meet and are wide enough to be one (island_min_width_px): an
// object's top seen between nearer ones, a bowl's inside whose rim fitted no circle; the
// rest, mixed pixels along occluding edges and broken pieces of one surface, are dropped.
#include <algorithm>
#include <cstring>

#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {

/// Islands: connected components (4-neighbours, depth-continuous) of object pixels that no
/// segment reached, of min_seed_points or more, become segments n + 1, ... for the rim
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
        if (size < x.prm.min_seed_points) continue;
        const int id = n + (++added);
        for (int i = 0; i < size; ++i) ws.label[static_cast<std::size_t>(ws.queue[i])] = id;
    }
    return added;
}

/// Why each test: an island that continues into a segment with continuous depth is a piece
/// of it that no crease test let grow (not an object); one nearer than a segment it meets
/// lies in depth between two surfaces, as the mixed pixels along an occluding edge and the
/// broken pieces of one surface do (osd_mosd test59 at --decimate 2: a 77-point piece of a
/// box's top, nearer than one neighbour and farther than the other); one narrower than
/// island_min_width_px is such a band of mixed pixels (a RealSense frame, image_0003: 1.7
/// points wide along the drill's top edge). What is left is seen past every segment it
/// meets: a bowl's inside whose rim fitted no circle, an object's top between nearer ones.
int keep_lone_islands(const Ctx& x, SegmentBuffers& ws, int n, int islands) {
    int* const label = ws.label.data();
    const int W = x.W, H = x.H;
    const int min_width = x.prm.island_min_width_px;
    // Per island: its pixels, its outline pairs (to anything but itself; none past the frame)
    // and whether it is still lone.
    ws.island_pixels.assign(static_cast<std::size_t>(islands) + 1, 0);
    ws.island_outline.assign(static_cast<std::size_t>(islands) + 1, 0);
    ws.island_lone.assign(static_cast<std::size_t>(islands) + 1, 1);
    int first_row = H, last_row = -1;
    for (int v = 0; v < H; ++v) {
        const int* const row = label + static_cast<std::size_t>(v) * W;
        if (!row_has_label_over(row, 0, W, n)) continue;  // most rows hold no island
        first_row = std::min(first_row, v);
        last_row = v;
        if (min_width <= 0) continue;  // no island kept (none counts pixels): only the rows
        for (int u = 0; u < W; ++u) {
            const int l = row[u];
            if (l <= n) continue;
            const std::size_t i = static_cast<std::size_t>(l - n);
            ++ws.island_pixels[i];
            const int p = v * W + u;
            for (const int q : four_neighbours(p, u, v, W, H)) {
                if (q < 0 || label[q] == l) continue;  // past the frame, or itself
                ++ws.island_outline[i];
                const std::size_t a = static_cast<std::size_t>(p), b = static_cast<std::size_t>(q);
                if (label[q] > 0 && label[q] <= n && (x.connected(a, b) || x.c.z[a] <= x.c.z[b]))
                    ws.island_lone[i] = 0;
            }
        }
    }
    // Width 2 * pixels / outline pairs: a band w wide and L long has w L pixels and about 2 L
    // outline pairs. One smaller than an object is not kept: it could not be one, and its
    // pixels stay free for the floor gaps (fill_container_gaps).
    int kept = 0;
    for (std::size_t i = 1; i <= static_cast<std::size_t>(islands); ++i) {
        const long long pixels = ws.island_pixels[i];
        ws.island_lone[i] &= static_cast<std::uint8_t>(
            pixels >= x.prm.min_points && 2 * pixels >= static_cast<long long>(min_width) * ws.island_outline[i]);
        kept += ws.island_lone[i];
    }
    const std::uint8_t* const lone = ws.island_lone.data();
    for (int v = first_row; v <= last_row; ++v) {
        int* const row = label + static_cast<std::size_t>(v) * W;
        for (int u = 0; u < W; ++u)
            if (row[u] > n && !lone[row[u] - n]) row[u] = 0;
    }
    return kept;
}

}  // namespace wul3d::detail
