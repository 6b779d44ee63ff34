#include "bench_support.hpp"

#include "wul3d/io.hpp"

namespace wul3d::bench {

const RgbdFrame& tabletop_frame() {
    static const RgbdFrame frame = [] {
        auto source = open_source(std::string(WUL3D_SAMPLE_DIR) + "/uois_tabletop/image_0000",
                                  SourceOptions{});
        SourceItem item;
        source->read(0, item);
        return item.frame;
    }();
    return frame;
}

}  // namespace wul3d::bench
