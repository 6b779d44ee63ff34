#pragma once
// Reading a recording ahead of the loop that processes it (FrameFeed, FeedOptions::read_ahead):
// decoding a 640x480 frame's two PNGs costs about as much as processing it, so readers decode
// while the loop works; on a machine of many cores one reader (about 95 frames a second at
// 640x480) would be slower than the stages, so several read at once, each with a decoder of
// its own (FrameSource::clone). Private to the library.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "wul3d/io.hpp"

namespace wul3d::detail {

/// Frames 0..count-1 of a recording, read by one thread per source in `readers` (the same
/// frames each: the source and its clones) into a ring of `depth` items, and taken in order
/// by next(). Each reader takes the next frame not yet taken by another, so the frames come
/// in order whatever the number of readers. The items' buffers circulate: next() swaps the
/// read frame into the caller's item and the caller's buffers into the ring, so nothing is
/// allocated per frame once the sizes settle. Only the reader threads call read(), each on
/// its own source; the caller may still call the sources' const members (name()).
class ReadAhead {
public:
    ReadAhead(std::vector<FrameSource*> readers, std::size_t count, std::size_t depth);
    ~ReadAhead();  ///< stops reading and joins the threads
    ReadAhead(const ReadAhead&) = delete;
    ReadAhead& operator=(const ReadAhead&) = delete;

    /// Blocks until the next frame is read and swaps it into `item`; false past the last.
    /// A frame that could not be read throws its error here, in its turn.
    bool next(SourceItem& item);

private:
    struct Slot {
        SourceItem item;
        std::exception_ptr error;
        bool ready = false;
    };
    void read_loop(FrameSource& source);
    void stop();  // stops reading and joins the threads

    std::size_t end_;  // frames to read; cut short by a frame that fails
    std::vector<Slot> ring_;  // frame i lives in ring_[i % ring_.size()]
    std::size_t next_read_ = 0, next_taken_ = 0;
    bool stopping_ = false;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<std::thread> threads_;
};

}  // namespace wul3d::detail
