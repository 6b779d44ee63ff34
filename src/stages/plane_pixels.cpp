// Steps 6 and 7 of remove_support_plane (plane.cpp): every pixel classified against the
// support, then the islands given back. The islands: on-plane patches that the objects enclose (a
// bowl's inner bottom seen through its opening) are object material, not the support: a
// 4-connected patch of removed on-band pixels that touches neither the image border nor
// other removed points, borders object points, is small and sits on average above the
// plane is given back (kPlaneInside). The patches are found as runs of on-band pixels per
// row joined by union-find where runs of consecutive rows overlap: a few thousand runs
// instead of a flood fill over the table.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "branch_free.hpp"
#include "plane_internal.hpp"

namespace wul3d::detail {

using PlaneBuffers = PlaneWorkspace::Buffers;

namespace {

/// What classify_pixels tests per pixel: the cloud, normals and active mask (raw
/// pointers), the support and its band, and its extent.
struct PixelTest {
    const float *xs, *ys, *zs, *nxs, *nys, *nzs;
    const std::uint8_t *act, *has_normal, *over_most;
    Plane pl;
    Band on_band;
    float cos_inlier;
    HullMask hull;
};

/// classify_pixels' per-pixel test up to the hull lookup, for pixels [p0, p0 + n): what the
/// hull decides (`hull_makes`: object above the band, foot on it where the normal faces
/// otherwise, else removed; removed where inactive), the hull cell under the pixel (`cell`,
/// -1 off the image) and whether it lies on the band (`near`). Branch-free so that it
/// vectorizes; built for AVX2 and baseline x86-64 (no FMA either way: the same bits).
/// Cost: one pass.
WUL3D_AVX2_CLONES
void hull_candidates(const PixelTest& t, std::size_t p0, int n, std::uint8_t* __restrict hull_makes,
                     std::uint8_t* __restrict near, int* __restrict cell) {
    // Locals: a byte store may alias `t` as far as the compiler knows.
    const float *const xs = t.xs, *const ys = t.ys, *const zs = t.zs;
    const float *const nxs = t.nxs, *const nys = t.nys, *const nzs = t.nzs;
    const std::uint8_t *const act = t.act, *const has_normal = t.has_normal, *const over_most = t.over_most;
    const float pnx = t.pl.nx, pny = t.pl.ny, pnz = t.pl.nz, pd = t.pl.d, cos_inlier = t.cos_inlier;
    const Band on_band = t.on_band;
    const HullMask hull = t.hull;
    for (int j = 0; j < n; ++j) {
        const std::size_t p = p0 + j;
        const float x = xs[p], y = ys[p], z = zs[p];
        const float h = pnx * x + pny * y + pnz * z + pd, band = on_band(z);
        const bool faces_otherwise = (h > -band) & (has_normal[p] != 0) &
                                     (nxs[p] * pnx + nys[p] * pny + nzs[p] * pnz < cos_inlier);
        // Arithmetic, not `?:`, which GCC keeps as branches here. A lone pixel over the
        // band (mark_over_most) is taken as on it.
        const bool above = over_most[p] != 0;
        const int makes = above * kPlaneObject + (!above & faces_otherwise) * kPlaneFoot;
        hull_makes[j] = static_cast<std::uint8_t>(makes * (act[p] != 0));
        near[j] = (act[p] != 0) & !above & (h >= -band);
        cell[j] = hull.foot_cell_or_none(x, y, z, h);
    }
}

/// Per pixel, into ws.over_most: 1 where it lies over the band and so do most of the pixels
/// with depth in its 3 x 3, itself counted (the median of their heights is over the band: of
/// n such pixels, (n + 1) / 2 or more over it). A pixel over the band among pixels on it is a
/// depth error, not an object: a time-of-flight camera's flying pixels, mixed between an
/// object's edge and the floor behind; a noisy camera's spikes on the table. Left over the
/// band, they seeded specks and bridged objects to the floor; taken as on it, they join the
/// band's classes (feet, the islands of restore_islands) as its other pixels do. An object's
/// pixels have their neighbours over the band, but where it is thinner than two pixels.
/// Each pixel's vote is one byte, 16 x (over the band) + (has depth): three rows of them
/// summed, then three columns, hold both counts (at most 9 each) in one byte. Cost: three
/// parallel passes over the pixels, byte arithmetic that vectorizes.
void mark_over_most(const OrganizedCloud& cloud, const Plane& pl, Band on_band, PlaneBuffers& ws) {
    const int W = cloud.width, H = cloud.height;
    ws.band_votes.resize(cloud.size());
    ws.column_votes.resize(cloud.size());
    ws.over_most.resize(cloud.size());
    const float *const xs = cloud.x.data(), *const ys = cloud.y.data(), *const zs = cloud.z.data();
    const std::uint8_t* const valid = cloud.valid.data();
    std::uint8_t* const vote = ws.band_votes.data();
    const auto n_px = static_cast<std::ptrdiff_t>(cloud.size());
    const float pnx = pl.nx, pny = pl.ny, pnz = pl.nz, pd = pl.d;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n_px; ++p) {
        const float h = pnx * xs[p] + pny * ys[p] + pnz * zs[p] + pd;
        const int has_depth = valid[p] != 0;
        vote[p] = static_cast<std::uint8_t>(has_depth * (16 * (h > on_band(zs[p])) + 1));
    }
    std::uint8_t* const column = ws.column_votes.data();
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        // Rows off the image add nothing.
        const std::uint8_t* const mid = vote + static_cast<std::size_t>(v) * W;
        const std::uint8_t* const up = v > 0 ? mid - W : nullptr;
        const std::uint8_t* const down = v + 1 < H ? mid + W : nullptr;
        std::uint8_t* const out = column + static_cast<std::size_t>(v) * W;
        for (int u = 0; u < W; ++u) out[u] = mid[u];
        if (up)
            for (int u = 0; u < W; ++u) out[u] = static_cast<std::uint8_t>(out[u] + up[u]);
        if (down)
            for (int u = 0; u < W; ++u) out[u] = static_cast<std::uint8_t>(out[u] + down[u]);
    }
    std::uint8_t* const most = ws.over_most.data();
    auto decide = [](std::uint8_t own, int sum) {
        const int over = sum >> 4, n = sum & 15;
        return static_cast<std::uint8_t>((own >> 4) & (2 * over >= n + (n & 1)));
    };
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        const std::uint8_t *const c = column + row, *const own = vote + row;
        std::uint8_t* const out = most + row;
        if (W == 1) {
            out[0] = decide(own[0], c[0]);
            continue;
        }
        out[0] = decide(own[0], c[0] + c[1]);
        for (int u = 1; u + 1 < W; ++u) out[u] = decide(own[u], c[u - 1] + c[u] + c[u + 1]);
        out[W - 1] = decide(own[W - 1], c[W - 2] + c[W - 1]);
    }
}

}  // namespace

