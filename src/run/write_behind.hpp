#pragma once
// Writing behind the loop that processes frames (run.cpp): encoding a frame's PNGs costs
// more than processing it, so writer threads encode and write while the loop goes on, and
// the loop commits the written frames in their order. Private to the library.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace wul3d::detail {

/// A ring of `capacity` jobs written by `writers` threads. The loop fills the slot next()
/// gives and submit()s it; writers run `write` on submitted jobs, any number at once, each
/// writer with its own WriterState (what it reuses from job to job: an encoder's tables); the
/// loop takes finished jobs back with oldest() in the order they were submitted, so what it
/// does with them (a log line, a callback) keeps the frame order. Jobs live in the ring:
/// their buffers are reused from frame to frame.
template <class Job, class WriterState>
class WriteBehind {
public:
    WriteBehind(std::size_t capacity, int writers, std::function<void(Job&, WriterState&)> write)
        : ring_(capacity < 1 ? 1 : capacity), write_(std::move(write)) {
        for (int t = 0; t < (writers < 1 ? 1 : writers); ++t)
            threads_.emplace_back([this] { write_loop(); });
    }
    /// Finishes the jobs being written, skips those not started, and joins the writers.
    ~WriteBehind() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
        }
        changed_.notify_all();
        for (std::thread& t : threads_) t.join();
    }
    WriteBehind(const WriteBehind&) = delete;
    WriteBehind& operator=(const WriteBehind&) = delete;

    bool full() const { return submitted_ - taken_ == ring_.size(); }
    bool empty() const { return submitted_ == taken_; }
    /// The slot the next job fills; only while !full().
    Job& next() { return ring_[submitted_ % ring_.size()].job; }
    /// Hands next() to the writers.
    void submit() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            ++submitted_;
        }
        changed_.notify_all();
    }
    /// The oldest submitted job once written (waiting for it when `wait`), or nullptr when
    /// none is in flight or, without `wait`, it is not written yet. `error` is what its
    /// write threw. Give it back with release() before the next call.
    Job* oldest(bool wait, std::exception_ptr& error) {
        if (empty()) return nullptr;
        Slot& slot = ring_[taken_ % ring_.size()];
        std::unique_lock<std::mutex> lock(mutex_);
        if (wait) changed_.wait(lock, [&slot] { return slot.done; });
        if (!slot.done) return nullptr;
        error = slot.error;
        return &slot.job;
    }
    void release() {
        Slot& slot = ring_[taken_ % ring_.size()];
        std::lock_guard<std::mutex> lock(mutex_);
        slot.done = false;
        slot.error = nullptr;
        ++taken_;
    }

private:
    struct Slot {
        Job job;
        std::exception_ptr error;
        bool done = false;
    };

    void write_loop() {
        WriterState state;
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            changed_.wait(lock, [this] { return stopping_ || started_ < submitted_; });
            if (stopping_) return;
            Slot& slot = ring_[started_++ % ring_.size()];
            lock.unlock();
            std::exception_ptr error;
            try {
                write_(slot.job, state);
            } catch (...) {
                error = std::current_exception();
            }
            lock.lock();
            slot.error = error;
            slot.done = true;
            changed_.notify_all();
        }
    }

    std::vector<Slot> ring_;
    std::function<void(Job&, WriterState&)> write_;
    // Jobs [taken_, submitted_) are in flight; [started_, submitted_) wait for a writer.
    std::size_t submitted_ = 0, started_ = 0, taken_ = 0;
    bool stopping_ = false;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<std::thread> threads_;
};

}  // namespace wul3d::detail
