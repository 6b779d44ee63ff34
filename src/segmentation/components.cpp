// Components: the seeds (cuts.cpp) grow into segments, 4-connected where depth is
// continuous; fragments too small to seed an object go back to the pool, and the pixels
// no segment took (cut pixels, feet, containers' insides) join the segment they touch. At
// the end, after the rules, the segments are renumbered 1..n into the output. Segments are
// the unit every rule works on.
#include <algorithm>
#include <cstring>
#include <limits>

#include <omp.h>

#include "../team_tasks.hpp"
#include "internal.hpp"
#include "wul3d/plane.hpp"

namespace wul3d::detail {
namespace {

/// label_components with one strip: a breadth-first search from each seedable pixel no
/// component holds yet, in raster order. Cost: a memchr over the pixels for the seeds and
/// the search over the seedable ones (ws.queue).
int components_by_search(const Ctx& x, const std::uint8_t* seeds, SegmentBuffers& ws) {
    const std::size_t N = static_cast<std::size_t>(x.W) * x.H;
    std::fill(ws.label.begin(), ws.label.end(), 0);
    ws.sizes.assign(1, 0);
    int n = 0;
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
            x, ws.queue, static_cast<int>(seed), [&](std::size_t q) { return seeds[q] && !ws.label[q]; },
            [&](std::size_t q) { ws.label[q] = id; }));
    }
    return n;
}

// ---- label_components on strips -------------------------------------------------------
// The search's components, put together from sets: two 4-neighbours whose depth is
// continuous seen from either are one set (the search crosses between them both ways, so a
// component holds a set whole), and a pair continuous seen from the far pixel only is a
// one-way pair from that pixel's set to the near one's. A component is then its first set
// (in raster order of the sets' first pixels, among those no component holds yet) and the
// sets it reaches over one-way pairs. Sets are a union-find over pixels whose root is the
// set's first pixel; one-way pairs are rare (a depth step between the noise at the near and
// at the far depth), and without any a component is one set.

/// The root of pixel p's set; halves the path (writes parent: the caller's strip only).
inline int find_pixel(int* parent, int p) {
    while (parent[p] != p) {
        parent[p] = parent[parent[p]];
        p = parent[p];
    }
    return p;
}

/// Joins the sets of p and q (the first pixel stays root) and their sizes at the root.
inline void unite_pixels(int* parent, int* size, int p, int q) {
    int a = find_pixel(parent, p), b = find_pixel(parent, q);
    if (a == b) return;
    if (a > b) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
}

/// Seedable 4-neighbours p and q: one set where depth is continuous seen from both, else a
/// one-way pair (from, to) into `oneway` where from one only.
inline void link_pixels(const Ctx& x, int* parent, int* size, std::vector<int>& oneway, int p, int q) {
    const bool pq = x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q));
    const bool qp = x.connected(static_cast<std::size_t>(q), static_cast<std::size_t>(p));
    if (pq && qp) {
        unite_pixels(parent, size, p, q);
    } else if (pq || qp) {
        oneway.push_back(pq ? p : q);
        oneway.push_back(pq ? q : p);
    }
}

/// The sets of rows [v0, v1) on their own (pairs within the strip), one-way pairs into
/// `oneway`. Cost: two neighbour tests per seedable pixel.
void link_strip(const Ctx& x, const std::uint8_t* seeds, SegmentBuffers& ws, int v0, int v1,
                std::vector<int>& oneway) {
    const int W = x.W;
    int* const parent = ws.cc_parent.data();
    int* const size = ws.cc_size.data();
    oneway.clear();
    for (int v = v0; v < v1; ++v) {
        const int row = v * W;
        for (int u = 0; u < W; ++u) {
            const int p = row + u;
            if (!seeds[p]) continue;
            parent[p] = p;
            size[p] = 1;
            if (u > 0 && seeds[p - 1]) link_pixels(x, parent, size, oneway, p, p - 1);
            if (v > v0 && seeds[p - W]) link_pixels(x, parent, size, oneway, p, p - W);
        }
    }
}

/// Each seedable pixel of rows [v0, v1) gets its set's root + 1 in ws.label (0 elsewhere),
/// the strip's roots go to `roots` in raster order. Reads the union-find only.
void find_roots(const std::uint8_t* seeds, SegmentBuffers& ws, int W, int v0, int v1, std::vector<int>& roots) {
    const int* const parent = ws.cc_parent.data();
    int* const label = ws.label.data();
    roots.clear();
    for (int p = v0 * W; p < v1 * W; ++p) {
        if (!seeds[p]) {
            label[p] = 0;
            continue;
        }
        int r = p;
        while (parent[r] != r) r = parent[r];
        label[p] = r + 1;
        if (r == p) roots.push_back(p);
    }
}

