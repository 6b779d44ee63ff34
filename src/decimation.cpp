#include "wul3d/decimation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "branch_free.hpp"
#include "param_check.hpp"
#include "wul3d/error.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/visualization.hpp"

namespace wul3d {

namespace {

// The colour vote's weights, exp(-d2 / (2 kColourSigma^2)) at d2 = 16 i + 8 (d2 the squared
// colour distance): a look-up instead of an exp per vote. Past the table's end the weights
// are below 1e-35; its last one stands for them.
constexpr int kWeightShift = 4, kWeights = 4096;

const std::array<float, kWeights>& vote_weights() {
    static const std::array<float, kWeights> table = [] {
        std::array<float, kWeights> t{};
        const float sigma = DecimatedSource::kColourSigma, scale = -1.0f / (2.0f * sigma * sigma);
        for (int i = 0; i < kWeights; ++i)
            t[static_cast<std::size_t>(i)] =
                std::exp(scale * static_cast<float>((i << kWeightShift) + (1 << (kWeightShift - 1))));
        return t;
    }();
    return table;
}

/// A row of n input columns from its blocks: the `channels` values of block b over its
/// columns b * factor ... b * factor + factor - 1 (the last block may be cut by n). The
/// default factor 2 has its own loop, which the compiler vectorizes; others go one column
/// of each block at a time (no division per column).
template <int channels, class T>
void widen_row(const T* blocks, int factor, int n, T* out) {
    if (factor == 2) {
        for (int b = 0; b < n / 2; ++b)
            for (int c = 0; c < channels; ++c)
                out[channels * 2 * b + c] = out[channels * (2 * b + 1) + c] = blocks[channels * b + c];
        if (n % 2)
            for (int c = 0; c < channels; ++c) out[channels * (n - 1) + c] = blocks[channels * (n / 2) + c];
        return;
    }
    for (int k = 0; k < factor; ++k)
        for (int b = 0, u = k; u < n; ++b, u += factor)
            for (int c = 0; c < channels; ++c) out[channels * u + c] = blocks[channels * b + c];
}

/// The limits of takes_own_block's test.
struct OwnBlockTest {
    float same, same_rel, scale, zmin, zmax;
};

/// takes_own[u] = 1 where pixel u's depth `full[u]` (units) and its block's `block[u]` are
/// both there, on one surface (same_surface) and in range (DepthRange::contains), with the
/// same float operations: the same answers. `&`, not `&&`: a branch per pixel would keep
/// the loop from vectorizing. Built for AVX2 and baseline x86-64 (no FMA either way).
/// Cost: one pass over the W pixels.
WUL3D_AVX2_CLONES
void takes_own_block(const std::uint16_t* __restrict full, const float* __restrict block, int W, OwnBlockTest t,
                     std::uint8_t* __restrict takes_own) {
    for (int u = 0; u < W; ++u) {
        const float z = full[u], b = block[u], metres = z * t.scale;
        takes_own[u] = (z != 0) & (b != 0) & (std::fabs(b - z) <= t.same + t.same_rel * z * z) &
                       (metres >= t.zmin) & (metres <= t.zmax);
    }
}

}  // namespace

void decimate_frame(const RgbdView& in, int factor, RgbdFrame& out, const DepthRange* range) {
    detail::require_param(factor >= 1 && factor <= 8, "", "decimate", factor, "in [1, 8]");
    const int W = in.width, H = in.height;
    const bool color = in.has_color();
    if (color && !in.color_matches())
        throw InputError(std::string(in.name) + ": colour and depth sizes differ");
    const int w = (W + factor - 1) / factor, h = (H + factor - 1) / factor;
    out.name = in.name;
    out.intrinsics = in.intrinsics;
    out.intrinsics.width = w;
    out.intrinsics.height = h;
    // Pixel (u, v) of `out` samples (N u, N v) of `in`: u_in = fx X / Z + cx = N u.
    out.intrinsics.fx /= factor;
    out.intrinsics.fy /= factor;
    out.intrinsics.cx /= factor;
    out.intrinsics.cy /= factor;
    out.depth.width = w;
    out.depth.height = h;
    out.depth.scale_m_per_unit = in.depth_scale_m_per_unit;
    out.depth.data.resize(static_cast<std::size_t>(w) * h);
    out.color.width = color ? w : 0;
    out.color.height = color ? h : 0;
    out.color.rgb.resize(color ? static_cast<std::size_t>(w) * h * 3 : 0);
    const std::uint16_t* const depth = in.depth;
    const std::uint8_t* const rgb = in.rgb;

    const float scale = in.depth_scale_m_per_unit;  // z = depth * scale, as back-projected
    // Raw output pointers, taken once: through the vectors, each byte stored would make the
    // compiler load them again.
    std::uint16_t* const out_depth = out.depth.data.data();
    std::uint8_t* const out_rgb = out.color.rgb.data();
    // The range's limits as locals, for the same reason; none: every depth is in range.
    const DepthRange all{-std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
    const DepthRange limits = range ? *range : all;

#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
            // The block's first pixel in range, row-major; else its first with depth; else
            // its top-left one. Mostly the top-left one is in range: the search is skipped.
            const std::size_t top_left = static_cast<std::size_t>(v) * factor * W + static_cast<std::size_t>(u) * factor;
            std::size_t pick = top_left;
            bool in_range = depth[top_left] != 0 && limits.contains(static_cast<float>(depth[top_left]) * scale);
            if (!in_range) {
                const int rows = std::min(factor, H - v * factor), cols = std::min(factor, W - u * factor);
                bool with_depth = false;
                for (int dv = 0; dv < rows && !in_range; ++dv)
                    for (int du = 0; du < cols && !in_range; ++du) {
                        const std::size_t q = top_left + static_cast<std::size_t>(dv) * W + du;
                        if (depth[q] == 0) continue;
                        in_range = limits.contains(static_cast<float>(depth[q]) * scale);
                        if (in_range || !with_depth) pick = q;
                        with_depth = true;
                    }
            }
            const std::size_t o = static_cast<std::size_t>(v) * w + u;
            out_depth[o] = depth[pick];
            if (rgb)
                for (int c = 0; c < 3; ++c) out_rgb[3 * o + c] = rgb[3 * pick + c];
        }
    }
}

