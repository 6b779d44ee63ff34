// write_ply (io.hpp): a frame's labelled points as binary little-endian PLY, written
// atomically.
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"

namespace wul3d {

using detail::size_str;

void write_ply(const std::string& path, const OrganizedCloud& cloud, const LabelImage& labels,
               const ColorImage& colors) {
    const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
    const bool sizes_ok = cloud.valid.size() == n && cloud.x.size() == n && cloud.y.size() == n &&
                          cloud.z.size() == n && labels.width == cloud.width &&
                          labels.height == cloud.height && labels.labels.size() == n;
    const bool own_colors = !colors.empty();
    if (!sizes_ok || (own_colors && (colors.width != cloud.width || colors.height != cloud.height ||
                                     colors.rgb.size() != 3 * n))) {
        throw IoError(path + ": cannot write PLY: cloud " + size_str(cloud.width, cloud.height) +
                      ", labels " + size_str(labels.width, labels.height) + " and colours " +
                      size_str(colors.width, colors.height) + " differ in size");
    }
    const bool cloud_colors = !own_colors && cloud.has_color && cloud.r.size() == n &&
                              cloud.g.size() == n && cloud.b.size() == n;
    std::size_t count = 0;
    for (std::size_t p = 0; p < n; ++p) count += (labels.labels[p] > 0 && cloud.valid[p]) ? 1 : 0;

    const std::string header = "ply\nformat binary_little_endian 1.0\ncomment wul3d labelled points\n"
                               "element vertex " + std::to_string(count) +
                               "\nproperty float x\nproperty float y\nproperty float z\n"
                               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                               "property ushort label\nend_header\n";
    constexpr std::size_t kVertexBytes = 3 * 4 + 3 + 2;
    std::vector<char> buf(header.size() + count * kVertexBytes);
    std::memcpy(buf.data(), header.data(), header.size());
    char* out = buf.data() + header.size();
    static_assert(std::endian::native == std::endian::little,
                  "write_ply writes the host's floats as little-endian");
    for (std::size_t p = 0; p < n; ++p) {
        if (labels.labels[p] == 0 || !cloud.valid[p]) continue;
        const float xyz[3] = {cloud.x[p], cloud.y[p], cloud.z[p]};
        std::uint8_t rgb[3] = {200, 200, 200};  // depth-only without colours: light grey
        if (own_colors) {
            std::memcpy(rgb, &colors.rgb[3 * p], 3);
        } else if (cloud_colors) {
            rgb[0] = cloud.r[p], rgb[1] = cloud.g[p], rgb[2] = cloud.b[p];
        }
        const std::uint16_t label = labels.labels[p];
        std::memcpy(out, xyz, 12);
        std::memcpy(out + 12, rgb, 3);
        std::memcpy(out + 15, &label, 2);
        out += kVertexBytes;
    }
    write_file_atomic(path, buf.data(), buf.size());
}

}  // namespace wul3d
