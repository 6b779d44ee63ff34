// wul3d._wul3d: the compiled part of the Python module (docs/PYTHON.md). The pipeline,
// its result, frame reading and scoring; python/wul3d/__init__.py re-exports them with the
// pure-Python helpers. Errors: ParamError -> ValueError, InputError -> wul3d.InputError
// (a ValueError), IoError -> wul3d.IoError (an OSError).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "buffer_pool.hpp"
#include "convert.hpp"
#include "params.hpp"
#include "run_binding.hpp"
#include "wul3d/error.hpp"
#include "wul3d/eval.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/registration.hpp"
#include "wul3d/threads.hpp"
#include "wul3d/version.hpp"

#if __has_include("wul3d/image_view.hpp")
#include "wul3d/image_view.hpp"
#define WUL3D_PYTHON_HAS_VIEW 1
#else
#define WUL3D_PYTHON_HAS_VIEW 0
#endif

namespace wul3d::python {
namespace {

/// One object of a result; the mask is cut from the result's objects image on demand.
struct Instance {
    DetectedObject object;
    py::object objects;  ///< the result's objects image (shared, not copied), or None
};

template <std::size_t N>
py::array_t<float> floats(const std::array<float, N>& a) {
    py::array_t<float> out(static_cast<py::ssize_t>(N));
    std::copy(a.begin(), a.end(), out.mutable_data());
    return out;
}

/// Everything process() returns; owns the frame's images (None for an image
/// that process(outputs=...) left out). The instances, plane, times and stats are kept as
/// the library's values and made Python objects on first read (then the same object on each
/// read): a loop that reads none of them does not pay for some sixty objects a frame.
struct Result {
    int width = 0, height = 0;
    py::object labels, objects, colors;
    std::vector<DetectedObject> object_list;
    PlaneResult plane;
    StageTimes times;
    double call_ms = 0;  ///< the C++ Pipeline::process call, timed by the binding
    FrameStats stats;
    std::size_t active_points = 0;
    float depth_noise_px = 0.0f;
    int normal_radius_px = 0;
    SegmentStats segment_stats;
    py::object instances_py, plane_py, times_py, stats_py;  ///< made on first read
};

/// The images process() gives: all by default, or those named by `outputs`.
struct ImageSelection {
    bool labels = true, objects = true, colors = true;
};

ImageSelection to_selection(const py::object& outputs) {
    ImageSelection s;
    if (outputs.is_none()) return s;
    if (PyUnicode_Check(outputs.ptr()) || PyBytes_Check(outputs.ptr()) ||
        !py::isinstance<py::iterable>(outputs))
        throw py::type_error("outputs: expected a tuple of names ('labels', 'objects', "
                             "'colors') or None, got " +
                             py::str(py::type::of(outputs).attr("__name__")).cast<std::string>());
    s = ImageSelection{false, false, false};
    for (const py::handle name : outputs) {
        const std::string n = to_string(name, "outputs[]");
        if (n == "labels") s.labels = true;
        else if (n == "objects") s.objects = true;
        else if (n == "colors") s.colors = true;
        else throw py::value_error("outputs: '" + n + "' is not one of 'labels', 'objects', 'colors'");
    }
    return s;
}

/// The images asked for, in vectors of the pipeline's pools (buffer_pool.hpp): handed over
/// by the pipeline without a copy where it can (Pipeline::swap_images, with decimation), the
/// pool's vectors taking their place, else copied into them (the pipeline's buffers are
/// reused by the next frame).
void take_images(Pipeline& pipeline, const FrameResult& r, const ImageSelection& selection, ResultPools& pools,
                 Result& out) {
    out.width = r.labels.width;
    out.height = r.labels.height;
    const std::vector<py::ssize_t> grey{r.labels.height, r.labels.width}, rgb{r.labels.height, r.labels.width, 3};
    if (!selection.labels && !selection.objects && !selection.colors) {
        out.labels = out.colors = out.objects = py::none();
        return;
    }
    const std::size_t pixels = r.labels.labels.size();  // r's vectors are the pool's after a swap
    std::vector<std::uint16_t> labels = pools.labels->take(pixels);
    std::vector<std::uint8_t> colours = pools.rgb->take(r.colors.rgb.size());
    std::vector<std::uint16_t> objects = pools.labels->take(r.objects.labels.size());
    const bool swapped = pipeline.swap_images(labels, colours, objects);
    // `taken` holds the image when swapped; else it has the image's size and gets a copy.
    auto image = [&](bool wanted, auto& pool, auto& taken, const auto& own, const std::vector<py::ssize_t>& shape) {
        if (!wanted) {
            pool.give_back(std::move(taken));
            return py::object(py::none());
        }
        if (!swapped) copy_streaming(taken.data(), own.data(), own.size() * sizeof(own[0]));
        return py::object(pool.array(std::move(taken), shape));
    };
    out.labels = image(selection.labels, *pools.labels, labels, r.labels.labels, grey);
    out.colors = image(selection.colors, *pools.rgb, colours, r.colors.rgb, rgb);
    if (selection.objects && objects.empty()) {  // objects not detected: all background
        objects.assign(pixels, 0);
        out.objects = pools.labels->array(std::move(objects), grey);
    } else {
        out.objects = image(selection.objects, *pools.labels, objects, r.objects.labels, grey);
    }
}

Result make_result(Pipeline& pipeline, const FrameResult& r, const ImageSelection& selection, ResultPools& pools) {
    Result out;
    take_images(pipeline, r, selection, pools, out);
    out.object_list = r.object_list;
    out.plane.found = r.plane.found;
    out.plane.support = r.plane.support;
    out.times = r.times;
    out.stats = r.stats;
    out.depth_noise_px = r.depth_noise_px;
    out.normal_radius_px = r.normal_radius_px;
    out.active_points = r.active_points;
    out.segment_stats = r.segment_stats;
    return out;
}

py::list instances_list(const Result& r) {
    py::list out;
    for (const DetectedObject& d : r.object_list) out.append(Instance{d, r.objects});
    return out;
}

py::object plane_dict(const Result& r) {
    if (!r.plane.found) return py::none();
    const Plane& pl = r.plane.support;
    py::dict plane;
    plane["normal"] = py::make_tuple(pl.nx, pl.ny, pl.nz);
    plane["d_m"] = pl.d;
    return plane;
}

py::dict times_dict(const Result& r) {
    const StageTimes& t = r.times;
    const std::pair<const char*, double> stages[] = {
        {"registration", t.registration}, {"decimation", t.decimation},
        {"backprojection", t.backprojection}, {"normals", t.normals},
        {"background", t.background}, {"clustering", t.clustering}, {"colors", t.colors},
        {"plane", t.plane}, {"segmentation", t.segmentation}, {"objects", t.objects},
        {"overlap", t.overlap}, {"total", t.total()}, {"call", r.call_ms}};
    py::dict out;
    for (const auto& [name, ms] : stages) out[name] = ms;
    return out;
}

py::dict stats_dict(const Result& r) {
    py::dict out;
    out["points"] = r.stats.points;
    out["active_points"] = r.active_points;
    out["seeded"] = r.stats.seeded;
    out["reseeded"] = r.stats.reseeded;
    out["mean_f"] = r.stats.mean_f;
    out["depth_noise_px"] = r.depth_noise_px;
    out["normal_radius_px"] = r.normal_radius_px;
    out["segments"] = r.segment_stats.segments;
    out["merges"] = r.segment_stats.merge.joins;
    out["containers"] = r.segment_stats.containers.joins;
    out["occluded_joins"] = r.segment_stats.occlusion.joins;
    out["neck_joins"] = r.segment_stats.necks.joins;
    out["gaps_filled"] = r.segment_stats.containers.gaps_filled;
    out["color_splits"] = r.segment_stats.colour.splits;
    out["texture_splits"] = r.segment_stats.colour.texture_splits;
    out["stack_splits"] = r.segment_stats.stacks.splits;
    out["piece_splits"] = r.segment_stats.pieces.splits;
    out["low_support"] = r.plane.low_found;
    return out;
}

/// A field of Result made on its first read, the same object after.
template <py::object Result::*Field, class Make>
py::object made_once(Result& r, Make make) {
    if (!(r.*Field)) r.*Field = make(r);
    return r.*Field;
}

/// process() calls running now without the GIL, and the most seen at once: shows in tests
/// (tests/python) that pipelines in two threads run at the same time.
std::atomic<int> g_running{0};
std::atomic<int> g_max_running{0};

struct RunningScope {
    RunningScope() {
        const int now = ++g_running;
        int seen = g_max_running.load();
        while (now > seen && !g_max_running.compare_exchange_weak(seen, now)) {
        }
    }
    ~RunningScope() { --g_running; }
    RunningScope(const RunningScope&) = delete;
    RunningScope& operator=(const RunningScope&) = delete;
};

#if WUL3D_PYTHON_HAS_VIEW
/// The checked arrays as the library's frame view (image_view.hpp): C-contiguous uint16
/// depth and RGB colour are the stages' own layout, read in place.
FrameView frame_view(const FrameArrays& a, const PinholeIntrinsics& K, float depth_scale) {
    FrameView v;
    v.name = "frame";
    v.intrinsics = K;
    v.depth.data = a.depth.data();
    v.depth.width = a.width;
    v.depth.height = a.height;
    v.depth.format = DepthFormat::U16;
    v.depth.scale_m_per_unit = depth_scale;
    if (a.has_color) {
        v.color.data = static_cast<const std::uint8_t*>(a.color.data());
        v.color.width = a.width;
        v.color.height = a.height;
        v.color.order = ColorOrder::RGB;
    }
    return v;
}
#endif

/// wul3d.Pipeline: the C++ Pipeline, its reused input frame, and a lock so that two Python
/// threads sharing one pipeline take turns (its state carries from frame to frame).
class PyPipeline {
public:
    explicit PyPipeline(const ParamArgs& args) : pipeline_(make_params(args)) {}