DecimatedSource::DecimatedSource(const DepthImage& input, const DepthImage& decimated,
                                 int factor, float same_m, float same_rel)
    : DecimatedSource(input.data.data(), input.width, input.height, input.scale_m_per_unit,
                      decimated, factor, same_m, same_rel) {
    if (input.data.size() != static_cast<std::size_t>(W_) * H_)
        throw InputError("decimation: the decimated depth does not match the input's size");
}

DecimatedSource::DecimatedSource(const std::uint16_t* input, int width, int height,
                                 float scale_m_per_unit, const DepthImage& decimated, int factor,
                                 float same_m, float same_rel)
    : full_(input),
      small_(decimated.data.data()),
      W_(width),
      H_(height),
      w_(decimated.width),
      h_(decimated.height),
      factor_(factor),
      // Depths compared in the images' units: metres = units * scale.
      same_(same_m / scale_m_per_unit),
      same_rel_(same_rel * scale_m_per_unit),
      scale_(scale_m_per_unit) {
    if (factor < 1 || w_ != (W_ + factor - 1) / factor ||
        h_ != (H_ + factor - 1) / factor ||
        decimated.data.size() != static_cast<std::size_t>(w_) * h_)
        throw InputError("decimation: the decimated depth does not match the input's size");
}

void DecimatedSource::use_colour_at_edges(const ColorImage& input, const ColorImage& decimated,
                                          const std::uint8_t* edge_blocks,
                                          const std::uint16_t* block_labels,
                                          std::vector<std::int32_t>& block_source) {
    if (input.empty() || decimated.empty()) return;  // depth only: depth decides alone
    if (input.width != W_ || input.height != H_ ||
        input.rgb.size() != 3 * static_cast<std::size_t>(W_) * H_)
        throw InputError("decimation: colour and depth sizes differ");
    use_colour_at_edges(input.rgb.data(), decimated, edge_blocks, block_labels, block_source);
}

void DecimatedSource::use_colour_at_edges(const std::uint8_t* input_rgb,
                                          const ColorImage& decimated,
                                          const std::uint8_t* edge_blocks,
                                          const std::uint16_t* block_labels,
                                          std::vector<std::int32_t>& block_source) {
    if (input_rgb == nullptr || decimated.empty()) return;  // depth only: depth decides alone
    if (decimated.width != w_ || decimated.height != h_ ||
        decimated.rgb.size() != 3 * static_cast<std::size_t>(w_) * h_)
        throw InputError("decimation: colour and depth sizes differ");
    rgb_ = input_rgb;
    small_rgb_ = decimated.rgb.data();
    edges_ = edge_blocks;
    block_source.resize(static_cast<std::size_t>(w_) * h_);
    voted_ = block_source.data();
    vote(block_labels, block_source.data());
}

