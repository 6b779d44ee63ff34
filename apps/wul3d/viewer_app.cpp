// The `wul3d view` window. One loop: poll input, maybe run the pipeline on the next frame,
// lay out the UI (controls and the object list | 3D cloud over objects, clusters, depth),
// draw, maybe screenshot.
#include "viewer_app.hpp"

#define GL_GLEXT_PROTOTYPES 1
#define GLFW_INCLUDE_NONE
#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "frame_feed.hpp"
#include "video_writer.hpp"
#include "viewer.hpp"
#include "viewer_gl.hpp"
#include "wul3d/capture.hpp"
#include "wul3d/error.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/visualization.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {
namespace {

// ---- the window and the UI library, released in reverse order ------------------------------

std::string g_glfw_error;  // the last GLFW error, for the one-line message
std::vector<int> g_keys;   // keys pressed since the last loop turn

struct GlfwWindow {
    GLFWwindow* window = nullptr;
    GlfwWindow(int width, int height, const std::string& title) {
        const char* x11 = std::getenv("DISPLAY");
        const char* wayland = std::getenv("WAYLAND_DISPLAY");
        if ((!x11 || !*x11) && (!wayland || !*wayland))
            throw InputError("no display: DISPLAY is not set (run in a desktop session, or "
                             "under xvfb-run)");
        glfwSetErrorCallback([](int, const char* text) { g_glfw_error = text; });
        if (!glfwInit()) throw InputError("no display: " + g_glfw_error);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
        window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
        if (!window) {
            glfwTerminate();
            throw InputError("no display: cannot open an OpenGL 3.3 window: " + g_glfw_error);
        }
        glfwMakeContextCurrent(window);
        glfwSwapInterval(1);
        // Ours first; the UI library chains to it.
        glfwSetKeyCallback(window, [](GLFWwindow*, int key, int, int action, int) {
            if (action == GLFW_PRESS || action == GLFW_REPEAT) g_keys.push_back(key);
        });
    }
    ~GlfwWindow() {
        glfwDestroyWindow(window);
        glfwTerminate();
    }
    GlfwWindow(const GlfwWindow&) = delete;
    GlfwWindow& operator=(const GlfwWindow&) = delete;
};

struct ImGuiSession {
    explicit ImGuiSession(GLFWwindow* window) {
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
        ImGui::StyleColorsDark();
        ImGuiStyle& style = ImGui::GetStyle();
        style.WindowRounding = 0;
        style.FrameRounding = 3;
        style.GrabRounding = 3;
        style.WindowBorderSize = 0;
        style.Colors[ImGuiCol_WindowBg] = ImVec4(0.11f, 0.12f, 0.14f, 1.0f);
        style.Colors[ImGuiCol_TitleBg] = ImVec4(0.16f, 0.18f, 0.22f, 1.0f);
        style.Colors[ImGuiCol_TitleBgActive] = style.Colors[ImGuiCol_TitleBg];
        ImGui_ImplGlfw_InitForOpenGL(window, true);
        ImGui_ImplOpenGL3_Init("#version 330 core");
    }
    ~ImGuiSession() {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    ImGuiSession(const ImGuiSession&) = delete;
    ImGuiSession& operator=(const ImGuiSession&) = delete;
};

}  // namespace

Viewer::Viewer(const ViewerConfig& config, GLFWwindow* window)
    : cfg_(config), window_(window), params_(config.params), pending_(config.params) {
    if (cfg_.camera.empty()) {
        source_ = open_source(cfg_.input, cfg_.source);
    } else {
        LiveOptions live;
        live.lossless = cfg_.lossless;
        live_ = std::make_unique<LiveSource>(open_camera(parse_camera_spec(cfg_.camera)), live);
        // The first frame, before the window shows anything: a camera that delivers none
        // ends in DeviceLost (LiveOptions::stall_timeout), a replay that ends in InputError.
        for (;;) {
            const LiveSource::Next r = live_->next(item_, std::chrono::milliseconds(100));
            if (r == LiveSource::Next::Frame) break;
            if (r == LiveSource::Next::End)
                throw InputError(live_->description() + ": ended before the first frame");
            if (stop_requested()) throw InputError("stopped before the first frame");
        }
    }
    delta_is_one_minus_alpha_ =
        std::abs(params_.cluster.alpha + params_.cluster.delta - 1.0f) < 1e-6f;
    pipeline_ = std::make_unique<Pipeline>(params_);
    // --select: a click on the objects panel at that pixel, once the panel is laid out.
    pending_click_ = cfg_.select;
    scripted_ = cfg_.exit_after > 0;
    playing_ = true;
    process(0);
    const RgbdFrame& f = *frame_;
    const float fov_y = 2.0f * std::atan(static_cast<float>(f.height()) /
                                         (2.0f * static_cast<float>(f.intrinsics.fy)));
    view_fov_y_ = fov_y;
    if (pending_click_ && (pending_click_->first < 0 || pending_click_->second < 0 ||
                           pending_click_->first >= f.width() ||
                           pending_click_->second >= f.height()))
        throw InputError("--select " + std::to_string(pending_click_->first) + "," +
                         std::to_string(pending_click_->second) + " is outside the " +
                         std::to_string(f.width()) + "x" + std::to_string(f.height()) +
                         " frame");
    camera_.reset(scene_depth_, fov_y);
    constexpr float kRadPerDeg = 3.14159265f / 180.0f;
    camera_.yaw = cfg_.orbit_yaw_deg * kRadPerDeg;
    camera_.pitch = std::clamp(cfg_.orbit_pitch_deg * kRadPerDeg, -1.48f, 1.48f);
}

// ---- frames --------------------------------------------------------------------------------

void Viewer::process(std::size_t index) {
    // Live: item_ already holds the frame (taken from the camera, or the one on screen).
    if (!live_) source_->read(index, item_);
    const StereoCalibration* calibration = live_ ? live_->calibration() : source_->calibration();
    const auto run_once = [&]() -> const FrameResult& {
        return item_.is_raw ? pipeline_->process(item_.raw, *calibration,
                                                 cfg_.source.registration)
                            : pipeline_->process(item_.frame);
    };
    const PipelineParams before = params_;
    const bool changed = params_dirty_;
    if (params_dirty_) apply_pending();
    try {
        result_ = &run_once();
    } catch (const wul3d::Error& e) {
        if (!changed) throw;
        // The new parameters do not fit this input (e.g. k above its points): keep the old.
        param_error_ = e.what();
        params_ = pending_ = before;
        pipeline_ = std::make_unique<Pipeline>(params_);
        first_seen_.clear();
        result_ = &run_once();
    }
    frame_ = item_.is_raw ? &pipeline_->registered() : &item_.frame;
    current_ = index;
    ++played_;
    // FPS from the median of the last 30 frames: the seeding frame does not skew it for long.
    recent_ms_.push_back(result_->times.total());
    if (recent_ms_.size() > 30) recent_ms_.erase(recent_ms_.begin());
    std::vector<double> sorted = recent_ms_;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                     sorted.end());
    pipeline_ms_avg_ = sorted[sorted.size() / 2];
    if (played_ == 1) {
        // Where the scene is, for the orbit camera's first target.
        std::vector<float> z;
        const OrganizedCloud& c = result_cloud();
        for (std::size_t p = 0; p < c.z.size(); p += 7)
            if (result_->active[p]) z.push_back(c.z[p]);
        if (!z.empty()) {
            std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2), z.end());
            scene_depth_ = std::max(0.1f, z[z.size() / 2]);
        }
    }
    for (const DetectedObject& d : result_->object_list) first_seen_.try_emplace(d.id, played_);
    follow_selection();
    refresh_views();
}

