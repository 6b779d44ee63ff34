#pragma once
// Selects without a branch, for the per-pixel loops that GCC should vectorize, and the
// attribute that builds such a loop twice.
#include <bit>
#include <cstdint>

/// Before a function: built for AVX2 and for baseline x86-64, the one the CPU runs picked at
/// load time (GCC's target_clones, an ifunc). No FMA either way, so both give the same bits.
/// Off under AddressSanitizer: an ifunc's resolver runs while the program is relocated,
/// before the sanitizer's runtime is up.
#if defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
#define WUL3D_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define WUL3D_AVX2_CLONES
#endif

namespace wul3d::detail {

/// ok ? a : b, by a bit mask in place of a branch: GCC turns `ok ? a : b` back into a branch
/// when an operand is a load or may trap (an FP multiply), sinks it into the branch, and
/// then no longer vectorizes the loop. The same bits as the branch.
inline float pick(bool ok, float a, float b) {
    const std::uint32_t m = 0u - static_cast<std::uint32_t>(ok);
    return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & m) | (std::bit_cast<std::uint32_t>(b) & ~m));
}

/// The same for ints (GCC makes a branch of `ok ? a : b` where the test follows no pattern,
/// and the branch then mispredicts).
inline int pick(bool ok, int a, int b) {
    const int m = -static_cast<int>(ok);
    return (a & m) | (b & ~m);
}

}  // namespace wul3d::detail
