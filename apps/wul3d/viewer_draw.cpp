// The `wul3d view` window's panels: the controls, the object list, the 3D cloud, the images,
// the screenshot (viewer.hpp holds the state they draw).
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "viewer.hpp"
#include "wul3d/error.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/visualization.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {

// ---- drawing -------------------------------------------------------------------------------

void Viewer::draw_controls(const Rect& area) {
    ImGui::SetNextWindowPos(ImVec2(area.x, area.y));
    ImGui::SetNextWindowSize(ImVec2(area.w, area.h));
    ImGui::Begin("wul3d view", nullptr, kPanelFlags & ~ImGuiWindowFlags_NoScrollbar &
                                            ~ImGuiWindowFlags_NoScrollWithMouse);
    draw_source();
    draw_playback();
    draw_object_list();
    draw_parameters();
    draw_timings();
    draw_selected();
    draw_view_options();
    draw_keys();
    ImGui::End();
}

/// The recording (or camera) and the frame on screen.
void Viewer::draw_source() {
    if (live_) {
        ImGui::TextWrapped("%s", live_->description().c_str());
        ImGui::Text("%s   %llu captured, %llu dropped%s", frame_->name.c_str(),
                    static_cast<unsigned long long>(live_->captured()),
                    static_cast<unsigned long long>(live_->dropped()),
                    live_ended_ ? ", ended" : "");
    } else {
        ImGui::TextWrapped("%s", cfg_.input.c_str());
        ImGui::Text("frame %zu / %zu   %s", current_ + 1, source_->size(), frame_->name.c_str());
    }
}