    Result process(const py::object& color, const py::object& depth,
                   const py::object& intrinsics, const py::object& depth_scale_arg,
                   const py::object& outputs) {
        const double depth_scale = to_double(depth_scale_arg, "depth_scale");
        if (!(depth_scale > 0) || !std::isfinite(depth_scale) || depth_scale > 1e3)
            throw py::value_error("depth_scale = " + std::to_string(depth_scale) +
                                  ": must be a positive number of metres per unit");
        const FrameArrays arrays = check_frame_arrays(color, depth);
        const PinholeIntrinsics K = to_intrinsics(intrinsics, arrays.width, arrays.height);
        const ImageSelection selection = to_selection(outputs);
        const FrameResult* r = nullptr;
        double call_ms = 0;
        // Held until the result is taken: it is valid until the next process(). A thread
        // waiting for the lock waits without the GIL, so this thread can take it back.
        std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
        {
            py::gil_scoped_release release;
            lock.lock();
            const RunningScope running;
            pipeline_.set_render_colors(selection.colors);  // eq. 9's colours only when returned
            auto t0 = std::chrono::steady_clock::now();
#if WUL3D_PYTHON_HAS_VIEW
            if (!arrays.depth_is_float) {  // the caller's memory as it is: no copy
                const FrameView view = frame_view(arrays, K, static_cast<float>(depth_scale));
                t0 = std::chrono::steady_clock::now();
                r = &pipeline_.process(view);
            } else
#endif
            {
                // float32 metres: converted here (0.1 mm steps, coarser beyond 6.55 m).
                frame_.name = "frame";
                frame_.intrinsics = K;
                fill_frame(arrays, static_cast<float>(depth_scale), frame_);
                t0 = std::chrono::steady_clock::now();
                r = &pipeline_.process(frame_);
            }
            call_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        }
        Result out = make_result(pipeline_, *r, selection, pools_);
        out.call_ms = call_ms;
        return out;
    }

