#pragma once
// `wul3d run --video FILE`: a side-by-side video of the run (colour | objects | clusters) with the frame number and the pipeline's FPS burned in, written through OpenCV's
// FFmpeg-backed VideoWriter in the plugin libwul3d_video.so (video_plugin.hpp), loaded only
// here. Also the panel pictures the viewer (`wul3d view`) shows, so the video and the window
// look alike.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/frame.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {

// ---- panels (shared with the viewer) --------------------------------------------------

/// Depth as a colour ramp over the depths in [zmin_m, zmax_m] (1st to 99th percentile):
/// near warm, far cool; out of range dark grey, invalid (0) black. Returns the ramp's
/// ends, metres.
std::pair<float, float> render_depth_panel(const DepthImage& depth, float zmin_m, float zmax_m,
                                           ColorImage& out);

/// `base` with the pixels outside `mask` (255 = object) darkened and the object's outline
/// drawn in `outline`; `mask` empty: `base` unchanged.
void highlight_mask(const ColorImage& base, const std::vector<std::uint8_t>& mask,
                    const std::uint8_t outline[3], ColorImage& out);

/// The outline colour of the selected object in the viewer and the video.
inline constexpr std::uint8_t kSelectionOutline[3] = {255, 255, 255};

// ---- the video --------------------------------------------------------------------------

/// The extensions of the containers RunVideo writes (FFmpeg picks the container from it):
/// .mp4, .m4v, .mov, .mkv, .avi.
inline constexpr const char* kVideoExtensions[] = {".mp4", ".m4v", ".mov", ".mkv", ".avi"};

/// Throws ParamError (one line, naming `path`) unless its extension is one of
/// kVideoExtensions (any case): another name would fail only at the first frame.
void check_video_name(const std::filesystem::path& path);

/// Writes one video frame per pipeline frame: three panels of the frame's size side by side
/// (colour | objects, tinted with their track ids and oriented 3D boxes | clusters, eq. 9),
/// with the frame number and FPS in the first panel. The file plays at kVideoFps frames per second, H.264 (avc1) when FFmpeg has it,
/// else MPEG-4 part 2 (mp4v). Written under a temporary name beside `path` and renamed by
/// close(); destroyed without close(), the partial file is removed.
class RunVideo {
public:
    static constexpr double kVideoFps = 30.0;

    /// Loads the video plugin (once per process, from wul3d's own folder) and creates the
    /// folder of `path`; opens nothing yet (the size comes with the first frame). Throws
    /// IoError (one line, naming the file) if the plugin is missing or cannot be loaded, or
    /// the folder cannot be created.
    explicit RunVideo(std::filesystem::path path);
    ~RunVideo();
    RunVideo(const RunVideo&) = delete;
    RunVideo& operator=(const RunVideo&) = delete;

    /// Appends the frame. `selected` is the followed cluster's mask (255 = cluster), shown
    /// on the clusters panel, or nullptr; `selected_object_id` the followed object's track
    /// id (the others darkened on the objects panel), 0 none; `index` counts from 0; `fps` is the pipeline's current
    /// frames per second. Throws IoError if the writer cannot be opened (one line, naming
    /// the file). A frame of another size than the first is scaled to the first's.
    void write(const RgbdFrame& frame, const FrameResult& result,
               const std::vector<std::uint8_t>* selected, std::size_t index, std::size_t total,
               double fps, int selected_object_id = 0);

    /// Finishes the file and renames it to `path`. Throws IoError if no frame was written.
    void close();

private:
    struct Impl;
    std::filesystem::path path_, tmp_path_;
    std::unique_ptr<Impl> impl_;
    ColorImage colour_, objects_, clusters_;
};

}  // namespace wul3d::cli
