// Background (step 5): the depth-range mask.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/background.hpp"

using namespace wul3d;

static void BM_SelectDepthRange(benchmark::State& state) {
    const OrganizedCloud& cloud = bench::processed_tabletop().pipeline.cloud();
    const DepthRange range = bench::processed_tabletop().pipeline.params().range;
    std::vector<std::uint8_t> active;
    select_depth_range(range, cloud, active);
    for (auto _ : state) benchmark::DoNotOptimize(select_depth_range(range, cloud, active));
}
BENCHMARK(BM_SelectDepthRange)->Unit(benchmark::kMillisecond)->UseRealTime();
