// A caller's frame as the stages read it (image_view.hpp): in place when it already has
// their layout, else converted once into reused buffers.
#include "wul3d/image_view.hpp"

#include <cmath>
#include <cstring>

#include "wul3d/error.hpp"

namespace wul3d {

namespace {

std::string size_str(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

/// The row stride of an image of `width` pixels of `bytes` each: `stride` or the packed one.
std::size_t row_bytes(const FrameView& f, const char* what, int width, std::size_t stride,
                      std::size_t bytes) {
    const std::size_t packed = static_cast<std::size_t>(width) * bytes;
    if (stride == 0) return packed;
    if (stride < packed)
        throw InputError(f.name + ": " + what + " row stride " + std::to_string(stride) +
                         " bytes is shorter than a row of " + std::to_string(packed));
    return stride;
}

/// Float metres to the stages' 16-bit units of `scale`; invalid (0) where not representable.
std::uint16_t to_units(float z_m, double scale) {
    if (!(z_m > 0.0f) || !std::isfinite(z_m)) return 0;
    const double units = std::round(static_cast<double>(z_m) / scale);
    if (units < 1.0 || units > 65535.0) return 0;
    return static_cast<std::uint16_t>(units);
}

void check(const FrameView& f) {
    const DepthView& d = f.depth;
    if (d.data == nullptr || d.width <= 0 || d.height <= 0)
        throw InputError(f.name + ": empty depth image (" + size_str(d.width, d.height) + ")");
    if (!(d.scale_m_per_unit > 0.0f) || !std::isfinite(d.scale_m_per_unit))
        throw InputError(f.name + ": depth scale " + std::to_string(d.scale_m_per_unit) +
                         " m per unit: must be finite and > 0");
    const PinholeIntrinsics& K = f.intrinsics;
    if (!(std::isfinite(K.fx) && std::isfinite(K.fy) && std::isfinite(K.cx) &&
          std::isfinite(K.cy) && K.fx > 0 && K.fy > 0))
        throw InputError(f.name + ": invalid intrinsics (fx " + std::to_string(K.fx) + ", fy " +
                         std::to_string(K.fy) + ", cx " + std::to_string(K.cx) + ", cy " +
                         std::to_string(K.cy) + "): must be finite with fx, fy > 0");
    const ColorView& c = f.color;
    if (c.data != nullptr && (c.width != d.width || c.height != d.height))
        throw InputError(f.name + ": colour is " + size_str(c.width, c.height) +
                         " but depth is " + size_str(d.width, d.height));
}

}  // namespace

RgbdView stage_view(const FrameView& f, RgbdFrame& staging) {
    check(f);
    const DepthView& d = f.depth;
    const ColorView& c = f.color;
    const int W = d.width, H = d.height;
    const std::size_t n = static_cast<std::size_t>(W) * H;

    RgbdView v;
    v.name = f.name;
    v.intrinsics = f.intrinsics;
    if (v.intrinsics.width == 0 && v.intrinsics.height == 0) {
        v.intrinsics.width = W;
        v.intrinsics.height = H;
    }
    v.width = W;
    v.height = H;
    v.depth_scale_m_per_unit = d.scale_m_per_unit;
    v.color_width = c.data ? W : 0;
    v.color_height = c.data ? H : 0;

    // Depth: in place when 16-bit, packed and aligned; else into staging.depth.
    const std::size_t depth_pixel = d.format == DepthFormat::U16 ? 2 : 4;
    const std::size_t depth_stride = row_bytes(f, "depth", W, d.stride_bytes, depth_pixel);
    const auto* depth_bytes = static_cast<const unsigned char*>(d.data);
    if (d.format == DepthFormat::U16 && depth_stride == 2 * static_cast<std::size_t>(W) &&
        reinterpret_cast<std::uintptr_t>(d.data) % alignof(std::uint16_t) == 0) {
        v.depth = static_cast<const std::uint16_t*>(d.data);
    } else {
        staging.depth.width = W;
        staging.depth.height = H;
        staging.depth.scale_m_per_unit = d.scale_m_per_unit;
        staging.depth.data.resize(n);
        std::uint16_t* out = staging.depth.data.data();
        const double scale = d.scale_m_per_unit;
        for (int y = 0; y < H; ++y) {
            const unsigned char* row = depth_bytes + static_cast<std::size_t>(y) * depth_stride;
            std::uint16_t* o = out + static_cast<std::size_t>(y) * W;
            if (d.format == DepthFormat::U16) {
                std::memcpy(o, row, 2 * static_cast<std::size_t>(W));
                continue;
            }
            for (int x = 0; x < W; ++x) {
                float z;
                std::memcpy(&z, row + 4 * static_cast<std::size_t>(x), 4);
                o[x] = to_units(z, scale);
            }
        }
        v.depth = out;
    }

    // Colour: in place when RGB and packed; else into staging.color.
    if (c.data != nullptr) {
        const std::size_t stride = row_bytes(f, "colour", W, c.stride_bytes, 3);
        if (c.order == ColorOrder::RGB && stride == 3 * static_cast<std::size_t>(W)) {
            v.rgb = c.data;
        } else {
            staging.color.width = W;
            staging.color.height = H;
            staging.color.rgb.resize(3 * n);
            std::uint8_t* out = staging.color.rgb.data();
            for (int y = 0; y < H; ++y) {
                const std::uint8_t* row = c.data + static_cast<std::size_t>(y) * stride;
                std::uint8_t* o = out + 3 * static_cast<std::size_t>(y) * W;
                if (c.order == ColorOrder::RGB) {
                    std::memcpy(o, row, 3 * static_cast<std::size_t>(W));
                    continue;
                }
                for (int x = 0; x < 3 * W; x += 3) {
                    o[x] = row[x + 2];
                    o[x + 1] = row[x + 1];
                    o[x + 2] = row[x];
                }
            }
            v.rgb = out;
        }
    }
    return v;
}

}  // namespace wul3d
