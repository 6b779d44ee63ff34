#include "wul3d/background.hpp"

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

std::size_t select_depth_range(const DepthRange& range, const OrganizedCloud& cloud,
                               std::vector<std::uint8_t>& active) {
    const std::size_t n = cloud.size();
    active.resize(n);
    std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (std::size_t p = 0; p < n; ++p) {
        const float z = cloud.z[p];
        const std::uint8_t keep = (cloud.valid[p] && range.contains(z)) ? 1 : 0;
        active[p] = keep;
        count += keep;
    }
    return count;
}

}  // namespace wul3d
