// The process's worker threads (threads.hpp), bounded before OpenMP sees the number.
#include "wul3d/threads.hpp"

#include <omp.h>

#include <string>

#include "wul3d/error.hpp"

namespace wul3d {

void set_num_threads(int n) {
    if (n < 1 || n > kMaxThreads)
        throw ParamError("threads = " + std::to_string(n) + ": must be in [1, " +
                         std::to_string(kMaxThreads) + "]");
    omp_set_num_threads(n);
}

int num_threads() { return omp_get_max_threads(); }

}  // namespace wul3d
