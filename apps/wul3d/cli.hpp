#pragma once
// The wul3d command: one file per subcommand, each registering its options on the CLI11 app
// and turning them into library parameters. No algorithm lives here.
#include <CLI/CLI.hpp>
#include <exception>

namespace wul3d::cli {

/// Registers `wul3d run` on `app`; the returned callback runs it after parsing.
void add_run_command(CLI::App& app);
void add_bench_command(CLI::App& app);  ///< `wul3d bench` (bench_command.cpp)
void add_eval_command(CLI::App& app);
void add_view_command(CLI::App& app);  ///< `wul3d view` (view_command.cpp or view_unavailable.cpp)
void add_record_command(CLI::App& app);           ///< `wul3d record` (record_command.cpp)
void add_export_fakenect_command(CLI::App& app);  ///< `wul3d export-fakenect`

/// Prints "wul3d: <message>" as one line on stderr and returns `code`.
int report(const std::exception& e, int code);

}  // namespace wul3d::cli
