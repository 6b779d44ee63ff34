#pragma once
// remove_support_plane's scratch (PlaneWorkspace::Buffers) and the phases that plane.cpp and
// plane_islands.cpp share. Private to the library.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "branch_free.hpp"
#include "wul3d/cloud.hpp"
#include "wul3d/plane.hpp"

namespace wul3d {

struct PlaneWorkspace::Buffers {
    /// The grid's points gathered once (every grid_stride_px-th pixel), structure of arrays.
    struct GridPoints {
        std::vector<float> x, y, z, nx, ny, nz;
        std::vector<std::uint8_t> active, usable;  ///< usable: active with a normal
    } grid;
    std::vector<int> region;          ///< grid point -> region id, -1 none
    std::vector<int> stack;
    std::vector<double> sums;         ///< per region: count, sum x, y, z, xx, xy, xz, yy, yz, zz
    std::vector<std::uint8_t> hull;   ///< grid-resolution mask of the support's extent
    std::vector<int> hull_points;     ///< (gu, gv) pairs: each grid row's outermost inliers
    std::vector<Plane> fitted;        ///< the merged planes, fitted, inliers counted
    std::vector<float> layer_t;       ///< per grid point: height over the chosen support in
                                      ///< half bands (1e9 if it does not face like it)
    std::vector<int> by_extent;       ///< candidate indices, largest extent first
    std::vector<std::uint32_t> candidate_bits;  ///< per grid point: bit r = inlier of rank r
    std::vector<int> shared;          ///< inliers two candidates share (ranks i > j)
    std::vector<std::uint8_t> sliver; ///< per rank: cuts through a larger candidate, not scored
    std::vector<std::uint8_t> tall_foot;  ///< per grid cell: something rises from it past
                                          ///< max_object_height_m over the candidate counted
    std::vector<std::uint8_t> on_band;  ///< per pixel: 1 = removed and on the plane's band
    /// Per pixel (mark_over_most): its vote, 16 x (over the band) + (has depth); the votes of
    /// its column's three rows summed; 1 = over the band, and so is most of its 3 x 3.
    std::vector<std::uint8_t> band_votes, column_votes, over_most;
    std::vector<int> low_piece;         ///< grid points of a low support's top (remove_low_support)
    std::vector<std::uint8_t> low_mask; ///< per grid point: in the low support's layer, piece or plane
    std::vector<double> low_sums;       ///< per piece of low_mask: count, summed height and band
    /// Runs of on-band pixels, row by row, and their union-find components (islands).
    struct Run {
        int row, begin, end;  ///< pixels [begin, end) of the row
        int parent;           ///< union-find parent (a run index)
    };
    std::vector<Run> runs;
    std::vector<int> row_first_run;     ///< per row + 1: index of its first run
    /// Per run, then summed into its root run: heights over the plane, pixels (roots only),
    /// flags 1 = open (image border, or beside removed points off the band), 2 = beside
    /// object points.
    std::vector<double> island_height;
    std::vector<int> island_size;
    std::vector<std::uint8_t> island_flags;
};

namespace detail {

/// The coarse grid planes are grown on: w x h points, every s-th pixel of a W-wide image.
struct Grid {
    int w = 0, h = 0, s = 1, W = 0;
    int size() const { return w * h; }
};

inline Grid make_grid(int W, int H, int stride) {
    Grid grid;
    grid.s = stride;
    grid.w = (W + grid.s - 1) / grid.s;
    grid.h = (H + grid.s - 1) / grid.s;
    grid.W = W;
    return grid;
}

/// The plane's band at depth z: heights within it are on the plane (sensor noise grows
/// with z^2). Plain values, copied into the loops that use it: the grid loops vectorize,
/// and a byte store there cannot change them as far as the compiler knows.
struct Band {
    float m, rel;
    float operator()(float z) const { return m + rel * z * z; }
};

/// The support's extent as a grid-resolution mask, and the test the pixels take against it:
/// a point belongs over the support when its foot (the point moved down the normal onto the
/// plane, `h` above it) projects into the mask. Plain values and a raw pointer: the
/// per-pixel loops that call it store bytes, which would otherwise make the compiler reload
/// every member on each pixel.
struct HullMask {
    const std::uint8_t* mask;
    std::size_t w;
    float fw, fh;            // w, h as floats
    float gfx, gfy, gcx, gcy;  // intrinsics in grid cells, centres + 0.5 (cell by truncation)
    float nx, ny, nz;        // the plane's normal

