#pragma once
/// @file pipeline.hpp
/// The whole per-frame pipeline of the paper, stages in order:
/// registration -> back-projection -> normals -> background -> clustering -> colours, then
/// the object stages: support plane -> segmentation -> objects (tracks and their weights).
/// Holds the stages' buffers (no allocation after the first frame) and the two objects that
/// live across frames, ClusterState and ObjectTracker, out of sight (pipeline.cpp).
#include <cstdint>
#include <memory>
#include <vector>

#include "wul3d/background.hpp"
#include "wul3d/backprojection.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/decimation.hpp"
#include "wul3d/frame_result.hpp"
#include "wul3d/image_view.hpp"
#include "wul3d/normals.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/plane.hpp"
#include "wul3d/registration.hpp"
#include "wul3d/segmentation.hpp"
#include "wul3d/visualization.hpp"

namespace wul3d {

struct PipelineParams {
    NormalParams normals;
    DepthRange range;
    ClusterParams cluster;
    /// false: stop after the paper's steps (eq. 9 colours): no support plane, segments or
    /// tracks, and none of their buffers (`wul3d bench --pipeline paper`).
    bool detect_objects = true;
    bool remove_plane = true;  ///< false: --no-plane, the paper's background (depth range only)
    /// false: eq. 9's display colours are not made. FrameResult::colors stays empty (0 x 0)
    /// and times.colors 0; nothing else reads them. For a caller that neither shows nor
    /// writes them: `wul3d run` without colors.png, cloud.ply or --video, the Python module's
    /// process(outputs=...) without 'colors'. It saves their pass over the clusters' weights
    /// and, with decimation, their share of the way back.
    bool render_colors = true;
    PlaneParams plane;
    SegmentParams segmentation;
    ObjectParams objects;
    /// 1: every pixel. N in [2, 8]: the stages run on the frame decimated N x N
    /// (decimation.hpp) and the per-pixel results come back at the input's size. The
    /// parameters above stay in the input's pixels; stage_params() scales them. The default
    /// 2: a quarter of the pixels to work on, and the same score on OSD but for its most
    /// cluttered frames (docs/SPEED.md, "Decimation", measures both).
    int decimation = 2;

    /// The paper's setting: ClusterParams::paper(), depth range 0.5-4.5 m (Kinect v2), every
    /// pixel.
    static PipelineParams paper();
    void validate() const;
    /// The parameters the stages run with: with decimation N, the pixel counts of objects
    /// (min_points of segments and tracks, containers.gap_max_px) divided by N^2 and the
    /// plane's hull margin and the merge and rim boundary lengths by N (rounded; 0 stays off). The
    /// neighbourhood sizes and the plane's grid step stay as given, in decimated pixels
    /// (pipeline.cpp says why).
    PipelineParams stage_params() const;
};

class Pipeline {
public:
    explicit Pipeline(const PipelineParams& params);  ///< validates params
    ~Pipeline();
    Pipeline(Pipeline&&) noexcept;
    Pipeline& operator=(Pipeline&&) noexcept;

    /// Runs every stage on a registered frame. Throws Stopped when a stop is requested
    /// (stop.hpp) during the frame; the Pipeline is then not to be used again.
    const FrameResult& process(const RgbdFrame& frame);
    /// The same on the caller's memory (image_view.hpp): read in place when its layout is the
    /// stages' own (packed rows, RGB, 16-bit depth), else converted once into the pipeline's
    /// buffers. The result is the one process(RgbdFrame) gives for the same pixels. Throws
    /// InputError for a view that cannot be read (null data, a stride shorter than a row,
    /// colour of another size, invalid intrinsics or depth scale).
    const FrameResult& process(const FrameView& frame);
    /// Registers a raw two-camera frame first (timed as "registration").
    const FrameResult& process(const RawRgbdFrame& raw, const StereoCalibration& calib,
                               RegistrationMode mode);

    /// The last result's images handed over without a copy (the Python module's results): its
    /// labels, colours and objects are swapped with `labels`, `rgb` and `objects`, vectors of
    /// any size and contents, which the next frame sizes and writes again, every pixel. With
    /// decimation > 1 only, where these images are made for the caller alone (the way back
    /// from decimation writes each pixel of each); at decimation 1 the stages' own work is in
    /// them, nothing is swapped and this returns false. The result keeps its sizes.
    bool swap_images(std::vector<std::uint16_t>& labels, std::vector<std::uint8_t>& rgb,
                     std::vector<std::uint16_t>& objects);

    /// params().render_colors, from the next frame on (nothing else changes).
    void set_render_colors(bool on);

    const PipelineParams& params() const;
    /// The cloud, normals and clusters the stages ran on: the decimated frame's with
    /// decimation > 1 (its pixels are not FrameResult's then).
    const OrganizedCloud& cloud() const;
    const NormalMap& normals() const;
    const ClusterState& state() const;
    const ObjectTracker& tracker() const;
    const RgbdFrame& registered() const;  ///< last raw frame, registered

private:
    struct Impl;  ///< the stages' state and buffers (pipeline.cpp)
    std::unique_ptr<Impl> impl_;
};

}  // namespace wul3d
