// The colour cue (the hybrid segmenter): two objects of two colours standing flush, front
// and top faces coplanar, meet along no crease and no depth step, and only their colours
// tell them apart. Each segment is split in two by 2-means under the paper's distance (eq.
// 4, 6) with a colour-heavy alpha, and the split is kept only when the parts differ in
// colour, are large and meet as two objects do (one side of the smaller part, or round a
// compact piece), across a smooth surface or with a turn of colour, on a segment that does
// not stand round (a can's label is print). Where 2-means follows a texture, the split is
// judged between the segment's materials instead.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include <omp.h>

#include "../branch_free.hpp"
#include "../circle_fit.hpp"
#include "../team_tasks.hpp"
#include "internal.hpp"
#include "wul3d/clustering.hpp"  // ClusterParams: the colour cue's alpha and delta

namespace wul3d::detail {

// Declared in internal.hpp: the scope sorts the pixels again for their spans.
void sort_pixels_by_segment(const Ctx& x, SegmentBuffers& ws, int n) {
    const int W = x.W;
    constexpr int kSortBands = 8;
    const std::size_t L = static_cast<std::size_t>(n) + 1;
    ws.remap.assign(kSortBands * L, 0);  // per band: counts, then write positions
    const int H = x.H;
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kSortBands; ++band) {
        int* const count = ws.remap.data() + static_cast<std::size_t>(band) * L;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kSortBands) * W;
        for_label_runs(ws.label.data(), static_cast<std::size_t>(H * band / kSortBands) * W, p1,
                       [&](int l, std::size_t, std::size_t run) { count[l] += static_cast<int>(run); });
    }
    ws.offsets.assign(L + 1, 0);  // segment l's pixels: order[offsets[l], offsets[l + 1])
    int position = 0;
    for (std::size_t l = 1; l < L; ++l) {
        ws.offsets[l] = position;
        for (int band = 0; band < kSortBands; ++band) {
            int& slot = ws.remap[static_cast<std::size_t>(band) * L + l];
            const int count = slot;
            slot = position;
            position += count;
        }
    }
    ws.offsets[L] = position;
    ws.order.resize(static_cast<std::size_t>(position));
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kSortBands; ++band) {
        int* const next = ws.remap.data() + static_cast<std::size_t>(band) * L;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kSortBands) * W;
        for_label_runs(ws.label.data(), static_cast<std::size_t>(H * band / kSortBands) * W, p1,
                       [&](int l, std::size_t p, std::size_t run) {
                           if (l == 0) return;
                           int* const out = ws.order.data() + next[l];
                           for (std::size_t i = 0; i < run; ++i) out[i] = static_cast<int>(p + i);
                           next[l] += static_cast<int>(run);
                       });
    }
}

namespace {

int segment_size(const SegmentBuffers& ws, int l) {
    return ws.offsets[static_cast<std::size_t>(l) + 1] - ws.offsets[static_cast<std::size_t>(l)];
}

/// One plane, for the brightness step (judge_split): the normals a crease step either side
/// of the boundary within this angle. The smallest that gains on the generated tune seeds
/// (3 degrees left out their boxes' faces), well under the smooth test's 15, which took in
/// a white bowl's lit and shaded sides on the RealSense frames (docs/ABLATION.md).
constexpr float kStepPlaneDeg = 5.0f;

/// The 2-means features of the segments' pixels, one plane each in segment order so that
/// every pass over a segment reads contiguous memory.
struct ColourFeatures {
    const float* f[6];  ///< delta x, y, z, then alpha times the chromaticity r, g, b
    int first;          ///< the position in ws.order of every plane's element 0
};

/// Gathers ColourFeatures into ws.feature, scaled by the paper's delta and alpha (eq. 4) so
/// that a squared distance is a sum. Only the segments' pixels (order positions first..last)
/// are gathered: plane q holds position i at f[q][i - first], sized by the object pixels, not
/// the image. In: ws.order, ws.offsets. Cost: one parallel pass over the object pixels.
ColourFeatures gather_features(const Ctx& x, const ClusterParams& cp, SegmentBuffers& ws, int n) {
    const int first = ws.offsets[1], last = ws.offsets[static_cast<std::size_t>(n) + 1];
    const std::size_t M = static_cast<std::size_t>(last - first);
    ws.feature.resize(6 * M);
    float* f[6];
    for (int q = 0; q < 6; ++q) f[q] = ws.feature.data() + static_cast<std::size_t>(q) * M;
    // The colour term is the chromaticity (chromaticity()): light falling on two faces of
    // one box at other angles scales their colour and leaves it, so the two parts are two
    // materials, not a lit face and a shaded one.
#pragma omp parallel for schedule(static)
    for (int i = first; i < last; ++i) {
        const std::size_t p = static_cast<std::size_t>(ws.order[static_cast<std::size_t>(i)]);
        f[0][i - first] = cp.delta * x.c.x[p];
        f[1][i - first] = cp.delta * x.c.y[p];
        f[2][i - first] = cp.delta * x.c.z[p];
        float c[3];
        chromaticity(x.c, p, c);
        f[3][i - first] = cp.alpha * c[0];
        f[4][i - first] = cp.alpha * c[1];
        f[5][i - first] = cp.alpha * c[2];
    }
    return {{f[0], f[1], f[2], f[3], f[4], f[5]}, first};
}

/// The segments of this round (ws.to_try) large enough to split (2 x min_points), largest
/// first, into ws.by_size: tried in parallel, no thread is left with a big one at the end.
/// Cost: O(n log n).
void order_by_size(const SegmentParams& prm, SegmentBuffers& ws, int n) {
    ws.by_size.clear();
    for (int l = 1; l <= n; ++l)
        if (ws.to_try[static_cast<std::size_t>(l)] && segment_size(ws, l) >= 2 * prm.min_points)
            ws.by_size.push_back(l);
    std::stable_sort(ws.by_size.begin(), ws.by_size.end(),
                     [&](int a, int b) { return segment_size(ws, a) > segment_size(ws, b); });
}

/// The position among the m pixels of one segment's planes `f` farthest in colour from
/// (r, g, b); the first on ties.
int farthest_colour(const float* const* f, int m, double r, double g, double b) {
    const float *const cr = f[3], *const cg = f[4], *const cb = f[5];
    int best = 0;
    double bd = -1;
    for (int i = 0; i < m; ++i) {
        const double dr = cr[i] - r, dg = cg[i] - g, db = cb[i] - b;
        const double d = dr * dr + dg * dg + db * db;
        if (d > bd) { bd = d; best = i; }
    }
    return best;
}

/// The principal axis of a 3 x 3 covariance (unit length) and its variance, by power
/// iteration from the axis of the largest diagonal entry. Cost: O(1).
double principal_axis(const double (&cov)[3][3], double (&e)[3]) {
    e[0] = e[1] = e[2] = 0;
    e[cov[0][0] >= cov[1][1] && cov[0][0] >= cov[2][2] ? 0 : cov[1][1] >= cov[2][2] ? 1 : 2] = 1;
    double variance = 0;
    for (int it = 0; it < 20; ++it) {
        double next[3];
        for (int a = 0; a < 3; ++a) next[a] = cov[a][0] * e[0] + cov[a][1] * e[1] + cov[a][2] * e[2];
        const double len = std::sqrt(next[0] * next[0] + next[1] * next[1] + next[2] * next[2]);
        if (!(len > 0)) break;
        for (int a = 0; a < 3; ++a) e[a] = next[a] / len;
        variance = len;
    }
    return variance;
}

/// 2-means seeds for one segment (planes `f`, m pixels) in `cen`: the mean colour plus and
/// minus one standard deviation along the colours' principal axis, both at the mean
/// position. Seeds at the farthest colours (the pixel farthest from the mean, then the one
/// farthest from it) let a few outlying pixels, the feet a segment took from the table or
/// a line of mixed colour at an edge, pull 2-means into a part of their own, which the
/// share test then rejects; they move the principal axis little (better on the generated
/// tune seeds, docs/ABLATION.md). False, and no seeds, when the colour spread
/// cannot hold parts `min_spread` apart (feature units). `total`: the planes' sums (in
/// double, pixel order), which two_means needs too. Cost: three passes over the segment's
/// planes.
bool seed_centres(const float* const* f, int m, float min_spread, float (&cen)[2][6], double (&total)[6]) {
    // The six sums side by side, each in pixel order: one sum alone waits for each addition.
    double sum[6] = {};
    for (int i = 0; i < m; ++i)
        for (int q = 0; q < 6; ++q) sum[q] += f[q][i];
    double mean[6];
    for (int q = 0; q < 6; ++q) total[q] = sum[q], mean[q] = total[q] / m;
    const float *const cr = f[3], *const cg = f[4], *const cb = f[5];
    // The parts' mean colours lie among the segment's colours, so they are at most the
    // segment's colour diameter apart, at most twice the farthest colour from the mean:
    // below the minimum distance no split can be kept.
    {
        const int a0 = farthest_colour(f, m, mean[3], mean[4], mean[5]);
        const double dr = cr[a0] - mean[3], dg = cg[a0] - mean[4], db = cb[a0] - mean[5];
        if (2 * std::sqrt(dr * dr + dg * dg + db * db) < min_spread) return false;
    }
    double cov[3][3] = {};
    for (int i = 0; i < m; ++i) {
        const double d[3] = {cr[i] - mean[3], cg[i] - mean[4], cb[i] - mean[5]};
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) cov[a][b] += d[a] * d[b];
    }
    double e[3];
    const double sd = std::sqrt(principal_axis(cov, e) / m);
    for (int q = 0; q < 6; ++q) {
        const double step = q < 3 ? 0.0 : sd * e[q - 3];
        cen[0][q] = static_cast<float>(mean[q] + step);
        cen[1][q] = static_cast<float>(mean[q] - step);
    }
    return true;
}

