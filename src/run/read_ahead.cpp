// A recording read ahead of its processing (read_ahead.hpp).
#include "read_ahead.hpp"

#include <algorithm>
#include <utility>

namespace wul3d::detail {

ReadAhead::ReadAhead(std::vector<FrameSource*> readers, std::size_t count, std::size_t depth)
    : end_(count), ring_(std::max<std::size_t>(1, depth)) {
    threads_.reserve(readers.size());
    try {
        for (FrameSource* source : readers) threads_.emplace_back([this, source] { read_loop(*source); });
    } catch (...) {
        stop();
        throw;
    }
}

ReadAhead::~ReadAhead() { stop(); }

void ReadAhead::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
}

void ReadAhead::read_loop(FrameSource& source) {
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
            source.read(i, slot.item);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        slot.error = error;
        slot.ready = true;
        changed_.notify_all();
        if (error) {  // the run ends at this frame: nothing after it is needed
            end_ = std::min(end_, i + 1);
            return;
        }
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
        end_ = next_taken_;  // the readers stop at this frame: nothing follows it
    } else {
        std::swap(item, slot.item);
    }
    lock.unlock();
    changed_.notify_all();
    if (error) std::rethrow_exception(error);
    return true;
}

}  // namespace wul3d::detail
