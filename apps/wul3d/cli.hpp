#pragma once
// The wul3d command: one file per subcommand, each registering its options on the CLI11 app
// and turning them into library parameters. No algorithm lives here.
#include <CLI/CLI.hpp>
#include <cmath>
#include <exception>
#include <string>
#include <type_traits>

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

/// CLI::Range(min, max), but what is not a number (of T's kind: a whole number for an
/// integral T) says so ("--tolerance: '3abc' is not a whole number") where CLI::Range says
/// "Value 3abc not in range"; NaN and infinities are out of every range.
template <class T>
CLI::Validator NumberIn(T min, T max) {
    const CLI::Range range(min, max);
    return CLI::Validator(
        [range, min, max](std::string& text) -> std::string {
            const char* kind = std::is_integral_v<T> ? "a whole number" : "a number";
            std::size_t used = 0;
            double v = 0;
            try {
                v = std::stod(text, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used == 0 || used != text.size() || (std::is_integral_v<T> && v != std::floor(v)))
                return "'" + text + "' is not " + kind;
            std::string why = range(text);
            if (why.empty() && !(v >= static_cast<double>(min) && v <= static_cast<double>(max)))
                why = "Value " + text + " not in range";  // NaN, which CLI::Range lets through
            return why;
        },
        range.get_description());
}

}  // namespace wul3d::cli
