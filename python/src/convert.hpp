#pragma once
// Between numpy arrays and wul3d's images: the checks a caller's arrays must pass (one-line
// messages naming the argument), and the copies out of a FrameResult. Used by module.cpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>

#include "wul3d/camera.hpp"
#include "wul3d/frame.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::python {
namespace py = pybind11;

// ---- one Python value, named: every keyword and option goes through these -------------
// A wrong type raises TypeError "NAME: expected an int, got str"; an int that does not fit
// the C++ type raises ValueError "NAME = 1099511627776: out of range". pybind11's own casts
// would raise RuntimeError "Unable to cast" (inside a dict) or a TypeError naming nothing.

/// An int (Python int, numpy integer; not bool, not float) that fits in [lo, hi].
long long to_int(const py::handle& v, const std::string& name, long long lo, long long hi);
/// A non-negative int that fits 64 bits (a seed).
std::uint64_t to_uint64(const py::handle& v, const std::string& name);
/// A real number (int or float, numpy's too; not bool, not str).
double to_double(const py::handle& v, const std::string& name);
/// True or False (numpy.bool_ too); not 0, 1 or a string.
bool to_bool(const py::handle& v, const std::string& name);
/// A str.
std::string to_string(const py::handle& v, const std::string& name);
/// A file name: str, bytes or os.PathLike, as the file system spells it (os.fsencode: a
/// name that is not UTF-8 passes unchanged).
std::string to_path(const py::handle& v, const std::string& name);

/// The C++ type T from `v` by the functions above (int, long long, std::uint64_t, float,
/// double, bool, std::string).
template <typename T>
T to_value(const py::handle& v, const std::string& name);

/// The same, None -> nullopt.
template <typename T>
std::optional<T> to_optional(const py::handle& v, const std::string& name) {
    if (v.is_none()) return std::nullopt;
    return to_value<T>(v, name);
}

/// The caller's colour and depth arrays, checked (dtype, shape, C order, sizes agree); the
/// pointers stay valid while the arrays are held. Checked with the GIL held; read without.
struct FrameArrays {
    bool has_color = false;  ///< false: depth only (`color` is then an empty array)
    py::array color;
    py::array depth;
    bool depth_is_float = false;  ///< float32 metres, else uint16 units of depth_scale
    int width = 0, height = 0;
};

/// Throws TypeError (dtype, not an array) or ValueError (shape, order, empty) naming the
/// argument.
FrameArrays check_frame_arrays(const py::object& color, const py::object& depth);

/// wul3d.Intrinsics, or a dict with fx, fy, cx, cy (as in intrinsics.json; width and height
/// there must match the arrays when given). Finite values, fx, fy > 0, else ValueError.
/// width = height = 0: an override for frames of any size, checked without a size.
PinholeIntrinsics to_intrinsics(const py::object& intrinsics, int width, int height);

/// An override for every frame (wul3d.run's and wul3d.read's `intrinsics`): "fx,fy,cx,cy"
/// parsed as `--intrinsics` (wul3d/parse.hpp), wul3d.Intrinsics or a dict; checked without
/// a size.
PinholeIntrinsics intrinsics_override(const py::object& intrinsics);

/// Copies the arrays into `frame`'s reused buffers (float32 depth; uint16 depth goes through
/// the library's frame view instead, module.cpp) (no allocation after the first frame of a
/// size). float32 metres are stored in units of 0.1 mm, or coarser when the farthest depth
/// would not fit 16 bits; NaN, infinite and non-positive depths become 0 (no depth). Runs
/// without the GIL.
void fill_frame(const FrameArrays& a, float depth_scale, RgbdFrame& frame);

/// (H, W) uint16 and (H, W, 3) uint8 copies of an image of the result.
py::array_t<std::uint16_t> to_array(const LabelImage& image);
py::array_t<std::uint8_t> to_array(const ColorImage& image);
py::array_t<std::uint16_t> to_array(const DepthImage& image);

/// A (H, W) uint16 label image from any integer array in [0, 65535] (TypeError, ValueError).
LabelImage to_label_image(const py::object& array, const char* what);

}  // namespace wul3d::python
