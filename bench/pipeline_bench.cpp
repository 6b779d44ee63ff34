// The whole pipeline on a real 640x480 frame; each stage alone is in bench/<stage>_bench.cpp.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/pipeline.hpp"

using namespace wul3d;

static void BM_Pipeline(benchmark::State& state) {
    PipelineParams params;
    params.cluster.k = static_cast<int>(state.range(0));
    Pipeline pipeline(params);
    const RgbdFrame& f = bench::tabletop_frame();
    pipeline.process(f);
    for (auto _ : state) benchmark::DoNotOptimize(pipeline.process(f).stats.points);
}
BENCHMARK(BM_Pipeline)->ArgName("k")->Arg(7)->Arg(10)->Unit(benchmark::kMillisecond)
    ->UseRealTime();
