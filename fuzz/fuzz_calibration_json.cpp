// libFuzzer harness: the calibration JSON of an unregistered sensor.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = wul3d::fuzz::write_input("calibration.json", data, size);
    try {
        const wul3d::StereoCalibration c = wul3d::read_calibration_json(path);
        c.validate();  // what the reader accepts must be valid
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
