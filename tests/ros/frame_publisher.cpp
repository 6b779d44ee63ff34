// wul3d_test_publisher: plays the frames of a folder to wul3d_ros on the RealSense driver's
// topics and listens to its labels (tests/ros/node_test.cpp; docs/ROS.md for the figures).
//
//   wul3d_test_publisher FOLDER OUT lockstep       each frame sent once its predecessor's
//                                                  labels came back; labels -> OUT/<i>.png
//   wul3d_test_publisher FOLDER OUT malformed      a wrong encoding, a size mismatch, then
//                                                  one good frame that must come back
//   wul3d_test_publisher FOLDER OUT stream FPS N   N frames at FPS, not waiting
//
// Prints "sent S received R latency_ms median M p95 P max X"; exit 0, or 1 on a timeout.
#include <ros/ros.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "ros_frames.hpp"
#include "wul3d/io.hpp"

namespace {

using wul3d::test::color_msg;
using wul3d::test::depth_msg;
using wul3d::test::info_msg;
using wul3d::test::ros_header;

struct Listener {
    std::mutex mutex;
    std::map<double, double> received;  // stamp -> wall time received
    std::map<double, sensor_msgs::ImageConstPtr> labels;

    void on_labels(const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        received[m->header.stamp.toSec()] = ros::WallTime::now().toSec();
        labels[m->header.stamp.toSec()] = m;
    }
    bool has(double stamp) {
        std::lock_guard<std::mutex> lock(mutex);
        return received.count(stamp) > 0;
    }
};

struct Publishers {
    ros::Publisher color, depth, info;

    void send(const wul3d::RgbdFrame& f, ros::Time stamp, unsigned seq) {
        const auto h = ros_header(stamp, "camera_color_optical_frame", seq);
        info.publish(info_msg(f.intrinsics, h));
        depth.publish(depth_msg(f, h));
        color.publish(color_msg(f, h, "rgb8"));
    }
};

bool wait_for(const std::function<bool()>& done, double seconds) {
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < until) {
        if (done()) return true;
        ros::WallDuration(0.002).sleep();
    }
    return done();
}

}  // namespace

