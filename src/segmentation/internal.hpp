#pragma once
// Private to src/segmentation/ (not installed): the context every phase of segment_objects
// reads, coordinates on the support plane, the union-find over segments, and the phases and
// rules the driver (segmentation.cpp) calls, each defined in a file of its own.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../plane_axes.hpp"
#include "wul3d/cloud.hpp"
#include "wul3d/normals.hpp"
#include "wul3d/plane.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d {

namespace detail {
/// A 4-neighbour pixel pair where two segments meet (the container rule).
struct BoundaryStep {
    std::uint64_t key;   ///< lower segment << 34 | higher << 4 | depth step << 1 | lower nearer
    std::uint32_t near;  ///< the nearer pixel
};
}  // namespace detail

/// Pixels u0..u1 of row v, all of segment `label` (the pieces phase).
struct LabelRun {
    int v, u0, u1, label;
};

/// segment_objects' buffers (SegmentWorkspace, opaque to its callers).
struct SegmentWorkspace::Buffers {
    NormalMap smooth;                  ///< smoothed normals (cuts.normal_smooth_px)
    std::vector<float> smooth_scratch;
    std::vector<std::uint8_t> cut;     ///< 1 = may seed a component
    std::vector<std::uint8_t> crease;  ///< bit 0: (p, p + s) concave along u; bit 1: along v
    std::vector<int> label;    ///< 0 none, 1..n
    std::vector<LabelRun> runs;        ///< pieces: the runs of equal labels, row by row
    std::vector<int> row_runs;         ///< pieces: each row's first run (H + 1)
    std::vector<int> run_parent;       ///< pieces: union-find over runs
    std::vector<int> run_pixels;       ///< pieces: per root run, its piece's pixels
    std::vector<int> queue;
    std::vector<int> dist;
    std::vector<int> sizes;
    std::vector<int> remap;
    std::vector<int> offsets;  ///< counting sort of pixels by label
    std::vector<int> order;
    // The final renumbering (compact) reuses sizes, offsets and order for each label's pixel
    // count, first pixel and the labels kept, in order of their first pixel.
    // Components on several threads (components.cpp): per pixel the union-find parent, the
    // set's pixels at its root, each root's component; per strip of rows its roots in raster
    // order and its one-way pairs (far, near: depth continuous seen from the far pixel only).
    std::vector<int> cc_parent, cc_size, cc_id;
    std::vector<std::vector<int>> cc_roots, cc_oneway;
    std::vector<std::uint64_t> cc_edges;  ///< one-way pairs between sets: from << 32 | to
    // Passes over the pixels in strips of rows, a strip per thread (merge, containers, scope):
    // per strip its pairs, its boundary steps, and per segment its first and last row.
    std::vector<std::vector<std::uint64_t>> strip_pairs;
    std::vector<std::vector<detail::BoundaryStep>> strip_steps;
    std::vector<int> strip_rows;
    std::vector<std::uint8_t> part;    ///< colour cue: 2-means part per pixel
    std::vector<std::uint8_t> part_in_order;  ///< ... and per position in `order`
    std::vector<int> next_order, next_offsets;  ///< colour cue: the next round's sort
    std::vector<float> feature;        ///< colour cue: 6 planes, segment pixels in `order`
    std::vector<std::uint8_t> split;   ///< colour cue: 1 = split segment l
    std::vector<std::uint8_t> to_try;  ///< colour cue: 1 = try segment l this round
    std::vector<int> by_size;          ///< colour cue: the segments tried, largest first
    std::vector<std::uint64_t> edges;  ///< (segment pair, concave bit) per boundary pair
    std::vector<int> parent;           ///< union-find over segments
    std::vector<std::pair<std::uint64_t, float>> occluded_lines;  ///< occlusion: segment pair,
                                                                  ///< offset per line (steps)
    std::vector<std::uint8_t> occluded_outline;  ///< occlusion: 1 = outline pixel, one row
    // The neck rule (necks.cpp): segment pairs in contact in view and their contacts, the pairs
    // that touch; the segments of those given slots, and per slot its points' summed height,
    // count and greatest height; the pairs whose upper segment stands on the lower (NeckPair);
    // per slot whether a pass wants its pixels, its walls' sums (NeckWallSums), as a lower one
    // its walls (NeckWall) and axis, and as an upper one its first pair.
    struct NeckWallSums {
        double c4 = 0, s4 = 0;  ///< the normals' directions on the plane at four times their angle
        int walls = 0;
    };
    struct NeckWall {
        int slot, layer;  ///< layer: round_layer of its height
        double u, v;      ///< on the support plane (PlaneAxes)
    };
    /// A round body's axis and radius on the support plane (the neck rule's body_axis).
    struct BodyAxis {
        Eigen::Vector2d centre = Eigen::Vector2d::Zero();
        double radius = 0;  ///< the widest layer's
    };
    struct NeckPair {
        int upper = 0, lower = 0;
        BodyAxis body;              ///< the lower one's axis and radius
        int points = 0, near = 0;   ///< the upper one's points, and those near the axis
        int in_body = 0;            ///< ... those within the body's radius of it
        int top = 0, top_near = 0;  ///< ... those of its top (kNeckTopM), and those near the axis
    };
    std::vector<std::uint8_t> neck_outline;  ///< one row's outline pixels and run ends
    std::vector<std::array<int, 3>> neck_runs;  ///< runs of one label: label, first pixel, length
    std::vector<std::pair<std::uint64_t, int>> neck_pairs;
    std::vector<int> neck_slot;      ///< per label its slot, -1 none (so between frames)
    std::vector<int> neck_segments;  ///< per slot its label
    std::vector<std::array<int, 2>> neck_touching;  ///< in slots
    std::vector<std::array<float, 3>> neck_heights;
    std::vector<NeckPair> neck_stand;  ///< in slots
    std::vector<std::uint8_t> neck_wanted;
    std::vector<NeckWallSums> neck_wall_sums;
    std::vector<NeckWall> neck_walls, neck_walls_by_slot;  ///< the lower segments' walls, then by slot
    std::vector<std::optional<BodyAxis>> neck_axes;  ///< per slot: a round body's axis on the plane
    std::vector<int> neck_first;
    // Containers:
    std::vector<detail::BoundaryStep> steps;   ///< boundary pairs of two segments
    std::vector<int> rim_rows;         ///< first and last row of each segment
    std::vector<std::array<double, 6>> rim_fits;  ///< front, back, circle centre (2), radius,
                                                  ///< rim height per candidate
    std::vector<std::array<double, 3>> rim_back;  ///< back's pixels, inside, top per candidate
    std::vector<int> rim_next;         ///< candidates of one back segment, linked
    std::vector<int> rim_far_px;       ///< the back's far rim, of the pair being fitted
    std::vector<std::uint8_t> rim_joined;  ///< per segment, 1 = joined across its rim (kept
                                           ///< whole by the pieces phase); empty: none
    // Floor gaps:
    std::vector<std::uint8_t> gap_seen;  ///< 1 = explored this frame (0 between frames)
    std::vector<int> gap_touched;        ///< pixels marked by searches that filled nothing
    // Scope: per segment its lowest and highest point over the support, points above the
    // height limit, outline pairs, and those that continue into removed points above it.
    std::vector<float> scope_lo, scope_hi;
    std::vector<int> scope_any_px;                     ///< one pixel of each segment
    std::vector<double> scope_sx, scope_sy, scope_sz;  ///< sums of each segment's points
    std::vector<int> scope_high, scope_outline, scope_outside;
    std::vector<int> scope_frame, scope_upright;  ///< outline pairs into the frame's edges;
                                                  ///< pixels facing sideways
    std::vector<std::uint8_t> scope_keep;
    std::vector<int> scope_held;  ///< per segment, the kept segments it holds (low supports)
    std::vector<std::uint8_t> scope_wide;  ///< per segment, 1 = spans past the height limit
    std::vector<int> scope_span_pixels;    ///< per segment, its pixels (measure_spans)
    std::vector<float> scope_span_range;   ///< per segment, its least and greatest positions
                                           ///< along four directions on the support
    std::vector<float> scope_along;  ///< one wide segment's positions, direction by direction
    /// What the scope counts of one segment in one strip of rows (scope_lo, hi, ...).
    struct ScopeCounts {
        float lo, hi;
        int any_px, high, outline, outside, frame, size;
    };
    std::vector<ScopeCounts> scope_strips;               ///< per strip, per segment
    // Stacks:
    std::vector<int> layer_hist;             ///< per segment, upward pixels per height bin
    std::vector<float> stack_cut;            ///< per segment, the height it is cut at (< 0: not)
    /// A pixel of an upper object's wall: its segment and where it stands on the support plane.
    struct WallPoint {
        int segment;
        float u, v;
    };
    /// Where one segment's upper object's walls stand: cells of wall_cells[at, at + cols *
    /// rows), row by row from (u0, v0) on the plane; cols 0: no map.
    struct WallMap {
        float u0 = 0, v0 = 0;
        int cols = 0, rows = 0;
        std::size_t at = 0;
    };
    std::vector<WallPoint> stack_walls;      ///< the cut segments' upper walls
    std::vector<WallMap> wall_maps;          ///< per segment
    std::vector<std::array<float, 4>> wall_box;  ///< scratch: per segment its walls' u0, v0, u1, v1
    std::vector<std::uint8_t> wall_cells;    ///< 1 = an upper object's wall stands in that cell
    std::vector<std::array<double, 4>> wall_colour;  ///< per segment and piece: chromaticity
                                                     ///< sums (3) and count
    /// Per cut segment, the colour's verdict on its walls and, where colour cannot tell, its
    /// upper object's footprint on the support plane and where its lower layer's top shows
    /// round it (stacks.cpp, keep_walls).
    struct Footprint {
        bool up_by_colour = false;             ///< the walls under its walls go up by colour
        bool wanted = false;                   ///< measured: colour cannot tell (one material)
        double su = 0, sv = 0, n = 0;          ///< the upper object's points summed (u, v), counted
        double c4 = 0, s4 = 0, walls = 0;      ///< its walls' normals' directions, four times the
                                               ///< angle, summed; its walls counted
        double axis[2][2] = {};                ///< its two axes (unit u, v)
        double lo[2] = {0, 0}, hi[2] = {0, 0};  ///< its extent along them from its mean point
        int side[4] = {0, 0, 0, 0};            ///< the lower top's upward pixels beyond each side
    };
    std::vector<Footprint> footprints;
    std::vector<int> footprint_px;  ///< scratch: the pixels of the segments whose footprint is wanted
};

}  // namespace wul3d