/// Play, pause, step, loop, real time.
void Viewer::draw_playback() {
    if (ImGui::CollapsingHeader("Playback", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (ImGui::Button(playing_ ? "Pause" : "Play", ImVec2(70, 0))) playing_ = !playing_;
        ImGui::SameLine();
        if (ImGui::Button("Step", ImVec2(70, 0))) {
            playing_ = false;
            step_ = true;
        }
        ImGui::SameLine();
        ImGui::Checkbox("Loop", &loop_);
        ImGui::Checkbox("Real time (30 FPS at most)", &real_time_);
    }
}

/// The clustering's parameters, applied (and re-seeded) at the next frame.
void Viewer::draw_parameters() {
    if (ImGui::CollapsingHeader("Parameters")) {
        ImGui::PushItemWidth(170);
        ClusterParams& c = pending_.cluster;
        bool changed = false;
        changed |= ImGui::SliderInt("k", &c.k, 1, 32);
        changed |= ImGui::SliderFloat("alpha (eq. 4)", &c.alpha, 0.0005f, 0.2f, "%.4f",
                                      ImGuiSliderFlags_Logarithmic);
        changed |= ImGui::Checkbox("delta = 1 - alpha", &delta_is_one_minus_alpha_);
        ImGui::BeginDisabled(delta_is_one_minus_alpha_);
        if (delta_is_one_minus_alpha_) c.delta = 1.0f - c.alpha;
        changed |= ImGui::SliderFloat("delta (eq. 4)", &c.delta, 0.5f, 1.0f, "%.4f");
        ImGui::EndDisabled();
        changed |= ImGui::SliderFloat("gamma (eq. 6)", &c.gamma, 0.00001f, 0.1f, "%.5f",
                                      ImGuiSliderFlags_Logarithmic);
        changed |= ImGui::SliderFloat("psi (eq. 2)", &c.psi, 0.01f, 1.0f, "%.2f");
        changed |= ImGui::DragFloatRange2("depth, m", &pending_.range.zmin_m,
                                          &pending_.range.zmax_m, 0.01f, 0.0f, 10.0f, "%.2f");
        changed |= ImGui::SliderInt("stride, px", &c.stride, 1, 8);
        changed |= ImGui::SliderInt("iterations", &c.iters, 1, 10);
        ImGui::PopItemWidth();
        if (changed) params_dirty_ = true;
        if (ImGui::Button("Re-seed")) params_dirty_ = true;
        ImGui::SameLine();
        if (ImGui::Button("Paper preset")) {
            pending_ = PipelineParams::paper();
            delta_is_one_minus_alpha_ = true;
            params_dirty_ = true;
        }
        ImGui::TextColored(kDimColour, params_dirty_ ? "applies at the next frame (re-seeds)"
                                                     : "changes re-seed at the next frame");
        if (!param_error_.empty()) {
            ImGui::PushStyleColor(ImGuiCol_Text, kErrorColour);
            ImGui::TextWrapped("%s", param_error_.c_str());
            ImGui::PopStyleColor();
        }
    }
}

/// The pipeline's rate and each stage's share of the frame.
void Viewer::draw_timings() {
    if (ImGui::CollapsingHeader("Timings", ImGuiTreeNodeFlags_DefaultOpen)) {
        const StageTimes& t = result_->times;
        ImGui::Text("pipeline %.1f FPS (%.1f ms)   window %.0f FPS",
                    pipeline_ms_avg_ > 0 ? 1000.0 / pipeline_ms_avg_ : 0.0, pipeline_ms_avg_,
                    static_cast<double>(ImGui::GetIO().Framerate));
        const std::pair<const char*, double> stages[] = {
            {"registration", t.registration}, {"back-projection", t.backprojection},
            {"normals", t.normals},           {"background", t.background},
            {"clustering", t.clustering},     {"colours (eq. 9)", t.colors},
            // Stages added after these (objects, ...): total() counts them, less the time
            // they ran beside the clustering (StageTimes::overlap).
            {"later stages", t.total() - t.registration - t.backprojection - t.normals -
                                 t.background - t.clustering - t.colors}};
        const double total = std::max(1e-9, t.total());
        for (const auto& [name, ms] : stages) {
            char label[32];
            std::snprintf(label, sizeof label, "%.2f ms", ms);
            ImGui::ProgressBar(static_cast<float>(ms / total), ImVec2(150, 0), label);
            ImGui::SameLine();
            ImGui::TextUnformatted(name);
        }
        const FrameStats& s = result_->stats;
        ImGui::PushStyleColor(ImGuiCol_Text, kDimColour);
        ImGui::TextWrapped("%zu points clustered, %zu in range, tau %lld, re-seeded %d",
                           s.points, result_->active_points, static_cast<long long>(s.tau),
                           s.reseeded);
        ImGui::PopStyleColor();
    }
}

/// What the 3D view shows and colours.
void Viewer::draw_view_options() {
    if (ImGui::CollapsingHeader("3D view", ImGuiTreeNodeFlags_DefaultOpen)) {
        bool changed = ImGui::RadioButton("objects", &cloud_colour_mode_, kObjects);
        ImGui::SameLine();
        changed |= ImGui::RadioButton("clusters (eq. 9)", &cloud_colour_mode_, kClusters);
        ImGui::SameLine();
        changed |= ImGui::RadioButton("colour", &cloud_colour_mode_, kColour);
        changed |= ImGui::Checkbox("boxes and ids", &show_boxes_);
        ImGui::SameLine();
        changed |= ImGui::Checkbox("support plane", &show_plane_);
        changed |= ImGui::Checkbox("points out of range (dim)", &show_inactive_);
        ImGui::PushItemWidth(170);
        ImGui::SliderFloat("point size", &point_size_, 1.0f, 6.0f, "%.1f");
        ImGui::PopItemWidth();
        if (ImGui::Button("Reset view (R)")) camera_.reset(scene_depth_, view_fov_y_);
        if (changed) rebuild_cloud();
    }
}

/// The keyboard and mouse, as a reminder.
void Viewer::draw_keys() {
    if (ImGui::CollapsingHeader("Keys")) {
        ImGui::TextColored(kDimColour,
                           "space play/pause   N or right step\n"
                           "L loop   R reset view   C clear selection\n"
                           "O objects / clusters / colour in 3D\n"
                           "S screenshot (wul3d_view_NNN.png)   Q quit\n"
                           "3D: left drag orbit, right drag pan,\n"
                           "    wheel zoom, click select");
    }
}

void Viewer::draw_object_list() {
    const auto& list = result_->object_list;
    char header[64];
    std::snprintf(header, sizeof header, "Objects: %zu###objects", list.size());
    if (!ImGui::CollapsingHeader(header, ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (list.empty()) {
        ImGui::TextColored(kDimColour, "no object in this frame");
        return;
    }
    constexpr ImGuiTableFlags kFlags = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV |
                                       ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollY;
    const float rows = static_cast<float>(std::min<std::size_t>(list.size(), 8) + 1);
    if (!ImGui::BeginTable("##objects", 5, kFlags,
                           ImVec2(0, rows * ImGui::GetTextLineHeightWithSpacing() + 6)))
        return;
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("id");
    ImGui::TableSetupColumn("pixels");
    ImGui::TableSetupColumn("size, cm");
    ImGui::TableSetupColumn("dist, m");
    ImGui::TableSetupColumn("frames");
    ImGui::TableHeadersRow();
    for (const DetectedObject& d : list) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        const auto c = object_color(d.id);
        ImGui::ColorButton("##c", ImVec4(c[0] / 255.0f, c[1] / 255.0f, c[2] / 255.0f, 1),
                           ImGuiColorEditFlags_NoTooltip, ImVec2(12, 12));
        ImGui::SameLine();
        char id[16];
        std::snprintf(id, sizeof id, "%d", d.id);
        // The whole row is the click target.
        // A selection made elsewhere (a click in 2D or 3D) scrolls its row into view once.
        if (d.id == selected_id_ && listed_id_ != selected_id_) ImGui::SetScrollHereY();
        if (ImGui::Selectable(id, d.id == selected_id_, ImGuiSelectableFlags_SpanAllColumns)) {
            selected_id_ = d.id == selected_id_ ? 0 : d.id;
            follow_selection();
            refresh_views();
        }
        ImGui::TableNextColumn();
        ImGui::Text("%zu", d.pixels);
        ImGui::TableNextColumn();
        // The oriented box's sides, largest first.
        float side[3] = {200 * d.obb_half_extent[0], 200 * d.obb_half_extent[1],
                         200 * d.obb_half_extent[2]};
        std::sort(side, side + 3, std::greater<>());
        ImGui::Text("%.0f x %.0f x %.0f", static_cast<double>(side[0]),
                    static_cast<double>(side[1]), static_cast<double>(side[2]));
        ImGui::TableNextColumn();
        ImGui::Text("%.2f", static_cast<double>(std::sqrt(d.centroid[0] * d.centroid[0] +
                                                          d.centroid[1] * d.centroid[1] +
                                                          d.centroid[2] * d.centroid[2])));
        ImGui::TableNextColumn();
        const auto seen = first_seen_.find(d.id);
        ImGui::Text("%zu", seen == first_seen_.end() ? std::size_t{1} : played_ - seen->second + 1);
    }
    ImGui::EndTable();
    listed_id_ = selected_id_;
}

void Viewer::draw_selected() {
    if (!ImGui::CollapsingHeader("Selected object", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (selected_id_ == 0) {
        ImGui::PushStyleColor(ImGuiCol_Text, kDimColour);
        ImGui::TextWrapped("click an object in a picture, in 3D or in the list");
        ImGui::PopStyleColor();
    } else {
        const auto col = object_color(selected_id_);
        ImGui::ColorButton("##sel", ImVec4(col[0] / 255.0f, col[1] / 255.0f, col[2] / 255.0f, 1),
                           ImGuiColorEditFlags_NoTooltip, ImVec2(14, 14));
        ImGui::SameLine();
        ImGui::Text("object %d", selected_id_);
        if (const DetectedObject* d = selected_object()) {
            const auto seen = first_seen_.find(d->id);
            ImGui::Text("%zu px, tracked %zu frames", d->pixels,
                        seen == first_seen_.end() ? std::size_t{1} : played_ - seen->second + 1);
            ImGui::Text("centroid %.3f, %.3f, %.3f m", static_cast<double>(d->centroid[0]),
                        static_cast<double>(d->centroid[1]), static_cast<double>(d->centroid[2]));
            ImGui::Text("box %.1f x %.1f x %.1f cm", 200.0 * d->obb_half_extent[0],
                        200.0 * d->obb_half_extent[1], 200.0 * d->obb_half_extent[2]);
            ImGui::Text("mean colour %.0f, %.0f, %.0f", static_cast<double>(d->mean_rgb[0]),
                        static_cast<double>(d->mean_rgb[1]), static_cast<double>(d->mean_rgb[2]));
        }
        if (ImGui::Button("Clear (C)")) clear_selection();
    }
    if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
}

void Viewer::draw_cloud(const Rect& area) {
    ImGui::SetNextWindowPos(ImVec2(area.x, area.y));
    ImGui::SetNextWindowSize(ImVec2(area.w, area.h));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    static constexpr const char* kTitles[3] = {
        "3D: objects (track ids, oriented boxes)###3d", "3D: clusters (eq. 9)###3d",
        "3D: colour###3d"};
    ImGui::Begin(kTitles[cloud_colour_mode_], nullptr, kPanelFlags);
    const ImVec2 pos = ImGui::GetCursorScreenPos();
    const ImVec2 size = ImGui::GetContentRegionAvail();
    cloud_rect_ = {pos.x, pos.y, size.x, size.y};
    const ImGuiIO& io = ImGui::GetIO();
    const int w = std::max(1, static_cast<int>(size.x * io.DisplayFramebufferScale.x));
    const int h = std::max(1, static_cast<int>(size.y * io.DisplayFramebufferScale.y));

    ImGui::InvisibleButton("##cloud", ImVec2(std::max(1.0f, size.x), std::max(1.0f, size.y)),
                           ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                               ImGuiButtonFlags_MouseButtonMiddle);
    // Not on the press itself: the mouse may have jumped there since the last frame.
    if (ImGui::IsItemActive() && !ImGui::IsItemActivated()) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left))
            camera_.orbit(io.MouseDelta.x, io.MouseDelta.y);
        else
            camera_.pan(io.MouseDelta.x, io.MouseDelta.y, size.y);
    }
    if (ImGui::IsItemHovered() && io.MouseWheel != 0) camera_.zoom(io.MouseWheel);
    if (ImGui::IsItemHovered() && ImGui::IsMouseReleased(ImGuiMouseButton_Left) &&
        io.MouseDragMaxDistanceSqr[0] < 16.0f) {
        // A click, not a drag: the front-most point within 6 px of the mouse.
        const float mx = io.MousePos.x - pos.x, my = io.MousePos.y - pos.y;
        int best = -1;
        float best_w = 1e30f;
        for (std::size_t i = 0; i < pixel_of_point_.size(); ++i) {
            const float* p = &xyz_[3 * i];
            const float cx = mvp_[0] * p[0] + mvp_[4] * p[1] + mvp_[8] * p[2] + mvp_[12];
            const float cy = mvp_[1] * p[0] + mvp_[5] * p[1] + mvp_[9] * p[2] + mvp_[13];
            const float cw = mvp_[3] * p[0] + mvp_[7] * p[1] + mvp_[11] * p[2] + mvp_[15];
            if (cw <= 0) continue;
            const float sx = (cx / cw * 0.5f + 0.5f) * size.x;
            const float sy = (0.5f - cy / cw * 0.5f) * size.y;
            if ((sx - mx) * (sx - mx) + (sy - my) * (sy - my) < 36.0f && cw < best_w) {
                best_w = cw;
                best = pixel_of_point_[i];
            }
        }
        if (best >= 0) {
            // pixel_of_point_ indexes the results' pixels (result_cloud), not the
            // decimated cloud's.
            const int W = result_->labels.width;
            select_at(best % W, best / W);
        } else {
            status_ = "no point under the mouse";
        }
    }

    mvp_ = multiply(camera_.projection(size.x / std::max(1.0f, size.y)), camera_.view());
    const float background[3] = {0.05f, 0.055f, 0.07f};
    const unsigned tex = cloud_.render(w, h, mvp_, point_size_, background);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(tex)), pos,
                 ImVec2(pos.x + size.x, pos.y + size.y), ImVec2(0, 1), ImVec2(1, 0));
    // Each object's id on a tag at the top of its box, in screen space.
    for (const DetectedObject& d : result_->object_list) {
        if (!show_boxes_ && d.id != selected_id_) continue;
        if (!mask_.empty() && d.id != selected_id_) continue;
        float top[3] = {d.centroid[0], d.centroid[1], d.centroid[2]};
        top[1] = std::min(top[1], d.aabb_min[1]);  // camera y points down: the box's top
        const float x = top[0], y = -top[1], z = -top[2];
        const float cx = mvp_[0] * x + mvp_[4] * y + mvp_[8] * z + mvp_[12];
        const float cy = mvp_[1] * x + mvp_[5] * y + mvp_[9] * z + mvp_[13];
        const float cw = mvp_[3] * x + mvp_[7] * y + mvp_[11] * z + mvp_[15];
        if (cw <= 0) continue;
        const ImVec2 at(pos.x + (cx / cw * 0.5f + 0.5f) * size.x,
                        pos.y + (0.5f - cy / cw * 0.5f) * size.y);
        if (!cloud_rect_.contains(at)) continue;
        char id[16];
        std::snprintf(id, sizeof id, "%d", d.id);
        const ImVec2 ts = ImGui::CalcTextSize(id);
        const auto c = object_color(d.id);
        const ImVec2 lo(at.x - ts.x / 2 - 4, at.y - ts.y - 6), hi(at.x + ts.x / 2 + 4, at.y - 2);
        dl->AddRectFilled(lo, hi, IM_COL32(20, 20, 24, 220), 3);
        dl->AddRect(lo, hi, IM_COL32(c[0], c[1], c[2], 255), 3);
        dl->AddText(ImVec2(lo.x + 4, lo.y + 2), IM_COL32(255, 255, 255, 255), id);
    }
    char line[160];
    if (live_)
        std::snprintf(line, sizeof line, "live  %s   k = %d", frame_->name.c_str(),
                      params_.cluster.k);
    else
        std::snprintf(line, sizeof line, "frame %zu/%zu  %s   k = %d", current_ + 1,
                      source_->size(), frame_->name.c_str(), params_.cluster.k);
    dl->AddText(ImVec2(pos.x + 10, pos.y + 8), IM_COL32(235, 235, 235, 255), line);
    dl->AddText(ImVec2(pos.x + 10, pos.y + size.y - 22), IM_COL32(150, 155, 165, 255),
                "left drag: orbit   right drag: pan   wheel: zoom   R: reset   click: select");
    ImGui::End();
    ImGui::PopStyleVar();
}

