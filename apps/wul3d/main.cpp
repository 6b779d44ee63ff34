// wul3d command-line entry point: the only place that turns exceptions into exit codes
// (2 bad parameters or input, 3 camera lost, 1 anything else).
#include <iostream>
#include <string>

#include "cli.hpp"
#include "wul3d/error.hpp"
#include "wul3d/version.hpp"

namespace wul3d::cli {

int report(const std::exception& e, int code) {
    std::string line = e.what();
    for (char& c : line)
        if (c == '\n' || c == '\r') c = ' ';
    std::cerr << "wul3d: " << line << std::endl;
    return code;
}

}  // namespace wul3d::cli

int main(int argc, char** argv) {
    CLI::App app{"wul3d: real-time object detection in RGB-D video by weighted unsupervised "
                 "learning (Kowsari & Alassaf)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "wul3d " WUL3D_VERSION);
    wul3d::cli::add_run_command(app);
    wul3d::cli::add_bench_command(app);
    wul3d::cli::add_eval_command(app);
    wul3d::cli::add_view_command(app);
    wul3d::cli::add_record_command(app);
    wul3d::cli::add_export_fakenect_command(app);
    try {
        try {
            app.parse(argc, argv);
        } catch (const CLI::CallForHelp& e) {
            return app.exit(e);
        } catch (const CLI::CallForAllHelp& e) {
            return app.exit(e);
        } catch (const CLI::CallForVersion& e) {
            return app.exit(e);
        } catch (const CLI::ParseError& e) {
            // One line, exit 2, like every other bad input.
            return wul3d::cli::report(std::runtime_error(e.what()), 2);
        }
    } catch (const wul3d::ParamError& e) {
        return wul3d::cli::report(e, 2);
    } catch (const wul3d::InputError& e) {
        return wul3d::cli::report(e, 2);
    } catch (const wul3d::DeviceLost& e) {
        return wul3d::cli::report(e, 3);
    } catch (const std::exception& e) {
        return wul3d::cli::report(e, 1);
    }
    return 0;
}