    /// A foot below the frame's bottom edge is tested on that edge's row. A camera looking
    /// down on a table cuts off the table's near part with the frame's bottom, and a foot
    /// lies lower in the image than its point, so the nearest objects' feet fall out of
    /// the frame with the table running on under them: where the hull reaches the bottom
    /// edge there, they are over the support; where the table's near edge is in view, the
    /// hull stops above it and they are not. Beyond the top and sides a foot stays off the
    /// image (docs/ABLATION.md, "Support plane").
    float below_to_edge(float gv) const { return std::min(gv, fh - 0.5f); }

    /// The grid cell the foot projects into, -1 off the image.
    std::ptrdiff_t foot_cell(float x, float y, float z, float h) const {
        const float fx = x - h * nx, fy = y - h * ny, fz = z - h * nz;
        if (fz <= 1e-3f) return -1;
        const float inv_z = 1.0f / fz;
        const float gu = gfx * fx * inv_z + gcx, gv = below_to_edge(gfy * fy * inv_z + gcy);
        if (!(gu >= 0.0f && gv >= 0.0f && gu < fw && gv < fh)) return -1;
        return static_cast<std::ptrdiff_t>(static_cast<std::size_t>(gv) * w + static_cast<std::size_t>(gu));
    }
    /// foot_cell as int, without a branch (vectorizes): -1 off the image.
    int foot_cell_or_none(float x, float y, float z, float h) const {
        const float fx = x - h * nx, fy = y - h * ny, fz = z - h * nz;
        const float inv_z = 1.0f / fz;
        const float gu = gfx * fx * inv_z + gcx, gv = below_to_edge(gfy * fy * inv_z + gcy);
        const bool in = (fz > 1e-3f) & (gu >= 0.0f) & (gv >= 0.0f) & (gu < fw) & (gv < fh);
        // Off the image gu, gv may be anything (inf, NaN): 0 instead, so the conversion is defined.
        const int cu = static_cast<int>(detail::pick(in, gu, 0.0f)), cv = static_cast<int>(detail::pick(in, gv, 0.0f));
        return cv * static_cast<int>(w) + cu - !in;  // cu = cv = 0 off the image
    }
};

/// The test against `hull` (ws.hull, built by build_hull for `pl`). Per pixel in the hot
/// loops: float arithmetic, grid cell by rounding (no libm call).
inline HullMask make_hull_mask(const Grid& grid, const PinholeIntrinsics& K, const Plane& pl,
                        const std::vector<std::uint8_t>& hull) {
    const float inv_s = 1.0f / static_cast<float>(grid.s);
    return HullMask{hull.data(), static_cast<std::size_t>(grid.w), static_cast<float>(grid.w),
                    static_cast<float>(grid.h), static_cast<float>(K.fx) * inv_s,
                    static_cast<float>(K.fy) * inv_s, static_cast<float>(K.cx) * inv_s + 0.5f,
                    static_cast<float>(K.cy) * inv_s + 0.5f, pl.nx, pl.ny, pl.nz};
}

/// A grid point is an inlier of a plane when it lies on the plane's band and its normal
/// agrees with the plane's. No branch: a point without a usable normal holds the zero
/// normal and fails the normal test, so loops over the grid vectorize. Reads the gathered
/// grid (gather_grid), G points.
struct InlierTest {
    const float *x, *y, *z, *nx, *ny, *nz;
    int G;
    Band band;
    float cos_inlier;

