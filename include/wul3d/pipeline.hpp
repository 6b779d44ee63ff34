#pragma once
/// @file pipeline.hpp
/// The whole per-frame pipeline of the paper, stages in order:
/// registration -> back-projection -> normals -> background -> clustering -> colours, then
/// the object stages: support plane -> segmentation -> objects (tracks and their weights).
/// Holds the stages' buffers (no allocation after the first frame) and the two objects that
/// live across frames, ClusterState and ObjectTracker.
#include <algorithm>
#include <vector>

#include "wul3d/background.hpp"
#include "wul3d/backprojection.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/decimation.hpp"
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
    PlaneParams plane;
    SegmentParams segmentation;
    ObjectParams objects;
    /// 1: every pixel. N in [2, 8]: the stages run on the frame decimated N x N
    /// (decimation.hpp) and the per-pixel results come back at the input's size. The
    /// parameters above stay in the input's pixels; stage_params() scales them. The default
    /// 2 is 2.2-2.8 times as fast as every pixel at 640x480 and scores as well on OSD but
    /// for its most cluttered frames (README, "Decimation").
    int decimation = 2;

    /// The paper's setting: ClusterParams::paper(), depth range 0.5-4.5 m (Kinect v2), every
    /// pixel.
    static PipelineParams paper();
    void validate() const;
    /// The parameters the stages run with: with decimation N, the pixel counts of objects
    /// (min_points of segments and tracks, gap_max_px) divided by N^2 and the plane's hull
    /// margin and the merge and rim boundary lengths by N (rounded; 0 stays off). The
    /// neighbourhood sizes and the plane's grid step stay as given, in decimated pixels
    /// (pipeline.cpp says why).
    PipelineParams stage_params() const;
};

/// Milliseconds spent in each stage on one frame (0 for a stage that did not run). On two
/// threads the clustering (with its colours) and the plane and segmentation stages may run
/// side by side (detail::SideBySideChoice): each is timed as it ran, and `overlap` is the time
/// they shared.
struct StageTimes {
    double registration = 0, decimation = 0, backprojection = 0, normals = 0, background = 0,
           clustering = 0, colors = 0, plane = 0, segmentation = 0, objects = 0;
    double overlap = 0;  ///< counted in two stages above: total() takes it off once
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
    PlaneResult plane;                         ///< the support found (plane.found)
    std::vector<std::uint8_t> plane_classes;   ///< PlaneClass per pixel
    LabelImage segments;                       ///< this frame's segments, 0 = background
    SegmentStats segment_stats;
    LabelImage objects;                        ///< 0 = background, else track id (objects.png)
                                               ///< (the four above empty without detect_objects)
    std::vector<DetectedObject> object_list;   ///< one per object in `objects`
    StageTimes times;
};

namespace detail {
/// Whether Pipeline::run_on's two parts (the clustering with its colours; the plane and
/// segmentation stages) run side by side on two threads: each period of frames starts with
/// a few frames each way, timed, and goes on the faster way. It pays on new scenes at
/// --decimate 2, not when the clustering is cheap (a frame repeated) nor on 640x480 frames
/// (docs/DESIGN.md). Results are the same either way; only the time differs.
class SideBySideChoice {
public:
    static constexpr int kTrials = 3;    ///< frames each way per period (the fastest counts)
    static constexpr int kPeriod = 300;  ///< frames per choice

    bool next() const;  ///< the way for the coming frame: true = side by side
    void record(bool side_by_side, double ms);  ///< the coming frame's time for the two parts

private:
    int frame_ = 0;
    double best_ms_[2] = {0, 0};  ///< [0] one after the other, [1] side by side
    bool side_by_side_ = false;
};
}  // namespace detail

class Pipeline {
public:
    explicit Pipeline(const PipelineParams& params);  ///< validates params

    /// Runs every stage on a registered frame. Throws Stopped when a stop is requested
    /// (stop.hpp) during the frame; the Pipeline is then not to be used again.
    const FrameResult& process(const RgbdFrame& frame);
    /// Registers a raw two-camera frame first (timed as "registration").
    const FrameResult& process(const RawRgbdFrame& raw, const StereoCalibration& calib,
                               RegistrationMode mode);

    const PipelineParams& params() const { return params_; }
    /// The cloud, normals and clusters the stages ran on: the decimated frame's with
    /// decimation > 1 (its pixels are not FrameResult's then).
    const OrganizedCloud& cloud() const { return cloud_; }
    const NormalMap& normals() const { return normals_; }
    const ClusterState& state() const { return state_; }
    const ObjectTracker& tracker() const { return tracker_; }
    const RgbdFrame& registered() const { return registered_; }  ///< last raw frame, registered

private:
    const FrameResult& run_stages(const RgbdFrame& frame, double registration_ms);
    /// Every stage from back-projection on, with stage_params_, into `r`.
    void run_on(const RgbdFrame& frame, FrameResult& r);
    /// run_on's two independent parts: the paper's clusters and colours; the support plane
    /// and the segments (which read no cluster label but with the kmeans segmenter).
    void cluster_and_colour(const RgbdFrame& frame, FrameResult& r);
    void plane_and_segments(const RgbdFrame& frame, FrameResult& r);
    /// `decimated_result_` carried back to `frame`'s pixels, into result_.
    void expand_result(const RgbdFrame& frame);

    detail::SideBySideChoice side_by_side_;  ///< whether run_on's two parts run side by side

    PipelineParams params_;
    PipelineParams stage_params_;  ///< params_.stage_params()
    OrganizedCloud cloud_;
    NormalMap normals_;
    ClusterState state_;
    ObjectTracker tracker_;
    PlaneWorkspace plane_ws_;
    SegmentWorkspace segment_ws_;
    RegistrationWorkspace registration_ws_;
    RgbdFrame registered_;
    RgbdFrame decimated_;
    FrameResult decimated_result_;
    // expand_result's scratch: track id -> object_list index, and per row band the active
    // pixels and each object's pixels and box.
    struct PixelBox {
        int u_min, v_min, u_max, v_max;
        std::size_t pixels;
        void add(int u, int v) {
            ++pixels;
            u_min = std::min(u_min, u);
            v_min = std::min(v_min, v);
            u_max = std::max(u_max, u);
            v_max = std::max(v_max, v);
        }
        void merge(const PixelBox& b) {
            pixels += b.pixels;
            u_min = std::min(u_min, b.u_min);
            v_min = std::min(v_min, b.v_min);
            u_max = std::max(u_max, b.u_max);
            v_max = std::max(v_max, b.v_max);
        }
    };
    static constexpr int kExpandBands = 16;
    std::vector<int> object_index_;
    std::vector<std::size_t> band_active_;
    std::vector<PixelBox> band_boxes_;
    std::vector<std::uint8_t> edge_blocks_;  ///< decimated pixels at an object's outline
    std::vector<std::uint16_t> edge_lo_, edge_hi_;  ///< their 3-wide row minima and maxima
    std::vector<std::int32_t> block_source_;  ///< each edge block's source after the colour vote
    FrameResult result_;
};

}  // namespace wul3d
