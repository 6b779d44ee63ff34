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
    /// degrees, in each direction (normal_radius_for); [0, 90), 0: radius_px whatever the
    /// noise. 7: the tilt's size then stays mostly within the support plane's grow angle of
    /// 12 degrees (chosen on the generated tune seeds: docs/ABLATION.md, "Normals").
    float max_tilt_noise_deg = 7.0f;

    void validate() const;  ///< throws ParamError
};

/// The depth's noise in one frame as it tilts normals, in pixel footprints: the standard
/// deviation of a point's position along its surface's normal divided by the distance
/// between neighbouring points on that surface, over the frame. For a surface facing the
/// camera that is the depth's noise over the pixel footprint z / fx; a surface seen at an
/// angle a has its noise times cos a over neighbours 1 / cos a further apart, so it counts
/// cos^2 a as much (a table seen at 45 degrees, half). At the default decimation real
/// Kinect v1 frames measure 0.1-0.2, a RealSense with its filters about 0.1, the generator's
/// active-stereo camera 0.5-1.2. Measured on second differences of inverse depth along rows
/// and columns (zero on any plane: slopes are not noise) on every third pixel, with the
/// slope from the points 12 pixels either side; steeper than 80 degrees, and the largest
/// tenth, are edges and are dropped. Calibrated on Gaussian noise, within 12 % up to 2.5
/// (tests/stages/normals_test.cpp). 0 when fewer than 64 samples exist. `scratch` is
/// reused. Cost: O(N / 9) plus a selection on the samples.
float measure_depth_noise(const OrganizedCloud& cloud, float fx, std::vector<float>& scratch);

/// The radius the normals of a frame with depth noise `noise_px` (measure_depth_noise) need:
/// a normal from points r pixels either side tilts by about noise / (sqrt(2) r) radians in
/// each direction, so
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
