#pragma once
/// @file frame_result.hpp
/// What the pipeline gives for one frame (FrameResult) and the time of each of its stages,
/// a type of its own: the pipeline (pipeline.hpp) makes it, the way back from decimation
/// (decimation.hpp) fills it at the input's size, the outputs read it.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "wul3d/clustering.hpp"
#include "wul3d/image.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/support_plane.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d {

/// Milliseconds spent in each stage on one frame (0 for a stage that did not run). On two
/// threads the clustering (with its colours) and the plane and segmentation stages may run
/// side by side (src/stages/side_by_side.hpp): each is timed as it ran, and `overlap` is the time
/// they shared.
struct StageTimes {
    double registration = 0, decimation = 0, backprojection = 0, normals = 0, background = 0,
           clustering = 0, colors = 0, plane = 0, segmentation = 0, objects = 0;
    double overlap = 0;  ///< counted in two stages above: total() takes it off once
    bool side_by_side = false;  ///< the two ran side by side on this frame (`overlap` is then
                                ///< their shared time, 0 where the system ran them in turn)
    /// The frame's time.
    double total() const {
        return registration + decimation + backprojection + normals + background + clustering +
               colors + plane + segmentation + objects - overlap;
    }
};

/// Everything one frame produced, at the input frame's size (also with decimation). Valid
/// until the next process() call.
struct FrameResult {
    LabelImage labels;                  ///< 0 = no point, 1..k
    ColorImage colors;                  ///< eq. (9) display colours over the scene
    std::vector<std::uint8_t> active;   ///< points in the depth range
    std::size_t active_points = 0;
    FrameStats stats;
    /// The depth's noise measured on this frame (measure_depth_noise, normals.hpp) and the
    /// normal radius it chose (normal_radius_for), both in the pixels the stages ran on (the
    /// decimated ones with PipelineParams::decimation > 1).
    float depth_noise_px = 0.0f;
    int normal_radius_px = 0;
    PlaneResult plane;                         ///< the support found (plane.found)
    std::vector<std::uint8_t> plane_classes;   ///< PlaneClass per pixel
    LabelImage segments;                       ///< this frame's segments, 0 = background
    SegmentStats segment_stats;
    LabelImage objects;                        ///< 0 = background, else track id (objects.png)
                                               ///< (the four above empty without detect_objects)
    std::vector<DetectedObject> object_list;   ///< one per object in `objects`
    StageTimes times;
};

}  // namespace wul3d
