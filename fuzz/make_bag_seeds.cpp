// Seeds of fuzz_bag: small bags of both layouts the reader detects (docs/INPUTS.md, section
// 4), one 16x12 frame each.   make_bag_seeds OUT_DIR
// C++17, as every file that includes ROS 1 message headers (cmake/Ros.cmake).
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

sensor_msgs::Image image(const std::string& encoding, std::uint32_t bytes_per_pixel) {
    sensor_msgs::Image m;
    m.header.stamp = ros::Time(1700000000, 0);
    m.width = 16;
    m.height = 12;
    m.encoding = encoding;
    m.step = m.width * bytes_per_pixel;
    m.data.resize(std::size_t(m.step) * m.height);
    for (std::size_t i = 0; i < m.data.size(); ++i) m.data[i] = std::uint8_t(i * 7 + 3);
    return m;
}

sensor_msgs::CameraInfo info() {
    sensor_msgs::CameraInfo m;
    m.width = 16;
    m.height = 12;
    m.K = {20, 0, 8, 0, 20, 6, 0, 0, 1};
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_bag_seeds OUT_DIR\n");
        return 2;
    }
    const std::filesystem::path out = argv[1];
    std::filesystem::create_directories(out);
    const ros::Time t(1700000000, 0);
    {
        rosbag::Bag bag((out / "plain.bag").string(), rosbag::bagmode::Write);
        bag.write("/camera/color/image_raw", t, image("bgr8", 3));
        bag.write("/camera/depth/image_raw", t, image("16UC1", 2));
        bag.write("/camera/depth/camera_info", t, info());
    }
    {
        rosbag::Bag bag((out / "realsense.bag").string(), rosbag::bagmode::Write);
        bag.write("/device_0/sensor_0/Depth_0/info/camera_info", t, info());
        bag.write("/device_0/sensor_1/Color_0/info/camera_info", t, info());
        bag.write("/device_0/sensor_0/Depth_0/image/data", t, image("mono16", 2));
        bag.write("/device_0/sensor_1/Color_0/image/data", t, image("rgb8", 3));
    }
    return 0;
}