std::size_t classify_pixels(const Grid& grid, const PinholeIntrinsics& K, const OrganizedCloud& cloud,
                            const NormalMap& normals, const std::vector<std::uint8_t>& active,
                            const Plane& pl, const Band on_band, const float cos_inlier,
                            PlaneBuffers& ws, std::vector<std::uint8_t>& classes) {
    const int W = cloud.width, H = cloud.height;
    ws.on_band.resize(cloud.size());
    ws.row_first_run.assign(static_cast<std::size_t>(H) + 1, 0);
    std::size_t kept = 0;
    // Raw pointers: the byte stores below may alias anything, so through the containers the
    // compiler would reload their data pointers on every pixel.
    const float *const xs = cloud.x.data(), *const ys = cloud.y.data(), *const zs = cloud.z.data();
    const float *const nxs = normals.nx.data(), *const nys = normals.ny.data(), *const nzs = normals.nz.data();
    const std::uint8_t *const act = active.data(), *const has_normal = normals.valid.data();
    std::uint8_t* const cls = classes.data();
    std::uint8_t* const band_out = ws.on_band.data();
    // ... and the mask a local copy for the same reason. Per chunk of a row, the arithmetic
    // in hull_candidates (vectorized), then the hull lookups and counts here.
    const HullMask hull = make_hull_mask(grid, K, pl, ws.hull);
    mark_over_most(cloud, pl, on_band, ws);
    const PixelTest test{xs, ys, zs, nxs, nys, nzs, act, has_normal, ws.over_most.data(), pl, on_band, cos_inlier, hull};
    constexpr int kChunk = 64;  // pixels per call of hull_candidates
#pragma omp parallel for schedule(static) reduction(+ : kept)
    for (int v = 0; v < H; ++v) {
        int runs = 0;
        std::uint8_t previous = 0;
        for (int u0 = 0; u0 < W; u0 += kChunk) {
            const std::size_t p0 = static_cast<std::size_t>(v) * W + u0;
            const int n = std::min(kChunk, W - u0);
            std::uint8_t hull_makes[kChunk], near[kChunk];
            int cell[kChunk];
            hull_candidates(test, p0, n, hull_makes, near, cell);
            // Then the hull lookups where the hull decides, and the counts.
            for (int j = 0; j < n; ++j) {
                const std::uint8_t c = hull_makes[j] != kPlaneRemoved && cell[j] >= 0 && hull.mask[cell[j]] != 0
                                           ? hull_makes[j]
                                           : std::uint8_t{kPlaneRemoved};
                const std::uint8_t on_band_removed = c == kPlaneRemoved && near[j];
                cls[p0 + j] = c;
                band_out[p0 + j] = on_band_removed;
                kept += c != kPlaneRemoved;
                runs += on_band_removed > previous;
                previous = on_band_removed;
            }
        }
        ws.row_first_run[static_cast<std::size_t>(v) + 1] = runs;
    }
    return kept;
}

