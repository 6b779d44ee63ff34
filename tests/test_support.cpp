#include "test_support.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <fcntl.h>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "wul3d/io.hpp"

namespace wul3d::test {
namespace fs = std::filesystem;

fs::path sample_dir() { return fs::path(WUL3D_SAMPLE_DIR); }

wul3d::RgbdFrame read_sample_frame(const std::string& name) {
    const fs::path dir = sample_dir() / (name.find('/') == std::string::npos ? "uois_tabletop/" + name : name);
    wul3d::RgbdFrame f;
    const wul3d::IntrinsicsFile K = wul3d::read_intrinsics_json((dir / "intrinsics.json").string());
    f.intrinsics = K.intrinsics;
    f.depth = wul3d::read_depth_png((dir / "depth.png").string(), K.depth_scale_m_per_unit);
    f.color = wul3d::read_color_image((dir / "color.png").string());
    return f;
}
fs::path cli_path() { return fs::path(WUL3D_CLI); }

TempDir::TempDir() {
    std::random_device rd;
    for (int attempt = 0; attempt < 100; ++attempt) {
        fs::path p = fs::temp_directory_path() /
                     ("wul3d_test_" + std::to_string(::getpid()) + "_" + std::to_string(rd()));
        if (fs::create_directory(p)) {
            path_ = p;
            return;
        }
    }
    throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

void copy_frame(const fs::path& src, const fs::path& dst) {
    fs::create_directories(dst);
    for (const auto& e : fs::directory_iterator(src)) fs::copy_file(e.path(), dst / e.path().filename());
}

CommandResult run_bounded(const std::vector<std::string>& args, const std::vector<EnvChange>& env) {
    std::vector<std::string> argv = {"timeout", "60", cli_path().string()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, env);
}

std::string describe(const CommandResult& r) {
    return "exit " + std::to_string(r.exit_code) + "\n--- stdout ---\n" + r.out +
           "--- stderr ---\n" + r.err;
}

void expect_one_line(const CommandResult& r, int code, const std::vector<std::string>& words) {
    EXPECT_EQ(r.exit_code, code) << describe(r);
    std::vector<std::string> errors;
    std::istringstream lines(r.err);
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("wul3d: note:", 0) != 0) errors.push_back(line);
    ASSERT_EQ(errors.size(), 1u) << describe(r);
    for (const auto& w : words) EXPECT_NE(errors[0].find(w), std::string::npos) << w << "\n" << describe(r);
}

namespace {

CommandResult run_once(const std::vector<std::string>& args, const std::vector<EnvChange>& env) {
    TempDir io;
    const fs::path out_path = io / "stdout", err_path = io / "stderr";
    CommandResult result;
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
        for (const auto& [name, value] : env) {
            if (value)
                ::setenv(name.c_str(), value->c_str(), 1);
            else
                ::unsetenv(name.c_str());
        }
        const int in = ::open("/dev/null", O_RDONLY);
        const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(in, 0);
        ::dup2(out, 1);
        ::dup2(err, 2);
        std::vector<std::string> copy = args;
        std::vector<char*> argv;
        for (auto& s : copy) argv.push_back(s.data());
        argv.push_back(nullptr);
        ::execvp(argv[0], argv.data());
        ::_exit(127);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    result.out = slurp(out_path);
    result.err = slurp(err_path);
    return result;
}

}  // namespace

CommandResult run_command(const std::vector<std::string>& args,
                          const std::vector<EnvChange>& env) {
    // Under ASan, LeakSanitizer's tracer itself sometimes crashes at the exit of a process
    // with threads ("Tracer caught signal 11", google/sanitizers#1353): the command had done
    // its work, the leak check could not run. That, and only that, is run again (at most
    // twice); a leak report or any other failure is returned as it is.
    constexpr const char* kTracerCrash = "LeakSanitizer has encountered a fatal error";
    CommandResult result = run_once(args, env);
    for (int retry = 0; retry < 2 && result.err.find(kTracerCrash) != std::string::npos; ++retry)
        result = run_once(args, env);
    return result;
}

CommandResult run_cli(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {cli_path().string()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv);
}

std::vector<std::string> list_files(const fs::path& dir) {
    std::vector<std::string> files;
    if (!fs::exists(dir)) return files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files.push_back(fs::relative(e.path(), dir).string());
    std::sort(files.begin(), files.end());
    return files;
}

namespace {

void put32(std::string& s, std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) s.push_back(static_cast<char>((v >> shift) & 0xff));
}

void chunk(std::string& png, const char* type, const std::string& data) {
    put32(png, static_cast<std::uint32_t>(data.size()));
    std::string body = std::string(type, 4) + data;
    png += body;
    put32(png, static_cast<std::uint32_t>(
                   crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()))));
}

}  // namespace

std::string bomb_png(std::uint32_t width, std::uint32_t height) {
    std::string png = "\x89PNG\r\n\x1a\n";
    std::string ihdr;
    put32(ihdr, width);
    put32(ihdr, height);
    ihdr += std::string("\x10\x00\x00\x00\x00", 5);  // 16-bit grey, no interlace
    chunk(png, "IHDR", ihdr);
    std::string raw(2 * std::size_t{width} + 1, '\0');  // one zero row
    std::vector<Bytef> z(compressBound(static_cast<uLong>(raw.size())));
    uLongf n = static_cast<uLongf>(z.size());
    compress(z.data(), &n, reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()));
    chunk(png, "IDAT", std::string(reinterpret_cast<const char*>(z.data()), n));
    chunk(png, "IEND", "");
    return png;
}

}  // namespace wul3d::test
