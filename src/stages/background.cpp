#include "wul3d/background.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "wul3d/error.hpp"

namespace wul3d {

void DepthRange::validate() const {
    // 1000 m: beyond any depth sensor, and where a float still resolves millimetres.
    if (!(std::isfinite(zmin_m) && std::isfinite(zmax_m) && zmin_m >= 0 && zmax_m > zmin_m &&
          zmax_m <= 1000.0f)) {
        std::ostringstream msg;
        msg << "depth range zmin = " << zmin_m << " m, zmax = " << zmax_m
            << " m: need 0 <= zmin < zmax <= 1000";
        throw ParamError(msg.str());
    }
}

namespace {

/// active[p] for the pixels [p0, p1), as select_depth_range; returns their count. Raw
/// pointers, the limits as values and `&`, not `&&`: the loop vectorizes. Cost: one pass.
std::size_t select_pixels(const float* __restrict z, const std::uint8_t* __restrict valid, std::size_t p0,
                          std::size_t p1, float zmin, float zmax, std::uint8_t* __restrict active) {
    std::size_t count = 0;
    for (std::size_t p = p0; p < p1; ++p) {
        const std::uint8_t keep = (valid[p] != 0) & (z[p] >= zmin) & (z[p] <= zmax);
        active[p] = keep;
        count += keep;
    }
    return count;
}

}  // namespace

std::size_t select_depth_range(const DepthRange& range, const OrganizedCloud& cloud,
                               std::vector<std::uint8_t>& active) {
    const std::size_t n = cloud.size();
    active.resize(n);
    std::size_t count = 0;
    // Fixed pieces of the pixels (DepthRange::contains on each, as before).
    constexpr std::size_t kPiece = 4096;
    const auto pieces = static_cast<std::ptrdiff_t>((n + kPiece - 1) / kPiece);
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (std::ptrdiff_t i = 0; i < pieces; ++i) {
        const std::size_t p0 = static_cast<std::size_t>(i) * kPiece;
        count += select_pixels(cloud.z.data(), cloud.valid.data(), p0, std::min(n, p0 + kPiece), range.zmin_m,
                               range.zmax_m, active.data());
    }
    return count;
}

}  // namespace wul3d
