#pragma once
// Private to the library: write_frame (output.hpp) for a writer that writes many frames.
#include <string>

#include "wul3d/output.hpp"

namespace wul3d::detail {

class PngEncoder;  // io/png_encode.hpp

/// write_frame with the PNG encoder the writer keeps from frame to frame (a fresh one costs
/// its buffers' first touch each frame).
void write_frame(const std::string& out_dir, const std::string& name, const OrganizedCloud* cloud,
                 const RgbdFrame& frame, const FrameResult& result, const FrameOutputs& extra,
                 PngEncoder& encoder);

}  // namespace wul3d::detail
