#pragma once
/// @file backprojection.hpp
/// Step 3 of the paper: every pixel with valid depth becomes a 3D point (metres) with its
/// colour (0-255, the authors' units: see ALGORITHM.md step 6).
#include <cstdint>
#include <vector>

#include "wul3d/frame.hpp"

namespace wul3d {

/// An organized point cloud: one entry per pixel p = v * width + u, structure of arrays.
/// Invalid pixels (depth 0) have valid[p] = 0 and x = y = z = 0.
struct OrganizedCloud {
    int width = 0;
    int height = 0;
    bool has_color = false;      ///< false for depth-only frames: r, g, b are all 0
    std::vector<float> x, y, z;         ///< metres, camera frame (x right, y down, z forward)
    std::vector<std::uint8_t> r, g, b;  ///< the frame's 8-bit colour (memory: 3 bytes, not 12)
    std::vector<std::uint8_t> valid;

    std::size_t size() const { return valid.size(); }
    /// Sizes every array to w * h; allocates only when the size changes.
    void resize(int w, int h);
};

/// x = (u - cx) z / fx, y = (v - cy) z / fy, z = depth * scale (pinhole back-projection,
/// equal to the paper's eq. 12-14 for the FOV camera's pinhole equivalent).
/// Returns the number of valid points. Throws InputError if the colour size differs from
/// the depth size.
std::size_t back_project(const RgbdFrame& frame, OrganizedCloud& cloud);

}  // namespace wul3d
