// The decimation stage alone (--decimate 2) on a real 640x480 frame: shrinking the frame, and
// finding each input pixel's source among the decimated pixels (the look-up that
// expand_result (decimation.cpp) does per pixel before copying the results).
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/decimation.hpp"

using namespace wul3d;

static void BM_DecimateFrame(benchmark::State& state) {
    const RgbdFrame& f = bench::tabletop_frame();
    RgbdFrame out;
    decimate_frame(f, 2, out);
    for (auto _ : state) {
        decimate_frame(f, 2, out);
        benchmark::DoNotOptimize(out.depth.data.data());
    }
}
BENCHMARK(BM_DecimateFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_DecimatedSource(benchmark::State& state) {
    const RgbdFrame& f = bench::tabletop_frame();
    RgbdFrame small;
    decimate_frame(f, 2, small);
    std::vector<std::int32_t> source(f.depth.data.size());
    const int W = f.width(), H = f.height();
    for (auto _ : state) {
        const DecimatedSource s(f.depth, small.depth, 2, 0.008f, 0.024f);
#pragma omp parallel for schedule(static)
        for (int v = 0; v < H; ++v)
            for (int u = 0; u < W; ++u)  // blocks stepped as in expand_result: no division
                source[static_cast<std::size_t>(v) * W + u] = s.in_block(u, v, u >> 1, v >> 1);
        benchmark::DoNotOptimize(source.data());
    }
}
BENCHMARK(BM_DecimatedSource)->Unit(benchmark::kMillisecond)->UseRealTime();