/// 2-means (eq. 4 squared) on one segment's feature planes, m pixels, from the centres `cen`:
/// side[i] gets pixel i's part, `cen` the parts' means and `count` their sizes (the last
/// iteration's; a part may be empty). `total`: the planes' sums (seed_centres'); part 0's
/// sums are the totals minus part 1's. Cost: at most 6 passes over the 6 planes, stopping
/// when no pixel changes part; float sums per block of 1024, added up in double; no
/// allocation. Built for AVX2 and baseline x86-64 (the sides' loop vectorizes either way).
WUL3D_AVX2_CLONES void two_means(const float* const* planes, int m, const double (&total)[6], std::uint8_t* side,
                                 float (&cen)[2][6], int (&count)[2]) {
    const float* f[6];  // a local copy: the stores to `side` cannot alias it
    for (int q = 0; q < 6; ++q) f[q] = planes[q];
    for (int it = 0; it < 6; ++it) {
        // Nearer centre 1 than centre 0 (eq. 4 squared): |f - c1|^2 < |f - c0|^2, i.e.
        // 2 f . (c0 - c1) < |c0|^2 - |c1|^2, a linear test per pixel.
        float w[6], bias = 0;
        for (int q = 0; q < 6; ++q) {
            w[q] = 2.0f * (cen[0][q] - cen[1][q]);
            bias += cen[0][q] * cen[0][q] - cen[1][q] * cen[1][q];
        }
        double sum1[6] = {};
        int ones = 0, changed = 0;
        constexpr int kBlock = 1024;  // float partial sums per block, added up in double
        for (int i0 = 0; i0 < m; i0 += kBlock) {
            const int i1 = std::min(m, i0 + kBlock);
            float block[6] = {};
            int block_ones = 0, block_changed = 0;
            // The sides first, in a loop that vectorizes (one pixel per lane, each dot in
            // the same order); then the sums, pixel after pixel as before (a float sum
            // reordered would round otherwise).
            for (int i = i0; i < i1; ++i) {
                float dot = 0;
                for (int q = 0; q < 6; ++q) dot += w[q] * f[q][i];
                const std::uint8_t j = dot < bias;
                block_changed += j != side[i];
                side[i] = j;
                block_ones += j;
            }
            // Part 1's pixels only: a pixel of part 0 would add 0 * f = +-0, which changes
            // no sum (the features are finite).
            for (int i = i0; i < i1; ++i)
                if (side[i])
                    for (int q = 0; q < 6; ++q) block[q] += f[q][i];
            for (int q = 0; q < 6; ++q) sum1[q] += block[q];
            ones += block_ones;
            changed += block_changed;
        }
        count[1] = ones;
        count[0] = m - ones;
        if (count[0] == 0 || count[1] == 0) break;
        for (int q = 0; q < 6; ++q) {
            cen[1][q] = static_cast<float>(sum1[q] / count[1]);
            cen[0][q] = static_cast<float>((total[q] - sum1[q]) / count[0]);
        }
        if (it > 0 && changed == 0) break;  // converged: further iterations repeat this one
    }
}

/// Where the parts of a split segment meet.
struct SplitBoundary {
    int boundary = 0;       ///< 4-neighbour pairs inside the segment with different parts
    int with_normals = 0;   ///< ... with normals a crease step away on either side
    int smooth = 0;         ///< ... whose normals lie within colour.max_crease_deg
    int on_plane = 0;       ///< ... of those, on one plane (kStepPlaneDeg)
    int steps[2] = {0, 0};  ///< ... of those, where part 0's side (steps[0]) or part 1's
                            ///< is colour.min_step times brighter a crease step away
    int small_outline = 0;  ///< 4-neighbour pairs from the smaller part to anything else
    int convex = 0;         ///< pairs with normals across a convex fold (a box's edge); only when asked
};

