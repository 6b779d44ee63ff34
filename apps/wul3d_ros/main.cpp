// wul3d_ros: the ROS 1 node (docs/ROS.md). ROS glue only over the library: colour, depth and
// camera_info in (message_filters, approximate time), the pipeline on a worker thread with a
// one-frame mailbox (newest wins), labels, overlay, boxes and objects.json out. C++17, as
// every file that includes ROS 1 message headers (cmake/Ros.cmake).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>

#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"
#include "wul3d/parameters.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/ros_image.hpp"
#include "wul3d/segmentation.hpp"
#include "wul3d/visualization.hpp"

namespace {

using sensor_msgs::CameraInfoConstPtr;
using sensor_msgs::ImageConstPtr;

/// A row's ROS parameter: its name, or for a switch its flag's ("--no-plane": no_plane).
std::string ros_name(const wul3d::ParamSpec& spec) {
    if (spec.kind != wul3d::ParamKind::Switch) return spec.name;
    std::string name = wul3d::flag_of(spec).substr(2);
    for (char& c : name)
        if (c == '-') c = '_';
    return name;
}

/// The command's parameters as private ROS parameters, one per row of the library's table
/// (parameters.hpp: ~k, ~alpha, ..., ~object_psi; the plane switch as ~no_plane, like
/// --no-plane), over the preset (~preset); checked by the library, as `wul3d run` checks its
/// flags, and a ParamError names the ROS parameter.
wul3d::PipelineParams pipeline_params(const ros::NodeHandle& pnh) {
    using wul3d::ParamKind;
    std::vector<std::pair<std::string, wul3d::ParamValue>> given;
    std::string preset;
    pnh.getParam("preset", preset);
    try {
        for (const wul3d::ParamSpec& spec : wul3d::pipeline_parameters()) {
            int i = 0;
            double d = 0;
            bool b = false;
            std::string text;
            switch (spec.kind) {
                case ParamKind::Int:
                    if (pnh.getParam(spec.name, i)) given.emplace_back(spec.name, std::int64_t{i});
                    break;
                case ParamKind::UInt64:  // XmlRpc has 32-bit ints only
                    if (pnh.getParam(spec.name, i)) {
                        if (i < 0)
                            throw wul3d::ParamError(spec.name, std::to_string(i), "must be >= 0");
                        given.emplace_back(spec.name, std::uint64_t(i));
                    }
                    break;
                case ParamKind::Float:
                    if (pnh.getParam(spec.name, d)) given.emplace_back(spec.name, d);
                    break;
                case ParamKind::Choice:
                    if (pnh.getParam(spec.name, text)) given.emplace_back(spec.name, text);
                    break;
                case ParamKind::Switch:  // ~no_plane: true turns the switch off, as its flag
                    if (pnh.getParam(ros_name(spec), b)) given.emplace_back(spec.name, wul3d::ParamValue{!b});
                    break;
            }
        }
        wul3d::PipelineParams params = wul3d::make_params(preset, given);
        params.render_colors = false;  // the node publishes no eq. 9 colours
        return params;
    } catch (const wul3d::ParamError& e) {
        if (e.parameter().empty()) throw;
        const wul3d::ParamSpec* spec = wul3d::find_parameter(e.parameter());
        const std::string name = spec ? ros_name(*spec) : e.parameter();
        throw wul3d::ParamError("~" + name + " " + e.value() + ": " + e.requirement());
    }
}

/// A distinct colour per track id, for the boxes.
std_msgs::ColorRGBA track_colour(int id) {
    std_msgs::ColorRGBA c;
    const float hue = std::fmod(float(id) * 0.618034f, 1.0f) * 6.0f;
    const float x = 1.0f - std::abs(std::fmod(hue, 2.0f) - 1.0f);
    const int sector = int(hue);
    c.r = (sector == 0 || sector == 5) ? 1.0f : (sector == 1 || sector == 4) ? x : 0.0f;
    c.g = (sector == 1 || sector == 2) ? 1.0f : (sector == 0 || sector == 3) ? x : 0.0f;
    c.b = (sector == 3 || sector == 4) ? 1.0f : (sector == 2 || sector == 5) ? x : 0.0f;
    c.a = 0.5f;
    return c;
}

/// The oriented box's rotation (rows: its unit axes) as a quaternion; a left-handed set of
/// axes gets its third axis flipped (a box is symmetric).
geometry_msgs::Quaternion box_orientation(const wul3d::DetectedObject& o) {
    // Columns of R are the box's axes in camera coordinates.
    double R[3][3];
    for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) R[r][a] = o.obb_axes[std::size_t(a * 3 + r)];
    const double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                       R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                       R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
    if (det < 0)
        for (auto& row : R) row[2] = -row[2];
    geometry_msgs::Quaternion q;
    const double tr = R[0][0] + R[1][1] + R[2][2];
    if (tr > 0) {
        const double s = std::sqrt(tr + 1.0) * 2;
        q.w = 0.25 * s;
        q.x = (R[2][1] - R[1][2]) / s;
        q.y = (R[0][2] - R[2][0]) / s;
        q.z = (R[1][0] - R[0][1]) / s;
    } else if (R[0][0] > R[1][1] && R[0][0] > R[2][2]) {
        const double s = std::sqrt(1.0 + R[0][0] - R[1][1] - R[2][2]) * 2;
        q.w = (R[2][1] - R[1][2]) / s;
        q.x = 0.25 * s;
        q.y = (R[0][1] + R[1][0]) / s;
        q.z = (R[0][2] + R[2][0]) / s;
    } else if (R[1][1] > R[2][2]) {
        const double s = std::sqrt(1.0 + R[1][1] - R[0][0] - R[2][2]) * 2;
        q.w = (R[0][2] - R[2][0]) / s;
        q.x = (R[0][1] + R[1][0]) / s;
        q.y = 0.25 * s;
        q.z = (R[1][2] + R[2][1]) / s;
    } else {
        const double s = std::sqrt(1.0 + R[2][2] - R[0][0] - R[1][1]) * 2;
        q.w = (R[1][0] - R[0][1]) / s;
        q.x = (R[0][2] + R[2][0]) / s;
        q.y = (R[1][2] + R[2][1]) / s;
        q.z = 0.25 * s;
    }
    return q;
}