void DecimatedSource::vote(const std::uint16_t* labels, std::int32_t* source) const {
    // The grid: offsets -4, -2, 0, 2, 4 blocks in each direction. On the OSD learn frames
    // it scored as the whole 9 x 9 window did, with a third of the votes (docs/DESIGN.md).
    constexpr int kStep = 2, kReach = 4;
    const float* const weight = vote_weights().data();
#pragma omp parallel for schedule(dynamic, 8)
    for (int bv = 0; bv < h_; ++bv)
        for (int bu = 0; bu < w_; ++bu) {
            const std::int32_t b = bv * w_ + bu;
            if (!edges_[b]) continue;  // only edge blocks are looked up (search)
            source[b] = b;
            if (small_[b] == 0) continue;
            const float z = small_[b], tolerance = same_ + same_rel_ * z * z;
            const std::uint8_t* const c = small_rgb_ + 3 * static_cast<std::size_t>(b);
            const std::uint16_t own = labels[b];
            // The other labels vote together (an outline mostly parts two; counting each apart
            // scored the same on osd_mosd), and the block nearest in colour among theirs
            // speaks for them.
            float own_total = 0, other_total = 0;
            int nearest_d = std::numeric_limits<int>::max();
            std::int32_t nearest = b;
            // The grid's offsets that stay inside the image.
            const int v_first = bv - std::min(kReach, bv / kStep * kStep);
            const int u_first = bu - std::min(kReach, bu / kStep * kStep);
            const int v_last = std::min(h_ - 1, bv + kReach), u_last = std::min(w_ - 1, bu + kReach);
            for (int qv = v_first; qv <= v_last; qv += kStep)
                for (int qu = u_first; qu <= u_last; qu += kStep) {
                    const std::int32_t q = qv * w_ + qu;
                    const float depth = small_[q];
                    const bool on = depth != 0 && std::fabs(depth - z) <= tolerance;
                    const std::uint8_t* const s = small_rgb_ + 3 * static_cast<std::size_t>(q);
                    const int dr = c[0] - s[0], dg = c[1] - s[1], db = c[2] - s[2];
                    const int d = dr * dr + dg * dg + db * db;
                    const float w = on ? weight[std::min(d >> kWeightShift, kWeights - 1)] : 0.0f;
                    const bool mine = labels[q] == own;
                    own_total += mine ? w : 0.0f;
                    other_total += mine ? 0.0f : w;
                    const bool nearer = on && !mine && d < nearest_d;
                    nearest_d = nearer ? d : nearest_d;
                    nearest = nearer ? q : nearest;
                }
            // Another label wins only with more weight than its own.
            if (other_total > own_total) source[b] = nearest;
        }
}

std::int32_t DecimatedSource::search(int u, int v, int bu, int bv, float z, bool on_own) const {
    const std::int32_t own = bv * w_ + bu;
    if (edges_ && edges_[own]) {
        // Its own block and the three beside the quarter it lies in, on its surface: the
        // nearest in colour, its own first.
        const std::uint8_t* const c = rgb_ + 3 * (static_cast<std::size_t>(v) * W_ + u);
        auto colour_distance = [&](std::int32_t q) {
            const std::uint8_t* const s = small_rgb_ + 3 * static_cast<std::size_t>(q);
            const int dr = c[0] - s[0], dg = c[1] - s[1], db = c[2] - s[2];
            return dr * dr + dg * dg + db * db;
        };
        const int nu = 2 * (u - bu * factor_) < factor_ ? bu - 1 : bu + 1;
        const int nv = 2 * (v - bv * factor_) < factor_ ? bv - 1 : bv + 1;
        const bool u_in = nu >= 0 && nu < w_, v_in = nv >= 0 && nv < h_;
        const std::int32_t beside[3] = {u_in ? bv * w_ + nu : -1, v_in ? nv * w_ + bu : -1,
                                        u_in && v_in ? nv * w_ + nu : -1};
        std::int32_t best = on_own ? own : -1;
        int best_d = on_own ? colour_distance(own) : std::numeric_limits<int>::max();
        for (const std::int32_t q : beside) {
            if (q < 0 || !same_surface(q, z)) continue;
            const int d = colour_distance(q);
            if (d < best_d) {
                best_d = d;
                best = q;
            }
        }
        if (best >= 0) return edges_[best] ? voted_[best] : best;
    }
    // No block on its surface: the nearest in depth.
    const std::int32_t best = nearest_in_depth(bu, bv, z, nullptr);
    return best >= 0 && voted_ && edges_[best] ? voted_[best] : best;
}

