#pragma once
// Shared helpers of the test suite: where the shipped samples are, temporary folders, and
// running the wul3d command.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/frame.hpp"

namespace wul3d::test {

/// data/samples of the source tree (shipped real frames, MIT and BSD licensed).
std::filesystem::path sample_dir();
/// A shipped frame folder (depth.png, color.png, intrinsics.json) read with the library's
/// single-file readers: uois_tabletop/<name> unless `name` holds a '/'.
wul3d::RgbdFrame read_sample_frame(const std::string& name);
/// Path of the built `wul3d` command.
std::filesystem::path cli_path();

/// A fresh folder under the system temp dir, removed with its contents on destruction.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

struct CommandResult {
    int exit_code = -1;
    std::string out;  ///< stdout
    std::string err;  ///< stderr
};

/// An environment change for run_command: set to a value, or unset (nullopt).
using EnvChange = std::pair<std::string, std::optional<std::string>>;

/// Runs argv[0] (looked up in PATH) with `args`, stdin from /dev/null, `env` applied.
CommandResult run_command(const std::vector<std::string>& argv,
                          const std::vector<EnvChange>& env = {});

/// Runs the wul3d command with `args` (no shell quoting needed), stdin from /dev/null.
CommandResult run_cli(const std::vector<std::string>& args);

/// The wul3d command with `args` and `env` under `timeout 60`: a hang ends as exit 124
/// instead of stalling the suite.
CommandResult run_bounded(const std::vector<std::string>& args, const std::vector<EnvChange>& env = {});

/// The exit code, stdout and stderr of `r`, for a failed expectation's message.
std::string describe(const CommandResult& r);

/// Expects exit `code`, and one error line on stderr (besides "wul3d: note:" lines) that
/// contains every one of `words`.
void expect_one_line(const CommandResult& r, int code, const std::vector<std::string>& words);

/// The bytes of the file `p` ("" if it cannot be read).
std::string slurp(const std::filesystem::path& p);
/// Writes `text` as the whole of `p`.
void write_text(const std::filesystem::path& p, const std::string& text);
/// Copies the files of the frame folder `src` into `dst` (created).
void copy_frame(const std::filesystem::path& src, const std::filesystem::path& dst);

/// A valid-looking 16-bit grey PNG of width x height whose pixel data is one zero row: a
/// decompression bomb of a few hundred bytes, refused from its header or costing the whole
/// image once decoded.
std::string bomb_png(std::uint32_t width, std::uint32_t height);

/// Every regular file under `dir`, relative paths, sorted.
std::vector<std::string> list_files(const std::filesystem::path& dir);

}  // namespace wul3d::test
