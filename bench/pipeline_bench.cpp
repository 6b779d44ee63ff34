// The whole pipeline on a real 640x480 frame; each stage alone is in bench/<stage>_bench.cpp.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/pipeline.hpp"

using namespace wul3d;

// decimate: PipelineParams::decimation (1 = every pixel). The times of each stage are the
// counters, averaged over the iterations (StageTimes).
static void BM_Pipeline(benchmark::State& state) {
    PipelineParams params;
    params.cluster.k = static_cast<int>(state.range(0));
    params.decimation = static_cast<int>(state.range(1));
    Pipeline pipeline(params);
    const RgbdFrame& f = bench::tabletop_frame();
    pipeline.process(f);
    StageTimes sum;
    for (auto _ : state) {
        const StageTimes& t = pipeline.process(f).times;
        sum.decimation += t.decimation;
        sum.plane += t.plane;
        sum.segmentation += t.segmentation;
        sum.objects += t.objects;
    }
    using benchmark::Counter;
    state.counters["decimation_ms"] = Counter(sum.decimation, Counter::kAvgIterations);
    state.counters["plane_ms"] = Counter(sum.plane, Counter::kAvgIterations);
    state.counters["segmentation_ms"] = Counter(sum.segmentation, Counter::kAvgIterations);
    state.counters["objects_ms"] = Counter(sum.objects, Counter::kAvgIterations);
}
BENCHMARK(BM_Pipeline)
    ->ArgNames({"k", "decimate"})
    ->Args({7, 1})
    ->Args({10, 1})
    ->Args({10, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