std::int32_t DecimatedSource::nearest_in_depth(int bu, int bv, float z, const std::uint8_t* among) const {
    std::int32_t best = -1;
    float best_dz = std::numeric_limits<float>::infinity();
    for (int nv = std::max(0, bv - 1); nv <= std::min(h_ - 1, bv + 1); ++nv)
        for (int nu = std::max(0, bu - 1); nu <= std::min(w_ - 1, bu + 1); ++nu) {
            const std::int32_t q = nv * w_ + nu;
            if (small_[q] == 0 || (among && !among[q])) continue;
            const float dz = std::fabs(small_[q] - z);
            if (dz < best_dz) {
                best_dz = dz;
                best = q;
            }
        }
    return best;
}

void DecimatedSource::own_blocks_of_row(int v, const std::uint8_t* usable, const DepthRange* range,
                                        float* scratch, std::uint8_t* takes_own) const {
    // Locals: members read after each byte stored could have changed (char aliasing).
    const int factor = factor_, W = W_;
    const float same = same_, same_rel = same_rel_, scale = scale_;
    const float zmin = range ? range->zmin_m : -std::numeric_limits<float>::infinity();
    const float zmax = range ? range->zmax_m : std::numeric_limits<float>::infinity();
    const std::size_t first_block = static_cast<std::size_t>(v / factor) * w_;
    const std::uint16_t* const small = small_ + first_block;
    const std::uint8_t* const edges = edges_ ? edges_ + first_block : nullptr;
    if (usable) usable += first_block;
    // Each block's depth, 0 where its pixels cannot take it as it is: no depth (no
    // surface), an edge block (searched) or not usable; into scratch's tail, then over the
    // block's columns.
    float* const per_block = scratch + W;
    for (int bu = 0; bu < w_; ++bu) {
        const bool as_is = !(edges && edges[bu]) && !(usable && !usable[bu]);
        per_block[bu] = as_is ? static_cast<float>(small[bu]) : 0.0f;
    }
    widen_row<1>(per_block, factor, W, scratch);
    takes_own_block(full_ + static_cast<std::size_t>(v) * W, scratch, W, {same, same_rel, scale, zmin, zmax},
                    takes_own);
}

// ---- the way back: expand_result --------------------------------------------------------

