#pragma once
/// @file plane.hpp
/// Support-plane removal, part of the paper's background step (step 5): find the plane the
/// objects stand on from the organized cloud and the normals already computed, and remove
/// the points on and below it. No RANSAC, no kd-tree: planar regions are grown on a coarse
/// pixel grid, fitted by least squares and merged when coplanar; the support is chosen
/// among them by orientation (it faces up in the image) and by the points standing on it,
/// not by size alone (a wall or the floor can be larger than the table).
///
/// Plane convention: n . X + d = 0 with n a unit vector towards the camera, so d > 0 and
/// s(X) = n . X + d is the height of X above the plane (metres, camera side positive).
#include <cstdint>
#include <vector>

#include "wul3d/camera.hpp"
#include "wul3d/cloud.hpp"

namespace wul3d {

struct PlaneParams {
    int grid_stride_px = 4;        ///< planes are grown on every n-th pixel in u and v; [1, 32]
    float grow_angle_deg = 12.0f;  ///< a grid point joins a region when its normal is within
                                   ///< this of the region's mean normal; (0, 90)
    float grow_dist_m = 0.012f;    ///< ... and it lies within this of the region's plane; > 0
    int min_region_points = 40;    ///< grid points of a region worth fitting; >= 3
    float merge_angle_deg = 6.0f;  ///< regions this parallel ...; (0, 90)
    float merge_dist_m = 0.02f;    ///< ... and this close in offset d are one plane; > 0
    float on_plane_m = 0.008f;     ///< height below which a point is on the plane; > 0
    float on_plane_rel = 0.004f;   ///< plus this times z^2 (sensor noise grows with z^2); >= 0
    float inlier_angle_deg = 25.0f;  ///< an on-plane point whose normal departs more than this
                                     ///< from the plane's is a candidate foot; (0, 90)
    float min_extent = 0.04f;      ///< a support covers at least this share of the grid points
                                   ///< with a normal; (0, 1]
    float min_up = 0.25f;          ///< a support faces up in the image: -n_y >= min_up (y is
                                   ///< down; a wall facing a camera that looks down has
                                   ///< n_y > 0); [-1, 1]
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

/// A fitted plane and what its choice rested on.
struct Plane {
    float nx = 0, ny = 0, nz = 0, d = 0;  ///< n . X + d = 0, |n| = 1, n towards the camera
    std::size_t inliers = 0;  ///< grid points on it (distance and normal agree)
    std::size_t above = 0;    ///< grid points standing on it (0 < height <= max, foot on it);
                              ///< 0 if not counted (a candidate that could not be the support)
    float up = 0;             ///< -n_y
    float height(float x, float y, float z) const { return nx * x + ny * y + nz * z + d; }
};

/// Per-pixel result classes of remove_support_plane.
enum PlaneClass : std::uint8_t {
    kPlaneRemoved = 0,     ///< not active, on or below the support, or off its extent
    kPlaneObject = 1,      ///< above the support and over it: object material
    kPlaneFoot = 2,        ///< on the support's band but not facing like it: maybe a foot
    kPlaneInside = 3,      ///< on the band but enclosed by object points: a container's inside
};

struct PlaneResult {
    bool found = false;           ///< false: no support; every active point is kept
    Plane support;                ///< valid when found
    std::vector<Plane> candidates;  ///< every merged plane that met min_extent
    std::size_t kept = 0;         ///< pixels of class kPlaneObject or kPlaneFoot
};

/// Scratch of remove_support_plane; allocates nothing after the first frame of a size.
struct PlaneWorkspace {
    /// The grid's points gathered once (every grid_stride_px-th pixel), structure of arrays.
    struct GridPoints {
        std::vector<float> x, y, z, nx, ny, nz;
        std::vector<std::uint8_t> active, usable;  ///< usable: active with a normal
    } grid;
    std::vector<int> region;          ///< grid point -> region id, -1 none
    std::vector<int> stack;
    std::vector<double> sums;         ///< per region: count, sum x, y, z, xx, xy, xz, yy, yz, zz
    std::vector<std::uint8_t> hull;   ///< grid-resolution mask of the support's extent
    std::vector<int> hull_points;     ///< (gu, gv) pairs: each grid row's outermost inliers
    std::vector<Plane> fitted;        ///< the merged planes, fitted, inliers counted
    std::vector<float> layer_t;       ///< per grid point: height over the chosen support in
                                      ///< half bands (1e9 if it does not face like it)
    std::vector<int> by_extent;       ///< candidate indices, largest extent first
    std::vector<std::uint32_t> candidate_bits;  ///< per grid point: bit r = inlier of rank r
    std::vector<int> shared;          ///< inliers two candidates share (ranks i > j)
    std::vector<std::uint8_t> sliver; ///< per rank: cuts through a larger candidate, not scored
    std::vector<std::uint8_t> tall_foot;  ///< per grid cell: something rises from it past
                                          ///< max_object_height_m over the candidate counted
    std::vector<std::uint8_t> on_band;  ///< per pixel: 1 = removed and on the plane's band
    /// Runs of on-band pixels, row by row, and their union-find components (islands).
    struct Run {
        int row, begin, end;  ///< pixels [begin, end) of the row
        int parent;           ///< union-find parent (a run index)
    };
    std::vector<Run> runs;
    std::vector<int> row_first_run;     ///< per row + 1: index of its first run
    /// Per run, then summed into its root run: heights over the plane, pixels (roots only),
    /// flags 1 = open (image border, or beside removed points off the band), 2 = beside
    /// object points.
    std::vector<double> island_height;
    std::vector<int> island_size;
    std::vector<std::uint8_t> island_flags;
};

/// Finds the support plane among the `active` points and classifies every pixel
/// (PlaneClass) into `classes` (resized to W x H). With no support found every active point
/// is kPlaneObject.
/// `K` projects the feet of points (their foot on the plane) into the image to test them
/// against the support's extent.
PlaneResult remove_support_plane(const PlaneParams& params, const PinholeIntrinsics& K,
                                 const OrganizedCloud& cloud, const NormalMap& normals,
                                 const std::vector<std::uint8_t>& active, PlaneWorkspace& ws,
                                 std::vector<std::uint8_t>& classes);

}  // namespace wul3d
