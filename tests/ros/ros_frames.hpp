#pragma once
// Shared by the ROS tests (tests/ros/): wul3d frames as ROS 1 messages, for the bags the
// tests write and the frames the test publisher plays. C++17, like every file that includes
// ROS 1 message headers (cmake/Ros.cmake).
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstring>
#include <string>

#include "wul3d/frame.hpp"

namespace wul3d::test {

inline std_msgs::Header ros_header(ros::Time stamp, const std::string& frame_id, unsigned seq = 0) {
    std_msgs::Header h;
    h.stamp = stamp;
    h.frame_id = frame_id;
    h.seq = seq;
    return h;
}

/// 16UC1 (or another 16-bit encoding, e.g. RealSense's mono16), the frame's units.
inline sensor_msgs::Image depth_msg(const RgbdFrame& f, const std_msgs::Header& h,
                                    const std::string& encoding = "16UC1") {
    sensor_msgs::Image m;
    m.header = h;
    m.width = static_cast<std::uint32_t>(f.depth.width);
    m.height = static_cast<std::uint32_t>(f.depth.height);
    m.encoding = encoding;
    m.step = 2 * m.width;
    m.data.resize(2 * f.depth.data.size());
    std::memcpy(m.data.data(), f.depth.data.data(), m.data.size());
    return m;
}

/// 32FC1 metres (REP 118), 0 where the frame has no depth.
inline sensor_msgs::Image depth_msg_float(const RgbdFrame& f, const std_msgs::Header& h) {
    sensor_msgs::Image m;
    m.header = h;
    m.width = static_cast<std::uint32_t>(f.depth.width);
    m.height = static_cast<std::uint32_t>(f.depth.height);
    m.encoding = "32FC1";
    m.step = 4 * m.width;
    m.data.resize(4 * f.depth.data.size());
    for (std::size_t p = 0; p < f.depth.data.size(); ++p) {
        const float z = float(f.depth.data[p]) * f.depth.scale_m_per_unit;
        std::memcpy(m.data.data() + 4 * p, &z, 4);
    }
    return m;
}

/// rgb8 or bgr8, rows padded by `pad` bytes (step > 3 width) to exercise the step.
inline sensor_msgs::Image color_msg(const RgbdFrame& f, const std_msgs::Header& h,
                                    const std::string& encoding = "rgb8", unsigned pad = 0) {
    sensor_msgs::Image m;
    m.header = h;
    m.width = static_cast<std::uint32_t>(f.color.width);
    m.height = static_cast<std::uint32_t>(f.color.height);
    m.encoding = encoding;
    m.step = 3 * m.width + pad;
    m.data.assign(std::size_t(m.step) * m.height, 0);
    const bool bgr = encoding == "bgr8";
    for (std::uint32_t v = 0; v < m.height; ++v) {
        for (std::uint32_t u = 0; u < m.width; ++u) {
            const std::uint8_t* s = f.color.rgb.data() + 3 * (std::size_t(v) * m.width + u);
            std::uint8_t* d = m.data.data() + std::size_t(v) * m.step + 3 * u;
            d[0] = s[bgr ? 2 : 0];
            d[1] = s[1];
            d[2] = s[bgr ? 0 : 2];
        }
    }
    return m;
}

inline sensor_msgs::CameraInfo info_msg(const PinholeIntrinsics& K, const std_msgs::Header& h) {
    sensor_msgs::CameraInfo m;
    m.header = h;
    m.width = static_cast<std::uint32_t>(K.width);
    m.height = static_cast<std::uint32_t>(K.height);
    m.distortion_model = "plumb_bob";
    m.D.assign(5, 0.0);
    m.K = {K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1};
    m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.P = {K.fx, 0, K.cx, 0, 0, K.fy, K.cy, 0, 0, 0, 1, 0};
    return m;
}

}  // namespace wul3d::test
