// libFuzzer harness: an organized PCD file as a frame (read_pcd_frame's parser, in memory).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    wul3d::fuzz::set_fuzz_limits();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // Every bad file must end in InputError; anything else (a crash, another exception,
    // a sanitizer report, a read past the buffer) is a finding.
    try {
        const wul3d::RgbdFrame f = wul3d::parse_pcd_frame("input.pcd", data, size);
        if (f.depth.data.size() != static_cast<std::size_t>(f.depth.width) * f.depth.height)
            __builtin_trap();
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
