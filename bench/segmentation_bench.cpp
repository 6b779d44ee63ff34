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
    const Plane* low_support = support && pf.result.plane.low_found ? &pf.result.plane.low_support : nullptr;
    SegmentStats stats = segment_objects(params, pf.pipeline.cloud(), pf.pipeline.normals(),
                                         classes, support, low_support, clusters, ws, out);
    SegmentStats::Phases sum;
    for (auto _ : state) {
        stats = segment_objects(params, pf.pipeline.cloud(), pf.pipeline.normals(), classes,
                                support, low_support, clusters, ws, out);
        benchmark::DoNotOptimize(out.labels.data());
        sum.smoothing += stats.ms.smoothing;
        sum.cuts += stats.ms.cuts;
        sum.components += stats.ms.components;
        sum.reattach += stats.ms.reattach;
        sum.merge += stats.ms.merge;
        sum.containers += stats.ms.containers;
        sum.color += stats.ms.color;
        sum.stacks += stats.ms.stacks;
        sum.pieces += stats.ms.pieces;
        sum.gaps += stats.ms.gaps;
        sum.occluded += stats.ms.occluded;
        sum.necks += stats.ms.necks;
        sum.scope += stats.ms.scope;
        sum.compact += stats.ms.compact;
    }
    using benchmark::Counter;
    state.counters["segments"] = stats.segments;
    state.counters["smoothing_ms"] = Counter(sum.smoothing, Counter::kAvgIterations);
    state.counters["cuts_ms"] = Counter(sum.cuts, Counter::kAvgIterations);
    state.counters["components_ms"] = Counter(sum.components, Counter::kAvgIterations);
    state.counters["reattach_ms"] = Counter(sum.reattach, Counter::kAvgIterations);
    state.counters["merge_ms"] = Counter(sum.merge, Counter::kAvgIterations);
    state.counters["containers_ms"] = Counter(sum.containers, Counter::kAvgIterations);
    state.counters["color_ms"] = Counter(sum.color, Counter::kAvgIterations);
    state.counters["stacks_ms"] = Counter(sum.stacks, Counter::kAvgIterations);
    state.counters["pieces_ms"] = Counter(sum.pieces, Counter::kAvgIterations);
    state.counters["gaps_ms"] = Counter(sum.gaps, Counter::kAvgIterations);
    state.counters["occluded_ms"] = Counter(sum.occluded, Counter::kAvgIterations);
    state.counters["necks_ms"] = Counter(sum.necks, Counter::kAvgIterations);
    state.counters["scope_ms"] = Counter(sum.scope, Counter::kAvgIterations);
    state.counters["compact_ms"] = Counter(sum.compact, Counter::kAvgIterations);
}
BENCHMARK_CAPTURE(BM_SegmentObjects, geometric, Segmenter::Geometric)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SegmentObjects, hybrid, Segmenter::Hybrid)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SegmentObjects, kmeans, Segmenter::Kmeans)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
