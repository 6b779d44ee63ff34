// A whole run (run.hpp): the feed through the pipeline, each frame's folder written, then
// summary.json. `wul3d run` is this plus argument parsing and printing.
#include "wul3d/run.hpp"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/output.hpp"

namespace wul3d {
namespace fs = std::filesystem;

namespace {

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

double peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

/// summary.json's "parameters": what the frames were processed with.
nlohmann::json parameters_json(const PipelineParams& params, const std::string& preset) {
    const auto& c = params.cluster;
    return {{"k", c.k},
            {"alpha", c.alpha},
            {"delta", c.delta},
            {"gamma", c.gamma},
            {"psi", c.psi},
            {"iters", c.iters},
            {"stride", c.stride},
            {"seed", c.seed},
            {"zmin_m", params.range.zmin_m},
            {"zmax_m", params.range.zmax_m},
            {"normal_radius_px", params.normals.radius_px},
            {"segmenter", segmenter_name(params.segmentation.segmenter)},
            {"remove_plane", params.remove_plane},
            {"min_points", params.segmentation.min_points},
            {"object_psi", params.objects.psi},
            {"decimate", params.decimation},
            {"preset", preset.empty() ? "default" : preset}};
}

/// One frame's line of summary.json's "per_frame".
nlohmann::json frame_json(const std::string& name, const FrameResult& r) {
    return {{"name", name},
            {"points", r.stats.points},
            {"active_points", r.active_points},
            {"seeded", r.stats.seeded},
            {"reseeded", r.stats.reseeded},
            {"mean_f", r.stats.mean_f},
            {"ms", r.times.total()},
            {"support_plane", r.plane.found},
            {"segments", r.segment_stats.segments},
            {"merges", r.segment_stats.merges},
            {"containers", r.segment_stats.containers},
            {"gaps_filled", r.segment_stats.gaps_filled},
            {"color_splits", r.segment_stats.color_splits},
            {"objects", r.object_list.size()}};
}

/// The stage times of every frame, for summary.json's medians.
struct StageLog {
    std::map<std::string, std::vector<double>> stage_ms;
    std::vector<double> compute_ms;

    void add(const StageTimes& t, double output_ms) {
        stage_ms["registration"].push_back(t.registration);
        stage_ms["decimation"].push_back(t.decimation);
        stage_ms["backprojection"].push_back(t.backprojection);
        stage_ms["normals"].push_back(t.normals);
        stage_ms["background"].push_back(t.background);
        stage_ms["clustering"].push_back(t.clustering);
        stage_ms["colors"].push_back(t.colors);
        stage_ms["plane"].push_back(t.plane);
        stage_ms["segmentation"].push_back(t.segmentation);
        stage_ms["objects"].push_back(t.objects);
        stage_ms["overlap"].push_back(t.overlap);
        stage_ms["output"].push_back(output_ms);
        compute_ms.push_back(t.total());
    }
    nlohmann::json medians() const {
        nlohmann::json m;
        for (const auto& [stage, values] : stage_ms) m[stage] = median(values);
        return m;
    }
};

/// The user's picked object (--select): its cluster and its object, followed over frames.
struct Selection {
    std::optional<SelectedObject> cluster, object;
    std::vector<std::uint8_t> cluster_mask, object_mask;
    bool object_selected = false;  ///< this frame's object mask is the followed object

    explicit Selection(const std::optional<std::pair<int, int>>& uv) {
        if (!uv) return;
        cluster.emplace(uv->first, uv->second);
        object.emplace(uv->first, uv->second);
    }
    void update(const FrameResult& r) {
        if (cluster) cluster->update(r.labels, cluster_mask);
        // The user-defined object followed as an object (objects.png), once it has one.
        object_selected = false;
        if (!object) return;
        if (object->label() != 0 ||
            std::any_of(r.objects.labels.begin(), r.objects.labels.end(),
                        [](std::uint16_t l) { return l != 0; })) {
            try {
                object->update(r.objects, object_mask);
                object_selected = true;
            } catch (const InputError&) {
                // No object near the picked pixel yet: try again next frame.
            }
        }
        if (!object_selected) object_mask.assign(r.objects.labels.size(), 0);
    }
    FrameOutputs outputs(bool ply) const {
        FrameOutputs o;
        o.selected = cluster ? &cluster_mask : nullptr;
        o.selected_object = object ? &object_mask : nullptr;
        o.selected_id = object_selected ? object->label() : 0;
        o.ply = ply;
        return o;
    }
};

void create_out_dir(const std::string& out) {
    const fs::path out_dir(out);
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec || !fs::is_directory(out_dir))
        throw IoError(out + ": cannot create output folder" + (ec ? ": " + ec.message() : ""));
}

}  // namespace

