#include "pipeline_options.hpp"

#include "cli.hpp"

#include <charconv>
#include <cstdlib>

#include "wul3d/capture.hpp"
#include "wul3d/error.hpp"
#include "wul3d/parameters.hpp"
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

namespace {

/// One option per row of the table (parameters.hpp), its help the row's with its range and
/// default, the text kept as typed for make_pipeline_params.
void add_parameter_options(CLI::App* cmd, PipelineOptions& o) {
    const PipelineParams defaults;
    for (const ParamSpec& spec : pipeline_parameters()) {
        const std::string name = spec.name;
        if (spec.kind == ParamKind::Switch) {
            cmd->add_flag_callback(flag_of(spec), [&o, name] { o.given[name] = "false"; },
                                   spec.flag_help ? spec.flag_help : spec.help);
            continue;
        }
        std::string help = spec.help;
        if (spec.kind != ParamKind::Choice) help += ", " + range_text(spec);  // a choice's help names them
        const ParamValue value = spec.get(defaults);
        const std::string* name_value = std::get_if<std::string>(&value);
        help += " (default " + (name_value ? *name_value : value_text(value)) + ")";
        cmd->add_option_function<std::string>(
               flag_of(spec), [&o, name](const std::string& text) { o.given[name] = text; }, help)
            ->type_name(spec.kind == ParamKind::Choice ? "TEXT"
                        : spec.kind == ParamKind::Float ? "FLOAT"
                                                        : "INT");
    }
}

}  // namespace

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
    std::string presets;
    for (const auto& [name, help] : preset_names_and_help())
        presets += (presets.empty() ? "" : "; ") + name + ": " + help;
    cmd->add_option("--preset", o.preset, presets);
    add_parameter_options(cmd, o);
    cmd->add_option("--select", o.select, "U,V: follow the object under this pixel of the first frame");
    cmd->add_option("--threads", o.threads, "Worker threads, [1, 1024] (default: all cores)")
        ->check(NumberIn(1, wul3d::kMaxThreads));
    cmd->add_option("--tum-camera", o.tum_camera,
                    "TUM intrinsics preset: kinect_v1|tum_fr1|tum_fr2|tum_fr3 (default: from folder name)");
    cmd->add_option("--intrinsics", o.intrinsics, "fx,fy,cx,cy: override every frame's intrinsics");
    cmd->add_option("--calibration", o.calibration,
                    "Unregistered input: calibration JSON, or kinect_v2 for the built-in preset");
    cmd->add_option("--registration", o.registration, "depth-to-color|color-to-depth")
        ->capture_default_str();
}

PipelineParams make_pipeline_params(const PipelineOptions& o) {
    try {
        std::vector<std::pair<std::string, ParamValue>> given;
        for (const ParamSpec& spec : pipeline_parameters()) {
            const auto it = o.given.find(spec.name);
            if (it == o.given.end()) continue;
            // A switch's flag turns it off (--no-plane); the others carry their value.
            given.emplace_back(spec.name, spec.kind == ParamKind::Switch
                                              ? ParamValue{false}
                                              : parse_parameter(spec, it->second));
        }
        return make_params(o.preset, given);
    } catch (const ParamError& e) {
        if (e.parameter().empty()) throw;
        const ParamSpec* spec = find_parameter(e.parameter());
        const std::string flag = spec ? flag_of(*spec) : "--" + e.parameter();
        throw ParamError(flag + " " + e.value() + ": " + e.requirement());
    }
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
