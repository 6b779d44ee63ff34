#include "wul3d/visualization.hpp"

#include "wul3d/clustering.hpp"
#include "wul3d/objects.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "weight_colours.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

namespace {

/// HSV (h in [0, 6), s, v in [0, 1]) to 8-bit RGB.
std::array<std::uint8_t, 3> hsv_bytes(double h, double s, double v) {
    const int sector = static_cast<int>(h);
    const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double r = v, g = t, b = p;
    switch (sector) {
        case 1: r = q; g = v; b = p; break;
        case 2: r = p; g = v; b = t; break;
        case 3: r = p; g = q; b = v; break;
        case 4: r = t; g = p; b = v; break;
        case 5: r = v; g = p; b = q; break;
        default: break;
    }
    auto byte = [](double x) { return static_cast<std::uint8_t>(std::lround(x * 255.0)); };
    return {byte(r), byte(g), byte(b)};
}

}  // namespace

std::array<std::uint8_t, 3> cluster_color(int j) {
    // Distinct, saturated colours first (readable next to each other), then hues spaced
    // by the golden ratio.
    static constexpr std::uint8_t kFixed[12][3] = {
        {230, 25, 75},  {60, 180, 75},  {255, 225, 25}, {0, 130, 200},
        {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230},
        {210, 245, 60}, {250, 190, 212}, {0, 128, 128}, {170, 110, 40}};
    if (j >= 0 && j < 12) return {kFixed[j][0], kFixed[j][1], kFixed[j][2]};
    return hsv_bytes(std::fmod(0.1 + 0.618033988749895 * j, 1.0) * 6.0, 0.75, 0.95);
}

std::array<std::uint8_t, 3> object_color(int track_id) {
    // Successive ids land far apart on the hue circle (golden ratio), whatever their number;
    // saturation alternates so that ids whose hues come close again still differ.
    const double h = std::fmod(0.05 + 0.618033988749895 * track_id, 1.0) * 6.0;
    return hsv_bytes(h, track_id % 2 ? 0.85 : 0.65, 0.95);
}

void detail::WeightColours::prepare(const ClusterState& state, const LabelImage& labels, const RgbdView& frame,
                                    ColorImage& out) {
    const int W = labels.width, H = labels.height, k = state.params().k;
    out.width = W;
    out.height = H;
    out.rgb.resize(static_cast<std::size_t>(W) * H * 3);
    colour_.assign(static_cast<std::size_t>(k) * 4, 0.0f);
    for (int j = 0; j < k; ++j) {
        const auto c = cluster_color(j);
        for (int q = 0; q < 3; ++q) colour_[4 * static_cast<std::size_t>(j) + q] = c[q] / PixelWeights::kOne;
    }
    const bool grey_ok = frame.has_color() && frame.color_width == W && frame.color_height == H;
    rgb_ = grey_ok ? frame.rgb : nullptr;
    state_ = &state;
    labels_ = &labels;
    out_ = &out;
}

void detail::WeightColours::rows(int v0, int v1) const {
    const int W = labels_->width;
    // Four floats a colour (the fourth 0): a slot's three products and sums are one 4-wide
    // operation each (GCC's and Clang's vector extension), each lane the scalar one.
    using Float4 = float __attribute__((vector_size(16)));
    // Raw pointers, read once: through the vectors and the state, each byte stored would
    // make the compiler load them again.
    const std::uint16_t* const label = labels_->labels.data();
    std::uint8_t* const out_rgb = out_->rgb.data();
    const std::uint8_t* const rgb = rgb_;
    const float* const colour = colour_.data();
    const ClusterState& state = *state_;
    const PixelWeights* const weights =
        state.grid_width() > 0 && state.grid_height() > 0 ? &state.weights(0) : nullptr;
    const int stride = state.params().stride;
    for (int v = v0; v < v1; ++v) {
        // Pixel u's grid point, stepped: a division per pixel cost more than the sum.
        int cell = state.grid_index(0, v), in_cell = 0;
        for (int u = 0; u < W; ++u, in_cell = in_cell + 1 == stride ? 0 : in_cell + 1, cell += in_cell == 0) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            std::uint8_t* o = out_rgb + 3 * p;
            if (label[p] != 0) {
                // Paper eq. (9): C_p = sum_j C_j mu_j, over the kept weights (the others
                // are 0 or negligible, see PixelWeights). Every slot is summed: an empty one
                // adds 0 (its mu), which leaves the sum as it is, and a test per slot (or a
                // comparison with the pixel before, to reuse its colour) mispredicted more
                // than it saved.
                const PixelWeights& w = weights[cell];
                Float4 acc = {0, 0, 0, 0};
                for (int s = 0; s < PixelWeights::kSlots; ++s) {
                    Float4 c;
                    std::memcpy(&c, colour + 4 * w.cluster[s], sizeof c);
                    acc += c * static_cast<float>(w.mu[s]);
                }
                for (int q = 0; q < 3; ++q)
                    o[q] = static_cast<std::uint8_t>(std::min(255.0f, acc[q] + 0.5f));
            } else if (rgb) {
                o[0] = o[1] = o[2] = dimmed_grey(rgb + 3 * p);
            } else {
                o[0] = o[1] = o[2] = 0;
            }
        }
    }
}