const DetectedObject* Viewer::selected_object() const {
    if (selected_id_ == 0) return nullptr;
    for (const DetectedObject& d : result_->object_list)
        if (d.id == selected_id_) return &d;
    return nullptr;
}

void Viewer::follow_selection() {
    // Track ids are stable (ObjectTracker), so following is finding the id again.
    mask_.clear();
    if (selected_id_ == 0) return;
    const std::string id = "object " + std::to_string(selected_id_);
    if (const DetectedObject* d = selected_object()) {
        const auto& L = result_->objects.labels;
        mask_.resize(L.size());
        for (std::size_t p = 0; p < L.size(); ++p) mask_[p] = L[p] == selected_id_ ? 255 : 0;
        status_ = "following " + id + ", " + std::to_string(d->pixels) + " px, tracked " +
                  std::to_string(played_ - first_seen_[d->id] + 1) + " frames";
    } else {
        status_ = id + " is not in this frame (kept: it may come back)";
    }
    if (scripted_) std::cout << "wul3d: " << frame_->name << ": " << status_ << std::endl;
}

void Viewer::clear_selection() {
    selected_id_ = 0;
    mask_.clear();
    status_.clear();
    refresh_views();
}

void Viewer::apply_pending() {
    params_dirty_ = false;
    param_error_.clear();
    if (delta_is_one_minus_alpha_) pending_.cluster.delta = 1.0f - pending_.cluster.alpha;
    try {
        pending_.validate();
    } catch (const ParamError& e) {
        param_error_ = e.what();
        pending_ = params_;
        return;
    }
    // The pipeline has no setters: a new one is the honest way, and it re-seeds (track ids
    // start again at 1, so the selection goes).
    params_ = pending_;
    pipeline_ = std::make_unique<Pipeline>(params_);
    first_seen_.clear();
    selected_id_ = 0;
}

