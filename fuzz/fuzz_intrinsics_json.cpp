// libFuzzer harness: intrinsics.json.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = wul3d::fuzz::write_input("intrinsics.json", data, size);
    try {
        const wul3d::IntrinsicsFile f = wul3d::read_intrinsics_json(path);
        // What the reader accepts is in range: validate() must agree with it.
        f.intrinsics.validate();
        if (!(f.depth_scale_m_per_unit > 0) || !std::isfinite(f.depth_scale_m_per_unit)) __builtin_trap();
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
