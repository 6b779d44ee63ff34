// The JSON files of io.hpp: intrinsics.json and the stereo calibration, read with their
// checks (one InputError naming the file and the key) and written.
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "json_text.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {
namespace {

nlohmann::json read_json(const std::string& path) {
    std::vector<unsigned char> bytes;
    detail::read_regular_file(path, kMaxJsonBytes, bytes);
    try {
        return nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::exception& e) {
        // Also out_of_range: a number such as 1e400 that no double holds.
        throw InputError(path + ": invalid JSON (" + e.what() + ")");
    }
}

const nlohmann::json& member(const std::string& path, const nlohmann::json& obj,
                             const std::string& prefix, const char* key) {
    if (!obj.is_object()) {
        throw InputError(path + ": " + (prefix.empty() ? "the top level" : "'" + prefix + "'") +
                         " must be a JSON object");
    }
    const auto it = obj.find(key);
    if (it == obj.end()) throw InputError(path + ": missing key '" + prefix + key + "'");
    return *it;
}

double number(const std::string& path, const nlohmann::json& obj, const std::string& prefix,
              const char* key) {
    const nlohmann::json& v = member(path, obj, prefix, key);
    if (!v.is_number()) throw InputError(path + ": key '" + prefix + key + "' must be a number");
    return v.get<double>();
}

int integer(const std::string& path, const nlohmann::json& obj, const std::string& prefix,
            const char* key) {
    const double v = number(path, obj, prefix, key);
    if (v != std::floor(v) || v < 0 || v > 1e6) {
        throw InputError(path + ": key '" + prefix + key + "' must be a whole number of pixels");
    }
    return static_cast<int>(v);
}

float depth_scale(const std::string& path, const nlohmann::json& obj) {
    // Optional: 16-bit depth in millimetres is the common default (OpenNI, RealSense, Kinect).
    if (!obj.contains("depth_scale_m_per_unit")) return 0.001f;
    const double s = number(path, obj, "", "depth_scale_m_per_unit");
    // 1 um to 1 m per unit: 16-bit depth then reaches from 65 mm to 65 km.
    if (!(s >= 1e-6 && s <= 1.0)) {
        throw InputError(path + ": key 'depth_scale_m_per_unit' = " + detail::number_str(s) +
                         ": must be in [1e-6, 1] metres per unit");
    }
    return static_cast<float>(s);
}

PinholeIntrinsics intrinsics_from(const std::string& path, const nlohmann::json& obj,
                                  const std::string& prefix) {
    PinholeIntrinsics K;
    K.fx = number(path, obj, prefix, "fx");
    K.fy = number(path, obj, prefix, "fy");
    K.cx = number(path, obj, prefix, "cx");
    K.cy = number(path, obj, prefix, "cy");
    K.width = integer(path, obj, prefix, "width");
    K.height = integer(path, obj, prefix, "height");
    try {
        K.validate(prefix.empty() ? "intrinsics" : prefix.substr(0, prefix.size() - 1));
    } catch (const ParamError& e) {
        throw InputError(path + ": " + e.what());
    }
    return K;
}

nlohmann::json intrinsics_to_json(const PinholeIntrinsics& K) {
    return {{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy},
            {"width", K.width}, {"height", K.height}};
}

/// The float's shortest decimal form as a double: 0.001f is written "0.001", not
/// "0.0010000000474974513".
double float_for_json(float f) {
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, f);
    return std::strtod(std::string(buf, res.ptr).c_str(), nullptr);
}

}  // namespace

IntrinsicsFile read_intrinsics_json(const std::string& path) {
    const nlohmann::json j = read_json(path);
    IntrinsicsFile f;
    f.intrinsics = intrinsics_from(path, j, "");
    f.depth_scale_m_per_unit = depth_scale(path, j);
    return f;
}

StereoCalibration read_calibration_json(const std::string& path) {
    const nlohmann::json j = read_json(path);
    StereoCalibration c;
    c.depth = intrinsics_from(path, member(path, j, "", "depth"), "depth.");
    c.color = intrinsics_from(path, member(path, j, "", "color"), "color.");
    const nlohmann::json& ext = member(path, j, "", "depth_to_color");
    auto read_array = [&](const char* key, double* dst, std::size_t n) {
        const nlohmann::json& a = member(path, ext, "depth_to_color.", key);
        if (!a.is_array() || a.size() != n) {
            throw InputError(path + ": key 'depth_to_color." + key + "' must be an array of " +
                             std::to_string(n) + " numbers");
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (!a[i].is_number()) {
                throw InputError(path + ": key 'depth_to_color." + key + "' must hold numbers only");
            }
            dst[i] = a[i].get<double>();
        }
    };
    read_array("rotation", c.rotation.data(), 9);
    read_array("translation_m", c.translation_m.data(), 3);
    c.depth_scale_m_per_unit = depth_scale(path, j);
    try {
        c.validate();
    } catch (const ParamError& e) {
        throw InputError(path + ": " + e.what());
    }
    return c;
}

void write_calibration_json(const std::string& path, const StereoCalibration& calib) {
    nlohmann::json j;
    j["depth"] = intrinsics_to_json(calib.depth);
    j["color"] = intrinsics_to_json(calib.color);
    j["depth_to_color"] = {{"rotation", calib.rotation}, {"translation_m", calib.translation_m}};
    j["depth_scale_m_per_unit"] = float_for_json(calib.depth_scale_m_per_unit);
    write_text_file(path, json_text(j, 2) + "\n");
}

}  // namespace wul3d
