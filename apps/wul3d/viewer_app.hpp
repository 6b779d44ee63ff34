#pragma once
// The `wul3d view` window: plays a recording through the pipeline and shows its objects (a
// colour per track id, oriented boxes and ids) in the 3D cloud and over the colour picture,
// the list of objects, the clusters (eq. 9) and depth pictures, live parameter controls,
// timings and the selected object, followed from frame to frame. GLFW + OpenGL 3.3 + Dear
// ImGui.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {

struct ViewerConfig {
    std::string input;       ///< a recording, or
    std::string camera;      ///< --camera BACKEND[:ARG]: a live camera (capture.hpp)
    bool lossless = false;   ///< --lossless: capture waits for the viewer (replays)
    SourceOptions source;
    PipelineParams params;
    std::optional<std::pair<int, int>> select;  ///< click the objects panel at frame pixel
                                                ///< (u, v) of the first frame (selects and
                                                ///< follows the object there)
    std::string screenshot;  ///< write the window here after exit_after frames, then exit
    std::vector<std::string> inputs;  ///< what the view reads: no screenshot replaces them
    int exit_after = 0;      ///< frames to play before the screenshot and exit; 0 = until closed
    int width = 1600, height = 900;  ///< window size, screen pixels
    float orbit_yaw_deg = 0, orbit_pitch_deg = 0;  ///< first 3D view, turned from the sensor's
};

/// Opens the window and runs until it is closed (or, with exit_after, until that many frames
/// were played). Throws InputError "no display ..." when no window can be opened.
void run_viewer(const ViewerConfig& config);

}  // namespace wul3d::cli
