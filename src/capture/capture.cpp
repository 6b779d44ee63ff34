// Live capture (capture.hpp): the camera spec, the backend dispatch and the capture thread
// with its single-slot mailbox. The backends are in src/capture/.
#include "wul3d/capture.hpp"

#include <cstdio>
#include <utility>

#include "backends.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

namespace {

struct Backend {
    const char* name;
    const char* what;     // the devices, for messages
    const char* package;  // what to build with
    bool built;
    std::unique_ptr<CameraDevice> (*open)(const std::string&);
};

[[maybe_unused]] std::unique_ptr<CameraDevice> not_built(const std::string&) { return nullptr; }

const Backend kBackends[] = {
#ifdef WUL3D_WITH_FREENECT
    {"freenect", "Kinect v1", "libfreenect-dev", true, detail::open_freenect},
#else
    {"freenect", "Kinect v1", "libfreenect-dev", false, not_built},
#endif
#ifdef WUL3D_WITH_OPENNI2
    {"openni2", "OpenNI2 devices and .oni files", "libopenni2-dev", true, detail::open_openni2},
#else
    {"openni2", "OpenNI2 devices and .oni files", "libopenni2-dev", false, not_built},
#endif
#ifdef WUL3D_WITH_FREENECT2
    {"freenect2", "Kinect v2", "libfreenect2", true, detail::open_freenect2},
#else
    {"freenect2", "Kinect v2", "libfreenect2", false, not_built},
#endif
#ifdef WUL3D_WITH_REALSENSE
    {"realsense", "Intel RealSense", "librealsense2", true, detail::open_realsense},
#else
    {"realsense", "Intel RealSense", "librealsense2", false, not_built},
#endif
};

std::string frame_name(std::uint64_t index) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "frame_%06llu", static_cast<unsigned long long>(index));
    return buf;
}

}  // namespace

CameraSpec parse_camera_spec(const std::string& text) {
    CameraSpec spec;
    spec.text = text;
    const auto colon = text.find(':');
    spec.backend = text.substr(0, colon);
    if (colon != std::string::npos) spec.arg = text.substr(colon + 1);
    for (const Backend& b : kBackends)
        if (spec.backend == b.name) return spec;
    std::string known;
    for (const Backend& b : kBackends) known += std::string(known.empty() ? "" : ", ") + b.name;
    throw ParamError("--camera '" + text + "': unknown camera backend (known: " + known + ")");
}

std::vector<std::string> camera_backends() {
    std::vector<std::string> names;
    for (const Backend& b : kBackends)
        if (b.built) names.emplace_back(b.name);
    return names;
}

std::unique_ptr<CameraDevice> open_camera(const CameraSpec& spec) {
    for (const Backend& b : kBackends) {
        if (spec.backend != b.name) continue;
        if (!b.built)
            throw InputError("--camera " + spec.text + ": this wul3d was built without " +
                             b.name + " (" + b.what + "); rebuild with " + b.package +
                             " installed (docs/CAMERAS.md)");
        return b.open(spec.arg);
    }
    throw ParamError("--camera '" + spec.text + "': unknown camera backend");
}

// ---- LiveSource -------------------------------------------------------------------------

LiveSource::LiveSource(std::unique_ptr<CameraDevice> camera, const LiveOptions& options)
    : camera_(std::move(camera)), options_(options) {
    if (!camera_) throw ParamError("LiveSource: no camera");
    description_ = camera_->description();
    calibration_ = camera_->calibration();
    thread_ = std::thread([this] { capture_loop(); });
}

LiveSource::~LiveSource() {
    stop();
    if (thread_.joinable()) thread_.join();
}

void LiveSource::stop() {
    stop_.store(true);
    cv_.notify_all();
}

void LiveSource::capture_loop() {
    using Clock = std::chrono::steady_clock;
    constexpr std::chrono::milliseconds kGrabTimeout{100};  // how often stop_ is looked at
    SourceItem back;  // filled here, then swapped into the slot
    std::uint64_t index = 0;
    auto last_frame = Clock::now();
    try {
        while (!stop_.load()) {
            const GrabResult g = camera_->grab(back, kGrabTimeout);
            if (g == GrabResult::End) break;
            if (g == GrabResult::Timeout) {
                if (Clock::now() - last_frame > options_.stall_timeout)
                    throw DeviceLost(description_ + ": no frame for " +
                                     std::to_string(options_.stall_timeout.count()) +
                                     " ms, the camera stopped or was disconnected");
                continue;
            }
            (back.is_raw ? back.raw.name : back.frame.name) = frame_name(index++);
            captured_.fetch_add(1);
            std::unique_lock lock(mutex_);
            if (options_.lossless) {
                // Replay: wait for processing to take the previous frame (with a timeout, so
                // that stop() is seen).
                while (slot_full_ && !stop_.load())
                    cv_.wait_for(lock, kGrabTimeout);
                if (stop_.load()) break;
            } else if (slot_full_) {
                dropped_.fetch_add(1);  // newest wins
            }
            std::swap(slot_, back);
            slot_full_ = true;
            lock.unlock();
            cv_.notify_all();
            last_frame = Clock::now();
        }
    } catch (...) {
        std::lock_guard lock(mutex_);
        error_ = std::current_exception();
    }
    {
        std::lock_guard lock(mutex_);
        ended_ = true;
    }
    cv_.notify_all();
}

LiveSource::Next LiveSource::next(SourceItem& item, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!cv_.wait_for(lock, timeout, [this] { return slot_full_ || ended_; }))
        return Next::Timeout;
    if (slot_full_) {
        std::swap(item, slot_);
        slot_full_ = false;
        lock.unlock();
        cv_.notify_all();
        return Next::Frame;
    }
    if (error_) std::rethrow_exception(error_);
    return Next::End;
}

}  // namespace wul3d
