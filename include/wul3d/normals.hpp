#pragma once
/// @file normals.hpp
/// Step 4 of the paper: a normal per point from its grid neighbours, O(N) on the organized
/// cloud. n = (P(u+r) - P(u-r)) x (P(v+r) - P(v-r)), oriented towards the camera.
/// Across a depth discontinuity the difference is taken one-sided, on the pixel's own
/// surface; with no usable neighbour pair the point gets no normal (valid = 0), never a
/// made-up vector.
///
/// The radius adapts to the camera: measure_depth_noise() measures how noisy the frame's
/// depth is, and normal_radius_for() widens the neighbourhood until that noise tilts a
/// normal by at most NormalParams::max_tilt_noise_deg. A Kinect v1 keeps radius_px; a noisier
/// camera (an active-stereo one far away) gets a wider one, with no setting to choose.
#include <cstdint>
#include <vector>

#include "wul3d/cloud.hpp"

namespace wul3d {

struct NormalParams {
    int radius_px = 2;  ///< least neighbour distance in pixels, [1, 64]. Larger smooths noise.
    /// Two neighbours belong to one surface when their depths differ by at most
    /// max_depth_jump_rel * z * radius_px (scales with depth, like sensor noise); > 0.
    float max_depth_jump_rel = 0.02f;
    /// The radius grows (up to 64) until the depth's noise tilts a normal by at most this,
    /// degrees (normal_radius_for); [0, 90), 0: radius_px whatever the noise. The default is
    /// the support plane's grow angle (PlaneParams::grow_angle_deg), which its normals must meet.
    float max_tilt_noise_deg = 12.0f;

    void validate() const;  ///< throws ParamError
};

/// The depth's noise in one frame, in pixel footprints: the standard deviation of a point's
/// depth divided by the distance between neighbouring pixels at that depth (z / fx), over
/// the frame. A structured-light Kinect v1 measures about 0.6 at 1-1.5 m, an active-stereo
/// camera without its smoothing filters about 1.8. Measured on second differences of
/// inverse depth (zero on any plane, so slopes do not count), along rows and columns on
/// every third pixel; the largest tenth are edges, not noise, and are dropped. Calibrated
/// on Gaussian noise (tests/stages/normals_test.cpp). 0 when fewer than 64 samples exist.
/// `scratch` is reused. Cost: O(N / 9) plus a selection on the samples.
float measure_depth_noise(const OrganizedCloud& cloud, float fx, std::vector<float>& scratch);

/// The radius the normals of a frame with depth noise `noise_px` need: a normal from points
/// r pixels either side tilts by about noise / (sqrt(2) r) radians, so
/// r = round(noise / (sqrt(2) tan(max_tilt_noise_deg))), at least radius_px, at most 64.
/// radius_px when max_tilt_noise_deg is 0.
int normal_radius_for(const NormalParams& params, float noise_px);
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
