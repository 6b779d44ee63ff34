// Per-stage timings of the pipeline on a real 640x480 frame, and OpenCV's k-means on the same
// features as a peer in the same run.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include "bench_support.hpp"
#include "wul3d/pipeline.hpp"

using namespace wul3d;

static void BM_BackProject(benchmark::State& state) {
    const RgbdFrame& f = bench::tabletop_frame();
    OrganizedCloud cloud;
    for (auto _ : state) benchmark::DoNotOptimize(back_project(f, cloud));
}
BENCHMARK(BM_BackProject)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_Normals(benchmark::State& state) {
    OrganizedCloud cloud;
    back_project(bench::tabletop_frame(), cloud);
    NormalMap normals;
    for (auto _ : state) estimate_normals(NormalParams{}, cloud, normals);
}
BENCHMARK(BM_Normals)->Unit(benchmark::kMillisecond)->UseRealTime();

// One frame of Algorithm 1 (assign, weight update, centre move) after seeding.
static void BM_ClusterStep(benchmark::State& state) {
    OrganizedCloud cloud;
    back_project(bench::tabletop_frame(), cloud);
    NormalMap normals;
    estimate_normals(NormalParams{}, cloud, normals);
    std::vector<std::uint8_t> active;
    select_depth_range(DepthRange{}, cloud, active);
    ClusterParams p = ClusterParams::paper();
    p.k = static_cast<int>(state.range(0));
    ClusterState cs(p);
    LabelImage labels;
    cs.step(cloud, normals, active, labels);
    for (auto _ : state) benchmark::DoNotOptimize(cs.step(cloud, normals, active, labels));
    state.counters["points"] = static_cast<double>(cs.step(cloud, normals, active, labels).points);
}
BENCHMARK(BM_ClusterStep)->Arg(7)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

// Peer: cv::kmeans with k-means++ seeding and one iteration on the same points (it seeds on
// every call: that is what a per-frame k-means costs, as in the paper-as-published run), features
// scaled so that its Euclidean distance is eq. (4) (no normal term: OpenCV has none).
static void BM_OpenCvKmeans(benchmark::State& state) {
    OrganizedCloud cloud;
    back_project(bench::tabletop_frame(), cloud);
    std::vector<std::uint8_t> active;
    select_depth_range(DepthRange{}, cloud, active);
    const ClusterParams p = ClusterParams::paper();
    cv::Mat features(0, 6, CV_32F);
    features.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        if (!active[i]) continue;
        const float row[6] = {p.delta * cloud.x[i], p.delta * cloud.y[i], p.delta * cloud.z[i],
                              p.alpha * cloud.r[i], p.alpha * cloud.g[i], p.alpha * cloud.b[i]};
        features.push_back(cv::Mat(1, 6, CV_32F, const_cast<float*>(row)));
    }
    cv::Mat labels, centres;
    const int k = static_cast<int>(state.range(0));
    for (auto _ : state)
        benchmark::DoNotOptimize(cv::kmeans(features, k, labels,
                                            cv::TermCriteria(cv::TermCriteria::COUNT, 1, 0), 1,
                                            cv::KMEANS_PP_CENTERS, centres));
    state.counters["points"] = features.rows;
}
BENCHMARK(BM_OpenCvKmeans)->Arg(7)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_Pipeline(benchmark::State& state) {
    PipelineParams params;
    params.cluster.k = static_cast<int>(state.range(0));
    Pipeline pipeline(params);
    const RgbdFrame& f = bench::tabletop_frame();
    pipeline.process(f);
    for (auto _ : state) benchmark::DoNotOptimize(pipeline.process(f).stats.points);
}
BENCHMARK(BM_Pipeline)->Arg(7)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();