    const PipelineParams& params() const { return pipeline_.params(); }

private:
    Pipeline pipeline_;
    RgbdFrame frame_;
    std::mutex mutex_;
    /// The results' memory; shared with their arrays' leases, which may outlive the pipeline.
    ResultPools pools_;
};

/// One frame read from disk (wul3d.read), registered when the input is unregistered.
/// A file name as Python's os.fsdecode gives it: bytes that are not UTF-8 as surrogates
/// (a frame folder named "img\xff\xfe" reads back, and os.fsencode gives its bytes again).
py::str fs_str(const std::string& name) {
    PyObject* s = PyUnicode_DecodeFSDefaultAndSize(name.data(), static_cast<Py_ssize_t>(name.size()));
    if (!s) throw py::error_already_set();
    return py::reinterpret_steal<py::str>(s);
}

struct PyFrame {
    std::string name;
    py::object color;  ///< (H, W, 3) uint8 or None
    py::array_t<std::uint16_t> depth;
    float depth_scale = 0.001f;
    PinholeIntrinsics intrinsics;
};

/// wul3d.read: the frames of a recording, as `wul3d run` reads them (open_source).
class Reader {
public:
    Reader(const std::string& path, const SourceOptions& options)
        : source_(open_source(path, options)), registration_(options.registration) {}

    std::size_t size() const { return source_->size(); }

