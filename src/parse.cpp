// The numbers of the options shared by the command and the Python module (parse.hpp).
#include "wul3d/parse.hpp"

#include <sstream>
#include <stdexcept>

#include "wul3d/error.hpp"

namespace wul3d {

std::vector<double> parse_numbers(const std::string& flag, const std::string& text,
                                  std::size_t expected) {
    std::vector<double> values;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            std::size_t used = 0;
            values.push_back(std::stod(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::exception&) {
            throw ParamError(flag + " '" + text + "': '" + item + "' is not a number");
        }
    }
    if (values.size() != expected)
        throw ParamError(flag + " '" + text + "': expected " + std::to_string(expected) +
                         " comma-separated numbers");
    return values;
}

std::pair<int, int> select_pixel(double u, double v, const std::string& text) {
    // Checked before the conversion: a double outside int's range has no int value.
    for (const double c : {u, v})
        if (!(c >= 0 && c < kMaxSidePx))
            throw ParamError("--select '" + text + "': U and V must be pixels in [0, " +
                             std::to_string(kMaxSidePx) + ")");
    return {static_cast<int>(u), static_cast<int>(v)};
}

std::pair<int, int> parse_select(const std::string& text) {
    const std::vector<double> uv = parse_numbers("--select", text, 2);
    return select_pixel(uv[0], uv[1], text);
}

PinholeIntrinsics parse_intrinsics_override(const std::string& text) {
    const std::vector<double> v = parse_numbers("--intrinsics", text, 4);
    PinholeIntrinsics K;  // width and height 0: each frame's own size, checked then
    K.fx = v[0];
    K.fy = v[1];
    K.cx = v[2];
    K.cy = v[3];
    K.validate_unsized("--intrinsics '" + text + "'");
    return K;
}

}  // namespace wul3d
