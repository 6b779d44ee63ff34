#include "wul3d/pipeline.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <exception>
#include <iterator>
#include <utility>

#include "param_check.hpp"
#include "side_by_side.hpp"
#include "weight_colours.hpp"
#include "wul3d/error.hpp"
#include "wul3d/stop.hpp"

namespace wul3d {

PipelineParams PipelineParams::paper() {
    PipelineParams p;
    p.cluster = ClusterParams::paper();
    p.range.zmin_m = 0.5f;  // Kinect v2's working range (paper, section II.A)
    p.range.zmax_m = 4.5f;
    p.decimation = 1;  // every point, as the paper clusters them
    p.normals.max_tilt_noise_deg = 0.0f;  // the paper's fixed neighbourhood
    return p;
}

void PipelineParams::validate() const {
    detail::require_param(decimation >= 1 && decimation <= 8, "", "decimate", decimation,
                          "in [1, 8]");
    normals.validate();
    range.validate();
    cluster.validate();
    plane.validate();
    segmentation.validate();
    objects.validate();
}

PipelineParams PipelineParams::stage_params() const {
    PipelineParams s = *this;
    const int n = decimation;
    if (n <= 1) return s;
    // What counts an object's pixels or spans the scene scales, so that --min-points 300 is
    // the same object at every N; 0 keeps meaning "off". The neighbourhoods (normal radius,
    // crease step and smoothing, re-attachment, depth jumps), the seeds' size and the plane's
    // grid step stay in the decimated pixels: scaling the neighbourhoods lost Boundary F on
    // osd_mosd's learn frames (docs/DESIGN.md, "Decimation"); a grid that kept its points scored
    // about the same as one with N^2 fewer (docs/DESIGN.md) and cost time at N = 2.
    auto length = [n](int px, int at_least) { return px == 0 ? 0 : std::max(at_least, (px + n / 2) / n); };
    auto area = [n](int px) { return px == 0 ? 0 : std::max(1, (px + n * n / 2) / (n * n)); };
    s.plane.hull_margin_px = length(plane.hull_margin_px, 0);
    SegmentParams& g = s.segmentation;
    g.min_points = area(segmentation.min_points);
    g.containers.gap_max_px = area(segmentation.containers.gap_max_px);
    g.merge.min_boundary = length(segmentation.merge.min_boundary, 1);
    g.containers.min_boundary = length(segmentation.containers.min_boundary, 3);
    s.objects.min_points = area(objects.min_points);
    return s;
}

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// What the way back from decimation needs of `p` (the input's parameters, not the stages'):
/// an input pixel takes a neighbouring block's results across a depth step no larger than
/// the segmentation's own connection rule over the block's width.
ExpandParams expand_params(const PipelineParams& p) {
    const float n = static_cast<float>(p.decimation);
    ExpandParams e;
    e.factor = p.decimation;
    e.same_m = n * p.segmentation.depth_jump_m;
    e.same_rel = n * p.segmentation.depth_jump_rel;
    e.range = p.range;
    e.objects = p.detect_objects;
    e.colors = p.render_colors;
    e.min_object_pixels = static_cast<std::size_t>(p.objects.min_points);
    return e;
}
}  // namespace

/// The pipeline's stages, their state across frames and their buffers.
struct Pipeline::Impl {
    explicit Impl(const PipelineParams& params)
        : params_((params.validate(), params)),
          stage_params_(params.stage_params()),
          state_(stage_params_.cluster),
          tracker_(stage_params_.objects) {}

    const FrameResult& run_stages(const RgbdView& frame, double registration_ms);
    /// Every stage from back-projection on, with stage_params_, into `r`.
    void run_on(const RgbdView& frame, FrameResult& r);
    /// run_on's two independent parts: the paper's clusters and colours; the support plane
    /// and the segments (which read no cluster label but with the kmeans segmenter).
    void cluster_and_colour(const RgbdView& frame, FrameResult& r);
    void plane_and_segments(const RgbdView& frame, FrameResult& r);
    /// cluster_and_colour's first step (eq. 4-8: r.labels), timed.
    void cluster(FrameResult& r);
    /// Its second (eq. 9: r.colors) as OpenMP tasks of a band of rows each, for a thread of
    /// a team: either thread may take them, at the latest at the region's end (libgomp runs
    /// them on the creating thread first; their order is not ours to set). Their times add
    /// up in colour_task_ms_.
    void colour_as_tasks(const RgbdView& frame, FrameResult& r);
    /// Eq. 9's palette and r.colors sized (timed into r.times.colors); or, without
    /// render_colors, r.colors emptied and false returned: no colours this frame.
    bool prepare_colours(const RgbdView& frame, FrameResult& r);
    /// The objects stage's first phase (ObjectTracker::observe), which needs only the cloud:
    /// beside the segmentation when the halves run side by side. Times it into
    /// r.times.objects.
    void observe_surfaces(FrameResult& r);