void Viewer::refresh_views() {
    const FrameResult& r = *result_;
    render_frame_picture(*frame_, img_color_);
    depth_ramp_ = render_depth_panel(frame_->depth, params_.range.zmin_m, params_.range.zmax_m,
                                     img_depth_);
    if (r.objects.labels.size() == img_color_.rgb.size() / 3) {
        OverlayStyle style;
        style.boxes = true;
        style.selected = selected_object() ? selected_id_ : 0;
        render_object_overlay(img_color_, r.objects, r.object_list, frame_->intrinsics,
                              img_objects_, style);
    } else {
        img_objects_ = img_color_;  // no object stages: the colour alone
    }
    if (!mask_.empty()) {
        highlight_mask(r.colors, mask_, kSelectionOutline, img_clusters_);
    } else {
        img_clusters_ = r.colors;
    }
    tex_objects_.upload(img_objects_);
    tex_depth_.upload(img_depth_);
    tex_clusters_.upload(img_clusters_);
    rebuild_cloud();
}

const OrganizedCloud& Viewer::result_cloud() {
    // The cloud on the results' pixels: under --decimate the pipeline's is the smaller frame's.
    const OrganizedCloud& c = pipeline_->cloud();
    if (c.size() == result_->labels.labels.size()) return c;
    back_project(*frame_, full_cloud_);
    return full_cloud_;
}

void Viewer::rebuild_cloud() {
    const OrganizedCloud& c = result_cloud();
    const FrameResult& r = *result_;
    const bool selected = mask_.size() == c.x.size();
    const bool objects = r.objects.labels.size() == c.x.size();
    xyz_.clear();
    rgb_.clear();
    pixel_of_point_.clear();
    for (std::size_t p = 0; p < c.x.size(); ++p) {
        if (!c.valid[p]) continue;
        const bool labelled = r.labels.labels[p] != 0;
        if (!labelled && !show_inactive_) continue;
        const int object = objects ? r.objects.labels[p] : 0;
        xyz_.insert(xyz_.end(), {c.x[p], -c.y[p], -c.z[p]});
        pixel_of_point_.push_back(static_cast<std::int32_t>(p));
        std::uint8_t col[3] = {160, 160, 160};
        float gain = labelled ? 1.0f : 0.3f;
        if (cloud_colour_mode_ == kObjects && object != 0) {
            const auto oc = object_color(object);
            std::copy_n(oc.data(), 3, col);
        } else if (cloud_colour_mode_ == kClusters && labelled) {
            std::copy_n(&r.colors.rgb[3 * p], 3, col);
        } else {
            if (frame_->has_color()) std::copy_n(&frame_->color.rgb[3 * p], 3, col);
            // Objects mode: the rest of the scene (the table) stays readable but recedes.
            if (cloud_colour_mode_ == kObjects) gain *= 0.5f;
        }
        if (selected && !mask_[p]) gain *= 0.35f;
        for (int q = 0; q < 3; ++q)
            rgb_.push_back(static_cast<std::uint8_t>(static_cast<float>(col[q]) * gain));
    }
    cloud_.set_points(xyz_, rgb_);

    // Each object's oriented box in its colour (the selected one white), and a cross at the
    // selected one's centroid. View space is the camera's (x, -y, -z).
    std::vector<float> lines;
    std::vector<std::uint8_t> line_rgb;
    const auto add_line = [&](const float* a, const float* b, const std::uint8_t* rgb) {
        lines.insert(lines.end(), {a[0], -a[1], -a[2], b[0], -b[1], -b[2]});
        line_rgb.insert(line_rgb.end(), {rgb[0], rgb[1], rgb[2], rgb[0], rgb[1], rgb[2]});
    };
    for (const DetectedObject& d : r.object_list) {
        const bool is_selected = d.id == selected_id_;
        if (!show_boxes_ && !is_selected) continue;
        if (selected && !is_selected) continue;  // a selection shows its own box alone
        const auto oc = object_color(d.id);
        const std::uint8_t* rgb = is_selected ? kSelectionOutline : oc.data();
        float corner[8][3];
        for (int k = 0; k < 8; ++k)
            for (int i = 0; i < 3; ++i) {
                corner[k][i] = d.obb_centre[i];
                for (int a = 0; a < 3; ++a)
                    corner[k][i] += ((k >> a) & 1 ? 1.0f : -1.0f) * d.obb_half_extent[a] *
                                    d.obb_axes[3 * a + i];
            }
        for (int k = 0; k < 8; ++k)
            for (int a = 0; a < 3; ++a)
                if (!((k >> a) & 1)) add_line(corner[k], corner[k | (1 << a)], rgb);
        if (is_selected) {
            for (int a = 0; a < 3; ++a) {
                float lo[3], hi[3];
                for (int i = 0; i < 3; ++i) lo[i] = hi[i] = d.centroid[i];
                lo[a] -= 0.02f;
                hi[a] += 0.02f;
                add_line(lo, hi, kSelectionOutline);
            }
        }
    }
    cloud_.set_lines(lines, line_rgb);
    add_plane_patch();
}

