#pragma once
/// @file threads.hpp
/// How many worker threads the pipelines of this process use (OpenMP's team size), with the
/// one bound every entry point shares: the command's --threads, `wul3d bench`, Python's
/// wul3d.set_num_threads and the batch.
namespace wul3d {

/// The most worker threads accepted. A team of tens of thousands makes OpenMP's runtime
/// exhaust memory or stacks and end the process; no machine wul3d runs on has more cores.
inline constexpr int kMaxThreads = 1024;

/// Sets the worker threads of every pipeline in this process. Throws ParamError (naming
/// `threads` and the range) unless 1 <= n <= kMaxThreads; nothing changes then.
void set_num_threads(int n);

/// The worker threads a pipeline uses now.
int num_threads();

}  // namespace wul3d
