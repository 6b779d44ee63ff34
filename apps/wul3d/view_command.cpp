// `wul3d view`: the options of `wul3d run` that shape the pipeline (pipeline_options.hpp),
// plus the window's own; the window itself is viewer_app.cpp. Built only with GLFW, OpenGL
// and Dear ImGui (cmake/Viewer.cmake); otherwise view_unavailable.cpp stands in.
#include <cmath>
#include <memory>
#include <string>

#include "cli.hpp"
#include "pipeline_options.hpp"
#include "viewer_app.hpp"
#include "wul3d/capture.hpp"
#include "wul3d/error.hpp"
#include "wul3d/parse.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {
namespace {

struct ViewOptions {
    PipelineOptions pipeline;  // input and parameters, shared with `wul3d run`
    std::string screenshot, orbit;
    int exit_after = 0, width = 1600, height = 900;
};

ViewerConfig make_config(const ViewOptions& o) {
    ViewerConfig c;
    c.input = o.pipeline.input;
    c.camera = o.pipeline.camera;
    c.lossless = o.pipeline.lossless;
    if (c.camera.empty() == c.input.empty())
        throw ParamError(c.camera.empty() ? "an INPUT or --camera is required"
                                          : "give an INPUT or --camera, not both");
    if (c.lossless && c.camera.empty()) throw ParamError("--lossless needs --camera");
    if (!c.camera.empty()) parse_camera_spec(c.camera);  // an unknown backend: exit 2 now
    c.params = make_pipeline_params(o.pipeline);
    c.source = make_source_options(o.pipeline);
    c.select = selected_pixel(o.pipeline);
    if (!o.screenshot.empty() && o.exit_after == 0)
        throw ParamError("--screenshot needs --exit-after N (frames to play first)");
    c.inputs = input_paths(o.pipeline);
    if (!o.screenshot.empty())  // before the window: a refused target costs no display
        check_write_target(o.screenshot, WriteTarget::File, c.inputs, "--screenshot");
    if (!o.orbit.empty()) {
        const auto yp = parse_numbers("--orbit", o.orbit, 2);
        // A turn of NaN degrees draws nothing; 1e308 has no float.
        if (!(std::abs(yp[0]) <= 360.0) || !(std::abs(yp[1]) <= 90.0))
            throw ParamError("--orbit '" + o.orbit +
                             "': YAW must be in [-360, 360] and PITCH in [-90, 90] degrees");
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
        "view", "Watch a recording live: objects in 3D and 2D, clusters, depth, live parameters");
    add_pipeline_options(cmd, o->pipeline);
    cmd->add_option("--screenshot", o->screenshot,
                    "After --exit-after frames, write the window to this PNG and exit");
    cmd->add_option("--exit-after", o->exit_after, "Play N frames, then exit (0: until closed)")
        ->check(NumberIn(0, 1 << 30));
    cmd->add_option("--orbit", o->orbit,
                    "YAW,PITCH: degrees to turn the first 3D view from the sensor's (default 0,0)");
    cmd->add_option("--width", o->width, "Window width, px")->check(NumberIn(640, 8192))
        ->capture_default_str();
    cmd->add_option("--height", o->height, "Window height, px")->check(NumberIn(480, 8192))
        ->capture_default_str();
    cmd->callback([o]() {
        const ViewerConfig config = make_config(*o);
        apply_threads(o->pipeline);
        run_viewer(config);
    });
}

}  // namespace wul3d::cli