void Viewer::add_plane_patch() {
    // The support plane as a rectangle on it, over the 2nd to 98th percentile of its points
    // along their two principal directions in the plane: the table, not the whole plane.
    std::vector<float> tri;
    std::vector<std::uint8_t> tri_rgb;
    const PlaneResult& pr = result_->plane;
    const OrganizedCloud& c = result_cloud();
    if (show_plane_ && pr.found) {
        const Plane& pl = pr.support;
        const float n[3] = {pl.nx, pl.ny, pl.nz};
        // e1 = n x (0, 0, 1) (or x (1, 0, 0) for a plane facing sideways), e2 = n x e1.
        float e1[3] = {n[1], -n[0], 0};
        if (std::abs(n[2]) > 0.9f) e1[0] = 0, e1[1] = n[2], e1[2] = -n[1];
        const float l1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        for (float& x : e1) x /= l1;
        const float e2[3] = {n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2],
                             n[0] * e1[1] - n[1] * e1[0]};
        std::vector<float> s1, s2;
        for (std::size_t p = 0; p < c.x.size(); p += 3) {
            if (!c.valid[p] || !result_->active[p]) continue;
            if (std::abs(pl.height(c.x[p], c.y[p], c.z[p])) > 0.01f) continue;
            s1.push_back(c.x[p] * e1[0] + c.y[p] * e1[1] + c.z[p] * e1[2]);
            s2.push_back(c.x[p] * e2[0] + c.y[p] * e2[1] + c.z[p] * e2[2]);
        }
        if (s1.size() >= 50) {
            // Turn (e1, e2) onto the principal axes of the points' 2 x 2 covariance, so
            // that the rectangle lies along the table's sides.
            double m1 = 0, m2 = 0, c11 = 0, c12 = 0, c22 = 0;
            for (std::size_t i = 0; i < s1.size(); ++i) m1 += s1[i], m2 += s2[i];
            m1 /= static_cast<double>(s1.size());
            m2 /= static_cast<double>(s1.size());
            for (std::size_t i = 0; i < s1.size(); ++i) {
                const double a = s1[i] - m1, b = s2[i] - m2;
                c11 += a * a, c12 += a * b, c22 += b * b;
            }
            const double angle = 0.5 * std::atan2(2 * c12, c11 - c22);
            const float ca = static_cast<float>(std::cos(angle)), sa = static_cast<float>(std::sin(angle));
            float r1[3], r2[3];
            for (int i = 0; i < 3; ++i) {
                r1[i] = ca * e1[i] + sa * e2[i];
                r2[i] = -sa * e1[i] + ca * e2[i];
            }
            for (std::size_t i = 0; i < s1.size(); ++i) {
                const float a = s1[i], b = s2[i];
                s1[i] = ca * a + sa * b;
                s2[i] = -sa * a + ca * b;
            }
            std::copy_n(r1, 3, e1);
            const float* f2 = r2;
            const auto pct = [](std::vector<float>& v, double q) {
                const auto i = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
                std::nth_element(v.begin(), v.begin() + i, v.end());
                return v[static_cast<std::size_t>(i)];
            };
            const float a0 = pct(s1, 0.02), a1 = pct(s1, 0.98), b0 = pct(s2, 0.02),
                        b1 = pct(s2, 0.98);
            const auto at = [&](float a, float b) {
                // The point a e1 + b e2 - d n lies on the plane n . X + d = 0.
                for (int i = 0; i < 3; ++i) {
                    const float x = a * e1[i] + b * f2[i] - pl.d * n[i];
                    tri.push_back(i == 0 ? x : -x);
                    tri_rgb.push_back(i == 1 ? 200 : 90);  // green
                }
            };
            at(a0, b0);
            at(a1, b0);
            at(a1, b1);
            at(a0, b0);
            at(a1, b1);
            at(a0, b1);
        }
    }
    cloud_.set_patch(tri, tri_rgb);
}

