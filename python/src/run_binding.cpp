#include "run_binding.hpp"

#include <pybind11/stl.h>

#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "convert.hpp"
#include "params.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/registration.hpp"
#include "wul3d/write_guard.hpp"

#if __has_include("wul3d/run.hpp")
#include "wul3d/run.hpp"
#define WUL3D_PYTHON_HAS_RUN 1
#endif

namespace wul3d::python {

#ifdef WUL3D_PYTHON_HAS_RUN
namespace {

template <typename T>
std::optional<T> take(py::dict& d, const char* key) {
    if (!d.contains(key)) return std::nullopt;
    py::object v = d[key];
    PyDict_DelItemString(d.ptr(), key);
    if (v.is_none()) return std::nullopt;
    try {
        return v.cast<T>();
    } catch (const py::cast_error&) {
        throw py::type_error(std::string("run: option '") + key + "' has the wrong type (" +
                             py::str(py::type::of(v).attr("__name__")).cast<std::string>() + ")");
    }
}

/// "fx,fy,cx,cy" (as --intrinsics), wul3d.Intrinsics or a dict.
PinholeIntrinsics intrinsics_option(const py::object& v) {
    if (py::isinstance<py::str>(v)) {
        const std::string text = v.cast<std::string>();
        double x[4];
        char tail = 0;
        if (std::sscanf(text.c_str(), "%lf,%lf,%lf,%lf%c", &x[0], &x[1], &x[2], &x[3], &tail) != 4)
            throw ParamError("--intrinsics '" + text + "': expected 4 comma-separated numbers");
        if (!(x[0] > 0 && x[1] > 0))
            throw ParamError("--intrinsics '" + text + "': fx and fy must be > 0");
        PinholeIntrinsics K;
        K.fx = x[0];
        K.fy = x[1];
        K.cx = x[2];
        K.cy = x[3];
        K.validate_unsized("--intrinsics '" + text + "'");
        return K;
    }
    return to_intrinsics(v, 0, 0);  // each frame's own size
}

std::pair<int, int> select_option(const py::object& v) {
    if (py::isinstance<py::str>(v)) {
        const std::string text = v.cast<std::string>();
        double u = 0, w = 0;
        char tail = 0;
        if (std::sscanf(text.c_str(), "%lf,%lf%c", &u, &w, &tail) != 2)
            throw ParamError("--select '" + text + "': expected 2 comma-separated numbers");
        return {static_cast<int>(u), static_cast<int>(w)};
    }
    const auto uv = v.cast<std::pair<int, int>>();
    return uv;
}

RunOptions run_options(const std::string& input, const std::string& out, py::dict o) {
    RunOptions r;
    ParamArgs a;
    a.preset = take<std::string>(o, "preset");
    a.k = take<int>(o, "k");
    a.alpha = take<float>(o, "alpha");
    a.delta = take<float>(o, "delta");
    a.gamma = take<float>(o, "gamma");
    a.psi = take<float>(o, "psi");
    a.iters = take<int>(o, "iters");
    a.stride = take<int>(o, "stride");
    a.seed = take<std::uint64_t>(o, "seed");
    a.zmin = take<float>(o, "zmin");
    a.zmax = take<float>(o, "zmax");
    a.normal_radius = take<int>(o, "normal_radius");
    a.segmenter = take<std::string>(o, "segmenter");
    a.scope = take<std::string>(o, "scope");
    a.min_points = take<int>(o, "min_points");
    a.object_psi = take<float>(o, "object_psi");
    a.decimate = take<int>(o, "decimate");
    if (take<bool>(o, "no_plane").value_or(false)) a.remove_plane = false;
    r.params = make_params(a);
    r.preset = a.preset.value_or("");
    if (r.preset == "default") r.preset.clear();

    r.feed.input = input;
    SourceOptions& s = r.feed.source;
    s.format = parse_input_format(take<std::string>(o, "format").value_or("auto"));
    s.tum_camera = take<std::string>(o, "tum_camera").value_or("");
    s.calibration = take<std::string>(o, "calibration").value_or("");
    s.registration =
        parse_registration_mode(take<std::string>(o, "registration").value_or("depth-to-color"));
    if (o.contains("intrinsics")) {
        py::object v = o["intrinsics"];
        PyDict_DelItemString(o.ptr(), "intrinsics");
        if (!v.is_none()) s.intrinsics = intrinsics_option(v);
    }
    if (o.contains("select")) {
        py::object v = o["select"];
        PyDict_DelItemString(o.ptr(), "select");
        if (!v.is_none()) r.select = select_option(v);
    }
    const auto frames = take<long long>(o, "frames");
    if (frames && *frames < 1) throw ParamError("--frames " + std::to_string(*frames) + ": must be >= 1");
    r.max_frames = frames ? static_cast<std::size_t>(*frames) : 0;
    r.ply = take<bool>(o, "ply").value_or(false);
    r.overlay = take<bool>(o, "overlay").value_or(false);
    r.overwrite = take<bool>(o, "overwrite").value_or(false);
    r.out_dir = out;
    if (!o.empty()) {
        std::string keys;
        for (const auto& item : o) keys += (keys.empty() ? "" : ", ") + py::str(item.first).cast<std::string>();
        throw py::type_error("run: unknown option(s): " + keys);
    }
    return r;
}

}  // namespace

void bind_run(py::module_& m) {
    m.def(
        "_run",
        [](const std::string& input, const std::string& out, const py::dict& options) {
            const RunOptions r = run_options(input, out, options.attr("copy")());  // a copy to consume
            RunSummary s;
            {
                py::gil_scoped_release release;
                s = run_sequence(r);
            }
            return py::dict(py::arg("frames") = s.frames, py::arg("stopped_by") = s.stopped_by,
                            py::arg("ms_per_frame_median") = s.ms_per_frame_median,
                            py::arg("fps") = s.fps, py::arg("wall_s") = s.wall_s,
                            py::arg("peak_rss_mb") = s.peak_rss_mb);
        },
        py::arg("input"), py::arg("out"), py::arg("options"));
    m.def(
        "_check_run_options",
        [](const py::dict& options) { run_options("", "", options.attr("copy")()); },
        py::arg("options"), "Raises what _run would for these options, before any input is read.");
}
#else
void bind_run(py::module_&) {}  // the library has no run loop yet
#endif

void bind_write_guard(py::module_& m) {
    m.def(
        "_check_write_target",
        [](const std::string& target, const std::string& kind,
           const std::vector<std::string>& inputs, const std::string& flag) {
            if (kind != "file" && kind != "folder")
                throw py::value_error("kind '" + kind + "': must be 'file' or 'folder'");
            check_write_target(target, kind == "file" ? WriteTarget::File : WriteTarget::Folder,
                               inputs, flag);
        },
        py::arg("target"), py::arg("kind"), py::arg("inputs"), py::arg("flag") = "",
        "The library's guard of every write (wul3d/write_guard.hpp): raises wul3d.InputError "
        "unless `target` is apart from every input and not a link out.");
    py::class_<OutputLock>(m, "_OutputLock",
                           "The advisory lock of an output folder (wul3d/write_guard.hpp): "
                           "raises wul3d.InputError when another process writes it.")
        .def(py::init<const std::string&>(), py::arg("dir"));
    m.def("_remove_stale_temporaries", &remove_stale_temporaries, py::arg("dir"),
          "Removes the .wul3d.tmp-* / .wul3d.partial-* a killed writer left in `dir`.");
}

}  // namespace wul3d::python