int main(int argc, char** argv) {
    ros::init(argc, argv, "wul3d_test_publisher", ros::init_options::AnonymousName);
    if (argc < 4) {
        std::fprintf(stderr, "usage: %s FOLDER OUT lockstep|malformed|stream FPS N\n", argv[0]);
        return 2;
    }
    const std::string folder = argv[1], out = argv[2], mode = argv[3];
    std::vector<wul3d::RgbdFrame> frames;
    {
        auto source = wul3d::open_source(folder, {});
        wul3d::SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            frames.push_back(item.frame);
        }
    }

    ros::NodeHandle nh;
    Publishers pub{nh.advertise<sensor_msgs::Image>("/camera/color/image_raw", 4),
                   nh.advertise<sensor_msgs::Image>("/camera/aligned_depth_to_color/image_raw", 4),
                   nh.advertise<sensor_msgs::CameraInfo>("/camera/color/camera_info", 4)};
    Listener listener;
    ros::Subscriber sub = nh.subscribe("/wul3d/labels", 100, &Listener::on_labels, &listener);
    ros::AsyncSpinner spinner(1);
    spinner.start();

    const bool connected = wait_for([&] {
        return pub.color.getNumSubscribers() > 0 && pub.depth.getNumSubscribers() > 0 &&
               pub.info.getNumSubscribers() > 0 && sub.getNumPublishers() > 0;
    }, 60);
    if (!connected) {
        std::fprintf(stderr, "wul3d_test_publisher: wul3d_ros did not connect within 60 s\n");
        return 1;
    }
    ros::WallDuration(0.3).sleep();  // the connections' headers exchanged both ways

    std::vector<double> sent;  // stamps
    std::map<double, double> sent_at;
    const auto send = [&](const wul3d::RgbdFrame& f) {
        // Stamps from the wall clock, so a restarted publisher goes on forward in time.
        const ros::Time stamp = ros::Time::now();
        sent_at[stamp.toSec()] = ros::WallTime::now().toSec();
        pub.send(f, stamp, unsigned(sent.size()));
        sent.push_back(stamp.toSec());
        return stamp.toSec();
    };

    int rc = 0;
    if (mode == "lockstep") {
        for (std::size_t i = 0; i < frames.size() && rc == 0; ++i) {
            const double stamp = send(frames[i]);
            if (!wait_for([&] { return listener.has(stamp); }, 60)) {
                std::fprintf(stderr, "wul3d_test_publisher: no labels for frame %zu in 60 s\n", i);
                rc = 1;
                break;
            }
            const auto m = listener.labels[stamp];
            wul3d::LabelImage labels;
            labels.width = int(m->width);
            labels.height = int(m->height);
            labels.labels.resize(std::size_t(m->width) * m->height);
            std::memcpy(labels.labels.data(), m->data.data(),
                        std::min(m->data.size(), 2 * labels.labels.size()));
            wul3d::write_label_png(out + "/" + std::to_string(i) + ".png", labels);
        }
    } else if (mode == "malformed") {
        const ros::Time t = ros::Time::now();
        const auto h = ros_header(t, "camera_color_optical_frame");
        auto bad_color = color_msg(frames[0], h, "rgb8");
        bad_color.encoding = "yuv422";  // an encoding wul3d does not read
        pub.info.publish(info_msg(frames[0].intrinsics, h));
        pub.depth.publish(depth_msg(frames[0], h));
        pub.color.publish(bad_color);
        ros::WallDuration(0.5).sleep();
        const auto h2 = ros_header(t + ros::Duration(0.1), "camera_color_optical_frame");
        auto cut = depth_msg(frames[0], h2);
        cut.data.resize(cut.data.size() / 3);  // data shorter than its size says
        pub.info.publish(info_msg(frames[0].intrinsics, h2));
        pub.depth.publish(cut);
        pub.color.publish(color_msg(frames[0], h2, "rgb8"));
        ros::WallDuration(0.5).sleep();
        const double stamp = send(frames[0]);
        if (!wait_for([&] { return listener.has(stamp); }, 60)) {
            std::fprintf(stderr, "wul3d_test_publisher: no labels after the malformed frames\n");
            rc = 1;
        }
    } else if (mode == "stream" && argc >= 6) {
        const double fps = std::atof(argv[4]);
        const int n = std::atoi(argv[5]);
        ros::WallRate rate(fps);
        for (int i = 0; i < n && ros::ok(); ++i) {
            send(frames[std::size_t(i) % frames.size()]);
            rate.sleep();
        }
        const double last = sent.back();
        wait_for([&] { return listener.has(last); }, 5);
        ros::WallDuration(0.5).sleep();
    } else {
        std::fprintf(stderr, "wul3d_test_publisher: unknown mode '%s'\n", mode.c_str());
        return 2;
    }

    std::vector<double> latency_ms;
    std::size_t received = 0;
    {
        std::lock_guard<std::mutex> lock(listener.mutex);
        for (double s : sent) {
            const auto it = listener.received.find(s);
            if (it == listener.received.end()) continue;
            ++received;
            latency_ms.push_back((it->second - sent_at[s]) * 1e3);
        }
    }
    std::sort(latency_ms.begin(), latency_ms.end());
    const auto at = [&](double q) {
        return latency_ms.empty() ? 0.0 : latency_ms[std::size_t(q * double(latency_ms.size() - 1))];
    };
    std::printf("sent %zu received %zu latency_ms median %.1f p95 %.1f max %.1f\n", sent.size(),
                received, at(0.5), at(0.95), latency_ms.empty() ? 0.0 : latency_ms.back());
    spinner.stop();
    return rc;
}
