// `wul3d run`: parsing and printing over the library's run_sequence (wul3d/run.hpp), which
// reads the recording, runs the pipeline on every frame and writes the outputs and summary.
#include <unistd.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli.hpp"
#include "frame_feed.hpp"
#include "pipeline_options.hpp"
#include "video_writer.hpp"
#include "wul3d/error.hpp"
#include "wul3d/run.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {

namespace {

struct RunCommandOptions {
    PipelineOptions pipeline;    // input and parameters, shared with `wul3d view`
    std::string out_dir;
    std::string video;           // --video FILE: side-by-side video (video_writer.hpp)
    std::size_t max_frames = 0;  // 0 = all
    std::string outputs = "labels,colors,objects,json";  // --outputs: OutputFiles (output.hpp)
    bool ply = false;            // --ply: adds cloud.ply
    bool overlay = false;        // --overlay: adds overlay.png
    bool quiet = false;
    bool overwrite = false;
};

/// A one-line progress bar on stderr, only when stderr is a terminal.
class Progress {
public:
    explicit Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)) {}
    void update(std::size_t done, std::size_t total, double fps) {
        if (!enabled_) return;
        if (total == 0) {  // a live camera: no end known
            std::cerr << "\r" << done << " frames  " << std::fixed << std::setprecision(1) << fps
                      << " FPS" << std::flush;
            return;
        }
        const int width = 30;
        const int filled = static_cast<int>(width * done / total);
        std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ')
                  << "] " << done << "/" << total << "  " << std::fixed << std::setprecision(1)
                  << fps << " FPS" << std::flush;
    }
    void finish() {
        if (enabled_) std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
    }

private:
    bool enabled_;
};

/// What `wul3d run` prints while the library runs: the progress bar, notes, the last line;
/// and the --video it writes.
class RunPrinter : public RunObserver {
public:
    RunPrinter(const RunCommandOptions& o, int k) : o_(o), k_(k), progress_(!o.quiet) {}

    void started(std::size_t) override {
        if (!o_.video.empty()) video_.emplace(o_.video);
    }
    void note(const std::string& text) override { std::cerr << "wul3d: note: " << text << "\n"; }
    void frame(const RunFrame& f) override {
        progress_.update(f.index + 1, f.total, f.fps);
        if (video_) {
            try {
                video_->write(f.frame, f.result, f.selected, f.index,
                              f.total ? f.total : f.index + 1,  // live without --frames: no end known
                              f.fps, f.selected_object);
            } catch (...) {
                video_.reset();  // its partial file goes; the run ends with this error
                throw;
            }
        }
        objects_ += f.result.object_list.size();
    }
    void frames_done() override {
        progress_.finish();
        // The run loop records an error of close() in summary.json (and keeps the first
        // error when the run had already failed).
        if (!video_) return;
        try {
            video_->close();
        } catch (...) {
            video_.reset();  // its partial file goes
            throw;
        }
        video_.reset();
    }
    void finished(const RunSummary& s) override {
        std::cout << std::fixed << std::setprecision(1) << "wul3d: " << s.frames << " frame"
                  << (s.frames == 1 ? "" : "s") << ", " << objects_ << " object"
                  << (objects_ == 1 ? "" : "s") << " in all, k = " << k_ << ": " << s.fps << " FPS ("
                  << s.ms_per_frame_median << " ms/frame without disk I/O), "
                  << s.end_to_end_fps << " FPS end to end, peak "
                  << std::setprecision(0) << s.peak_rss_mb << " MB -> " << o_.out_dir
                  << std::endl;
    }
private:
    const RunCommandOptions& o_;
    int k_;  // for the last line
    Progress progress_;
    std::optional<RunVideo> video_;
    std::size_t objects_ = 0;  // objects found, summed over the frames
};

/// Puts the default signal handlers back however the run ends.
struct SignalScope {
    SignalScope() { install_stop_signals(); }
    ~SignalScope() { restore_signals(); }
    SignalScope(const SignalScope&) = delete;
    SignalScope& operator=(const SignalScope&) = delete;
};

/// What can be known of --video before the first frame: a name FFmpeg writes a video
/// under, and a target that is no input, link, folder or device (write_guard.hpp).
void check_video_target(const RunCommandOptions& o) {
    if (o.video.empty()) return;
    check_video_name(o.video);
    check_write_target(o.video, WriteTarget::File, input_paths(o.pipeline), "--video");
}

void run(const RunCommandOptions& o) {
    check_video_target(o);  // before OUT is touched: a refused --video writes nothing
    RunOptions r;
    r.params = make_pipeline_params(o.pipeline);
    r.feed = feed_options(o.pipeline, make_source_options(o.pipeline));
    r.preset = o.pipeline.preset;
    r.select = selected_pixel(o.pipeline);
    r.out_dir = o.out_dir;
    r.max_frames = o.max_frames;
    try {
        r.files = parse_output_files(o.outputs);
    } catch (const ParamError& e) {
        throw ParamError("--" + std::string(e.what()));
    }
    r.files.ply = r.files.ply || o.ply;
    r.files.overlay = r.files.overlay || o.overlay;
    r.params.render_colors = r.files.reads_colors() || !o.video.empty();  // the video's clusters panel
    r.overwrite = o.overwrite;
    r.stop = stop_requested;
    apply_threads(o.pipeline);

    RunPrinter printer(o, r.params.cluster.k);
    RunSummary s;
    {
        SignalScope signals;
        s = run_sequence(r, &printer);
    }
    if (s.stopped_by == "signal")
        std::cerr << "wul3d: stopped by a signal after " << s.frames
                  << " frames; outputs complete\n";
}

}  // namespace

void add_run_command(CLI::App& app) {
    auto opts = std::make_shared<RunCommandOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Detect objects in an RGB-D recording or from a live camera (--camera)");
    add_pipeline_options(cmd, opts->pipeline);
    cmd->add_option("-o,--out", opts->out_dir, "Output folder")->required();
    cmd->add_option("--frames", opts->max_frames,
                    "Stop after N frames (default: all; with --camera: until Ctrl-C or its end)")
        ->check(NumberIn(1, 1 << 30));
    cmd->add_option("--outputs", opts->outputs,
                    "The files of each OUT/<frame>/: a comma-separated subset of labels, colors, "
                    "objects, json, ply, overlay (objects,json: what object users read, at "
                    "half the writing time)")
        ->capture_default_str();
    cmd->add_flag("--ply", opts->ply, "Also write each frame's labelled cloud as binary PLY");
    cmd->add_flag("--overlay", opts->overlay,
                  "Also write OUT/<frame>/overlay.png: the objects tinted, outlined and numbered "
                  "over the colour image");
    cmd->add_option("--video", opts->video,
                    "Also write a video: colour | objects | clusters (e.g. out.mp4)");
    cmd->add_flag("-q,--quiet", opts->quiet, "No progress bar");
    cmd->add_flag("--overwrite", opts->overwrite,
                  "Write into an output folder that holds other files too (only wul3d's own "
                  "files there are replaced)");
    cmd->callback([opts]() { run(*opts); });
}

}  // namespace wul3d::cli
