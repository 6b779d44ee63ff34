#include "pipeline_options.hpp"

#include "cli.hpp"

#include <charconv>
#include <cstdlib>

#include "wul3d/capture.hpp"
#include "wul3d/error.hpp"
#include "wul3d/parse.hpp"
#include "wul3d/segmentation.hpp"
#include "wul3d/threads.hpp"

namespace wul3d::cli {

void add_max_pixels_option(CLI::App* cmd) {
    // Read as text: an unsigned option took -1 as 18446744073709551615 in its message.
    cmd->add_option_function<std::string>(
        "--max-pixels",
        [](const std::string& text) {
            std::uint64_t n = 0;
            const char* end = text.data() + text.size();
            const auto [ptr, ec] = std::from_chars(text.data(), end, n);
            if (text.empty() || ptr != end || ec != std::errc() || n < 1 ||
                n > kMaxImagePixelsCeiling)
                throw ParamError("--max-pixels '" + text + "': must be a whole number of pixels in [1, " +
                                 std::to_string(kMaxImagePixelsCeiling) + "]");
            set_max_image_pixels(n);
        },
        "Largest image read, width x height (default 2^24 = 16777216; at most 2^30)");
}

void add_pipeline_options(CLI::App* cmd, PipelineOptions& o) {
    add_max_pixels_option(cmd);
    cmd->add_option("input", o.input,
                    "Frame folder(s), TUM RGB-D sequence, unregistered frames or a ROS bag (or --camera)");
    cmd->add_option("--camera", o.camera,
                    "Live camera instead of INPUT: freenect[:INDEX] (Kinect v1), "
                    "openni2[:URI|FILE.oni], freenect2[:SERIAL], realsense[:SERIAL]");
    cmd->add_flag("--lossless", o.lossless,
                  "With --camera: capture waits for processing instead of dropping frames "
                  "(for replays: fakenect, .oni)");
    cmd->add_option("--format", o.format, "auto|frames|tum|unregistered|bag|ocid|pcd|osd|bop")->capture_default_str();
    cmd->add_option("--topics", o.topics,
                    "ROS bag topics COLOR,DEPTH[,INFO] (default: detected; docs/INPUTS.md)");
    cmd->add_option("--preset", o.preset, "paper: the paper's parameters");
    cmd->add_option("--k", o.k, "Number of clusters (default 7)");
    cmd->add_option("--alpha", o.alpha, "Colour scale, eq. 4, [0.002, 0.1] (default 0.0033)");
    cmd->add_option("--delta", o.delta, "Position scale, eq. 4, alpha + delta <= 1 (default 1 - alpha)");
    cmd->add_option("--gamma", o.gamma, "Normal scale, eq. 6, [0.0001, 0.01] (default 0.0001)");
    cmd->add_option("--psi", o.psi, "Weight increment, eq. 2, (0, 1] (default 1)");
    cmd->add_option("--iters", o.iters, "k-means iterations per frame (default 1)");
    cmd->add_option("--stride", o.stride, "Sampling stride in pixels (default 1)");
    cmd->add_option("--seed", o.seed, "k-means++ seed (default 1)");
    cmd->add_option("--zmin", o.zmin, "Nearest depth kept, metres (default 0.2)");
    cmd->add_option("--zmax", o.zmax, "Farthest depth kept, metres (default 4.5)");
    cmd->add_option("--normal-radius", o.normal_radius, "Normal neighbour distance, px (default 2)");
    cmd->add_option("--select", o.select, "U,V: follow the object under this pixel of the first frame");
    cmd->add_option("--segmenter", o.segmenter,
                    "Object segmentation: geometric|kmeans|hybrid (default hybrid)");
    cmd->add_option("--scope", o.scope,
                    "Objects: support (what the support holds; the default, the whole scene "
                    "when no support is found) or scene (every segment)");
    cmd->add_flag("--no-plane", o.no_plane,
                  "Keep the support plane (the paper's background step: depth range only)");
    cmd->add_option("--min-points", o.min_points, "Smallest object, pixels (default 300)");
    cmd->add_option("--object-psi", o.object_psi,
                    "Weight increment of eq. 2 for object tracks, (0, 1] (default 0.5; 1 = no smoothing)");
    cmd->add_option("--threads", o.threads, "Worker threads, [1, 1024] (default: all cores)")
        ->check(NumberIn(1, wul3d::kMaxThreads));
    cmd->add_option("--decimate", o.decimate,
                    "N in [1, 8]: run the stages on every N-th pixel in u and v (N^2 times fewer "
                    "points), results at the input's size (default 2; 1 with --preset paper)");
    cmd->add_option("--tum-camera", o.tum_camera,
                    "TUM intrinsics preset: kinect_v1|tum_fr1|tum_fr2|tum_fr3 (default: from folder name)");
    cmd->add_option("--intrinsics", o.intrinsics, "fx,fy,cx,cy: override every frame's intrinsics");
    cmd->add_option("--calibration", o.calibration,
                    "Unregistered input: calibration JSON, or kinect_v2 for the built-in preset");
    cmd->add_option("--registration", o.registration, "depth-to-color|color-to-depth")
        ->capture_default_str();
}

PipelineParams make_pipeline_params(const PipelineOptions& o) {
    PipelineParams p;
    if (o.preset == "paper") {
        p = PipelineParams::paper();
    } else if (!o.preset.empty()) {
        throw ParamError("--preset '" + o.preset + "': unknown (known: paper)");
    }
    if (o.k) p.cluster.k = *o.k;
    if (o.alpha) {
        p.cluster.alpha = *o.alpha;
        if (!o.delta) p.cluster.delta = 1.0f - *o.alpha;  // eq. (5) at equality, as the paper
    }
    if (o.delta) p.cluster.delta = *o.delta;
    if (o.gamma) p.cluster.gamma = *o.gamma;
    if (o.psi) p.cluster.psi = *o.psi;
    if (o.iters) p.cluster.iters = *o.iters;
    if (o.stride) p.cluster.stride = *o.stride;
    if (o.seed) p.cluster.seed = *o.seed;
    if (o.zmin) p.range.zmin_m = *o.zmin;
    if (o.zmax) p.range.zmax_m = *o.zmax;
    if (o.normal_radius) p.normals.radius_px = *o.normal_radius;
    if (!o.segmenter.empty()) p.segmentation.segmenter = parse_segmenter(o.segmenter);
    if (!o.scope.empty()) p.segmentation.scope = parse_scope(o.scope);
    if (o.no_plane) p.remove_plane = false;
    if (o.min_points) p.segmentation.min_points = *o.min_points;
    if (o.object_psi) p.objects.psi = *o.object_psi;
    if (o.decimate) p.decimation = *o.decimate;
    p.validate();
    return p;
}

SourceOptions make_source_options(const PipelineOptions& o) {
    SourceOptions s;
    s.format = parse_input_format(o.format);
    s.tum_camera = o.tum_camera;
    s.calibration = o.calibration;
    s.bag_topics = o.topics;
    s.registration = parse_registration_mode(o.registration);
    if (!o.intrinsics.empty()) s.intrinsics = parse_intrinsics_override(o.intrinsics);
    return s;
}

std::optional<std::pair<int, int>> selected_pixel(const PipelineOptions& o) {
    if (o.select.empty()) return std::nullopt;
    return parse_select(o.select);  // the Python module's parser too (wul3d/parse.hpp)
}

void apply_threads(const PipelineOptions& o) {
    if (o.threads > 0) wul3d::set_num_threads(o.threads);
}

std::vector<std::string> input_paths(const PipelineOptions& o) {
    std::vector<std::string> inputs;
    if (!o.input.empty()) inputs.push_back(o.input);
    if (!o.calibration.empty() && o.calibration != "kinect_v2") inputs.push_back(o.calibration);
    if (!o.camera.empty()) {
        const CameraSpec spec = parse_camera_spec(o.camera);
        if (spec.backend == "openni2" && !spec.arg.empty()) inputs.push_back(spec.arg);
        const char* fake = std::getenv("FAKENECT_PATH");
        if (spec.backend == "freenect" && fake && *fake) inputs.emplace_back(fake);
    }
    return inputs;
}

}  // namespace wul3d::cli