/// Calls visit(q, du, dv) for each 4-neighbour q of pixel p to its right (du = 1) or below
/// (dv = 1) that lies in segment l in another part (ws.part): each boundary pair inside the
/// segment once. Cost: two lookups.
template <class Visit>
void for_part_boundary_pairs(const Ctx& x, const SegmentBuffers& ws, int l, int p, Visit&& visit) {
    const int W = x.W, u = p % W, v = p / W;
    const std::uint8_t* const part = ws.part.data();
    if (u + 1 < W && ws.label[static_cast<std::size_t>(p) + 1] == l && part[p + 1] != part[p]) visit(p + 1, 1, 0);
    if (v + 1 < x.H && ws.label[static_cast<std::size_t>(p + W)] == l && part[p + W] != part[p]) visit(p + W, 0, 1);
}

/// The boundary between the parts of segment l (pixels px[0, m), parts in ws.part), its
/// brightness steps on one plane, its convex folds (with `folds`, else none counted), and
/// the smaller part's outline. Cost: one pass over the segment's pixels and their
/// neighbours.
SplitBoundary split_boundary(const Ctx& x, const SegmentBuffers& ws, int l, const int* px, int m,
                             std::uint8_t small_part, float cos_crease, bool folds) {
    const int W = x.W, s = x.prm.cuts.crease_step_px;
    const std::uint8_t* const part = ws.part.data();
    // One plane: within kStepPlaneDeg, and smooth whatever colour.max_crease_deg says.
    const float cos_plane = std::max(std::cos(kStepPlaneDeg * kDegToRad), cos_crease);
    auto brightness = [&](int p) { return static_cast<float>(x.c.r[p] + x.c.g[p] + x.c.b[p]) + kDark; };
    SplitBoundary sb;
    for (int i = 0; i < m; ++i) {
        const int p = px[i];
        const int u = p % W, v = p / W;
        if (part[p] == small_part) {
            for (const int q : four_neighbours(p, u, v, W, x.H))
                sb.small_outline += q < 0 || ws.label[q] != l || part[q] != small_part;
        }
        for_part_boundary_pairs(x, ws, l, p, [&](int q, int du, int dv) {
            ++sb.boundary;
            const int pu = u - s * du, pv = v - s * dv;
            const int qu = u + du + s * du, qv = v + dv + s * dv;
            if (pu < 0 || pv < 0 || qu >= W || qv >= x.H) return;
            const int a = pv * W + pu, b = qv * W + qu;
            if (!x.n.valid[a] || !x.n.valid[b]) return;
            const float cos_ab = x.n.nx[a] * x.n.nx[b] + x.n.ny[a] * x.n.ny[b] + x.n.nz[a] * x.n.nz[b];
            sb.smooth += cos_ab >= cos_crease;
            ++sb.with_normals;
            // A fold whose normals turn away from each other (the crease test's concavity,
            // negated) on one surface: two faces of one solid.
            const auto pa = static_cast<std::size_t>(a), pb = static_cast<std::size_t>(b);
            if (folds && cos_ab < cos_crease && x.connected(pa, pb, static_cast<float>(2 * s + 1)))
                sb.convex += x.concavity(pa, pb) < -x.prm.cuts.concavity;
            // A step in brightness counts on one plane only (a lies on p's side, b on q's):
            // light falls alike there, while a curved surface turns from it (a bowl's lit
            // and shaded sides).
            if (cos_ab < cos_plane) return;
            ++sb.on_plane;
            const float ia = brightness(a), ib = brightness(b);
            sb.steps[part[p]] += ia >= x.prm.colour.min_step * ib;
            sb.steps[part[q]] += ib >= x.prm.colour.min_step * ia;
        });
    }
    return sb;
}

/// The depth's noise scatters a wall's points along their rays; stands_round's residual
/// allows this many times the scatter the frame's measured noise (Ctx::depth_noise_rel)
/// gives each wall point across its circle. The measure leaves out the noisiest tenth of
/// its samples, and an active-stereo camera's error grows with z^2 from the frame's typical
/// depth. First 60 family tune seeds, the nine sets summed: 1 / 1.25 / 1.5 / 1.75 / 2 / 3
/// times 808.1 / 808.6 / 809.0 / 809.1 / 808.8 / 807.5, 807.8 without (docs/ABLATION.md,
/// "Colour cue"); the least on the plateau kept.
constexpr double kRoundNoiseScale = 1.5;

/// Whether the pixels px[0, m) of one segment stand round on the support pl: a quarter of
/// them or more are walls (normals within colour.round_deg of the plane), the walls lie on
/// upright circles about one axis, one per layer of height (fit_coaxial on the plane: RMS
/// within containers.max_residual_m, or, added in quadrature, kRoundNoiseScale times the
/// scatter across the circle that the measured depth noise gives the walls' points; spanning
/// containers.min_arc of the mean diameter, radii up to colour.round_max_radius_m) and three
/// quarters of them face within colour.round_deg of their radii. A can, a bottle or a cup
/// is one solid of revolution; two objects flush in view show flat faces. Cost: two passes
/// and fit_coaxial's eight over the m pixels.
bool stands_round(const Ctx& x, const PlaneAxes& plane_xy, const Plane& pl, const int* px, int m) {
    const SegmentParams& prm = x.prm;
    const float sin_wall = std::sin(prm.colour.round_deg * kDegToRad);
    auto for_walls = [&](auto&& visit) {
        for (int i = 0; i < m; ++i) {
            const auto p = static_cast<std::size_t>(px[i]);
            if (faces_sideways(x, pl, p, sin_wall)) visit(p);
        }
    };
    double walls = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for_walls([&](std::size_t p) {
        ++walls;
        mean += plane_xy(x.c, p);
    });
    if (walls < 3 || 4 * walls < m) return false;
    mean /= walls;
    auto layer_of = [&](std::size_t p) { return round_layer(pl.height(x.c.x[p], x.c.y[p], x.c.z[p])); };
    const auto fit = fit_coaxial<kRoundLayers>([&](auto&& visit) {
        for_walls([&](std::size_t p) { visit(Eigen::Vector2d(plane_xy(x.c, p) - mean), layer_of(p)); });
    });
    if (!fit.fitted) return false;
    double R = 0, widest = 0;  // the walls' mean radius, and the widest layer's
    for (int l = 0; l < kRoundLayers; ++l) {
        R += fit.radius[l] * fit.count[l];
        if (fit.count[l] > 0) widest = std::max(widest, fit.radius[l]);
    }
    R /= walls;
    if (!(R > 0) || widest > prm.colour.round_max_radius_m) return false;
    const double cos_radial = std::cos(prm.colour.round_deg * kDegToRad);
    // Residual, the noise's share of it, the walls' extent (the diagonal of their box on the
    // plane) and how many face along a radius (either way: a cup's inside faces in).
    double res = 0, noise = 0, radial = 0;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for_walls([&](std::size_t p) {
        const Eigen::Vector2d at = plane_xy(x.c, p), d = at - mean - fit.centre;
        const double r = d.norm(), off = r - fit.radius[layer_of(p)];
        res += off * off;
        // A depth error of sigma_z = depth_noise_rel z moves the point along its ray by
        // depth_noise_rel times its position, so across the circle by depth_noise_rel times
        // the position's component along the radius (on the plane: the camera at its origin).
        if (r > 0) {
            const double across = x.depth_noise_rel * at.dot(d) / r;
            noise += across * across;
        }
        const Eigen::Vector3d nrm(x.n.nx[p], x.n.ny[p], x.n.nz[p]);
        const Eigen::Vector2d n2(nrm.dot(plane_xy.e1), nrm.dot(plane_xy.e2));  // the normal on the plane
        radial += std::fabs(n2.dot(d)) >= cos_radial * n2.norm() * r;
        lo = lo.cwiseMin(d);
        hi = hi.cwiseMax(d);
    });
    const double on_circle = prm.containers.max_residual_m;
    return res <= on_circle * on_circle * walls + kRoundNoiseScale * kRoundNoiseScale * noise &&
           (hi - lo).norm() >= prm.containers.min_arc * 2 * R && 4 * radial >= 3 * walls;
}

