// How soon a stop request (stop.hpp) ends a frame that would take minutes: the clustering at
// k = 65535 on every pixel of a real 640x480 frame, stopped 200 ms in. The time is from the
// request to Pipeline::process throwing Stopped (the issue asks for under 1 s).
#include <benchmark/benchmark.h>

#include <chrono>
#include <thread>

#include "bench_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/stop.hpp"

using namespace wul3d;

static void BM_StopLatency(benchmark::State& state) {
    PipelineParams params;
    params.cluster.k = 65535;
    params.decimation = 1;
    params.range.zmin_m = 0.01f;
    params.range.zmax_m = 100.0f;
    Pipeline pipeline(params);
    const RgbdFrame& f = bench::tabletop_frame();
    using Clock = std::chrono::steady_clock;
    for (auto _ : state) {
        clear_stop_request();
        Clock::time_point requested;
        std::thread stopper([&] {
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            requested = Clock::now();
            request_stop();
        });
        bool stopped = false;
        try {
            pipeline.process(f);
        } catch (const Stopped&) {
            stopped = true;
        }
        const Clock::time_point ended = Clock::now();
        stopper.join();
        if (!stopped) state.SkipWithError("the frame ended without the stop request");
        state.SetIterationTime(std::chrono::duration<double>(ended - requested).count());
    }
    clear_stop_request();
}
BENCHMARK(BM_StopLatency)->UseManualTime()->Iterations(5)->Unit(benchmark::kMillisecond);
