// The side-by-side video of `wul3d run --video` (colour | objects | clusters) and the panel pictures shared with the viewer.
#include "video_writer.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <dlfcn.h>

#include <opencv2/imgproc.hpp>
#include <string>
#include <system_error>
#include <utility>

#include "video_plugin.hpp"
#include "wul3d/error.hpp"
#include "wul3d/visualization.hpp"

namespace wul3d::cli {
namespace fs = std::filesystem;

namespace {

void resize_like(int width, int height, ColorImage& out) {
    out.width = width;
    out.height = height;
    out.rgb.resize(static_cast<std::size_t>(width) * height * 3);
}

/// A ramp from warm (t = 0, near) through green to blue (t = 1, far): readable without a
/// legend, and distinct from the cluster colours' grey surroundings.
void ramp(float t, std::uint8_t* o) {
    static constexpr float kStops[5][3] = {
        {250, 230, 90}, {245, 130, 50}, {200, 60, 90}, {90, 70, 170}, {30, 50, 110}};
    t = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(3, static_cast<int>(t));
    const float f = t - static_cast<float>(i);
    for (int q = 0; q < 3; ++q)
        o[q] = static_cast<std::uint8_t>(kStops[i][q] + f * (kStops[i + 1][q] - kStops[i][q]));
}

}  // namespace

std::pair<float, float> render_depth_panel(const DepthImage& depth, float zmin_m, float zmax_m,
                                           ColorImage& out) {
    resize_like(depth.width, depth.height, out);
    // The ramp spans the 1st to 99th percentile of the depths in range (a sample of them),
    // so a tabletop at 0.6-1.2 m does not sit in one colour of a 0.2-4.5 m ramp.
    std::vector<float> sample;
    for (std::size_t p = 0; p < depth.data.size(); p += 5) {
        const float z = static_cast<float>(depth.data[p]) * depth.scale_m_per_unit;
        if (depth.data[p] != 0 && z >= zmin_m && z <= zmax_m) sample.push_back(z);
    }
    float lo = zmin_m, hi = zmax_m;
    if (sample.size() >= 100) {
        const auto at = [&](std::size_t i) {
            std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(i),
                             sample.end());
            return sample[i];
        };
        lo = at(sample.size() / 100);
        hi = at(sample.size() - 1 - sample.size() / 100);
    }
    const float span = std::max(1e-3f, hi - lo);
    for (std::size_t p = 0; p < depth.data.size(); ++p) {
        std::uint8_t* o = out.rgb.data() + 3 * p;
        const float z = static_cast<float>(depth.data[p]) * depth.scale_m_per_unit;
        if (depth.data[p] == 0) {
            o[0] = o[1] = o[2] = 0;
        } else if (z < zmin_m || z > zmax_m) {
            o[0] = o[1] = o[2] = 60;
        } else {
            ramp((z - lo) / span, o);
        }
    }
    return {lo, hi};
}

void highlight_mask(const ColorImage& base, const std::vector<std::uint8_t>& mask,
                    const std::uint8_t outline[3], ColorImage& out) {
    out = base;
    const int W = base.width, H = base.height;
    if (mask.size() != static_cast<std::size_t>(W) * H) return;
    auto in = [&](int u, int v) {
        return u >= 0 && v >= 0 && u < W && v < H && mask[static_cast<std::size_t>(v) * W + u];
    };
    for (int v = 0; v < H; ++v) {
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            std::uint8_t* o = out.rgb.data() + 3 * p;
            if (!mask[p]) {
                for (int q = 0; q < 3; ++q) o[q] = static_cast<std::uint8_t>(o[q] / 4);
            } else if (!in(u - 1, v) || !in(u + 1, v) || !in(u, v - 1) || !in(u, v + 1)) {
                for (int q = 0; q < 3; ++q) o[q] = outline[q];
            }
        }
    }
}

// ---- RunVideo ---------------------------------------------------------------------------

void check_video_name(const fs::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string known;
    for (const char* e : kVideoExtensions) {
        if (ext == e) return;
        known += (known.empty() ? "" : ", ") + std::string(e);
    }
    throw ParamError("--video " + path.string() + ": " +
                     (ext.empty() ? std::string("no extension") : "unknown extension " + ext) +
                     "; a video is written as " + known);
}