namespace {

/// expand_result's scratch: track id -> object_list index, and per row band the active pixels
/// and each object's pixels and box; the edge blocks and their colour vote.
struct ExpandBuffers {
    /// Pixels and 2D box of one object within one band of rows.
    struct Box {
        int u_min, v_min, u_max, v_max;
        std::size_t pixels;
        /// Pixels u_first..u_last of row v.
        void add_run(int u_first, int u_last, int v) {
            pixels += static_cast<std::size_t>(u_last - u_first + 1);
            u_min = std::min(u_min, u_first);
            v_min = std::min(v_min, v);
            u_max = std::max(u_max, u_last);
            v_max = std::max(v_max, v);
        }
        void merge(const Box& o) {
            pixels += o.pixels;
            u_min = std::min(u_min, o.u_min);
            v_min = std::min(v_min, o.v_min);
            u_max = std::max(u_max, o.u_max);
            v_max = std::max(v_max, o.v_max);
        }
    };
    /// Row bands, counted apart and reduced in band order: the same sums on any thread count.
    static constexpr int kBands = 16;
    std::vector<int> object_index;
    std::vector<std::size_t> band_active;
    std::vector<Box> band_boxes;
    std::vector<std::uint8_t> edge_blocks;        ///< decimated pixels at an object's outline
    std::vector<std::uint16_t> edge_lo, edge_hi;  ///< their 3-wide row minima and maxima
    std::vector<std::int32_t> block_source;       ///< each edge block's source after the colour vote
    /// One block row's results repeated over the input's columns (each block's over its
    /// factor columns): each input row of the block row starts as a copy of it. One per band.
    struct BlockRow {
        int bv = -1;  ///< the block row it holds
        std::vector<std::uint16_t> labels, segments, objects;
        std::vector<std::uint8_t> rgb, active, classes;
        std::vector<float> scratch;           ///< own_blocks_of_row's (W + w)
        std::vector<std::uint8_t> takes_own;  ///< own_blocks_of_row's
    };
    std::vector<BlockRow> band_rows;
};

/// 1. Edge blocks: an object (or, without the object stages, a cluster) other than the
/// block's own in its 3 x 3 neighbourhood; there the input's colour places the outline.
/// Separable: each pixel's row-wise minimum and maximum over three, then column-wise; an
/// edge where the 3 x 3 minimum and maximum differ. Plain loops over rows through raw
/// pointers, the borders clamped by the row pointers' choice, not per pixel: they
/// vectorize. In: `outline` (w x h). Out: buf.edge_blocks (and edge_lo, edge_hi). O(w h),
/// two parallel passes, no allocation.
void mark_edge_blocks(const LabelImage& outline, ExpandBuffers& buf) {
    const int w = outline.width, h = outline.height;
    const std::size_t n_small = outline.labels.size();
    buf.edge_blocks.resize(n_small);
    buf.edge_lo.resize(n_small);
    buf.edge_hi.resize(n_small);
    const std::uint16_t* const l = outline.labels.data();
    std::uint16_t *const lo = buf.edge_lo.data(), *const hi = buf.edge_hi.data();
    std::uint8_t* const edge = buf.edge_blocks.data();
    auto min3 = [](std::uint16_t a, std::uint16_t b, std::uint16_t c) { return std::min(std::min(a, b), c); };
    auto max3 = [](std::uint16_t a, std::uint16_t b, std::uint16_t c) { return std::max(std::max(a, b), c); };
#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        const std::uint16_t* const in = l + static_cast<std::size_t>(v) * w;
        std::uint16_t *const row_lo = lo + static_cast<std::size_t>(v) * w, *const row_hi = hi + static_cast<std::size_t>(v) * w;
        row_lo[0] = min3(in[0], in[0], in[std::min(1, w - 1)]);
        row_hi[0] = max3(in[0], in[0], in[std::min(1, w - 1)]);
        for (int u = 1; u < w - 1; ++u) {
            row_lo[u] = min3(in[u - 1], in[u], in[u + 1]);
            row_hi[u] = max3(in[u - 1], in[u], in[u + 1]);
        }
        if (w > 1) {
            row_lo[w - 1] = min3(in[w - 2], in[w - 1], in[w - 1]);
            row_hi[w - 1] = max3(in[w - 2], in[w - 1], in[w - 1]);
        }
    }
#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        const std::size_t up = static_cast<std::size_t>(std::max(v - 1, 0)) * w,
                          row = static_cast<std::size_t>(v) * w,
                          down = static_cast<std::size_t>(std::min(v + 1, h - 1)) * w;
        const std::uint16_t *const lo_up = lo + up, *const lo_row = lo + row, *const lo_down = lo + down;
        const std::uint16_t *const hi_up = hi + up, *const hi_row = hi + row, *const hi_down = hi + down;
        std::uint8_t* const out = edge + row;
        for (int u = 0; u < w; ++u)
            out[u] = min3(lo_up[u], lo_row[u], lo_down[u]) != max3(hi_up[u], hi_row[u], hi_down[u]);
    }
}

/// 2. The result at the input's size W x H: `small`'s stats, plane and object list copied,
/// its images sized (without the object stages theirs stay empty, as run_on leaves them).
/// The pixels are written by expand_bands. O(objects) plus the resizes (none from the
/// second frame of a size).
void shape_result(const FrameResult& small, int W, int H, bool objects, FrameResult& r) {
    r.stats = small.stats;
    r.plane = small.plane;
    r.segment_stats = small.segment_stats;
    r.object_list = small.object_list;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    auto shape = [](LabelImage& img, int width, int height) {
        img.width = width;
        img.height = height;
        img.labels.resize(static_cast<std::size_t>(width) * height);
    };
    shape(r.labels, W, H);
    shape(r.segments, objects ? W : 0, objects ? H : 0);
    shape(r.objects, objects ? W : 0, objects ? H : 0);
    r.colors.width = W;
    r.colors.height = H;
    r.colors.rgb.resize(3 * N);
    r.active.resize(N);
    r.plane_classes.resize(objects ? N : 0);
}

