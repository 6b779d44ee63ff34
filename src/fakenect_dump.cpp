// Writing a fakenect dump (kinect_v1.hpp): the file layout fakenect-record(1) documents.
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
    if (!(fps > 0.0)) throw ParamError("FakenectDumpWriter: fps must be > 0");
    std::error_code ec;
    if (fs::exists(dir_, ec) && !(fs::is_directory(dir_, ec) && fs::is_empty(dir_, ec)))
        throw IoError(dir_ + ": exists and is not an empty folder");
    fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_)) throw IoError(dir_ + ": cannot create folder");
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
    const auto ticks = static_cast<unsigned>(static_cast<double>(frames_) * 60e6 / fps_);
    char name[64];
    std::snprintf(name, sizeof name, "r-%.6f-%u.ppm", t, ticks);
    write_file(fs::path(dir_) / name, "P6 640 480 255\n", color.rgb.data(), color.rgb.size());
    index_.emplace_back(name);
    // Little-endian uint16, what fakenect hands to the depth callback byte for byte.
    std::vector<unsigned char> bytes(2 * n);
    for (std::size_t p = 0; p < n; ++p) {
        bytes[2 * p] = static_cast<unsigned char>(raw_depth[p] & 0xff);
        bytes[2 * p + 1] = static_cast<unsigned char>(raw_depth[p] >> 8);
    }
    std::snprintf(name, sizeof name, "d-%.6f-%u.pgm", t + 0.001, ticks);
    write_file(fs::path(dir_) / name, "P5 640 480 65535\n", bytes.data(), bytes.size());
    index_.emplace_back(name);
    ++frames_;
}

void FakenectDumpWriter::finish() {
    std::string text;
    for (const std::string& line : index_) text += line + "\n";
    const fs::path tmp = fs::path(dir_) / ".INDEX.txt.partial";
    write_file(tmp, text, nullptr, 0);
    std::error_code ec;
    fs::rename(tmp, fs::path(dir_) / "INDEX.txt", ec);
    if (ec) throw IoError(dir_ + "/INDEX.txt: cannot write: " + ec.message());
}

}  // namespace wul3d
