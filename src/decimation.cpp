#include "wul3d/decimation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "param_check.hpp"
#include "wul3d/error.hpp"

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

}  // namespace

void decimate_frame(const RgbdFrame& in, int factor, RgbdFrame& out, const DepthRange* range) {
    detail::require_param(factor >= 1 && factor <= 8, "", "decimate", factor, "in [1, 8]");
    const int W = in.width(), H = in.height();
    const bool color = in.has_color();
    if (color && (in.color.width != W || in.color.height != H))
        throw InputError(in.name + ": colour and depth sizes differ");
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
    out.depth.scale_m_per_unit = in.depth.scale_m_per_unit;
    out.depth.data.resize(static_cast<std::size_t>(w) * h);
    out.color.width = color ? w : 0;
    out.color.height = color ? h : 0;
    out.color.rgb.resize(color ? static_cast<std::size_t>(w) * h * 3 : 0);
    const std::uint16_t* const depth = in.depth.data.data();
    const std::uint8_t* const rgb = color ? in.color.rgb.data() : nullptr;

    const float scale = in.depth.scale_m_per_unit;  // z = depth * scale, as back-projected

#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
            // The block's first pixel in range, row-major; else its first with depth; else
            // its top-left one.
            const std::size_t top_left = static_cast<std::size_t>(v) * factor * W + static_cast<std::size_t>(u) * factor;
            std::size_t pick = top_left;
            const int rows = std::min(factor, H - v * factor), cols = std::min(factor, W - u * factor);
            bool with_depth = false, in_range = false;
            for (int dv = 0; dv < rows && !in_range; ++dv)
                for (int du = 0; du < cols && !in_range; ++du) {
                    const std::size_t q = top_left + static_cast<std::size_t>(dv) * W + du;
                    if (depth[q] == 0) continue;
                    in_range = !range || range->contains(static_cast<float>(depth[q]) * scale);
                    if (in_range || !with_depth) pick = q;
                    with_depth = true;
                }
            const std::size_t o = static_cast<std::size_t>(v) * w + u;
            out.depth.data[o] = depth[pick];
            if (rgb)
                for (int c = 0; c < 3; ++c) out.color.rgb[3 * o + c] = rgb[3 * pick + c];
        }
    }
}

DecimatedSource::DecimatedSource(const DepthImage& input, const DepthImage& decimated,
                                 int factor, float same_m, float same_rel)
    : full_(input.data.data()),
      small_(decimated.data.data()),
      W_(input.width),
      H_(input.height),
      w_(decimated.width),
      h_(decimated.height),
      factor_(factor),
      // Depths compared in the images' units: metres = units * scale.
      same_(same_m / input.scale_m_per_unit),
      same_rel_(same_rel * input.scale_m_per_unit) {
    if (factor < 1 || w_ != (W_ + factor - 1) / factor ||
        h_ != (H_ + factor - 1) / factor ||
        decimated.data.size() != static_cast<std::size_t>(w_) * h_ ||
        input.data.size() != static_cast<std::size_t>(W_) * H_)
        throw InputError("decimation: the decimated depth does not match the input's size");
}

void DecimatedSource::use_colour_at_edges(const ColorImage& input, const ColorImage& decimated,
                                          const std::uint8_t* edge_blocks,
                                          const std::uint16_t* block_labels,
                                          std::vector<std::int32_t>& block_source) {
    if (input.empty() || decimated.empty()) return;  // depth only: depth decides alone
    if (input.width != W_ || input.height != H_ || decimated.width != w_ || decimated.height != h_ ||
        input.rgb.size() != 3 * static_cast<std::size_t>(W_) * H_ ||
        decimated.rgb.size() != 3 * static_cast<std::size_t>(w_) * h_)
        throw InputError("decimation: colour and depth sizes differ");
    rgb_ = input.rgb.data();
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

}  // namespace wul3d
