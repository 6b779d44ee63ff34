// Back-projection (step 3): every valid depth pixel to a 3D point with its colour.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/backprojection.hpp"

using namespace wul3d;

static void BM_BackProject(benchmark::State& state) {
    const RgbdFrame& f = bench::tabletop_frame();
    OrganizedCloud cloud;
    back_project(f, cloud);  // allocates once
    for (auto _ : state) benchmark::DoNotOptimize(back_project(f, cloud));
}
BENCHMARK(BM_BackProject)->Unit(benchmark::kMillisecond)->UseRealTime();
