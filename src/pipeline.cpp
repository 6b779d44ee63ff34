#include "wul3d/pipeline.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <utility>

#include "param_check.hpp"
#include "wul3d/error.hpp"
#include "wul3d/stop.hpp"

namespace wul3d {

PipelineParams PipelineParams::paper() {
    PipelineParams p;
    p.cluster = ClusterParams::paper();
    p.range.zmin_m = 0.5f;  // Kinect v2's working range (paper, section II.A)
    p.range.zmax_m = 4.5f;
    p.decimation = 1;  // every point, as the paper clusters them
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
    // grid step stay in the decimated pixels: scaling the neighbourhoods cost up to 7 points
    // of Boundary F on osd_mosd's learn frames (README, "Decimation"); a grid that kept its
    // points scored about the same as one with N^2 fewer (docs/DESIGN.md) and cost 0.6-0.9 ms
    // more at N = 2.
    auto length = [n](int px, int at_least) { return px == 0 ? 0 : std::max(at_least, (px + n / 2) / n); };
    auto area = [n](int px) { return px == 0 ? 0 : std::max(1, (px + n * n / 2) / (n * n)); };
    s.plane.hull_margin_px = length(plane.hull_margin_px, 0);
    SegmentParams& g = s.segmentation;
    g.min_points = area(segmentation.min_points);
    g.gap_max_px = area(segmentation.gap_max_px);
    g.merge_min_boundary = length(segmentation.merge_min_boundary, 1);
    g.rim_min_boundary = length(segmentation.rim_min_boundary, 3);
    s.objects.min_points = area(objects.min_points);
    return s;
}

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace

Pipeline::Pipeline(const PipelineParams& params)
    : params_((params.validate(), params)),
      stage_params_(params.stage_params()),
      state_(stage_params_.cluster),
      tracker_(stage_params_.objects) {}

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
    if (frame.width() <= 0 || frame.height() <= 0 || frame.depth.empty())
        throw InputError(frame.name + ": empty depth image");
    // Readers check the intrinsics they read; this also covers cameras and callers' frames.
    frame.intrinsics.validate(frame.name);
    throw_if_stop_requested("the frame's start");
    const int n = params_.decimation;
    if (n == 1) {
        run_on(frame, result_);
    } else {
        auto t = Clock::now();
        decimate_frame(frame, n, decimated_, &params_.range);
        double ms = ms_since(t);
        run_on(decimated_, decimated_result_);
        t = Clock::now();
        expand_result(frame);
        ms += ms_since(t);
        result_.times = decimated_result_.times;
        result_.times.decimation = ms;
    }
    result_.times.registration = registration_ms;
    return result_;
}