    PyFrame get(py::ssize_t index) {
        const auto n = static_cast<py::ssize_t>(size());
        if (index < 0) index += n;
        if (index < 0 || index >= n) throw py::index_error("frame index out of range");
        // The source, the item and the registration's buffers are this reader's, reused from
        // frame to frame: one thread at a time reads, up to the copies into arrays. A thread
        // waits for the lock without the GIL, so the one holding it can take the GIL back.
        std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
        {
            py::gil_scoped_release release;
            lock.lock();
            source_->read(static_cast<std::size_t>(index), item_);
            if (item_.is_raw) {
                if (registration_ == RegistrationMode::DepthToColor)
                    register_depth_to_color(*source_->calibration(), item_.raw, ws_, registered_);
                else
                    register_color_to_depth(*source_->calibration(), item_.raw, ws_, registered_);
                registered_.name = item_.raw.name;
            }
        }
        const RgbdFrame& f = item_.is_raw ? registered_ : item_.frame;
        PyFrame out;
        out.name = source_->name(static_cast<std::size_t>(index));
        out.color = f.has_color() ? py::object(to_array(f.color)) : py::none();
        out.depth = to_array(f.depth);
        out.depth_scale = f.depth.scale_m_per_unit;
        out.intrinsics = f.intrinsics;
        return out;
    }

    std::string format() const { return input_format_name(source_->format()); }

private:
    std::unique_ptr<FrameSource> source_;
    RegistrationMode registration_;
    std::mutex mutex_;  ///< held by get() from the read to the last copy out
    SourceItem item_;
    RegistrationWorkspace ws_;
    RgbdFrame registered_;
};

py::dict score_dict(const ImageScore& s) {
    py::dict d;
    d["overlap_p"] = s.overlap_p;
    d["overlap_r"] = s.overlap_r;
    d["overlap_f"] = s.overlap_f;
    d["boundary_p"] = s.boundary_p;
    d["boundary_r"] = s.boundary_r;
    d["boundary_f"] = s.boundary_f;
    d["detected_share"] = s.detected_share;
    d["gt_objects"] = s.gt_objects;
    d["pred_objects"] = s.pred_objects;
    d["detected"] = s.detected;
    d["boundary_tolerance_px"] = s.boundary_tolerance_px;
    py::list matches;
    for (const MatchedPair& m : s.matches)
        matches.append(py::dict(py::arg("gt_id") = m.gt_id, py::arg("pred_id") = m.pred_id,
                                py::arg("true_positives") = m.true_positives,
                                py::arg("overlap_f") = m.overlap_f));
    d["matches"] = matches;
    return d;
}

py::dict summary_dict(const EvalSummary& s) {
    py::dict d;
    d["overlap_p"] = s.overlap_p;
    d["overlap_r"] = s.overlap_r;
    d["overlap_f"] = s.overlap_f;
    d["boundary_p"] = s.boundary_p;
    d["boundary_r"] = s.boundary_r;
    d["boundary_f"] = s.boundary_f;
    d["detected_share"] = s.detected_share;
    d["images"] = s.images;
    d["gt_objects"] = s.gt_objects;
    d["pred_objects"] = s.pred_objects;
    d["detected"] = s.detected;
    return d;
}

EvalParams eval_params(double boundary_fraction, int boundary_tolerance_px, double detected_f) {
    EvalParams p;
    p.boundary_fraction = boundary_fraction;
    p.boundary_tolerance_px = boundary_tolerance_px;
    p.detected_f = detected_f;
    p.validate();
    return p;
}

void bind_errors(py::module_& m) {
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::exception<IoError> io_error(m, "IoError", PyExc_OSError);
    input_error.doc() = "Input data that cannot be used (missing or unreadable file, wrong size).";
    io_error.doc() = "Writing an output failed (disk full, permission denied).";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ParamError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const InputError& e) {
            PyErr_SetString(input_error.ptr(), e.what());
        } catch (const IoError& e) {
            PyErr_SetString(io_error.ptr(), e.what());
        } catch (const Error& e) {
            PyErr_SetString(PyExc_RuntimeError, e.what());
        }
    });
}