void detail::WeightColours::all_rows() const {
    const int H = height();
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) rows(v, v + 1);
}

void render_weight_colors(const ClusterState& state, const LabelImage& labels,
                          const RgbdView& frame, ColorImage& out) {
    detail::WeightColours colours;
    colours.prepare(state, labels, frame, out);
    colours.all_rows();
}

namespace {

/// Tints, dims and outlines the pixels (the first layer of render_object_overlay).
void tint_objects(const LabelImage& objects, const OverlayStyle& style, ColorImage& out) {
    const int W = objects.width, H = objects.height;
    const std::uint16_t* L = objects.labels.data();
    const float keep = 1.0f - style.tint;
    std::uint16_t max_id = 0;
    for (const std::uint16_t l : objects.labels) max_id = std::max(max_id, l);
    std::vector<float> tint(3 * (static_cast<std::size_t>(max_id) + 1));
    for (int id = 1; id <= max_id; ++id) {
        const auto c = object_color(id);
        for (int q = 0; q < 3; ++q) tint[3 * id + q] = style.tint * c[q];
    }
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            const int l = L[p];
            std::uint8_t* o = out.rgb.data() + 3 * p;
            if (style.selected != 0 && l != style.selected) {
                for (int q = 0; q < 3; ++q) o[q] = static_cast<std::uint8_t>(o[q] / 4);
            }
            if (l == 0) continue;
            // A border pixel: a 4-neighbour (inside the image) with another label.
            const bool border = (u > 0 && L[p - 1] != l) || (u + 1 < W && L[p + 1] != l) ||
                                (v > 0 && L[p - W] != l) || (v + 1 < H && L[p + W] != l);
            if (border && style.outline && (style.selected == 0 || l == style.selected)) {
                o[0] = o[1] = o[2] = 255;
            } else if (style.selected == 0 || l == style.selected) {
                for (int q = 0; q < 3; ++q)
                    o[q] = static_cast<std::uint8_t>(
                        std::min(255.0f, keep * o[q] + tint[3 * l + q] + 0.5f));
            }
        }
    }
}

/// The 12 edges of the object's oriented box, projected; nothing when a corner is behind
/// (or within 5 cm of) the camera.
void draw_box(const DetectedObject& d, const PinholeIntrinsics& K, const cv::Scalar& colour,
              int thickness, cv::Mat& image) {
    cv::Point2f corner[8];
    for (int c = 0; c < 8; ++c) {
        float x[3];
        for (int i = 0; i < 3; ++i) {
            x[i] = d.obb_centre[i];
            for (int a = 0; a < 3; ++a)
                x[i] += ((c >> a) & 1 ? 1.0f : -1.0f) * d.obb_half_extent[a] * d.obb_axes[3 * a + i];
        }
        if (x[2] < 0.05f) return;
        corner[c] = {static_cast<float>(K.fx * x[0] / x[2] + K.cx),
                     static_cast<float>(K.fy * x[1] / x[2] + K.cy)};
    }
    for (int c = 0; c < 8; ++c)
        for (int a = 0; a < 3; ++a)
            if (!((c >> a) & 1))  // each edge once: from the corner with bit a clear
                cv::line(image, corner[c], corner[c | (1 << a)], colour, thickness, cv::LINE_AA);
}

}  // namespace

