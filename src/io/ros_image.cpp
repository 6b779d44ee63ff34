// ROS image messages' contents to wul3d images (ros_image.hpp); no ROS headers here.
#include "wul3d/ros_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

namespace {

/// The first byte of the image's rows, after checking its size against its data.
const std::uint8_t* checked_rows(const std::string& what, const RosImage& img,
                                 std::size_t bytes_per_pixel) {
    if (img.width == 0 || img.height == 0 || img.width > kMaxImageSide ||
        img.height > kMaxImageSide || std::uint64_t{img.width} * img.height > max_image_pixels()) {
        throw InputError(what + ": image of " + std::to_string(img.width) + "x" +
                         std::to_string(img.height) + " is empty or over the limit");
    }
    const std::uint64_t row = std::uint64_t{img.width} * bytes_per_pixel;
    const std::uint64_t need = std::max<std::uint64_t>(row, img.step) * img.height;
    if (img.step < row || need > img.size || img.data == nullptr) {
        throw InputError(what + ": " + img.encoding + " image of " + std::to_string(img.width) +
                         "x" + std::to_string(img.height) + " with step " +
                         std::to_string(img.step) + " needs " + std::to_string(need) +
                         " bytes but has " + std::to_string(img.size));
    }
    return img.data;
}

}  // namespace

bool is_ros_depth_encoding(const std::string& e) {
    return e == "16UC1" || e == "mono16" || e == "32FC1";
}

bool is_ros_color_encoding(const std::string& e) {
    return e == "rgb8" || e == "bgr8" || e == "rgba8" || e == "bgra8" || e == "mono8";
}

void depth_from_ros(const std::string& what, const RosImage& img, float scale_m_per_unit,
                    DepthImage& out) {
    if (!is_ros_depth_encoding(img.encoding)) {
        throw InputError(what + ": depth encoding '" + img.encoding +
                         "' is not read (16UC1, mono16, 32FC1 are)");
    }
    const bool is_float = img.encoding == "32FC1";
    const std::size_t bpp = is_float ? 4 : 2;
    const std::uint8_t* src = checked_rows(what, img, bpp);
    const std::size_t w = img.width, h = img.height;
    out.width = static_cast<int>(w);
    out.height = static_cast<int>(h);
    out.data.resize(w * h);
    out.scale_m_per_unit = is_float ? 0.001f : scale_m_per_unit;
    const bool swap = img.big_endian;  // the machines wul3d runs on are little-endian
    for (std::size_t v = 0; v < h; ++v) {
        const std::uint8_t* row = src + v * img.step;
        std::uint16_t* dst = out.data.data() + v * w;
        if (!is_float && !swap) {
            std::memcpy(dst, row, 2 * w);
            continue;
        }
        for (std::size_t u = 0; u < w; ++u) {
            std::uint8_t b[4];
            std::memcpy(b, row + u * bpp, bpp);
            if (swap) std::reverse(b, b + bpp);
            if (!is_float) {
                std::memcpy(&dst[u], b, 2);
                continue;
            }
            float z;
            std::memcpy(&z, b, 4);
            const float mm = z * 1000.0f;  // 32FC1 is metres (REP 118)
            dst[u] = std::isfinite(mm) && mm >= 0.5f && mm < 65535.5f
                         ? static_cast<std::uint16_t>(std::lround(mm))
                         : std::uint16_t{0};
        }
    }
}

void color_from_ros(const std::string& what, const RosImage& img, ColorImage& out) {
    const std::string& e = img.encoding;
    if (!is_ros_color_encoding(e)) {
        throw InputError(what + ": colour encoding '" + e +
                         "' is not read (rgb8, bgr8, rgba8, bgra8, mono8 are)");
    }
    const std::size_t bpp = e == "mono8" ? 1 : (e == "rgba8" || e == "bgra8") ? 4 : 3;
    const std::uint8_t* src = checked_rows(what, img, bpp);
    const bool bgr = e == "bgr8" || e == "bgra8";
    const std::size_t w = img.width, h = img.height;
    out.width = static_cast<int>(w);
    out.height = static_cast<int>(h);
    out.rgb.resize(3 * w * h);
    for (std::size_t v = 0; v < h; ++v) {
        const std::uint8_t* row = src + v * img.step;
        std::uint8_t* dst = out.rgb.data() + 3 * v * w;
        if (e == "rgb8") {
            std::memcpy(dst, row, 3 * w);
            continue;
        }
        for (std::size_t u = 0; u < w; ++u, row += bpp, dst += 3) {
            if (bpp == 1) {
                dst[0] = dst[1] = dst[2] = row[0];
            } else {
                dst[0] = row[bgr ? 2 : 0];
                dst[1] = row[1];
                dst[2] = row[bgr ? 0 : 2];
            }
        }
    }
}

PinholeIntrinsics intrinsics_from_ros(std::uint32_t width, std::uint32_t height,
                                      const std::array<double, 9>& K) {
    PinholeIntrinsics out;
    out.width = static_cast<int>(std::min<std::uint32_t>(width, 1u << 30));
    out.height = static_cast<int>(std::min<std::uint32_t>(height, 1u << 30));
    out.fx = K[0];
    out.fy = K[4];
    out.cx = K[2];
    out.cy = K[5];
    return out;
}

}  // namespace wul3d