/// Numbers the components from the sets (roots in raster order, strip by strip) into
/// ws.cc_id at each root, their sizes into ws.sizes; returns n. Without one-way pairs each
/// set is a component; with some, a depth-first search over them from each set no
/// component holds yet (ws.queue, ws.cc_edges). In: ws.label holding root + 1.
int number_components(SegmentBuffers& ws, int strips) {
    int* const id = ws.cc_id.data();
    ws.sizes.assign(1, 0);
    ws.cc_edges.clear();
    for (int s = 0; s < strips; ++s) {
        const std::vector<int>& pairs = ws.cc_oneway[static_cast<std::size_t>(s)];
        for (std::size_t i = 0; i < pairs.size(); i += 2) {
            const auto a = static_cast<std::uint64_t>(ws.label[static_cast<std::size_t>(pairs[i])] - 1);
            const auto b = static_cast<std::uint64_t>(ws.label[static_cast<std::size_t>(pairs[i + 1])] - 1);
            if (a != b) ws.cc_edges.push_back(a << 32 | b);
        }
    }
    std::sort(ws.cc_edges.begin(), ws.cc_edges.end());
    for (int s = 0; s < strips; ++s)
        for (const int r : ws.cc_roots[static_cast<std::size_t>(s)]) id[r] = 0;
    int n = 0;
    for (int s = 0; s < strips; ++s) {
        for (const int r : ws.cc_roots[static_cast<std::size_t>(s)]) {
            if (id[r]) continue;
            const int c = ++n;
            int size = 0, top = 0;
            id[r] = c;
            ws.queue[static_cast<std::size_t>(top++)] = r;
            while (top > 0) {
                const int a = ws.queue[static_cast<std::size_t>(--top)];
                size += ws.cc_size[static_cast<std::size_t>(a)];
                const std::uint64_t from = static_cast<std::uint64_t>(a) << 32;
                auto e = std::lower_bound(ws.cc_edges.begin(), ws.cc_edges.end(), from);
                for (; e != ws.cc_edges.end() && (*e >> 32) == static_cast<std::uint64_t>(a); ++e) {
                    const auto b = static_cast<int>(*e & 0xffffffffu);
                    if (id[b]) continue;
                    id[b] = c;
                    ws.queue[static_cast<std::size_t>(top++)] = b;
                }
            }
            ws.sizes.push_back(size);
        }
    }
    return n;
}

/// label_components on `strips` strips of rows (2 or more, at most H): the sets of each
/// strip in parallel, joined along the seams, their roots found in parallel, numbered, and
/// the numbers written in parallel.
int components_on_strips(const Ctx& x, const std::uint8_t* seeds, SegmentBuffers& ws, int strips) {
    const int W = x.W, H = x.H;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    ws.cc_parent.resize(N);
    ws.cc_size.resize(N);
    ws.cc_id.resize(N);
    ws.cc_roots.resize(static_cast<std::size_t>(strips));
    ws.cc_oneway.resize(static_cast<std::size_t>(strips));
    auto strip_row = [&](int s) { return static_cast<int>(static_cast<long long>(H) * s / strips); };
#pragma omp parallel for schedule(static)
    for (int s = 0; s < strips; ++s)
        link_strip(x, seeds, ws, strip_row(s), strip_row(s + 1), ws.cc_oneway[static_cast<std::size_t>(s)]);
    // The seams, in order (their one-way pairs with the first strip's).
    for (int s = 1; s < strips; ++s) {
        const int row = strip_row(s) * W;
        for (int p = row; p < row + W; ++p)
            if (seeds[p] && seeds[p - W])
                link_pixels(x, ws.cc_parent.data(), ws.cc_size.data(), ws.cc_oneway[0], p, p - W);
    }
#pragma omp parallel for schedule(static)
    for (int s = 0; s < strips; ++s)
        find_roots(seeds, ws, W, strip_row(s), strip_row(s + 1), ws.cc_roots[static_cast<std::size_t>(s)]);
    const int n = number_components(ws, strips);
    int* const label = ws.label.data();
    const int* const id = ws.cc_id.data();
    const auto n_px = static_cast<std::ptrdiff_t>(N);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p)
        if (label[p]) label[p] = id[label[p] - 1];
    return n;
}

/// A foot candidate (kPlaneFoot: on the support's band, its normal tilted) joins a segment
/// across at most this share of the depth step that joins one surface (Ctx::connected).
/// Where an object stands on the support, its side runs down into the support in small
/// steps. Round an occluding edge seen from above, a camera that blurs depth (the Xtion of
/// OCID, active stereo) leaves a ramp of steep steps down to the support whose normals tilt
/// as well: without this share a ring of table joined every object there. 0.4 of 0.3-0.7
/// tried (docs/ABLATION.md, "Steep feet").
constexpr float kFootStep = 0.4f;

