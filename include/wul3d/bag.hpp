#pragma once
/// @file bag.hpp
/// ROS 1 bags as a FrameSource (docs/INPUTS.md, "4. ROS bags"). Built only where librosbag
/// is found (Debian: librosbag-dev); elsewhere open_bag says so with an InputError.
///
/// Two layouts are read with no options: plain topics (one depth image, 16UC1 / mono16 in
/// millimetres or 32FC1 in metres; one colour image, rgb8 / bgr8 / rgba8 / bgra8 / mono8
/// or a CompressedImage in JPEG or PNG; a CameraInfo beside one of them) and RealSense
/// Viewer recordings (/device_N/sensor_M/Depth_0/image/data, Color_0, their
/// info/camera_info and tf/0 topics, the depth unit in option/Depth Units/value).
/// SourceOptions::bag_topics ("COLOR,DEPTH[,INFO]") names the topics instead.
#include <memory>
#include <string>

#include "wul3d/io.hpp"

namespace wul3d {

/// Whether this build of wul3d reads bags.
bool bag_support();

/// Whether `path` is a regular file that begins with the ROS 1 bag magic "#ROSBAG V2.0".
bool is_bag_file(const std::string& path);

/// Opens a bag. Each depth message takes the colour message nearest to it in recorded
/// time, if within SourceOptions::bag_max_dt_s; depth messages without one are dropped.
/// Frames are named by the depth message's time ("1700000000.033333333"). Throws
/// InputError (one line naming the bag) for a file that is no bag or is truncated, a bag
/// with no depth image topic, a topic given that is not there, no CameraInfo and no
/// SourceOptions::intrinsics; and, when a frame is read, for an encoding not read or
/// an image whose size disagrees with its data, the CameraInfo or the other image.
std::unique_ptr<FrameSource> open_bag(const std::string& path, const SourceOptions& options);

}  // namespace wul3d
