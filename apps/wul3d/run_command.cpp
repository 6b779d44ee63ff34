// `wul3d run`: read a recording, run the pipeline on every frame, write the outputs and a
// summary. Parsing and output only; the algorithm is the library's.
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "frame_feed.hpp"
#include "pipeline_options.hpp"
#include "video_writer.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {
namespace fs = std::filesystem;

namespace {

struct RunOptions {
    PipelineOptions pipeline;    // input and parameters, shared with `wul3d view`
    std::string out_dir;
    std::string video;           // --video FILE: side-by-side video (video_writer.hpp)
    std::size_t max_frames = 0;  // 0 = all
    bool ply = false;
    bool quiet = false;
};

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

/// A one-line progress bar on stderr, only when stderr is a terminal.
class Progress {
public:
    explicit Progress(std::size_t total, bool enabled)
        : total_(total), enabled_(enabled && ::isatty(STDERR_FILENO)) {}
    void update(std::size_t done, double fps) {
        if (!enabled_) return;
        if (total_ == 0) {  // a live camera: no end known
            std::cerr << "\r" << done << " frames  " << std::fixed << std::setprecision(1) << fps
                      << " FPS" << std::flush;
            return;
        }
        const int width = 30;
        const int filled = static_cast<int>(width * done / total_);
        std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ')
                  << "] " << done << "/" << total_ << "  " << std::fixed << std::setprecision(1)
                  << fps << " FPS" << std::flush;
    }
    void finish() {
        if (enabled_) std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
    }

private:
    std::size_t total_;
    bool enabled_;
};

/// objects.json of one frame: every object with its boxes, colour and sources.
std::string objects_json(const FrameResult& r, int selected_id) {
    nlohmann::json objs = nlohmann::json::array();
    for (const DetectedObject& d : r.object_list) {
        nlohmann::json o = {{"id", d.id},
                            {"track_id", d.track_id},
                            {"pixels", d.pixels},
                            {"centroid_m", d.centroid},
                            {"aabb_m", {{"min", d.aabb_min}, {"max", d.aabb_max}}},
                            {"obb_m",
                             {{"centre", d.obb_centre},
                              {"axes", {{d.obb_axes[0], d.obb_axes[1], d.obb_axes[2]},
                                        {d.obb_axes[3], d.obb_axes[4], d.obb_axes[5]},
                                        {d.obb_axes[6], d.obb_axes[7], d.obb_axes[8]}}},
                              {"half_extent", d.obb_half_extent}}},
                            {"box_px", {{"u_min", d.u_min}, {"v_min", d.v_min},
                                        {"u_max", d.u_max}, {"v_max", d.v_max}}},
                            {"mean_rgb", d.mean_rgb},
                            {"source_clusters", d.source_clusters},
                            {"source_segments", d.source_segments}};
        if (selected_id != 0) o["selected"] = d.id == selected_id;
        objs.push_back(std::move(o));
    }
    nlohmann::json j = {{"objects", objs},
                        {"scope", r.segment_stats.support_scope ? "support" : "scene"},
                        {"support_plane", nullptr}};
    if (r.plane.found) {
        const Plane& pl = r.plane.support;
        j["support_plane"] = {{"normal", {pl.nx, pl.ny, pl.nz}}, {"d_m", pl.d}};
    }
    return j.dump(1) + "\n";
}

/// Writes one frame's outputs into OUT/.<name>.partial, then renames it to OUT/<name>, so a
/// frame folder is either complete or absent.
void write_frame(const fs::path& out_dir, const std::string& name, const Pipeline& pipeline,
                 const RgbdFrame& frame, const FrameResult& r, const std::vector<std::uint8_t>* selected,
                 const std::vector<std::uint8_t>* selected_object, int selected_id, bool ply) {
    const fs::path final_dir = out_dir / name;
    const fs::path tmp_dir = out_dir / ("." + name + ".partial");
    std::error_code ec;
    fs::remove_all(tmp_dir, ec);
    fs::create_directories(tmp_dir, ec);
    if (ec) throw IoError(tmp_dir.string() + ": cannot create folder: " + ec.message());
    try {
        write_label_png((tmp_dir / "labels.png").string(), r.labels);
        write_color_png((tmp_dir / "colors.png").string(), r.colors);
        if (selected)
            write_mask_png((tmp_dir / "selected.png").string(), r.labels.width,
                           r.labels.height, *selected);
        write_label_png((tmp_dir / "objects.png").string(), r.objects);
        write_text_file((tmp_dir / "objects.json").string(), objects_json(r, selected_id));
        if (selected_object)
            write_mask_png((tmp_dir / "selected_object.png").string(), r.objects.width,
                           r.objects.height, *selected_object);
        if (ply && pipeline.cloud().size() == r.labels.labels.size()) {
            write_ply((tmp_dir / "cloud.ply").string(), pipeline.cloud(), r.labels, r.colors);
        } else if (ply) {  // --decimate: the results are at the input's size, the cloud is not
            OrganizedCloud full;
            back_project(frame, full);
            write_ply((tmp_dir / "cloud.ply").string(), full, r.labels, r.colors);
        }
        fs::remove_all(final_dir, ec);
        fs::rename(tmp_dir, final_dir);
    } catch (...) {
        fs::remove_all(tmp_dir, ec);
        throw;
    }
}

void run(const RunOptions& o) {
    const PipelineParams params = make_pipeline_params(o.pipeline);
    const SourceOptions source_options = make_source_options(o.pipeline);
    std::optional<SelectedObject> selection, selected_object;
    if (const auto uv = selected_pixel(o.pipeline)) {
        selection.emplace(uv->first, uv->second);
        selected_object.emplace(uv->first, uv->second);
    }
    apply_threads(o.pipeline);

    install_stop_signals();
    FrameFeed feed(o.pipeline, source_options);
    // A recording has a known length; a camera runs until --frames, Ctrl-C or its end.
    const std::size_t n_total =
        feed.live() ? o.max_frames
                    : (o.max_frames ? std::min(o.max_frames, feed.size()) : feed.size());

    const fs::path out_dir(o.out_dir);
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec || !fs::is_directory(out_dir))
        throw IoError(o.out_dir + ": cannot create output folder" +
                      (ec ? ": " + ec.message() : ""));

