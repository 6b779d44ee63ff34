#include "convert.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "wul3d/io.hpp"
#include "wul3d/parse.hpp"

namespace wul3d::python {

namespace {

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) {
        if (i) s += ", ";
        s += std::to_string(a.shape(i));
    }
    return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

py::array as_array(const py::object& o, const char* what) {
    if (!py::isinstance<py::array>(o))
        throw py::type_error(std::string(what) + ": expected a numpy array, got " +
                             py::str(py::type::of(o).attr("__name__")).cast<std::string>());
    return py::reinterpret_borrow<py::array>(o);
}

void require_c_order(const py::array& a, const char* what) {
    if (!(a.flags() & py::array::c_style))
        throw py::value_error(std::string(what) +
                              ": array is not C-contiguous (pass numpy.ascontiguousarray(" +
                              what + "))");
}

}  // namespace

namespace {

std::string text_of(const py::handle& v) { return py::str(v).cast<std::string>(); }

std::string type_name(const py::handle& v) {
    return py::str(py::type::of(v).attr("__name__")).cast<std::string>();
}

[[noreturn]] void wrong_type(const py::handle& v, const std::string& name, const char* expected) {
    throw py::type_error(name + ": expected " + expected + ", got " + type_name(v));
}

bool is_numpy_bool(const py::handle& v) {
    const py::handle type = py::type::of(v);
    return py::str(type.attr("__module__")).cast<std::string>() == "numpy" &&
           py::str(type.attr("__name__")).cast<std::string>().rfind("bool", 0) == 0;
}

/// `v` as a Python int (int or numpy integer), else nothing.
std::optional<py::int_> as_int(const py::handle& v) {
    if (PyBool_Check(v.ptr()) || is_numpy_bool(v) || !PyIndex_Check(v.ptr())) return std::nullopt;
    return py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
}

}  // namespace

