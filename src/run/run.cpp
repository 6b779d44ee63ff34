// A whole run (run.hpp): the feed through the pipeline, each frame's folder written, then
// summary.json. `wul3d run` is this plus argument parsing and printing.
#include "wul3d/run.hpp"

#include <fcntl.h>
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>
#include <thread>
#include <chrono>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "json_text.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/output.hpp"
#include "wul3d/parameters.hpp"
#include "wul3d/stop.hpp"
#include "wul3d/threads.hpp"
#include "wul3d/write_guard.hpp"
#include "io/png_encode.hpp"
#include "output_detail.hpp"
#include "write_behind.hpp"

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

/// summary.json's "parameters": what the frames were processed with, every row of the
/// table (parameters.hpp) under its summary_key, and the preset.
nlohmann::json parameters_json(const PipelineParams& params, const std::string& preset) {
    nlohmann::json out = nlohmann::json::object();
    for (const ParamSpec& spec : pipeline_parameters())
        std::visit([&](const auto& value) { out[summary_key(spec)] = value; }, spec.get(params));
    out["preset"] = preset.empty() ? "default" : preset;
    return out;
}

/// One frame's line of OUT/frames.jsonl.
nlohmann::json frame_json(const std::string& name, const FrameResult& r) {
    return {{"name", name},
            {"points", r.stats.points},
            {"active_points", r.active_points},
            {"seeded", r.stats.seeded},
            {"reseeded", r.stats.reseeded},
            {"mean_f", r.stats.mean_f},
            {"depth_noise_px", r.depth_noise_px},
            {"normal_radius_px", r.normal_radius_px},
            {"ms", r.times.total()},
            {"support_plane", r.plane.found},
            {"low_support", r.plane.low_found},
            {"segments", r.segment_stats.segments},
            {"merges", r.segment_stats.merge.joins},
            {"containers", r.segment_stats.containers.joins},
            {"occluded_joins", r.segment_stats.occlusion.joins},
            {"neck_joins", r.segment_stats.necks.joins},
            {"gaps_filled", r.segment_stats.containers.gaps_filled},
            {"color_splits", r.segment_stats.colour.splits},
            {"texture_splits", r.segment_stats.colour.texture_splits},
            {"stack_splits", r.segment_stats.stacks.splits},
            {"piece_splits", r.segment_stats.pieces.splits},
            {"scope", r.segment_stats.scope.applied ? "support" : "scene"},
            {"out_of_scope", r.segment_stats.scope.out_of_scope},
            {"objects", r.object_list.size()}};
}

/// A bounded sample of a run's values for their median: every value up to kKeep, then a
/// uniform sample of kKeep (reservoir sampling, fixed seed), so that memory stays flat over
/// a run of days. Exact for the first kKeep frames.
class MedianSample {
public:
    static constexpr std::size_t kKeep = 4096;
    void add(double v) {
        ++seen_;
        if (values_.size() < kKeep) {
            values_.push_back(v);
            return;
        }
        const std::uint64_t j = std::uniform_int_distribution<std::uint64_t>(0, seen_ - 1)(rng_);
        if (j < kKeep) values_[j] = v;
    }
    double median() const { return wul3d::median(values_); }

private:
    std::vector<double> values_;
    std::uint64_t seen_ = 0;
    std::mt19937_64 rng_{1};
};

/// The stage times of the frames, for summary.json's medians.
struct StageLog {
    std::map<std::string, MedianSample> stage_ms;
    MedianSample compute_ms;

    void add(const StageTimes& t, double output_ms) {
        stage_ms["registration"].add(t.registration);
        stage_ms["decimation"].add(t.decimation);
        stage_ms["backprojection"].add(t.backprojection);
        stage_ms["normals"].add(t.normals);
        stage_ms["background"].add(t.background);
        stage_ms["clustering"].add(t.clustering);
        stage_ms["colors"].add(t.colors);
        stage_ms["plane"].add(t.plane);
        stage_ms["segmentation"].add(t.segmentation);
        stage_ms["objects"].add(t.objects);
        stage_ms["overlap"].add(t.overlap);
        stage_ms["output"].add(output_ms);
        compute_ms.add(t.total());
    }
    nlohmann::json medians() const {
        nlohmann::json m = nlohmann::json::object();
        for (const auto& [stage, values] : stage_ms) m[stage] = values.median();
        return m;
    }
};

