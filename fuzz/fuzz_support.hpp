#pragma once
// Shared by the libFuzzer harnesses of fuzz/: the readers take paths, so each input is
// written to a file in a folder of this process's own (on tmpfs where there is one).
#include <omp.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "wul3d/io.hpp"

namespace wul3d::fuzz {

/// This process's scratch folder, created on first use and reused.
inline const std::filesystem::path& scratch() {
    static const std::filesystem::path dir = [] {
        std::filesystem::path base = std::filesystem::exists("/dev/shm")
                                         ? std::filesystem::path("/dev/shm")
                                         : std::filesystem::temp_directory_path();
        std::filesystem::path d = base / ("wul3d_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        // Removed at exit, so that a CI run leaves nothing behind.
        static const std::filesystem::path keep = d;
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(keep, ec);
        });
        return d;
    }();
    return dir;
}

/// Writes [data, data + size) to scratch() / name and returns its path.
inline std::string write_input(const std::string& name, const std::uint8_t* data, std::size_t size) {
    const std::filesystem::path p = scratch() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return p.string();
}

/// The limits the harnesses run under: images up to 2^20 pixels, so that each run stays
/// fast and small (the limit itself is what io.hpp checks before allocating).
/// One OpenMP thread: a run is one small input, and on a busy machine the start of each
/// parallel region would cost more than the work.
inline void one_thread() { omp_set_num_threads(1); }

inline void set_fuzz_limits() { set_max_image_pixels(std::uint64_t{1} << 20); }

}  // namespace wul3d::fuzz
