#pragma once
/// @file feed.hpp
/// Where a run takes its frames from: a recording (FrameSource, one frame after the other)
/// or a live camera (LiveSource: its own capture thread, newest frame wins), behind one
/// loop step. A caller's stop request (e.g. the CLI's SIGINT handler) is polled, so that a
/// stopped run still finalizes its outputs.
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "wul3d/capture.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

/// What to read: exactly one of `input` and `camera`.
struct FeedOptions {
    std::string input;      ///< a recording (open_source), or
    std::string camera;     ///< a live camera, BACKEND[:ARG] (parse_camera_spec)
    bool lossless = false;  ///< camera only: capture waits for processing (replays, tests)
    SourceOptions source;   ///< how to read `input`
    /// Recording only: frames read ahead, per reader, on threads of their own while the
    /// caller processes the current one (0: each frame is read in next(), on the caller's
    /// thread).
    std::size_t read_ahead = 0;
    /// Recording, with read_ahead: threads that read at once, each with a decoder of its own
    /// (FrameSource::clone; one where the source has no second reader, as a bag).
    std::size_t readers = 1;
};

namespace detail {
class ReadAhead;
}

class FrameFeed {
public:
    enum class Status {
        Frame,   ///< `item` holds the next frame, named `name()`
        End,     ///< the recording or the replay ended
        Stopped, ///< `stop` returned true
    };

    /// Opens the camera or the recording. `stop`, if given, is polled between frames (and
    /// every 100 ms while a camera has none). Throws ParamError (both or neither of input
    /// and camera; --lossless without a camera) and what open_source / open_camera throw.
    explicit FrameFeed(const FeedOptions& options, std::function<bool()> stop = {});
    ~FrameFeed();
    FrameFeed(const FrameFeed&) = delete;
    FrameFeed& operator=(const FrameFeed&) = delete;

    /// Blocks until the next frame, the end, or a stop request (polled every 100 ms).
    /// Throws DeviceLost when the camera disappears, InputError for a damaged recording.
    Status next(SourceItem& item);
    /// The loop step `run` and `record` share: next() and what ended the feed. True with a
    /// frame in `item`; false at the end ("end" stays in `stopped_by`), on a stop request
    /// ("signal") or when the camera is lost ("device_lost", the DeviceLost kept in `lost`
    /// to be rethrown once the outputs are final).
    bool next_frame(SourceItem& item, std::string& stopped_by, std::exception_ptr& lost);
    /// Waits at most `timeout` (live: newest frame; recording: reads the next one).
    /// Returns Frame, End, Stopped, or, live only, no frame yet: `false` in `got`.
    Status poll(SourceItem& item, std::chrono::milliseconds timeout, bool& got);

    bool live() const { return live_ != nullptr; }
    const std::string& name() const { return name_; }  ///< name of the last frame
    const StereoCalibration* calibration() const;
    /// Recording: its frame count; live: 0 (unknown).
    std::size_t size() const { return source_ ? source_->size() : 0; }
    /// "recording" formats (frames, tum, unregistered) or "camera".
    std::string format() const;
    std::string description() const;  ///< camera description or input path
    std::uint64_t captured() const { return live_ ? live_->captured() : index_; }
    std::uint64_t dropped() const { return live_ ? live_->dropped() : 0; }
    /// Random access (recordings only; nullptr for a camera).
    FrameSource* source() { return source_.get(); }
    /// Threads reading the recording ahead (0: none, frames are read in next()).
    std::size_t readers() const { return readers_; }

private:
    bool stop_requested() const { return stop_ && stop_(); }

    std::unique_ptr<FrameSource> source_;
    std::vector<std::unique_ptr<FrameSource>> clones_;  // the further readers' sources
    std::unique_ptr<LiveSource> live_;
    std::unique_ptr<detail::ReadAhead> ahead_;  // declared after the sources: stops before they go
    std::size_t readers_ = 0;
    std::string input_;
    std::function<bool()> stop_;
    std::size_t index_ = 0;
    std::string name_;
};

}  // namespace wul3d
