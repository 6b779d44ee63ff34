#include "synthetic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

namespace wul3d::test {

PinholeIntrinsics scene_intrinsics(int width, int height) {
    return PinholeIntrinsics{width, height, 0.9 * width, 0.9 * width, width / 2.0 - 0.5,
                             height / 2.0 - 0.5};
}

namespace {
// Ray (dx, dy, 1) against an axis-aligned box; returns the entry t or +inf.
float hit_box(float dx, float dy, float dz, float x0, float x1, float y0, float y1, float z0, float z1) {
    float t0 = 0, t1 = std::numeric_limits<float>::infinity();
    auto slab = [&](float dir, float lo, float hi) {
        if (std::fabs(dir) < 1e-12f) return lo <= 0 && 0 <= hi;
        float a = lo / dir, b = hi / dir;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        return t0 <= t1;
    };
    if (!slab(dx, x0, x1) || !slab(dy, y0, y1) || !slab(dz, z0, z1))
        return std::numeric_limits<float>::infinity();
    return t0 > 0 ? t0 : std::numeric_limits<float>::infinity();
}

// Ray (dx, dy, dz) against an open cup standing at height `table_y` (y down): the
// nearest of its outer and inner walls, rim and floor (a bottle: its outer wall, closed top
// and neck), or +inf. Taking the nearest hit of every surface is exact for a closed
// thick-walled shape: a ray that meets an inner wall from outside has met the outer wall or
// passed over the rim first.
float hit_cup(float dx, float dy, float dz, const SceneCup& c, float table_y) {
    const float top = table_y - c.h, floor_y = table_y - c.wall, inner = c.radius - c.wall;
    float best = std::numeric_limits<float>::infinity();
    auto keep = [&](float t, bool ok) {
        if (ok && t > 0 && t < best) best = t;
    };
    // Vertical walls: (t dx - x)^2 + (t dz - z)^2 = r^2, between y_lo and y_hi.
    auto tube = [&](float r, float y_lo, float y_hi) {
        const float a = dx * dx + dz * dz, b = -2 * (dx * c.x + dz * c.z),
                    cc = c.x * c.x + c.z * c.z - r * r;
        const float disc = b * b - 4 * a * cc;
        if (a < 1e-12f || disc < 0) return;
        for (float sign : {-1.0f, 1.0f}) {
            const float t = (-b + sign * std::sqrt(disc)) / (2 * a);
            keep(t, t * dy >= y_lo && t * dy <= y_hi);
        }
    };
    tube(c.radius, top, table_y);
    const bool bottle = c.neck_radius > 0 && c.neck_h > 0;
    // A bottle's shoulder: a cone at 45 degrees from the body's radius at its top to the
    // neck's, its radius r = radius - (top - y) = k0 + k1 t at the ray's point (y = t dy,
    // downwards: r shrinks as the point rises).
    const float shoulder = c.radius - c.neck_radius, neck_top = top - shoulder - c.neck_h;
    if (bottle) {
        const float k0 = c.radius - top, k1 = dy;
        const float a = dx * dx + dz * dz - k1 * k1, b = -2 * (dx * c.x + dz * c.z) - 2 * k0 * k1,
                    cc = c.x * c.x + c.z * c.z - k0 * k0;
        const float disc = b * b - 4 * a * cc;
        if (std::fabs(a) > 1e-12f && disc >= 0)
            for (float sign : {-1.0f, 1.0f}) {
                const float t = (-b + sign * std::sqrt(disc)) / (2 * a), y = t * dy;
                keep(t, y >= top - shoulder && y <= top);
            }
        tube(c.neck_radius, neck_top, top - shoulder);
    } else {
        tube(inner, top, floor_y);
    }
    // Horizontal rings: the rim (inner..radius at the top) and the floor (0..inner).
    auto ring = [&](float y, float r0, float r1) {
        if (std::fabs(dy) < 1e-12f) return;
        const float t = y / dy, ex = t * dx - c.x, ez = t * dz - c.z, d2 = ex * ex + ez * ez;
        keep(t, d2 >= r0 * r0 && d2 <= r1 * r1);
    };
    if (bottle) {
        ring(neck_top, 0, c.neck_radius);
    } else {
        ring(top, inner, c.radius);
        ring(floor_y, 0, inner);
    }
    return best;
}
}  // namespace

RgbdFrame render_scene(const Scene& s, std::vector<int>* truth) {
    RgbdFrame f;
    f.name = "synthetic";
    f.intrinsics = scene_intrinsics(s.width, s.height);
    f.depth.width = f.color.width = s.width;
    f.depth.height = f.color.height = s.height;
    f.depth.scale_m_per_unit = 0.0001f;
    const std::size_t n = static_cast<std::size_t>(s.width) * s.height;
    f.depth.data.assign(n, 0);
    f.color.rgb.assign(3 * n, 0);
    if (truth) truth->assign(n, 0);
    std::mt19937 rng(s.noise_seed);
    std::uniform_int_distribution<int> noise(-3, 3);

    const auto& K = f.intrinsics;
    for (int v = 0; v < s.height; ++v) {
        for (int u = 0; u < s.width; ++u) {
            const float dx = static_cast<float>((u - K.cx) / K.fx);
            const float dy_cam = static_cast<float>((v - K.cy) / K.fy);
            // The ray (dx, dy_cam, 1) in the scene's axes: the camera's forward axis points
            // down by pitch. Its parameter t stays the camera-frame depth.
            const float cp = std::cos(s.pitch_rad), sp = std::sin(s.pitch_rad);
            const float dy = dy_cam * cp + sp, dz = -dy_cam * sp + cp;
            float best = std::numeric_limits<float>::infinity();
            int id = 0;
            std::uint8_t rgb[3] = {0, 0, 0};
            // Table: the plane y = table_y, a rectangle on it.
            if (dy > 1e-6f) {
                const float t = s.table_y / dy;
                const float x = dx * t, zt = dz * t;
                if (zt >= s.table_near && zt <= s.table_far && std::fabs(x) <= s.table_half_width) {
                    best = t;
                    id = kTruthTable;
                    rgb[0] = 150; rgb[1] = 140; rgb[2] = 120;
                }
            }
            if (s.floor_y > 0 && dy > 1e-6f && s.floor_y / dy < best) {
                best = s.floor_y / dy;
                id = kTruthFloor;
                rgb[0] = 60; rgb[1] = 150; rgb[2] = 70;
            }
            for (std::size_t i = 0; i < s.floor_boxes.size(); ++i) {
                const SceneBox& b = s.floor_boxes[i];
                const float t = hit_box(dx, dy, dz, b.x - b.w / 2, b.x + b.w / 2, s.floor_y - b.h,
                                        s.floor_y, b.z - b.d / 2, b.z + b.d / 2);
                if (t < best) {
                    best = t;
                    id = kTruthFloorBox0 + static_cast<int>(i);
                    rgb[0] = b.r; rgb[1] = b.g; rgb[2] = b.b;
                }
            }
            if (s.wall && dz > 1e-6f && 2.4f / dz < best) {
                best = 2.4f / dz;
                id = kTruthWall;
                rgb[0] = 90; rgb[1] = 110; rgb[2] = 140;
            }
            for (std::size_t i = 0; i < s.boxes.size(); ++i) {
                const SceneBox& b = s.boxes[i];
                const float t = hit_box(dx, dy, dz, b.x - b.w / 2, b.x + b.w / 2, s.table_y - b.lift - b.h,
                                        s.table_y - b.lift, b.z - b.d / 2, b.z + b.d / 2);
                if (t < best) {
                    best = t;
                    id = kTruthBox0 + static_cast<int>(i);
                    rgb[0] = b.r; rgb[1] = b.g; rgb[2] = b.b;
                }
            }
            for (std::size_t i = 0; i < s.cups.size(); ++i) {
                const SceneCup& c = s.cups[i];
                const float base_y = s.table_y - c.lift;
                const float t = hit_cup(dx, dy, dz, c, base_y);
                if (t < best) {
                    best = t;
                    id = kTruthCup0 + static_cast<int>(i);
                    rgb[0] = c.r; rgb[1] = c.g; rgb[2] = c.b;
                    const float ex = t * dx - c.x, ez = t * dz - c.z, height = base_y - t * dy;
                    const float mid = c.radius - c.wall / 2;
                    const bool outer = ex * ex + ez * ez >= mid * mid || height > c.h + 1e-4f;  // or the neck
                    if (outer && height >= c.band_lo && height <= c.band_hi) {
                        rgb[0] = c.band_r; rgb[1] = c.band_g; rgb[2] = c.band_b;
                    }
                }
            }
            const std::size_t p = static_cast<std::size_t>(v) * s.width + u;
            if (id == 0) continue;
            f.depth.data[p] = static_cast<std::uint16_t>(std::lround(best / f.depth.scale_m_per_unit));
            for (int q = 0; q < 3; ++q) {
                const int c = rgb[q] + (s.noise_seed ? noise(rng) : 0);
                f.color.rgb[3 * p + q] = static_cast<std::uint8_t>(std::clamp(c, 0, 255));
            }
            if (truth) (*truth)[p] = id;
        }
    }
    return f;
}

Scene pitched_tabletop_scene() {
    Scene s;
    s.width = 320;
    s.height = 240;
    s.pitch_rad = 0.5f;
    s.table_y = 0.6f;
    s.table_near = 0.4f;
    s.table_far = 1.6f;
    return s;
}

Scene small_box_before_tall_box() {
    Scene s = pitched_tabletop_scene();
    const SceneBox tall{.x = 0.05f, .z = 1.0f, .w = 0.2f, .h = 0.25f, .d = 0.1f};
    // Same colour; its back face touches the tall box's front face (z = 0.95).
    const SceneBox small{.x = 0.0f, .z = 0.9f, .w = 0.12f, .h = 0.1f, .d = tall.d};
    s.boxes = {tall, small};
    return s;
}

Scene board_on_table_scene(float w, float d) {
    Scene s = pitched_tabletop_scene();
    const SceneBox board{.x = -0.05f, .z = 1.1f, .w = w, .h = 0.02f, .d = d, .r = 220, .g = 220, .b = 220};
    const SceneBox on_board{.x = board.x - 0.06f, .z = board.z - 0.04f, .w = 0.1f, .h = 0.1f, .d = 0.1f, .lift = board.h};
    SceneBox other = on_board;
    other.x = board.x + 0.06f;
    other.z = board.z + 0.06f;
    other.g = 160;
    SceneBox beside = on_board;
    beside.lift = 0;
    beside.x = board.x + w / 2 + 0.15f;
    beside.z = 0.9f;
    beside.b = 160;
    s.boxes = {board, on_board, other, beside};
    return s;
}

LabelImage blank_labels(int w, int h) {
    LabelImage l;
    l.width = w;
    l.height = h;
    l.labels.assign(static_cast<std::size_t>(w) * h, 0);
    return l;
}

void fill_rect(LabelImage& l, int u0, int v0, int u1, int v1, std::uint16_t id) {
    for (int v = v0; v <= v1; ++v)
        for (int u = u0; u <= u1; ++u) l.labels[static_cast<std::size_t>(v) * l.width + u] = id;
}

double dominant_share(const std::vector<std::uint16_t>& labels, const std::vector<int>& truth,
                      int id, int* dominant) {
    std::map<int, std::size_t> counts;
    std::size_t total = 0;
    for (std::size_t p = 0; p < truth.size(); ++p)
        if (truth[p] == id) {
            ++counts[labels[p]];
            ++total;
        }
    if (total == 0) return 0.0;
    const auto best = std::max_element(counts.begin(), counts.end(),
                                       [](auto& a, auto& b) { return a.second < b.second; });
    if (dominant) *dominant = best->first;
    return static_cast<double>(best->second) / static_cast<double>(total);
}

}  // namespace wul3d::test
