// `wul3d run`: read a recording, run the pipeline on every frame, write the outputs and a
// summary. Parsing and output only; the algorithm is the library's.
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
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
#include "video_writer.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {
namespace fs = std::filesystem;

namespace {

struct RunOptions {
    std::string input;
    std::string out_dir;
    std::string format = "auto";
    std::string preset;
    std::string tum_camera;
    std::string intrinsics;
    std::string calibration;
    std::string registration = "depth-to-color";
    std::string select;
    std::string video;  // --video FILE: side-by-side video (video_writer.hpp)
    std::string segmenter;
    bool no_plane = false;
    std::optional<int> min_points;
    std::optional<float> object_psi;
    std::size_t max_frames = 0;  // 0 = all
    int threads = 0;             // 0 = all cores
    bool ply = false;
    bool quiet = false;
    // Parameters given on the command line override the preset; kept apart so we know.
    std::optional<int> k, iters, stride, normal_radius;
    std::optional<float> alpha, delta, gamma, psi, zmin, zmax;
    std::optional<std::uint64_t> seed;
};

/// Splits "a,b,c" into numbers; throws ParamError naming the flag.
std::vector<double> parse_list(const std::string& flag, const std::string& text,
                               std::size_t expected) {
    std::vector<double> values;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            std::size_t used = 0;
            values.push_back(std::stod(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw ParamError(flag + " '" + text + "': '" + item + "' is not a number");
        }
    }
    if (values.size() != expected)
        throw ParamError(flag + " '" + text + "': expected " + std::to_string(expected) +
                         " comma-separated numbers");
    return values;
}

PipelineParams make_params(const RunOptions& o) {
    PipelineParams p;
    if (o.preset == "paper") {
        p = PipelineParams::paper();
    } else if (!o.preset.empty()) {
        throw ParamError("--preset '" + o.preset + "': unknown (known: paper)");
    }
    if (o.k) p.cluster.k = *o.k;
    if (o.alpha) {
        p.cluster.alpha = *o.alpha;
        if (!o.delta) p.cluster.delta = 1.0f - *o.alpha;  // eq. (5) at equality, as the paper
    }
    if (o.delta) p.cluster.delta = *o.delta;
    if (o.gamma) p.cluster.gamma = *o.gamma;
    if (o.psi) p.cluster.psi = *o.psi;
    if (o.iters) p.cluster.iters = *o.iters;
    if (o.stride) p.cluster.stride = *o.stride;
    if (o.seed) p.cluster.seed = *o.seed;
    if (o.zmin) p.range.zmin_m = *o.zmin;
    if (o.zmax) p.range.zmax_m = *o.zmax;
    if (o.normal_radius) p.normals.radius_px = *o.normal_radius;
    if (!o.segmenter.empty()) p.segmentation.segmenter = parse_segmenter(o.segmenter);
    if (o.no_plane) p.remove_plane = false;
    if (o.min_points) p.segmentation.min_points = *o.min_points;
    if (o.object_psi) p.objects.psi = *o.object_psi;
    p.validate();
    return p;
}

SourceOptions make_source_options(const RunOptions& o) {
    SourceOptions s;
    s.format = parse_input_format(o.format);
    s.tum_camera = o.tum_camera;
    s.calibration = o.calibration;
    s.registration = parse_registration_mode(o.registration);
    if (!o.intrinsics.empty()) {
        const auto v = parse_list("--intrinsics", o.intrinsics, 4);
        PinholeIntrinsics K;  // width and height come from each frame
        K.fx = v[0];
        K.fy = v[1];
        K.cx = v[2];
        K.cy = v[3];
        if (!(K.fx > 0 && K.fy > 0))
            throw ParamError("--intrinsics '" + o.intrinsics + "': fx and fy must be > 0");
        s.intrinsics = K;
    }
    return s;
}

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
        const int width = 30;
        const int filled = total_ ? static_cast<int>(width * done / total_) : width;
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
    nlohmann::json j = {{"objects", objs}, {"support_plane", nullptr}};
    if (r.plane.found) {
        const Plane& pl = r.plane.support;
        j["support_plane"] = {{"normal", {pl.nx, pl.ny, pl.nz}}, {"d_m", pl.d}};
    }
    return j.dump(1) + "\n";
}

