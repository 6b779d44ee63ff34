// OpenNI2 devices (Kinect v1 through a driver, Asus Xtion, Orbbec Astra, PrimeSense) and .oni
// recordings, through OpenNI2 (Debian: libopenni2-dev). The device registers depth to colour
// itself (IMAGE_REGISTRATION_DEPTH_TO_COLOR), so frames come out registered, with pinhole
// intrinsics from the colour stream's field of view (the paper's FOV model, camera.hpp).
// An .oni file given as the URI plays back through the same path, once (no repeat).
#include <OpenNI.h>

#include <chrono>
#include <cstring>
#include <filesystem>

#include "backends.hpp"
#include "wul3d/error.hpp"

namespace wul3d::detail {

namespace {

/// OpenNI's extended error, on one line.
std::string oni_error() {
    std::string s = openni::OpenNI::getExtendedError();
    for (char& c : s)
        if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    return s;
}

/// The supported mode of `stream` with this pixel format nearest 640x480 at 30 FPS, if any.
bool pick_mode(openni::VideoStream& stream, openni::PixelFormat format, openni::VideoMode& out) {
    const auto& modes = stream.getSensorInfo().getSupportedVideoModes();
    int best = -1;
    long best_cost = 0;
    for (int i = 0; i < modes.getSize(); ++i) {
        if (modes[i].getPixelFormat() != format) continue;
        const long cost = std::labs(modes[i].getResolutionX() - 640L) +
                          std::labs(modes[i].getResolutionY() - 480L) +
                          10L * std::labs(modes[i].getFps() - 30L);
        if (best < 0 || cost < best_cost) best = i, best_cost = cost;
    }
    if (best < 0) return false;
    out = modes[best];
    return true;
}

class OpenNI2Camera final : public CameraDevice {
public:
    explicit OpenNI2Camera(const std::string& uri) {
        if (!uri.empty() && !std::filesystem::exists(uri) &&
            (uri.size() > 4 && uri.compare(uri.size() - 4, 4, ".oni") == 0))
            throw InputError(uri + ": no such file or directory");
        if (openni::OpenNI::initialize() != openni::STATUS_OK)
            throw InputError("OpenNI2 cannot start: " + oni_error());
        initialized_ = true;
        const char* open_uri = uri.empty() ? openni::ANY_DEVICE : uri.c_str();
        if (device_.open(open_uri) != openni::STATUS_OK)
            fail(uri.empty() ? "no OpenNI2 device found (" + oni_error() + ")"
                             : "OpenNI2: cannot open '" + uri + "' (" + oni_error() + ")");
        file_ = device_.isFile();
        description_ = file_ ? "OpenNI2 recording " + uri
                             : std::string("OpenNI2 ") + device_.getDeviceInfo().getName() +
                                   " (" + device_.getDeviceInfo().getUri() + ")";
        if (!device_.hasSensor(openni::SENSOR_DEPTH) || !device_.hasSensor(openni::SENSOR_COLOR))
            fail(description_ + ": needs both a depth and a colour stream");
        if (depth_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK ||
            color_.create(device_, openni::SENSOR_COLOR) != openni::STATUS_OK)
            fail(description_ + ": cannot create the streams (" + oni_error() + ")");
        if (!file_) {
            openni::VideoMode mode;
            if (pick_mode(depth_, openni::PIXEL_FORMAT_DEPTH_1_MM, mode)) depth_.setVideoMode(mode);
            if (pick_mode(color_, openni::PIXEL_FORMAT_RGB888, mode)) color_.setVideoMode(mode);
            if (!device_.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) ||
                device_.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) !=
                    openni::STATUS_OK)
                fail(description_ + ": depth-to-colour registration not supported");
            device_.setDepthColorSyncEnabled(true);  // best effort
        } else if (openni::PlaybackControl* playback = device_.getPlaybackControl()) {
            playback->setRepeatEnabled(false);
        }
        const openni::VideoMode dm = depth_.getVideoMode(), cm = color_.getVideoMode();
        if (dm.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_1_MM &&
            dm.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_100_UM)
            fail(description_ + ": depth is not in millimetres or 100 um (unsupported mode)");
        if (cm.getPixelFormat() != openni::PIXEL_FORMAT_RGB888)
            fail(description_ + ": colour is not RGB888 (unsupported mode)");
        if (dm.getResolutionX() != cm.getResolutionX() || dm.getResolutionY() != cm.getResolutionY())
            fail(description_ + ": depth " + std::to_string(dm.getResolutionX()) + "x" +
                 std::to_string(dm.getResolutionY()) + " and colour " +
                 std::to_string(cm.getResolutionX()) + "x" + std::to_string(cm.getResolutionY()) +
                 " differ, so they are not registered (unsupported mode)");
        scale_ = dm.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ? 0.001f : 0.0001f;
        FovCamera fov;
        fov.width = cm.getResolutionX();
        fov.height = cm.getResolutionY();
        fov.fov_x_rad = color_.getHorizontalFieldOfView();
        fov.fov_y_rad = color_.getVerticalFieldOfView();
        intrinsics_ = fov.to_pinhole();
        if (depth_.start() != openni::STATUS_OK || color_.start() != openni::STATUS_OK)
            fail(description_ + ": cannot start streaming (busy?) (" + oni_error() + ")");
        started_ = true;
    }