    detail::SideBySideChoice side_by_side_;  ///< whether run_on's two parts run side by side
    PipelineParams params_;
    PipelineParams stage_params_;  ///< params_.stage_params()
    OrganizedCloud cloud_;
    NormalMap normals_;
    std::vector<float> noise_scratch_;  ///< measure_depth_noise's samples
    ClusterState state_;
    detail::WeightColours colours_;  ///< eq. 9's colours, a band of rows at a time
    static constexpr int kColourTasks = 8;
    double colour_task_ms_[kColourTasks] = {};
    ObjectTracker tracker_;
    PlaneWorkspace plane_ws_;
    SegmentWorkspace segment_ws_;
    RegistrationWorkspace registration_ws_;
    RgbdFrame registered_;
    RgbdFrame staging_;  ///< a caller's FrameView in the stages' layout, when it is not already
    RgbdFrame decimated_;
    FrameResult decimated_result_;
    ExpandWorkspace expand_ws_;
    FrameResult result_;
};

Pipeline::Pipeline(const PipelineParams& params) : impl_(std::make_unique<Impl>(params)) {}
Pipeline::~Pipeline() = default;
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;

bool Pipeline::swap_images(std::vector<std::uint16_t>& labels, std::vector<std::uint8_t>& rgb,
                           std::vector<std::uint16_t>& objects) {
    if (impl_->params_.decimation <= 1) return false;
    FrameResult& r = impl_->result_;
    r.labels.labels.swap(labels);
    r.colors.rgb.swap(rgb);
    r.objects.labels.swap(objects);
    return true;
}

void Pipeline::set_render_colors(bool on) {
    impl_->params_.render_colors = on;
    impl_->stage_params_.render_colors = on;
}

const PipelineParams& Pipeline::params() const { return impl_->params_; }
const OrganizedCloud& Pipeline::cloud() const { return impl_->cloud_; }
const NormalMap& Pipeline::normals() const { return impl_->normals_; }
const ClusterState& Pipeline::state() const { return impl_->state_; }
const ObjectTracker& Pipeline::tracker() const { return impl_->tracker_; }
const RgbdFrame& Pipeline::registered() const { return impl_->registered_; }

const FrameResult& Pipeline::process(const RgbdFrame& frame) {
    return impl_->run_stages(frame.view(), 0.0);
}

const FrameResult& Pipeline::process(const FrameView& frame) {
    return impl_->run_stages(stage_view(frame, impl_->staging_), 0.0);
}

const FrameResult& Pipeline::process(const RawRgbdFrame& raw, const StereoCalibration& calib,
                                     RegistrationMode mode) {
    Impl& m = *impl_;
    const auto t0 = Clock::now();
    if (mode == RegistrationMode::DepthToColor)
        register_depth_to_color(calib, raw, m.registration_ws_, m.registered_);
    else
        register_color_to_depth(calib, raw, m.registration_ws_, m.registered_);
    return m.run_stages(m.registered_.view(), ms_since(t0));
}

const FrameResult& Pipeline::Impl::run_stages(const RgbdView& frame, double registration_ms) {
    if (frame.width <= 0 || frame.height <= 0 || frame.depth == nullptr)
        throw InputError(std::string(frame.name) + ": empty depth image");
    // Readers check the intrinsics they read; this also covers cameras and callers' frames.
    frame.intrinsics.validate(std::string(frame.name));
    throw_if_stop_requested("the frame's start");
    const int n = params_.decimation;
    if (n == 1) {
        run_on(frame, result_);
    } else {
        auto t = Clock::now();
        decimate_frame(frame, n, decimated_, &params_.range);
        double ms = ms_since(t);
        run_on(decimated_.view(), decimated_result_);
        t = Clock::now();
        expand_result(expand_params(params_), frame, decimated_, decimated_result_, expand_ws_, result_);
        ms += ms_since(t);
        result_.times = decimated_result_.times;
        result_.times.decimation = ms;
    }
    result_.times.registration = registration_ms;
    return result_;
}