/// Boundary pairs on one plane that a brightness step needs: as many as the convexity
/// merge tests.
constexpr int kMinStepPairs = 6;

// A split between the materials of kMoreTextureColours is weaker evidence than one of four
// colours (eight clusters find more in one object's print): more_colours_like_objects keeps
// it only where its parts meet as two objects of a pile do, by the three constants below.

/// At most this share of the split's boundary pairs with normals cross a convex fold: one
/// box printed otherwise on two faces (`osd_mosd` learn24) does, where the objects of a pile
/// meet across a concave fold or a smooth surface (generated tune seeds: 0.4-0.6 alike, 0.3
/// lower, 0.7 costs `osd_mosd` 0.1 Overlap F).
constexpr float kMaxConvexShare = 0.5f;
/// The smaller part holds at least this share of the segment (colour.min_share, three times
/// over) ...
constexpr float kMoreColoursMinShare = 0.15f;
/// ... and at least this times its outline squared in pixels: a square has 1/16, a 1:6
/// rectangle 1/33, a band of the table's colour round an object whose depth the sensor took
/// in far less (the shipped RealSense frames: 0.0034). These two were chosen on those
/// frames, whose table bands came apart as objects without them; the generated tune seeds
/// score the same with or without them, and lower at 0.2 and 0.006.
constexpr float kMinRoundness = 0.005f;

/// Whether the parts of a split between the materials of kMoreTextureColours meet as two
/// objects of a pile do (the three constants above): `small` pixels of the segment's `m` in
/// the smaller part. Cost: O(1).
bool more_colours_like_objects(const SplitBoundary& sb, int small, int m) {
    const auto outline = static_cast<float>(sb.small_outline);
    return static_cast<float>(sb.convex) <= kMaxConvexShare * static_cast<float>(sb.with_normals) &&
           static_cast<float>(small) >= kMoreColoursMinShare * static_cast<float>(m) &&
           static_cast<float>(small) >= kMinRoundness * outline * outline;
}

/// What the colour cue's tests say of a split.
enum class Verdict {
    kKept,
    kTexture,  ///< the boundary runs round many pieces: the parts follow a texture
    kRejected,
};

/// The colour cue's tests (SegmentParams, "Colour cue") of a split of segment l: pixels
/// px[0, m), parts in ws.part, part sizes `count` and means `cen` (feature units).
/// `more_colours`: a split between the materials of kMoreTextureColours, which must also
/// pass more_colours_like_objects. Cost: one pass over the segment's pixels for the
/// boundary; the round test's three more, on a support, when every other test passed.
Verdict judge_split(const Ctx& x, const Plane* support, const PlaneAxes* plane_xy, const ClusterParams& cp,
                    float cos_crease, const SegmentBuffers& ws, int l, const int* px, int m, const int (&count)[2],
                    const float (&cen)[2][6], bool more_colours = false) {
    const SegmentParams& prm = x.prm;
    const int small = std::min(count[0], count[1]);
    if (small < prm.min_points || static_cast<float>(small) < prm.colour.min_share * static_cast<float>(m))
        return Verdict::kRejected;
    const float dr = (cen[0][3] - cen[1][3]) / cp.alpha, dg = (cen[0][4] - cen[1][4]) / cp.alpha,
                db = (cen[0][5] - cen[1][5]) / cp.alpha;
    const bool far_in_colour = std::sqrt(dr * dr + dg * dg + db * db) >= prm.colour.min_distance;
    if (!far_in_colour && !(prm.colour.min_step > 1)) return Verdict::kRejected;
    // Boundary: 4-neighbour pairs inside the segment with different parts; the normals a
    // crease step away on either side tell a smooth surface from a fold.
    const std::uint8_t small_part = count[0] < count[1] ? 0 : 1;
    const SplitBoundary sb = split_boundary(x, ws, l, px, m, small_part, cos_crease, more_colours);
    // A contact between two objects is one side of the smaller one's outline, or, where the
    // larger one encloses it in view (a box lying on a box, seen from above), the whole
    // outline of a compact piece: 4 sqrt(pixels) for a square, 6 for a 6:1 rectangle. A
    // split along a texture (stripes, checks, print) runs round most of each of its many
    // pieces, far longer than either.
    const bool one_side = static_cast<float>(sb.boundary) <= prm.colour.max_boundary * static_cast<float>(sb.small_outline);
    const bool compact = static_cast<double>(sb.boundary) <= prm.colour.max_compact * std::sqrt(static_cast<double>(small));
    if (!one_side && !compact) return Verdict::kTexture;
    // Most of the boundary must cross a smooth surface (a few pairs near a box's corner
    // straddle its edge), or the parts must differ in chromaticity: light falling on two
    // faces of one box at other angles scales their colour, it does not turn it, so
    // across a fold (a flat box on another, flush boxes of two heights) only a change of
    // material turns the mean colour by colour.min_hue_deg. Or, either way, a step in
    // brightness along the boundary where it crosses one plane: light falls alike on both
    // sides there, so only a change of material (two flush boxes of one hue, a light and a
    // dark one, which the chromaticity cannot tell apart) makes one side brighter, along
    // most of the crossing, in one direction. Most: half the smooth crossing or more lies on
    // one plane (a curved surface's does not: a white bowl's shaded floor, 6 of 52), and 70 %
    // of that steps (DESIGN.md, "The brightness step").
    const bool brightness_step = prm.colour.min_step > 1 && sb.on_plane >= kMinStepPairs &&
                                 2 * sb.on_plane >= sb.smooth &&
                                 10 * std::max(sb.steps[0], sb.steps[1]) >= 7 * sb.on_plane;
    if (!far_in_colour && !brightness_step) return Verdict::kRejected;
    const bool across_smooth = sb.with_normals > 0 && 10 * sb.smooth >= 7 * sb.with_normals;
    if (more_colours && !more_colours_like_objects(sb, small, m)) return Verdict::kRejected;
    if (!across_smooth && !brightness_step) {
        const float r0 = cen[0][3], g0 = cen[0][4], b0c = cen[0][5];
        const float r1 = cen[1][3], g1 = cen[1][4], b1c = cen[1][5];
        const float dot = r0 * r1 + g0 * g1 + b0c * b1c;
        const float norms = std::sqrt((r0 * r0 + g0 * g0 + b0c * b0c) * (r1 * r1 + g1 * g1 + b1c * b1c));
        if (!(norms > 0) || dot >= std::cos(prm.colour.min_hue_deg * kDegToRad) * norms) return Verdict::kRejected;
    }
    // Last, as it is the rarest to fail: a round thing's colours are print.
    if (support && prm.colour.round_deg > 0 && stands_round(x, *plane_xy, *support, px, m)) return Verdict::kRejected;
    return Verdict::kKept;
}

