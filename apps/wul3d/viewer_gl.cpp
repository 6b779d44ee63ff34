// OpenGL 3.3 core pieces of the viewer. Entry points come from libGL (glvnd exports the whole
// core API), so no loader is needed.
#define GL_GLEXT_PROTOTYPES 1
#include "viewer_gl.hpp"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "wul3d/error.hpp"

namespace wul3d::cli {

// ---- ImageTexture -----------------------------------------------------------------------

ImageTexture::~ImageTexture() {
    if (id_) glDeleteTextures(1, &id_);
}

void ImageTexture::upload(const ColorImage& image) {
    if (image.empty()) return;
    if (!id_) glGenTextures(1, &id_);
    glBindTexture(GL_TEXTURE_2D, id_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (image.width != width_ || image.height != height_) {
        width_ = image.width;
        height_ = image.height;
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, width_, height_, 0, GL_RGB, GL_UNSIGNED_BYTE,
                     image.rgb.data());
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE,
                        image.rgb.data());
    }
}

// ---- matrices and the orbit camera --------------------------------------------------------

Mat4 multiply(const Mat4& a, const Mat4& b) {
    Mat4 c{};
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) {
            float s = 0;
            for (int i = 0; i < 4; ++i) s += a[i * 4 + row] * b[col * 4 + i];
            c[col * 4 + row] = s;
        }
    return c;
}

void OrbitCamera::reset(float depth_m, float fov_y) {
    target[0] = target[1] = 0;
    target[2] = -depth_m;
    distance = depth_m;
    yaw = pitch = 0;
    fov_y_rad = fov_y;
}

void OrbitCamera::orbit(float dx_px, float dy_px) {
    yaw -= dx_px * 0.006f;
    pitch = std::clamp(pitch - dy_px * 0.006f, -1.48f, 1.48f);
}

void OrbitCamera::pan(float dx_px, float dy_px, float viewport_h_px) {
    // Move the target in the view plane so the scene follows the mouse at the target's depth.
    const float metres_per_px =
        2.0f * distance * std::tan(fov_y_rad / 2) / std::max(1.0f, viewport_h_px);
    const float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch),
                sp = std::sin(pitch);
    const float right[3] = {cy, 0, -sy};
    const float up[3] = {-sy * sp, cp, -cy * sp};
    for (int i = 0; i < 3; ++i)
        target[i] += (-dx_px * right[i] + dy_px * up[i]) * metres_per_px;
}

void OrbitCamera::zoom(float wheel_steps) {
    distance = std::clamp(distance * std::pow(0.88f, wheel_steps), 0.02f, 100.0f);
}

Mat4 OrbitCamera::view() const {
    // Eye on a sphere around the target; yaw = pitch = 0 puts it on +z of the target.
    const float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch),
                sp = std::sin(pitch);
    const float back[3] = {sy * cp, sp, cy * cp};  // from target to eye, unit
    const float right[3] = {cy, 0, -sy};
    const float up[3] = {-sy * sp, cp, -cy * sp};
    float eye[3];
    for (int i = 0; i < 3; ++i) eye[i] = target[i] + distance * back[i];
    auto dot = [](const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    return {right[0], up[0], back[0], 0,  //
            right[1], up[1], back[1], 0,  //
            right[2], up[2], back[2], 0,  //
            -dot(right, eye), -dot(up, eye), -dot(back, eye), 1};
}

Mat4 OrbitCamera::projection(float aspect) const {
    const float n = 0.01f, f = 200.0f, t = 1.0f / std::tan(fov_y_rad / 2);
    return {t / aspect, 0, 0, 0,  //
            0, t, 0, 0,           //
            0, 0, (f + n) / (n - f), -1,
            0, 0, 2 * f * n / (n - f), 0};
}

// ---- CloudRenderer ------------------------------------------------------------------------

namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 color;
uniform mat4 mvp;
uniform float point_size;
out vec3 v_color;
void main() {
    gl_Position = mvp * vec4(position, 1.0);
    gl_PointSize = point_size;
    v_color = color;
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_color;
uniform float alpha;
out vec4 frag;
void main() { frag = vec4(v_color, alpha); }
)";

unsigned compile(GLenum type, const char* source) {
    const GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        glDeleteShader(s);
        throw Error(std::string("viewer: shader does not compile: ") + log);
    }
    return s;
}

}  // namespace

