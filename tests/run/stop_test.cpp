// The stop request of stop.hpp: a frame of minutes (k = 65535) must end within a bounded
// time of the request, with Stopped, and a withdrawn request must not stop the next run.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "synthetic_scene.hpp"
#include "wul3d/error.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/stop.hpp"

namespace {

using namespace wul3d;

/// A 640 x 480 frame whose every pixel is in the depth range: a wall 2.4 m away behind a
/// table, enough points for k = 65535.
RgbdFrame big_frame() {
    test::Scene scene;
    scene.wall = true;
    scene.width = 640;
    scene.height = 480;
    return test::render_scene(scene);
}

TEST(Stop, RequestEndsAFrameOfMinutes) {
    PipelineParams params;
    params.cluster.k = 65535;
    params.decimation = 1;
    params.range.zmin_m = 0.01f;
    params.range.zmax_m = 100.0f;
    Pipeline pipeline(params);
    const RgbdFrame frame = big_frame();
    clear_stop_request();
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        request_stop();
    });
    bool stopped = false;
    try {
        pipeline.process(frame);
    } catch (const Stopped&) {
        stopped = true;
    }
    stopper.join();
    clear_stop_request();
    // The frame takes minutes unless the request ends it (ctest's timeout bounds the test);
    // how fast it ends is measured in bench/stop_bench.cpp, not here.
    EXPECT_TRUE(stopped) << "the frame ended without the request (it should take minutes)";
}

TEST(Stop, WithdrawnRequestDoesNotStopTheNextFrame) {
    request_stop();
    EXPECT_TRUE(stop_requested());
    EXPECT_THROW(throw_if_stop_requested("a test"), Stopped);
    clear_stop_request();
    EXPECT_FALSE(stop_requested());
    PipelineParams params;
    Pipeline pipeline(params);
    test::Scene scene;
    EXPECT_NO_THROW(pipeline.process(test::render_scene(scene)));
}

}  // namespace