void Pipeline::run_on(const RgbdFrame& frame, FrameResult& r) {
    const PipelineParams& params = stage_params_;
    r.times = StageTimes{};
    auto t = Clock::now();
    const std::size_t valid = back_project(frame, cloud_);
    r.times.backprojection = ms_since(t);
    if (valid == 0) throw InputError(frame.name + ": depth has no valid pixel (all zero)");
    throw_if_stop_requested("the back-projection");

    t = Clock::now();
    estimate_normals(params.normals, cloud_, normals_);
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
    // thread (nested loops run on the thread that meets them). Whether that pays depends on
    // the frame (SideBySideChoice). With more threads every stage's loops use them all: the
    // stages run one after the other.
    const bool may_overlap = params.segmentation.segmenter != Segmenter::Kmeans &&
                             omp_get_max_threads() == 2 && !omp_in_parallel();
    const bool side_by_side = may_overlap && side_by_side_.next();
    t = Clock::now();
    if (side_by_side) {
        std::exception_ptr failed[2];  // an exception may not leave an OpenMP section
#pragma omp parallel sections num_threads(2)
        {
#pragma omp section
            try {
                cluster_and_colour(frame, r);
            } catch (...) {
                failed[0] = std::current_exception();
            }
#pragma omp section
            try {
                plane_and_segments(frame, r);
            } catch (...) {
                failed[1] = std::current_exception();
            }
        }
        for (const auto& e : failed)
            if (e) std::rethrow_exception(e);
    } else {
        cluster_and_colour(frame, r);
        plane_and_segments(frame, r);
    }
    const double both_ms = ms_since(t);
    throw_if_stop_requested("the segmentation");
    if (may_overlap) side_by_side_.record(side_by_side, both_ms);
    if (side_by_side)
        r.times.overlap = std::max(0.0, r.times.clustering + r.times.colors + r.times.plane +
                                            r.times.segmentation - both_ms);

    t = Clock::now();
    tracker_.step(cloud_, r.segments, r.segment_stats.segments, r.labels, r.objects,
                  r.object_list);
    r.times.objects = ms_since(t);
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

void Pipeline::cluster_and_colour(const RgbdFrame& frame, FrameResult& r) {
    auto t = Clock::now();
    r.stats = state_.step(cloud_, normals_, r.active, r.labels);
    r.times.clustering = ms_since(t);
    t = Clock::now();
    render_weight_colors(state_, r.labels, frame, r.colors);
    r.times.colors = ms_since(t);
}

void Pipeline::plane_and_segments(const RgbdFrame& frame, FrameResult& r) {
    const PipelineParams& params = stage_params_;
    // Objects: the support plane goes (part of the paper's background step, kept out of the
    // clustering's mask so that labels.png keeps the paper's clusters), the rest is segmented.
    auto t = Clock::now();
    if (params.remove_plane) {
        r.plane = remove_support_plane(params.plane, frame.intrinsics, cloud_, normals_,
                                       r.active, plane_ws_, r.plane_classes);
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
    r.segment_stats = segment_objects(params.segmentation, cloud_, normals_, r.plane_classes,
                                      r.plane.found ? &r.plane.support : nullptr, r.labels,
                                      segment_ws_, r.segments);
    r.times.segmentation = ms_since(t);
}

void Pipeline::expand_result(const RgbdFrame& frame) {
    const FrameResult& s = decimated_result_;
    FrameResult& r = result_;
    const int W = frame.width(), H = frame.height();
    // An input pixel takes a neighbouring block's results across a depth step no larger
    // than the segmentation's own connection rule over the block's width.
    const float n = static_cast<float>(params_.decimation);
    DecimatedSource source(frame.depth, decimated_.depth, params_.decimation,
                           n * params_.segmentation.depth_jump_m,
                           n * params_.segmentation.depth_jump_rel);
    // Edge blocks: an object (or, without the object stages, a cluster) other than the
    // block's own in its 3 x 3 neighbourhood. There the input's colour places the outline.
    const LabelImage& outline = params_.detect_objects ? s.objects : s.labels;
    const int w = outline.width, h = outline.height;
    const std::size_t n_small = outline.labels.size();
    // Separable: each pixel's row-wise minimum and maximum over three, then column-wise;
    // an edge where the 3 x 3 minimum and maximum differ. Plain loops over rows through raw
    // pointers, the borders clamped by the row pointers' choice, not per pixel: they vectorize.
    edge_blocks_.resize(n_small);
    edge_lo_.resize(n_small);
    edge_hi_.resize(n_small);
    const std::uint16_t* const l = outline.labels.data();
    std::uint16_t *const lo = edge_lo_.data(), *const hi = edge_hi_.data();
    std::uint8_t* const edge = edge_blocks_.data();
    auto min3 = [](std::uint16_t a, std::uint16_t b, std::uint16_t c) { return std::min(std::min(a, b), c); };
    auto max3 = [](std::uint16_t a, std::uint16_t b, std::uint16_t c) { return std::max(std::max(a, b), c); };
#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        const std::uint16_t* const in = l + static_cast<std::size_t>(v) * w;
        std::uint16_t *const row_lo = lo + static_cast<std::size_t>(v) * w, *const row_hi = hi + static_cast<std::size_t>(v) * w;
        row_lo[0] = min3(in[0], in[0], in[std::min(1, w - 1)]);
        row_hi[0] = max3(in[0], in[0], in[std::min(1, w - 1)]);
        for (int u = 1; u < w - 1; ++u) {
            row_lo[u] = min3(in[u - 1], in[u], in[u + 1]);
            row_hi[u] = max3(in[u - 1], in[u], in[u + 1]);
        }
        if (w > 1) {
            row_lo[w - 1] = min3(in[w - 2], in[w - 1], in[w - 1]);
            row_hi[w - 1] = max3(in[w - 2], in[w - 1], in[w - 1]);
        }
    }
#pragma omp parallel for schedule(static)
    for (int v = 0; v < h; ++v) {
        const std::size_t up = static_cast<std::size_t>(std::max(v - 1, 0)) * w,
                          row = static_cast<std::size_t>(v) * w,
                          down = static_cast<std::size_t>(std::min(v + 1, h - 1)) * w;
        const std::uint16_t *const lo_up = lo + up, *const lo_row = lo + row, *const lo_down = lo + down;
        const std::uint16_t *const hi_up = hi + up, *const hi_row = hi + row, *const hi_down = hi + down;
        std::uint8_t* const out = edge + row;
        for (int u = 0; u < w; ++u)
            out[u] = min3(lo_up[u], lo_row[u], lo_down[u]) != max3(hi_up[u], hi_row[u], hi_down[u]);
    }
    source.use_colour_at_edges(frame.color, decimated_.color, edge_blocks_.data(), l, block_source_);
    r.stats = s.stats;
    r.plane = s.plane;
    r.segment_stats = s.segment_stats;
    r.object_list = s.object_list;
    const bool objects = params_.detect_objects;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    // Without the object stages their images stay empty, as run_on leaves them.
    auto shape = [](LabelImage& img, int width, int height) {
        img.width = width;
        img.height = height;
        img.labels.resize(static_cast<std::size_t>(width) * height);
    };
    shape(r.labels, W, H);
    shape(r.segments, objects ? W : 0, objects ? H : 0);
    shape(r.objects, objects ? W : 0, objects ? H : 0);
    r.colors.width = W;
    r.colors.height = H;
    r.colors.rgb.resize(3 * N);
    r.active.resize(N);
    r.plane_classes.resize(objects ? N : 0);

    // Track id -> index in object_list, for each object's pixel count and 2D box.
    int max_id = 0;
    for (const DetectedObject& d : r.object_list) max_id = std::max(max_id, d.id);
    object_index_.assign(static_cast<std::size_t>(max_id) + 1, -1);
    for (std::size_t i = 0; i < r.object_list.size(); ++i)
        object_index_[static_cast<std::size_t>(r.object_list[i].id)] = static_cast<int>(i);
    const std::size_t n_obj = r.object_list.size();
    band_boxes_.assign(kExpandBands * n_obj, PixelBox{W, H, -1, -1, 0});
    band_active_.assign(kExpandBands, 0);

    // One pass: every result of the pixel's source, or "no point" without one; the counts
    // and boxes per fixed row band, reduced in band order below.
    // Raw pointers: through the vectors, every byte store would make the compiler reload
    // every data pointer.
    const std::uint8_t* const frame_rgb = frame.color.rgb.size() == 3 * N ? frame.color.rgb.data() : nullptr;
    const std::uint16_t *const in_labels = s.labels.labels.data(), *const in_segments = s.segments.labels.data(),
                        *const in_objects = s.objects.labels.data();
    const std::uint8_t *const in_rgb = s.colors.rgb.data(), *const in_active = s.active.data(),
                       *const in_classes = s.plane_classes.data();
    std::uint16_t *const labels = r.labels.labels.data(), *const segments = r.segments.labels.data(),
                  *const objects_out = r.objects.labels.data();
    std::uint8_t *const colors = r.colors.rgb.data(), *const active_out = r.active.data(),
                 *const classes = r.plane_classes.data();
    const int* const object_index = object_index_.data();
    // A pixel is in the depth range by its own depth, as at every pixel (select_depth_range):
    // the block it takes can lie on the other side of a limit. In range, on a block that is
    // not, it takes the nearest in depth of the 3 x 3 blocks that are (its own is: the frame
    // was decimated to blocks in range where they could be); out of range, none.
    const float scale = frame.depth.scale_m_per_unit;
    const DepthRange& range = params_.range;
    const std::uint16_t* const depth = frame.depth.data.data();
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kExpandBands; ++band) {
        PixelBox* const boxes = band_boxes_.data() + static_cast<std::size_t>(band) * n_obj;
        std::size_t active = 0;
        for (int v = band * H / kExpandBands; v < (band + 1) * H / kExpandBands; ++v) {
            const int bv = v / source.factor();
            for (int u = 0, bu = 0, in_block = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                std::uint8_t* const rgb = colors + 3 * p;
                std::int32_t q = source.in_block(u, v, bu, bv);
                if (q >= 0) {
                    if (!range.contains(static_cast<float>(depth[p]) * scale))
                        q = -1;
                    else if (!in_active[q])
                        q = source.nearest_in_depth(bu, bv, depth[p], in_active);
                }
                if (++in_block == source.factor()) {
                    in_block = 0;
                    ++bu;
                }
                if (q < 0) {
                    labels[p] = 0;
                    rgb[0] = rgb[1] = rgb[2] = frame_rgb ? dimmed_grey(frame_rgb + 3 * p) : 0;
                    active_out[p] = 0;
                    if (!objects) continue;
                    classes[p] = kPlaneRemoved;
                    segments[p] = 0;
                    objects_out[p] = 0;
                    continue;
                }
                const auto sq = static_cast<std::size_t>(q);
                labels[p] = in_labels[sq];
                rgb[0] = in_rgb[3 * sq];
                rgb[1] = in_rgb[3 * sq + 1];
                rgb[2] = in_rgb[3 * sq + 2];
                active += active_out[p] = in_active[sq];
                if (!objects) continue;
                classes[p] = in_classes[sq];
                segments[p] = in_segments[sq];
                const std::uint16_t id = objects_out[p] = in_objects[sq];
                if (id == 0 || id > max_id || object_index[id] < 0) continue;
                boxes[object_index[id]].add(u, v);
            }
        }
        band_active_[static_cast<std::size_t>(band)] = active;
    }
    r.active_points = 0;
    for (std::size_t a : band_active_) r.active_points += a;
    for (std::size_t i = 0; i < n_obj; ++i) {
        DetectedObject& d = r.object_list[i];
        PixelBox total{W, H, -1, -1, 0};
        for (int band = 0; band < kExpandBands; ++band)
            total.merge(band_boxes_[static_cast<std::size_t>(band) * n_obj + i]);
        d.pixels = total.pixels;
        d.u_min = total.u_min;
        d.v_min = total.v_min;
        d.u_max = total.u_max;
        d.v_max = total.v_max;
    }
    // The tracker's minimum (ObjectParams::min_points) counts the input's pixels: the stages
    // checked it divided by N^2 on blocks, and an object can come back a few pixels short.
    const auto min_pixels = static_cast<std::size_t>(params_.objects.min_points);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n_obj; ++i) {
        DetectedObject& d = r.object_list[i];
        if (d.pixels >= min_pixels) {
            if (kept != i) r.object_list[kept] = std::move(d);
            ++kept;
            continue;
        }
        for (int v = d.v_min; v <= d.v_max; ++v)
            for (int u = d.u_min; u <= d.u_max; ++u) {
                std::uint16_t& id = objects_out[static_cast<std::size_t>(v) * W + u];
                if (id == d.id) id = 0;
            }
    }
    r.object_list.resize(kept);
}

}  // namespace wul3d