/// Writes one frame's outputs into OUT/.<name>.partial, then renames it to OUT/<name>, so a
/// frame folder is either complete or absent.
void write_frame(const fs::path& out_dir, const std::string& name, const Pipeline& pipeline,
                 const FrameResult& r, const std::vector<std::uint8_t>* selected,
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
        if (ply) write_ply((tmp_dir / "cloud.ply").string(), pipeline.cloud(), r.labels, r.colors);
        fs::remove_all(final_dir, ec);
        fs::rename(tmp_dir, final_dir);
    } catch (...) {
        fs::remove_all(tmp_dir, ec);
        throw;
    }
}

void run(const RunOptions& o) {
    const PipelineParams params = make_params(o);
    const SourceOptions source_options = make_source_options(o);
    std::optional<SelectedObject> selection, selected_object;
    if (!o.select.empty()) {
        const auto uv = parse_list("--select", o.select, 2);
        selection.emplace(static_cast<int>(uv[0]), static_cast<int>(uv[1]));
        selected_object.emplace(static_cast<int>(uv[0]), static_cast<int>(uv[1]));
    }
    if (o.threads > 0) omp_set_num_threads(o.threads);

    auto source = open_source(o.input, source_options);
    const std::size_t n_frames =
        o.max_frames ? std::min(o.max_frames, source->size()) : source->size();

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
    Progress progress(n_frames, !o.quiet);
    using Clock = std::chrono::steady_clock;
    const auto run_start = Clock::now();
    std::optional<RunVideo> video;
    if (!o.video.empty()) video.emplace(o.video);

    for (std::size_t i = 0; i < n_frames; ++i) {
        source->read(i, item);
        const FrameResult& r = item.is_raw
                                   ? pipeline.process(item.raw, *source->calibration(),
                                                      source_options.registration)
                                   : pipeline.process(item.frame);
        const RgbdFrame& frame = item.is_raw ? pipeline.registered() : item.frame;
        if (!frame.has_color() && !said_depth_only) {
            std::cerr << "wul3d: note: " << source->name(i)
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
        write_frame(out_dir, source->name(i), pipeline, r, selection ? &selected_mask : nullptr,
                    selected_object ? &selected_object_mask : nullptr,
                    object_selected ? selected_object->label() : 0, o.ply);
        const double out_ms =
            std::chrono::duration<double, std::milli>(Clock::now() - t_out).count();

        stage_ms["registration"].push_back(r.times.registration);
        stage_ms["backprojection"].push_back(r.times.backprojection);
        stage_ms["normals"].push_back(r.times.normals);
        stage_ms["background"].push_back(r.times.background);
        stage_ms["clustering"].push_back(r.times.clustering);
        stage_ms["colors"].push_back(r.times.colors);
        stage_ms["plane"].push_back(r.times.plane);
        stage_ms["segmentation"].push_back(r.times.segmentation);
        stage_ms["objects"].push_back(r.times.objects);
        stage_ms["output"].push_back(out_ms);
        compute_ms.push_back(r.times.total());
        nlohmann::json f = {{"name", source->name(i)},
                            {"points", r.stats.points},
                            {"active_points", r.active_points},
                            {"seeded", r.stats.seeded},
                            {"reseeded", r.stats.reseeded},
                            {"mean_f", r.stats.mean_f},
                            {"ms", r.times.total()},
                            {"support_plane", r.plane.found},
                            {"segments", r.segment_stats.segments},
                            {"color_splits", r.segment_stats.color_splits},
                            {"objects", r.object_list.size()}};
        if (selection) f["selected_pixels"] = selection->pixels();
        per_frame.push_back(std::move(f));
        progress.update(i + 1, 1000.0 / std::max(1e-9, median(compute_ms)));
        if (video) video->write(frame, r, selection ? &selected_mask : nullptr, i, n_frames,
                                1000.0 / std::max(1e-9, median(compute_ms)));
    }
    progress.finish();
    if (video) video->close();

    const double ms = median(compute_ms);
    const double fps = ms > 0 ? 1000.0 / ms : 0.0;
    const double rss = peak_rss_mb();
    const double wall_s =
        std::chrono::duration<double>(Clock::now() - run_start).count();
    const auto& c = params.cluster;
    nlohmann::json summary;
    summary["input"] = o.input;
    summary["format"] = input_format_name(source->format());
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
                             {"remove_plane", params.remove_plane},
                             {"min_points", params.segmentation.min_points},
                             {"object_psi", params.objects.psi},
                             {"preset", o.preset.empty() ? "default" : o.preset}};
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
}

}  // namespace