/// OUT/frames.jsonl: one line per frame written, appended and flushed as each frame is
/// done, so that it is complete up to the last frame however the run ends, and nothing of
/// it stays in memory.
class FramesLog {
public:
    explicit FramesLog(const std::string& path) : path_(path) {
        // A new file (a link or a FIFO under the name is refused, never followed), appended
        // to: each line lands whole at its end.
        fd_ = open_new_append_file(path);
    }
    ~FramesLog() { ::close(fd_); }
    FramesLog(const FramesLog&) = delete;
    FramesLog& operator=(const FramesLog&) = delete;

    void append(const nlohmann::json& line) {
        const std::string text = json_text(line) + "\n";
        std::size_t done = 0;
        while (done < text.size()) {
            const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0)
                throw IoError(path_ + ": cannot write (" +
                              (n < 0 ? std::string(std::strerror(errno)) : "short write") + ")");
            done += static_cast<std::size_t>(n);
        }
    }

private:
    std::string path_;
    int fd_ = -1;
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
    FrameOutputs outputs(const OutputFiles& files) const {
        FrameOutputs o;
        o.selected = cluster ? &cluster_mask : nullptr;
        o.selected_object = object ? &object_mask : nullptr;
        o.selected_id = object_selected ? object->label() : 0;
        o.files = files;
        return o;
    }
};

/// Refuses an output folder that is, holds or lies in an input: the outputs would replace
/// the recording's files (a frame's folder and OUT/<frame>/ would be one).
void check_out_apart_from_inputs(const RunOptions& o) {
    std::vector<std::string> inputs;
    if (!o.feed.input.empty()) inputs.push_back(o.feed.input);
    const std::string& calib = o.feed.source.calibration;
    if (!calib.empty() && calib != "kinect_v2") inputs.push_back(calib);
    check_write_target(o.out_dir, WriteTarget::Folder, inputs, "output folder");
}

/// How a run shares its worker threads (threads.hpp's count, all cores by default): a
/// quarter of them, 1 to 4, write (a frame's outputs cost about as much as its processing),
/// as many read (decoding a frame costs about what writing its outputs does: 10 and 8 ms at
/// 640x480 on the 2-core machine), and the stages take the rest, at least one. On 2 cores
/// the stages then run on one thread beside the reader and the writer: alternated on
/// osd_mosd, that ran the whole command 1.5 times as fast as the stages on both cores
/// fighting them for the cores (docs/SPEED.md, "The command end to end").
struct RunThreads {
    int total, readers, writers, stages;
};
int run_writers(int total) { return std::clamp(total / 4, 1, 4); }
/// `readers`: the threads that read (a camera's capture thread; fewer than wanted where the
/// recording has no second reader, FrameSource::clone).
RunThreads run_threads(int readers) {
    const int total = num_threads();
    const int writers = run_writers(total);
    return {total, readers, writers, std::max(1, total - readers - writers)};
}

/// summary.json's frame-independent part.
nlohmann::json summary_json(const RunOptions& o, const FrameFeed& feed, const RunSummary& s,
                            const StageLog& log, const Selection& selection,
                            const RunThreads& threads) {
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
    summary["error"] = s.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.error);
    summary["parameters"] = parameters_json(o.params, o.preset);
    summary["outputs"] = output_files_names(o.files);  // what each OUT/<frame>/ holds
    summary["frames"] = s.frames;
    summary["frames_file"] = kFramesFile;
    summary["threads"] = threads.total;
    summary["threads_stages"] = threads.stages;
    summary["threads_readers"] = threads.readers;
    summary["threads_writers"] = threads.writers;
    summary["stage_ms_median"] = log.medians();
    summary["ms_per_frame_median"] = s.ms_per_frame_median;
    summary["fps"] = s.fps;
    summary["wall_s"] = s.wall_s;
    summary["fps_end_to_end"] = s.end_to_end_fps;
    summary["peak_rss_mb"] = s.peak_rss_mb;
    if (selection.cluster) summary["selected_cluster"] = selection.cluster->cluster();
    return summary;
}


