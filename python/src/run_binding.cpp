#include "run_binding.hpp"

#include <pybind11/stl.h>

#include <chrono>
#include <csignal>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "convert.hpp"
#include "params.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/parse.hpp"
#include "wul3d/registration.hpp"
#include "wul3d/stop.hpp"
#include "wul3d/output.hpp"
#include "wul3d/write_guard.hpp"

#if __has_include("wul3d/run.hpp")
#include "wul3d/run.hpp"
#define WUL3D_PYTHON_HAS_RUN 1
#endif

namespace wul3d::python {

#ifdef WUL3D_PYTHON_HAS_RUN
namespace {

/// wul3d.run(select=...): "u,v" as `--select` (the library's parser, parse.hpp), or a pair
/// of numbers given to the same bound check.
std::pair<int, int> select_option(const py::object& v) {
    if (py::isinstance<py::str>(v)) return parse_select(v.cast<std::string>());
    if (!py::isinstance<py::sequence>(v) || py::len(v) != 2)
        throw py::type_error("select: expected \"u,v\" or a pair (u, v), got " +
                             py::str(py::type::of(v).attr("__name__")).cast<std::string>());
    const auto pair = py::reinterpret_borrow<py::sequence>(v);
    const double u = to_double(pair[0], "select[0]"), w = to_double(pair[1], "select[1]");
    return select_pixel(u, w, py::str(v).cast<std::string>());
}

/// Removes `key` from `o`; its value unless absent or None.
std::optional<py::object> pop(py::dict& o, const char* key) {
    if (!o.contains(key)) return std::nullopt;
    py::object v = o[key];
    PyDict_DelItemString(o.ptr(), key);
    if (v.is_none()) return std::nullopt;
    return v;
}

RunOptions run_options(const std::string& input, const std::string& out, py::dict o) {
    RunOptions r;
    ParamArgs a = take_param_args(o);
    if (take<bool>(o, "no_plane").value_or(false)) a.given.emplace_back("remove_plane", false);
    r.params = make_params(a);
    r.preset = a.preset == "default" ? "" : a.preset;

    r.feed.input = input;
    SourceOptions& s = r.feed.source;
    s.format = parse_input_format(take<std::string>(o, "format").value_or("auto"));
    s.tum_camera = take<std::string>(o, "tum_camera").value_or("");
    if (const auto v = pop(o, "calibration")) s.calibration = to_path(*v, "calibration");
    s.registration =
        parse_registration_mode(take<std::string>(o, "registration").value_or("depth-to-color"));
    if (const auto v = pop(o, "intrinsics")) s.intrinsics = intrinsics_override(*v);
    if (const auto v = pop(o, "select")) r.select = select_option(*v);
    const auto frames = take<long long>(o, "frames");
    if (frames && *frames < 1) throw ParamError("--frames " + std::to_string(*frames) + ": must be >= 1");
    r.max_frames = frames ? static_cast<std::size_t>(*frames) : 0;
    if (const auto v = pop(o, "outputs")) {
        // "objects,json" as the command's --outputs, or a sequence of the names.
        std::string names;
        if (py::isinstance<py::str>(*v)) {
            names = to_string(*v, "outputs");
        } else {
            for (const py::handle item : py::iter(*v))
                names += (names.empty() ? "" : ",") + to_string(item, "outputs[]");
        }
        r.files = parse_output_files(names);
    }
    if (take<bool>(o, "ply").value_or(false)) r.files.ply = true;
    if (take<bool>(o, "overlay").value_or(false)) r.files.overlay = true;
    r.params.render_colors = r.files.reads_colors();
    r.overwrite = take<bool>(o, "overwrite").value_or(false);
    r.out_dir = out;
    if (!o.empty()) {
        std::string keys;
        for (const auto& item : o) keys += (keys.empty() ? "" : ", ") + py::str(item.first).cast<std::string>();
        throw py::type_error("run: unknown option(s): " + keys +
                             (o.contains("threads") ? " (threads: wul3d.set_num_threads)" : ""));
    }
    return r;
}

/// SIGINT and SIGTERM while a run is on the main thread: the CLI's handling (frame_feed.cpp)
/// for as long as the run lasts. The handler asks the library to stop (stop.hpp), which the
/// stages check mid-frame; the run then ends as "signal" with its outputs complete, and once
/// summary.json is written SIGINT raises KeyboardInterrupt and SIGTERM ends the process as
/// its default action would. Python's own handler cannot do this: it runs only when the
/// main thread runs Python, which it does not until the run returns.
volatile std::sig_atomic_t g_stopped_by = 0;  // the signal that stopped the run, 0 none

extern "C" void on_stop_signal(int signal_number) {
    g_stopped_by = signal_number;
    request_stop();
}

class InterruptScope {
public:
    /// Takes a signal over only where Python leaves it to its default: SIGINT with
    /// signal.default_int_handler (KeyboardInterrupt), SIGTERM with SIG_DFL; and only on the
    /// main thread. GIL held.
    InterruptScope() {
        const py::module_ threading = py::module_::import("threading");
        const py::module_ signal = py::module_::import("signal");
        if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return;
        g_stopped_by = 0;
        clear_stop_request();
        if (signal.attr("getsignal")(SIGINT).is(signal.attr("default_int_handler")))
            int_.take(SIGINT);
        if (signal.attr("getsignal")(SIGTERM).equal(signal.attr("SIG_DFL"))) term_.take(SIGTERM);
    }
    ~InterruptScope() {
        int_.give_back(SIGINT);  // Python's handlers again
        term_.give_back(SIGTERM);
        if (g_stopped_by) clear_stop_request();  // later runs and pipelines start afresh
    }
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;

