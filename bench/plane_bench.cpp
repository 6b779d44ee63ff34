// Support plane: find the table and classify every pixel.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/plane.hpp"

using namespace wul3d;

static void BM_RemoveSupportPlane(benchmark::State& state) {
    const bench::ProcessedFrame& pf = bench::processed_tabletop();
    const PlaneParams params = pf.pipeline.params().plane;
    const std::vector<std::uint8_t> active = pf.result.active;
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    PlaneResult r = remove_support_plane(params, pf.frame.intrinsics, pf.pipeline.cloud(),
                                         pf.pipeline.normals(), active, ws, classes);
    for (auto _ : state) {
        r = remove_support_plane(params, pf.frame.intrinsics, pf.pipeline.cloud(),
                                 pf.pipeline.normals(), active, ws, classes);
        benchmark::DoNotOptimize(classes.data());
    }
    state.counters["found"] = r.found ? 1 : 0;
    state.counters["kept_px"] = static_cast<double>(r.kept);
}
BENCHMARK(BM_RemoveSupportPlane)->Unit(benchmark::kMillisecond)->UseRealTime();
