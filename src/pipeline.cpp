#include "wul3d/pipeline.hpp"

#include <chrono>

#include "wul3d/error.hpp"

namespace wul3d {

PipelineParams PipelineParams::paper() {
    PipelineParams p;
    p.cluster = ClusterParams::paper();
    p.range.zmin_m = 0.5f;  // Kinect v2's working range (paper, section II.A)
    p.range.zmax_m = 4.5f;
    return p;
}

void PipelineParams::validate() const {
    normals.validate();
    range.validate();
    cluster.validate();
    plane.validate();
    segmentation.validate();
    objects.validate();
}

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace

Pipeline::Pipeline(const PipelineParams& params)
    : params_((params.validate(), params)), state_(params.cluster), tracker_(params.objects) {}

const FrameResult& Pipeline::process(const RgbdFrame& frame) { return run_stages(frame, 0.0); }

const FrameResult& Pipeline::process(const RawRgbdFrame& raw, const StereoCalibration& calib,
                                     RegistrationMode mode) {
    const auto t0 = Clock::now();
    if (mode == RegistrationMode::DepthToColor)
        register_depth_to_color(calib, raw, registration_ws_, registered_);
    else
        register_color_to_depth(calib, raw, registration_ws_, registered_);
    return run_stages(registered_, ms_since(t0));
}

const FrameResult& Pipeline::run_stages(const RgbdFrame& frame, double registration_ms) {
    FrameResult& r = result_;
    r.times = StageTimes{};
    r.times.registration = registration_ms;
    if (frame.width() <= 0 || frame.height() <= 0 || frame.depth.empty())
        throw InputError(frame.name + ": empty depth image");

    auto t = Clock::now();
    const std::size_t valid = back_project(frame, cloud_);
    r.times.backprojection = ms_since(t);
    if (valid == 0) throw InputError(frame.name + ": depth has no valid pixel (all zero)");

    t = Clock::now();
    estimate_normals(params_.normals, cloud_, normals_);
    r.times.normals = ms_since(t);

    t = Clock::now();
    r.active_points = select_depth_range(params_.range, cloud_, r.active);
    r.times.background = ms_since(t);

    t = Clock::now();
    r.stats = state_.step(cloud_, normals_, r.active, r.labels);
    r.times.clustering = ms_since(t);

    t = Clock::now();
    render_weight_colors(state_, r.labels, frame, r.colors);
    r.times.colors = ms_since(t);
    if (!params_.detect_objects) {
        r.plane = PlaneResult{};
        r.plane_classes.clear();
        r.segments = LabelImage{};
        r.segment_stats = SegmentStats{};
        r.objects = LabelImage{};
        r.object_list.clear();
        return r;
    }

    // Objects: the support plane goes (part of the paper's background step, done after the
    // clustering so that labels.png keeps the paper's clusters), the rest is segmented and
    // tracked.
    t = Clock::now();
    if (params_.remove_plane) {
        r.plane = remove_support_plane(params_.plane, frame.intrinsics, cloud_, normals_,
                                       r.active, plane_ws_, r.plane_classes);
    } else {
        r.plane = PlaneResult{};
        r.plane_classes.resize(r.active.size());
        for (std::size_t p = 0; p < r.active.size(); ++p)
            r.plane_classes[p] = r.active[p] ? kPlaneObject : kPlaneRemoved;
        r.plane.kept = r.active_points;
    }
    r.times.plane = ms_since(t);

    t = Clock::now();
    r.segment_stats = segment_objects(params_.segmentation, cloud_, normals_, r.plane_classes,
                                      r.plane.found ? &r.plane.support : nullptr, r.labels,
                                      segment_ws_, r.segments);
    r.times.segmentation = ms_since(t);

    t = Clock::now();
    tracker_.step(cloud_, r.segments, r.segment_stats.segments, r.labels, r.objects,
                  r.object_list);
    r.times.objects = ms_since(t);
    return r;
}

}  // namespace wul3d
