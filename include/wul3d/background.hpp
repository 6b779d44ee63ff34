#pragma once
/// @file background.hpp
/// Step 5 of the paper: keep the points whose depth lies in [zmin, zmax] metres.
#include <cstdint>
#include <vector>

#include "wul3d/backprojection.hpp"

namespace wul3d {

struct DepthRange {
    float zmin_m = 0.2f;  ///< metres; >= 0
    float zmax_m = 4.5f;  ///< metres; > zmin_m (Kinect v2 reaches about 4.5 m)

    void validate() const;  ///< throws ParamError
    /// Whether depth z (metres, float as back-projected) is kept; every stage that asks, asks
    /// this.
    bool contains(float z) const { return z >= zmin_m && z <= zmax_m; }
};

/// active[p] = 1 where the point is valid and zmin <= z <= zmax, else 0. Returns the count.
std::size_t select_depth_range(const DepthRange& range, const OrganizedCloud& cloud,
                               std::vector<std::uint8_t>& active);

}  // namespace wul3d
