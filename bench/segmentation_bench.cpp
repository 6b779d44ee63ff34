// Segmentation: the three segmenters on the same plane classes and cluster labels.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"
#include "wul3d/segmentation.hpp"

using namespace wul3d;

static void BM_SegmentObjects(benchmark::State& state, Segmenter segmenter) {
    const bench::ProcessedFrame& pf = bench::processed_tabletop();
    SegmentParams params = pf.pipeline.params().segmentation;
    params.segmenter = segmenter;
    const std::vector<std::uint8_t> classes = pf.result.plane_classes;
    const LabelImage clusters = pf.result.labels;
    SegmentWorkspace ws;
    LabelImage out;
    const Plane* support = pf.result.plane.found ? &pf.result.plane.support : nullptr;
    SegmentStats stats = segment_objects(params, pf.pipeline.cloud(), pf.pipeline.normals(),
                                         classes, support, clusters, ws, out);
    for (auto _ : state) {
        stats = segment_objects(params, pf.pipeline.cloud(), pf.pipeline.normals(), classes,
                                support, clusters, ws, out);
        benchmark::DoNotOptimize(out.labels.data());
    }
    state.counters["segments"] = stats.segments;
}
BENCHMARK_CAPTURE(BM_SegmentObjects, geometric, Segmenter::Geometric)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SegmentObjects, hybrid, Segmenter::Hybrid)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SegmentObjects, kmeans, Segmenter::Kmeans)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
