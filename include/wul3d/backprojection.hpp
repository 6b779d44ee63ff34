#pragma once
/// @file backprojection.hpp
/// Step 3 of the paper: every pixel with valid depth becomes a 3D point (metres) with its
/// colour (0-255, the authors' units: see ALGORITHM.md step 6).
#include <cstddef>

#include "wul3d/cloud.hpp"
#include "wul3d/frame.hpp"

namespace wul3d {

/// x = (u - cx) z / fx, y = (v - cy) z / fy, z = depth * scale (pinhole back-projection,
/// equal to the paper's eq. 12-14 for the FOV camera's pinhole equivalent).
/// Returns the number of valid points. Throws InputError if the colour size differs from
/// the depth size.
std::size_t back_project(const RgbdView& frame, OrganizedCloud& cloud);
inline std::size_t back_project(const RgbdFrame& frame, OrganizedCloud& cloud) {
    return back_project(frame.view(), cloud);
}

}  // namespace wul3d