/// Grows the labelled pixels into unlabelled foreground (cut pixels, feet, pixels without a
/// normal, dropped fragments) breadth-first, up to `max_steps`, where depth is continuous
/// (for feet: within kFootStep of the step). With `inside_only`, grows only into
/// kPlaneInside pixels (a container's inside joins the container, however wide). Returns the
/// pixels added. Cost: one parallel pass over the pixels for the search's start, then the
/// search over the pixels it reaches.
std::size_t reattach(const Ctx& x, SegmentBuffers& ws, int max_steps, bool inside_only = false) {
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
            const float steps = x.cls[q] == kPlaneFoot ? kFootStep : 1.0f;
            if (!inside_only && !x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q), steps)) continue;
            ws.label[q] = ws.label[p];
            ws.dist[q] = ws.dist[p] + 1;
            ws.queue[tail++] = q;
            ++added;
        }
    }
    return added;
}

/// Fragments too small to seed an object (cuts.min_seed_points) go back to the unassigned pool:
/// their labels in ws.label become 0. In: ws.sizes from components. Cost: one parallel pass
/// over the pixels.
void drop_small_components(SegmentBuffers& ws, int min_seed) {
    int* const label = ws.label.data();
    const int* const sizes = ws.sizes.data();
    const auto n_px = static_cast<std::ptrdiff_t>(ws.label.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p)
        if (label[p] && sizes[label[p]] < min_seed) label[p] = 0;
}

}  // namespace

int row_strips(int rows) {
    return omp_in_parallel() ? 1 : std::max(1, std::min(omp_get_max_threads(), rows / 8));
}

int team_strips(int rows) {
    return omp_in_parallel() ? std::max(1, std::min(omp_get_num_threads(), rows / 8)) : row_strips(rows);
}

void relabel_to_roots(SegmentBuffers& ws) {
    int* const parent = ws.parent.data();
    const auto n = static_cast<int>(ws.parent.size());
    for (int l = 1; l < n; ++l) parent[l] = find_root(ws.parent, l);
    int* const label = ws.label.data();
    const auto n_px = static_cast<std::ptrdiff_t>(ws.label.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p)
        if (label[p]) label[p] = parent[label[p]];
}

int label_components(const Ctx& x, const std::uint8_t* seedable, SegmentBuffers& ws, int strips) {
    strips = std::min(strips, x.H);
    return strips > 1 ? components_on_strips(x, seedable, ws, strips) : components_by_search(x, seedable, ws);
}

int seed_components(const Ctx& x, SegmentBuffers& ws) {
    // A strip per thread; one thread searches.
    const int n = label_components(x, ws.cut.data(), ws, row_strips(x.H));
    drop_small_components(ws, x.prm.cuts.min_seed_points);
    return n;
}

std::size_t reattach_foreground(const Ctx& x, SegmentBuffers& ws) {
    // Cut pixels, feet and dropped fragments, then containers' insides, join what they touch.
    const std::size_t near = reattach(x, ws, x.prm.cuts.reattach_px);
    return near + reattach(x, ws, x.W + x.H, true);
}

namespace {

/// An orphan region becomes a segment when at least this share of its pixels lie inside it
/// (their four neighbours in it): a small object seen whole is a blob; a band of table behind
/// an object's top edge, object pixels by their height that no segment reaches, is a line
/// two or three pixels thick (a RealSense frame, `uois_realsense_tabletop` image_0003: 254
/// pixels along a drill's top).
constexpr float kOrphanInnerShare = 0.5f;

// Marks in ws.label while seed_orphans runs: the region being flooded, regions left out.
constexpr int kFlooding = -2, kLeftOut = -1;

/// An object pixel that no segment holds. Branch-free, so that the run test below vectorizes.
bool is_orphan(const Ctx& x, const int* label, int p) { return (label[p] == 0) & (x.cls[p] == kPlaneObject); }

/// The first pixel at or after `p` that may be an orphan: runs of 32 pixels without one are
/// skipped with a test the compiler vectorizes (most of a frame is labelled or not an object).
int next_orphan_candidate(const Ctx& x, const int* label, int p, int n_px) {
    constexpr int kRun = 32;
    while (p % kRun == 0 && p < n_px) {
        const int m = std::min(kRun, n_px - p);
        int any = 0;
        for (int i = 0; i < m; ++i) any |= is_orphan(x, label, p + i);
        if (any) break;
        p += m;
    }
    return p;
}

/// Floods the orphan region of `seed` (4-neighbours, depth-continuous) into pixels[first..),
/// marking it kFlooding. Returns its end in `pixels`; `reached` says whether a segment
/// continues into it where depth is continuous (its cut band, not an object).
/// Cost: O(region pixels).
int flood_orphan_region(const Ctx& x, int* label, int* pixels, int first, int seed, bool& reached) {
    int end = first;
    reached = false;
    pixels[end++] = seed;
    label[seed] = kFlooding;
    for (int k = first; k < end; ++k) {
        const int p = pixels[k];
        for (const int q : four_neighbours(p, p % x.W, p / x.W, x.W, x.H)) {
            if (q < 0 || label[q] < 0) continue;
            const bool continuous = x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q));
            if (label[q] > 0) {
                reached |= continuous;
            } else if (x.cls[q] == kPlaneObject && continuous) {
                label[q] = kFlooding;
                pixels[end++] = q;
            }
        }
    }
    return end;
}

