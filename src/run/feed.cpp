// The frame feed of a run (feed.hpp): a recording or a live camera behind one loop step.
#include "wul3d/feed.hpp"

#include <algorithm>

#include "wul3d/error.hpp"
#include "read_ahead.hpp"

namespace wul3d {

FrameFeed::FrameFeed(const FeedOptions& o, std::function<bool()> stop)
    : input_(o.input), stop_(std::move(stop)) {
    if (!o.camera.empty() && !o.input.empty())
        throw ParamError("give an INPUT or --camera, not both");
    if (o.camera.empty() && o.input.empty())
        throw ParamError("an INPUT (frame folders, TUM RGB-D) or --camera is required");
    if (!o.camera.empty()) {
        const CameraSpec spec = parse_camera_spec(o.camera);
        LiveOptions live;
        live.lossless = o.lossless;
        live_ = std::make_unique<LiveSource>(open_camera(spec), live);
    } else {
        if (o.lossless) throw ParamError("--lossless needs --camera");
        source_ = open_source(o.input, o.source);
        if (o.read_ahead > 0) {
            std::vector<FrameSource*> readers{source_.get()};
            while (readers.size() < std::min(o.readers, source_->size())) {
                std::unique_ptr<FrameSource> clone = source_->clone();
                if (!clone) break;
                readers.push_back(clone.get());
                clones_.push_back(std::move(clone));
            }
            readers_ = readers.size();
            ahead_ = std::make_unique<detail::ReadAhead>(readers, source_->size(), o.read_ahead * readers_);
        }
    }
}

FrameFeed::~FrameFeed() = default;

const StereoCalibration* FrameFeed::calibration() const {
    return live_ ? live_->calibration() : source_->calibration();
}

std::string FrameFeed::format() const {
    return live_ ? "camera" : input_format_name(source_->format());
}

std::string FrameFeed::description() const { return live_ ? live_->description() : input_; }

FrameFeed::Status FrameFeed::poll(SourceItem& item, std::chrono::milliseconds timeout,
                                  bool& got) {
    got = false;
    if (stop_requested()) return Status::Stopped;
    if (!live_) {
        if (index_ >= source_->size()) return Status::End;
        if (ahead_) {
            if (!ahead_->next(item)) return Status::End;
        } else {
            source_->read(index_, item);
        }
        name_ = source_->name(index_++);
        got = true;
        return Status::Frame;
    }
    switch (live_->next(item, timeout)) {
        case LiveSource::Next::Frame:
            name_ = item.is_raw ? item.raw.name : item.frame.name;
            got = true;
            return Status::Frame;
        case LiveSource::Next::End:
            return Status::End;
        case LiveSource::Next::Timeout:
            break;
    }
    return stop_requested() ? Status::Stopped : Status::Frame;
}

FrameFeed::Status FrameFeed::next(SourceItem& item) {
    for (;;) {
        bool got = false;
        const Status s = poll(item, std::chrono::milliseconds(100), got);
        if (s != Status::Frame || got) return s;
    }
}

bool FrameFeed::next_frame(SourceItem& item, std::string& stopped_by, std::exception_ptr& lost) {
    Status status;
    try {
        status = next(item);
    } catch (const DeviceLost&) {
        lost = std::current_exception();
        stopped_by = "device_lost";
        return false;
    }
    if (status == Status::Stopped) stopped_by = "signal";
    return status == Status::Frame;
}

}  // namespace wul3d
