#pragma once
/// @file decimation.hpp
/// The optional first and last stage (PipelineParams::decimation, `--decimate N`): the frame
/// shrinks by N in u and v before back-projection, every later stage runs on N^2 times fewer
/// pixels, and each per-pixel result is carried back to the input's pixels at the end.
/// The speed/quality trade-off is measured in the README ("Decimation").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "wul3d/frame.hpp"

namespace wul3d {

/// Each N x N block of `in` becomes one pixel of `out` ((W + N - 1) / N x (H + N - 1) / N):
/// the block's first pixel with valid depth in row-major order, its depth and colour both
/// (never an average: a block across an object's edge would get a depth between the two
/// surfaces). A block without depth takes its top-left colour. The intrinsics scale to the
/// top-left samples (fx / N, cx / N); a block whose top-left pixel has no depth is back-
/// projected up to N - 1 pixels off, a sub-pixel error at the decimated resolution.
/// N = 1 copies. Throws ParamError for N outside [1, 8] and InputError for a colour image
/// whose size differs from the depth's.
void decimate_frame(const RgbdFrame& in, int factor, RgbdFrame& out);

/// Which pixel of the decimated frame an input pixel takes its results from (the pipeline
/// copies every per-pixel result through it: Pipeline::expand_result). An input pixel
/// without depth has none (-1). One with depth z takes its own block when that block's depth
/// is within same_m + same_rel z^2 (metres) of z, else the one of the 3 x 3 neighbouring
/// blocks whose depth is nearest to z (an edge pixel whose block was sampled on the other
/// surface), else none when none of them has depth.
class DecimatedSource {
public:
    /// Throws InputError unless `decimated` is `input` decimated by `factor` in size.
    DecimatedSource(const DepthImage& input, const DepthImage& decimated, int factor,
                    float same_m, float same_rel);

    int factor() const { return factor_; }
    /// The decimated pixel (v' w + u') for input pixel (u, v), or -1.
    std::int32_t operator()(int u, int v) const { return in_block(u, v, u / factor_, v / factor_); }
    /// The same, for loops that step the block (bu, bv) = (u / factor, v / factor) themselves
    /// (a division per pixel costs more than the rest of the test).
    std::int32_t in_block(int u, int v, int bu, int bv) const {
        const float z = full_[static_cast<std::size_t>(v) * W_ + u];
        if (z == 0) return -1;
        const std::int32_t own = bv * w_ + bu;
        if (small_[own] != 0 && std::fabs(small_[own] - z) <= same_ + same_rel_ * z * z) return own;
        std::int32_t best = -1;
        float best_dz = std::numeric_limits<float>::infinity();
        for (int nv = std::max(0, bv - 1); nv <= std::min(h_ - 1, bv + 1); ++nv)
            for (int nu = std::max(0, bu - 1); nu <= std::min(w_ - 1, bu + 1); ++nu) {
                const std::int32_t q = nv * w_ + nu;
                if (small_[q] == 0) continue;
                const float dz = std::fabs(small_[q] - z);
                if (dz < best_dz) {
                    best_dz = dz;
                    best = q;
                }
            }
        return best;
    }

private:
    const std::uint16_t* full_;
    const std::uint16_t* small_;
    int W_, w_, h_, factor_;
    float same_, same_rel_;  ///< in the depth images' units
};

}  // namespace wul3d