namespace wul3d::detail {

using SegmentBuffers = SegmentWorkspace::Buffers;

constexpr float kDegToRad = 3.14159265358979f / 180.0f;

/// The largest depth step between neighbours on one surface at depth z, metres: the
/// sensor's noise, which grows with z^2. On plain values, so that loops that call it keep
/// vectorizing.
inline float sensor_depth_step(float jump_m, float jump_rel, float z) { return jump_m + jump_rel * z * z; }

/// Whether any of row[from, to) holds a label: an OR over the row, a loop that vectorizes,
/// so that the per-pixel passes skip the rows without objects (most rows above and below
/// them).
inline bool row_has_label(const int* row, int from, int to) {
    int any = 0;
    for (int u = from; u < to; ++u) any |= row[u];
    return any != 0;
}

/// Marks out[u] = 1 where row[u] is labelled and its right neighbour or the one below
/// (`below`, the next row; the row itself on the last) is another label, else 0: a segment
/// outline's pixels, in a branch-free pass that vectorizes (the occlusion and neck rules
/// then visit those few).
inline void mark_outline_row(const int* row, const int* below, int W, std::uint8_t* out) {
    for (int u = 0; u + 1 < W; ++u)
        out[u] = static_cast<std::uint8_t>((row[u] != 0) & ((row[u + 1] != row[u]) | (below[u] != row[u])));
    out[W - 1] = static_cast<std::uint8_t>((row[W - 1] != 0) & (below[W - 1] != row[W - 1]));
}

/// The 4-neighbours of pixel p = v W + u in a W x H image (left, right, up, down); -1 where
/// one lies past the frame.
inline std::array<int, 4> four_neighbours(int p, int u, int v, int W, int H) {
    return {u > 0 ? p - 1 : -1, u + 1 < W ? p + 1 : -1, v > 0 ? p - W : -1, v + 1 < H ? p + W : -1};
}

/// Added to a pixel's r + g + b before a ratio of colours: keeps the chromaticity of dark,
/// noisy pixels near grey, and their brightness ratios small.
constexpr float kDark = 30.0f;

/// The chromaticity of the colour (r, g, b), rgb / (r + g + b), at the scale of 8-bit colour
/// (a grey of any brightness: 85, 85, 85; kDark pulls dark colours towards grey): what the
/// colour cue calls a material's colour, as light falling at other angles scales a colour
/// and leaves its chromaticity.
template <class T>
void chromaticity(T r, T g, T b, T (&out)[3]) {
    const T dark = static_cast<T>(kDark), k = static_cast<T>(255) / (r + g + b + dark);
    out[0] = k * (r + dark / 3), out[1] = k * (g + dark / 3), out[2] = k * (b + dark / 3);
}

/// Pixel p's chromaticity.
inline void chromaticity(const OrganizedCloud& c, std::size_t p, float (&out)[3]) {
    chromaticity<float>(c.r[p], c.g[p], c.b[p], out);
}

/// A pixel faces sideways (an upright surface: a wall, a box's or a can's side) when its
/// normal lies within this of the support plane, and up when within this of its normal.
/// Shared by the round test, the scope and the stack rule.
constexpr float kUprightDeg = 25.0f;

/// Walls face along a box's two axes when the mean of their normals' unit vectors on the
/// support plane, at four times their angle, is this long or more: a box's walls, 90 degrees
/// apart, add up; a round body's face every way and cancel. Boxes measure 0.56-0.99 (0.56
/// seen steeply from above, `ocid_sample`), cans 0.07-0.13 seen whole (the shipped RealSense
/// frames' soup can on a tin); on the generated piles and floors, where the normals' radius
/// spans much of a narrow body, the bodies of bottles 0.29 and of boxes 0.64-0.72 at the
/// median (docs/ABLATION.md, "Necks"). Set between them by hand, not tuned. Shared by the
/// stack rule (a footprint with sides) and the neck rule (a body that is not a box).
constexpr double kBoxAxes = 0.4;

/// The walls of a solid of revolution are fitted with circles about one axis, one per layer
/// of height over the support (fit_coaxial), so that a bottle's neck and its body, narrower
/// and wider, share their centre: kRoundLayerM of height each. 0.5, 1 and 2 cm scored alike
/// on the generated tune seeds (docs/ABLATION.md, "Colour cue"). The layers reach 48 cm,
/// about the scope's height limit (scope.max_height_m); walls higher share the top one.
/// Shared by the round test and the neck rule.
constexpr double kRoundLayerM = 0.01;
constexpr int kRoundLayers = 48;

/// The layer of kRoundLayerM that height h over the support falls in.
inline int round_layer(double h) {
    return std::clamp(static_cast<int>(std::floor(h / kRoundLayerM)), 0, kRoundLayers - 1);
}

/// What every phase reads: the parameters, the frame and the normals of the crease tests
/// (smoothed when cuts.normal_smooth_px > 0), the plane's classes per pixel, and the top of
/// a board or tray lying on the support (nullptr: none).
struct Ctx {
    const SegmentParams& prm;
    const OrganizedCloud& c;
    const NormalMap& n;
    const std::vector<std::uint8_t>& cls;
    int W, H;
    const Plane* low_support = nullptr;
    float depth_noise_rel = 0.0f;  ///< the depth's measured noise over depth, sigma_z / z