namespace {

/// The plugin's table, or why there is none (one line). Loaded once per process.
struct LoadedPlugin {
    const Wul3dVideoApi* api = nullptr;
    std::string error;
};

LoadedPlugin load_plugin() {
    LoadedPlugin r;
    const std::string name = WUL3D_VIDEO_PLUGIN_FILE;
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) {
        r.error = "plugin " + name + " not found: no /proc/self/exe: " + ec.message();
        return r;
    }
    const fs::path file = exe.parent_path() / name;
    dlerror();
    void* lib = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char* why = dlerror();
        r.error = "plugin " + name +
                  (fs::exists(file, ec) ? " cannot be loaded: " : " not found next to wul3d: ") +
                  (why ? why : file.string());
        return r;
    }
    const auto entry = reinterpret_cast<Wul3dVideoApiEntry>(dlsym(lib, WUL3D_VIDEO_API_SYMBOL));
    r.api = entry ? entry(WUL3D_VIDEO_API_VERSION) : nullptr;
    if (!r.api || r.api->version != WUL3D_VIDEO_API_VERSION) {
        r.api = nullptr;
        r.error = "plugin " + file.string() + " is not wul3d's video plugin of interface version " +
                  std::to_string(WUL3D_VIDEO_API_VERSION) + " (rebuild wul3d and its plugin together)";
        dlclose(lib);
    }
    // Kept loaded to the end of the process: FFmpeg may hold threads and atexit handlers.
    return r;
}

const Wul3dVideoApi& video_plugin(const fs::path& video) {
    static const LoadedPlugin plugin = load_plugin();
    if (!plugin.api) throw IoError(video.string() + ": cannot write the video (" + plugin.error + ")");
    return *plugin.api;
}

}  // namespace

struct RunVideo::Impl {
    const Wul3dVideoApi* api = nullptr;
    void* writer = nullptr;  // the plugin's, null until the first frame
    cv::Size panel;          // every panel's size: the first frame's
    cv::Mat canvas;          // BGR, 3 panels side by side
};

RunVideo::RunVideo(fs::path path) : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
    // First the plugin: without it nothing is created.
    impl_->api = &video_plugin(path_);
    const fs::path dir = path_.has_parent_path() ? path_.parent_path() : fs::path(".");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
        throw IoError(path_.string() + ": cannot create the video's folder" +
                      (ec ? ": " + ec.message() : ""));
    // FFmpeg picks the container from the extension, so the temporary name keeps it.
    std::string name = path_.stem().string();
    name.insert(0, 1, '.');
    name.append(".partial").append(path_.extension().string());
    tmp_path_ = dir / name;
}

RunVideo::~RunVideo() {
    if (impl_->writer) impl_->api->close(impl_->writer);
    std::error_code ec;
    if (!tmp_path_.empty()) fs::remove(tmp_path_, ec);
}

namespace {

/// Pastes an RGB image into the BGR canvas at column x0, scaled to `size` if needed.
void paste(const ColorImage& image, cv::Mat& canvas, int x0, cv::Size size) {
    const cv::Mat rgb(image.height, image.width, CV_8UC3,
                      const_cast<std::uint8_t*>(image.rgb.data()));
    cv::Mat roi = canvas(cv::Rect(x0, 0, size.width, size.height));
    if (rgb.size() == size) {
        cv::cvtColor(rgb, roi, cv::COLOR_RGB2BGR);
    } else {
        cv::Mat scaled;
        cv::resize(rgb, scaled, size, 0, 0, cv::INTER_NEAREST);
        cv::cvtColor(scaled, roi, cv::COLOR_RGB2BGR);
    }
}

/// White text on a dark band, top-left of a panel, one line per entry.
void caption(cv::Mat& canvas, int x0, const std::vector<std::string>& lines) {
    const double scale = std::max(0.45, canvas.rows / 960.0);
    const int thick = scale > 0.8 ? 2 : 1;
    int baseline = 0;
    const int line_h =
        cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, scale, thick, &baseline).height + 10;
    int width = 0;
    for (const auto& s : lines)
        width = std::max(width,
                         cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, thick, &baseline).width);
    cv::Mat band = canvas(cv::Rect(x0, 0, std::min(width + 16, canvas.cols - x0),
                                   std::min(line_h * static_cast<int>(lines.size()) + 8, canvas.rows)));
    band *= 0.35;  // darken, keep the picture faintly visible
    for (std::size_t i = 0; i < lines.size(); ++i)
        cv::putText(canvas, lines[i], cv::Point(x0 + 8, line_h * static_cast<int>(i + 1)),
                    cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), thick,
                    cv::LINE_AA);
}

}  // namespace

