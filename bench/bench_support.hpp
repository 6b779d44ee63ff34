#pragma once
// Real frames for the benchmarks, loaded once.
#include "wul3d/frame.hpp"

namespace wul3d::bench {

/// data/samples/uois_tabletop/image_0000: a real 640x480 tabletop frame (MIT licence).
const RgbdFrame& tabletop_frame();

}  // namespace wul3d::bench