visualization_msgs::MarkerArray box_markers(const wul3d::FrameResult& r, const std_msgs::Header& h) {
    visualization_msgs::MarkerArray out;
    visualization_msgs::Marker clear;
    clear.header = h;
    clear.action = visualization_msgs::Marker::DELETEALL;
    out.markers.push_back(clear);
    for (const wul3d::DetectedObject& o : r.object_list) {
        visualization_msgs::Marker box;
        box.header = h;
        box.ns = "wul3d_boxes";
        box.id = o.track_id;
        box.type = visualization_msgs::Marker::CUBE;
        box.action = visualization_msgs::Marker::ADD;
        box.pose.position.x = o.obb_centre[0];
        box.pose.position.y = o.obb_centre[1];
        box.pose.position.z = o.obb_centre[2];
        box.pose.orientation = box_orientation(o);
        box.scale.x = std::max(2.0 * o.obb_half_extent[0], 1e-3);
        box.scale.y = std::max(2.0 * o.obb_half_extent[1], 1e-3);
        box.scale.z = std::max(2.0 * o.obb_half_extent[2], 1e-3);
        box.color = track_colour(o.track_id);
        out.markers.push_back(box);
        visualization_msgs::Marker text = box;
        text.ns = "wul3d_track_ids";
        text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
        text.pose.orientation = geometry_msgs::Quaternion();
        text.pose.orientation.w = 1;
        text.scale.x = text.scale.y = 0;
        text.scale.z = 0.04;
        text.color.r = text.color.g = text.color.b = text.color.a = 1.0f;
        text.text = std::to_string(o.track_id);
        out.markers.push_back(text);
    }
    return out;
}