    bool interrupted() const { return (int_.taken || term_.taken) && g_stopped_by != 0; }
    /// After a SIGTERM stopped the run: its default action, now that the outputs are final.
    void end_if_terminated() {
        if (!term_.taken || g_stopped_by != SIGTERM) return;
        term_.give_back(SIGTERM);
        std::raise(SIGTERM);
    }

private:
    struct Taken {
        bool taken = false;
        struct sigaction previous {};
        void take(int signal_number) {
            struct sigaction sa {};
            sa.sa_handler = on_stop_signal;
            sigemptyset(&sa.sa_mask);
            sa.sa_flags = SA_RESETHAND;  // as the command: a second signal acts at once
            taken = sigaction(signal_number, &sa, &previous) == 0;
        }
        void give_back(int signal_number) {
            if (taken) sigaction(signal_number, &previous, nullptr);
            taken = false;
        }
    };
    Taken int_, term_;
};

/// Between frames, at most every 50 ms: Python's pending signals, with the GIL taken back
/// for the check. A handler that raises (SIGINT where InterruptScope did not take it over, or
/// a handler of the caller's) ends the run as "signal"; its exception is raised after it.
class SignalPoll {
public:
    bool operator()() {
        const auto now = std::chrono::steady_clock::now();
        if (now < next_) return false;
        next_ = now + std::chrono::milliseconds(50);
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() == 0) return false;
        PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
        PyErr_Fetch(&type, &value, &trace);
        type_ = py::reinterpret_steal<py::object>(type);
        value_ = py::reinterpret_steal<py::object>(value);
        trace_ = py::reinterpret_steal<py::object>(trace);
        return true;
    }
    /// Raises the handler's exception, if one ended the run. GIL held.
    void rethrow() {
        if (!type_) return;
        PyErr_Restore(type_.release().ptr(), value_.release().ptr(), trace_.release().ptr());
        throw py::error_already_set();
    }

private:
    std::chrono::steady_clock::time_point next_{};
    py::object type_, value_, trace_;
};

}  // namespace

void bind_run(py::module_& m) {
    m.def(
        "_run",
        [](const py::object& input, const py::object& out, const py::dict& options) {
            RunOptions r = run_options(to_path(input, "input"), to_path(out, "out"),
                                       options.attr("copy")());  // a copy to consume
            InterruptScope interrupt;
            SignalPoll poll;
            r.stop = [&interrupt, &poll] { return interrupt.interrupted() || poll(); };
            RunSummary s;
            {
                py::gil_scoped_release release;
                s = run_sequence(r);
            }
            poll.rethrow();
            interrupt.end_if_terminated();
            if (interrupt.interrupted()) {
                PyErr_SetNone(PyExc_KeyboardInterrupt);
                throw py::error_already_set();
            }
            return py::dict(py::arg("frames") = s.frames, py::arg("stopped_by") = s.stopped_by,
                            py::arg("ms_per_frame_median") = s.ms_per_frame_median,
                            py::arg("fps") = s.fps, py::arg("wall_s") = s.wall_s,
                            py::arg("fps_end_to_end") = s.end_to_end_fps,
                            py::arg("peak_rss_mb") = s.peak_rss_mb);
        },
        py::arg("input"), py::arg("out"), py::arg("options"));
    m.def("_request_stop", &request_stop,
          "Asks every wul3d.run and Pipeline.process running now or later in this process to "
          "stop (the library's stop request, stop.hpp): a run ends as \"signal\" with its "
          "outputs complete. For a caller that handles its signals itself (the batch's worker "
          "threads, which SIGINT does not reach); withdraw it with _clear_stop_request.");
    m.def("_clear_stop_request", &clear_stop_request, "Withdraws _request_stop's request.");
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
    m.def("_frame_output_files", &frame_output_files,
          "The files wul3d writes in a frame folder (output.hpp, frame_output_files).");
    m.def("_remove_stale_temporaries", &remove_stale_temporaries, py::arg("dir"),
          "Removes the .wul3d.tmp-* / .wul3d.partial-* a killed writer left in `dir`.");
}

}  // namespace wul3d::python