namespace {

using Run = PlaneBuffers::Run;

/// The root of run `a`'s set, halving the path on the way.
int find_run(std::vector<Run>& runs, int a) {
    while (runs[static_cast<std::size_t>(a)].parent != a) {
        auto& r = runs[static_cast<std::size_t>(a)];
        r.parent = runs[static_cast<std::size_t>(r.parent)].parent;
        a = r.parent;
    }
    return a;
}

/// The runs of `ws.on_band`, row by row in parallel, each row's at its offset. In:
/// `ws.row_first_run[v + 1]` = row v's count (classify_pixels). Out: `ws.row_first_run`
/// as offsets (H + 1), `ws.runs` (each its own set). O(N), one parallel pass; no
/// allocation once `ws.runs` has the capacity.
void find_band_runs(int W, int H, PlaneBuffers& ws) {
    const std::uint8_t* band = ws.on_band.data();
    auto& runs = ws.runs;
    for (int v = 0; v < H; ++v)
        ws.row_first_run[static_cast<std::size_t>(v) + 1] += ws.row_first_run[static_cast<std::size_t>(v)];
    const std::size_t R = static_cast<std::size_t>(ws.row_first_run[static_cast<std::size_t>(H)]);
    runs.resize(R);
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        int id = ws.row_first_run[static_cast<std::size_t>(v)];
        const std::uint8_t* row = band + static_cast<std::size_t>(v) * W;
        for (int u = 0; u < W;) {
            if (!row[u]) {
                ++u;
                continue;
            }
            const int begin = u;
            while (u < W && row[u]) ++u;
            runs[static_cast<std::size_t>(id)] = {v, begin, u, id};
            ++id;
        }
    }
}

/// Per run (in parallel): what borders it and, unless that opens it (its island is then
/// open whatever else it holds: most of the table's runs), its heights over `pl`. Out:
/// `ws.island_flags`, `ws.island_height` per run; `ws.island_size` zeroed. O(runs' pixels
/// and their neighbours above and below), one parallel pass; no allocation once sized.
void inspect_runs(const OrganizedCloud& cloud, const std::vector<std::uint8_t>& active, const Plane& pl,
                  const std::vector<std::uint8_t>& classes, PlaneBuffers& ws) {
    const int W = cloud.width, H = cloud.height;
    const std::uint8_t* band = ws.on_band.data();
    const auto& runs = ws.runs;
    const std::size_t R = runs.size();
    ws.island_height.assign(R, 0.0);
    ws.island_size.assign(R, 0);
    ws.island_flags.assign(R, 0);
    // A neighbour outside the patch: object material, or a removed active point off the
    // band (support or room beside it) that opens the patch.
    auto look = [&](std::size_t q, std::uint8_t& flags) {
        if (band[q]) return;
        if (classes[q] != kPlaneRemoved) flags |= 2;
        else if (active[q]) flags |= 1;
    };
    const auto Rn = static_cast<std::ptrdiff_t>(R);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < Rn; ++i) {
        const auto& r = runs[static_cast<std::size_t>(i)];
        std::uint8_t flags = 0;
        const std::size_t row = static_cast<std::size_t>(r.row) * W;
        if (r.row == 0 || r.row == H - 1 || r.begin == 0 || r.end == W) {
            flags |= 1;  // touches the image border
        } else {
            look(row + static_cast<std::size_t>(r.begin) - 1, flags);
            look(row + static_cast<std::size_t>(r.end), flags);
            for (int u = r.begin; u < r.end && !(flags & 1); ++u) {
                look(row - W + static_cast<std::size_t>(u), flags);
                look(row + W + static_cast<std::size_t>(u), flags);
            }
        }
        double height = 0;
        if (!(flags & 1))
            for (int u = r.begin; u < r.end; ++u) {
                const std::size_t p = row + static_cast<std::size_t>(u);
                height += pl.height(cloud.x[p], cloud.y[p], cloud.z[p]);
            }
        ws.island_height[static_cast<std::size_t>(i)] = height;
        ws.island_flags[static_cast<std::size_t>(i)] = flags;
    }
}