void render_object_overlay(const ColorImage& base, const LabelImage& objects,
                           const std::vector<DetectedObject>& list,
                           const PinholeIntrinsics& intrinsics, ColorImage& out,
                           const OverlayStyle& style) {
    if (base.width != objects.width || base.height != objects.height ||
        base.rgb.size() != static_cast<std::size_t>(base.width) * base.height * 3 ||
        objects.labels.size() != static_cast<std::size_t>(objects.width) * objects.height)
        throw ParamError("render_object_overlay: the picture (" + std::to_string(base.width) +
                         "x" + std::to_string(base.height) + ") and the objects (" +
                         std::to_string(objects.width) + "x" + std::to_string(objects.height) +
                         ") differ in size");
    if (!(style.tint >= 0.0f && style.tint <= 1.0f))
        throw ParamError("render_object_overlay: tint must be in [0, 1]");
    if (style.boxes && !intrinsics.same_size(base.width, base.height))
        throw ParamError("render_object_overlay: the intrinsics are not the picture's size");
    out = base;
    if (out.empty()) return;
    tint_objects(objects, style, out);

    cv::Mat image(out.height, out.width, CV_8UC3, out.rgb.data());  // RGB order
    // Text and lines grow with the picture: a 640x480 frame gets 0.6, 1920x1080 1.35.
    const double scale = std::max(0.4, out.height / 800.0);
    const int thick = std::max(1, static_cast<int>(std::lround(scale * 1.6)));
    for (const DetectedObject& d : list) {
        if (style.selected != 0 && d.id != style.selected) continue;
        const auto c = object_color(d.id);
        if (style.boxes) draw_box(d, intrinsics, cv::Scalar(c[0], c[1], c[2]), thick, image);
        if (!style.ids) continue;
        // The id on a dark tag at the top-left corner of the object's 2D box, kept inside.
        const std::string text = std::to_string(d.id);
        int baseline = 0;
        const cv::Size ts = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, thick, &baseline);
        const int pad = thick + 2;
        const int w = ts.width + 2 * pad, h = ts.height + baseline + 2 * pad;
        const int x0 = std::clamp(d.u_min, 0, std::max(0, out.width - w));
        const int y0 = std::clamp(d.v_min, 0, std::max(0, out.height - h));
        const cv::Rect tag = cv::Rect(x0, y0, w, h) & cv::Rect(0, 0, out.width, out.height);
        image(tag) *= 0.25;
        cv::rectangle(image, tag, cv::Scalar(c[0], c[1], c[2]), 1);
        cv::putText(image, text, cv::Point(x0 + pad, y0 + pad + ts.height), cv::FONT_HERSHEY_SIMPLEX,
                    scale, cv::Scalar(255, 255, 255), thick, cv::LINE_AA);
    }
}

void render_frame_picture(const RgbdFrame& frame, ColorImage& out) {
    if (frame.has_color()) {
        out = frame.color;
        return;
    }
    out.width = frame.depth.width;
    out.height = frame.depth.height;
    out.rgb.resize(frame.depth.data.size() * 3);
    std::uint16_t lo = 0xffff, hi = 0;
    for (const std::uint16_t d : frame.depth.data)
        if (d) lo = std::min(lo, d), hi = std::max(hi, d);
    const float span = std::max(1.0f, static_cast<float>(hi) - static_cast<float>(lo));
    for (std::size_t p = 0; p < frame.depth.data.size(); ++p) {
        const std::uint16_t d = frame.depth.data[p];
        const auto g = d ? static_cast<std::uint8_t>(
                               235.0f - 180.0f * (static_cast<float>(d) - static_cast<float>(lo)) / span)
                         : std::uint8_t{0};
        out.rgb[3 * p] = out.rgb[3 * p + 1] = out.rgb[3 * p + 2] = g;
    }
}

}  // namespace wul3d