    /// `band_share` narrows the band: refine_support parts layers on half of it.
    bool operator()(const Plane& pl, int g, float band_share = 1.0f) const {
        const float h = pl.nx * x[g] + pl.ny * y[g] + pl.nz * z[g] + pl.d;
        const bool on = std::fabs(h) <= band_share * band(z[g]);
        const bool facing = nx[g] * pl.nx + ny[g] * pl.ny + nz[g] * pl.nz >= cos_inlier;
        return on & facing;
    }
    /// take(g, (*this)(pl, g)) over the whole grid. G is read once: an int that take()
    /// stores could be G as far as the compiler knows.
    template <class Take>
    void for_each(const Plane& pl, Take&& take) const {
        const int n = G;
        for (int g = 0; g < n; ++g) take(g, (*this)(pl, g));
    }
    std::size_t count(const Plane& pl) const {
        unsigned inliers = 0;
        for_each(pl, [&](int, bool in) { inliers += static_cast<unsigned>(in); });
        return static_cast<std::size_t>(inliers);
    }
};

/// 6. Classify every pixel (plane_pixels.cpp): below or on the plane (and facing like it)
/// is removed; on the band but facing otherwise is a candidate foot; above and over the
/// support is object, where most of the pixels with depth in its 3 x 3 lie above the band
/// too (mark_over_most: a lone pixel over the band is a depth error, and counts as on it).
/// In: the support `pl` and its extent `ws.hull`. Out: `classes` (N, PlaneClass),
/// `ws.on_band` (N, 1 = removed and on the band) and `ws.row_first_run[v + 1]` (row v's
/// number of runs of on-band pixels, for restore_islands); returns the pixels kept. O(N):
/// mark_over_most's three parallel passes, then one for the classes; no allocation once the
/// buffers have the frame's size.
std::size_t classify_pixels(const Grid& grid, const PinholeIntrinsics& K, const OrganizedCloud& cloud,
                            const NormalMap& normals, const std::vector<std::uint8_t>& active,
                            const Plane& pl, Band on_band, float cos_inlier,
                            PlaneWorkspace::Buffers& ws, std::vector<std::uint8_t>& classes);

/// 7. Islands (plane_pixels.cpp) (plane_islands.cpp): on-plane patches that the objects enclose (a bowl's
/// inner bottom seen through its opening) given back as kPlaneInside. In: classify_pixels'
/// `classes`, `ws.on_band` and run counts. Out: `classes` with kPlaneInside; returns the
/// pixels given back. O(N) for the runs, then O(runs).
std::size_t restore_islands(const PlaneParams& params, const OrganizedCloud& cloud,
                            const std::vector<std::uint8_t>& active, const Plane& pl,
                            PlaneWorkspace::Buffers& ws, std::vector<std::uint8_t>& classes);

/// The least-squares plane of the grid points with take[g] != 0 into `out` (plane.cpp; the
/// same sums on any number of threads); false (and `out` unchanged) under min_points. O(G).
bool fit_grid_points(const InlierTest& grid, int min_points, const std::uint8_t* take, Plane& out);

/// 8. A low support (plane_low_support.cpp): a board or tray lying on the support `pl`, the
/// objects on it. Its top is the densest layer of grid points facing like `pl` over three
/// quarters of its band and at most 5 cm above it, whose largest 8-connected piece spans
/// 0.1 m^2 on the plane (more than any object lying flat). Over that piece's extent in the
/// image, every object pixel (or container's inside) not above the low support's band is
/// removed (its top, its sides, what lies under it), but those on its band facing otherwise,
/// which become candidate feet; off it, those up to 5 cm over the low support whose foot lies
/// within 5 cm of the piece's hull on the plane (a tray's rim). The layer and its plane take
/// `inliers`' band (the given one); the pixels take `removal_band` (the frame's, widened with
/// its noise as the support's pixels' is). Out: `classes`, `low` (its plane, when found); returns the pixels
/// removed (0: none found).
/// O(G) for the layer and its pieces, O(N) for the pixels and a test against the hull's edges
/// for each pixel low enough to be a rim; OpenCV allocates the hulls.
std::size_t remove_low_support(const PlaneParams& params, const Grid& grid, const OrganizedCloud& cloud,
                               const NormalMap& normals, const InlierTest& inliers, const Plane& pl,
                               PlaneWorkspace::Buffers& ws, std::vector<std::uint8_t>& classes, Plane& low,
                               const Band& removal_band);

}  // namespace detail
}  // namespace wul3d
