// The process-wide stop request of stop.hpp.
#include "wul3d/stop.hpp"

#include <atomic>
#include <string>

namespace wul3d {

namespace {
// Lock-free, so that a signal handler may store to it.
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace

void request_stop() noexcept { g_stop.store(true, std::memory_order_relaxed); }
void clear_stop_request() noexcept { g_stop.store(false, std::memory_order_relaxed); }
bool stop_requested() noexcept { return g_stop.load(std::memory_order_relaxed); }

void throw_if_stop_requested(const char* where) {
    if (stop_requested()) throw Stopped(std::string("stopped by request during ") + where);
}

}  // namespace wul3d
