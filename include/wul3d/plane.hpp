#pragma once
/// @file plane.hpp
/// Support-plane removal, part of the paper's background step (step 5): find the plane the
/// objects stand on from the organized cloud and the normals already computed, and remove
/// the points on and below it. No RANSAC, no kd-tree: planar regions are grown on a coarse
/// pixel grid, fitted by least squares and merged when coplanar; the support is chosen
/// among them by orientation (it faces up in the image) and by the points standing on it,
/// not by size alone (a wall or the floor can be larger than the table).
/// The plane's convention and the result's types: support_plane.hpp.
#include <cstdint>
#include <memory>
#include <vector>

#include "wul3d/camera.hpp"
#include "wul3d/cloud.hpp"
#include "wul3d/support_plane.hpp"

namespace wul3d {

struct PlaneParams {
    int grid_stride_px = 4;        ///< planes are grown on every n-th pixel in u and v; [1, 32]
    float grow_angle_deg = 12.0f;  ///< a grid point joins a region when its normal is within
                                   ///< this of the region's mean normal; (0, 90); widened
                                   ///< with the depth's noise (remove_support_plane)
    float grow_dist_m = 0.012f;    ///< ... and it lies within this of the region's plane; > 0
    int min_region_points = 40;    ///< grid points of a region worth fitting; >= 3
    float merge_angle_deg = 6.0f;  ///< regions this parallel ...; (0, 90)
    float merge_dist_m = 0.02f;    ///< ... and this close in offset d are one plane; > 0
    float on_plane_m = 0.008f;     ///< height below which a point is on the plane; > 0
    float on_plane_rel = 0.004f;   ///< plus this times z^2 (sensor noise grows with z^2); >= 0;
                                   ///< the band widened with the depth's noise
                                   ///< (remove_support_plane)
    float inlier_angle_deg = 25.0f;  ///< an on-plane point whose normal departs more than this
                                     ///< from the plane's is a candidate foot; (0, 90)
    float min_extent = 0.04f;      ///< a support covers at least this share of the grid points
                                   ///< with a normal; (0, 1]
    float min_up = 0.1f;           ///< a support faces up in the image: -n_y >= min_up (y is
                                   ///< down; a wall facing a camera that looks down has
                                   ///< n_y >= 0, a floor cos(pitch): 0.1 takes a camera
                                   ///< looking down up to 84 degrees; when none does, a
                                   ///< plane facing any way that holds objects); [-1, 1]
    float max_object_height_m = 0.5f;  ///< points up to this height over the support count as
                                       ///< standing on it; > 0
    float island_min_height_m = 0.0025f;  ///< an on-plane patch enclosed by object points (a
                                         ///< bowl's or box's inner bottom) whose mean height
                                         ///< is above this belongs to the object; > 0
    float island_max_share = 0.05f;  ///< ... and holds at most this share of the image; [0, 1]
    int hull_margin_px = 12;       ///< objects' feet may lie this far outside the support's
                                   ///< image-space convex hull; >= 0

    void validate() const;  ///< throws ParamError naming the field
};

/// Scratch of remove_support_plane; allocates nothing after the first frame of a size.
/// Opaque: its buffers are plane.cpp's (src/stages/plane_internal.hpp).
class PlaneWorkspace {
public:
    PlaneWorkspace();
    ~PlaneWorkspace();
    PlaneWorkspace(PlaneWorkspace&&) noexcept;
    PlaneWorkspace& operator=(PlaneWorkspace&&) noexcept;

    struct Buffers;      ///< src/stages/plane_internal.hpp
    Buffers& buffers();  ///< for plane.cpp's phases (made again after a move)

private:
    std::unique_ptr<Buffers> b_;
};

/// Finds the support plane among the `active` points and classifies every pixel
/// (PlaneClass) into `classes` (resized to W x H). With no support found every active point
/// is kPlaneObject.
/// `K` projects the feet of points (their foot on the plane) into the image to test them
/// against the support's extent. `noise_widening` (>= 1; the pipeline passes
/// plane_noise_widening of the frame's measured depth noise) widens the grow angle and the
/// on-plane band for a camera noisier than the parameters assume; a low support's layer
/// keeps the given band (docs/DESIGN.md, "Support plane").
PlaneResult remove_support_plane(const PlaneParams& params, const PinholeIntrinsics& K,
                                 const OrganizedCloud& cloud, const NormalMap& normals,
                                 const std::vector<std::uint8_t>& active, PlaneWorkspace& ws,
                                 std::vector<std::uint8_t>& classes, float noise_widening = 1.0f);

}  // namespace wul3d
