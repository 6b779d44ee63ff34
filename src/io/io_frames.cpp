// Writing frames in the frame-folder layout (docs/INPUTS.md, section 1), so that a live
// session recorded with `wul3d record` replays exactly with `wul3d run`.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "json_text.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"

namespace wul3d {
namespace fs = std::filesystem;

void write_intrinsics_json(const std::string& path, const PinholeIntrinsics& K,
                           float depth_scale_m_per_unit) {
    // nlohmann::json prints doubles with the fewest digits that read back to the same value.
    const nlohmann::json j = {{"fx", K.fx},         {"fy", K.fy},
                              {"cx", K.cx},         {"cy", K.cy},
                              {"width", K.width},   {"height", K.height},
                              {"depth_scale_m_per_unit", depth_scale_m_per_unit}};
    write_text_file(path, json_text(j, 1) + "\n");
}

void write_frame_folder(const std::string& dir, const RgbdFrame& frame) {
    write_folder_atomic(dir, [&](const std::string& tmp) {
        const fs::path tmp_dir(tmp);
        write_depth_png((tmp_dir / "depth.png").string(), frame.depth);
        if (frame.has_color()) write_color_png((tmp_dir / "color.png").string(), frame.color);
        PinholeIntrinsics K = frame.intrinsics;
        K.width = frame.depth.width;
        K.height = frame.depth.height;
        write_intrinsics_json((tmp_dir / "intrinsics.json").string(), K,
                              frame.depth.scale_m_per_unit);
    }, {"depth.png", "color.png", "intrinsics.json"});
}

}  // namespace wul3d
