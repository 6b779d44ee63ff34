#pragma once
/// @file normals.hpp
/// Step 4 of the paper: a normal per point from its grid neighbours, O(N) on the organized
/// cloud. n = (P(u+r) - P(u-r)) x (P(v+r) - P(v-r)), oriented towards the camera.
/// Across a depth discontinuity the difference is taken one-sided, on the pixel's own
/// surface; with no usable neighbour pair the point gets no normal (valid = 0), never a
/// made-up vector.
#include <cstdint>
#include <vector>

#include "wul3d/cloud.hpp"

namespace wul3d {

struct NormalParams {
    int radius_px = 2;  ///< neighbour distance in pixels; >= 1. Larger smooths sensor noise.
    /// Two neighbours belong to one surface when their depths differ by at most
    /// max_depth_jump_rel * z * radius_px (scales with depth, like sensor noise); > 0.
    float max_depth_jump_rel = 0.02f;

    void validate() const;  ///< throws ParamError
};

void estimate_normals(const NormalParams& params, const OrganizedCloud& cloud, NormalMap& out);

/// Normals averaged over a (2 radius + 1)^2 window of valid normals and renormalized: less
/// sensor noise for tests that compare normals a few pixels apart (segmentation's crease
/// cuts). Separable: vertical running sums, then a direct horizontal sum (O(N r), cheap for
/// the small radii used); a pixel without a normal stays without one. `scratch` is resized
/// as needed and reused. Only rows [row_begin, row_end) are computed (row_end < 0: to the
/// last row); the others get no normal. The result depends on the row range (the running
/// sums restart at fixed bands of it), not on the number of threads.
void smooth_normals(const NormalMap& in, int radius_px, std::vector<float>& scratch, NormalMap& out,
                    int row_begin = 0, int row_end = -1);

}  // namespace wul3d