/// A processed frame on its way to disk (WriteBehind's job): what write_frame, frames.jsonl
/// and the observer read, taken out of the pipeline so that the next frame can be processed
/// while this one is written.
struct PendingFrame {
    std::string name;
    SourceItem input;       // the frame as read (swapped in, not copied)
    RgbdFrame registered;   // a raw frame's registration (copied: the pipeline keeps its own)
    FrameResult result;     // the fields the outputs read (copied)
    OrganizedCloud cloud;   // the stages' cloud, for cloud.ply; unused when `has_cloud` is false
    bool has_cloud = false;
    std::vector<std::uint8_t> cluster_mask, object_mask;
    FrameOutputs outputs;   // its masks point into the two above
    nlohmann::json line;    // frames.jsonl's line
    double output_ms = 0;   // the writer's time

    const RgbdFrame& frame() const { return input.is_raw ? registered : input.frame; }
};

/// Fills `p` with the frame just processed. Costs a copy of the result's images (a few MB at
/// 640x480, reusing `p`'s buffers), against the PNG encoding it takes off the loop.
void take_frame(PendingFrame& p, const std::string& name, SourceItem& item, const Pipeline& pipeline,
                const FrameResult& r, const Selection& selection, const RunOptions& o) {
    p.name = name;
    std::swap(p.input, item);  // `item` gets p's old buffers for the next read
    if (p.input.is_raw) p.registered = pipeline.registered();
    FrameResult& c = p.result;  // not active, plane_classes, segments: no output reads them
    c.labels = r.labels;
    c.colors = r.colors;
    c.objects = r.objects;
    c.object_list = r.object_list;
    c.active_points = r.active_points;
    c.stats = r.stats;
    c.plane = r.plane;
    c.segment_stats = r.segment_stats;
    c.times = r.times;
    p.has_cloud = o.files.ply && pipeline.cloud().size() == r.labels.labels.size();
    if (p.has_cloud) p.cloud = pipeline.cloud();
    p.outputs = selection.outputs(o.files);
    if (p.outputs.selected) {
        p.cluster_mask = *p.outputs.selected;
        p.outputs.selected = &p.cluster_mask;
    }
    if (p.outputs.selected_object) {
        p.object_mask = *p.outputs.selected_object;
        p.outputs.selected_object = &p.object_mask;
    }
    p.line = frame_json(name, r);
    if (selection.cluster) p.line["selected_pixels"] = selection.cluster->pixels();
}

/// The calling thread's OpenMP team size for a scope (an OpenMP setting of each thread: other
/// threads' pipelines keep theirs), then back.
class ScopedTeam {
public:
    explicit ScopedTeam(int n) : previous_(omp_get_max_threads()) { omp_set_num_threads(n); }
    ~ScopedTeam() { omp_set_num_threads(previous_); }
    ScopedTeam(const ScopedTeam&) = delete;
    ScopedTeam& operator=(const ScopedTeam&) = delete;

private:
    int previous_;
};

}  // namespace

namespace {

using Clock = std::chrono::steady_clock;

/// One run of run_sequence: the feed, the pipeline and the writers behind it, and the
/// phases in order (open, then step until the end, drain, finish). Its members live as long
/// as the run; the writers stop (and join) before what they write from goes.
class RunLoop {
public:
    RunLoop(const RunOptions& o, RunObserver& obs)
        : o_(o), obs_(obs), feed_(feed_options(o), o.stop), n_total_(open_out_dir()),
          lock_(o.out_dir), pipeline_(o.params), selection_(o.select) {
        remove_stale_temporaries(o.out_dir);  // of a run killed mid-write (SIGKILL, power)
    }

