#pragma once
// The `wul3d view` window's state (viewer_app.cpp: the window, the frames, input and the
// loop; viewer_draw.cpp: the panels). Private to the command.
#define GL_GLEXT_PROTOTYPES 1
#define GLFW_INCLUDE_NONE
#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer_app.hpp"
#include "viewer_gl.hpp"
#include "wul3d/io.hpp"
#include "wul3d/capture.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::cli {

using Clock = std::chrono::steady_clock;

struct Rect {
    float x = 0, y = 0, w = 0, h = 0;
    bool contains(ImVec2 p) const { return p.x >= x && p.y >= y && p.x < x + w && p.y < y + h; }
};

inline constexpr ImGuiWindowFlags kPanelFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoScrollbar |
    ImGuiWindowFlags_NoScrollWithMouse | ImGuiWindowFlags_NoBringToFrontOnFocus;
inline constexpr float kControlsWidth = 340;
inline constexpr double kRecordingFps = 30;  // playback pace when "real time" is on
inline const ImVec4 kErrorColour(1.0f, 0.45f, 0.4f, 1.0f);
inline const ImVec4 kDimColour(0.6f, 0.62f, 0.66f, 1.0f);

class Viewer {
public:
    /// Opens the input (or the camera, waiting for its first frame), runs the first frame
    /// and places the 3D view; InputError for a --select outside the frame.
    Viewer(const ViewerConfig& config, GLFWwindow* window);

    void run();

private:
    void process(std::size_t index);
    void apply_pending();
    void refresh_views();
    void rebuild_cloud();
    const OrganizedCloud& result_cloud();
    void select_at(int u, int v);
    void follow_selection();
    const DetectedObject* selected_object() const;
    void clear_selection();
    void add_plane_patch();
    void inject_pending_click();
    void handle_keys();
    void draw_object_list();
    void draw_selected();
    void draw_controls(const Rect& area);  // the left panel, its sections below in order
    void draw_source();
    void draw_playback();
    void draw_parameters();
    void draw_timings();
    void draw_view_options();
    void draw_keys();
    void draw_cloud(const Rect& area);
    void draw_image(const char* title, ImageTexture& texture, const Rect& area, bool clickable,
                    Rect* image_rect);
    void take_screenshot(const std::string& path, bool scripted);

    ViewerConfig cfg_;
    GLFWwindow* window_;
    std::unique_ptr<FrameSource> source_;  // a recording, or
    std::unique_ptr<LiveSource> live_;     // a live camera (newest frame wins)
    bool live_ended_ = false;              // a replayed camera reached its end
    SourceItem item_;
    std::unique_ptr<Pipeline> pipeline_;
    PipelineParams params_;   // what the pipeline runs with
    PipelineParams pending_;  // what the controls show; applied at the next frame
    bool params_dirty_ = false;
    bool delta_is_one_minus_alpha_ = true;
    std::string param_error_;

    const FrameResult* result_ = nullptr;
    const RgbdFrame* frame_ = nullptr;
    std::size_t current_ = 0;   // index of the frame on screen
    std::size_t played_ = 0;    // frames run through the pipeline
    double pipeline_ms_avg_ = 0;  // median of recent_ms_
    std::vector<double> recent_ms_;
    float scene_depth_ = 1.0f;  // median depth of the first frame's points, metres

    bool playing_ = true, loop_ = true, real_time_ = true, step_ = false, scripted_ = false;
    Clock::time_point last_frame_time_{};

    int selected_id_ = 0;                       // the followed object's track id, 0 none
    std::vector<std::uint8_t> mask_;            // its pixels this frame (255), empty if none
    std::map<int, std::size_t> first_seen_;     // track id -> played_ when it first showed
    std::optional<std::pair<int, int>> pending_click_;  // --select's click, frame pixel
    int click_stage_ = 0;                       // 0 not yet, 1 pressed, 2 released
    int listed_id_ = 0;                         // the selection the object list last showed
    std::string status_;

    ImageTexture tex_objects_, tex_depth_, tex_clusters_;
    ColorImage img_color_, img_objects_, img_depth_, img_clusters_;
    std::pair<float, float> depth_ramp_{0, 0};  // metres at the ramp's warm and cool ends
    CloudRenderer cloud_;
    OrbitCamera camera_;
    float view_fov_y_ = 0.8f;
    std::vector<float> xyz_;
    std::vector<std::uint8_t> rgb_;
    std::vector<std::int32_t> pixel_of_point_;
    OrganizedCloud full_cloud_;  // the frame's own cloud under --decimate (result_cloud)
    enum ColourMode { kObjects = 0, kClusters = 1, kColour = 2 };
    int cloud_colour_mode_ = kObjects;  // what colours the 3D points
    bool show_plane_ = true;            // the support plane as a translucent patch
    bool show_boxes_ = true;            // each object's oriented box and id in 3D
    bool show_inactive_ = true;
    float point_size_ = 2.0f;
    Mat4 mvp_{};
    Rect cloud_rect_, clusters_rect_, objects_rect_;
    int screenshots_ = 0;
};

}  // namespace wul3d::cli