/// 3. Each band's counts and block row made ready: track id -> index in `objects` (for each
/// object's pixels and 2D box), empty boxes and counts per band, and each band's block row
/// sized for W input columns and w blocks. O(bands x objects), no allocation once sized.
void prepare_bands(const std::vector<DetectedObject>& objects, int W, int H, int w, bool with_objects,
                   ExpandBuffers& buf) {
    int max_id = 0;
    for (const DetectedObject& d : objects) max_id = std::max(max_id, d.id);
    buf.object_index.assign(static_cast<std::size_t>(max_id) + 1, -1);
    for (std::size_t i = 0; i < objects.size(); ++i)
        buf.object_index[static_cast<std::size_t>(objects[i].id)] = static_cast<int>(i);
    buf.band_boxes.assign(ExpandBuffers::kBands * objects.size(), ExpandBuffers::Box{W, H, -1, -1, 0});
    buf.band_active.assign(ExpandBuffers::kBands, 0);
    buf.band_rows.resize(ExpandBuffers::kBands);
    const auto n_row = static_cast<std::size_t>(W);
    for (ExpandBuffers::BlockRow& b : buf.band_rows) {
        b.bv = -1;  // a new frame: no block row held
        b.labels.resize(n_row);
        b.segments.resize(with_objects ? n_row : 0);
        b.objects.resize(with_objects ? n_row : 0);
        b.rgb.resize(3 * n_row);
        b.active.resize(n_row);
        b.classes.resize(with_objects ? n_row : 0);
        b.scratch.resize(n_row + static_cast<std::size_t>(w));
        b.takes_own.resize(n_row);
    }
}

/// The per-pixel results, in (`small`'s, per block) and out (`r`'s, per input pixel), as
/// raw pointers: through the vectors, every byte store would make the compiler reload every
/// data pointer. Copied by value into each band's closures for the same reason.
struct PixelArrays {
    const std::uint8_t* frame_rgb;  ///< the input's colour, or nullptr
    const std::uint16_t *in_labels, *in_segments, *in_objects;
    const std::uint8_t *in_rgb, *in_active, *in_classes;
    std::uint16_t *labels, *segments, *objects;
    std::uint8_t *colors, *active, *classes;
    bool with_objects;
};

PixelArrays pixel_arrays(const RgbdView& frame, const FrameResult& s, bool with_objects, FrameResult& r) {
    return {frame.has_color() && frame.color_matches() ? frame.rgb : nullptr,
            s.labels.labels.data(), s.segments.labels.data(), s.objects.labels.data(),
            s.colors.rgb.data(), s.active.data(), s.plane_classes.data(),
            r.labels.labels.data(), r.segments.labels.data(), r.objects.labels.data(),
            r.colors.rgb.data(), r.active.data(), r.plane_classes.data(), with_objects};
}

