#pragma once
/// @file run.hpp
/// A whole run, as `wul3d run` does it: every frame of a recording or a live camera through
/// the pipeline, each frame's outputs written to OUT/<frame>/ (output.hpp) and, at the end,
/// OUT/summary.json. A RunObserver hears of each frame (for a progress bar or a video);
/// the outputs are the same whoever calls (docs/OUTPUTS.md; docs/LIBRARY.md).
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/feed.hpp"
#include "wul3d/output.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d {

struct RunOptions {
    FeedOptions feed;           ///< the recording or camera
    PipelineParams params;      ///< validated by the Pipeline
    /// The preset `params` came from, for summary.json ("" is written as "default").
    std::string preset;
    std::string out_dir;        ///< OUT; created if missing
    std::size_t max_frames = 0; ///< stop after N frames; 0 = all (a camera: until stop or end)
    OutputFiles files;          ///< which files each OUT/<frame>/ gets (output.hpp)
    /// Follow the object under pixel (u, v) of the first frame: selected.png (its cluster),
    /// selected_object.png (its object) and "selected" in objects.json.
    std::optional<std::pair<int, int>> select;
    /// Polled between frames: true ends the run as "signal" (outputs still complete). A stop
    /// request (stop.hpp) also ends it, even mid-frame.
    std::function<bool()> stop;
    /// An existing OUT may hold what wul3d did not write; only wul3d's own files there are
    /// replaced (prepare_out_dir). Without it such an OUT is refused.
    bool overwrite = false;
};

/// One processed frame, as the observer sees it (valid during the call only).
struct RunFrame {
    const std::string& name;   ///< OUT/<name>/, already written
    std::size_t index;         ///< from 0
    std::size_t total;         ///< frames this run will process; 0 = unknown (a camera)
    const RgbdFrame& frame;    ///< the (registered) input frame
    const FrameResult& result;
    const Mask* selected;      ///< the followed cluster's mask, or nullptr
    int selected_object;       ///< the followed object's track id this frame, 0 none
    double fps;                ///< the pipeline's rate so far (median frame time)
};

/// What a run did; also in summary.json.
struct RunSummary {
    std::size_t frames = 0;
    /// "end", "frames" (max_frames reached), "signal" (stop), "device_lost", "error" (a bad
    /// frame, a full disk: the exception is rethrown after summary.json is written).
    std::string stopped_by = "end";
    std::string error;  ///< the error line of "error" and "device_lost"; empty otherwise
    double ms_per_frame_median = 0;  ///< the pipeline's time, no disk I/O
    double fps = 0;
    double wall_s = 0;
    /// Frames a second of the whole run, reading and writing included (frames / wall_s):
    /// what a user waits for. Reading ahead and writing behind overlap them with the work.
    double end_to_end_fps = 0;
    double peak_rss_mb = 0;
};

/// Hears of a run's progress; every method defaults to nothing. Called on the caller's
/// thread.
class RunObserver {
public:
    virtual ~RunObserver() = default;
    /// The input is open, OUT exists, the pipeline is built; `total` as in RunFrame.
    virtual void started(std::size_t total) { (void)total; }
    /// A remark for the user, one line (e.g. a frame without colour).
    virtual void note(const std::string& text) { (void)text; }
    virtual void frame(const RunFrame& f) { (void)f; }
    /// No more frames will come; summary.json is not written yet. An error thrown here
    /// ends the run as a frame's would (summary.json says it), unless one already did.
    virtual void frames_done() {}
    /// summary.json is written. A lost camera is thrown after this.
    virtual void finished(const RunSummary& summary) { (void)summary; }
};

/// Runs `options.feed` through a Pipeline into `options.out_dir` exactly as `wul3d run`.
/// OUT may not be, hold or lie in an input (ParamError), nor hold what wul3d did not write
/// unless `overwrite` (InputError); every frame name must pass check_frame_name. Each frame's
/// statistics are appended to OUT/frames.jsonl as it is written; OUT/summary.json is written
/// however the run ends once OUT is prepared, with "stopped_by" and "error". Throws
/// ParamError, InputError (unreadable input or frame; a camera that ended before its first
/// frame), IoError (disk full); DeviceLost when the camera disappears. Every error but the
/// first three checks is thrown after summary.json is written.
RunSummary run_sequence(const RunOptions& options, RunObserver* observer = nullptr);

}  // namespace wul3d