/// Runs of consecutive rows that share a column (4-connectivity) join, except two open
/// runs: their islands are open whatever else they join (most of the table's runs). Then
/// each run's size, heights and flags are summed into its root. Out: `ws.runs`' parents,
/// `ws.island_*` complete at the roots. O(runs) near-constant union-find steps,
/// sequential; no allocation.
void join_runs_into_islands(int H, PlaneBuffers& ws) {
    auto& runs = ws.runs;
    for (int v = 1; v < H; ++v) {
        int a = ws.row_first_run[static_cast<std::size_t>(v) - 1];
        const int a_end = ws.row_first_run[static_cast<std::size_t>(v)];
        const int b_end = ws.row_first_run[static_cast<std::size_t>(v) + 1];
        for (int b = a_end; b < b_end; ++b) {
            const auto& rb = runs[static_cast<std::size_t>(b)];
            while (a < a_end && runs[static_cast<std::size_t>(a)].end <= rb.begin) ++a;
            const bool b_open = ws.island_flags[static_cast<std::size_t>(b)] & 1;
            for (int c = a; c < a_end && runs[static_cast<std::size_t>(c)].begin < rb.end; ++c) {
                if (b_open && (ws.island_flags[static_cast<std::size_t>(c)] & 1)) continue;
                const int ra = find_run(runs, c), rb_root = find_run(runs, b);
                if (ra != rb_root) runs[static_cast<std::size_t>(std::max(ra, rb_root))].parent = std::min(ra, rb_root);
            }
        }
    }
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const auto& r = runs[i];
        const std::size_t root = static_cast<std::size_t>(find_run(runs, static_cast<int>(i)));
        ws.island_size[root] += r.end - r.begin;
        if (root == i) continue;
        ws.island_height[root] += ws.island_height[i];
        ws.island_flags[root] |= ws.island_flags[i];
    }
}

/// The closed islands that border object points only, are small and sit above the plane
/// become kPlaneInside in `classes`; returns their pixels. O(runs + the pixels given
/// back), sequential; no allocation.
std::size_t give_back_islands(const PlaneParams& params, int W, std::size_t N, PlaneBuffers& ws,
                              std::vector<std::uint8_t>& classes) {
    auto& runs = ws.runs;
    const double max_size = params.island_max_share * static_cast<double>(N);
    std::size_t restored = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const auto& r = runs[i];
        const std::size_t root = static_cast<std::size_t>(find_run(runs, static_cast<int>(i)));
        const int size = ws.island_size[root];
        if (ws.island_flags[root] != 2 || size > max_size ||
            ws.island_height[root] / size <= params.island_min_height_m)
            continue;
        std::fill(classes.begin() + static_cast<std::ptrdiff_t>(r.row) * W + r.begin,
                  classes.begin() + static_cast<std::ptrdiff_t>(r.row) * W + r.end, kPlaneInside);
        restored += static_cast<std::size_t>(r.end - r.begin);
    }
    return restored;
}

}  // namespace

std::size_t restore_islands(const PlaneParams& params, const OrganizedCloud& cloud,
                            const std::vector<std::uint8_t>& active, const Plane& pl,
                            PlaneBuffers& ws, std::vector<std::uint8_t>& classes) {
    find_band_runs(cloud.width, cloud.height, ws);
    inspect_runs(cloud, active, pl, classes, ws);
    join_runs_into_islands(cloud.height, ws);
    return give_back_islands(params, cloud.width, cloud.size(), ws, classes);
}

}  // namespace wul3d::detail
