// `wul3d record --camera SPEC --out DIR`: writes what a live camera sees as frame folders
// (registered colour and depth, the device's intrinsics), the layout `wul3d run` reads, so that
// a live session can be replayed exactly. Parsing and output only.
#include <unistd.h>

#include <exception>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli.hpp"
#include "frame_feed.hpp"
#include "json_text.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/registration.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {
namespace fs = std::filesystem;

namespace {

struct RecordOptions {
    PipelineOptions input;  // only camera and lossless are used
    std::string out_dir;
    std::size_t max_frames = 0;  // 0 = until Ctrl-C or the end of a replay
    bool quiet = false;
};

void record(const RecordOptions& o) {
    if (o.input.camera.empty()) throw ParamError("record: --camera is required");
    // Before the camera opens: a replay's own file or dump is never recorded over.
    check_write_target(o.out_dir, WriteTarget::Folder, input_paths(o.input), "--out");
    install_stop_signals();
    FrameFeed feed(feed_options(o.input, SourceOptions{}), stop_requested);
    std::error_code ec;
    fs::create_directories(o.out_dir, ec);
    if (ec || !fs::is_directory(o.out_dir))
        throw IoError(o.out_dir + ": cannot create output folder");

    SourceItem item;
    RegistrationWorkspace ws;
    RgbdFrame registered;
    std::size_t written = 0;
    std::string stopped_by = "end";
    std::exception_ptr lost;
    for (;;) {
        if (o.max_frames && written >= o.max_frames) {
            stopped_by = "frames";
            break;
        }
        if (!feed.next_frame(item, stopped_by, lost)) break;
        const RgbdFrame* frame = &item.frame;
        if (item.is_raw) {  // the same registration as `run` (Pipeline::process)
            register_depth_to_color(*feed.calibration(), item.raw, ws, registered);
            frame = &registered;
        }
        write_frame_folder((fs::path(o.out_dir) / feed.name()).string(), *frame);
        ++written;
        if (!o.quiet && ::isatty(2)) std::cerr << "\r" << written << " frames" << std::flush;
    }
    if (!o.quiet && ::isatty(2)) std::cerr << "\n";
    const nlohmann::json j = {{"camera", {{"spec", o.input.camera},
                                          {"device", feed.description()},
                                          {"lossless", o.input.lossless}}},
                              {"frames", written},
                              {"frames_captured", feed.captured()},
                              {"frames_dropped", feed.dropped()},
                              {"stopped_by", stopped_by}};
    write_text_file((fs::path(o.out_dir) / "recording.json").string(), json_text(j, 2) + "\n");
    std::cout << "wul3d: recorded " << written << " frames (" << feed.dropped()
              << " dropped) from " << feed.description() << " -> " << o.out_dir << std::endl;
    restore_signals();
    if (lost) std::rethrow_exception(lost);
    if (written == 0) throw InputError(feed.description() + ": ended before the first frame");
}

}  // namespace

void add_record_command(CLI::App& app) {
    auto o = std::make_shared<RecordOptions>();
    CLI::App* cmd = app.add_subcommand(
        "record", "Record a live camera as frame folders that `wul3d run` replays exactly");
    cmd->add_option("--camera", o->input.camera,
                    "freenect[:INDEX], openni2[:URI|FILE.oni], freenect2[:SERIAL], realsense[:SERIAL]")
        ->required();
    cmd->add_option("-o,--out", o->out_dir, "Output folder (frame_NNNNNN/ per frame)")->required();
    cmd->add_option("--frames", o->max_frames, "Stop after N frames (default: Ctrl-C or the end)")
        ->check(NumberIn(1, 1 << 30));
    cmd->add_flag("--lossless", o->input.lossless,
                  "Capture waits for each frame to be written instead of dropping (replays)");
    cmd->add_flag("-q,--quiet", o->quiet, "No progress");
    cmd->callback([o]() { record(*o); });
}

}  // namespace wul3d::cli
