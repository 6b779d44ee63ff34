// Kinect v2 (the paper's camera) through libfreenect2, which Debian 12 does not package: this
// file is compiled only when pkg-config finds freenect2 (docs/CAMERAS.md says how to build it).
// NOT COMPILED OR RUN in wul3d's own CI: written against libfreenect2 0.2's public API, with
// no device and no library at hand. Check it on a device before relying on it.
//
// Frames are raw (depth 512x424 in the IR camera, colour 1920x1080), and the pipeline
// registers them depth-to-colour with the device's own calibration: the colour-resolution
// cloud of the paper. The calibration is the device's IR and colour intrinsics; libfreenect2
// models the IR -> colour mapping with a polynomial plus a horizontal disparity term
// (shift_m / z, z in mm), which wul3d approximates by a pinhole pair with R = I and a baseline
// t_x = shift_m mm. Lens distortion is ignored.
#include <libfreenect2/frame_listener_impl.h>
#include <libfreenect2/libfreenect2.hpp>
#include <libfreenect2/logger.h>
#include <libfreenect2/packet_pipeline.h>

#include <cmath>
#include <cstring>

#include "backends.hpp"
#include "wul3d/error.hpp"

namespace wul3d::detail {

namespace {

class Freenect2Camera final : public CameraDevice {
public:
    explicit Freenect2Camera(const std::string& serial_arg)
        : listener_(libfreenect2::Frame::Color | libfreenect2::Frame::Depth) {
        libfreenect2::setGlobalLogger(nullptr);
        if (freenect2_.enumerateDevices() <= 0) throw InputError("no Kinect v2 found (libfreenect2)");
        serial_ = serial_arg.empty() ? freenect2_.getDefaultDeviceSerialNumber() : serial_arg;
        device_ = freenect2_.openDevice(serial_, new libfreenect2::CpuPacketPipeline());
        if (!device_)
            throw InputError("Kinect v2 " + serial_ + ": cannot open it (busy, or no such serial)");
        device_->setColorFrameListener(&listener_);
        device_->setIrAndDepthFrameListener(&listener_);
        if (!device_->start()) {
            device_->close();
            delete device_;
            throw InputError("Kinect v2 " + serial_ + ": cannot start streaming");
        }
        const auto ir = device_->getIrCameraParams();
        const auto c = device_->getColorCameraParams();
        calib_.depth = PinholeIntrinsics{512, 424, ir.fx, ir.fy, ir.cx, ir.cy};
        calib_.color = PinholeIntrinsics{1920, 1080, c.fx, c.fy, c.cx, c.cy};
        calib_.rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        calib_.translation_m = {c.shift_m / 1000.0, 0.0, 0.0};
        calib_.depth_scale_m_per_unit = 0.001f;
        calib_.validate();
    }

    ~Freenect2Camera() override {
        if (device_) {
            device_->stop();
            device_->close();
            delete device_;
        }
    }

    std::string description() const override { return "Kinect v2 " + serial_ + " (libfreenect2)"; }
    const StereoCalibration* calibration() const override { return &calib_; }

    GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) override {
        libfreenect2::FrameMap frames;
        if (!listener_.waitForNewFrame(frames, static_cast<int>(timeout.count())))
            return GrabResult::Timeout;
        const libfreenect2::Frame* rgb = frames[libfreenect2::Frame::Color];
        const libfreenect2::Frame* depth = frames[libfreenect2::Frame::Depth];
        item.is_raw = true;
        DepthImage& d = item.raw.depth;
        d.width = static_cast<int>(depth->width);
        d.height = static_cast<int>(depth->height);
        d.scale_m_per_unit = 0.001f;
        d.data.resize(static_cast<std::size_t>(d.width) * d.height);
        const auto* z = reinterpret_cast<const float*>(depth->data);  // millimetres
        for (std::size_t p = 0; p < d.data.size(); ++p)
            d.data[p] = std::isfinite(z[p]) && z[p] > 0 && z[p] < 65535
                            ? static_cast<std::uint16_t>(std::lround(z[p]))
                            : 0;
        ColorImage& c = item.raw.color;
        c.width = static_cast<int>(rgb->width);
        c.height = static_cast<int>(rgb->height);
        c.rgb.resize(3 * static_cast<std::size_t>(c.width) * c.height);
        const bool bgr = rgb->format == libfreenect2::Frame::BGRX;
        for (std::size_t p = 0; p < static_cast<std::size_t>(c.width) * c.height; ++p) {
            const unsigned char* px = rgb->data + 4 * p;
            c.rgb[3 * p + 0] = bgr ? px[2] : px[0];
            c.rgb[3 * p + 1] = px[1];
            c.rgb[3 * p + 2] = bgr ? px[0] : px[2];
        }
        listener_.release(frames);
        return GrabResult::Frame;
    }

private:
    libfreenect2::Freenect2 freenect2_;
    libfreenect2::SyncMultiFrameListener listener_;
    libfreenect2::Freenect2Device* device_ = nullptr;
    std::string serial_;
    StereoCalibration calib_;
};

}  // namespace

std::unique_ptr<CameraDevice> open_freenect2(const std::string& arg) {
    return std::make_unique<Freenect2Camera>(arg);
}

}  // namespace wul3d::detail