void Viewer::select_at(int u, int v) {
    // The object under (u, v), or the nearest object pixel within 15 px: a click just off a
    // thin object still takes it.
    const LabelImage& L = result_->objects;
    int best = 0, best_d2 = 15 * 15 + 1;
    for (int dv = -15; dv <= 15; ++dv)
        for (int du = -15; du <= 15; ++du) {
            const int x = u + du, y = v + dv, d2 = du * du + dv * dv;
            if (x < 0 || y < 0 || x >= L.width || y >= L.height || d2 >= best_d2) continue;
            const int l = L.labels[static_cast<std::size_t>(y) * L.width + x];
            if (l != 0) best = l, best_d2 = d2;
        }
    selected_id_ = best;
    if (best == 0) {
        status_ = "no object at (" + std::to_string(u) + ", " + std::to_string(v) + ")";
        if (scripted_) std::cout << "wul3d: " << frame_->name << ": " << status_ << std::endl;
    } else if (scripted_) {
        std::cout << "wul3d: " << frame_->name << ": clicked (" << u << ", " << v
                  << "): selected object " << best << std::endl;
    }
    follow_selection();
    refresh_views();
}

// ---- input -------------------------------------------------------------------------------

void Viewer::handle_keys() {
    std::vector<int> keys;
    keys.swap(g_keys);
    if (ImGui::GetIO().WantCaptureKeyboard) return;
    for (const int key : keys) {
        switch (key) {
            case GLFW_KEY_SPACE: playing_ = !playing_; break;
            case GLFW_KEY_RIGHT:
            case GLFW_KEY_N:
                playing_ = false;
                step_ = true;
                break;
            case GLFW_KEY_L: loop_ = !loop_; break;
            case GLFW_KEY_R: camera_.reset(scene_depth_, view_fov_y_); break;
            case GLFW_KEY_C: clear_selection(); break;
            case GLFW_KEY_O:
                cloud_colour_mode_ = (cloud_colour_mode_ + 1) % 3;
                rebuild_cloud();
                break;
            case GLFW_KEY_S: {
                char name[64];
                std::snprintf(name, sizeof name, "wul3d_view_%03d.png", ++screenshots_);
                take_screenshot(name, false);
                break;
            }
            case GLFW_KEY_ESCAPE:
            case GLFW_KEY_Q: glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
            default: break;
        }
    }
}

// ---- the loop ------------------------------------------------------------------------------

void Viewer::inject_pending_click() {
    // --select U,V: a mouse click on the objects panel at the frame's pixel (U, V), through
    // the UI library as a real click would come (press one frame, release the next), once
    // the panel has been laid out. Playback waits for it.
    if (!pending_click_ || objects_rect_.w <= 0 || tex_objects_.width() <= 0) return;
    ImGuiIO& io = ImGui::GetIO();
    const auto [u, v] = *pending_click_;
    io.MousePos = ImVec2(objects_rect_.x + (static_cast<float>(u) + 0.5f) * objects_rect_.w /
                                               static_cast<float>(tex_objects_.width()),
                         objects_rect_.y + (static_cast<float>(v) + 0.5f) * objects_rect_.h /
                                               static_cast<float>(tex_objects_.height()));
    io.MouseDown[0] = click_stage_ == 0;
    if (++click_stage_ == 2) pending_click_.reset();
}

