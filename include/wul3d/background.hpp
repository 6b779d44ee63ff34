#pragma once
/// @file background.hpp
/// Step 5 of the paper: keep the points whose depth lies in [zmin, zmax] metres.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "wul3d/cloud.hpp"
#include "wul3d/depth_range.hpp"

namespace wul3d {

/// active[p] = 1 where the point is valid and zmin <= z <= zmax, else 0. Returns the count.
std::size_t select_depth_range(const DepthRange& range, const OrganizedCloud& cloud,
                               std::vector<std::uint8_t>& active);

}  // namespace wul3d