    /// sensor_depth_step with this frame's parameters.
    float depth_step(float z) const { return sensor_depth_step(prm.depth_jump_m, prm.depth_jump_rel, z); }
    bool connected(std::size_t p, std::size_t q, float steps = 1.0f) const {
        const float z = c.z[p];
        return std::fabs(z - c.z[q]) <= steps * depth_step(z);
    }
    /// Paper-free LCCP test between two surface points: concave when the normals face
    /// each other across the step, (n_p - n_q) . (X_q - X_p) > 0.
    float concavity(std::size_t p, std::size_t q) const {
        const float dx = c.x[q] - c.x[p], dy = c.y[q] - c.y[p], dz = c.z[q] - c.z[p];
        const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(len > 1e-6f)) return 0.0f;
        return ((n.nx[p] - n.nx[q]) * dx + (n.ny[p] - n.ny[q]) * dy + (n.nz[p] - n.nz[q]) * dz) / len;
    }
};

/// Whether pixel p has a normal within the angle whose sine is `sin_max` of the support
/// plane: it faces sideways.
inline bool faces_sideways(const Ctx& x, const Plane& pl, std::size_t p, float sin_max) {
    return x.n.valid[p] && std::fabs(x.n.nx[p] * pl.nx + x.n.ny[p] * pl.ny + x.n.nz[p] * pl.nz) <= sin_max;
}