    /// Runs every frame, then writes summary.json; rethrows the error that ended the run.
    RunSummary run() {
        obs_.started(n_total_);  // may refuse the run (a video writer that cannot start)
        FramesLog frames_log((out_dir() / kFramesFile).string());
        frames_log_ = &frames_log;
        const ScopedTeam stages_team(threads_.stages);
        detail::WriteBehind<PendingFrame, detail::PngEncoder> writes(
            static_cast<std::size_t>(threads_.writers) + 2, threads_.writers,
            [this](PendingFrame& p, detail::PngEncoder& encoder) { write(p, encoder); });
        writes_ = &writes;
        try {
            while (step()) {}
            while (commit(true)) {}
        } catch (const std::exception& e) {
            fail(e);
            // The frames processed before a bad input frame are still written and listed;
            // after a failed write, none is listed past it.
            try {
                while (!write_failed_ && commit(true)) {}
            } catch (const std::exception&) {
            }
        }
        try {
            obs_.frames_done();  // e.g. a video that cannot be finished: an error like a frame's
        } catch (const std::exception& e) {
            if (!failed_) fail(e);
        }
        return finish();
    }

private:
    static FeedOptions feed_options(const RunOptions& o) {
        FeedOptions f = o.feed;
        f.read_ahead = 2;  // the next frames decode while this one is processed
        f.readers = static_cast<std::size_t>(run_writers(num_threads()));  // RunThreads
        return f;
    }
    fs::path out_dir() const { return fs::path(o_.out_dir); }

    /// OUT checked against the inputs and every frame's name, then made ready; returns the
    /// frames to run (a recording's length, or max_frames; 0 = until the camera ends).
    std::size_t open_out_dir() {
        check_out_apart_from_inputs(o_);
        if (!feed_.live()) {
            // Every name before the first frame: a run must not fail at frame 50,000 for it.
            for (std::size_t i = 0; i < feed_.size(); ++i) check_frame_name(feed_.source()->name(i));
        }
        const std::size_t n = feed_.live() ? o_.max_frames
                                           : (o_.max_frames ? std::min(o_.max_frames, feed_.size())
                                                            : feed_.size());
        prepare_out_dir(o_.out_dir, o_.overwrite);
        return n;
    }

    /// A writer thread's job: one frame's folder, with the writer's encoder.
    void write(PendingFrame& p, detail::PngEncoder& encoder) const {
        omp_set_num_threads(1);  // a writer's overlay is one thread's work among several
        const auto t0 = Clock::now();
        detail::write_frame(o_.out_dir, p.name, p.has_cloud ? &p.cloud : nullptr, p.frame(), p.result,
                            p.outputs, encoder);
        p.output_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }

    /// The oldest frame in flight, once written: its line in frames.jsonl, the observer, the
    /// count, on this thread and in frame order. False when none is (or, without `wait`, not
    /// yet). Rethrows its write's error.
    bool commit(bool wait) {
        std::exception_ptr error;
        const PendingFrame* p = writes_->oldest(wait, error);
        if (!p) return false;
        writes_->release();  // safe to read *p below: only next() refills a slot, on this thread
        if (error) {
            write_failed_ = true;
            std::rethrow_exception(error);
        }
        log_.add(p->result.times, p->output_ms);
        frames_log_->append(p->line);
        const double fps = 1000.0 / std::max(1e-9, log_.compute_ms.median());
        obs_.frame(RunFrame{p->name, s_.frames, n_total_, p->frame(), p->result,
                            p->outputs.selected, p->outputs.selected_id, fps});
        ++s_.frames;
        return true;
    }

    /// One turn of the loop: commit what is written, then read and process the next frame and
    /// hand it to the writers. False at the end (all frames, a stop, the feed's end).
    bool step() {
        while (commit(false)) {}
        if (n_total_ && taken_ >= n_total_) {
            s_.stopped_by = feed_.live() || n_total_ < feed_.size() ? "frames" : "end";
            return false;
        }
        if (writes_->full()) {
            commit(true);
            return true;
        }
        if (!feed_.next_frame(item_, s_.stopped_by, lost_)) return false;
        const std::string name = feed_.name();
        if (feed_.live()) check_frame_name(name);
        const FrameResult* result = process(name);
        if (!result) {  // SIGINT/SIGTERM mid-frame: this frame is not written
            s_.stopped_by = "signal";
            return false;
        }
        const RgbdFrame& frame = item_.is_raw ? pipeline_.registered() : item_.frame;
        if (!frame.has_color() && !said_depth_only_) {
            obs_.note(name + " has no colour image; clustering on position and normals only");
            said_depth_only_ = true;
        }
        selection_.update(*result);
        take_frame(writes_->next(), name, item_, pipeline_, *result, selection_, o_);
        writes_->submit();
        ++taken_;
        return true;
    }