    Pipeline pipeline(params);
    SourceItem item;
    std::vector<std::uint8_t> selected_mask, selected_object_mask;
    std::map<std::string, std::vector<double>> stage_ms;
    std::vector<double> compute_ms;
    nlohmann::json per_frame = nlohmann::json::array();
    bool said_depth_only = false;
    Progress progress(n_total, !o.quiet);
    using Clock = std::chrono::steady_clock;
    const auto run_start = Clock::now();
    std::optional<RunVideo> video;
    if (!o.video.empty()) video.emplace(o.video);

    std::size_t i = 0;  // frames processed
    std::string stopped_by = "end";
    std::exception_ptr lost;  // DeviceLost: rethrown (exit 3) once the outputs are final
    for (;;) {
        if (n_total && i >= n_total) {
            stopped_by = feed.live() || n_total < feed.size() ? "frames" : "end";
            break;
        }
        if (!feed.next_frame(item, stopped_by, lost)) break;
        const std::string name = feed.name();
        const FrameResult& r = item.is_raw
                                   ? pipeline.process(item.raw, *feed.calibration(),
                                                      source_options.registration)
                                   : pipeline.process(item.frame);
        const RgbdFrame& frame = item.is_raw ? pipeline.registered() : item.frame;
        if (!frame.has_color() && !said_depth_only) {
            std::cerr << "wul3d: note: " << name
                      << " has no colour image; clustering on position and normals only\n";
            said_depth_only = true;
        }
        if (selection) selection->update(r.labels, selected_mask);
        // The user-defined object followed as an object (objects.png), once it has one.
        bool object_selected = false;
        if (selected_object) {
            if (selected_object->label() != 0 ||
                std::any_of(r.objects.labels.begin(), r.objects.labels.end(),
                            [](std::uint16_t l) { return l != 0; })) {
                try {
                    selected_object->update(r.objects, selected_object_mask);
                    object_selected = true;
                } catch (const InputError&) {
                    // No object near the picked pixel yet: try again next frame.
                }
            }
            if (!object_selected) selected_object_mask.assign(r.objects.labels.size(), 0);
        }

        const auto t_out = Clock::now();
        write_frame(out_dir, name, pipeline, frame, r, selection ? &selected_mask : nullptr,
                    selected_object ? &selected_object_mask : nullptr,
                    object_selected ? selected_object->label() : 0, o.ply);
        const double out_ms =
            std::chrono::duration<double, std::milli>(Clock::now() - t_out).count();

        stage_ms["registration"].push_back(r.times.registration);
        stage_ms["decimation"].push_back(r.times.decimation);
        stage_ms["backprojection"].push_back(r.times.backprojection);
        stage_ms["normals"].push_back(r.times.normals);
        stage_ms["background"].push_back(r.times.background);
        stage_ms["clustering"].push_back(r.times.clustering);
        stage_ms["colors"].push_back(r.times.colors);
        stage_ms["plane"].push_back(r.times.plane);
        stage_ms["segmentation"].push_back(r.times.segmentation);
        stage_ms["objects"].push_back(r.times.objects);
        stage_ms["overlap"].push_back(r.times.overlap);
        stage_ms["output"].push_back(out_ms);
        compute_ms.push_back(r.times.total());
        nlohmann::json f = {{"name", name},
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
                            {"scope", r.segment_stats.support_scope ? "support" : "scene"},
                            {"out_of_scope", r.segment_stats.out_of_scope},
                            {"objects", r.object_list.size()}};
        if (selection) f["selected_pixels"] = selection->pixels();
        per_frame.push_back(std::move(f));
        ++i;
        progress.update(i, 1000.0 / std::max(1e-9, median(compute_ms)));
        if (video) video->write(frame, r, selection ? &selected_mask : nullptr, i - 1,
                                n_total ? n_total : i,  // live without --frames: no end known
                                1000.0 / std::max(1e-9, median(compute_ms)));
    }
    const std::size_t n_frames = i;
    progress.finish();
    if (video) video->close();

