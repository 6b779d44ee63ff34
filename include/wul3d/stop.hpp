#pragma once
/// @file stop.hpp
/// A stop request that the pipeline's stages check while they run, so that SIGINT or SIGTERM
/// ends even a frame of minutes (k = 65535) within a second: the clustering checks it
/// between blocks of points and between centres while seeding, the pipeline between stages.
/// A processed frame then throws Stopped, and the Pipeline must not be used for further
/// frames. The request is process-wide, set by one atomic store, so a signal handler may set
/// it.
#include "wul3d/error.hpp"

namespace wul3d {

/// Asks every running and later computation to stop. Async-signal-safe.
void request_stop() noexcept;
/// Withdraws the request (before a new run).
void clear_stop_request() noexcept;
bool stop_requested() noexcept;
/// Throws Stopped if a stop was requested; `where` names the stage for the message.
void throw_if_stop_requested(const char* where);

}  // namespace wul3d