/// The node: synchronizer callbacks fill a one-frame mailbox; a worker runs the pipeline.
class Wul3dNode {
public:
    Wul3dNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, const wul3d::PipelineParams& params)
        : pipeline_(params),
          color_sub_(nh, "/camera/color/image_raw", 2),
          depth_sub_(nh, "/camera/aligned_depth_to_color/image_raw", 2),
          info_sub_(nh, "/camera/color/camera_info", 2),
          sync_(Policy(pnh.param("sync_queue", 5)), color_sub_, depth_sub_, info_sub_) {
        depth_scale_ = float(pnh.param("depth_scale", 0.001));
        if (!(depth_scale_ >= 1e-6f && depth_scale_ <= 1.0f))
            throw wul3d::ParamError("~depth_scale = " + std::to_string(depth_scale_) +
                                    ": not in [1e-6, 1] metres per unit");
        std::string calibration = pnh.param<std::string>("calibration", "");
        if (!calibration.empty()) {
            calib_ = calibration == "kinect_v2" ? wul3d::kinect_v2_default_calibration()
                                                : wul3d::read_calibration_json(calibration);
            registration_ = wul3d::parse_registration_mode(
                pnh.param<std::string>("registration", "depth-to-color"));
        }
        overlay_on_ = pnh.param("publish_overlay", true);
        sync_.registerCallback(&Wul3dNode::on_frame, this);
        labels_pub_ = pnh.advertise<sensor_msgs::Image>("labels", 2);
        overlay_pub_ = pnh.advertise<sensor_msgs::Image>("overlay", 2);
        markers_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("markers", 2);
        objects_pub_ = pnh.advertise<std_msgs::String>("objects", 2);
        diag_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 2);
        worker_ = std::thread(&Wul3dNode::work, this);
    }

    ~Wul3dNode() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
        }
        wake_.notify_one();
        worker_.join();
        // After ros::spin's end rosconsole may be gone: straight to stderr.
        std::fprintf(stderr, "wul3d: %zu frames processed, %zu dropped (newest wins), %zu malformed\n",
                     processed_.load(), dropped_.load(), malformed_.load());
    }