    const double ms = median(compute_ms);
    const double fps = ms > 0 ? 1000.0 / ms : 0.0;
    const double rss = peak_rss_mb();
    const double wall_s =
        std::chrono::duration<double>(Clock::now() - run_start).count();
    const auto& c = params.cluster;
    nlohmann::json summary;
    if (feed.live()) {
        summary["input"] = nullptr;
        summary["camera"] = {{"spec", o.pipeline.camera},
                             {"device", feed.description()},
                             {"lossless", o.pipeline.lossless}};
        summary["frames_captured"] = feed.captured();
        summary["frames_dropped"] = feed.dropped();
    } else {
        summary["input"] = o.pipeline.input;
    }
    summary["format"] = feed.format();
    summary["stopped_by"] = stopped_by;
    summary["parameters"] = {{"k", c.k},
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
                             {"scope", scope_name(params.segmentation.scope)},
                             {"remove_plane", params.remove_plane},
                             {"min_points", params.segmentation.min_points},
                             {"object_psi", params.objects.psi},
                             {"decimate", params.decimation},
                             {"preset", o.pipeline.preset.empty() ? "default" : o.pipeline.preset}};
    summary["frames"] = n_frames;
    summary["threads"] = omp_get_max_threads();
    nlohmann::json medians;
    for (const auto& [stage, values] : stage_ms) medians[stage] = median(values);
    summary["stage_ms_median"] = medians;
    summary["ms_per_frame_median"] = ms;
    summary["fps"] = fps;
    summary["wall_s"] = wall_s;
    summary["peak_rss_mb"] = rss;
    if (selection) summary["selected_cluster"] = selection->cluster();
    summary["per_frame"] = per_frame;
    write_text_file((out_dir / "summary.json").string(), summary.dump(2) + "\n");

    std::cout << std::fixed << std::setprecision(1) << "wul3d: " << n_frames << " frame"
              << (n_frames == 1 ? "" : "s") << ", k = " << c.k << ": " << fps << " FPS ("
              << ms << " ms/frame without disk I/O), peak " << std::setprecision(0) << rss
              << " MB -> " << o.out_dir << std::endl;
    restore_signals();
    if (lost) std::rethrow_exception(lost);
    if (stopped_by == "signal")
        std::cerr << "wul3d: stopped by a signal after " << n_frames << " frames; outputs complete\n";
    else if (feed.live() && n_frames == 0)
        throw InputError(feed.description() + ": ended before the first frame");
}

}  // namespace

void add_run_command(CLI::App& app) {
    auto opts = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Detect objects in an RGB-D recording or from a live camera (--camera)");
    add_pipeline_options(cmd, opts->pipeline);
    cmd->add_option("-o,--out", opts->out_dir, "Output folder")->required();
    cmd->add_option("--frames", opts->max_frames,
                    "Stop after N frames (default: all; with --camera: until Ctrl-C or its end)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_flag("--ply", opts->ply, "Also write each frame's labelled cloud as binary PLY");
    cmd->add_option("--video", opts->video,
                    "Also write a video: colour | clusters | selected object (e.g. out.mp4)");
    cmd->add_flag("-q,--quiet", opts->quiet, "No progress bar");
    cmd->callback([opts]() { run(*opts); });
}

}  // namespace wul3d::cli
