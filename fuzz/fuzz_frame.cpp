// libFuzzer harness: a whole frame folder through Pipeline::process. The input is
// [u32 size][depth.png][u32 size][color.png][intrinsics.json] (sizes little-endian; a size
// of 0 leaves color.png out); the parts are written as a frame folder, opened with
// open_source, read and processed with the default parameters by a new Pipeline.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/pipeline.hpp"

namespace {

bool take(const std::uint8_t*& p, std::size_t& left, std::string& part) {
    if (left < 4) return false;
    std::uint32_t n = 0;
    for (int i = 3; i >= 0; --i) n = (n << 8) | p[i];
    p += 4;
    left -= 4;
    if (n > left) return false;
    part.assign(reinterpret_cast<const char*>(p), n);
    p += n;
    left -= n;
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wul3d::fuzz::one_thread();
    // Small frames only: each run processes one, and the pipeline is what is fuzzed here.
    wul3d::set_max_image_pixels(std::uint64_t{1} << 16);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string depth, color;
    const std::uint8_t* p = data;
    std::size_t left = size;
    if (!take(p, left, depth) || !take(p, left, color)) return 0;
    const auto dir = wul3d::fuzz::scratch() / "frame";
    std::filesystem::create_directories(dir);
    std::filesystem::remove(dir / "color.png");
    wul3d::fuzz::write_input("frame/depth.png", reinterpret_cast<const std::uint8_t*>(depth.data()), depth.size());
    if (!color.empty())
        wul3d::fuzz::write_input("frame/color.png", reinterpret_cast<const std::uint8_t*>(color.data()), color.size());
    wul3d::fuzz::write_input("frame/intrinsics.json", p, left);
    try {
        const auto source = wul3d::open_source(dir.string(), wul3d::SourceOptions{});
        wul3d::SourceItem item;
        source->read(0, item);
        wul3d::Pipeline pipeline(wul3d::PipelineParams{});
        const wul3d::FrameResult& r = pipeline.process(item.frame);
        if (r.labels.labels.size() != static_cast<std::size_t>(item.frame.width()) * item.frame.height())
            __builtin_trap();
    } catch (const wul3d::InputError&) {
    } catch (const wul3d::ParamError&) {  // intrinsics out of range are reported as such
    }
    return 0;
}
