// Normals (step 4) and the smoothed normals that segmentation's crease tests use.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/normals.hpp"

using namespace wul3d;

static void BM_Normals(benchmark::State& state) {
    const OrganizedCloud& cloud = bench::processed_tabletop().pipeline.cloud();
    const NormalParams params = bench::processed_tabletop().pipeline.params().normals;
    NormalMap normals;
    estimate_normals(params, cloud, normals);
    for (auto _ : state) {
        estimate_normals(params, cloud, normals);
        benchmark::DoNotOptimize(normals.valid.data());
    }
}
BENCHMARK(BM_Normals)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_SmoothNormals(benchmark::State& state) {
    const NormalMap& normals = bench::processed_tabletop().pipeline.normals();
    const int radius = static_cast<int>(state.range(0));
    std::vector<float> scratch;
    NormalMap smooth;
    smooth_normals(normals, radius, scratch, smooth);
    for (auto _ : state) {
        smooth_normals(normals, radius, scratch, smooth);
        benchmark::DoNotOptimize(smooth.valid.data());
    }
}
BENCHMARK(BM_SmoothNormals)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();