/// Whether pixel p has a normal within the angle whose cosine is `cos_min` of the support's
/// normal (both towards the camera): it faces up.
inline bool faces_up(const Ctx& x, const Plane& pl, std::size_t p, float cos_min) {
    return x.n.valid[p] && x.n.nx[p] * pl.nx + x.n.ny[p] * pl.ny + x.n.nz[p] * pl.nz >= cos_min;
}

/// The points `for_pixels` visits (it calls its argument with each pixel) on the support
/// plane, less `mean` (for the circle fit's conditioning): what fit_circle takes.
template <class ForPixels>
auto on_plane(const Ctx& x, const PlaneAxes& plane_xy, const Eigen::Vector2d& mean, ForPixels& for_pixels) {
    return [&x, &plane_xy, &mean, &for_pixels](auto&& visit) {
        for_pixels([&](std::size_t p) { visit(Eigen::Vector2d(plane_xy(x.c, p) - mean)); });
    };
}

/// One region by breadth-first search from `seed` (the caller has marked it): every
/// 4-neighbour q of a region pixel with is_open(q) and continuous depth is marked (mark(q))
/// and joins. The region's pixels land in queue[0, size); returns the size. Shared by the
/// components that seed segments. Cost: O(region).
template <class IsOpen, class Mark>
int flood_region(const Ctx& x, std::vector<int>& queue, int seed, IsOpen&& is_open, Mark&& mark) {
    const int W = x.W, H = x.H;
    int head = 0, tail = 0;
    queue[static_cast<std::size_t>(tail++)] = seed;
    while (head < tail) {
        const int p = queue[static_cast<std::size_t>(head++)];
        for (int q : four_neighbours(p, p % W, p / W, W, H)) {
            if (q < 0 || !is_open(static_cast<std::size_t>(q))) continue;
            if (!x.connected(static_cast<std::size_t>(p), static_cast<std::size_t>(q))) continue;
            mark(static_cast<std::size_t>(q));
            queue[static_cast<std::size_t>(tail++)] = q;
        }
    }
    return tail;
}