// ---- the colour cue's materials ------------------------------------------------------------
//
// 2-means follows a texture when one object of the segment is textured: stripes of two
// colours beside a plain box put the stripes in two parts and the box with one of them.
// More colours then: the texture's two, the plain one's, and one for the rest. Two colours
// whose contact is far longer than any two objects' (they interleave) are one material; the
// split is between the materials. Where the four make one material, or leave one too small
// to be tried again, the segment holds more textures than four colours can tell apart (two
// textured objects flush side by side need four for their checks alone), and eight are
// tried.

/// Colours per segment when 2-means followed a texture: a textured object's two, a plain
/// one's beside it, and one more for what fits none (mixed pixels along edges, a third
/// colour). Chosen on the generated tune seeds, where 4 scored above 3 and 5, learnt from
/// every pixel (docs/ABLATION.md, "Colour cue").
constexpr int kTextureColours = 4;

/// Colours per segment where kTextureColours make no split of two materials large enough:
/// textured objects touching in a pile show more colours than four, and each of the four
/// then spans several objects, so every pair interleaves, or the fourth, the one for what
/// fits none, is left a material of its own too small to be tried. Generated tune seeds: 6 and 8 alike, 6 costing `osd_mosd` 0.1 Overlap F; tried
/// only there, since 5 or 6 colours everywhere split real prints (docs/ABLATION.md, "Colour
/// cue").
constexpr int kMoreTextureColours = 8;

/// k-means learns the colours from at most this many pixels per colour of kTextureColours
/// (every stride-th pixel), then gives every pixel its nearest once: FAISS's Clustering
/// subsamples its training set the same way (max_points_per_centroid, 256 by default). The
/// eight colours learn from the same 1,024 pixels: 2,048 scored the same on the generated
/// tune seeds at twice the cost, 512 cost `osd_mosd` 0.2 Overlap F.
constexpr int kSamplesPerColour = 256;

/// Vectors of eight lanes (GCC's and Clang's vector extension), each lane the scalar
/// operation: one AVX2 operation, or two of SSE2.
using Float8 = float __attribute__((vector_size(32)));
using Int8 = std::int32_t __attribute__((vector_size(32)));

/// Each pixel's nearest centre (eq. 4 squared) for pixels [0, n) of the planes `f`, into
/// out[0, n): |f - c_k|^2 less |f|^2, i.e. |c_k|^2 - 2 f . c_k, from `w` = 2 c_k and `bias`
/// = |c_k|^2; the first of equals. A block of pixels at a time, the centres in the outer loop
/// (as FAISS orders its distances): the distances, then the nearest, in loops over
/// contiguous floats that vectorize at any K (a loop over the centres inside one over the
/// pixels did not at eight). Inlined into texture_colours, so built for AVX2 with it. Cost:
/// K + 1 passes over each block; 5 KB of stack at K = 8.
template <int K>
[[gnu::always_inline]] inline void nearest_colours(const float* const* f, int n, const float (&w)[K][6],
                                                   const float (&bias)[K], std::uint8_t* out) {
    const float *const f0 = f[0], *const f1 = f[1], *const f2 = f[2], *const f3 = f[3], *const f4 = f[4],
                      *const f5 = f[5];
    constexpr int kBlock = 128;
    float dist[K][kBlock];
    for (int i0 = 0; i0 < n; i0 += kBlock) {
        const int b = std::min(kBlock, n - i0);
        for (int k = 0; k < K; ++k) {
            const float w0 = w[k][0], w1 = w[k][1], w2 = w[k][2], w3 = w[k][3], w4 = w[k][4], w5 = w[k][5];
            const float c = bias[k];
            float* const dk = dist[k];
            for (int i = 0; i < b; ++i) {
                const int j = i0 + i;
                float d = c;
                d -= w0 * f0[j];
                d -= w1 * f1[j];
                d -= w2 * f2[j];
                d -= w3 * f3[j];
                d -= w4 * f4[j];
                d -= w5 * f5[j];
                dk[i] = d;
            }
        }
        // Eight pixels at a time, the nearest so far in registers: kept in memory between
        // the centres, it went through masked stores, which no load can take from.
        int i = 0;
        for (; i + 8 <= b; i += 8) {
            Float8 best, d;
            std::memcpy(&best, dist[0] + i, sizeof best);
            Int8 nearest = {};
            for (int k = 1; k < K; ++k) {
                std::memcpy(&d, dist[k] + i, sizeof d);
                const Int8 nearer = d < best;  // -1 or 0 per lane
                best = nearer ? d : best;
                nearest = nearer ? k : nearest;
            }
            for (int l = 0; l < 8; ++l) out[i0 + i + l] = static_cast<std::uint8_t>(nearest[l]);
        }
        for (; i < b; ++i) {
            float best = dist[0][i];
            int nearest = 0;
            for (int k = 1; k < K; ++k)
                if (dist[k][i] < best) best = dist[k][i], nearest = k;
            out[i0 + i] = static_cast<std::uint8_t>(nearest);
        }
    }
}

/// The index of the first largest of v[0, n) (std::max_element's), for n >= 1 and no NaN:
/// the largest by a loop that vectorizes (max is exact in any order), then its first index.
/// Inlined into texture_colours. Cost: at most two passes over v.
[[gnu::always_inline]] inline int first_largest(const float* v, int n) {
    // One running largest per lane, in a vector: as a float reduction the loop would not
    // vectorize. It starts at v[0] in every lane (a scalar less a vector is taken lane by lane).
    Float8 lane = v[0] - Float8{};
    int j = 0;
    for (; j + 8 <= n; j += 8) {
        Float8 x;
        std::memcpy(&x, v + j, sizeof x);
        lane = x > lane ? x : lane;
    }
    float largest = v[0];
    for (int l = 0; l < 8; ++l) largest = lane[l] > largest ? lane[l] : largest;
    for (; j < n; ++j) largest = v[j] > largest ? v[j] : largest;
    j = 0;
    while (v[j] != largest) ++j;
    return j;
}

