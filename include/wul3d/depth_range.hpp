#pragma once
/// @file depth_range.hpp
/// The depth range of step 5 of the paper (background.hpp selects by it), a type of its own:
/// decimation, the stages after it and the pipeline's parameters share it.
namespace wul3d {

struct DepthRange {
    float zmin_m = 0.2f;  ///< metres; >= 0
    float zmax_m = 4.5f;  ///< metres; > zmin_m (Kinect v2 reaches about 4.5 m)

    void validate() const;  ///< throws ParamError (background.cpp)
    /// Whether depth z (metres, float as back-projected) is kept; every stage that asks, asks
    /// this.
    bool contains(float z) const { return z >= zmin_m && z <= zmax_m; }
};

}  // namespace wul3d