void Viewer::run() {
    last_frame_time_ = Clock::now();
    int settle = 0;  // UI frames drawn after the last scripted frame (layout settles in two)
    install_stop_signals();
    while (!glfwWindowShouldClose(window_) && !stop_requested()) {
        glfwPollEvents();
        handle_keys();

        const bool scripted_done = scripted_ && played_ >= static_cast<std::size_t>(cfg_.exit_after);
        if (live_) {
            // The camera sets the pace: take the newest frame when there is one. DeviceLost
            // propagates (exit 3).
            if ((playing_ || step_) && !scripted_done && !live_ended_) {
                const LiveSource::Next r = live_->next(item_, std::chrono::milliseconds(5));
                if (r == LiveSource::Next::Frame) {
                    process(current_ + 1);
                    step_ = false;
                } else if (r == LiveSource::Next::End) {
                    live_ended_ = true;
                    status_ = "the camera's replay ended";
                    if (scripted_) break;
                }
            } else if (params_dirty_) {
                process(current_);  // paused: the new parameters on the frame on screen
            }
        } else {
            const std::size_t n = source_->size();
            const bool at_end = current_ + 1 >= n;
            const double since =
                std::chrono::duration<double>(Clock::now() - last_frame_time_).count();
            const bool due = playing_ && !scripted_done && !pending_click_ &&
                             (!at_end || loop_) &&
                             (scripted_ || !real_time_ || since >= 1.0 / kRecordingFps);
            if (due || step_) {
                last_frame_time_ = Clock::now();
                process(at_end ? 0 : current_ + 1);
            } else if (params_dirty_ && !playing_) {
                process(current_);  // paused: show the new parameters on this frame
            }
            step_ = false;
        }

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        inject_pending_click();
        ImGui::NewFrame();
        const ImVec2 display = ImGui::GetIO().DisplaySize;
        const float right_w = std::max(300.0f, display.x - kControlsWidth);
        const float panel_w = right_w / 3;
        const float aspect =
            static_cast<float>(frame_->height()) / static_cast<float>(std::max(1, frame_->width()));
        const float title_h = ImGui::GetFrameHeight();
        const float panel_h = std::min((panel_w - 8) * aspect + title_h + 8, display.y * 0.5f);
        const float cloud_h = std::max(100.0f, display.y - panel_h);
        draw_controls({0, 0, kControlsWidth, display.y});
        draw_cloud({kControlsWidth, 0, right_w, cloud_h});
        char objects_title[96];
        std::snprintf(objects_title, sizeof objects_title,
                      "objects: %zu, click to select###objects", result_->object_list.size());
        draw_image(objects_title, tex_objects_, {kControlsWidth, cloud_h, panel_w, panel_h}, true,
                   &objects_rect_);
        draw_image("clusters (eq. 9)###clusters", tex_clusters_,
                   {kControlsWidth + panel_w, cloud_h, panel_w, panel_h}, true, &clusters_rect_);
        char depth_title[128];
        std::snprintf(depth_title, sizeof depth_title,
                      "depth: %.2f m (yellow) to %.2f m (blue), grey out of range###depth",
                      static_cast<double>(depth_ramp_.first),
                      static_cast<double>(depth_ramp_.second));
        draw_image(depth_title, tex_depth_,
                   {kControlsWidth + 2 * panel_w, cloud_h, display.x - kControlsWidth - 2 * panel_w,
                    panel_h},
                   true, nullptr);
        ImGui::Render();

        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(window_, &fb_w, &fb_h);
        glViewport(0, 0, fb_w, fb_h);
        glClearColor(0.08f, 0.08f, 0.1f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

        if (scripted_done && ++settle >= 3) {
            if (!cfg_.screenshot.empty()) take_screenshot(cfg_.screenshot, true);
            break;
        }
        glfwSwapBuffers(window_);
    }
    restore_signals();
}

void run_viewer(const ViewerConfig& config) {
    const std::string title =
        "wul3d view: " + (config.camera.empty() ? config.input : "--camera " + config.camera);
    GlfwWindow window(config.width, config.height, title);
    ImGuiSession ui(window.window);
    Viewer viewer(config, window.window);
    viewer.run();
}

}  // namespace wul3d::cli
