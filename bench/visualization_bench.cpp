// Colours (step 8): eq. (9) display colours from the kept weights.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/objects.hpp"
#include "wul3d/visualization.hpp"

using namespace wul3d;

static void BM_RenderWeightColors(benchmark::State& state) {
    const bench::ProcessedFrame& pf = bench::processed_tabletop();
    const LabelImage labels = pf.result.labels;
    ColorImage out;
    render_weight_colors(pf.pipeline.state(), labels, pf.frame, out);
    for (auto _ : state) {
        render_weight_colors(pf.pipeline.state(), labels, pf.frame, out);
        benchmark::DoNotOptimize(out.rgb.data());
    }
}
BENCHMARK(BM_RenderWeightColors)->Unit(benchmark::kMillisecond)->UseRealTime();
