// Peer for the normals stage: PCL's integral-image normal estimation on the same organized
// clouds as our estimate_normals, in the same iteration. Its own executable (wul3d_bench_pcl),
// built only when PCL is found (bench/CMakeLists.txt), and compiled without any -march or AVX
// flag: Debian's PCL is built for generic x86-64, and Eigen code inlined from PCL's headers with
// another alignment than the library's crashes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "bench_support.hpp"
#include "wul3d/normals.hpp"

using namespace wul3d;

namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

using PclCloud = pcl::PointCloud<pcl::PointXYZ>;
using PclNormals = pcl::PointCloud<pcl::Normal>;

// Our cloud as PCL's organized cloud: width x height, NaN where there is no point.
PclCloud::ConstPtr to_pcl(const OrganizedCloud& cloud) {
    PclCloud::Ptr out(new PclCloud(static_cast<std::uint32_t>(cloud.width),
                                   static_cast<std::uint32_t>(cloud.height)));
    out->is_dense = false;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        pcl::PointXYZ& p = (*out)[i];
        if (cloud.valid[i]) {
            p.x = cloud.x[i];
            p.y = cloud.y[i];
            p.z = cloud.z[i];
        } else {
            p.x = p.y = p.z = nan;
        }
    }
    return out;
}

using Estimator = pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal>;

// PCL's normals per frame: a new input cloud (PCL sizes its integral images there) and compute.
void pcl_normals(Estimator& ne, const PclCloud::ConstPtr& cloud, PclNormals& out) {
    ne.setInputCloud(cloud);
    ne.compute(out);
}

// How far apart the two peers' results are, once, outside the timing: points with a normal
// in each, and the median angle between the two where both have one.
void agreement(const NormalMap& ours, const PclNormals& theirs, benchmark::State& state) {
    std::size_t ours_valid = 0, theirs_valid = 0;
    std::vector<double> angles;
    for (std::size_t i = 0; i < ours.valid.size(); ++i) {
        const pcl::Normal& n = theirs[i];
        const bool t = std::isfinite(n.normal_x) && std::isfinite(n.normal_y) &&
                       std::isfinite(n.normal_z);
        ours_valid += ours.valid[i];
        theirs_valid += t;
        if (!ours.valid[i] || !t) continue;
        const double c =
            ours.nx[i] * n.normal_x + ours.ny[i] * n.normal_y + ours.nz[i] * n.normal_z;
        angles.push_back(std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / std::numbers::pi);
    }
    state.counters["ours_valid"] = static_cast<double>(ours_valid);
    state.counters["theirs_valid"] = static_cast<double>(theirs_valid);
    state.counters["median_deg"] = bench::median(std::move(angles));
}

}  // namespace

// Each iteration: our estimate_normals, then PCL's, on the same frame, alternating over the
// four tabletop frames; counters ours_ms, theirs_ms, ratio (bench_support.hpp). Our normals use
// the pipeline's default NormalParams (radius 2 px, depth jump 0.02 z); PCL's a smoothing size
// of 10 px and a max depth change factor of 0.02.
static void BM_NormalsVsPcl(benchmark::State& state, Estimator::NormalEstimationMethod method) {
    const std::vector<bench::StageInputs>& inputs = bench::tabletop_inputs();
    std::vector<PclCloud::ConstPtr> clouds;
    for (const bench::StageInputs& in : inputs) clouds.push_back(to_pcl(in.cloud));

    Estimator ne;
    ne.setNormalEstimationMethod(method);
    ne.setMaxDepthChangeFactor(0.02f);
    ne.setNormalSmoothingSize(10.0f);
    const NormalParams params;
    NormalMap ours;
    PclNormals theirs;
    estimate_normals(params, inputs[0].cloud, ours);
    pcl_normals(ne, clouds[0], theirs);
    agreement(ours, theirs, state);

    bench::PeerTimes times;
    std::size_t frame = 0;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        estimate_normals(params, inputs[frame].cloud, ours);
        benchmark::DoNotOptimize(ours.valid.data());
        const auto t1 = Clock::now();
        pcl_normals(ne, clouds[frame], theirs);
        benchmark::DoNotOptimize(theirs.data());
        const auto t2 = Clock::now();
        times.add(ms_between(t0, t1), ms_between(t1, t2));
        frame = (frame + 1) % inputs.size();
    }
    times.report(state);
}
BENCHMARK_CAPTURE(BM_NormalsVsPcl, average_3d_gradient, Estimator::AVERAGE_3D_GRADIENT)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_NormalsVsPcl, covariance_matrix, Estimator::COVARIANCE_MATRIX)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