void add_run_command(CLI::App& app) {
    auto opts = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Detect objects in an RGB-D recording");
    cmd->add_option("input", opts->input,
                    "Frame folder(s), TUM RGB-D sequence, or unregistered frames")
        ->required();
    cmd->add_option("-o,--out", opts->out_dir, "Output folder")->required();
    cmd->add_option("--format", opts->format, "auto|frames|tum|unregistered")
        ->capture_default_str();
    cmd->add_option("--preset", opts->preset, "paper: the paper's parameters");
    cmd->add_option("--k", opts->k, "Number of clusters (default 7)");
    cmd->add_option("--alpha", opts->alpha, "Colour scale, eq. 4, [0.002, 0.1] (default 0.0033)");
    cmd->add_option("--delta", opts->delta, "Position scale, eq. 4, alpha + delta <= 1 (default 1 - alpha)");
    cmd->add_option("--gamma", opts->gamma, "Normal scale, eq. 6, [0.0001, 0.01] (default 0.0001)");
    cmd->add_option("--psi", opts->psi, "Weight increment, eq. 2, (0, 1] (default 1)");
    cmd->add_option("--iters", opts->iters, "k-means iterations per frame (default 1)");
    cmd->add_option("--stride", opts->stride, "Sampling stride in pixels (default 1)");
    cmd->add_option("--seed", opts->seed, "k-means++ seed (default 1)");
    cmd->add_option("--zmin", opts->zmin, "Nearest depth kept, metres (default 0.2)");
    cmd->add_option("--zmax", opts->zmax, "Farthest depth kept, metres (default 4.5)");
    cmd->add_option("--normal-radius", opts->normal_radius, "Normal neighbour distance, px (default 2)");
    cmd->add_option("--select", opts->select, "U,V: follow the object under this pixel of the first frame");
    cmd->add_option("--segmenter", opts->segmenter,
                    "Object segmentation: geometric|kmeans|hybrid (default hybrid)");
    cmd->add_flag("--no-plane", opts->no_plane,
                  "Keep the support plane (the paper's background step: depth range only)");
    cmd->add_option("--min-points", opts->min_points, "Smallest object, pixels (default 300)");
    cmd->add_option("--object-psi", opts->object_psi,
                    "Weight increment of eq. 2 for object tracks, (0, 1] (default 0.5; 1 = no smoothing)");
    cmd->add_option("--frames", opts->max_frames, "Stop after N frames (default: all)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_option("--threads", opts->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_flag("--ply", opts->ply, "Also write each frame's labelled cloud as binary PLY");
    cmd->add_option("--video", opts->video,
                    "Also write a video: colour | clusters | selected object (e.g. out.mp4)");
    cmd->add_flag("-q,--quiet", opts->quiet, "No progress bar");
    cmd->add_option("--tum-camera", opts->tum_camera,
                    "TUM intrinsics preset: kinect_v1|tum_fr1|tum_fr2|tum_fr3 (default: from folder name)");
    cmd->add_option("--intrinsics", opts->intrinsics, "fx,fy,cx,cy: override every frame's intrinsics");
    cmd->add_option("--calibration", opts->calibration,
                    "Unregistered input: calibration JSON, or kinect_v2 for the built-in preset");
    cmd->add_option("--registration", opts->registration, "depth-to-color|color-to-depth")
        ->capture_default_str();
    cmd->callback([opts]() { run(*opts); });
}

}  // namespace wul3d::cli