    ~OpenNI2Camera() override { close(); }

    std::string description() const override { return description_; }

    GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) override {
        using Clock = std::chrono::steady_clock;
        const auto deadline = Clock::now() + timeout;
        openni::VideoStream* streams[2] = {&depth_, &color_};
        while (!(have_depth_ && have_color_)) {
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            if (left.count() <= 0) {
                // A recording played once: a second without frames after the last is its end.
                if (file_ && Clock::now() - last_frame_ > std::chrono::seconds(1))
                    return GrabResult::End;
                return GrabResult::Timeout;
            }
            int ready = -1;
            const openni::Status s = openni::OpenNI::waitForAnyStream(
                streams, 2, &ready, static_cast<int>(left.count()));
            if (s == openni::STATUS_TIME_OUT) continue;
            if (s != openni::STATUS_OK || ready < 0)
                throw DeviceLost(description_ + ": lost (" + oni_error() + ")");
            openni::VideoFrameRef& ref = ready == 0 ? depth_frame_ : color_frame_;
            if (streams[ready]->readFrame(&ref) != openni::STATUS_OK || !ref.isValid())
                throw DeviceLost(description_ + ": lost (" + oni_error() + ")");
            (ready == 0 ? have_depth_ : have_color_) = true;
            last_frame_ = Clock::now();
        }
        have_depth_ = have_color_ = false;
        const int w = depth_frame_.getWidth(), h = depth_frame_.getHeight();
        if (color_frame_.getWidth() != w || color_frame_.getHeight() != h)
            throw InputError(description_ + ": depth and colour frames differ in size");
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.intrinsics = intrinsics_;
        f.intrinsics.width = w;
        f.intrinsics.height = h;
        f.depth.width = f.color.width = w;
        f.depth.height = f.color.height = h;
        f.depth.scale_m_per_unit = scale_;
        f.depth.data.resize(static_cast<std::size_t>(w) * h);
        f.color.rgb.resize(3 * static_cast<std::size_t>(w) * h);
        const auto* dsrc = static_cast<const unsigned char*>(depth_frame_.getData());
        const auto* csrc = static_cast<const unsigned char*>(color_frame_.getData());
        for (int v = 0; v < h; ++v) {
            std::memcpy(f.depth.data.data() + static_cast<std::size_t>(v) * w,
                        dsrc + static_cast<std::size_t>(v) * depth_frame_.getStrideInBytes(),
                        sizeof(std::uint16_t) * w);
            std::memcpy(f.color.rgb.data() + 3 * static_cast<std::size_t>(v) * w,
                        csrc + static_cast<std::size_t>(v) * color_frame_.getStrideInBytes(),
                        3 * static_cast<std::size_t>(w));
        }
        return GrabResult::Frame;
    }

private:
    [[noreturn]] void fail(const std::string& message) {
        close();
        throw InputError(message);
    }

    void close() {
        if (started_) {
            depth_.stop();
            color_.stop();
            started_ = false;
        }
        depth_frame_.release();
        color_frame_.release();
        depth_.destroy();
        color_.destroy();
        if (device_.isValid()) device_.close();
        if (initialized_) {
            openni::OpenNI::shutdown();
            initialized_ = false;
        }
    }

    openni::Device device_;
    openni::VideoStream depth_, color_;
    openni::VideoFrameRef depth_frame_, color_frame_;
    bool initialized_ = false, started_ = false, file_ = false;
    bool have_depth_ = false, have_color_ = false;
    float scale_ = 0.001f;
    PinholeIntrinsics intrinsics_;
    std::string description_;
    std::chrono::steady_clock::time_point last_frame_ = std::chrono::steady_clock::now();
};

}  // namespace

std::unique_ptr<CameraDevice> open_openni2(const std::string& arg) {
    return std::make_unique<OpenNI2Camera>(arg);
}

}  // namespace wul3d::detail
