#pragma once
// The options that `wul3d run` and `wul3d view` share: the input and the pipeline's
// parameters. One place registers them on a subcommand and turns them into library structs,
// so the two commands cannot drift apart.
#include <CLI/CLI.hpp>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/io.hpp"
#include "wul3d/parse.hpp"  // parse_numbers, parse_select: shared with Python
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {

struct PipelineOptions {
    std::string input;   // a recording, or
    std::string camera;  // --camera BACKEND[:ARG], a live camera (capture.hpp)
    bool lossless = false;  // --lossless: capture waits for processing (replays, tests)
    std::string format = "auto";
    std::string preset;
    std::string tum_camera;
    std::string intrinsics;
    std::string calibration;
    std::string topics;  // --topics COLOR,DEPTH[,INFO] of a ROS bag
    std::string registration = "depth-to-color";
    std::string select;
    int threads = 0;  // 0 = all cores
    // The table's parameters given on the command line (parameters.hpp), name -> text as
    // typed; they override the preset. Read in the table's order by make_pipeline_params.
    std::map<std::string, std::string> given;
};

/// Registers --max-pixels on `cmd`: the largest image the readers decode (io.hpp), set as
/// it is parsed (ParamError, exit 2, outside [1, 2^30]).
void add_max_pixels_option(CLI::App* cmd);

/// Registers the input positional (or --camera) and every shared option on `cmd`.
void add_pipeline_options(CLI::App* cmd, PipelineOptions& o);

/// The preset, then every parameter given (wul3d::make_params); validated. A ParamError
/// that names a parameter of the table names its flag instead ("--object-psi 2: ...").
PipelineParams make_pipeline_params(const PipelineOptions& o);
SourceOptions make_source_options(const PipelineOptions& o);
/// --select U,V, if given.
std::optional<std::pair<int, int>> selected_pixel(const PipelineOptions& o);
/// Applies --threads.
void apply_threads(const PipelineOptions& o);

/// The files and folders the command reads, for check_write_target (write_guard.hpp): the
/// input, --calibration (not the kinect_v2 preset), an openni2:FILE.oni replay and, for
/// freenect under fakenect, the dump of FAKENECT_PATH.
std::vector<std::string> input_paths(const PipelineOptions& o);

}  // namespace wul3d::cli
