// Loops whose iterations may run on any thread, inside a team or not (internal).
#pragma once

#include <omp.h>

#include <cstddef>

namespace wul3d::detail {

/// How for_each_part spreads its parts outside a team.
enum class Spread { kStatic, kDynamic };

/// Calls part(i) for each i in [0, n), each on one thread. Inside a team (the pipeline's
/// two halves side by side, Pipeline::Impl::run_on) the parts go out as tasks, which the
/// other half's thread takes once its own work is done; elsewhere the threads share them
/// in a loop, in fixed shares (kStatic) or one part at a time (kDynamic: parts of uneven
/// cost). part(i) must write only what part i owns: which thread runs it is not fixed.
template <class Part>
void for_each_part(std::ptrdiff_t n, Spread spread, Part&& part) {
    if (omp_in_parallel()) {
        // An unsigned counter: clang compares a signed one with its unsigned trip count
        // (-Wsign-compare in its taskloop's code).
        const auto parts = static_cast<std::size_t>(n > 0 ? n : 0);
#pragma omp taskloop grainsize(1)
        for (std::size_t i = 0; i < parts; ++i) part(static_cast<std::ptrdiff_t>(i));
    } else if (spread == Spread::kDynamic) {
#pragma omp parallel for schedule(dynamic, 1)
        for (std::ptrdiff_t i = 0; i < n; ++i) part(i);
    } else {
#pragma omp parallel for schedule(static)
        for (std::ptrdiff_t i = 0; i < n; ++i) part(i);
    }
}

}  // namespace wul3d::detail
