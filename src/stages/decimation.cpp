#include "wul3d/decimation.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "branch_free.hpp"
#include "decimated_source.hpp"
#include "param_check.hpp"
#include "wul3d/error.hpp"
#include "wul3d/frame_result.hpp"
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
void widen_row(const T* __restrict blocks, int factor, int n, T* __restrict out) {
    if (channels == 3 && sizeof(T) == 1 && factor == 2 && n >= 4) {
        // RGB bytes, which GCC does not load as vectors: each block's triple read as 4 bytes
        // and stored twice as 4, overlapping (the 4th byte of each store is overwritten by
        // the next one). The last block goes by the loop below: nothing read or written
        // past the rows.
        const int last = (n - 1) / 2;
        for (int b = 0; b < last; ++b) {
            std::uint32_t x;
            std::memcpy(&x, blocks + 3 * b, 4);
            std::memcpy(out + 6 * b, &x, 4);
            std::memcpy(out + 6 * b + 3, &x, 4);
        }
        for (int u = 2 * last; u < n; ++u)
            for (int c = 0; c < channels; ++c) out[channels * u + c] = blocks[channels * last + c];
        return;
    }
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

/// Each block's top-left depth of one row of blocks (`row`: the input row, w blocks of
/// `factor` pixels), into `out`, and search[u] = 1 where it is not in the range (no depth,
/// or DepthRange::contains says no: the same float operations): those blocks are searched.
/// Branch-free; built for AVX2 and baseline x86-64. Cost: one pass over w blocks.
WUL3D_AVX2_CLONES
void top_left_depths(const std::uint16_t* __restrict row, int factor, int w, float scale, DepthRange limits,
                     std::uint16_t* __restrict out, std::uint8_t* __restrict search) {
    const float zmin = limits.zmin_m, zmax = limits.zmax_m;
    auto take = [&](int u, std::uint16_t d) {
        const float z = static_cast<float>(d) * scale;
        out[u] = d;
        search[u] = static_cast<std::uint8_t>(!((d != 0) & (z >= zmin) & (z <= zmax)));
    };
    if (factor == 2)  // the default: a constant stride, which the compiler vectorizes
        for (int u = 0; u < w; ++u) take(u, row[2 * u]);
    else
        for (int u = 0; u < w; ++u) take(u, row[static_cast<std::size_t>(u) * factor]);
}

/// Each top-left colour of w blocks in a row into `out` (RGB): at factor 2 each triple read
/// and written as 4 bytes (the 4th overwritten by the next block's), the last block's byte
/// by byte, nothing read or written past the w blocks. O(w).
void top_left_colours(const std::uint8_t* row, int factor, int w, std::uint8_t* out) {
    int u = 0;
    if (factor == 2)
        for (; u + 1 < w; ++u) {
            std::uint32_t x;
            std::memcpy(&x, row + 6 * u, 4);
            std::memcpy(out + 3 * u, &x, 4);
        }
    for (; u < w; ++u)
        for (int c = 0; c < 3; ++c) out[3 * u + c] = row[3 * static_cast<std::size_t>(u) * factor + c];
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
        const std::size_t first = static_cast<std::size_t>(v) * factor * W, o = static_cast<std::size_t>(v) * w;
        // Mostly a block's top-left pixel is in range: taken for every block of a chunk in
        // a pass that vectorizes, then the chunk's others searched.
        constexpr int kChunk = 256;
        std::uint8_t search[kChunk];
        for (int u0 = 0; u0 < w; u0 += kChunk) {
            const int n = std::min(kChunk, w - u0);
            const std::size_t in0 = first + static_cast<std::size_t>(u0) * factor;
            top_left_depths(depth + in0, factor, n, scale, limits, out_depth + o + u0, search);
            if (rgb) top_left_colours(rgb + 3 * in0, factor, n, out_rgb + 3 * (o + u0));
            for (int i = 0; i < n; ++i) {
                if (!search[i]) continue;
                const int u = u0 + i;
                // The block's first pixel in range, row-major; else its first with depth; else
                // its top-left one.
                const std::size_t top_left = first + static_cast<std::size_t>(u) * factor;
                std::size_t pick = top_left;
                const int rows = std::min(factor, H - v * factor), cols = std::min(factor, W - u * factor);
                bool in_range = false, with_depth = false;
                for (int dv = 0; dv < rows && !in_range; ++dv)
                    for (int du = 0; du < cols && !in_range; ++du) {
                        const std::size_t q = top_left + static_cast<std::size_t>(dv) * W + du;
                        if (depth[q] == 0) continue;
                        in_range = limits.contains(static_cast<float>(depth[q]) * scale);
                        if (in_range || !with_depth) pick = q;
                        with_depth = true;
                    }
                out_depth[o + u] = depth[pick];
                if (rgb)
                    for (int c = 0; c < 3; ++c) out_rgb[3 * (o + u) + c] = rgb[3 * pick + c];
            }
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
      same_rel_(same_rel * scale_m_per_unit) {
    if (factor < 1 || w_ != (W_ + factor - 1) / factor ||
        h_ != (H_ + factor - 1) / factor ||
        decimated.data.size() != static_cast<std::size_t>(w_) * h_)
        throw InputError("decimation: the decimated depth does not match the input's size");
}

void DecimatedSource::use_colour_at_edges(const ColorImage& input, const ColorImage& decimated,
                                          const std::uint8_t* edge_blocks,
                                          const std::uint16_t* block_labels, VoteBuffers& buffers) {
    if (input.empty() || decimated.empty()) return;  // depth only: depth decides alone
    if (input.width != W_ || input.height != H_ ||
        input.rgb.size() != 3 * static_cast<std::size_t>(W_) * H_)
        throw InputError("decimation: colour and depth sizes differ");
    use_colour_at_edges(input.rgb.data(), decimated, edge_blocks, block_labels, buffers);
}

void DecimatedSource::use_colour_at_edges(const std::uint8_t* input_rgb,
                                          const ColorImage& decimated,
                                          const std::uint8_t* edge_blocks,
                                          const std::uint16_t* block_labels, VoteBuffers& buffers) {
    if (input_rgb == nullptr || decimated.empty()) return;  // depth only: depth decides alone
    if (decimated.width != w_ || decimated.height != h_ ||
        decimated.rgb.size() != 3 * static_cast<std::size_t>(w_) * h_)
        throw InputError("decimation: colour and depth sizes differ");
    rgb_ = input_rgb;
    small_rgb_ = decimated.rgb.data();
    edges_ = edge_blocks;
    buffers.block_source.resize(static_cast<std::size_t>(w_) * h_);
    voted_ = buffers.block_source.data();
    vote(block_labels, buffers);
}

namespace {

// The vote's grid: offsets -kReach ... kReach blocks, kStep apart, in both directions (the
// whole 9 x 9 window scored the same on the OSD learn frames with three times the votes:
// docs/DESIGN.md); kLanes edge blocks are voted together.
constexpr int kStep = 2, kReach = 4, kSide = 2 * kReach / kStep + 1, kTaps = kSide * kSide, kLanes = 8;

/// The decimated frame into the vote's padded arrays (VoteBuffers): depth | label << 16 and
/// r | g << 8 | b << 16 per block, kReach blocks of zeros on every side (zeroed when the size
/// changes; the interior is written every frame). O(w h), parallel over rows.
void pad_for_vote(const std::uint16_t* depth, const std::uint16_t* labels, const std::uint8_t* rgb, int w, int h,
                  VoteBuffers& vb) {
    const int pw = w + 2 * kReach, ph = h + 2 * kReach;
    if (vb.padded_width != pw || vb.padded_height != ph) {
        vb.depth_label.assign(static_cast<std::size_t>(pw) * ph, 0);
        vb.rgb.assign(static_cast<std::size_t>(pw) * ph, 0);
        vb.padded_width = pw;
        vb.padded_height = ph;
    }
    std::uint32_t *const depth_label = vb.depth_label.data(), *const colour = vb.rgb.data();
    const std::size_t last = static_cast<std::size_t>(w) * h - 1;
#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        const std::size_t in = static_cast<std::size_t>(v) * w, out = static_cast<std::size_t>(v + kReach) * pw + kReach;
        for (int u = 0; u < w; ++u)
            depth_label[out + u] = depth[in + u] | static_cast<std::uint32_t>(labels[in + u]) << 16;
        // A triple read as 4 bytes, the 4th masked off (little-endian); the image's last one
        // byte by byte (nothing read past it).
        const bool little = std::endian::native == std::endian::little;
        const int whole = !little ? 0 : in + static_cast<std::size_t>(w) - 1 < last ? w : w - 1;
        for (int u = 0; u < whole; ++u) {
            std::uint32_t c;
            std::memcpy(&c, rgb + 3 * (in + static_cast<std::size_t>(u)), 4);
            colour[out + u] = c & 0xffffffu;  // little-endian: r | g << 8 | b << 16
        }
        for (int u = whole; u < w; ++u) {
            const std::uint8_t* const c = rgb + 3 * (in + static_cast<std::size_t>(u));
            colour[out + u] = c[0] | static_cast<std::uint32_t>(c[1]) << 8 | static_cast<std::uint32_t>(c[2]) << 16;
        }
    }
}

/// The votes of kLanes edge blocks at padded indices `at`, each lane as DecimatedSource's
/// doc says, with the taps in row-major order: the same sums, in the same order, as one block
/// at a time. The other labels vote together (an outline mostly parts two; counting each
/// apart scored the same on osd_mosd), and the block nearest in colour among theirs speaks
/// for them. winner[l]: the tap (index into `offsets`) of that block where they outweigh the
/// block's own label, else -1 (and -1 for a block without depth). Branch-free (whether a tap
/// is on the surface or of the label follows no pattern a predictor learns) and lane by lane,
/// so that the lanes' arithmetic runs as vectors (AVX2 and baseline x86-64 clones; the taps'
/// loads stay scalar). Cost: kTaps taps per lane.
WUL3D_AVX2_CLONES
void vote_lanes(const std::uint32_t* __restrict depth_label, const std::uint32_t* __restrict rgb,
                const std::int32_t* __restrict at, const std::int32_t* __restrict offsets,
                const float* __restrict weight, float same, float same_rel, int* __restrict winner) {
    float z[kLanes], tolerance[kLanes], own_total[kLanes], other_total[kLanes];
    int c0[kLanes], c1[kLanes], c2[kLanes], own[kLanes], nearest_d[kLanes], nearest[kLanes];
    for (int l = 0; l < kLanes; ++l) {
        const std::uint32_t x = depth_label[at[l]], c = rgb[at[l]];
        z[l] = static_cast<float>(x & 0xffffu);
        tolerance[l] = same + same_rel * z[l] * z[l];
        own[l] = static_cast<int>(x >> 16);
        c0[l] = static_cast<int>(c & 0xffu);
        c1[l] = static_cast<int>((c >> 8) & 0xffu);
        c2[l] = static_cast<int>(c >> 16);
        own_total[l] = other_total[l] = 0.0f;
        nearest_d[l] = std::numeric_limits<int>::max();
        nearest[l] = -1;
    }
    for (int t = 0; t < kTaps; ++t) {
        const std::int32_t offset = offsets[t];
        for (int l = 0; l < kLanes; ++l) {
            const std::int32_t q = at[l] + offset;
            const std::uint32_t x = depth_label[q], c = rgb[q];
            const float depth = static_cast<float>(x & 0xffffu);
            const bool on = (depth != 0) & (std::fabs(depth - z[l]) <= tolerance[l]);
            const int dr = c0[l] - static_cast<int>(c & 0xffu), dg = c1[l] - static_cast<int>((c >> 8) & 0xffu),
                      db = c2[l] - static_cast<int>(c >> 16);
            const int d = dr * dr + dg * dg + db * db;
            const float wq = weight[std::min(d >> kWeightShift, kWeights - 1)];
            const bool mine = static_cast<int>(x >> 16) == own[l];
            own_total[l] += detail::pick(on & mine, wq, 0.0f);
            other_total[l] += detail::pick(on & !mine, wq, 0.0f);
            const int nearer = -static_cast<int>(on & !mine & (d < nearest_d[l]));
            nearest_d[l] = (d & nearer) | (nearest_d[l] & ~nearer);
            nearest[l] = (t & nearer) | (nearest[l] & ~nearer);
        }
    }
    for (int l = 0; l < kLanes; ++l)
        winner[l] = detail::pick((z[l] != 0) & (other_total[l] > own_total[l]), nearest[l], -1);
}

}  // namespace

void DecimatedSource::vote(const std::uint16_t* labels, VoteBuffers& vb) const {
    pad_for_vote(small_, labels, small_rgb_, w_, h_, vb);
    const int w = w_, pw = vb.padded_width;
    std::int32_t* const source = vb.block_source.data();
    // The edge blocks (found by memchr, not a test per block), a whole number of lanes: the
    // last lanes repeat the last block (their results are not kept).
    vb.edges.clear();
    for (int bv = 0; bv < h_; ++bv) {
        const std::uint8_t* const row = edges_ + static_cast<std::size_t>(bv) * w;
        for (const auto* at = static_cast<const std::uint8_t*>(std::memchr(row, 1, static_cast<std::size_t>(w)));
             at != nullptr;
             at = static_cast<const std::uint8_t*>(std::memchr(at + 1, 1, static_cast<std::size_t>(row + w - at - 1)))) {
            const int bu = static_cast<int>(at - row);
            vb.edges.push_back(bv * w + bu);
        }
    }
    const std::size_t n = vb.edges.size();
    if (n == 0) return;
    vb.edges.resize((n + kLanes - 1) / kLanes * kLanes, vb.edges.back());
    std::array<std::int32_t, kTaps> padded_offsets{}, block_offsets{};
    for (int t = 0; t < kTaps; ++t) {
        const int dv = (t / kSide) * kStep - kReach, du = (t % kSide) * kStep - kReach;
        padded_offsets[static_cast<std::size_t>(t)] = dv * pw + du;
        block_offsets[static_cast<std::size_t>(t)] = dv * w + du;
    }
    const float* const weight = vote_weights().data();
    const std::int32_t* const edges = vb.edges.data();
    const float same = same_, same_rel = same_rel_;
    const auto batches = static_cast<std::ptrdiff_t>(vb.edges.size() / kLanes);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < batches; ++i) {
        // Block b = bv w + bu in the padded copy: (bv + kReach) pw + bu + kReach.
        std::int32_t at[kLanes];
        int winner[kLanes];
        for (int l = 0; l < kLanes; ++l) {
            const std::int32_t b = edges[i * kLanes + l];
            at[l] = b + (b / w) * (pw - w) + kReach * (pw + 1);
        }
        vote_lanes(vb.depth_label.data(), vb.rgb.data(), at, padded_offsets.data(), weight, same, same_rel, winner);
        for (int l = 0; l < kLanes; ++l) {
            const std::int32_t b = edges[i * kLanes + l];
            // Another label wins only with more weight than its own.
            source[b] = winner[l] < 0 ? b : b + block_offsets[static_cast<std::size_t>(winner[l])];
        }
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
    VoteBuffers vote;                             ///< the colour vote's
    /// One block row's results repeated over the input's columns (each block's over its
    /// factor columns), and its depth where its pixels may take it as it is: what each input
    /// row of the block row takes from its own block. One per band.
    struct BlockRow {
        int bv = -1;  ///< the block row it holds
        std::vector<std::uint16_t> labels, segments, objects;
        std::vector<std::uint8_t> rgb, classes;
        std::vector<float> depth;         ///< 0 where the block cannot be taken as it is
        std::vector<float> block_depth;   ///< depth, one per block (w)
        std::vector<std::uint8_t> code;   ///< per input column: a PixelSource
        std::vector<std::uint8_t> grey, mask3, grey3;  ///< colour_row's (W, 3 W, 3 W)
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
/// its images sized (without the object stages theirs stay empty, as run_on leaves them;
/// without `colors`, r.colors). The pixels are written by expand_bands. O(objects) plus the
/// resizes (none from the second frame of a size).
void shape_result(const FrameResult& small, int W, int H, bool objects, bool colors, FrameResult& r) {
    r.stats = small.stats;
    r.depth_noise_px = small.depth_noise_px;
    r.normal_radius_px = small.normal_radius_px;
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
    r.colors.width = colors ? W : 0;
    r.colors.height = colors ? H : 0;
    r.colors.rgb.resize(colors ? 3 * N : 0);
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
        b.classes.resize(with_objects ? n_row : 0);
        b.depth.resize(n_row);
        b.block_depth.resize(static_cast<std::size_t>(w));
        b.code.resize(n_row);
        b.grey.resize(n_row);
        b.mask3.resize(3 * n_row);
        b.grey3.resize(3 * n_row);
    }
}

/// Where an input pixel takes its results from (expand_bands' code per column).
enum PixelSource : std::uint8_t {
    kNoPoint = 0,   ///< no depth, or out of the range: no point
    kOwnBlock = 1,  ///< its own block as it is (nearly every pixel with depth)
    kSearch = 2,    ///< another block, or none: DecimatedSource's search, one pixel at a time
};

/// The limits of source_codes' test.
struct SourceTest {
    float same, same_rel, scale, zmin, zmax;
};

/// code[u] for pixel u of a row: kOwnBlock where its depth `full[u]` (units) and its block's
/// `block[u]` (0: not to be taken as it is) are both there, on one surface (same_surface) and
/// in range (DepthRange::contains), with the same float operations: the same answers; else
/// kNoPoint without depth or out of range; else kSearch. `&`, not `&&`: a branch per pixel
/// would keep the loop from vectorizing. Built for AVX2 and baseline x86-64 (no FMA either
/// way). Cost: one pass over the W pixels.
WUL3D_AVX2_CLONES
void source_codes(const std::uint16_t* __restrict full, const float* __restrict block, int W, SourceTest t,
                  std::uint8_t* __restrict code) {
    for (int u = 0; u < W; ++u) {
        const float z = full[u], b = block[u], metres = z * t.scale;
        const int point = (z != 0) & (metres >= t.zmin) & (metres <= t.zmax);
        const int own = point & (b != 0) & (std::fabs(b - z) <= t.same + t.same_rel * z * z);
        code[u] = static_cast<std::uint8_t>(point + point - own);  // 0, 1 (own) or 2
    }
}

/// out[u] = own[u] where code[u] is kOwnBlock, else `none`: the block row's values on the
/// pixels that take their own block, the no-point value on the others (the searched ones are
/// written again). By a mask, not `?:`, which GCC makes a branch around the load: the loops
/// vectorize (AVX2 and baseline clones).
WUL3D_AVX2_CLONES
void blend_row16(const std::uint8_t* __restrict code, const std::uint16_t* __restrict own, std::uint16_t none,
                 int W, std::uint16_t* __restrict out) {
    for (int u = 0; u < W; ++u) {
        const auto m = static_cast<std::uint16_t>(-static_cast<int>(code[u] == kOwnBlock));
        out[u] = static_cast<std::uint16_t>((own[u] & m) | (none & ~m));
    }
}
/// active[u] = 1 on the pixels that take their own block (an active block: the others are
/// not taken as they are), else 0 (a searched pixel is written again); returns their count.
WUL3D_AVX2_CLONES
unsigned active_row(const std::uint8_t* __restrict code, int W, std::uint8_t* __restrict active) {
    unsigned count = 0;
    for (int u = 0; u < W; ++u) {
        const std::uint8_t a = code[u] == kOwnBlock;
        active[u] = a;
        count += a;
    }
    return count;
}

/// The object stages' results and the active flags of a row in one pass (blend_row16 on
/// each, and active_row): the block row's labels, segments, objects and plane
/// classes where code[u] is kOwnBlock, else 0 (kPlaneRemoved for the classes). Returns the
/// pixels made active.
WUL3D_AVX2_CLONES
unsigned object_row(const std::uint8_t* __restrict code, const std::uint16_t* __restrict labels,
                    const std::uint16_t* __restrict segments, const std::uint16_t* __restrict objects,
                    const std::uint8_t* __restrict classes, int W, std::uint16_t* __restrict out_labels,
                    std::uint16_t* __restrict out_segments, std::uint16_t* __restrict out_objects,
                    std::uint8_t* __restrict out_classes, std::uint8_t* __restrict active) {
    static_assert(kPlaneRemoved == 0, "no point's class is the masks' 0");
    unsigned count = 0;
    for (int u = 0; u < W; ++u) {
        const std::uint8_t own = code[u] == kOwnBlock;
        const auto m16 = static_cast<std::uint16_t>(-static_cast<int>(own));
        const auto m8 = static_cast<std::uint8_t>(-static_cast<int>(own));
        out_labels[u] = static_cast<std::uint16_t>(labels[u] & m16);
        out_segments[u] = static_cast<std::uint16_t>(segments[u] & m16);
        out_objects[u] = static_cast<std::uint16_t>(objects[u] & m16);
        out_classes[u] = static_cast<std::uint8_t>(classes[u] & m8);
        active[u] = own;
        count += own;
    }
    return count;
}

/// The colours of `n` pixels: the block row's (`own`, RGB) where code[u] is kOwnBlock, else
/// the input pixel's dimmed grey (visualization.hpp; 0 without colour: `frame_rgb`
/// nullptr). The grey's float operations are dimmed_grey's, in its order: the same bytes.
/// In passes that vectorize (GCC does not load RGB triples as vectors, but stores them):
/// the greys into `grey` (n), each pixel's mask and masked grey three times over into
/// `mask3` and `grey3` (3 n each), then the choice byte by byte.
WUL3D_AVX2_CLONES
void colour_pixels(const std::uint8_t* __restrict code, const std::uint8_t* __restrict own,
                   const std::uint8_t* __restrict frame_rgb, int n, std::uint8_t* __restrict grey,
                   std::uint8_t* __restrict mask3, std::uint8_t* __restrict grey3, std::uint8_t* __restrict out) {
    if (frame_rgb == nullptr)
        std::memset(grey, 0, static_cast<std::size_t>(n));
    else
        for (int u = 0; u < n; ++u) {
            const float g = 0.299f * frame_rgb[3 * u] + 0.587f * frame_rgb[3 * u + 1] + 0.114f * frame_rgb[3 * u + 2];
            grey[u] = static_cast<std::uint8_t>(g * 0.35f);
        }
    for (int u = 0; u < n; ++u) {
        const auto m = static_cast<std::uint8_t>(-static_cast<int>(code[u] == kOwnBlock));
        const auto dim = static_cast<std::uint8_t>(grey[u] & ~m);
        mask3[3 * u] = mask3[3 * u + 1] = mask3[3 * u + 2] = m;
        grey3[3 * u] = grey3[3 * u + 1] = grey3[3 * u + 2] = dim;
    }
    for (int i = 0; i < 3 * n; ++i) out[i] = static_cast<std::uint8_t>((own[i] & mask3[i]) | grey3[i]);
}

/// Whether all of code[0, n) is kOwnBlock (a reduction that vectorizes).
WUL3D_AVX2_CLONES
bool all_own(const std::uint8_t* __restrict code, int n) {
    unsigned other = 0;
    for (int u = 0; u < n; ++u) other |= code[u] ^ kOwnBlock;
    return other == 0;
}

/// colour_pixels on a row of W pixels, by chunks of 64: a chunk whose pixels all take their
/// own block is a copy of the block row's colours (no grey to compute): most of a scene.
void colour_row(const std::uint8_t* code, const std::uint8_t* own, const std::uint8_t* frame_rgb, int W,
                std::uint8_t* grey, std::uint8_t* mask3, std::uint8_t* grey3, std::uint8_t* out) {
    constexpr int kChunk = 64;
    for (int u = 0; u < W; u += kChunk) {
        const int n = std::min(kChunk, W - u);
        if (all_own(code + u, n))
            std::memcpy(out + 3 * u, own + 3 * u, 3 * static_cast<std::size_t>(n));
        else
            colour_pixels(code + u, own + 3 * u, frame_rgb ? frame_rgb + 3 * u : nullptr, n, grey, mask3, grey3,
                          out + 3 * u);
    }
}

/// The per-pixel results, in (`small`'s, per block) and out (`r`'s, per input pixel), as
/// raw pointers: through the vectors, every byte store would make the compiler reload every
/// data pointer. Copied by value into each band's closures for the same reason. `colors`
/// (and `in_rgb`) nullptr: no colours to make (ExpandParams::colors).
struct PixelArrays {
    const std::uint8_t* frame_rgb;  ///< the input's colour, or nullptr
    const std::uint16_t* in_depth;  ///< the decimated depth
    const std::uint16_t *in_labels, *in_segments, *in_objects;
    const std::uint8_t *in_rgb, *in_active, *in_classes;
    const std::uint8_t* edges;  ///< the edge blocks
    std::uint16_t *labels, *segments, *objects;
    std::uint8_t *colors, *active, *classes;
    bool with_objects;
};

PixelArrays pixel_arrays(const RgbdView& frame, const RgbdFrame& decimated, const FrameResult& s,
                         const ExpandBuffers& buf, bool with_objects, bool with_colors, FrameResult& r) {
    return {frame.has_color() && frame.color_matches() ? frame.rgb : nullptr,
            decimated.depth.data.data(),
            s.labels.labels.data(), s.segments.labels.data(), s.objects.labels.data(),
            with_colors ? s.colors.rgb.data() : nullptr, s.active.data(), s.plane_classes.data(),
            buf.edge_blocks.data(),
            r.labels.labels.data(), r.segments.labels.data(), r.objects.labels.data(),
            with_colors ? r.colors.rgb.data() : nullptr, r.active.data(), r.plane_classes.data(), with_objects};
}

/// Block row bv into `row`: its results over the input's W columns, and its depth (float,
/// as the surface test reads it) where its pixels may take it as it is: not an edge block
/// (searched) and active (an inactive block is no pixel's source). O(W).
void widen_block_row(const PixelArrays& a, int bv, int w, int factor, int W, ExpandBuffers::BlockRow& row) {
    const std::size_t first = static_cast<std::size_t>(bv) * w;
    float* const block_depth = row.block_depth.data();
    for (int bu = 0; bu < w; ++bu) {
        const std::size_t b = first + static_cast<std::size_t>(bu);
        const bool as_is = (a.edges[b] == 0) & (a.in_active[b] != 0);
        block_depth[bu] = detail::pick(as_is, static_cast<float>(a.in_depth[b]), 0.0f);
    }
    widen_row<1>(block_depth, factor, W, row.depth.data());
    widen_row<1>(a.in_labels + first, factor, W, row.labels.data());
    if (a.colors) widen_row<3>(a.in_rgb + 3 * first, factor, W, row.rgb.data());
    if (a.with_objects) {
        widen_row<1>(a.in_classes + first, factor, W, row.classes.data());
        widen_row<1>(a.in_segments + first, factor, W, row.segments.data());
        widen_row<1>(a.in_objects + first, factor, W, row.objects.data());
    }
    row.bv = bv;
}

/// Input row v's results (row offset `row` = v W) from its block row's, by code: every pixel
/// from its own block or as no point, a pass per result that vectorizes. Returns the pixels
/// it made active.
unsigned write_row(const PixelArrays& a, ExpandBuffers::BlockRow& b, std::size_t row, int W) {
    const std::uint8_t* const code = b.code.data();
    if (a.colors)
        colour_row(code, b.rgb.data(), a.frame_rgb ? a.frame_rgb + 3 * row : nullptr, W, b.grey.data(),
                   b.mask3.data(), b.grey3.data(), a.colors + 3 * row);
    if (a.with_objects)
        return object_row(code, b.labels.data(), b.segments.data(), b.objects.data(), b.classes.data(), W,
                          a.labels + row, a.segments + row, a.objects + row, a.classes + row, a.active + row);
    blend_row16(code, b.labels.data(), 0, W, a.labels + row);
    return active_row(code, W, a.active + row);
}

/// Input row v's searched pixels (code kSearch: in range, with depth, but not on their own
/// block as it is; nearly all lie in edge blocks), one by one through `source`, each from the
/// block it finds or as no point (as write_row left it). Returns the pixels it made active.
/// O(searched pixels).
unsigned write_searched(const PixelArrays& a, const DecimatedSource& source, const std::uint8_t* code,
                        const std::uint16_t* depth_row, int v, int W) {
    // The arrays as locals: through the struct, every byte stored would make the compiler
    // load each pointer again (char aliasing).
    const std::uint8_t *const in_active = a.in_active, *const in_rgb = a.in_rgb, *const in_classes = a.in_classes;
    const std::uint16_t *const in_labels = a.in_labels, *const in_segments = a.in_segments,
                        *const in_objects = a.in_objects;
    const std::size_t row = static_cast<std::size_t>(v) * W;
    const bool with_objects = a.with_objects;  // without, the object stages' arrays are empty
    std::uint16_t* const labels = a.labels + row;
    std::uint16_t* const segments = with_objects ? a.segments + row : nullptr;
    std::uint16_t* const objects = with_objects ? a.objects + row : nullptr;
    std::uint8_t *const colors = a.colors ? a.colors + 3 * row : nullptr, *const active = a.active + row;
    std::uint8_t* const classes = with_objects ? a.classes + row : nullptr;
    const int factor = source.factor(), bv = v / factor;
    unsigned made = 0;
    // Runs of searched pixels (an edge block's are side by side): memchr finds each run's
    // start, the run is walked pixel by pixel.
    for (int u = 0; u < W;) {
        const auto* const at = static_cast<const std::uint8_t*>(std::memchr(code + u, kSearch, static_cast<std::size_t>(W - u)));
        if (at == nullptr) break;
        for (u = static_cast<int>(at - code); u < W && code[u] == kSearch; ++u) {
            const int bu = factor == 2 ? u >> 1 : u / factor;  // no division at N = 2
            std::int32_t q = source.in_block(u, v, bu, bv);
            if (q >= 0 && !in_active[q]) q = source.nearest_in_depth(bu, bv, depth_row[u], in_active);
            if (q < 0) continue;  // no point: written so by write_row
            const auto sq = static_cast<std::size_t>(q);
            labels[u] = in_labels[sq];
            if (colors)
                for (int c = 0; c < 3; ++c) colors[3 * u + c] = in_rgb[3 * sq + c];
            active[u] = 1;  // q is active: the search takes no other
            ++made;
            if (!with_objects) continue;
            classes[u] = in_classes[sq];
            segments[u] = in_segments[sq];
            objects[u] = in_objects[sq];
        }
    }
    return made;
}

/// 4. Every input pixel's results, band by band of rows in parallel. Per row: each pixel's
/// source code (source_codes: its own block, no point, or a search), then every result from
/// the block row by code (write_row), then the searched pixels (another block or none: no
/// depth on their block's surface, at an outline, or on a block out of the range) one by one
/// through DecimatedSource; last each object's runs into the band's boxes (reduced in band
/// order by count_objects). A pixel is in the depth range by its own depth, as at every
/// pixel (select_depth_range): the block it takes can lie on the other side of a limit. In
/// range, on a block that is not, it takes the nearest in depth of the 3 x 3 blocks that are
/// (its own is: the frame was decimated to blocks in range where they could be); out of
/// range, none. O(W H), one parallel pass, no allocation.
void expand_bands(const DepthRange& range, const RgbdView& frame, const DecimatedSource& source, int w,
                  const PixelArrays& arrays, ExpandBuffers& buf) {
    const int W = frame.width, H = frame.height;
    const std::uint16_t* const depth = frame.depth;
    const int factor = source.factor();
    const SourceTest test{source.same_units(), source.same_rel_units(), frame.depth_scale_m_per_unit, range.zmin_m,
                          range.zmax_m};
    const std::size_t n_obj = buf.band_boxes.size() / ExpandBuffers::kBands;
    const int max_id = static_cast<int>(buf.object_index.size()) - 1;
    const int* const object_index = buf.object_index.data();
    const PixelArrays a = arrays;  // a local copy: see PixelArrays
    const bool objects = a.with_objects;
#pragma omp parallel for schedule(static)
    for (int band = 0; band < ExpandBuffers::kBands; ++band) {
        ExpandBuffers::Box* const boxes = buf.band_boxes.data() + static_cast<std::size_t>(band) * n_obj;
        ExpandBuffers::BlockRow& block_row = buf.band_rows[static_cast<std::size_t>(band)];
        std::uint8_t* const code = block_row.code.data();
        std::size_t active = 0;
        for (int v = band * H / ExpandBuffers::kBands; v < (band + 1) * H / ExpandBuffers::kBands; ++v) {
            const int bv = v / factor;
            const std::size_t row = static_cast<std::size_t>(v) * W;
            if (block_row.bv != bv) widen_block_row(a, bv, w, factor, W, block_row);
            source_codes(depth + row, block_row.depth.data(), W, test, code);
            active += write_row(a, block_row, row, W);
            active += write_searched(a, source, code, depth + row, v, W);
            if (!objects) continue;
            // Each run of one object id adds to its box at once. The runs' starts are found
            // by memchr in a flag per column (0: a run starts), set by a loop that
            // vectorizes; the code row is free again to hold them.
            const std::uint16_t* const ids = a.objects + row;
            std::uint8_t* const continues = code;
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

void expand_result(const ExpandParams& params, const RgbdView& frame, const RgbdFrame& decimated,
                   const FrameResult& s, ExpandWorkspace& ws, FrameResult& r) {
    ExpandBuffers& buf = *ws.b_;
    const int W = frame.width, H = frame.height;
    DecimatedSource source(frame.depth, W, H, frame.depth_scale_m_per_unit, decimated.depth, params.factor,
                           params.same_m, params.same_rel);
    // At the objects' outlines (without the object stages, the clusters') the input's
    // colour places the outline.
    const bool objects = params.objects;
    const LabelImage& outline = objects ? s.objects : s.labels;
    if (outline.width != decimated.width() || outline.height != decimated.height() ||
        s.active.size() != outline.labels.size() ||
        (params.colors && s.colors.rgb.size() != 3 * outline.labels.size()))
        throw InputError(std::string(frame.name) + ": the decimated results do not match the decimated frame");
    mark_edge_blocks(outline, buf);
    if (frame.has_color() && !frame.color_matches())
        throw InputError(std::string(frame.name) + ": colour and depth sizes differ");
    source.use_colour_at_edges(frame.rgb, decimated.color, buf.edge_blocks.data(), outline.labels.data(),
                               buf.vote);
    shape_result(s, W, H, objects, params.colors, r);
    prepare_bands(r.object_list, W, H, outline.width, objects, buf);
    expand_bands(params.range, frame, source, outline.width,
                 pixel_arrays(frame, decimated, s, buf, objects, params.colors, r), buf);
    count_objects(W, H, buf, r);
    drop_small_objects(params.min_object_pixels, r);
}

}  // namespace wul3d