void bind_intrinsics(py::module_& m) {
    py::class_<PinholeIntrinsics>(m, "Intrinsics", R"doc(
Pinhole intrinsics of an undistorted camera, in pixels.

Projection: u = fx * x / z + cx, v = fy * y / z + cy (x right, y down, z forward, metres).

Args:
    fx (float): focal length along u, pixels (> 0).
    fy (float): focal length along v, pixels (> 0).
    cx (float): principal point u.
    cy (float): principal point v.
    width (int, optional): image width; 0 = the arrays' size.
    height (int, optional): image height; 0 = the arrays' size.
)doc")
        .def(py::init([](const py::object& fx, const py::object& fy, const py::object& cx,
                         const py::object& cy, const py::object& width, const py::object& height) {
                 PinholeIntrinsics K;
                 K.fx = to_double(fx, "fx");
                 K.fy = to_double(fy, "fy");
                 K.cx = to_double(cx, "cx");
                 K.cy = to_double(cy, "cy");
                 K.width = to_value<int>(width, "width");
                 K.height = to_value<int>(height, "height");
                 return K;
             }),
             py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("width") = 0,
             py::arg("height") = 0)
        .def_readwrite("fx", &PinholeIntrinsics::fx, "Focal length along u, pixels.")
        .def_readwrite("fy", &PinholeIntrinsics::fy, "Focal length along v, pixels.")
        .def_readwrite("cx", &PinholeIntrinsics::cx, "Principal point u, pixels.")
        .def_readwrite("cy", &PinholeIntrinsics::cy, "Principal point v, pixels.")
        .def_readwrite("width", &PinholeIntrinsics::width, "Image width (0 = any).")
        .def_readwrite("height", &PinholeIntrinsics::height, "Image height (0 = any).")
        .def("to_dict",
             [](const PinholeIntrinsics& K) {
                 return py::dict(py::arg("fx") = K.fx, py::arg("fy") = K.fy,
                                 py::arg("cx") = K.cx, py::arg("cy") = K.cy,
                                 py::arg("width") = K.width, py::arg("height") = K.height);
             },
             "The intrinsics as a dict (the keys of intrinsics.json).")
        .def("__repr__", [](const PinholeIntrinsics& K) {
            return "Intrinsics(fx=" + std::to_string(K.fx) + ", fy=" + std::to_string(K.fy) +
                   ", cx=" + std::to_string(K.cx) + ", cy=" + std::to_string(K.cy) +
                   ", width=" + std::to_string(K.width) + ", height=" +
                   std::to_string(K.height) + ")";
        });
}