/// k-means (eq. 4 squared, on the 2-means features `f` of the m pixels) with K centres
/// (kTextureColours, or kMoreTextureColours), seeded at the two 2-means parts' means `two`
/// and then, one by one, at the colour farthest from the centres so far; learnt from every
/// stride-th pixel (at most kSamplesPerColour x kTextureColours, copied together).
/// cluster[i] gets pixel i's colour, `cen` and `count` the colours' means (of the samples)
/// and sizes (of all pixels). Cost: at most 8 passes over the samples (the nearest colours
/// vectorized), then one over the m pixels; about 35 KB of stack, no allocation. Inlined into
/// the two texture_colours below (target_clones takes no template).
template <int K>
[[gnu::always_inline]] inline void texture_colours_of(const float* const* f, int m, const float (&two)[2][6],
                                                      std::uint8_t* cluster, float (&cen)[K][6], int (&count)[K]) {
    constexpr int kMaxSamples = kSamplesPerColour * kTextureColours;
    const int stride = (m + kMaxSamples - 1) / kMaxSamples;
    float samples[6][kMaxSamples];
    std::uint8_t nearest[kMaxSamples], before[kMaxSamples];
    int n = 0;
    for (int i = 0; i < m; i += stride, ++n)
        for (int q = 0; q < 6; ++q) samples[q][n] = f[q][i];
    const float* const s[6] = {samples[0], samples[1], samples[2], samples[3], samples[4], samples[5]};
    auto colour_distance = [&](int j, const float* c) {
        float d = 0;
        for (int q = 3; q < 6; ++q) d += (s[q][j] - c[q]) * (s[q][j] - c[q]);
        return d;
    };
    for (int q = 0; q < 6; ++q) cen[0][q] = two[0][q], cen[1][q] = two[1][q];
    float nearest_d[kMaxSamples];  // each sample's colour distance to the nearest centre so far
    for (int j = 0; j < n; ++j) nearest_d[j] = std::min(colour_distance(j, cen[0]), colour_distance(j, cen[1]));
    for (int k = 2; k < K; ++k) {
        const int farthest = first_largest(nearest_d, n);
        for (int q = 0; q < 6; ++q) cen[k][q] = s[q][farthest];
        for (int j = 0; j < n; ++j) nearest_d[j] = std::min(nearest_d[j], colour_distance(j, cen[k]));
    }
    float w[K][6], bias[K];
    auto set_weights = [&] {
        for (int k = 0; k < K; ++k) {
            bias[k] = 0;
            for (int q = 0; q < 6; ++q) w[k][q] = 2 * cen[k][q], bias[k] += cen[k][q] * cen[k][q];
        }
    };
    for (int it = 0; it < 8; ++it) {
        set_weights();
        if (it > 0) std::copy(nearest, nearest + n, before);
        nearest_colours(s, n, w, bias, nearest);
        int changed = n;  // every sample on the first pass
        if (it > 0) {
            changed = 0;
            for (int j = 0; j < n; ++j) changed += nearest[j] != before[j];
        }
        float sum[K][6] = {};
        int n_k[K] = {};
        for (int j = 0; j < n; ++j) {
            const int k = nearest[j];
            ++n_k[k];
            for (int q = 0; q < 6; ++q) sum[k][q] += s[q][j];
        }
        for (int k = 0; k < K; ++k)
            if (n_k[k] > 0)
                for (int q = 0; q < 6; ++q) cen[k][q] = sum[k][q] / static_cast<float>(n_k[k]);
        if (changed == 0) break;
    }
    set_weights();
    nearest_colours(f, m, w, bias, cluster);
    // Four counts per colour, for pixels i mod 4: one count waited for the pixel before
    // whenever both had the same colour.
    int counts[4][K] = {};
    int i = 0;
    for (; i + 4 <= m; i += 4)
        for (int l = 0; l < 4; ++l) ++counts[l][cluster[i + l]];
    for (; i < m; ++i) ++counts[0][cluster[i]];
    for (int k = 0; k < K; ++k) count[k] = counts[0][k] + counts[1][k] + counts[2][k] + counts[3][k];
}

/// texture_colours_of at kTextureColours and at kMoreTextureColours, each built for AVX2 and
/// baseline x86-64.
WUL3D_AVX2_CLONES void texture_colours(const float* const* f, int m, const float (&two)[2][6], std::uint8_t* cluster,
                                       float (&cen)[kTextureColours][6], int (&count)[kTextureColours]) {
    texture_colours_of(f, m, two, cluster, cen, count);
}
WUL3D_AVX2_CLONES void texture_colours(const float* const* f, int m, const float (&two)[2][6], std::uint8_t* cluster,
                                       float (&cen)[kMoreTextureColours][6], int (&count)[kMoreTextureColours]) {
    texture_colours_of(f, m, two, cluster, cen, count);
}

/// The materials of segment l's colours (ws.part at its pixels px[0, m), sizes `count`):
/// per pair of colours their contact, the 4-neighbour pairs between them, over the square
/// root of the smaller's size. Above colour.max_compact (longer than the outline of any
/// compact piece) they interleave: one material; else they lie apart. Returns the number of
/// materials; where two or more, `material` (0 or 1 per colour): two are the split; of more
/// (a pile of objects in one segment) the one that touches the others least for its size,
/// the likeliest to be an object of its own, is part 0 and the rest part 1, which the next
/// round may split again. Cost: one pass over the segment's pixels.
template <int K>
int texture_materials(const Ctx& x, const SegmentBuffers& ws, int l, const int* px, int m, const int (&count)[K],
                      std::uint8_t (&material)[K]) {
    const SegmentParams& prm = x.prm;
    const std::uint8_t* const part = ws.part.data();
    int contact[K][K] = {};  // symmetric
    for (int i = 0; i < m; ++i)
        for_part_boundary_pairs(x, ws, l, px[i], [&](int q, int, int) {
            ++contact[part[px[i]]][part[q]];
            ++contact[part[q]][part[px[i]]];
        });
    int root[K];  // union-find over the colours
    for (int k = 0; k < K; ++k) root[k] = k;
    auto find = [&](int k) {
        while (root[k] != k) k = root[k];
        return k;
    };
    int materials = K;
    auto join = [&](int a, int b) {
        if (const int ra = find(a), rb = find(b); ra != rb) root[rb] = ra, --materials;
    };
    // A colour too small for an object (mixed pixels along an edge, a sticker) is part of
    // the material it touches most; so is one that no pixel took (a segment of fewer clean
    // colours than K).
    auto tiny = [&](int k) { return count[k] < prm.min_points; };
    for (int k = 0; k < K; ++k) {
        if (!tiny(k)) continue;
        int most = k == 0 ? 1 : 0;
        for (int j = 0; j < K; ++j)
            if (j != k && contact[k][j] > contact[k][most]) most = j;
        join(most, k);
    }
    for (int a = 0; a < K; ++a)
        for (int b = a + 1; b < K; ++b) {
            if (tiny(a) || tiny(b)) continue;
            const double unit = std::sqrt(static_cast<double>(std::min(count[a], count[b])));
            if (contact[a][b] > prm.colour.max_compact * unit) join(a, b);
        }
    if (materials < 2) return materials;
    int apart = find(0);
    if (materials > 2) {
        int size[K] = {};      // per material (at its root): pixels
        double touch[K] = {};  // ... and contact with the other materials
        for (int k = 0; k < K; ++k) size[find(k)] += count[k];
        for (int a = 0; a < K; ++a)
            for (int b = 0; b < K; ++b)
                if (find(a) != find(b)) touch[find(a)] += contact[a][b];
        double least = std::numeric_limits<double>::infinity();
        for (int k = 0; k < K; ++k) {
            if (find(k) != k || size[k] == 0) continue;
            const double per_size = touch[k] / std::sqrt(static_cast<double>(size[k]));
            if (per_size < least) least = per_size, apart = k;
        }
    }
    for (int k = 0; k < K; ++k) material[k] = find(k) == apart ? 0 : 1;
    return materials;
}

