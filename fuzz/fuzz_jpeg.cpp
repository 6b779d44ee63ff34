// libFuzzer harness: the JPEG path of the colour reader.
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
    const std::string path = wul3d::fuzz::write_input("image.jpg", data, size);
    try {
        const wul3d::ColorImage c = wul3d::read_color_image(path);
        if (c.rgb.size() != 3 * static_cast<std::size_t>(c.width) * c.height) __builtin_trap();
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
