// Kinect v1 through libfreenect (Debian: libfreenect-dev). The raw 11-bit depth mode, the one
// mode fakenect replays, converted to millimetres with the Kinect v1 disparity model and left
// in the IR camera: the frames are raw, and the pipeline registers them to colour with
// kinect_v1_calibration() (kinect_v1.hpp, docs/CAMERAS.md).
//
// Only functions that fakenect's stand-in libfreenect also provides are used (no
// freenect_sync, no freenect_registration), so `fakenect DUMP wul3d ...` runs this file
// unchanged. Under fakenect (FAKENECT_PATH is set) freenect_process_events fails once the
// dump's INDEX.txt is exhausted: that is the end of the replay, not a lost device.
#include <libfreenect.h>
#include <sys/time.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "backends.hpp"
#include "wul3d/error.hpp"
#include "wul3d/kinect_v1.hpp"

namespace wul3d::detail {

namespace {

constexpr std::size_t kPixels = static_cast<std::size_t>(kKinectV1Width) * kKinectV1Height;

class FreenectCamera final : public CameraDevice {
public:
    explicit FreenectCamera(int index) : index_(index), calib_(kinect_v1_calibration()) {
        const char* fake = std::getenv("FAKENECT_PATH");
        replay_ = fake != nullptr && *fake != '\0';
        const std::string who = "Kinect v1 #" + std::to_string(index);
        if (freenect_init(&ctx_, nullptr) < 0 || ctx_ == nullptr)
            throw InputError("no Kinect v1 found (libfreenect cannot use USB)");
        freenect_set_log_level(ctx_, FREENECT_LOG_FATAL);
        freenect_select_subdevices(ctx_, FREENECT_DEVICE_CAMERA);
        const int count = freenect_num_devices(ctx_);
        if (count <= 0) fail("no Kinect v1 found (libfreenect)");
        if (index_ >= count)
            fail("no " + who + " (" + std::to_string(count) + " Kinect v1 found, #0 to #" +
                 std::to_string(count - 1) + ")");
        if (freenect_open_device(ctx_, &dev_, index_) < 0 || dev_ == nullptr) {
            dev_ = nullptr;
            fail(who + ": cannot open it (busy in another program, or no permission on its "
                       "USB device)");
        }
        freenect_set_user(dev_, this);
        freenect_set_depth_callback(dev_, &FreenectCamera::on_depth);
        freenect_set_video_callback(dev_, &FreenectCamera::on_video);
        const freenect_frame_mode depth_mode =
            freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT);
        const freenect_frame_mode video_mode =
            freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB);
        if (!depth_mode.is_valid || !video_mode.is_valid ||
            freenect_set_depth_mode(dev_, depth_mode) < 0 ||
            freenect_set_video_mode(dev_, video_mode) < 0)
            fail(who + ": 640x480 11-bit depth and RGB colour not supported");
        if (freenect_start_depth(dev_) < 0 || freenect_start_video(dev_) < 0)
            fail(who + ": cannot start streaming (busy in another program?)");
        raw_depth_.resize(kPixels);
        color_.width = kKinectV1Width;
        color_.height = kKinectV1Height;
        color_.rgb.resize(3 * kPixels);
        description_ = who + (replay_ ? " (libfreenect, fakenect replay)" : " (libfreenect)");
    }

    ~FreenectCamera() override { close(); }

    std::string description() const override { return description_; }
    const StereoCalibration* calibration() const override { return &calib_; }

    GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) override {
        using Clock = std::chrono::steady_clock;
        const auto deadline = Clock::now() + timeout;
        // A frame is the first depth and colour images that both arrived since the last
        // frame; a newer image of one kind replaces an older one still waiting for its pair.
        while (!(have_depth_ && have_color_)) {
            if (ended_) return GrabResult::End;
            const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
                deadline - Clock::now());
            if (left.count() <= 0) return GrabResult::Timeout;
            timeval tv{};
            tv.tv_sec = static_cast<time_t>(left.count() / 1000000);
            tv.tv_usec = static_cast<suseconds_t>(left.count() % 1000000);
            const int r = freenect_process_events_timeout(ctx_, &tv);
            if (r < 0) {
                if (replay_) {
                    ended_ = true;  // fakenect: the dump is exhausted
                    return GrabResult::End;
                }
                throw DeviceLost(description_ + ": lost (libfreenect error " +
                                 std::to_string(r) + "), the camera was disconnected");
            }
        }
        have_depth_ = have_color_ = false;
        item.is_raw = true;
        kinect_v1_raw_to_depth(raw_depth_.data(), item.raw.depth);
        item.raw.color.width = color_.width;
        item.raw.color.height = color_.height;
        item.raw.color.rgb = color_.rgb;
        return GrabResult::Frame;
    }

private:
    [[noreturn]] void fail(const std::string& message) {
        close();
        throw InputError(message);
    }

    void close() {
        if (dev_) {
            freenect_stop_depth(dev_);
            freenect_stop_video(dev_);
            freenect_close_device(dev_);
            dev_ = nullptr;
        }
        if (ctx_) {
            freenect_shutdown(ctx_);
            ctx_ = nullptr;
        }
    }

    static void on_depth(freenect_device* dev, void* depth, std::uint32_t) {
        auto* self = static_cast<FreenectCamera*>(freenect_get_user(dev));
        std::memcpy(self->raw_depth_.data(), depth, kPixels * sizeof(std::uint16_t));
        self->have_depth_ = true;
    }
    static void on_video(freenect_device* dev, void* rgb, std::uint32_t) {
        auto* self = static_cast<FreenectCamera*>(freenect_get_user(dev));
        std::memcpy(self->color_.rgb.data(), rgb, 3 * kPixels);
        self->have_color_ = true;
    }

    int index_;
    StereoCalibration calib_;
    bool replay_ = false;
    bool ended_ = false;
    freenect_context* ctx_ = nullptr;
    freenect_device* dev_ = nullptr;
    std::string description_;
    // Written by the callbacks, which run inside freenect_process_events on the grab thread.
    std::vector<std::uint16_t> raw_depth_;
    ColorImage color_;
    bool have_depth_ = false, have_color_ = false;
};

}  // namespace

std::unique_ptr<CameraDevice> open_freenect(const std::string& arg) {
    int index = 0;
    if (!arg.empty()) {
        char* end = nullptr;
        const long v = std::strtol(arg.c_str(), &end, 10);
        if (*end != '\0' || v < 0 || v > 64)
            throw ParamError("--camera freenect:" + arg + ": the index must be 0, 1, ...");
        index = static_cast<int>(v);
    }
    return std::make_unique<FreenectCamera>(index);
}

}  // namespace wul3d::detail
