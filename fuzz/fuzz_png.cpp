// libFuzzer harness: the PNG readers (depth, labels, colour) on one file.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    wul3d::fuzz::set_fuzz_limits();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = wul3d::fuzz::write_input("image.png", data, size);
    // Every bad file must end in InputError; anything else (a crash, another exception,
    // a sanitizer report) is a finding.
    try {
        wul3d::read_depth_png(path, 0.001f);
    } catch (const wul3d::InputError&) {
    }
    try {
        wul3d::read_label_png(path);
    } catch (const wul3d::InputError&) {
    }
    try {
        wul3d::read_color_image(path);
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