long long to_int(const py::handle& v, const std::string& name, long long lo, long long hi) {
    const std::optional<py::int_> i = as_int(v);
    if (!i || !i->ptr()) {
        PyErr_Clear();
        wrong_type(v, name, "an int");
    }
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(i->ptr(), &overflow);
    if (overflow || x < lo || x > hi)
        throw py::value_error(name + " = " + text_of(*i) + ": must be in [" +
                              std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return x;
}

std::uint64_t to_uint64(const py::handle& v, const std::string& name) {
    const std::optional<py::int_> i = as_int(v);
    if (!i || !i->ptr()) {
        PyErr_Clear();
        wrong_type(v, name, "an int");
    }
    const unsigned long long x = PyLong_AsUnsignedLongLong(i->ptr());
    if (PyErr_Occurred()) {  // negative or over 64 bits
        PyErr_Clear();
        throw py::value_error(name + " = " + text_of(*i) +
                              ": must be in [0, 2^64)");
    }
    return x;
}

double to_double(const py::handle& v, const std::string& name) {
    const bool number = PyFloat_Check(v.ptr()) || PyIndex_Check(v.ptr()) ||
                        (Py_TYPE(v.ptr())->tp_as_number && Py_TYPE(v.ptr())->tp_as_number->nb_float);
    if (!number || PyBool_Check(v.ptr()) || is_numpy_bool(v) || PyUnicode_Check(v.ptr()) ||
        PyBytes_Check(v.ptr()) || PyComplex_Check(v.ptr()))
        wrong_type(v, name, "a number");
    const double x = PyFloat_AsDouble(v.ptr());
    if (x == -1.0 && PyErr_Occurred()) {  // an int past double's range
        PyErr_Clear();
        throw py::value_error(name + " = " + text_of(v) + ": too large for a number");
    }
    return x;
}

bool to_bool(const py::handle& v, const std::string& name) {
    if (PyBool_Check(v.ptr())) return v.ptr() == Py_True;
    if (is_numpy_bool(v)) return PyObject_IsTrue(v.ptr()) == 1;
    wrong_type(v, name, "True or False");
}

std::string to_string(const py::handle& v, const std::string& name) {
    if (!PyUnicode_Check(v.ptr())) wrong_type(v, name, "a str");
    return v.cast<std::string>();
}

std::string to_path(const py::handle& v, const std::string& name) {
    py::object path = py::reinterpret_steal<py::object>(PyOS_FSPath(v.ptr()));
    if (!path) {
        PyErr_Clear();
        wrong_type(v, name, "a path (str, bytes or os.PathLike)");
    }
    if (PyUnicode_Check(path.ptr())) {
        path = py::reinterpret_steal<py::object>(PyUnicode_EncodeFSDefault(path.ptr()));
        if (!path) throw py::error_already_set();
    }
    std::string out(PyBytes_AS_STRING(path.ptr()), static_cast<std::size_t>(PyBytes_GET_SIZE(path.ptr())));
    if (out.find('\0') != std::string::npos)
        throw py::value_error(name + ": a path with a NUL byte");
    return out;
}

template <>
int to_value<int>(const py::handle& v, const std::string& name) {
    return static_cast<int>(to_int(v, name, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
}
template <>
long long to_value<long long>(const py::handle& v, const std::string& name) {
    return to_int(v, name, std::numeric_limits<long long>::min(), std::numeric_limits<long long>::max());
}
template <>
std::uint64_t to_value<std::uint64_t>(const py::handle& v, const std::string& name) {
    return to_uint64(v, name);
}
template <>
double to_value<double>(const py::handle& v, const std::string& name) {
    return to_double(v, name);
}
template <>
float to_value<float>(const py::handle& v, const std::string& name) {
    const double x = to_double(v, name);
    // Past float's range: infinity (the checks refuse it), not the undefined conversion.
    if (std::isfinite(x) && std::fabs(x) > double(std::numeric_limits<float>::max()))
        return x > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
    return static_cast<float>(x);
}
template <>
bool to_value<bool>(const py::handle& v, const std::string& name) {
    return to_bool(v, name);
}
template <>
std::string to_value<std::string>(const py::handle& v, const std::string& name) {
    return to_string(v, name);
}

FrameArrays check_frame_arrays(const py::object& color, const py::object& depth) {
    FrameArrays a;
    a.depth = as_array(depth, "depth");
    if (py::isinstance<py::array_t<std::uint16_t>>(a.depth)) {
        a.depth_is_float = false;
    } else if (py::isinstance<py::array_t<float>>(a.depth)) {
        a.depth_is_float = true;
    } else {
        throw py::type_error("depth: dtype " + dtype_text(a.depth) +
                             ", expected uint16 (units of depth_scale) or float32 (metres)");
    }
    if (a.depth.ndim() != 2)
        throw py::value_error("depth: shape " + shape_text(a.depth) + ", expected (H, W)");
    if (a.depth.shape(0) == 0 || a.depth.shape(1) == 0)
        throw py::value_error("depth: empty image " + shape_text(a.depth));
    // The readers' limits (io.hpp, the command's --max-pixels; wul3d.set_max_pixels), before
    // the pipeline allocates anything for the frame.
    const auto h = static_cast<std::uint64_t>(a.depth.shape(0));
    const auto w = static_cast<std::uint64_t>(a.depth.shape(1));
    if (h > kMaxImageSide || w > kMaxImageSide || h * w > max_image_pixels())
        throw py::value_error("depth: image " + shape_text(a.depth) + " is larger than the limit of " +
                              std::to_string(max_image_pixels()) + " pixels and " +
                              std::to_string(kMaxImageSide) + " a side (wul3d.set_max_pixels)");
    require_c_order(a.depth, "depth");
    a.height = static_cast<int>(a.depth.shape(0));
    a.width = static_cast<int>(a.depth.shape(1));

    if (!color.is_none()) {
        a.color = as_array(color, "color");
        if (!py::isinstance<py::array_t<std::uint8_t>>(a.color))
            throw py::type_error("color: dtype " + dtype_text(a.color) +
                                 ", expected uint8 (H, W, 3) RGB");
        if (a.color.ndim() != 3 || a.color.shape(2) != 3)
            throw py::value_error("color: shape " + shape_text(a.color) +
                                  ", expected (H, W, 3) RGB");
        if (a.color.shape(0) != a.height || a.color.shape(1) != a.width)
            throw py::value_error("color " + shape_text(a.color) + " and depth " +
                                  shape_text(a.depth) + " differ in size");
        require_c_order(a.color, "color");
        a.has_color = true;
    }
    return a;
}

PinholeIntrinsics to_intrinsics(const py::object& intrinsics, int width, int height) {
    PinholeIntrinsics K;
    if (py::isinstance<PinholeIntrinsics>(intrinsics)) {
        K = intrinsics.cast<PinholeIntrinsics>();
    } else if (py::isinstance<py::dict>(intrinsics)) {
        const auto d = py::reinterpret_borrow<py::dict>(intrinsics);
        for (const char* key : {"fx", "fy", "cx", "cy"}) {
            if (!d.contains(key))
                throw py::value_error(std::string("intrinsics: dict has no '") + key +
                                      "' (needs fx, fy, cx, cy)");
        }
        K.fx = to_double(d["fx"], "intrinsics['fx']");
        K.fy = to_double(d["fy"], "intrinsics['fy']");
        K.cx = to_double(d["cx"], "intrinsics['cx']");
        K.cy = to_double(d["cy"], "intrinsics['cy']");
        // Sizes past kMaxSidePx are refused by validate() with the intrinsics' message.
        if (d.contains("width")) K.width = to_value<int>(d["width"], "intrinsics['width']");
        if (d.contains("height")) K.height = to_value<int>(d["height"], "intrinsics['height']");
    } else {
        throw py::type_error("intrinsics: expected wul3d.Intrinsics or a dict with fx, fy, "
                             "cx, cy, got " +
                             py::str(py::type::of(intrinsics).attr("__name__")).cast<std::string>());
    }
    if (width == 0 && height == 0) {  // an override for frames of any size (--intrinsics)
        K.width = K.height = 0;
        K.validate_unsized("intrinsics");
        return K;
    }
    if ((K.width != 0 || K.height != 0) && !K.same_size(width, height))
        throw py::value_error("intrinsics: for a " + std::to_string(K.width) + "x" +
                              std::to_string(K.height) + " image, the arrays are " +
                              std::to_string(width) + "x" + std::to_string(height));
    K.width = width;
    K.height = height;
    K.validate("intrinsics");  // ParamError -> ValueError (module.cpp)
    return K;
}

PinholeIntrinsics intrinsics_override(const py::object& intrinsics) {
    if (py::isinstance<py::str>(intrinsics))
        return parse_intrinsics_override(intrinsics.cast<std::string>());
    return to_intrinsics(intrinsics, 0, 0);  // each frame's own size
}

void fill_frame(const FrameArrays& a, float depth_scale, RgbdFrame& frame) {
    const std::size_t n = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
    frame.depth.width = a.width;
    frame.depth.height = a.height;
    frame.depth.data.resize(n);
    if (!a.depth_is_float) {
        frame.depth.scale_m_per_unit = depth_scale;
        std::memcpy(frame.depth.data.data(), a.depth.data(), n * sizeof(std::uint16_t));
    } else {
        const float* z = static_cast<const float*>(a.depth.data());
        float z_max = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (std::isfinite(z[i])) z_max = std::max(z_max, z[i]);
        // 0.1 mm steps keep sensor precision to 6.5 m; farther scenes get coarser steps.
        const float scale = std::max(1e-4f, z_max / 65535.0f);
        frame.depth.scale_m_per_unit = scale;
        for (std::size_t i = 0; i < n; ++i) {
            const float units = z[i] / scale;
            frame.depth.data[i] = std::isfinite(units) && units > 0.5f
                                      ? static_cast<std::uint16_t>(std::min(65535.0f, std::round(units)))
                                      : std::uint16_t{0};
        }
    }
    if (a.has_color) {
        frame.color.width = a.width;
        frame.color.height = a.height;
        frame.color.rgb.resize(3 * n);
        std::memcpy(frame.color.rgb.data(), a.color.data(), 3 * n);
    } else {
        frame.color = ColorImage{};
    }
}

py::array_t<std::uint16_t> to_array(const LabelImage& image) {
    py::array_t<std::uint16_t> out({image.height, image.width});
    std::memcpy(out.mutable_data(), image.labels.data(), image.labels.size() * sizeof(std::uint16_t));
    return out;
}

py::array_t<std::uint16_t> to_array(const DepthImage& image) {
    py::array_t<std::uint16_t> out({image.height, image.width});
    std::memcpy(out.mutable_data(), image.data.data(), image.data.size() * sizeof(std::uint16_t));
    return out;
}

py::array_t<std::uint8_t> to_array(const ColorImage& image) {
    py::array_t<std::uint8_t> out({image.height, image.width, 3});
    std::memcpy(out.mutable_data(), image.rgb.data(), image.rgb.size());
    return out;
}

LabelImage to_label_image(const py::object& object, const char* what) {
    const py::array a = as_array(object, what);
    const char kind = a.dtype().kind();
    if (kind != 'u' && kind != 'i')
        throw py::type_error(std::string(what) + ": dtype " + dtype_text(a) +
                             ", expected an integer label image");
    if (a.ndim() != 2)
        throw py::value_error(std::string(what) + ": shape " + shape_text(a) + ", expected (H, W)");
    const auto wide = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    LabelImage out;
    out.height = static_cast<int>(a.shape(0));
    out.width = static_cast<int>(a.shape(1));
    out.labels.resize(static_cast<std::size_t>(wide.size()));
    const std::int64_t* v = wide.data();
    for (std::size_t i = 0; i < out.labels.size(); ++i) {
        if (v[i] < 0 || v[i] > 65535)
            throw py::value_error(std::string(what) + ": label " + std::to_string(v[i]) +
                                  " outside [0, 65535]");
        out.labels[i] = static_cast<std::uint16_t>(v[i]);
    }
    return out;
}

}  // namespace wul3d::python