/// Whether the flooded region pixels[first..end) is a blob: kOrphanInnerShare of its pixels
/// or more have their four neighbours in it. Cost: O(region pixels).
bool is_blob(const Ctx& x, const int* label, const int* pixels, int first, int end) {
    int inner = 0;
    for (int k = first; k < end; ++k) {
        const int p = pixels[k];
        bool all = true;
        for (const int q : four_neighbours(p, p % x.W, p / x.W, x.W, x.H)) all &= q >= 0 && label[q] == kFlooding;
        inner += all;
    }
    return static_cast<float>(inner) >= kOrphanInnerShare * static_cast<float>(end - first);
}

}  // namespace

int seed_orphans(const Ctx& x, SegmentBuffers& ws, int n) {
    const int n_px = x.W * x.H;
    int* const label = ws.label.data();
    int* const pixels = ws.queue.data();  // every region flooded, one after another
    int end = 0;
    for (int seed = next_orphan_candidate(x, label, 0, n_px); seed < n_px;
         seed = next_orphan_candidate(x, label, seed + 1, n_px)) {
        if (!is_orphan(x, label, seed)) continue;
        const int first = end;
        bool reached = false;
        end = flood_orphan_region(x, label, pixels, first, seed, reached);
        const bool object = !reached && end - first >= x.prm.cuts.min_seed_points && is_blob(x, label, pixels, first, end);
        if (object) ++n;
        for (int k = first; k < end; ++k) label[pixels[k]] = object ? n : kLeftOut;
    }
    for (int k = 0; k < end; ++k)
        if (label[pixels[k]] == kLeftOut) label[pixels[k]] = 0;
    return n;
}

/// Drops labels with fewer than min_points pixels and writes the rest to `out` renumbered
/// 1..n in order of first appearance (raster order); ws.label keeps the old numbers. Returns
/// n. Each band of the image (a band per thread, in parallel) counts its labels' pixels and
/// first pixel, the labels are numbered, then `out` is written in parallel. Cost: two
/// parallel passes over the pixels, O(bands n + n log n) between them.
int compact(SegmentBuffers& ws, int n, int min_points, std::uint16_t* out) {
    // Bands of 512 pixels at least (row_strips' 8 rows of 64).
    const int bands = team_strips(static_cast<int>(std::min<std::size_t>(ws.label.size(), 1u << 30) / 64));
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    const std::size_t B = (L + 15) / 16 * 16;  // a band's row, whole cache lines (no false sharing)
    const auto N = static_cast<std::ptrdiff_t>(ws.label.size());
    ws.sizes.assign(static_cast<std::size_t>(bands) * B, 0);  // per band: pixels
    ws.offsets.resize(static_cast<std::size_t>(bands) * B);   // per band: first pixel, valid where it has pixels
    int* const label = ws.label.data();
    for_each_part(bands, Spread::kStatic, [&](std::ptrdiff_t band) {
        int* const count = ws.sizes.data() + static_cast<std::size_t>(band) * B;
        int* const first = ws.offsets.data() + static_cast<std::size_t>(band) * B;
        const auto p0 = static_cast<std::size_t>(N * band / bands), p1 = static_cast<std::size_t>(N * (band + 1) / bands);
        for_label_runs(label, p0, p1, [&](int l, std::size_t p, std::size_t run) {
            if (count[l] == 0) first[l] = static_cast<int>(p);
            count[l] += static_cast<int>(run);
        });
    });
    // Labels in order of their first pixel; the large enough ones numbered in that order.
    ws.order.clear();
    for (std::size_t l = 1; l < L; ++l) {
        int size = 0, first = std::numeric_limits<int>::max();
        for (int band = 0; band < bands; ++band) {
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
    for_each_part(bands, Spread::kStatic, [&](std::ptrdiff_t band) {
        for (std::ptrdiff_t p = N * band / bands; p < N * (band + 1) / bands; ++p)
            out[p] = static_cast<std::uint16_t>(std::min(remap[label[p]], 65535));
    });
    return next;
}

}  // namespace wul3d::detail
