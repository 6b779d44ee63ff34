#pragma once
/// @file ros_image.hpp
/// What a ROS sensor_msgs/Image or CameraInfo holds, turned into wul3d's images, with no ROS
/// type in sight: the bag reader (bag.hpp) and the node (apps/wul3d_ros/, docs/ROS.md) share
/// it, and it builds without ROS.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "wul3d/camera.hpp"
#include "wul3d/image.hpp"

namespace wul3d {

/// The fields of a sensor_msgs/Image; `data` is the caller's, `size` bytes.
struct RosImage {
    std::uint32_t width = 0, height = 0;
    std::uint32_t step = 0;      ///< bytes from one row to the next (>= width x pixel size)
    std::string encoding;        ///< sensor_msgs/image_encodings: "16UC1", "rgb8", ...
    bool big_endian = false;
    const std::uint8_t* data = nullptr;
    std::size_t size = 0;
};

/// The fields of a ROS 1 sensor_msgs::Image (or anything with its members), without
/// including ROS here; `m` must outlive the result.
template <class ImageMsg>
RosImage ros_image_of(const ImageMsg& m) {
    RosImage r;
    r.width = m.width;
    r.height = m.height;
    r.step = m.step;
    r.encoding = m.encoding;
    r.big_endian = m.is_bigendian != 0;
    r.data = m.data.data();
    r.size = m.data.size();
    return r;
}

/// 16UC1, mono16 (units as the caller says; REP 118: millimetres) and 32FC1 (metres).
bool is_ros_depth_encoding(const std::string& encoding);
/// rgb8, bgr8, rgba8, bgra8, mono8.
bool is_ros_color_encoding(const std::string& encoding);

/// Depth into `out` (buffer reused). 16-bit encodings keep their values, at
/// `scale_m_per_unit`; 32FC1 metres become millimetres (scale 0.001): NaN, infinite, zero or
/// negative depth, and depth of 65.5 m or more, becomes 0 (no depth). InputError starting
/// with `what` for another encoding, a size of 0 or over max_image_pixels() (io.hpp), or
/// data shorter than step x height.
void depth_from_ros(const std::string& what, const RosImage& image, float scale_m_per_unit,
                    DepthImage& out);
/// Colour into `out` as RGB (alpha dropped, grey expanded); errors as depth_from_ros.
void color_from_ros(const std::string& what, const RosImage& image, ColorImage& out);

/// A CameraInfo's size and K (row-major 3x3): fx = K[0], cx = K[2], fy = K[4], cy = K[5].
/// Distortion is ignored. Not validated: call validate().
PinholeIntrinsics intrinsics_from_ros(std::uint32_t width, std::uint32_t height,
                                      const std::array<double, 9>& K);

}  // namespace wul3d