// ---- union-find over segments (the merge and container rules join segments) -------------

inline int find_root(std::vector<int>& parent, int a) {
    while (parent[static_cast<std::size_t>(a)] != a) {
        parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
        a = parent[static_cast<std::size_t>(a)];
    }
    return a;
}

/// Union-find over segments 0..n, each its own set.
inline void reset_sets(std::vector<int>& parent, int n) {
    parent.resize(static_cast<std::size_t>(n) + 1);
    for (int l = 0; l <= n; ++l) parent[static_cast<std::size_t>(l)] = l;
}

/// Joins the sets of segments a and b (the smaller root stays root); false when already one.
inline bool join_sets(std::vector<int>& parent, int a, int b) {
    const int ra = find_root(parent, a), rb = find_root(parent, b);
    if (ra == rb) return false;
    parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    return true;
}

/// Every labelled pixel takes its set's root (components.cpp): the sets flattened, then one
/// parallel pass over the pixels.
void relabel_to_roots(SegmentBuffers& ws);

/// How many strips of rows a pass over `rows` rows is cut into to run in parallel: one per
/// thread, of 8 rows at least (fewer cost more in joining than they save); 1 inside another
/// parallel region, or on one thread. What the passes compute does not depend on it.
int row_strips(int rows);
/// row_strips, but inside a team one strip per team thread (for_each_part hands them out as
/// tasks there): for the passes after the colour cue, when the clustering's thread beside
/// them is done with its own half and can take a share.
int team_strips(int rows);

