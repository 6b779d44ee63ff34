// `wul3d view`: the options of `wul3d run` that shape the pipeline, plus the window's own;
// the window itself is viewer_app.cpp. Built only with GLFW, OpenGL and Dear ImGui
// (cmake/Viewer.cmake); otherwise view_unavailable.cpp stands in.
#include <omp.h>

#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "viewer_app.hpp"
#include "wul3d/error.hpp"

namespace wul3d::cli {
namespace {

struct ViewOptions {
    std::string input, format = "auto", preset, tum_camera, intrinsics, calibration;
    std::string registration = "depth-to-color", select, screenshot, orbit;
    int exit_after = 0, threads = 0, width = 1600, height = 900;
    std::optional<int> k, iters, stride, normal_radius;
    std::optional<float> alpha, delta, gamma, psi, zmin, zmax;
    std::optional<std::uint64_t> seed;
};

std::vector<double> numbers(const std::string& flag, const std::string& text,
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

ViewerConfig make_config(const ViewOptions& o) {
    ViewerConfig c;
    c.input = o.input;
    PipelineParams& p = c.params;
    if (o.preset == "paper") {
        p = PipelineParams::paper();
    } else if (!o.preset.empty()) {
        throw ParamError("--preset '" + o.preset + "': unknown (known: paper)");
    }
    if (o.k) p.cluster.k = *o.k;
    if (o.alpha) {
        p.cluster.alpha = *o.alpha;
        if (!o.delta) p.cluster.delta = 1.0f - *o.alpha;  // eq. (5) at equality, as `run`
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
    p.validate();

    c.source.format = parse_input_format(o.format);
    c.source.tum_camera = o.tum_camera;
    c.source.calibration = o.calibration;
    c.source.registration = parse_registration_mode(o.registration);
    if (!o.intrinsics.empty()) {
        const auto v = numbers("--intrinsics", o.intrinsics, 4);
        if (!(v[0] > 0 && v[1] > 0))
            throw ParamError("--intrinsics '" + o.intrinsics + "': fx and fy must be > 0");
        PinholeIntrinsics K;
        K.fx = v[0];
        K.fy = v[1];
        K.cx = v[2];
        K.cy = v[3];
        c.source.intrinsics = K;
    }
    if (!o.select.empty()) {
        const auto uv = numbers("--select", o.select, 2);
        c.select = {static_cast<int>(uv[0]), static_cast<int>(uv[1])};
    }
    if (!o.screenshot.empty() && o.exit_after == 0)
        throw ParamError("--screenshot needs --exit-after N (frames to play first)");
    if (!o.orbit.empty()) {
        const auto yp = numbers("--orbit", o.orbit, 2);
        c.orbit_yaw_deg = static_cast<float>(yp[0]);
        c.orbit_pitch_deg = static_cast<float>(yp[1]);
    }
    c.screenshot = o.screenshot;
    c.exit_after = o.exit_after;
    c.width = o.width;
    c.height = o.height;
    return c;
}

}  // namespace

void add_view_command(CLI::App& app) {
    auto o = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand(
        "view", "Watch a recording live: 3D cloud, colour, depth, clusters, live parameters");
    cmd->add_option("input", o->input,
                    "Frame folder(s), TUM RGB-D sequence, or unregistered frames")
        ->required();
    cmd->add_option("--format", o->format, "auto|frames|tum|unregistered")->capture_default_str();
    cmd->add_option("--preset", o->preset, "paper: the paper's parameters");
    cmd->add_option("--k", o->k, "Number of clusters (default 7)");
    cmd->add_option("--alpha", o->alpha, "Colour scale, eq. 4 (default 0.0033)");
    cmd->add_option("--delta", o->delta, "Position scale, eq. 4 (default 1 - alpha)");
    cmd->add_option("--gamma", o->gamma, "Normal scale, eq. 6 (default 0.0001)");
    cmd->add_option("--psi", o->psi, "Weight increment, eq. 2, (0, 1] (default 1)");
    cmd->add_option("--iters", o->iters, "k-means iterations per frame (default 1)");
    cmd->add_option("--stride", o->stride, "Sampling stride in pixels (default 1)");
    cmd->add_option("--seed", o->seed, "k-means++ seed (default 1)");
    cmd->add_option("--zmin", o->zmin, "Nearest depth kept, metres (default 0.2)");
    cmd->add_option("--zmax", o->zmax, "Farthest depth kept, metres (default 4.5)");
    cmd->add_option("--normal-radius", o->normal_radius, "Normal neighbour distance, px (default 2)");
    cmd->add_option("--select", o->select, "U,V: follow the object under this pixel of the first frame");
    cmd->add_option("--threads", o->threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_option("--tum-camera", o->tum_camera, "TUM intrinsics preset (default: from folder name)");
    cmd->add_option("--intrinsics", o->intrinsics, "fx,fy,cx,cy: override every frame's intrinsics");
    cmd->add_option("--calibration", o->calibration, "Unregistered input: calibration JSON or kinect_v2");
    cmd->add_option("--registration", o->registration, "depth-to-color|color-to-depth")
        ->capture_default_str();
    cmd->add_option("--screenshot", o->screenshot,
                    "After --exit-after frames, write the window to this PNG and exit");
    cmd->add_option("--exit-after", o->exit_after, "Play N frames, then exit (0: until closed)")
        ->check(CLI::Range(0, 1 << 30));
    cmd->add_option("--orbit", o->orbit,
                    "YAW,PITCH: degrees to turn the first 3D view from the sensor's (default 0,0)");
    cmd->add_option("--width", o->width, "Window width, px")->check(CLI::Range(640, 8192))
        ->capture_default_str();
    cmd->add_option("--height", o->height, "Window height, px")->check(CLI::Range(480, 8192))
        ->capture_default_str();
    cmd->callback([o]() {
        const ViewerConfig config = make_config(*o);
        if (o->threads > 0) omp_set_num_threads(o->threads);
        run_viewer(config);
    });
}

}  // namespace wul3d::cli
