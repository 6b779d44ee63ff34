// Reading the shipped tabletop frames from a ROS bag against reading them from their frame
// folders (docs/INPUTS.md, section 4): each iteration opens the input and reads every frame.
//   build/bench/ros/wul3d_bench_bag --benchmark_repetitions=9 --benchmark_report_aggregates_only
// The bags (both layouts) are written once, into a temporary folder, from the same frames.
// C++17, as every file that includes ROS 1 message headers (cmake/Ros.cmake).
#include <benchmark/benchmark.h>
#include <rosbag/bag.h>
#include <std_msgs/Float32.h>
#include <unistd.h>

#include <filesystem>

#include "ros_frames.hpp"
#include "wul3d/io.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kFolder = std::string(WUL3D_SAMPLE_DIR) + "/uois_tabletop";

std::vector<wul3d::RgbdFrame> read_all(const std::string& path) {
    auto source = wul3d::open_source(path, {});
    std::vector<wul3d::RgbdFrame> frames;
    wul3d::SourceItem item;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        frames.push_back(item.frame);
    }
    return frames;
}

struct Bags {
    fs::path dir, plain, realsense;
    Bags() {
        dir = fs::temp_directory_path() / ("wul3d_bag_bench_" + std::to_string(::getpid()));
        fs::create_directories(dir);
        plain = dir / "plain.bag";
        realsense = dir / "realsense.bag";
        const auto frames = read_all(kFolder);
        rosbag::Bag p(plain.string(), rosbag::bagmode::Write);
        rosbag::Bag r(realsense.string(), rosbag::bagmode::Write);
        const ros::Time t0(1700000000, 0);
        std_msgs::Float32 units;
        units.data = 0.001f;
        r.write("/device_0/sensor_0/option/Depth Units/value", t0, units);
        for (const char* info : {"/device_0/sensor_0/Depth_0/info/camera_info",
                                 "/device_0/sensor_1/Color_0/info/camera_info"})
            r.write(info, t0, wul3d::test::info_msg(frames[0].intrinsics, wul3d::test::ros_header(t0, "")));
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const ros::Time t = t0 + ros::Duration(0.1 * double(i));
            const auto h = wul3d::test::ros_header(t, "camera");
            p.write("/camera/color/image_raw", t, wul3d::test::color_msg(frames[i], h, "rgb8"));
            p.write("/camera/aligned_depth_to_color/image_raw", t, wul3d::test::depth_msg(frames[i], h));
            p.write("/camera/aligned_depth_to_color/camera_info", t, wul3d::test::info_msg(frames[i].intrinsics, h));
            r.write("/device_0/sensor_0/Depth_0/image/data", t, wul3d::test::depth_msg(frames[i], h, "mono16"));
            r.write("/device_0/sensor_1/Color_0/image/data", t, wul3d::test::color_msg(frames[i], h, "rgb8"));
        }
    }
    ~Bags() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

const Bags& bags() {
    static const Bags b;
    return b;
}

void read_input(benchmark::State& state, const std::string& path) {
    std::size_t frames = 0;
    for (auto _ : state) {
        auto source = wul3d::open_source(path, {});
        wul3d::SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) source->read(i, item);
        frames += source->size();
        benchmark::DoNotOptimize(item.frame.depth.data.data());
    }
    state.counters["frames/s"] = benchmark::Counter(double(frames), benchmark::Counter::kIsRate);
}

void BM_ReadFrameFolders(benchmark::State& state) { read_input(state, kFolder); }
void BM_ReadBagPlainTopics(benchmark::State& state) { read_input(state, bags().plain.string()); }
void BM_ReadBagRealSenseLayout(benchmark::State& state) { read_input(state, bags().realsense.string()); }

}  // namespace

BENCHMARK(BM_ReadFrameFolders)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadBagPlainTopics)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadBagRealSenseLayout)->Unit(benchmark::kMillisecond);
