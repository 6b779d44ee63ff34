#pragma once
// Reading a recording ahead of the loop that processes it (FrameFeed, FeedOptions::read_ahead):
// decoding a 640x480 frame's two PNGs costs about as much as processing it, so one thread
// reads while the loop works. Private to the library.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "wul3d/io.hpp"

namespace wul3d::detail {

/// Frames 0..count-1 of `source`, read on one thread of its own into a ring of `depth`
/// items and taken in order by next(). The items' buffers circulate: next() swaps the read
/// frame into the caller's item and the caller's buffers into the ring, so nothing is
/// allocated per frame once the sizes settle. Only the reader thread calls source.read();
/// the caller may still call the source's const members (name()).
class ReadAhead {
public:
    ReadAhead(FrameSource& source, std::size_t count, std::size_t depth);
    ~ReadAhead();  ///< stops reading and joins the thread
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
    void read_loop();

    FrameSource& source_;
    std::size_t end_;  // frames to read; cut short by a frame that fails
    std::vector<Slot> ring_;  // frame i lives in ring_[i % ring_.size()]
    std::size_t next_read_ = 0, next_taken_ = 0;
    bool stopping_ = false;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::thread reader_;
};

}  // namespace wul3d::detail
