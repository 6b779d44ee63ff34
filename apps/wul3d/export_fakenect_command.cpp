// `wul3d export-fakenect INPUT DUMPDIR`: a recording written as a fakenect dump, the Kinect
// v1's raw 11-bit depth in its IR camera (kinect_v1.hpp), so that `fakenect DUMPDIR wul3d run
// --camera freenect` replays it through libfreenect and wul3d's registration.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "pipeline_options.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/kinect_v1.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {

namespace {

struct ExportOptions {
    std::string input, dump_dir, format = "auto";
    std::size_t max_frames = 0;
    double fps = 30.0;
};

void export_fakenect(const ExportOptions& o) {
    SourceOptions so;
    so.format = parse_input_format(o.format);
    auto source = open_source(o.input, so);
    check_write_target(o.dump_dir, WriteTarget::Folder, {o.input}, "DUMPDIR");
    const std::size_t n = o.max_frames ? std::min(o.max_frames, source->size()) : source->size();
    const StereoCalibration kinect = kinect_v1_calibration();
    FakenectDumpWriter dump(o.dump_dir, o.fps);
    SourceItem item;
    RegistrationWorkspace ws, ws_raw;
    RgbdFrame registered;
    std::vector<std::uint16_t> raw;
    bool noted = false;
    for (std::size_t i = 0; i < n; ++i) {
        source->read(i, item);
        const RgbdFrame* f = &item.frame;
        if (item.is_raw) {
            register_depth_to_color(*source->calibration(), item.raw, ws_raw, registered);
            f = &registered;
        }
        const std::string name = source->name(i);
        if (!f->has_color())
            throw InputError(name + ": no colour image; a Kinect v1 dump needs colour");
        if (f->width() != kKinectV1Width || f->height() != kKinectV1Height)
            throw InputError(name + ": " + std::to_string(f->width()) + "x" +
                             std::to_string(f->height()) + ", a Kinect v1 frame is 640x480");
        const PinholeIntrinsics& K = f->intrinsics;
        if (!noted && (std::abs(K.fx - kinect.color.fx) > 0.5 || std::abs(K.cx - kinect.color.cx) > 0.5 ||
                       std::abs(K.fy - kinect.color.fy) > 0.5 || std::abs(K.cy - kinect.color.cy) > 0.5)) {
            std::cerr << "wul3d: note: " << name << " has fx " << K.fx << ", cx " << K.cx
                      << "; the dump is seen through the Kinect v1 colour camera (fx "
                      << kinect.color.fx << ", cx " << kinect.color.cx
                      << "), so its replay has the Kinect v1's intrinsics\n";
            noted = true;
        }
        kinect_v1_depth_to_raw(f->depth, ws, raw);
        dump.add(f->color, raw);
    }
    dump.finish();
    std::cout << "wul3d: " << dump.frames() << " frames -> fakenect dump " << o.dump_dir
              << " (replay: fakenect " << o.dump_dir << " wul3d run --camera freenect ...)"
              << std::endl;
}

}  // namespace

void add_export_fakenect_command(CLI::App& app) {
    auto o = std::make_shared<ExportOptions>();
    CLI::App* cmd = app.add_subcommand(
        "export-fakenect",
        "Write a recording as a fakenect dump (Kinect v1 raw depth), for replays without a camera");
    cmd->add_option("input", o->input, "Frame folder(s), TUM RGB-D sequence, or unregistered frames")
        ->required();
    cmd->add_option("dumpdir", o->dump_dir, "Dump folder to create (must not exist or be empty)")
        ->required();
    cmd->add_option("--format", o->format, "auto|frames|tum|unregistered")->capture_default_str();
    cmd->add_option("--frames", o->max_frames, "Export the first N frames (default: all)")
        ->check(NumberIn(1, 1 << 30));
    cmd->add_option("--fps", o->fps, "Replay rate, frames per second")
        ->check(NumberIn(1.0, 120.0))->capture_default_str();
    add_max_pixels_option(cmd);
    cmd->callback([o]() { export_fakenect(*o); });
}

}  // namespace wul3d::cli