void bind_result(py::module_& m) {
    py::class_<Instance>(m, "Instance", R"doc(
One object of a frame. Positions in metres in the camera frame, colours 0-255; the same
fields as an entry of objects.json.
)doc")
        .def_property_readonly("id", [](const Instance& i) { return i.object.id; },
                               "Its value in Result.objects; equal to track_id.")
        .def_property_readonly("track_id", [](const Instance& i) { return i.object.track_id; },
                               "Stable across frames: 1, 2, ... in order of first appearance.")
        .def_property_readonly("pixels", [](const Instance& i) { return i.object.pixels; },
                               "Its pixel count.")
        .def_property_readonly("centroid", [](const Instance& i) { return floats(i.object.centroid); },
                               "(3,) float32: mean position, metres.")
        .def_property_readonly(
            "aabb",
            [](const Instance& i) {
                py::array_t<float> out({2, 3});
                std::copy(i.object.aabb_min.begin(), i.object.aabb_min.end(), out.mutable_data());
                std::copy(i.object.aabb_max.begin(), i.object.aabb_max.end(), out.mutable_data() + 3);
                return out;
            },
            "(2, 3) float32: axis-aligned box, rows min and max, metres.")
        .def_property_readonly(
            "obb",
            [](const Instance& i) {
                py::array_t<float> axes({3, 3});
                std::copy(i.object.obb_axes.begin(), i.object.obb_axes.end(), axes.mutable_data());
                return py::dict(py::arg("centre") = floats(i.object.obb_centre),
                                py::arg("axes") = axes,
                                py::arg("half_extent") = floats(i.object.obb_half_extent));
            },
            "Oriented box: dict with 'centre' (3,), 'axes' (3, 3), unit principal directions "
            "as rows, and 'half_extent' (3,) along them; metres.")
        .def_property_readonly(
            "box_px",
            [](const Instance& i) {
                return py::make_tuple(i.object.u_min, i.object.v_min, i.object.u_max, i.object.v_max);
            },
            "2D box (u_min, v_min, u_max, v_max), inclusive pixels.")
        .def_property_readonly("mean_rgb", [](const Instance& i) { return floats(i.object.mean_rgb); },
                               "(3,) float32: mean colour, 0-255.")
        .def_property_readonly("source_clusters", [](const Instance& i) { return i.object.source_clusters; },
                               "Clusters (Result.labels) covering >= 5 % of its pixels.")
        .def_property_readonly("source_segments", [](const Instance& i) { return i.object.source_segments; },
                               "This frame's segments that fed it.")
        .def("mask",
             [](const Instance& i) {
                 if (i.objects.is_none())
                     throw py::value_error("mask(): the result has no objects image (process() "
                                           "with outputs= that leaves out 'objects')");
                 const auto objects = py::reinterpret_borrow<py::array_t<std::uint16_t>>(i.objects);
                 py::array_t<bool> out({objects.shape(0), objects.shape(1)});
                 const std::uint16_t* o = objects.data();
                 bool* dst = out.mutable_data();
                 const auto id = static_cast<std::uint16_t>(i.object.id);
                 for (py::ssize_t p = 0; p < objects.size(); ++p) dst[p] = o[p] == id;
                 return out;
             },
             "(H, W) bool: its pixels, cut from Result.objects on each call (ValueError when "
             "process(outputs=...) left out 'objects').")
        .def("__repr__", [](const Instance& i) {
            return "Instance(id=" + std::to_string(i.object.id) +
                   ", pixels=" + std::to_string(i.object.pixels) + ")";
        });

    py::class_<Result>(m, "Result", R"doc(
Everything one frame produced, at the input's size. Owns its arrays: it stays valid after
the next process() and after its pipeline. An image that process(outputs=...) left out is
None. The images' memory goes back to the pipeline for a later frame when the result is
dropped; instances, plane, times and stats are made on first read.
)doc")
        .def_readonly("labels", &Result::labels,
                      "(H, W) uint16: the paper's clusters, 0 = no point, 1..k (labels.png).")
        .def_readonly("objects", &Result::objects,
                      "(H, W) uint16: objects, 0 = background, else the track id (objects.png).")
        .def_readonly("colors", &Result::colors,
                      "(H, W, 3) uint8 RGB: eq. (9) display colours over the scene (colors.png).")
        .def_readonly("width", &Result::width, "The frame's width, pixels.")
        .def_readonly("height", &Result::height, "The frame's height, pixels.")
        .def_property_readonly(
            "instances", [](Result& r) { return made_once<&Result::instances_py>(r, instances_list); },
            "list of Instance, one per object.")
        .def_property_readonly(
            "plane", [](Result& r) { return made_once<&Result::plane_py>(r, plane_dict); },
                      "The support plane n . X + d = 0 as {'normal': (nx, ny, nz), 'd_m': d}, "
                      "or None when none was found (objects.json's support_plane).")
        .def_property_readonly(
            "times", [](Result& r) { return made_once<&Result::times_py>(r, times_dict); },
                      "Milliseconds per stage, 'overlap' (counted twice), 'total' (the stages, as "
                      "`wul3d run` reports them) and 'call' (the whole C++ Pipeline::process "
                      "call; process() from Python costs this plus the binding's overhead).")
        .def_property_readonly(
            "stats", [](Result& r) { return made_once<&Result::stats_py>(r, stats_dict); },
                      "What the frame did: points clustered, active points, seeding, segments "
                      "(summary.json's per-frame entry).")
        .def("__repr__", [](const Result& r) {
            return "Result(" + std::to_string(r.width) + "x" + std::to_string(r.height) + ", " +
                   std::to_string(r.object_list.size()) + " objects)";
        });
}

