// Clustering (steps 6-7): one frame of Algorithm 1 with its phases, and OpenCV's cv::kmeans
// on the same features as a peer.
#include <benchmark/benchmark.h>

#include <chrono>

#include <omp.h>
#include <opencv2/core.hpp>

#include "bench_support.hpp"
#include "wul3d/clustering.hpp"

using namespace wul3d;

namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

ClusterParams params_with_k(int k) {
    ClusterParams p = bench::processed_tabletop().pipeline.params().cluster;
    p.k = k;
    return p;
}

// The active points as cv::kmeans features, scaled so that its Euclidean distance is eq. (4)
// (no normal term: OpenCV has none).
cv::Mat kmeans_features(const OrganizedCloud& cloud, const std::vector<std::uint8_t>& active,
                        const ClusterParams& p) {
    cv::Mat features(0, 6, CV_32F);
    features.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        if (!active[i]) continue;
        const float row[6] = {p.delta * cloud.x[i], p.delta * cloud.y[i], p.delta * cloud.z[i],
                              p.alpha * cloud.r[i], p.alpha * cloud.g[i], p.alpha * cloud.b[i]};
        features.push_back(cv::Mat(1, 6, CV_32F, const_cast<float*>(row)));
    }
    return features;
}

// cv::kmeans runs on OpenCV's thread pool (TBB on Debian): give it as many threads as OpenMP
// gives ours, so that OMP_NUM_THREADS=1 compares one core with one core.
int match_opencv_threads() {
    const int threads = omp_get_max_threads();
    cv::setNumThreads(threads);
    return threads;
}

// k-means++ seeding and one iteration, as a per-frame k-means without our state across frames
// (the paper-as-published run) would cost.
double opencv_kmeans(const cv::Mat& features, int k, cv::Mat& labels, cv::Mat& centres) {
    return cv::kmeans(features, k, labels, cv::TermCriteria(cv::TermCriteria::COUNT, 1, 0), 1,
                      cv::KMEANS_PP_CENTERS, centres);
}

}  // namespace

// One frame of Algorithm 1 (assign, weight update, centre move) after seeding; the counters
// are FrameStats::ms, each phase's milliseconds averaged over the iterations. frames:1 steps on
// the same frame every iteration (winners do not change: the weight update's cheapest case);
// frames:4 cycles through the four tabletop frames, four different scenes, so most pixels'
// winners change every frame (the weight update's dearest case).
static void BM_ClusterStep(benchmark::State& state) {
    const std::vector<bench::StageInputs>& inputs = bench::tabletop_inputs();
    const std::size_t frames = static_cast<std::size_t>(state.range(1));
    ClusterState cs(params_with_k(static_cast<int>(state.range(0))));
    LabelImage labels;
    FrameStats stats;
    for (std::size_t i = 0; i < frames; ++i)  // seeds on the first
        stats = cs.step(inputs[i].cloud, inputs[i].normals, inputs[i].active, labels);
    FrameStats::Phases sum;
    std::size_t frame = 0;
    for (auto _ : state) {
        const bench::StageInputs& in = inputs[frame];
        stats = cs.step(in.cloud, in.normals, in.active, labels);
        sum.seeding += stats.ms.seeding;
        sum.assign += stats.ms.assign;
        sum.weights += stats.ms.weights;
        sum.centres += stats.ms.centres;
        sum.labels += stats.ms.labels;
        frame = (frame + 1) % frames;
    }
    using benchmark::Counter;
    state.counters["seeding_ms"] = Counter(sum.seeding, Counter::kAvgIterations);
    state.counters["assign_ms"] = Counter(sum.assign, Counter::kAvgIterations);
    state.counters["weights_ms"] = Counter(sum.weights, Counter::kAvgIterations);
    state.counters["centres_ms"] = Counter(sum.centres, Counter::kAvgIterations);
    state.counters["labels_ms"] = Counter(sum.labels, Counter::kAvgIterations);
    state.counters["points"] = static_cast<double>(stats.points);
}
BENCHMARK(BM_ClusterStep)
    ->ArgNames({"k", "frames"})
    ->Args({7, 1})
    ->Args({10, 1})
    ->Args({7, 4})
    ->Args({10, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Peer alone: cv::kmeans on the features of the same frame (built outside the loop).
static void BM_OpenCvKmeans(benchmark::State& state) {
    const bench::ProcessedFrame& pf = bench::processed_tabletop();
    const int k = static_cast<int>(state.range(0));
    const cv::Mat features = kmeans_features(pf.pipeline.cloud(), pf.result.active,
                                             params_with_k(k));
    state.counters["threads"] = match_opencv_threads();
    cv::Mat labels, centres;
    for (auto _ : state) benchmark::DoNotOptimize(opencv_kmeans(features, k, labels, centres));
    state.counters["points"] = features.rows;
}
BENCHMARK(BM_OpenCvKmeans)->ArgName("k")->Arg(7)->Arg(10)->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Ours against cv::kmeans in the same iteration on the same frame, alternating over the four
// tabletop frames. Ours is ClusterState::step as the pipeline runs it, state across frames
// (seeded once, before the loop), gathering of the active points included; cv::kmeans seeds
// (k-means++) on every call and gets its features ready-made. The benchmark's own time is the
// sum of both; the counters are ours_ms, theirs_ms and ratio (bench_support.hpp).
static void BM_ClusterStepVsOpenCvKmeans(benchmark::State& state) {
    const std::vector<bench::StageInputs>& inputs = bench::tabletop_inputs();
    const int k = static_cast<int>(state.range(0));
    const ClusterParams p = params_with_k(k);
    std::vector<cv::Mat> features;
    for (const bench::StageInputs& in : inputs)
        features.push_back(kmeans_features(in.cloud, in.active, p));
    state.counters["threads"] = match_opencv_threads();
    ClusterState cs(p);
    LabelImage labels;
    for (const bench::StageInputs& in : inputs) cs.step(in.cloud, in.normals, in.active, labels);
    cv::Mat cv_labels, cv_centres;
    for (const cv::Mat& f : features) opencv_kmeans(f, k, cv_labels, cv_centres);

    bench::PeerTimes times;
    std::size_t frame = 0;
    for (auto _ : state) {
        const bench::StageInputs& in = inputs[frame];
        const auto t0 = Clock::now();
        benchmark::DoNotOptimize(cs.step(in.cloud, in.normals, in.active, labels));
        const auto t1 = Clock::now();
        benchmark::DoNotOptimize(opencv_kmeans(features[frame], k, cv_labels, cv_centres));
        const auto t2 = Clock::now();
        times.add(ms_between(t0, t1), ms_between(t1, t2));
        frame = (frame + 1) % inputs.size();
    }
    times.report(state);
}
BENCHMARK(BM_ClusterStepVsOpenCvKmeans)->ArgName("k")->Arg(7)->Arg(10)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