/// 4. Every input pixel's results, band by band of rows in parallel. Per row: first every
/// pixel from its own block (nearly every pixel's source: a plain copy of the block row,
/// each block's results loaded once), then the pixels whose source is another block or none
/// (no depth, off their block's surface, at an outline, out of the range or on a block out
/// of it) written again; last the row's count of active pixels and each object's runs,
/// into the band's counts and boxes (reduced in band order by count_objects). A pixel is in
/// the depth range by its own depth, as at every pixel (select_depth_range): the block it
/// takes can lie on the other side of a limit. In range, on a block that is not, it takes
/// the nearest in depth of the 3 x 3 blocks that are (its own is: the frame was decimated
/// to blocks in range where they could be); out of range, none. O(W H), one parallel pass.
void expand_bands(const DepthRange& range, const RgbdView& frame, const DecimatedSource& source, int w,
                  const PixelArrays& arrays, ExpandBuffers& buf) {
    const int W = frame.width, H = frame.height;
    const float scale = frame.depth_scale_m_per_unit;
    const std::uint16_t* const depth = frame.depth;
    const int factor = source.factor();
    const std::size_t n_obj = buf.band_boxes.size() / ExpandBuffers::kBands;
    const int max_id = static_cast<int>(buf.object_index.size()) - 1;
    const int* const object_index = buf.object_index.data();
    const PixelArrays a = arrays;  // a local copy: see PixelArrays
    const bool objects = a.with_objects;
#pragma omp parallel for schedule(static)
    for (int band = 0; band < ExpandBuffers::kBands; ++band) {
        ExpandBuffers::Box* const boxes = buf.band_boxes.data() + static_cast<std::size_t>(band) * n_obj;
        ExpandBuffers::BlockRow& block_row = buf.band_rows[static_cast<std::size_t>(band)];
        std::size_t active = 0;
        // Pixel p's results from block q, or "no point" for q < 0.
        auto take = [=](std::size_t p, std::int32_t q) {
            std::uint8_t* const rgb = a.colors + 3 * p;
            if (q < 0) {
                a.labels[p] = 0;
                rgb[0] = rgb[1] = rgb[2] = a.frame_rgb ? dimmed_grey(a.frame_rgb + 3 * p) : 0;
                a.active[p] = 0;
                if (!objects) return;
                a.classes[p] = kPlaneRemoved;
                a.segments[p] = 0;
                a.objects[p] = 0;
                return;
            }
            const auto sq = static_cast<std::size_t>(q);
            a.labels[p] = a.in_labels[sq];
            rgb[0] = a.in_rgb[3 * sq];
            rgb[1] = a.in_rgb[3 * sq + 1];
            rgb[2] = a.in_rgb[3 * sq + 2];
            a.active[p] = a.in_active[sq];
            if (!objects) return;
            a.classes[p] = a.in_classes[sq];
            a.segments[p] = a.in_segments[sq];
            a.objects[p] = a.in_objects[sq];
        };
        std::uint16_t *const row_labels = block_row.labels.data(), *const row_segments = block_row.segments.data(),
                      *const row_objects = block_row.objects.data();
        std::uint8_t *const row_rgb = block_row.rgb.data(), *const row_active = block_row.active.data(),
                     *const row_classes = block_row.classes.data();
        // Block row bv's results, each block's over its columns.
        auto widen = [=](int bv) {
            const std::size_t first = static_cast<std::size_t>(bv) * w;
            widen_row<1>(a.in_labels + first, factor, W, row_labels);
            widen_row<3>(a.in_rgb + 3 * first, factor, W, row_rgb);
            widen_row<1>(a.in_active + first, factor, W, row_active);
            if (!objects) return;
            widen_row<1>(a.in_classes + first, factor, W, row_classes);
            widen_row<1>(a.in_segments + first, factor, W, row_segments);
            widen_row<1>(a.in_objects + first, factor, W, row_objects);
        };
        float* const scratch = block_row.scratch.data();
        std::uint8_t* const takes_own = block_row.takes_own.data();
        for (int v = band * H / ExpandBuffers::kBands; v < (band + 1) * H / ExpandBuffers::kBands; ++v) {
            const int bv = v / factor;
            const std::size_t row = static_cast<std::size_t>(v) * W;
            // First every pixel from its own block, copied from the block row.
            if (block_row.bv != bv) {
                widen(bv);
                block_row.bv = bv;
            }
            const auto n_row = static_cast<std::size_t>(W);
            std::copy_n(row_labels, n_row, a.labels + row);
            std::copy_n(row_rgb, 3 * n_row, a.colors + 3 * row);
            std::copy_n(row_active, n_row, a.active + row);
            if (objects) {
                std::copy_n(row_classes, n_row, a.classes + row);
                std::copy_n(row_segments, n_row, a.segments + row);
                std::copy_n(row_objects, n_row, a.objects + row);
            }
            // Then the pixels that do not take their own block as it is (off its surface, out
            // of range, on a block out of it, or at an outline), one by one.
            source.own_blocks_of_row(v, a.in_active, &range, scratch, takes_own);
            const std::uint8_t* const end = takes_own + W;
            for (const auto* at = static_cast<const std::uint8_t*>(std::memchr(takes_own, 0, n_row)); at != nullptr;
                 at = static_cast<const std::uint8_t*>(std::memchr(at + 1, 0, static_cast<std::size_t>(end - at - 1)))) {
                const int u = static_cast<int>(at - takes_own), bu = u / factor;
                const std::size_t p = row + static_cast<std::size_t>(u);
                std::int32_t q = source.in_block(u, v, bu, bv);
                if (q >= 0) {
                    if (!range.contains(static_cast<float>(depth[p]) * scale))
                        q = -1;
                    else if (!a.in_active[q])
                        q = source.nearest_in_depth(bu, bv, depth[p], a.in_active);
                }
                take(p, q);
            }
            // Last the row's counts. A row's count fits in 32 bits, which sum faster.
            unsigned in_row = 0;
            for (std::size_t u = 0; u < n_row; ++u) in_row += a.active[row + u];
            active += in_row;
            if (!objects) continue;
            // Each run of one object id adds to its box at once. The runs' starts are found
            // by memchr in a flag per column (0: a run starts), set by a loop that
            // vectorizes; takes_own is free again to hold them.
            const std::uint16_t* const ids = a.objects + row;
            std::uint8_t* const continues = takes_own;
            continues[0] = 0;
            for (int u = 1; u < W; ++u) continues[u] = ids[u] == ids[u - 1];
            for (int u = 0; u < W;) {
                const auto* const next = static_cast<const std::uint8_t*>(
                    std::memchr(continues + u + 1, 0, static_cast<std::size_t>(W - u - 1)));
                const int run_end = next ? static_cast<int>(next - continues) : W;
                const std::uint16_t id = ids[u];
                if (id != 0 && id <= max_id && object_index[id] >= 0)
                    boxes[object_index[id]].add_run(u, run_end - 1, v);
                u = run_end;
            }
        }
        buf.band_active[static_cast<std::size_t>(band)] = active;
    }
}

