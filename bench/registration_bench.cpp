// Registration (step 2): both directions, with the typical Kinect v2 calibration.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_support.hpp"
#include "wul3d/registration.hpp"

using namespace wul3d;

namespace {

// No Kinect v2 recording is shipped, so the raw frame is a real tabletop frame resampled to
// the Kinect v2 sizes: depth 640x480 -> 512x424 by nearest neighbour (no invented depths),
// colour 640x480 -> 1920x1080 by linear interpolation (OpenCV's cv::resize). The aspect ratios
// differ, so the geometry is stretched; the work per pixel, which is what is timed, is that of
// a real frame of these sizes.
const RawRgbdFrame& kinect_v2_sized_frame() {
    static const RawRgbdFrame raw = [] {
        const RgbdFrame& f = bench::tabletop_frame();
        const StereoCalibration calib = kinect_v2_default_calibration();
        RawRgbdFrame r;
        r.name = f.name;

        cv::Mat depth(f.depth.height, f.depth.width, CV_16UC1,
                      const_cast<std::uint16_t*>(f.depth.data.data()));
        r.depth.width = calib.depth.width;
        r.depth.height = calib.depth.height;
        r.depth.scale_m_per_unit = f.depth.scale_m_per_unit;
        r.depth.data.resize(static_cast<std::size_t>(r.depth.width) * r.depth.height);
        cv::Mat depth_out(r.depth.height, r.depth.width, CV_16UC1, r.depth.data.data());
        cv::resize(depth, depth_out, depth_out.size(), 0, 0, cv::INTER_NEAREST);

        cv::Mat color(f.color.height, f.color.width, CV_8UC3,
                      const_cast<std::uint8_t*>(f.color.rgb.data()));
        r.color.width = calib.color.width;
        r.color.height = calib.color.height;
        r.color.rgb.resize(3 * static_cast<std::size_t>(r.color.width) * r.color.height);
        cv::Mat color_out(r.color.height, r.color.width, CV_8UC3, r.color.rgb.data());
        cv::resize(color, color_out, color_out.size(), 0, 0, cv::INTER_LINEAR);
        return r;
    }();
    return raw;
}

std::size_t valid_depth(const RgbdFrame& f) {
    std::size_t n = 0;
    for (const std::uint16_t d : f.depth.data) n += d != 0;
    return n;
}

}  // namespace

static void BM_RegisterDepthToColor(benchmark::State& state) {
    const StereoCalibration calib = kinect_v2_default_calibration();
    const RawRgbdFrame& raw = kinect_v2_sized_frame();
    RegistrationWorkspace ws;
    RgbdFrame out;
    register_depth_to_color(calib, raw, ws, out);  // sizes the workspace and the output
    for (auto _ : state) {
        register_depth_to_color(calib, raw, ws, out);
        benchmark::DoNotOptimize(out.depth.data.data());
    }
    state.counters["valid_px"] = static_cast<double>(valid_depth(out));
}
BENCHMARK(BM_RegisterDepthToColor)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_RegisterColorToDepth(benchmark::State& state) {
    const StereoCalibration calib = kinect_v2_default_calibration();
    const RawRgbdFrame& raw = kinect_v2_sized_frame();
    RegistrationWorkspace ws;
    RgbdFrame out;
    register_color_to_depth(calib, raw, ws, out);
    for (auto _ : state) {
        register_color_to_depth(calib, raw, ws, out);
        benchmark::DoNotOptimize(out.depth.data.data());
    }
    state.counters["valid_px"] = static_cast<double>(valid_depth(out));
}
BENCHMARK(BM_RegisterColorToDepth)->Unit(benchmark::kMillisecond)->UseRealTime();