void RunVideo::write(const RgbdFrame& frame, const FrameResult& result,
                     const std::vector<std::uint8_t>* selected, std::size_t index,
                     std::size_t total, double fps, int selected_object_id) {
    const Wul3dVideoApi& api = *impl_->api;
    if (!impl_->writer) {
        // Even sizes: H.264 in yuv420p needs them.
        impl_->panel = cv::Size(result.colors.width & ~1, result.colors.height & ~1);
        if (impl_->panel.width < 2 || impl_->panel.height < 2)
            throw InputError(path_.string() + ": frame " + frame.name + " is " +
                             std::to_string(result.colors.width) + "x" +
                             std::to_string(result.colors.height) +
                             ", too small for a video (at least 2x2)");
        const cv::Size size(3 * impl_->panel.width, impl_->panel.height);
        for (const char* codec : {"avc1", "mp4v"}) {
            impl_->writer =
                api.open(tmp_path_.c_str(), codec, kVideoFps, size.width, size.height);
            if (impl_->writer) break;
        }
        if (!impl_->writer)
            throw IoError(path_.string() +
                          ": cannot open a video writer (OpenCV's FFmpeg backend has neither "
                          "H.264 nor MPEG-4 for this container; try a .mp4 name)");
        impl_->canvas.create(size, CV_8UC3);
    }
    const cv::Size panel = impl_->panel;
    render_frame_picture(frame, colour_);
    paste(colour_, impl_->canvas, 0, panel);
    // Objects: tinted and numbered over the colour, with their oriented boxes.
    OverlayStyle style;
    style.boxes = true;
    style.selected = selected_object_id;
    if (result.objects.labels.size() == colour_.rgb.size() / 3) {
        render_object_overlay(colour_, result.objects, result.object_list, frame.intrinsics,
                              objects_, style);
    } else {
        objects_ = colour_;  // objects off (--no-objects): the colour alone
    }
    paste(objects_, impl_->canvas, panel.width, panel);
    if (selected) {
        highlight_mask(result.colors, *selected, kSelectionOutline, clusters_);
        paste(clusters_, impl_->canvas, 2 * panel.width, panel);
    } else {
        paste(result.colors, impl_->canvas, 2 * panel.width, panel);
    }

    char fps_text[64];
    std::snprintf(fps_text, sizeof fps_text, "%.1f FPS", fps);
    caption(impl_->canvas, 0,
            {"frame " + std::to_string(index + 1) + "/" + std::to_string(total) + "  " +
                 frame.name,
             fps_text});
    caption(impl_->canvas, panel.width,
            {std::to_string(result.object_list.size()) + " objects (track ids, 3D boxes)"});
    caption(impl_->canvas, 2 * panel.width,
            {selected ? "clusters (eq. 9), selected cluster" : "clusters (eq. 9)"});
    if (api.write(impl_->writer, impl_->canvas.data, impl_->canvas.step[0]) != 0)
        throw IoError(path_.string() + ": cannot write the video: " + api.last_error());
}

void RunVideo::close() {
    if (!impl_->writer) throw IoError(path_.string() + ": no frame was written to the video");
    const int status = impl_->api->close(impl_->writer);
    impl_->writer = nullptr;
    if (status != 0)
        throw IoError(path_.string() + ": cannot finish the video: " + impl_->api->last_error());
    std::error_code ec;
    fs::rename(tmp_path_, path_, ec);
    if (ec) throw IoError(path_.string() + ": cannot write the video: " + ec.message());
}

}  // namespace wul3d::cli
