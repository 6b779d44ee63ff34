#pragma once
// Selects without a branch, for the per-pixel loops that GCC should vectorize.
#include <bit>
#include <cstdint>

namespace wul3d::detail {

/// ok ? a : b, by a bit mask in place of a branch: GCC turns `ok ? a : b` back into a branch
/// when an operand is a load or may trap (an FP multiply), sinks it into the branch, and
/// then no longer vectorizes the loop. The same bits as the branch.
inline float pick(bool ok, float a, float b) {
    const std::uint32_t m = 0u - static_cast<std::uint32_t>(ok);
    return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & m) | (std::bit_cast<std::uint32_t>(b) & ~m));
}

}  // namespace wul3d::detail