/// Segment l's split into two materials of K colours, when 2-means (parts in `side`, means
/// in `cen`) followed a texture: texture_colours, texture_materials, then ws.part, side,
/// `count` and `cen` say the materials (cen: their means) where it returns true: two
/// materials, each large enough. False where the colours make one material or one of two
/// or more is too small to be tried again; ws.part and side are then not a split, and `cen`
/// is as it came. Cost: texture_colours' passes and two more over the segment's pixels.
template <int K>
bool split_by_materials(const Ctx& x, SegmentBuffers& ws, int l, const int* px, const float* const* f, int m,
                        std::uint8_t* side, float (&cen)[2][6], int (&count)[2]) {
    float colour[K][6];
    int colour_count[K];
    texture_colours(f, m, cen, side, colour, colour_count);
    std::uint8_t* const part = ws.part.data();
    for (int i = 0; i < m; ++i) part[px[i]] = side[i];
    std::uint8_t material[K];
    if (texture_materials(x, ws, l, px, m, colour_count, material) < 2) return false;
    double sum[2][6] = {};
    count[0] = count[1] = 0;
    for (int i = 0; i < m; ++i) {
        const std::uint8_t j = material[side[i]];
        side[i] = j;
        part[px[i]] = j;
        ++count[j];
        for (int q = 0; q < 6; ++q) sum[j][q] += f[q][i];
    }
    // Each material large enough to be tried again (as order_by_size asks of a segment):
    // grouping colours is weaker evidence than 2-means' own parts, and a print's block of
    // min_points split off a box seen in two pieces on osd_mosd's learn18 (docs/ABLATION.md,
    // "Textures").
    if (std::min(count[0], count[1]) < 2 * x.prm.min_points) return false;
    for (int j = 0; j < 2; ++j)
        for (int q = 0; q < 6; ++q) cen[j][q] = static_cast<float>(sum[j][q] / count[j]);
    return true;
}

/// How a segment was split by the colour cue (ws.split).
enum Split : std::uint8_t { kNotSplit = 0, kSplitByColour = 1, kSplitByMaterial = 2 };

/// Tries to split segment l in two: 2-means, then the tests of the colour cue (SegmentParams,
/// "Colour cue"); where 2-means followed a texture, the segment's materials of
/// kTextureColours (split_by_materials) and the same tests, or, where those colours make one
/// material or leave one too small, of kMoreTextureColours and the same tests with
/// more_colours_like_objects.
/// Writes ws.part at the segment's pixels once 2-means ran. Cost: O(segment pixels) per
/// 2-means iteration and for the boundary, the materials' passes when 2-means followed a
/// texture (twice where four colours make no split); no allocation (called in parallel,
/// one segment per call).
Split try_colour_split(const Ctx& x, const Plane* support, const PlaneAxes* plane_xy, const ColourFeatures& ft,
                       const ClusterParams& cp, float cos_crease, SegmentBuffers& ws, int l) {
    const SegmentParams& prm = x.prm;
    const int o = ws.offsets[static_cast<std::size_t>(l)];
    const int* px = ws.order.data() + o;
    const int m = segment_size(ws, l);
    const float* f[6];  // the segment's features
    for (int q = 0; q < 6; ++q) f[q] = ft.f[q] + (o - ft.first);
    float cen[2][6];
    double total[6];
    if (!seed_centres(f, m, prm.colour.min_distance * cp.alpha, cen, total)) return kNotSplit;
    std::uint8_t* const side = ws.part_in_order.data() + o;
    int count[2] = {0, 0};
    two_means(f, m, total, side, cen, count);
    std::uint8_t* part = ws.part.data();
    for (int i = 0; i < m; ++i) part[px[i]] = side[i];
    const Verdict verdict = judge_split(x, support, plane_xy, cp, cos_crease, ws, l, px, m, count, cen);
    if (verdict == Verdict::kKept) return kSplitByColour;
    // kTexture: both parts passed the share test, so both hold pixels.
    if (verdict != Verdict::kTexture || !prm.colour.textures) return kNotSplit;
    bool found = split_by_materials<kTextureColours>(x, ws, l, px, f, m, side, cen, count);
    // Two materials of 2 x min_points each (split_by_materials) need 4 x min_points.
    const bool more_colours = !found && m >= 4 * prm.min_points;
    if (more_colours) found = split_by_materials<kMoreTextureColours>(x, ws, l, px, f, m, side, cen, count);
    if (!found) return kNotSplit;
    return judge_split(x, support, plane_xy, cp, cos_crease, ws, l, px, m, count, cen, more_colours) == Verdict::kKept
               ? kSplitByMaterial
               : kNotSplit;
}

/// Part 1 of each split segment takes a new label, n + 1, n + 2, ... in segment order (not
/// thread order). Returns the splits, and adds those by
/// material to `by_material`. Cost: one pass over the split segments' pixels.
int number_splits(SegmentBuffers& ws, int n, int& by_material) {
    int splits = 0, next = n;
    for (int l = 1; l <= n; ++l) {
        if (ws.split[static_cast<std::size_t>(l)] == kNotSplit) continue;
        by_material += ws.split[static_cast<std::size_t>(l)] == kSplitByMaterial;
        const int id = ++next;
        const int o = ws.offsets[static_cast<std::size_t>(l)];
        const int m = ws.offsets[static_cast<std::size_t>(l) + 1] - o;
        for (int i = 0; i < m; ++i) {
            const std::size_t p = static_cast<std::size_t>(ws.order[static_cast<std::size_t>(o + i)]);
            if (ws.part[p] == 1) ws.label[p] = id;
        }
        ++splits;
    }
    return splits;
}

