#pragma once
// OpenGL 3.3 pieces of the viewer: image textures, the point-cloud renderer (drawn into an
// offscreen target that the UI shows as an image), an orbit camera and window screenshots.
// Needs a current OpenGL 3.3 core context for everything but OrbitCamera.
#include <array>
#include <cstdint>
#include <vector>

#include "wul3d/frame.hpp"

namespace wul3d::cli {

/// Column-major 4x4 matrix, as OpenGL takes it.
using Mat4 = std::array<float, 16>;

/// An 8-bit RGB texture holding one picture (colour, depth, clusters panels).
class ImageTexture {
public:
    ImageTexture() = default;
    ~ImageTexture();
    ImageTexture(const ImageTexture&) = delete;
    ImageTexture& operator=(const ImageTexture&) = delete;

    void upload(const ColorImage& image);  ///< (re)allocates on a size change
    unsigned id() const { return id_; }
    int width() const { return width_; }
    int height() const { return height_; }

private:
    unsigned id_ = 0;
    int width_ = 0, height_ = 0;
};

/// Orbits around a target point. Right-handed view space: x right, y up, looking down -z.
/// The cloud's camera frame (x right, y down, z forward) maps to it as (x, -y, -z), so
/// reset() shows the scene as the sensor saw it.
struct OrbitCamera {
    float target[3] = {0, 0, -1};
    float distance = 1;    ///< metres from the target
    float yaw = 0;         ///< radians about the view-space y axis
    float pitch = 0;       ///< radians, clamped to about +-85 degrees
    float fov_y_rad = 0.8f;

    /// Looks from the sensor's origin at (0, 0, -depth_m).
    void reset(float depth_m, float fov_y);
    void orbit(float dx_px, float dy_px);
    void pan(float dx_px, float dy_px, float viewport_h_px);
    void zoom(float wheel_steps);
    Mat4 view() const;
    Mat4 projection(float aspect) const;
};

Mat4 multiply(const Mat4& a, const Mat4& b);

/// Points (position + colour), line segments and translucent triangles, drawn with one tiny shader into an
/// offscreen colour texture of the size asked for.
class CloudRenderer {
public:
    CloudRenderer();  ///< compiles the shader; throws Error with the GL log on failure
    ~CloudRenderer();
    CloudRenderer(const CloudRenderer&) = delete;
    CloudRenderer& operator=(const CloudRenderer&) = delete;

    /// xyz: 3 floats per point (view space), rgb: 3 bytes per point.
    void set_points(const std::vector<float>& xyz, const std::vector<std::uint8_t>& rgb);
    /// Line segments: 2 vertices each, same layout.
    void set_lines(const std::vector<float>& xyz, const std::vector<std::uint8_t>& rgb);
    /// Translucent triangles (3 vertices each, same layout), drawn over the points with
    /// `patch_alpha` opacity (the support plane's patch).
    void set_patch(const std::vector<float>& xyz, const std::vector<std::uint8_t>& rgb);
    /// Draws into the offscreen target (resized to width x height) and returns its texture.
    unsigned render(int width, int height, const Mat4& mvp, float point_size_px,
                    const float background[3], float patch_alpha = 0.3f);

private:
    void resize_target(int width, int height);
    struct Buffers {
        unsigned vao = 0, vbo_xyz = 0, vbo_rgb = 0;
        int count = 0;
    };
    static void fill(Buffers& b, const std::vector<float>& xyz,
                     const std::vector<std::uint8_t>& rgb);
    unsigned program_ = 0;
    int mvp_loc_ = -1, size_loc_ = -1, alpha_loc_ = -1;
    Buffers points_, lines_, patch_;
    unsigned fbo_ = 0, color_tex_ = 0, depth_rb_ = 0;
    int fbo_w_ = 0, fbo_h_ = 0;
};

/// Reads the default framebuffer (width x height pixels) as a top-down RGB image.
ColorImage read_framebuffer(int width, int height);

}  // namespace wul3d::cli
