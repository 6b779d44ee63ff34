// The capture thread and its mailbox (capture.hpp) with a scripted camera: newest frame wins
// and drops are counted, lossless delivers every frame, a lost camera and a stalled one end
// with DeviceLost, stop() ends promptly; and the --camera spec.
#include "wul3d/capture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "wul3d/error.hpp"

using namespace wul3d;
using namespace std::chrono_literals;

namespace {

/// Delivers `frames` frames (every `period`), then End, or throws DeviceLost when `lose`;
/// `frames` < 0: forever. Each frame's depth holds its number.
class ScriptedCamera : public CameraDevice {
public:
    ScriptedCamera(int frames, std::chrono::milliseconds period, bool lose = false)
        : frames_(frames), period_(period), lose_(lose) {}
    std::string description() const override { return "scripted camera"; }
    GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) override {
        if (frames_ >= 0 && n_ >= frames_) {
            if (lose_) throw DeviceLost("scripted camera: unplugged");
            return GrabResult::End;
        }
        if (period_ > timeout) {
            std::this_thread::sleep_for(timeout);
            return GrabResult::Timeout;
        }
        std::this_thread::sleep_for(period_);
        item.is_raw = false;
        item.frame.depth.width = item.frame.depth.height = 1;
        item.frame.depth.data.assign(1, static_cast<std::uint16_t>(n_++));
        return GrabResult::Frame;
    }

private:
    int frames_;
    std::chrono::milliseconds period_;
    bool lose_;
    int n_ = 0;
};

}  // namespace

TEST(LiveSource, Lossless_DeliversEveryFrameInOrder_ThenEnd) {
    LiveOptions o;
    o.lossless = true;
    LiveSource live(std::make_unique<ScriptedCamera>(12, 0ms), o);
    SourceItem item;
    int expected = 0;
    for (;;) {
        const auto r = live.next(item, 2000ms);
        ASSERT_NE(r, LiveSource::Next::Timeout);
        if (r == LiveSource::Next::End) break;
        EXPECT_EQ(item.frame.depth.data[0], expected);
        EXPECT_EQ(item.frame.name, "frame_0000" + std::string(expected < 10 ? "0" : "") +
                                       std::to_string(expected));
        ++expected;
        std::this_thread::sleep_for(5ms);  // slower than the camera
    }
    EXPECT_EQ(expected, 12);
    EXPECT_EQ(live.captured(), 12u);
    EXPECT_EQ(live.dropped(), 0u);
}

TEST(LiveSource, SlowProcessing_NewestWins_AndDropsAreCounted) {
    LiveSource live(std::make_unique<ScriptedCamera>(40, 1ms));
    SourceItem item;
    int taken = 0, last = -1;
    for (;;) {
        const auto r = live.next(item, 2000ms);
        ASSERT_NE(r, LiveSource::Next::Timeout);
        if (r == LiveSource::Next::End) break;
        EXPECT_GT(item.frame.depth.data[0], last);  // never an older frame
        last = item.frame.depth.data[0];
        ++taken;
        // Slower than the camera by construction, not by a timed sleep: let it grab two more
        // frames before the next read, so at least one is replaced unread.
        const std::uint64_t until = std::min<std::uint64_t>(live.captured() + 2, 40);
        while (live.captured() < until) std::this_thread::yield();
    }
    EXPECT_EQ(live.captured(), 40u);
    EXPECT_GT(live.dropped(), 0u);
    EXPECT_EQ(static_cast<std::uint64_t>(taken) + live.dropped(), 40u);
    EXPECT_EQ(last, 39);  // the newest frame is never the one dropped
}

TEST(LiveSource, LostCamera_FramesBeforeItThenDeviceLost) {
    LiveOptions o;
    o.lossless = true;
    LiveSource live(std::make_unique<ScriptedCamera>(3, 0ms, true), o);
    SourceItem item;
    for (int i = 0; i < 3; ++i) ASSERT_EQ(live.next(item, 2000ms), LiveSource::Next::Frame);
    EXPECT_THROW(live.next(item, 2000ms), DeviceLost);
}

TEST(LiveSource, StalledCamera_EndsWithDeviceLost) {
    LiveOptions o;
    o.stall_timeout = 300ms;
    LiveSource live(std::make_unique<ScriptedCamera>(-1, 10000ms), o);
    SourceItem item;
    LiveSource::Next r = LiveSource::Next::Timeout;
    bool lost = false;
    // At most 50 waits of 100 ms: the stall (300 ms) must be reported well before.
    for (int wait = 0; !lost && wait < 50; ++wait) {
        try {
            r = live.next(item, 100ms);
        } catch (const DeviceLost& e) {
            lost = true;
            EXPECT_NE(std::string(e.what()).find("no frame for 300 ms"), std::string::npos);
        }
        ASSERT_NE(r, LiveSource::Next::Frame);
    }
    EXPECT_TRUE(lost);
}

TEST(LiveSource, Stop_EndsPromptly_EvenWhenTheConsumerIsGone) {
    LiveOptions o;
    o.lossless = true;  // the capture thread blocks on the full slot
    auto live = std::make_unique<LiveSource>(std::make_unique<ScriptedCamera>(-1, 1ms), o);
    SourceItem item;
    ASSERT_EQ(live->next(item, 2000ms), LiveSource::Next::Frame);
    while (live->captured() < 2) std::this_thread::yield();  // the next frame waits on the slot
    // A stop that waited for the gone consumer would never return: the test would then hang
    // until ctest's per-test TIMEOUT (tests/CMakeLists.txt) fails it.
    live->stop();
    LiveSource::Next r = LiveSource::Next::Frame;
    while ((r = live->next(item, 500ms)) == LiveSource::Next::Frame) {
    }
    EXPECT_EQ(r, LiveSource::Next::End);  // next() after stop(): what is left, then End
    live.reset();                          // joins
}

TEST(CameraSpec, ParsesBackendAndArgument) {
    const CameraSpec a = parse_camera_spec("freenect:1");
    EXPECT_EQ(a.backend, "freenect");
    EXPECT_EQ(a.arg, "1");
    const CameraSpec b = parse_camera_spec("openni2:/data/a:b.oni");
    EXPECT_EQ(b.backend, "openni2");
    EXPECT_EQ(b.arg, "/data/a:b.oni");
    EXPECT_EQ(parse_camera_spec("realsense").arg, "");
    EXPECT_THROW(parse_camera_spec("nosuch"), ParamError);
    EXPECT_THROW(parse_camera_spec(""), ParamError);
}

TEST(CameraSpec, BackendNotBuilt_SaysSo) {
    // freenect2 and realsense are not in Debian 12; when absent, opening says how to build.
    for (const char* name : {"freenect2", "realsense"}) {
        bool built = false;
        for (const std::string& b : camera_backends()) built |= b == name;
        if (built) continue;
        try {
            open_camera(parse_camera_spec(name));
            ADD_FAILURE() << name;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("built without"), std::string::npos) << e.what();
        }
    }
}
