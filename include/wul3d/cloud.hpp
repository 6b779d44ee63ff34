#pragma once
/// @file cloud.hpp
/// The per-pixel 3D types the stages pass on: the organized point cloud (back-projection,
/// backprojection.hpp) and its normals (normals.hpp). Structure of arrays, pixel
/// p = v * width + u.
#include <cstddef>
#include <cstdint>
#include <vector>

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

/// Unit normals, structure of arrays, one per pixel; valid = 0 where none could be computed,
/// and then n = (0, 0, 0) (smooth_normals relies on it).
struct NormalMap {
    int width = 0;
    int height = 0;
    std::vector<float> nx, ny, nz;
    std::vector<std::uint8_t> valid;

    void resize(int w, int h);  ///< allocates only when the size changes
};

}  // namespace wul3d
