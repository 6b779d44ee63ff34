// Writing a fakenect dump (kinect_v1.hpp): the file layout fakenect-record(1) documents.
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "wul3d/error.hpp"
#include "wul3d/kinect_v1.hpp"

namespace wul3d {
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& path, const std::string& header, const void* data,
                std::size_t bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(header.data(), static_cast<std::streamsize>(header.size()));
    f.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    f.close();
    if (!f) throw IoError(path.string() + ": cannot write");
}

}  // namespace

FakenectDumpWriter::FakenectDumpWriter(const std::string& dir, double fps)
    : dir_(dir), fps_(fps) {
    if (!(fps > 0.0 && fps <= 1000.0)) throw ParamError("FakenectDumpWriter: fps must be in (0, 1000]");
    std::error_code ec;
    if (fs::exists(dir_, ec) && !(fs::is_directory(dir_, ec) && fs::is_empty(dir_, ec)))
        throw IoError(dir_ + ": exists and is not an empty folder");
    // Beside the dump, under a short name of its own (whatever the length of the dump's).
    static std::atomic<unsigned> serial{0};
    const fs::path parent = fs::absolute(fs::path(dir_), ec).lexically_normal().parent_path();
    fs::create_directories(parent, ec);
    tmp_ = (parent / (".wul3d-dump-" + std::to_string(::getpid()) + "-" +
                      std::to_string(serial++)))
               .string();
    if (!fs::create_directory(tmp_, ec) || ec)
        throw IoError(tmp_ + ": cannot create folder" + (ec ? " (" + ec.message() + ")" : ""));
}

FakenectDumpWriter::~FakenectDumpWriter() {
    if (finished_) return;
    // Only what this writer wrote: its files, then its folder (rmdir fails if not empty).
    std::error_code ec;
    for (const std::string& name : index_) fs::remove(fs::path(tmp_) / name, ec);
    fs::remove(fs::path(tmp_) / "INDEX.txt", ec);
    fs::remove(tmp_, ec);
}

void FakenectDumpWriter::add(const ColorImage& color, const std::vector<std::uint16_t>& raw_depth) {
    const std::size_t n = static_cast<std::size_t>(kKinectV1Width) * kKinectV1Height;
    if (color.width != kKinectV1Width || color.height != kKinectV1Height || color.rgb.size() != 3 * n)
        throw InputError("colour image is " + std::to_string(color.width) + "x" +
                         std::to_string(color.height) + ", a Kinect v1 frame is 640x480");
    if (raw_depth.size() != n) throw InputError("raw depth must have 640x480 values");
    // File times start at 1 s (fakenect sleeps by their differences); the second number is
    // the sensor timestamp handed to the callbacks, in the Kinect's 60 MHz ticks.
    const double t = 1.0 + static_cast<double>(frames_) / fps_;
    // The counter is 32 bits and wraps, as the Kinect's does (after 72 s, frame 2148 at
    // 30 FPS): through 64 bits, since a double beyond unsigned's range has no unsigned value.
    const auto ticks = static_cast<unsigned>(
        static_cast<std::uint64_t>(static_cast<double>(frames_) * 60e6 / fps_) & 0xffffffffu);
    char name[64];
    std::snprintf(name, sizeof name, "r-%.6f-%u.ppm", t, ticks);
    index_.emplace_back(name);  // listed first, so that the destructor removes it if this fails
    write_file(fs::path(tmp_) / name, "P6 640 480 255\n", color.rgb.data(), color.rgb.size());
    // Little-endian uint16, what fakenect hands to the depth callback byte for byte.
    std::vector<unsigned char> bytes(2 * n);
    for (std::size_t p = 0; p < n; ++p) {
        bytes[2 * p] = static_cast<unsigned char>(raw_depth[p] & 0xff);
        bytes[2 * p + 1] = static_cast<unsigned char>(raw_depth[p] >> 8);
    }
    std::snprintf(name, sizeof name, "d-%.6f-%u.pgm", t + 0.001, ticks);
    index_.emplace_back(name);
    write_file(fs::path(tmp_) / name, "P5 640 480 65535\n", bytes.data(), bytes.size());
    ++frames_;
}

void FakenectDumpWriter::finish() {
    std::string text;
    for (const std::string& line : index_) text += line + "\n";
    write_file(fs::path(tmp_) / "INDEX.txt", text, nullptr, 0);
    // rename(2) replaces `dir` if it is an empty folder, and fails if anything came into it.
    std::error_code ec;
    fs::rename(tmp_, dir_, ec);
    if (ec) throw IoError(dir_ + ": cannot write the dump (" + ec.message() + ")");
    finished_ = true;
}

}  // namespace wul3d