/// Calls visit(l, p, run) for each run of equal labels label[p, p + run) in [p0, p1), in
/// order. A pass pixel by pixel that counted into memory made each pixel wait for the one
/// before, which mostly has the same label. Cost: one pass.
template <typename Visit>
void for_label_runs(const int* label, std::size_t p0, std::size_t p1, Visit&& visit) {
    std::size_t p = p0;
    while (p < p1) {
        const int l = label[p];
        std::size_t q = p + 1;
        while (q < p1 && label[q] == l) ++q;
        visit(l, p, q - p);
        p = q;
    }
}

/// Counting sort of the segments' pixels by segment (background left out): segment l's
/// pixels are ws.order[ws.offsets[l], ws.offsets[l + 1]), in raster order. Per fixed band of
/// rows in parallel: counts per band, then each band writes from its own start (segment by
/// segment, bands in order). In: ws.label (0..n). Cost: two parallel passes over the pixels,
/// O(8 n) between them (colour_cue.cpp).
void sort_pixels_by_segment(const Ctx& x, SegmentBuffers& ws, int n);

// ---- the phases before the rules ---------------------------------------------------------

/// The normals of the crease tests (cuts.cpp): `normals` smoothed over cuts.normal_smooth_px into
/// ws.smooth, or `normals` themselves when cuts.normal_smooth_px is 0.
const NormalMap& crease_normals(const SegmentParams& params, const NormalMap& normals,
                                const std::vector<std::uint8_t>& classes, int W, int H, SegmentBuffers& ws);

/// The seeds into ws.cut (cuts.cpp): object pixels off concave creases, or with the kmeans
/// segmenter off the boundaries of the paper's clusters (`clusters`, InputError when not the
/// frame's). `has_normal`: the raw normals' validity. Sizes ws.cut, label, queue and dist to
/// the frame. Cost: a few parallel passes over the pixels.
void find_seeds(const Ctx& x, const std::uint8_t* has_normal, const LabelImage& clusters, SegmentBuffers& ws);

/// The segments (components.cpp): connected components of the seeds into ws.label, 1..n,
/// fragments under cuts.min_seed_points unlabelled again. Returns n.
int seed_components(const Ctx& x, SegmentBuffers& ws);