RunSummary run_sequence(const RunOptions& o, RunObserver* observer) {
    RunObserver silent;
    RunObserver& obs = observer ? *observer : silent;
    FrameFeed feed(o.feed, o.stop);
    // A recording has a known length; a camera runs until max_frames, a stop or its end.
    const std::size_t n_total =
        feed.live() ? o.max_frames
                    : (o.max_frames ? std::min(o.max_frames, feed.size()) : feed.size());
    create_out_dir(o.out_dir);

    Pipeline pipeline(o.params);
    Selection selection(o.select);
    SourceItem item;
    StageLog log;
    nlohmann::json per_frame = nlohmann::json::array();
    bool said_depth_only = false;
    using Clock = std::chrono::steady_clock;
    const auto run_start = Clock::now();
    obs.started(n_total);

    RunSummary s;
    std::exception_ptr lost;  // DeviceLost: rethrown once the outputs are final
    for (;;) {
        if (n_total && s.frames >= n_total) {
            s.stopped_by = feed.live() || n_total < feed.size() ? "frames" : "end";
            break;
        }
        if (!feed.next_frame(item, s.stopped_by, lost)) break;
        const std::string name = feed.name();
        const FrameResult& r =
            item.is_raw ? pipeline.process(item.raw, *feed.calibration(), o.feed.source.registration)
                        : pipeline.process(item.frame);
        const RgbdFrame& frame = item.is_raw ? pipeline.registered() : item.frame;
        if (!frame.has_color() && !said_depth_only) {
            obs.note(name + " has no colour image; clustering on position and normals only");
            said_depth_only = true;
        }
        selection.update(r);

        const auto t_out = Clock::now();
        write_frame(o.out_dir, name, pipeline, frame, r, selection.outputs(o.ply));
        log.add(r.times, std::chrono::duration<double, std::milli>(Clock::now() - t_out).count());
        nlohmann::json f = frame_json(name, r);
        if (selection.cluster) f["selected_pixels"] = selection.cluster->pixels();
        per_frame.push_back(std::move(f));
        const double fps = 1000.0 / std::max(1e-9, median(log.compute_ms));
        obs.frame(RunFrame{name, s.frames, n_total, frame, r,
                           selection.cluster ? &selection.cluster_mask : nullptr, fps});
        ++s.frames;
    }
    obs.frames_done();

    s.ms_per_frame_median = median(log.compute_ms);
    s.fps = s.ms_per_frame_median > 0 ? 1000.0 / s.ms_per_frame_median : 0.0;
    s.peak_rss_mb = peak_rss_mb();
    s.wall_s = std::chrono::duration<double>(Clock::now() - run_start).count();
    nlohmann::json summary;
    if (feed.live()) {
        summary["input"] = nullptr;
        summary["camera"] = {{"spec", o.feed.camera},
                             {"device", feed.description()},
                             {"lossless", o.feed.lossless}};
        summary["frames_captured"] = feed.captured();
        summary["frames_dropped"] = feed.dropped();
    } else {
        summary["input"] = o.feed.input;
    }
    summary["format"] = feed.format();
    summary["stopped_by"] = s.stopped_by;
    summary["parameters"] = parameters_json(o.params, o.preset);
    summary["frames"] = s.frames;
    summary["threads"] = omp_get_max_threads();
    summary["stage_ms_median"] = log.medians();
    summary["ms_per_frame_median"] = s.ms_per_frame_median;
    summary["fps"] = s.fps;
    summary["wall_s"] = s.wall_s;
    summary["peak_rss_mb"] = s.peak_rss_mb;
    if (selection.cluster) summary["selected_cluster"] = selection.cluster->cluster();
    summary["per_frame"] = per_frame;
    write_text_file((fs::path(o.out_dir) / "summary.json").string(), summary.dump(2) + "\n");
    obs.finished(s);

    if (lost) std::rethrow_exception(lost);
    if (feed.live() && s.frames == 0)
        throw InputError(feed.description() + ": ended before the first frame");
    return s;
}

}  // namespace wul3d