    /// The pipeline on the frame read; nullptr when a stop request ended it mid-frame. An
    /// InputError names its frame ("image_0003: k = 7 is larger...").
    const FrameResult* process(const std::string& name) {
        try {
            return item_.is_raw ? &pipeline_.process(item_.raw, *feed_.calibration(),
                                                     o_.feed.source.registration)
                                : &pipeline_.process(item_.frame);
        } catch (const Stopped&) {
            return nullptr;
        } catch (const InputError& e) {
            const std::string what = e.what();
            if (what.rfind(name + ": ", 0) == 0) throw;
            throw InputError(name + ": " + what);
        }
    }

    /// A bad frame, a full disk: the frames before it are complete, and summary.json says
    /// what ended the run.
    void fail(const std::exception& e) {
        failed_ = std::current_exception();
        s_.stopped_by = "error";
        s_.error = e.what();
    }

    /// The summary's figures, summary.json, then the error that ended the run if any.
    RunSummary finish() {
        s_.ms_per_frame_median = log_.compute_ms.median();
        s_.fps = s_.ms_per_frame_median > 0 ? 1000.0 / s_.ms_per_frame_median : 0.0;
        s_.peak_rss_mb = peak_rss_mb();
        s_.wall_s = std::chrono::duration<double>(Clock::now() - start_).count();
        s_.end_to_end_fps = s_.wall_s > 0 ? static_cast<double>(s_.frames) / s_.wall_s : 0.0;
        if (lost_) {
            try {
                std::rethrow_exception(lost_);
            } catch (const std::exception& e) {
                s_.error = e.what();
            }
        }
        try {
            write_text_file((out_dir() / kSummaryFile).string(),
                            json_text(summary_json(o_, feed_, s_, log_, selection_, threads_), 2) + "\n");
        } catch (const std::exception&) {
            if (!failed_) throw;  // the first error is the one to report (a full disk, twice)
        }
        if (failed_) std::rethrow_exception(failed_);
        obs_.finished(s_);
        if (lost_) std::rethrow_exception(lost_);
        if (feed_.live() && s_.frames == 0)
            throw InputError(feed_.description() + ": ended before the first frame");
        return s_;
    }

    const RunOptions& o_;
    RunObserver& obs_;
    FrameFeed feed_;
    std::size_t n_total_;     // frames to run; 0 = until a live camera ends
    const OutputLock lock_;   // one writer at a time: frames.jsonl would interleave
    Pipeline pipeline_;
    Selection selection_;
    SourceItem item_;
    StageLog log_;
    RunSummary s_;
    const RunThreads threads_ = run_threads(feed_.live() ? 1 : static_cast<int>(feed_.readers()));
    const Clock::time_point start_ = Clock::now();
    FramesLog* frames_log_ = nullptr;                      // run()'s, while it runs
    detail::WriteBehind<PendingFrame, detail::PngEncoder>* writes_ = nullptr;  // run()'s, while it runs
    bool said_depth_only_ = false;
    bool write_failed_ = false;
    std::size_t taken_ = 0;      // frames processed and handed to the writers
    std::exception_ptr lost_;    // DeviceLost: rethrown once the outputs are final
    std::exception_ptr failed_;  // any other error: rethrown once summary.json is written
};

}  // namespace

RunSummary run_sequence(const RunOptions& o, RunObserver* observer) {
    RunObserver silent;
    RunLoop loop(o, observer ? *observer : silent);
    return loop.run();
}

}  // namespace wul3d