/// Connected components of the pixels with seedable[p] = 1 (else 0) into ws.label, 1..n, and
/// their sizes into ws.sizes[1..n]; returns n. A component is what a breadth-first search
/// from its first pixel in raster order reaches, a neighbour joining where depth is
/// continuous seen from the pixel already in it (Ctx::connected; the test is not symmetric),
/// the seeds taken in raster order: components are numbered by their first pixel. With
/// `strips` > 1 the rows are cut into that many strips, each labelled on a thread of its
/// own with a union-find, joined along the seams, then numbered: the labels are those of
/// strips = 1 (the search itself) at any count. Cost: O(pixels), strips in parallel.
int label_components(const Ctx& x, const std::uint8_t* seedable, SegmentBuffers& ws, int strips);

/// Cut pixels, feet, pixels without a normal and dropped fragments join the segment they
/// touch (up to cuts.reattach_px, where depth is continuous), then containers' insides, however
/// wide (components.cpp). Returns the pixels added.
std::size_t reattach_foreground(const Ctx& x, SegmentBuffers& ws);

/// Orphans (components.cpp): object pixels that no seed reached, after the re-attachment,
/// whose region (4-neighbours, depth-continuous) holds cuts.min_seed_points or more and
/// touches no segment where depth is continuous, become segments n + 1, n + 2, ... in raster
/// order of their first pixel. A small object seen far off by a noisy camera is cut through
/// by creases a wide crease step apart: no seed is left in it, and the segments beside it,
/// apart in depth, cannot reach it. A region that a segment reaches is that segment's cut
/// band, left over past cuts.reattach_px. Returns the new n. Cost: one pass over the labels,
/// a search over the orphan pixels; ws.queue holds them.
int seed_orphans(const Ctx& x, SegmentBuffers& ws, int n);

/// The segments of min_points or more into `out`, renumbered 1..n (components.cpp). Returns n.
int compact(SegmentBuffers& ws, int n, int min_points, std::uint16_t* out);

// ---- the rules, in the driver's order ----------------------------------------------------

/// A rule on segments: reads and writes ws.label (segments 1..n with gaps), numbers the
/// segments it adds n + 1, ... and adds them to n, and counts what it did into `stats`.
/// `support`: the support plane, nullptr when none was found (the rules that need one are
/// run only with one, or do nothing without).
using Rule = void (*)(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// The convexity merge (merge.cpp): joins segments that meet along a boundary that is mostly
/// not concave. stats.merges.
void merge_segments(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Containers (containers.cpp; SegmentParams, "Containers"): joins a container's inside,
/// seen over its rim, to the container. Nothing without a support. stats.containers.
void join_containers(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// The colour cue (colour_cue.cpp; hybrid): splits segments in two by colour.
/// stats.color_splits, texture_splits (those
/// between a texture and another material, ColourCueParams::textures).
void split_by_colour(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Stacks (stacks.cpp; SegmentParams, "Stacks"; `support` not null): cuts a segment whose
/// upward faces lie at two heights in two. stats.stack_splits.
void split_stacks(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Pieces (pieces.cpp): each 4-connected piece of a segment but its largest becomes a
/// segment of its own (under min_points, dropped at the end). stats.pieces.
void split_pieces(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Floor gaps (floor_gaps.cpp; ContainerParams::gap_max_px): small unlabelled patches beside a
/// container's inside, enclosed by one segment, join it. stats.gaps_filled.
void fill_floor_gaps(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Occlusion (occlusion.cpp; SegmentParams, "Occlusion"): joins the two parts of a surface
/// that a nearer object divides in view. stats.occluded.
void join_occluded(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Necks (necks.cpp; docs/DESIGN.md, "Necks"; `support` not null): a narrow segment standing
/// on the axis of a round one joins it (a bottle's neck and cap on its body). stats.necks.
void join_necks(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

/// Scope::Support (scope.cpp; docs/DESIGN.md, "Scope"; `support` not null): clears the
/// labels of the segments the support does not hold. stats.support_scope, out_of_scope.
void restrict_to_support(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats);

}  // namespace wul3d::detail
