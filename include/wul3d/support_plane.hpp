#pragma once
/// @file support_plane.hpp
/// The support plane's result types, shared by the plane stage (plane.hpp), segmentation
/// (segmentation.hpp) and the frame's result (frame_result.hpp).
///
/// Plane convention: n . X + d = 0 with n a unit vector towards the camera, so d > 0 and
/// s(X) = n . X + d is the height of X above the plane (metres, camera side positive).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace wul3d {

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
    bool low_found = false;       ///< a board or tray lies on the support (its points removed)
    Plane low_support;            ///< its top's plane, valid when low_found
    std::size_t kept = 0;         ///< pixels of class kPlaneObject or kPlaneFoot
};

}  // namespace wul3d
