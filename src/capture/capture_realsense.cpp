// Intel RealSense cameras through librealsense2, which Debian 12 does not package: this file
// is compiled only when pkg-config finds realsense2 (docs/CAMERAS.md says how to build it).
// NOT COMPILED OR RUN in wul3d's own CI: written against librealsense2's public C++ API, with
// no device and no library at hand. Check it on a device before relying on it.
//
// Depth (Z16) and colour (RGB8) at 640x480, 30 FPS; frames are raw and the pipeline registers
// them depth-to-colour with the device's own intrinsics, extrinsic and depth scale (wul3d's
// registration, not rs2::align, so that every camera goes through the same step).
#include <librealsense2/rs.hpp>

#include <cstring>

#include "backends.hpp"
#include "wul3d/error.hpp"

namespace wul3d::detail {

namespace {

PinholeIntrinsics to_pinhole(const rs2_intrinsics& k) {
    return PinholeIntrinsics{k.width, k.height, k.fx, k.fy, k.ppx, k.ppy};
}

class RealSenseCamera final : public CameraDevice {
public:
    explicit RealSenseCamera(const std::string& serial) : pipe_(ctx_) {
        try {
            if (ctx_.query_devices().size() == 0) throw InputError("no RealSense camera found");
            rs2::config cfg;
            if (!serial.empty()) cfg.enable_device(serial);
            cfg.enable_stream(RS2_STREAM_DEPTH, 640, 480, RS2_FORMAT_Z16, 30);
            cfg.enable_stream(RS2_STREAM_COLOR, 640, 480, RS2_FORMAT_RGB8, 30);
            if (!cfg.can_resolve(pipe_))
                throw InputError("RealSense " + serial + ": 640x480 Z16 depth and RGB8 colour at "
                                 "30 FPS not supported (or no such serial)");
            const rs2::pipeline_profile profile = pipe_.start(cfg);
            const auto depth = profile.get_stream(RS2_STREAM_DEPTH).as<rs2::video_stream_profile>();
            const auto color = profile.get_stream(RS2_STREAM_COLOR).as<rs2::video_stream_profile>();
            calib_.depth = to_pinhole(depth.get_intrinsics());
            calib_.color = to_pinhole(color.get_intrinsics());
            const rs2_extrinsics e = depth.get_extrinsics_to(color);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    calib_.rotation[3 * i + j] = e.rotation[3 * j + i];  // column-major in rs2
            for (int i = 0; i < 3; ++i) calib_.translation_m[i] = e.translation[i];
            calib_.depth_scale_m_per_unit =
                profile.get_device().first<rs2::depth_sensor>().get_depth_scale();
            calib_.validate();
            description_ = std::string("RealSense ") +
                           profile.get_device().get_info(RS2_CAMERA_INFO_NAME) + " " +
                           profile.get_device().get_info(RS2_CAMERA_INFO_SERIAL_NUMBER);
        } catch (const rs2::error& e) {
            throw InputError(std::string("RealSense: ") + e.what());
        }
    }

    ~RealSenseCamera() override {
        try {
            pipe_.stop();
        } catch (...) {
        }
    }

    std::string description() const override { return description_; }
    const StereoCalibration* calibration() const override { return &calib_; }

    GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) override {
        rs2::frameset frames;
        try {
            if (!pipe_.try_wait_for_frames(&frames, static_cast<unsigned>(timeout.count())))
                return GrabResult::Timeout;
        } catch (const rs2::error& e) {
            throw DeviceLost(description_ + ": lost (" + e.what() + ")");
        }
        const rs2::depth_frame depth = frames.get_depth_frame();
        const rs2::video_frame color = frames.get_color_frame();
        if (!depth || !color) return GrabResult::Timeout;
        item.is_raw = true;
        DepthImage& d = item.raw.depth;
        d.width = depth.get_width();
        d.height = depth.get_height();
        d.scale_m_per_unit = calib_.depth_scale_m_per_unit;
        d.data.resize(static_cast<std::size_t>(d.width) * d.height);
        for (int v = 0; v < d.height; ++v)
            std::memcpy(d.data.data() + static_cast<std::size_t>(v) * d.width,
                        static_cast<const unsigned char*>(depth.get_data()) +
                            static_cast<std::size_t>(v) * depth.get_stride_in_bytes(),
                        sizeof(std::uint16_t) * d.width);
        ColorImage& c = item.raw.color;
        c.width = color.get_width();
        c.height = color.get_height();
        c.rgb.resize(3 * static_cast<std::size_t>(c.width) * c.height);
        for (int v = 0; v < c.height; ++v)
            std::memcpy(c.rgb.data() + 3 * static_cast<std::size_t>(v) * c.width,
                        static_cast<const unsigned char*>(color.get_data()) +
                            static_cast<std::size_t>(v) * color.get_stride_in_bytes(),
                        3 * static_cast<std::size_t>(c.width));
        return GrabResult::Frame;
    }

private:
    rs2::context ctx_;
    rs2::pipeline pipe_;
    StereoCalibration calib_;
    std::string description_;
};

}  // namespace

std::unique_ptr<CameraDevice> open_realsense(const std::string& arg) {
    return std::make_unique<RealSenseCamera>(arg);
}

}  // namespace wul3d::detail
