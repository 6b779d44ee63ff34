// libFuzzer harness: what a fakenect dump feeds wul3d through libfreenect (capture_freenect.cpp):
// one 640 x 480 frame of raw 11-bit depth, little-endian uint16 (the bytes of a dump's .pgm
// after its header), converted to millimetres (kinect_v1_raw_to_depth) and registered to the
// colour camera with the Kinect v1 calibration, as the pipeline does with every raw frame.
// The input is repeated to fill the frame; the colour image is a fixed grey.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/kinect_v1.hpp"
#include "wul3d/registration.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 2) return 0;
    constexpr std::size_t kPixels = std::size_t{wul3d::kKinectV1Width} * wul3d::kKinectV1Height;
    static std::vector<std::uint16_t> raw(kPixels);
    const std::size_t values = size / 2;
    for (std::size_t p = 0; p < kPixels; ++p) {
        const std::size_t i = 2 * (p % values);
        raw[p] = static_cast<std::uint16_t>(data[i] | (data[i + 1] << 8));
    }
    static const wul3d::StereoCalibration calib = wul3d::kinect_v1_calibration();
    wul3d::RawRgbdFrame frame;
    frame.name = "fakenect";
    wul3d::kinect_v1_raw_to_depth(raw.data(), frame.depth);
    frame.color.width = wul3d::kKinectV1Width;
    frame.color.height = wul3d::kKinectV1Height;
    frame.color.rgb.assign(3 * kPixels, 128);
    static wul3d::RegistrationWorkspace ws;
    static wul3d::RgbdFrame out;
    try {
        wul3d::register_depth_to_color(calib, frame, ws, out);
    } catch (const wul3d::InputError&) {
    }
    return 0;
}