/// The next round's pixels by segment, from this round's: ws.order and ws.offsets over
/// labels 1..n + found hold only the parts of the segments this round split (part 0 keeps
/// label l, part 1 is the label number_splits gave it), each in raster order as
/// sort_pixels_by_segment would put them; every other segment is empty. In: ws.split,
/// ws.part_in_order. Cost: one pass over the split segments' pixels, O(n) more.
void sort_split_parts(SegmentBuffers& ws, int n, int found) {
    const std::size_t L = static_cast<std::size_t>(n + found) + 1;
    std::vector<int>& size = ws.remap;
    size.assign(L, 0);
    for (int l = 1, id = n; l <= n; ++l) {
        if (ws.split[static_cast<std::size_t>(l)] == kNotSplit) continue;
        const int o = ws.offsets[static_cast<std::size_t>(l)], m = segment_size(ws, l);
        const std::uint8_t* const part = ws.part_in_order.data() + o;
        const int in_part1 = static_cast<int>(std::count(part, part + m, std::uint8_t{1}));
        size[static_cast<std::size_t>(l)] = m - in_part1;
        size[static_cast<std::size_t>(++id)] = in_part1;
    }
    std::vector<int>& next = ws.next_offsets;
    next.assign(L + 1, 0);
    for (std::size_t l = 1; l < L; ++l) next[l + 1] = next[l] + size[l];
    std::vector<int>& order = ws.next_order;
    order.resize(static_cast<std::size_t>(next[L]));
    for (int l = 1, id = n; l <= n; ++l) {
        if (ws.split[static_cast<std::size_t>(l)] == kNotSplit) continue;
        const int o = ws.offsets[static_cast<std::size_t>(l)], m = segment_size(ws, l);
        int at[2] = {next[static_cast<std::size_t>(l)], next[static_cast<std::size_t>(++id)]};
        for (int i = 0; i < m; ++i)
            order[static_cast<std::size_t>(at[ws.part_in_order[static_cast<std::size_t>(o + i)]]++)] =
                ws.order[static_cast<std::size_t>(o + i)];
    }
    ws.offsets.swap(next);
    ws.order.swap(order);
}

/// One round of the colour cue over the segments marked in ws.to_try (1..n), whose pixels
/// ws.order and ws.offsets hold by segment: tries to split each in two, then numbers part 1
/// of each split segment n + 1, n + 2, ... in segment order. Returns the splits, and adds
/// those by material to `by_material`. Cost: a gather of the sorted pixels (a parallel pass),
/// then O(segment pixels) per 2-means iteration per segment tried, segments in parallel.
int split_round(const Ctx& x, const Plane* support, SegmentBuffers& ws, int n, int& by_material) {
    const SegmentParams& prm = x.prm;
    // part is written for a segment's pixels before anything reads them: no clearing.
    ws.part.resize(static_cast<std::size_t>(x.W) * x.H);
    ws.part_in_order.resize(static_cast<std::size_t>(ws.offsets[static_cast<std::size_t>(n) + 1]));
    ws.split.assign(static_cast<std::size_t>(n) + 1, kNotSplit);
    ClusterParams cp;
    cp.alpha = prm.colour.alpha;
    cp.delta = 1.0f - prm.colour.alpha;
    const ColourFeatures features = gather_features(x, cp, ws, n);
    const float cos_crease = std::cos(prm.colour.max_crease_deg * kDegToRad);
    std::optional<PlaneAxes> plane_xy;
    if (support) plane_xy.emplace(*support);
    // Each segment is tried on its own; split ids are given out in segment order afterwards
    // so that the labels do not depend on the threads.
    order_by_size(prm, ws, n);
    const auto n_tried = static_cast<std::ptrdiff_t>(ws.by_size.size());
    auto try_segment = [&](std::ptrdiff_t t) {
        const int l = ws.by_size[static_cast<std::size_t>(t)];
        const PlaneAxes* axes = plane_xy ? &*plane_xy : nullptr;
        ws.split[static_cast<std::size_t>(l)] = try_colour_split(x, support, axes, features, cp, cos_crease, ws, l);
    };
    // Inside a team the other half's thread takes a share once its own work is done.
    for_each_part(n_tried, Spread::kDynamic, try_segment);
    return number_splits(ws, n, by_material);
}

/// Rounds of the colour cue: each tries again the parts of the segments the round before
/// split. Three flush boxes of three colours need two; a pile whose textured objects are one
/// segment loses one material a round (split_by_materials), and the third round gains on
/// the generated tune seeds (pile under active stereo most), a fourth splits nothing more
/// (docs/ABLATION.md, "Colour cue").
constexpr int kColourRounds = 3;

/// The colour cue: tries to split each segment in two by 2-means under the paper's distance
/// (eq. 4, 6) with a colour-heavy alpha; keeps a split only when the parts differ in colour,
/// are large, and meet along one side of the smaller part or round a compact piece, across
/// a smooth surface or with a turn of colour, and the segment does not stand round on the
/// support (stands_round: a can's label is print). Where 2-means followed a texture, the
/// same tests judge a split between the segment's materials (split_by_materials). Each
/// further round (kColourRounds) tries the two parts of each segment the round before split.
/// In: ws.label (1..n with gaps). Out: ws.label with the new parts numbered n + 1, n + 2, ...
/// (round by round, each in segment order); `by_material` counts the splits between
/// materials. Cost: split_round once, and once more after each round that split anything.
int color_splits(const Ctx& x, const Plane* support, SegmentBuffers& ws, int n, int& by_material) {
    by_material = 0;
    ws.to_try.assign(static_cast<std::size_t>(n) + 1, 1);
    sort_pixels_by_segment(x, ws, n);
    int splits = 0;
    for (int round = 0; round < kColourRounds; ++round) {
        const int found = split_round(x, support, ws, n, by_material);
        if (found == 0) break;
        // The next round: the segments split in this one (part 0 kept their label) and their
        // new parts, the only pixels it sorts.
        ws.to_try.assign(static_cast<std::size_t>(n + found) + 1, 0);
        for (int l = 1; l <= n; ++l) ws.to_try[static_cast<std::size_t>(l)] = ws.split[static_cast<std::size_t>(l)] != kNotSplit;
        for (int l = n + 1; l <= n + found; ++l) ws.to_try[static_cast<std::size_t>(l)] = 1;
        if (round + 1 < kColourRounds) sort_split_parts(ws, n, found);
        n += found;
        splits += found;
    }
    return splits;
}

}  // namespace

void split_by_colour(const Ctx& x, const Plane* support, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    stats.colour.splits = color_splits(x, support, ws, n, stats.colour.texture_splits);
    n += stats.colour.splits;
}

}  // namespace wul3d::detail
