#include "frame_feed.hpp"

#include <csignal>

#include "wul3d/error.hpp"
#include "wul3d/stop.hpp"

namespace wul3d::cli {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;

// Also the library's stop request, which the pipeline's stages check mid-frame.
extern "C" void on_stop_signal(int sig) {
    g_stop_signal = sig;
    wul3d::request_stop();
}

}  // namespace

void install_stop_signals() {
    g_stop_signal = 0;
    wul3d::clear_stop_request();
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;  // a second Ctrl-C kills at once
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

bool stop_requested() { return g_stop_signal != 0; }

void restore_signals() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

FrameFeed::FrameFeed(const PipelineOptions& o, const SourceOptions& source) : input_(o.input) {
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
        source_ = open_source(o.input, source);
    }
}

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
        source_->read(index_, item);
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

}  // namespace wul3d::cli