CloudRenderer::CloudRenderer() {
    const unsigned vs = compile(GL_VERTEX_SHADER, kVertexShader);
    const unsigned fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    program_ = glCreateProgram();
    glAttachShader(program_, vs);
    glAttachShader(program_, fs);
    glLinkProgram(program_);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program_, GL_LINK_STATUS, &ok);
    if (!ok) throw Error("viewer: shader program does not link");
    mvp_loc_ = glGetUniformLocation(program_, "mvp");
    size_loc_ = glGetUniformLocation(program_, "point_size");
    alpha_loc_ = glGetUniformLocation(program_, "alpha");
    for (Buffers* b : {&points_, &lines_, &patch_}) {
        glGenVertexArrays(1, &b->vao);
        glGenBuffers(1, &b->vbo_xyz);
        glGenBuffers(1, &b->vbo_rgb);
        glBindVertexArray(b->vao);
        glBindBuffer(GL_ARRAY_BUFFER, b->vbo_xyz);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ARRAY_BUFFER, b->vbo_rgb);
        glVertexAttribPointer(1, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0, nullptr);
        glEnableVertexAttribArray(1);
    }
    glBindVertexArray(0);
}

CloudRenderer::~CloudRenderer() {
    for (Buffers* b : {&points_, &lines_, &patch_}) {
        glDeleteBuffers(1, &b->vbo_xyz);
        glDeleteBuffers(1, &b->vbo_rgb);
        glDeleteVertexArrays(1, &b->vao);
    }
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (color_tex_) glDeleteTextures(1, &color_tex_);
    if (depth_rb_) glDeleteRenderbuffers(1, &depth_rb_);
    glDeleteProgram(program_);
}

void CloudRenderer::fill(Buffers& b, const std::vector<float>& xyz,
                         const std::vector<std::uint8_t>& rgb) {
    b.count = static_cast<int>(std::min(xyz.size() / 3, rgb.size() / 3));
    glBindBuffer(GL_ARRAY_BUFFER, b.vbo_xyz);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(b.count * 3 * sizeof(float)),
                 xyz.data(), GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, b.vbo_rgb);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(b.count * 3), rgb.data(),
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void CloudRenderer::set_points(const std::vector<float>& xyz,
                               const std::vector<std::uint8_t>& rgb) {
    fill(points_, xyz, rgb);
}

void CloudRenderer::set_lines(const std::vector<float>& xyz,
                              const std::vector<std::uint8_t>& rgb) {
    fill(lines_, xyz, rgb);
}

void CloudRenderer::set_patch(const std::vector<float>& xyz,
                              const std::vector<std::uint8_t>& rgb) {
    fill(patch_, xyz, rgb);
}

void CloudRenderer::resize_target(int width, int height) {
    if (width == fbo_w_ && height == fbo_h_ && fbo_) return;
    fbo_w_ = width;
    fbo_h_ = height;
    if (!fbo_) {
        glGenFramebuffers(1, &fbo_);
        glGenTextures(1, &color_tex_);
        glGenRenderbuffers(1, &depth_rb_);
    }
    glBindTexture(GL_TEXTURE_2D, color_tex_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, width, height, 0, GL_RGB, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_tex_, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("viewer: the offscreen 3D target is incomplete");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

unsigned CloudRenderer::render(int width, int height, const Mat4& mvp, float point_size_px,
                               const float background[3], float patch_alpha) {
    width = std::max(width, 1);
    height = std::max(height, 1);
    resize_target(width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, width, height);
    glClearColor(background[0], background[1], background[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(program_);
    glUniformMatrix4fv(mvp_loc_, 1, GL_FALSE, mvp.data());
    glUniform1f(size_loc_, point_size_px);
    glUniform1f(alpha_loc_, 1.0f);
    glBindVertexArray(points_.vao);
    glDrawArrays(GL_POINTS, 0, points_.count);
    // The patch: blended over the points in front of it, hidden behind them, and writing
    // no depth so that the points under it still show through.
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glUniform1f(alpha_loc_, patch_alpha);
    glBindVertexArray(patch_.vao);
    glDrawArrays(GL_TRIANGLES, 0, patch_.count);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glUniform1f(alpha_loc_, 1.0f);
    glDisable(GL_DEPTH_TEST);  // the boxes stay visible through the points
    glBindVertexArray(lines_.vao);
    glDrawArrays(GL_LINES, 0, lines_.count);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return color_tex_;
}

// ---- screenshots ----------------------------------------------------------------------------

ColorImage read_framebuffer(int width, int height) {
    ColorImage out;
    out.width = width;
    out.height = height;
    out.rgb.resize(static_cast<std::size_t>(width) * height * 3);
    std::vector<std::uint8_t> bottom_up(out.rgb.size());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
    const std::size_t row = static_cast<std::size_t>(width) * 3;
    for (int y = 0; y < height; ++y)
        std::copy_n(bottom_up.data() + static_cast<std::size_t>(height - 1 - y) * row, row,
                    out.rgb.data() + static_cast<std::size_t>(y) * row);
    return out;
}

}  // namespace wul3d::cli