void Pipeline::Impl::run_on(const RgbdView& frame, FrameResult& r) {
    const PipelineParams& params = stage_params_;
    r.times = StageTimes{};
    auto t = Clock::now();
    const std::size_t valid = back_project(frame, cloud_);
    r.times.backprojection = ms_since(t);
    if (valid == 0)
        throw InputError(std::string(frame.name) + ": depth has no valid pixel (all zero)");
    throw_if_stop_requested("the back-projection");

    t = Clock::now();
    // The neighbourhood the camera's noise needs (normals.hpp), measured on this frame.
    r.depth_noise_px =
        measure_depth_noise(cloud_, static_cast<float>(frame.intrinsics.fx), noise_scratch_);
    r.normal_radius_px = normal_radius_for(params.normals, r.depth_noise_px);
    NormalParams normal_params = params.normals;
    normal_params.radius_px = r.normal_radius_px;
    estimate_normals(normal_params, cloud_, normals_);
    r.times.normals = ms_since(t);
    throw_if_stop_requested("the normals");

    t = Clock::now();
    r.active_points = select_depth_range(params.range, cloud_, r.active);
    r.times.background = ms_since(t);

    if (!params.detect_objects) {
        cluster_and_colour(frame, r);
        r.plane = PlaneResult{};
        r.plane_classes.clear();
        r.segments = LabelImage{};
        r.segment_stats = SegmentStats{};
        r.objects = LabelImage{};
        r.object_list.clear();
        return;
    }
    // On two threads the plane and segmentation stages leave one idle for half their time
    // (their flood fills are serial), so they may run beside the clustering, each on one
    // thread (nested loops run on the thread that meets them). The clustering's half is the
    // shorter: its thread then observes the surfaces for the objects stage, hands eq. 9's
    // colours out as tasks, and waits at the region's end, where it takes those and the
    // segmentation's tasks (the colour cue's segments, the passes after it). Whether that
    // pays depends on the frame (SideBySideChoice). With more threads every stage's loops
    // use them all: the stages run one after the other.
    const bool may_overlap = params.segmentation.segmenter != Segmenter::Kmeans &&
                             omp_get_max_threads() == 2 && !omp_in_parallel();
    const bool side_by_side = may_overlap && side_by_side_.next();
    t = Clock::now();
    if (side_by_side) {
        std::exception_ptr failed[2];  // an exception may not leave an OpenMP region
        auto run_half = [&](int half, auto&& part) {
            try {
                part();
            } catch (...) {
                failed[half] = std::current_exception();
            }
        };
#pragma omp parallel num_threads(2)
        {
            // Thread 1 clusters, thread 0 does the rest (both, in a team of one).
            const int me = omp_get_thread_num();
            if (me == 1 || omp_get_num_threads() == 1) run_half(0, [&] {
                cluster(r);
                observe_surfaces(r);
                colour_as_tasks(frame, r);
            });
            if (me == 0) run_half(1, [&] { plane_and_segments(frame, r); });
        }
        for (const auto& e : failed)
            if (e) std::rethrow_exception(e);
        for (const double ms : colour_task_ms_) r.times.colors += ms;
    } else {
        cluster_and_colour(frame, r);
        plane_and_segments(frame, r);
        observe_surfaces(r);  // timed with the halves either way, for SideBySideChoice
    }
    const double both_ms = ms_since(t);
    throw_if_stop_requested("the segmentation");
    if (may_overlap) side_by_side_.record(side_by_side, both_ms);
    r.times.side_by_side = side_by_side;
    if (side_by_side)
        r.times.overlap = std::max(0.0, r.times.clustering + r.times.colors + r.times.plane +
                                            r.times.segmentation + r.times.objects - both_ms);

    t = Clock::now();
    tracker_.step(cloud_, r.segments, r.segment_stats.segments, r.labels, r.objects,
                  r.object_list);
    r.times.objects += ms_since(t);
}

bool detail::SideBySideChoice::next() const {
    const int i = frame_ % kPeriod;
    return i < 2 * kTrials ? i % 2 == 0 : side_by_side_;
}

void detail::SideBySideChoice::record(bool side_by_side, double ms) {
    const int i = frame_++ % kPeriod;
    if (i >= 2 * kTrials) return;
    // The fastest frame of each way: the first frame of a sequence (k-means++ seeding) and a
    // frame another process slowed down do not decide.
    double& best = best_ms_[side_by_side ? 1 : 0];
    best = i < 2 ? ms : std::min(best, ms);
    if (i == 2 * kTrials - 1) side_by_side_ = best_ms_[1] < best_ms_[0];
}

void Pipeline::Impl::observe_surfaces(FrameResult& r) {
    const auto t = Clock::now();
    tracker_.observe(cloud_);
    r.times.objects = ms_since(t);
}

void Pipeline::Impl::cluster(FrameResult& r) {
    const auto t = Clock::now();
    r.stats = state_.step(cloud_, normals_, r.active, r.labels);
    r.times.clustering = ms_since(t);
}

