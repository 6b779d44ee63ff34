// Objects: one tracker step. The same frame's segments come in every iteration, so the
// tracker is in its steady state (tracks continued, weights saturating), not on a first frame.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/objects.hpp"

using namespace wul3d;

static void BM_ObjectTrackerStep(benchmark::State& state) {
    const bench::ProcessedFrame& pf = bench::processed_tabletop();
    const LabelImage segments = pf.result.segments;
    const int n_segments = pf.result.segment_stats.segments;
    const LabelImage clusters = pf.result.labels;
    ObjectTracker tracker(pf.pipeline.params().objects);
    LabelImage objects;
    std::vector<DetectedObject> list;
    for (int i = 0; i < 3; ++i)  // past the first frame: tracks exist, buffers are sized
        tracker.step(pf.pipeline.cloud(), segments, n_segments, clusters, objects, list);
    for (auto _ : state) {
        tracker.step(pf.pipeline.cloud(), segments, n_segments, clusters, objects, list);
        benchmark::DoNotOptimize(objects.labels.data());
    }
    state.counters["objects"] = static_cast<double>(list.size());
}
BENCHMARK(BM_ObjectTrackerStep)->Unit(benchmark::kMillisecond)->UseRealTime();