void bind_pipeline(py::module_& m) {
    // The keywords' lines come from the table (params_doc), so they cannot drift from it.
    static const std::string doc = std::string(R"doc(
The wul3d pipeline: the paper's weighted clustering of an RGB-D stream, then the support
plane, object segments and object tracks. Holds state across frames (clusters and tracks):
use one Pipeline per stream, feed its frames in order.

Every keyword is a flag of `wul3d run` (`wul3d run --help`), from the library's one table of
parameters (wul3d/parameters.hpp); None keeps the preset's value. A value outside its range
raises ValueError naming the keyword, with the command's message otherwise.

Args:
)doc") + params_doc() + R"doc(Example:
    >>> p = wul3d.Pipeline(k=7, decimate=2)
    >>> r = p.process(color, depth, wul3d.Intrinsics(525, 525, 319.5, 239.5))
    >>> [(i.id, i.pixels) for i in r.instances]
)doc";
    py::class_<PyPipeline>(m, "Pipeline", doc.c_str())
        .def(py::init([](const py::kwargs& kwargs) {
                 // Each keyword converted by its row's kind (params.hpp): a wrong type is a
                 // TypeError naming it; a keyword that is not a parameter, a TypeError too.
                 py::dict d(kwargs);
                 ParamArgs a = take_param_args(d);
                 if (!d.empty())
                     throw py::type_error("Pipeline() got an unexpected keyword argument '" +
                                          py::str(d.begin()->first).cast<std::string>() + "'");
                 return std::make_unique<PyPipeline>(a);
             }))
        .def("process", &PyPipeline::process, py::arg("color"), py::arg("depth"),
             py::arg("intrinsics"), py::arg("depth_scale") = 0.001, py::kw_only(),
             py::arg("outputs") = py::none(), R"doc(
Runs every stage on one registered frame and returns a Result.

Args:
    color: (H, W, 3) uint8 RGB array, or None for depth only.
    depth: (H, W) uint16 array in units of depth_scale (0 = no depth), or float32 metres
        (NaN, inf and <= 0 = no depth).
    intrinsics: wul3d.Intrinsics, or a dict with fx, fy, cx, cy (as intrinsics.json).
    depth_scale (float): metres per unit of a uint16 depth (default 0.001, millimetres).
    outputs (keyword only): the images given in the Result, a tuple of names from
        'labels', 'objects', 'colors'; None (default) gives all three. The others are None
        in the Result; the stages, instances, plane and stats are the same. Without
        'colors', eq. 9's colours are not made at all (times['colors'] is 0). With
        decimation (the default) the images are handed over without a copy; with
        decimate=1 each image left out saves its copy (a 640x480 frame's three are 2.1 MB).

C-contiguous arrays are required (TypeError for a wrong dtype, ValueError for a wrong shape
or order). uint16 depth and RGB colour are read in place, not copied; float32 depth is
converted once. The GIL is released while the pipeline runs: pipelines in other threads
run at the same time (do not write to the arrays meanwhile).
)doc")
        .def_property_readonly("params", [](const PyPipeline& p) { return params_dict(p.params()); },
                               "The parameters in force, as a dict (summary.json's names).");
}

void bind_reading(py::module_& m) {
    py::class_<PyFrame>(m, "Frame", "One registered RGB-D frame read from disk (wul3d.read).")
        .def_property_readonly(
            "name", [](const PyFrame& f) { return fs_str(f.name); },
            "Its name: OUT/<name>/ in `wul3d run` (bytes that are not UTF-8 as os.fsdecode "
            "gives them).")
        .def_readonly("color", &PyFrame::color, "(H, W, 3) uint8 RGB, or None.")
        .def_readonly("depth", &PyFrame::depth, "(H, W) uint16, units of depth_scale.")
        .def_readonly("depth_scale", &PyFrame::depth_scale, "Metres per depth unit.")
        .def_readonly("intrinsics", &PyFrame::intrinsics, "wul3d.Intrinsics of the frame.")
        .def("__repr__", [](const PyFrame& f) {
            return "Frame(" + py::repr(fs_str(f.name)).cast<std::string>() + ", " +
                   std::to_string(f.depth.shape(1)) + "x" + std::to_string(f.depth.shape(0)) +
                   (f.color.is_none() ? ", depth only)" : ")");
        });

    py::class_<Reader>(m, "_Reader")
        .def(py::init([](const py::object& path, const py::object& format,
                         const py::object& tum_camera, const py::object& intrinsics,
                         const py::object& calibration, const py::object& registration) {
                 SourceOptions o;
                 o.format = parse_input_format(to_string(format, "format"));
                 o.tum_camera = to_string(tum_camera, "tum_camera");
                 o.calibration = to_path(calibration, "calibration");
                 o.registration = parse_registration_mode(to_string(registration, "registration"));
                 if (!intrinsics.is_none()) o.intrinsics = intrinsics_override(intrinsics);
                 return std::make_unique<Reader>(to_path(path, "path"), o);
             }),
             py::arg("path"), py::arg("format"), py::arg("tum_camera"), py::arg("intrinsics"),
             py::arg("calibration"), py::arg("registration"))
        .def("__len__", &Reader::size)
        .def("__getitem__", &Reader::get)
        .def_property_readonly("format", &Reader::format);
}

void bind_eval(py::module_& m) {
    m.def(
        "_score_image",
        [](const py::object& pred, const py::object& gt, const py::object& fraction,
           const py::object& tolerance, const py::object& detected_f) {
            const EvalParams params =
                eval_params(to_double(fraction, "boundary_fraction"),
                            to_value<int>(tolerance, "boundary_tolerance_px"),
                            to_double(detected_f, "detected_f"));
            const LabelImage p = to_label_image(pred, "pred");
            const LabelImage g = to_label_image(gt, "gt");
            ImageScore s;
            {
                py::gil_scoped_release release;
                s = score_image(p, g, params);
            }
            return score_dict(s);
        },
        py::arg("pred"), py::arg("gt"), py::arg("boundary_fraction"),
        py::arg("boundary_tolerance_px"), py::arg("detected_f"));
    m.def(
        "_summarize",
        [](const py::list& scores) {
            std::vector<ImageScore> v;
            for (const auto& item : scores) {
                const auto d = item.cast<py::dict>();
                ImageScore s;
                s.overlap_p = d["overlap_p"].cast<double>();
                s.overlap_r = d["overlap_r"].cast<double>();
                s.overlap_f = d["overlap_f"].cast<double>();
                s.boundary_p = d["boundary_p"].cast<double>();
                s.boundary_r = d["boundary_r"].cast<double>();
                s.boundary_f = d["boundary_f"].cast<double>();
                s.detected_share = d["detected_share"].cast<double>();
                s.gt_objects = d["gt_objects"].cast<int>();
                s.pred_objects = d["pred_objects"].cast<int>();
                s.detected = d["detected"].cast<int>();
                v.push_back(s);
            }
            return summary_dict(summarize(v));
        },
        py::arg("scores"));
}

}  // namespace
}  // namespace wul3d::python