void Pipeline::Impl::cluster_and_colour(const RgbdView& frame, FrameResult& r) {
    cluster(r);
    if (!prepare_colours(frame, r)) return;
    const auto t = Clock::now();
    colours_.all_rows();
    r.times.colors += ms_since(t);
}

bool Pipeline::Impl::prepare_colours(const RgbdView& frame, FrameResult& r) {
    if (!stage_params_.render_colors) {
        r.colors.width = r.colors.height = 0;
        r.colors.rgb.clear();  // keeps its memory for a frame that wants them again
        return false;
    }
    const auto t = Clock::now();
    colours_.prepare(state_, r.labels, frame, r.colors);
    r.times.colors = ms_since(t);
    return true;
}

void Pipeline::Impl::colour_as_tasks(const RgbdView& frame, FrameResult& r) {
    std::fill(std::begin(colour_task_ms_), std::end(colour_task_ms_), 0.0);
    if (!prepare_colours(frame, r)) return;
    const int H = colours_.height();
    for (int task = 0; task < kColourTasks; ++task) {
#pragma omp task firstprivate(task)
        {
            const auto t0 = Clock::now();
            colours_.rows(H * task / kColourTasks, H * (task + 1) / kColourTasks);
            colour_task_ms_[task] = ms_since(t0);
        }
    }
}

namespace {

/// How much wider the support plane's grow angle and band are for a frame whose depth noise
/// is `noise_px` (measure_depth_noise; remove_support_plane's noise_widening): 1 up to the
/// noise that tilts normals of the least radius by max_tilt_noise_deg, then in proportion to
/// the noise, at most 1.5. From that noise, not from the one where normal_radius_for rounds
/// up to radius_px + 1 (a quarter more): between the two the normals keep the least radius
/// and tilt past their angle, and generated piles lost their table there (docs/ABLATION.md).
/// The noise is the frame's typical one, and a camera noisier than that tilts the normals of
/// a far table past the given angle and scatters its points past the given band (active
/// stereo, whose noise grows with z^2 from a larger base: in 1 of the 20 tabletop tune frames
/// the table was no candidate at all). O(1).
float plane_noise_widening(const NormalParams& normals, float noise_px) {
    if (!(normals.max_tilt_noise_deg > 0)) return 1.0f;
    const float least_radius_noise = static_cast<float>(normals.radius_px) * std::sqrt(2.0f) *
                                     std::tan(normals.max_tilt_noise_deg * std::numbers::pi_v<float> / 180.0f);
    return std::clamp(noise_px / least_radius_noise, 1.0f, 1.5f);
}

/// How far apart the segmentation's crease tests compare normals (CutParams::crease_step_px)
/// for normals estimated `normal_radius_px` either side (normal_radius_for): the given step,
/// or the radius when wider, at most 16. Two normals closer than the radius share most of
/// their neighbourhoods, and a crease between them fades: a noisy camera's wide normals (an
/// active-stereo one far away, radius 6-10) ran a pile's objects into one. O(1).
int crease_step_for(const CutParams& cuts, int normal_radius_px) {
    return std::max(cuts.crease_step_px, std::min(normal_radius_px, 16));
}

}  // namespace

void Pipeline::Impl::plane_and_segments(const RgbdView& frame, FrameResult& r) {
    const PipelineParams& params = stage_params_;
    // Objects: the support plane goes (part of the paper's background step, kept out of the
    // clustering's mask so that labels.png keeps the paper's clusters), the rest is segmented.
    auto t = Clock::now();
    if (params.remove_plane) {
        r.plane = remove_support_plane(params.plane, frame.intrinsics, cloud_, normals_, r.active, plane_ws_,
                                       r.plane_classes, plane_noise_widening(params.normals, r.depth_noise_px));
    } else {
        r.plane = PlaneResult{};
        r.plane_classes.resize(r.active.size());
        for (std::size_t p = 0; p < r.active.size(); ++p)
            r.plane_classes[p] = r.active[p] ? kPlaneObject : kPlaneRemoved;
        r.plane.kept = r.active_points;
    }
    r.times.plane = ms_since(t);
    throw_if_stop_requested("the plane removal");

    t = Clock::now();
    SegmentParams segmentation = params.segmentation;
    segmentation.cuts.crease_step_px = crease_step_for(params.segmentation.cuts, r.normal_radius_px);
    r.segment_stats = segment_objects(segmentation, cloud_, normals_, r.plane_classes,
                                      r.plane.found ? &r.plane.support : nullptr,
                                      r.plane.found && r.plane.low_found ? &r.plane.low_support : nullptr, r.labels,
                                      segment_ws_, r.segments,
                                      r.depth_noise_px / static_cast<float>(frame.intrinsics.fx));
    r.times.segmentation = ms_since(t);
}

}  // namespace wul3d
