// A recording read ahead of its processing (read_ahead.hpp).
#include "read_ahead.hpp"

#include <algorithm>
#include <utility>

namespace wul3d::detail {

ReadAhead::ReadAhead(FrameSource& source, std::size_t count, std::size_t depth)
    : source_(source), end_(count), ring_(std::max<std::size_t>(1, depth)) {
    reader_ = std::thread([this] { read_loop(); });
}

ReadAhead::~ReadAhead() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    reader_.join();
}

void ReadAhead::read_loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        // A slot is free when the frame that last used it has been taken.
        changed_.wait(lock, [this] {
            return stopping_ || (next_read_ < end_ && next_read_ < next_taken_ + ring_.size());
        });
        if (stopping_ || next_read_ >= end_) return;
        const std::size_t i = next_read_++;
        Slot& slot = ring_[i % ring_.size()];
        lock.unlock();
        std::exception_ptr error;
        try {
            source_.read(i, slot.item);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        slot.error = error;
        slot.ready = true;
        changed_.notify_all();
        if (error) return;  // the loop ends at this frame: nothing after it is needed
    }
}

bool ReadAhead::next(SourceItem& item) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (next_taken_ >= end_) return false;
    Slot& slot = ring_[next_taken_ % ring_.size()];
    changed_.wait(lock, [&slot] { return slot.ready; });
    slot.ready = false;
    ++next_taken_;
    std::exception_ptr error = std::exchange(slot.error, nullptr);
    if (error) {
        end_ = next_taken_;  // the reader stopped at this frame: nothing follows it
    } else {
        std::swap(item, slot.item);
    }
    lock.unlock();
    changed_.notify_all();
    if (error) std::rethrow_exception(error);
    return true;
}

}  // namespace wul3d::detail
