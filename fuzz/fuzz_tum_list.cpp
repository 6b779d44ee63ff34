// libFuzzer harness: TUM RGB-D lists. The input is rgb.txt, a line "----", then depth.txt
// (all of it rgb.txt, and depth.txt the same, without the separator); the sequence is opened
// and every frame named. The image files need not exist: their reading is fuzz_png's.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::size_t sep = text.find("\n----\n");
    const std::string rgb = sep == std::string::npos ? text : text.substr(0, sep + 1);
    const std::string depth = sep == std::string::npos ? text : text.substr(sep + 6);
    const auto dir = wul3d::fuzz::scratch() / "tum";
    std::filesystem::create_directories(dir);
    wul3d::fuzz::write_input("tum/rgb.txt", reinterpret_cast<const std::uint8_t*>(rgb.data()), rgb.size());
    wul3d::fuzz::write_input("tum/depth.txt", reinterpret_cast<const std::uint8_t*>(depth.data()), depth.size());
    wul3d::SourceOptions options;
    options.format = wul3d::InputFormat::Tum;
    try {
        const auto source = wul3d::open_source(dir.string(), options);
        for (std::size_t i = 0; i < source->size(); ++i) (void)source->name(i);
    } catch (const wul3d::Error&) {  // InputError, or ParamError for a bad tolerance
    }
    return 0;
}