/// 5. The bands' counts reduced in band order: r.active_points, and each object's pixels
/// and 2D box at the input's size. O(bands x objects).
void count_objects(int W, int H, const ExpandBuffers& buf, FrameResult& r) {
    r.active_points = 0;
    for (std::size_t a : buf.band_active) r.active_points += a;
    const std::size_t n_obj = r.object_list.size();
    for (std::size_t i = 0; i < n_obj; ++i) {
        DetectedObject& d = r.object_list[i];
        ExpandBuffers::Box total{W, H, -1, -1, 0};
        for (int band = 0; band < ExpandBuffers::kBands; ++band)
            total.merge(buf.band_boxes[static_cast<std::size_t>(band) * n_obj + i]);
        d.pixels = total.pixels;
        d.u_min = total.u_min;
        d.v_min = total.v_min;
        d.u_max = total.u_max;
        d.v_max = total.v_max;
    }
}

/// 6. Objects under `min_pixels` input pixels dropped from r.object_list and cleared from
/// r.objects. The tracker's minimum (ObjectParams::min_points) counts the input's pixels:
/// the stages checked it divided by N^2 on blocks, and an object can come back a few pixels
/// short. O(objects), plus each dropped object's box.
void drop_small_objects(std::size_t min_pixels, FrameResult& r) {
    const int W = r.objects.width;
    std::uint16_t* const ids = r.objects.labels.data();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < r.object_list.size(); ++i) {
        DetectedObject& d = r.object_list[i];
        if (d.pixels >= min_pixels) {
            if (kept != i) r.object_list[kept] = std::move(d);
            ++kept;
            continue;
        }
        for (int v = d.v_min; v <= d.v_max; ++v)
            for (int u = d.u_min; u <= d.u_max; ++u) {
                std::uint16_t& id = ids[static_cast<std::size_t>(v) * W + u];
                if (id == d.id) id = 0;
            }
    }
    r.object_list.resize(kept);
}

}  // namespace

/// The workspace's buffers (opaque in decimation.hpp): ExpandBuffers.
struct ExpandWorkspace::Buffers : ExpandBuffers {};

ExpandWorkspace::ExpandWorkspace() : b_(std::make_unique<Buffers>()) {}
ExpandWorkspace::~ExpandWorkspace() = default;
ExpandWorkspace::ExpandWorkspace(ExpandWorkspace&&) noexcept = default;
ExpandWorkspace& ExpandWorkspace::operator=(ExpandWorkspace&&) noexcept = default;

void expand_result(const PipelineParams& params, const RgbdView& frame,
                   const RgbdFrame& decimated, const FrameResult& s, ExpandWorkspace& ws,
                   FrameResult& r) {
    ExpandBuffers& buf = *ws.b_;
    const int W = frame.width, H = frame.height;
    // An input pixel takes a neighbouring block's results across a depth step no larger
    // than the segmentation's own connection rule over the block's width.
    const float n = static_cast<float>(params.decimation);
    DecimatedSource source(frame.depth, W, H, frame.depth_scale_m_per_unit, decimated.depth,
                           params.decimation,
                           n * params.segmentation.depth_jump_m,
                           n * params.segmentation.depth_jump_rel);
    // At the objects' outlines (without the object stages, the clusters') the input's
    // colour places the outline.
    const bool objects = params.detect_objects;
    const LabelImage& outline = objects ? s.objects : s.labels;
    mark_edge_blocks(outline, buf);
    if (frame.has_color() && !frame.color_matches())
        throw InputError(std::string(frame.name) + ": colour and depth sizes differ");
    source.use_colour_at_edges(frame.rgb, decimated.color, buf.edge_blocks.data(), outline.labels.data(),
                               buf.block_source);
    shape_result(s, W, H, objects, r);
    prepare_bands(r.object_list, W, H, outline.width, objects, buf);
    expand_bands(params.range, frame, source, outline.width, pixel_arrays(frame, s, objects, r), buf);
    count_objects(W, H, buf, r);
    drop_small_objects(static_cast<std::size_t>(params.objects.min_points), r);
}

}  // namespace wul3d