void Viewer::draw_image(const char* title, ImageTexture& texture, const Rect& area,
                        bool clickable, Rect* image_rect) {
    ImGui::SetNextWindowPos(ImVec2(area.x, area.y));
    ImGui::SetNextWindowSize(ImVec2(area.w, area.h));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(4, 4));
    ImGui::Begin(title, nullptr, kPanelFlags);
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const float aspect =
        static_cast<float>(texture.height()) / static_cast<float>(std::max(1, texture.width()));
    float w = avail.x, h = avail.x * aspect;
    if (h > avail.y) {
        h = avail.y;
        w = h / aspect;
    }
    ImVec2 pos = ImGui::GetCursorScreenPos();
    pos.x += (avail.x - w) / 2;  // centred
    ImGui::SetCursorScreenPos(pos);
    ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture.id())),
                 ImVec2(w, h));
    if (image_rect) *image_rect = {pos.x, pos.y, w, h};
    if (ImGui::IsItemHovered()) {
        const ImVec2 m = ImGui::GetIO().MousePos;
        const int u = std::clamp(static_cast<int>((m.x - pos.x) / w * static_cast<float>(texture.width())), 0,
                                 texture.width() - 1);
        const int v = std::clamp(static_cast<int>((m.y - pos.y) / h * static_cast<float>(texture.height())), 0,
                                 texture.height() - 1);
        const std::size_t p = static_cast<std::size_t>(v) * texture.width() + u;
        const float z = p < frame_->depth.data.size()
                            ? static_cast<float>(frame_->depth.data[p]) * frame_->depth.scale_m_per_unit
                            : 0.0f;
        const int label = p < result_->labels.labels.size() ? result_->labels.labels[p] : 0;
        const int object = p < result_->objects.labels.size() ? result_->objects.labels[p] : 0;
        ImGui::BeginTooltip();
        ImGui::Text("(%d, %d)  z %.3f m  cluster %d  object %d", u, v, static_cast<double>(z),
                    label, object);
        ImGui::EndTooltip();
        if (clickable && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) select_at(u, v);
    }
    ImGui::End();
    ImGui::PopStyleVar();
}

void Viewer::take_screenshot(const std::string& path, bool scripted) {
    try {
        check_write_target(path, WriteTarget::File, cfg_.inputs, "screenshot");
    } catch (const InputError& e) {
        if (scripted) throw;
        status_ = e.what();  // S in the window: said there, the viewer plays on
        return;
    }
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    write_color_png(path, read_framebuffer(w, h));
    const float s = ImGui::GetIO().DisplayFramebufferScale.x;
    const auto px = [s](float x) { return static_cast<int>(std::lround(x * s)); };
    status_ = "screenshot: " + path;
    if (scripted)
        std::cout << "wul3d: screenshot " << path << " (" << w << "x" << h
                  << "), objects panel at " << px(objects_rect_.x) << "," << px(objects_rect_.y)
                  << " " << px(objects_rect_.w) << "x" << px(objects_rect_.h)
                  << ", clusters panel at " << px(clusters_rect_.x) << "," << px(clusters_rect_.y)
                  << " " << px(clusters_rect_.w) << "x" << px(clusters_rect_.h) << std::endl;
}

}  // namespace wul3d::cli
