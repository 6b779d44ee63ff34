// libFuzzer harness: ROS 1 bags (wul3d/bag.hpp). The input is the bag file; it is opened with
// layout detection, and its first frames read. Built only where librosbag is
// (cmake/Ros.cmake); seeds from make_bag_seeds (a bag of each layout).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "wul3d/bag.hpp"
#include "wul3d/error.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    wul3d::set_max_image_pixels(std::uint64_t{1} << 20);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = wul3d::fuzz::write_input("in.bag", data, size);
    wul3d::SourceOptions options;
    options.format = wul3d::InputFormat::Bag;
    try {
        const auto source = wul3d::open_bag(path, options);
        wul3d::SourceItem item;
        for (std::size_t i = 0; i < source->size() && i < 4; ++i) source->read(i, item);
    } catch (const wul3d::Error&) {  // InputError for a bad bag, ParamError for bad intrinsics
    }
    return 0;
}