PYBIND11_MODULE(_wul3d, m) {
    using namespace wul3d::python;
    m.doc() = "The compiled part of wul3d (see the package wul3d).";
    m.attr("__version__") = WUL3D_VERSION;  // CMake's project(VERSION), as `wul3d --version`
    bind_errors(m);
    bind_intrinsics(m);
    bind_result(m);
    bind_pipeline(m);
    m.def(
        "parameters",
        [] {
            const wul3d::PipelineParams defaults;
            const py::dict values = params_dict(defaults);
            py::list rows;
            for (const wul3d::ParamSpec& s : wul3d::pipeline_parameters()) {
                py::dict row;
                row["name"] = s.name;
                row["stage"] = s.stage;
                row["type"] = python_type(s.kind);
                // A float row's default as its float's digits (0.0033, as --help says).
                row["default"] = s.kind == wul3d::ParamKind::Float
                                     ? py::object(py::float_(std::stod(wul3d::value_text(s.get(defaults)))))
                                     : py::object(values[s.name]);
                row["range"] = wul3d::range_text(s);
                row["help"] = s.help;
                row["flag"] = wul3d::flag_of(s);
                row["summary_key"] = wul3d::summary_key(s);
                rows.append(row);
            }
            return rows;
        },
        R"doc(The pipeline's parameters, one dict per row of the library's table: name (the
keyword of Pipeline and run), stage, type ("int", "float", "str", "bool"), default, range,
help, flag (`wul3d run`'s) and summary_key (summary.json's). The presets are "default" and
"paper".)doc");
    bind_reading(m);
    bind_eval(m);
    bind_run(m);
    bind_write_guard(m);
    m.def("read_label_image",
          [](const py::object& path) { return to_array(wul3d::read_label_png(to_path(path, "path"))); },
          py::arg("path"), "A 16-bit label PNG (labels.png, objects.png, ground truth) as (H, W) uint16.");
    m.def("read_color_image",
          [](const py::object& path) { return to_array(wul3d::read_color_image(to_path(path, "path"))); },
          py::arg("path"), "An 8-bit PNG or JPEG as (H, W, 3) uint8 RGB.");
    m.def(
        "set_num_threads",
        [](const py::object& n) {
            // The library's bound (threads.hpp), checked on the Python int before it is narrowed.
            wul3d::set_num_threads(static_cast<int>(to_int(n, "threads", 1, wul3d::kMaxThreads)));
        },
        py::arg("n"),
        "Worker threads of every pipeline in this process, in [1, 1024] (default: all cores): "
        "the command's --threads. ValueError outside that range, TypeError for a non-int; "
        "nothing changes then.");
    m.def(
        "set_max_pixels",
        [](const py::object& n) {
            wul3d::set_max_image_pixels(to_uint64(n, "max_pixels"));  // ParamError -> ValueError
        },
        py::arg("n"),
        "The largest image, width x height, that wul3d.read, wul3d.run and Pipeline.process "
        "accept, process-wide: the command's --max-pixels (default 2^24 = 16777216; in "
        "[1, 2^30], else ValueError). Images are refused by their declared size, before any "
        "decoding or allocation.");
    m.def("get_max_pixels", &wul3d::max_image_pixels, "The largest image accepted (set_max_pixels).");
    m.def("_concurrency", []() { return py::make_tuple(g_running.load(), g_max_running.load()); },
          "(running now, most at once): Pipeline.process calls running without the GIL.");
    m.def("_reset_concurrency", []() { g_max_running = g_running.load(); },
          "Restarts the count of _concurrency's maximum.");
    m.def("get_num_threads", &wul3d::num_threads,
          "Worker threads a pipeline uses.");
}