private:
    using Policy = message_filters::sync_policies::ApproximateTime<sensor_msgs::Image,
                                                                   sensor_msgs::Image,
                                                                   sensor_msgs::CameraInfo>;
    struct Job {
        ImageConstPtr color, depth;
        CameraInfoConstPtr info;
        ros::WallTime received;
    };

    void on_frame(const ImageConstPtr& color, const ImageConstPtr& depth,
                  const CameraInfoConstPtr& info) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (mailbox_) ++dropped_;  // the worker is behind: the newer frame replaces it
            mailbox_ = Job{color, depth, info, ros::WallTime::now()};
        }
        wake_.notify_one();
    }

    void work() {
        for (;;) {
            Job job;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [this] { return stopping_ || mailbox_.has_value(); });
                if (stopping_) return;
                job = std::move(*mailbox_);
                mailbox_.reset();
            }
            try {
                process(job);
            } catch (const wul3d::Error& e) {  // a malformed message: say so, go on
                ++malformed_;
                ROS_ERROR("wul3d: frame dropped: %s", e.what());
            }
            publish_diagnostics();
        }
    }

    void process(const Job& job) {
        const std::string what = "frame at " + std::to_string(job.depth->header.stamp.toSec());
        const wul3d::FrameResult* r = nullptr;
        const std_msgs::Header& header = job.depth->header;
        if (calib_) {
            raw_.name = what;
            wul3d::depth_from_ros(what + ": depth", wul3d::ros_image_of(*job.depth), depth_scale_, raw_.depth);
            wul3d::color_from_ros(what + ": colour", wul3d::ros_image_of(*job.color), raw_.color);
            r = &pipeline_.process(raw_, *calib_, registration_);
        } else {
            frame_.name = what;
            wul3d::depth_from_ros(what + ": depth", wul3d::ros_image_of(*job.depth), depth_scale_, frame_.depth);
            wul3d::color_from_ros(what + ": colour", wul3d::ros_image_of(*job.color), frame_.color);
            std::array<double, 9> K;
            std::copy(job.info->K.begin(), job.info->K.end(), K.begin());
            frame_.intrinsics = wul3d::intrinsics_from_ros(job.info->width, job.info->height, K);
            frame_.intrinsics.validate(what + ": camera_info");
            if (!frame_.intrinsics.same_size(frame_.depth.width, frame_.depth.height) ||
                frame_.color.width != frame_.depth.width || frame_.color.height != frame_.depth.height) {
                throw wul3d::InputError(
                    what + ": colour " + std::to_string(frame_.color.width) + "x" +
                    std::to_string(frame_.color.height) + ", depth " +
                    std::to_string(frame_.depth.width) + "x" + std::to_string(frame_.depth.height) +
                    " and camera_info " + std::to_string(frame_.intrinsics.width) + "x" +
                    std::to_string(frame_.intrinsics.height) +
                    " must be one size (registered; else set ~calibration)");
            }
            r = &pipeline_.process(frame_);
        }
        publish(*r, header, job);
    }

    void publish(const wul3d::FrameResult& r, const std_msgs::Header& header, const Job& job) {
        sensor_msgs::Image labels;
        labels.header = header;
        labels.width = std::uint32_t(r.objects.width);
        labels.height = std::uint32_t(r.objects.height);
        labels.encoding = "16UC1";
        labels.step = 2 * labels.width;
        labels.data.resize(2 * r.objects.labels.size());
        std::memcpy(labels.data.data(), r.objects.labels.data(), labels.data.size());
        labels_pub_.publish(labels);
        latency_ms_ = (ros::WallTime::now() - job.received).toSec() * 1e3;
        ++processed_;

        // Over the registered frame only; and only when objects were found at its size.
        if (overlay_on_ && overlay_pub_.getNumSubscribers() > 0 && !calib_ &&
            r.objects.labels.size() == frame_.depth.data.size()) {
            wul3d::render_frame_picture(frame_, base_);
            wul3d::render_object_overlay(base_, r.objects, r.object_list, frame_.intrinsics, overlay_);
            sensor_msgs::Image img;
            img.header = header;
            img.width = std::uint32_t(overlay_.width);
            img.height = std::uint32_t(overlay_.height);
            img.encoding = "rgb8";
            img.step = 3 * img.width;
            img.data = overlay_.rgb;
            overlay_pub_.publish(img);
        }
        markers_pub_.publish(box_markers(r, header));
        std_msgs::String json;
        json.data = wul3d::objects_json(r);
        objects_pub_.publish(json);
    }

    void publish_diagnostics() {
        const ros::WallTime now = ros::WallTime::now();
        if ((now - last_diag_).toSec() < 1.0) return;
        last_diag_ = now;
        diagnostic_msgs::DiagnosticArray arr;
        arr.header.stamp = ros::Time::now();
        diagnostic_msgs::DiagnosticStatus s;
        s.name = "wul3d: object segmentation";
        s.hardware_id = "wul3d";
        s.level = dropped_ > 0 ? diagnostic_msgs::DiagnosticStatus::WARN
                               : diagnostic_msgs::DiagnosticStatus::OK;
        s.message = dropped_ > 0 ? "dropping frames: processing is slower than the input"
                                 : "keeping up";
        const auto kv = [](const std::string& k, const std::string& v) {
            diagnostic_msgs::KeyValue x;
            x.key = k;
            x.value = v;
            return x;
        };
        s.values = {kv("frames processed", std::to_string(processed_.load())),
                    kv("frames dropped", std::to_string(dropped_.load())),
                    kv("frames malformed", std::to_string(malformed_.load())),
                    kv("last latency ms", std::to_string(latency_ms_.load()))};
        arr.status.push_back(s);
        diag_pub_.publish(arr);
        if (dropped_ > logged_drops_) {
            ROS_WARN("wul3d: %zu frames dropped so far (newest wins)", dropped_.load());
            logged_drops_ = dropped_;
        }
    }

    wul3d::Pipeline pipeline_;
    message_filters::Subscriber<sensor_msgs::Image> color_sub_, depth_sub_;
    message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
    message_filters::Synchronizer<Policy> sync_;
    ros::Publisher labels_pub_, overlay_pub_, markers_pub_, objects_pub_, diag_pub_;
    float depth_scale_ = 0.001f;
    std::optional<wul3d::StereoCalibration> calib_;
    wul3d::RegistrationMode registration_ = wul3d::RegistrationMode::DepthToColor;
    bool overlay_on_ = true;

    std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<Job> mailbox_;  // one frame: a newer one replaces it (a drop)
    bool stopping_ = false;
    std::thread worker_;

    // The worker's alone.
    wul3d::RgbdFrame frame_;
    wul3d::RawRgbdFrame raw_;
    wul3d::ColorImage base_, overlay_;
    ros::WallTime last_diag_;
    std::size_t logged_drops_ = 0;

    std::atomic<std::size_t> processed_{0}, dropped_{0}, malformed_{0};
    std::atomic<double> latency_ms_{0};
};

}  // namespace

int main(int argc, char** argv) {
    ros::init(argc, argv, "wul3d");
    ros::NodeHandle nh, pnh("~");
    try {
        Wul3dNode node(nh, pnh, pipeline_params(pnh));
        ros::spin();
    } catch (const wul3d::Error& e) {  // bad parameters or calibration: one line, exit 2
        ROS_FATAL("wul3d: %s", e.what());
        return 2;
    }
    return 0;
}
