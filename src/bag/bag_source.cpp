// ROS 1 bags as a FrameSource (wul3d/bag.hpp, docs/INPUTS.md "4. ROS bags"), thin over
// librosbag. Compiled as C++17 (cmake/Ros.cmake): ROS 1's generated message headers use
// std::allocator<void>::rebind, which C++20 removed.
#include <console_bridge/console.h>
#include <geometry_msgs/Transform.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float32.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>

#include "io/io_detail.hpp"
#include "wul3d/bag.hpp"
#include "wul3d/error.hpp"
#include "wul3d/ros_image.hpp"

namespace wul3d {

namespace {

using detail::size_str;

constexpr const char* kImage = "sensor_msgs/Image";
constexpr const char* kCompressed = "sensor_msgs/CompressedImage";
constexpr const char* kInfo = "sensor_msgs/CameraInfo";

std::string parent_of(const std::string& topic) {
    const auto slash = topic.rfind('/');
    return slash == std::string::npos || slash == 0 ? std::string() : topic.substr(0, slash);
}

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

/// "1700000000.033333333": the recorded time, exactly.
std::string stamp_name(const ros::Time& t) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%u.%09u", t.sec, t.nsec);
    return buf;
}

/// Which topics hold what, decided once when the bag is opened.
struct Layout {
    std::string color, depth, info;  // color empty: depth-only; info empty: intrinsics given
    bool realsense = false;
    std::string color_info;            // RealSense: the colour stream's camera_info
    std::string depth_tf, color_tf;    // RealSense: each stream's tf/0
    std::string depth_units;           // RealSense: option/Depth Units/value
};

/// Everything librosbag tells of one bag: its topics and their types, and a reader of the
/// first message of a topic.
class Bag {
public:
    Bag(const std::string& path) : path_(path) {
        try {
            bag_.open(path, rosbag::bagmode::Read);
            rosbag::View all(bag_);
            for (const rosbag::ConnectionInfo* c : all.getConnections())
                types_[c->topic] = c->datatype;
        } catch (const std::exception& e) {
            throw InputError(path + ": cannot read the bag (" + e.what() + ")");
        }
    }

    const std::string& path() const { return path_; }
    rosbag::Bag& bag() { return bag_; }
    std::string type(const std::string& topic) const {
        const auto it = types_.find(topic);
        return it == types_.end() ? std::string() : it->second;
    }
    std::vector<std::string> topics_of(const char* type) const {
        std::vector<std::string> out;
        for (const auto& [topic, t] : types_)
            if (t == type) out.push_back(topic);
        return out;
    }
    const std::map<std::string, std::string>& types() const { return types_; }

    /// The first message of `topic`, or nullptr if it has none.
    template <class Msg>
    boost::shared_ptr<Msg> first(const std::string& topic) {
        try {
            rosbag::View view(bag_, rosbag::TopicQuery(topic));
            for (const rosbag::MessageInstance& m : view) return m.instantiate<Msg>();
        } catch (const std::exception& e) {
            throw InputError(path_ + ": " + topic + ": cannot read (" + e.what() + ")");
        }
        return nullptr;
    }

private:
    std::string path_;
    rosbag::Bag bag_;
    std::map<std::string, std::string> types_;
};

void require_type(Bag& bag, const std::string& topic, std::initializer_list<const char*> types) {
    const std::string t = bag.type(topic);
    if (t.empty()) throw InputError(bag.path() + ": no topic " + topic + " in the bag");
    for (const char* want : types)
        if (t == want) return;
    throw InputError(bag.path() + ": " + topic + " is " + t + ", expected " + *types.begin() +
                     (types.size() > 1 ? " or " + std::string(*(types.begin() + 1)) : ""));
}

/// The CameraInfo beside the depth topic, else beside the colour topic, else the only one.
std::string find_info(Bag& bag, const std::string& depth, const std::string& color) {
    for (const std::string& near : {parent_of(depth), parent_of(color)}) {
        if (!near.empty() && bag.type(near + "/camera_info") == kInfo) return near + "/camera_info";
    }
    const std::vector<std::string> infos = bag.topics_of(kInfo);
    if (infos.size() == 1) return infos.front();
    return {};
}

/// Plain topics: the depth and colour images told apart by their encodings.
Layout detect_plain(Bag& bag) {
    std::vector<std::string> depth, color;
    for (const std::string& t : bag.topics_of(kImage)) {
        const auto img = bag.first<sensor_msgs::Image>(t);
        if (!img) continue;
        if (is_ros_depth_encoding(img->encoding)) depth.push_back(t);
        else if (is_ros_color_encoding(img->encoding)) color.push_back(t);
    }
    for (const std::string& t : bag.topics_of(kCompressed)) {
        const auto img = bag.first<sensor_msgs::CompressedImage>(t);
        if (!img || img->format.find("compressedDepth") != std::string::npos) continue;
        // image_transport's ".../compressed" of an image topic that is there too: the raw one.
        const std::string raw = parent_of(t);
        if (std::find(color.begin(), color.end(), raw) == color.end()) color.push_back(t);
    }
    if (depth.empty()) {
        throw InputError(bag.path() + ": no depth image topic (sensor_msgs/Image in 16UC1, mono16 "
                                      "or 32FC1) in the bag; name one with --topics COLOR,DEPTH");
    }
    if (depth.size() > 1) {  // a RealSense driver's bag: prefer the depth aligned to colour
        std::vector<std::string> aligned;
        for (const std::string& t : depth)
            if (t.find("aligned_depth_to_color") != std::string::npos) aligned.push_back(t);
        if (aligned.size() != 1) {
            throw InputError(bag.path() + ": several depth image topics (" + join(depth) +
                             "); pick one with --topics COLOR,DEPTH");
        }
        depth = aligned;
    }
    if (color.size() > 1) {
        throw InputError(bag.path() + ": several colour image topics (" + join(color) +
                         "); pick one with --topics COLOR,DEPTH");
    }
    Layout l;
    l.depth = depth.front();
    if (!color.empty()) l.color = color.front();
    l.info = find_info(bag, l.depth, l.color);
    return l;
}

/// Whether `topic` is "/device_N/sensor_M/<Kind>_K/image/data" with Kind Depth or Color;
/// then `sensor` is "/device_N/sensor_M". (No std::regex: GCC 12 warns inside it under ASan.)
bool realsense_stream(const std::string& topic, std::string& sensor, std::string& kind) {
    std::vector<std::string> parts;
    std::stringstream in(topic);
    for (std::string p; std::getline(in, p, '/');) parts.push_back(p);
    const auto numbered = [](const std::string& s, const std::string& prefix) {
        return s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0 &&
               s.find_first_not_of("0123456789", prefix.size()) == std::string::npos;
    };
    if (parts.size() != 6 || !parts[0].empty() || !numbered(parts[1], "device_") ||
        !numbered(parts[2], "sensor_") || parts[4] != "image" || parts[5] != "data")
        return false;
    if (numbered(parts[3], "Depth_")) kind = "Depth";
    else if (numbered(parts[3], "Color_")) kind = "Color";
    else return false;
    sensor = "/" + parts[1] + "/" + parts[2];
    return true;
}

/// RealSense Viewer's layout: /device_N/sensor_M/<Stream>_K/image/data and its siblings.
std::optional<Layout> detect_realsense(Bag& bag) {
    Layout l;
    std::string depth_sensor;
    for (const auto& [topic, type] : bag.types()) {
        std::string sensor, kind;
        if (type != kImage || !realsense_stream(topic, sensor, kind)) continue;
        std::string& slot = kind == "Depth" ? l.depth : l.color;
        if (!slot.empty()) continue;  // the first stream of each kind (topics sorted by name)
        slot = topic;
        if (kind == "Depth") depth_sensor = sensor;
    }
    if (l.depth.empty()) return std::nullopt;
    l.realsense = true;
    const auto stream_of = [](const std::string& data) {  // ".../Depth_0/image/data"
        return parent_of(parent_of(data));
    };
    l.info = stream_of(l.depth) + "/info/camera_info";
    l.depth_tf = stream_of(l.depth) + "/tf/0";
    l.depth_units = depth_sensor + "/option/Depth Units/value";
    if (!l.color.empty()) {
        l.color_info = stream_of(l.color) + "/info/camera_info";
        l.color_tf = stream_of(l.color) + "/tf/0";
    }
    return l;
}

/// --topics COLOR,DEPTH[,INFO]; COLOR may be empty (depth only).
Layout given_layout(Bag& bag, const std::string& spec) {
    std::vector<std::string> parts;
    std::stringstream in(spec);
    for (std::string p; std::getline(in, p, ',');) parts.push_back(p);
    if (!spec.empty() && spec.back() == ',') parts.push_back("");
    if (parts.size() < 2 || parts.size() > 3 || parts[1].empty()) {
        throw ParamError("--topics '" + spec + "': expected COLOR,DEPTH or COLOR,DEPTH,INFO");
    }
    Layout l;
    l.color = parts[0];
    l.depth = parts[1];
    if (!l.color.empty()) require_type(bag, l.color, {kImage, kCompressed});
    require_type(bag, l.depth, {kImage});
    if (parts.size() == 3 && !parts[2].empty()) {
        l.info = parts[2];
        require_type(bag, l.info, {kInfo});
    } else {
        l.info = find_info(bag, l.depth, l.color);
    }
    return l;
}

PinholeIntrinsics intrinsics_of(const sensor_msgs::CameraInfo& info) {
    std::array<double, 9> K;
    std::copy(info.K.begin(), info.K.end(), K.begin());
    return intrinsics_from_ros(info.width, info.height, K);
}

/// A stream's pose in the device's frame: P_device = R P_stream + t.
struct Pose {
    std::array<double, 9> R{1, 0, 0, 0, 1, 0, 0, 0, 1};
    std::array<double, 3> t{0, 0, 0};
};

Pose pose_of(const geometry_msgs::Transform& tf) {
    const double w = tf.rotation.w, x = tf.rotation.x, y = tf.rotation.y, z = tf.rotation.z;
    Pose p;
    p.R = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
           2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
           2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    p.t = {tf.translation.x, tf.translation.y, tf.translation.z};
    return p;
}

/// depth -> colour = colour^-1 * depth: R = Rc^T Rd, t = Rc^T (td - tc).
void depth_to_color(const Pose& d, const Pose& c, StereoCalibration& calib) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            double s = 0;
            for (int k = 0; k < 3; ++k) s += c.R[k * 3 + i] * d.R[k * 3 + j];
            calib.rotation[i * 3 + j] = s;
        }
        double s = 0;
        for (int k = 0; k < 3; ++k) s += c.R[k * 3 + i] * (d.t[k] - c.t[k]);
        calib.translation_m[i] = s;
    }
}

bool same_camera(const StereoCalibration& c) {
    const std::array<double, 9> I{1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int i = 0; i < 9; ++i)
        if (std::abs(c.rotation[i] - I[i]) > 1e-9) return false;
    for (double t : c.translation_m)
        if (std::abs(t) > 1e-9) return false;
    const PinholeIntrinsics &a = c.depth, &b = c.color;
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
           a.cx == b.cx && a.cy == b.cy;
}

/// Every message of `topic`, in recorded order.
std::vector<rosbag::MessageInstance> messages_of(Bag& bag, const std::string& topic) {
    std::vector<rosbag::MessageInstance> out;
    try {
        rosbag::View view(bag.bag(), rosbag::TopicQuery(topic));
        for (const rosbag::MessageInstance& m : view) out.push_back(m);
    } catch (const std::exception& e) {
        throw InputError(bag.path() + ": " + topic + ": cannot read (" + e.what() + ")");
    }
    return out;
}

struct Pair {
    std::size_t depth = 0;
    std::optional<std::size_t> color;
    std::string name;
};

/// Each depth message takes the colour message nearest in recorded time, if within max_dt_s.
std::vector<Pair> pair_by_time(const std::vector<rosbag::MessageInstance>& depth,
                               const std::vector<rosbag::MessageInstance>& color, bool has_color,
                               double max_dt_s) {
    std::vector<double> tc(color.size());
    for (std::size_t i = 0; i < color.size(); ++i) tc[i] = color[i].getTime().toSec();
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < depth.size(); ++i) {
        Pair p;
        p.depth = i;
        p.name = stamp_name(depth[i].getTime());
        if (has_color) {
            const double t = depth[i].getTime().toSec();
            const auto it = std::lower_bound(tc.begin(), tc.end(), t);
            std::optional<std::size_t> best;
            if (it != tc.end()) best = static_cast<std::size_t>(it - tc.begin());
            if (it != tc.begin() && (!best || t - *(it - 1) <= tc[*best] - t))
                best = static_cast<std::size_t>(it - tc.begin() - 1);
            if (!best || std::abs(tc[*best] - t) > max_dt_s) continue;
            p.color = best;
        }
        // Two depth messages of one recorded time: the names of OUT/<name>/ stay distinct.
        if (!pairs.empty() && pairs.back().name.rfind(p.name, 0) == 0)
            p.name += "_" + std::to_string(i);
        pairs.push_back(std::move(p));
    }
    return pairs;
}

class BagSource final : public FrameSource {
public:
    BagSource(const std::string& path, const SourceOptions& options)
        : bag_(std::make_unique<Bag>(path)), path_(path) {
        Bag& bag = *bag_;
        std::optional<Layout> found;
        if (!options.bag_topics.empty()) found = given_layout(bag, options.bag_topics);
        if (!found) found = detect_realsense(bag);
        if (!found) found = detect_plain(bag);
        layout_ = *found;

        // Intrinsics: the CameraInfo, or the ones given (which then replace it).
        if (options.intrinsics) {
            if (layout_.realsense && !layout_.color.empty())
                throw ParamError("intrinsics cannot be given for a RealSense recording: its "
                                 "camera_info topics hold both cameras");
            K_ = *options.intrinsics;
            intrinsics_from_ = "the given intrinsics";
        } else {
            if (layout_.info.empty()) {
                throw InputError(path + ": no sensor_msgs/CameraInfo beside " + layout_.depth +
                                 "; name it with --topics COLOR,DEPTH,INFO or give --intrinsics");
            }
            const auto info = bag.first<sensor_msgs::CameraInfo>(layout_.info);
            if (!info) throw InputError(path + ": " + layout_.info + " holds no message");
            K_ = intrinsics_of(*info);
            K_.validate(path + ": " + layout_.info);
            intrinsics_from_ = layout_.info;
        }

        if (layout_.realsense) {
            if (const auto units = bag.first<std_msgs::Float32>(layout_.depth_units)) {
                depth_scale_ = units->data;
                if (!(depth_scale_ >= 1e-6f && depth_scale_ <= 1.0f)) {
                    throw InputError(path + ": " + layout_.depth_units + " = " +
                                     std::to_string(depth_scale_) + ": not in [1e-6, 1] m");
                }
            }
            if (!layout_.color.empty()) open_realsense_colour(bag);
        }

        depth_msgs_ = messages_of(bag, layout_.depth);
        if (!layout_.color.empty()) color_msgs_ = messages_of(bag, layout_.color);
        if (depth_msgs_.empty()) throw InputError(path + ": " + layout_.depth + " holds no message");
        pairs_ = pair_by_time(depth_msgs_, color_msgs_, !layout_.color.empty(),
                              options.bag_max_dt_s);
        if (pairs_.empty()) {
            std::ostringstream msg;
            msg << path << ": no frames found (no message of " << layout_.depth
                << " has one of " << layout_.color << " within " << options.bag_max_dt_s
                << " s)";
            throw InputError(msg.str());
        }
    }

    std::size_t size() const override { return pairs_.size(); }
    std::string name(std::size_t i) const override { return pairs_.at(i).name; }
    InputFormat format() const override { return InputFormat::Bag; }
    const StereoCalibration* calibration() const override { return raw_ ? &calib_ : nullptr; }

    void read(std::size_t i, SourceItem& item) override {
        const Pair& pair = pairs_.at(i);
        const std::string at = path_ + ": " + layout_.depth + " at " + pair.name;
        try {
            item.is_raw = raw_;
            DepthImage& depth = raw_ ? item.raw.depth : item.frame.depth;
            ColorImage& color = raw_ ? item.raw.color : item.frame.color;
            (raw_ ? item.raw.name : item.frame.name) = pair.name;

            const auto d = depth_msgs_[pair.depth].instantiate<sensor_msgs::Image>();
            if (!d) throw InputError(at + ": not a sensor_msgs/Image");
            depth_from_ros(at, ros_image_of(*d), depth_scale_, depth);
            if (pair.color) {
                read_color(color_msgs_[*pair.color], color);
            } else {
                color.width = color.height = 0;
                color.rgb.clear();
            }
            if (raw_) {
                check_size(at, "the depth camera_info", calib_.depth, depth.width, depth.height);
                if (!color.empty()) {
                    check_size(path_ + ": " + layout_.color, "the colour camera_info",
                               calib_.color, color.width, color.height);
                }
                return;
            }
            RgbdFrame& f = item.frame;
            f.intrinsics = K_;
            if (!K_.sized()) {  // given without a size: the frame's own
                f.intrinsics.width = depth.width;
                f.intrinsics.height = depth.height;
                f.intrinsics.validate(at + ": the given intrinsics");
            }
            check_size(at, intrinsics_from_, f.intrinsics, depth.width, depth.height);
            if (!color.empty() && (color.width != depth.width || color.height != depth.height)) {
                throw InputError(at + ": depth is " + size_str(depth.width, depth.height) +
                                 " but colour (" + layout_.color + ") is " +
                                 size_str(color.width, color.height) +
                                 "; registered topics must be the same size");
            }
        } catch (const rosbag::BagException& e) {
            throw InputError(at + ": cannot read the bag (" + e.what() + ")");
        } catch (const ros::Exception& e) {
            throw InputError(at + ": cannot read the message (" + e.what() + ")");
        }
    }

private:
    /// The colour stream's camera and pose: registered frames if they equal the depth
    /// stream's (a recording aligned already), raw frames with their calibration if not.
    void open_realsense_colour(Bag& bag) {
        calib_.depth = K_;
        calib_.depth_scale_m_per_unit = depth_scale_;
        const auto info = bag.first<sensor_msgs::CameraInfo>(layout_.color_info);
        if (!info) {
            throw InputError(path_ + ": no " + layout_.color_info +
                             " (the colour camera of a RealSense recording)");
        }
        calib_.color = intrinsics_of(*info);
        calib_.color.validate(path_ + ": " + layout_.color_info);
        Pose dp, cp;
        if (const auto tf = bag.first<geometry_msgs::Transform>(layout_.depth_tf)) dp = pose_of(*tf);
        if (const auto tf = bag.first<geometry_msgs::Transform>(layout_.color_tf)) cp = pose_of(*tf);
        depth_to_color(dp, cp, calib_);
        calib_.validate();
        raw_ = !same_camera(calib_);
    }

    void read_color(const rosbag::MessageInstance& m, ColorImage& out) {
        const std::string at = path_ + ": " + layout_.color + " at " + stamp_name(m.getTime());
        if (m.getDataType() == kCompressed) {
            const auto c = m.instantiate<sensor_msgs::CompressedImage>();
            if (!c) throw InputError(at + ": not a sensor_msgs/CompressedImage");
            scratch_.bytes.assign(c->data.begin(), c->data.end());
            detail::decode_color_image_into(at, scratch_, out);
            return;
        }
        const auto img = m.instantiate<sensor_msgs::Image>();
        if (!img) throw InputError(at + ": not a sensor_msgs/Image");
        color_from_ros(at, ros_image_of(*img), out);
    }

    static void check_size(const std::string& at, const std::string& from,
                           const PinholeIntrinsics& K, int w, int h) {
        if (!K.same_size(w, h)) {
            throw InputError(at + ": image is " + size_str(w, h) + " but " + from + " says " +
                             size_str(K.width, K.height));
        }
    }

    std::unique_ptr<Bag> bag_;  // MessageInstances point into it: never moved
    std::string path_;
    Layout layout_;
    PinholeIntrinsics K_;
    std::string intrinsics_from_;
    float depth_scale_ = 0.001f;  // 16UC1 is millimetres (REP 118) unless the bag says
    bool raw_ = false;
    StereoCalibration calib_;
    std::vector<rosbag::MessageInstance> depth_msgs_, color_msgs_;
    std::vector<Pair> pairs_;
    detail::ImageScratch scratch_;
};

/// The largest chunk a bag may declare, uncompressed: librosbag allocates that much before
/// decompressing. rosbag record writes chunks of 768 KiB (more only for one larger message).
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{256} << 20;
/// The largest record header: a connection's (its message definition) is a few KiB.
constexpr std::uint32_t kMaxRecordHeaderBytes = 1u << 20;

std::uint32_t le32(const char* p) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
    return v;
}

std::uint64_t le64(const char* p) {
    return le32(p) | (std::uint64_t{le32(p + 4)} << 32);
}

/// librosbag trusts the lengths and positions a bag declares (a record header of 2 GB is
/// allocated before it is read), so the top-level records are walked first: [u32 header
/// length][header: u32 length + "name=value" fields][u32 data length][data], each within the
/// file; a chunk's declared size ("size") at most kMaxChunkBytes; and the positions the bag
/// header ("index_pos") and the chunk infos ("chunk_pos") point to must be records' starts.
/// Only headers are read; data is skipped.
void check_records(const std::string& path) {
    std::error_code ec;
    const std::uint64_t file_size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path + ": cannot read the bag (" + ec.message() + ")");
    std::ifstream in(path, std::ios::binary);
    const auto damaged = [&](std::uint64_t at, const std::string& what) {
        return InputError(path + ": cannot read the bag (the record at byte " + std::to_string(at) +
                          " " + what + "; truncated or damaged)");
    };
    /// One record's lengths and the header fields that matter here, checked to end by `end`.
    struct Record {
        std::uint32_t header_len = 0, data_len = 0;
        char op = 0;
        std::optional<std::uint32_t> size;  // a chunk's uncompressed size
        std::string compression;            // a chunk's
        std::vector<std::uint64_t> points_to;  // index_pos, chunk_pos
    };
    std::vector<char> header, connection;
    // The fields must tile a header exactly, each "name=value": cpp_common's
    // ros::Header::parse reads past a header whose fields do not (fuzz_bag found it, in a
    // record's header and in a connection's). visit(field) sees each.
    const auto check_fields = [&](std::uint64_t pos, const std::vector<char>& h, auto&& visit) {
        for (std::size_t f = 0; f < h.size();) {
            const std::uint32_t n = h.size() - f >= 4 ? le32(h.data() + f) : 0;
            if (h.size() - f < 4 || n > h.size() - f - 4)
                throw damaged(pos, "has a header field running past its header");
            const std::string field(h.data() + f + 4, n);
            if (field.find('=') == std::string::npos) throw damaged(pos, "has a header field with no '='");
            visit(field);
            f += 4 + std::size_t(n);
        }
    };
    const auto read_record = [&](std::uint64_t pos, std::uint64_t end) {
        Record r;
        char len[4];
        if (end - pos < 4 || !in.seekg(std::streamoff(pos)).read(len, 4))
            throw damaged(pos, "is cut short");
        r.header_len = le32(len);
        if (r.header_len > kMaxRecordHeaderBytes || end - pos - 4 < std::uint64_t{r.header_len} + 4)
            throw damaged(pos, "declares a header of " + std::to_string(r.header_len) + " bytes");
        header.resize(r.header_len);
        in.read(header.data(), r.header_len);
        in.read(len, 4);
        if (!in) throw damaged(pos, "is cut short");
        r.data_len = le32(len);
        if (end - pos - 8 - r.header_len < r.data_len)
            throw damaged(pos, "declares " + std::to_string(r.data_len) + " bytes of data");
        check_fields(pos, header, [&](const std::string& field) {
            if (field.size() == 4 && field.compare(0, 3, "op=") == 0) r.op = field[3];
            if (field.size() == 9 && field.compare(0, 5, "size=") == 0) r.size = le32(field.data() + 5);
            if (field.compare(0, 12, "compression=") == 0) r.compression = field.substr(12);
            if (field.size() == 18 && (field.compare(0, 10, "index_pos=") == 0 ||
                                       field.compare(0, 10, "chunk_pos=") == 0)) {
                const std::uint64_t to = le64(field.data() + 10);
                if (to != 0) r.points_to.push_back(to);  // index_pos 0: an unindexed bag
            }
        });
        // A connection's data is a header of its own (topic, type, md5sum, definition): its
        // fields, the data length their header length, parsed by librosbag alike.
        if (r.op == 0x07) {
            if (r.data_len > kMaxRecordHeaderBytes)
                throw damaged(pos, "is a connection of " + std::to_string(r.data_len) + " bytes");
            connection.resize(r.data_len);
            in.read(connection.data(), r.data_len);
            if (!in) throw damaged(pos, "is cut short");
            check_fields(pos, connection, [](const std::string&) {});
        }
        return r;
    };

    std::vector<std::uint64_t> starts, targets;  // records' starts; positions pointed to
    std::vector<std::uint64_t> inner;            // the last plain chunk's records, from its data
    bool inner_known = false;
    for (std::uint64_t pos = 13; pos < file_size;) {  // after "#ROSBAG V2.0\n"
        const Record r = read_record(pos, file_size);
        targets.insert(targets.end(), r.points_to.begin(), r.points_to.end());
        const std::uint64_t data = pos + 8 + r.header_len, next = data + r.data_len;
        if (r.op == 0x05) {  // a chunk: its size; and, stored plainly, the records inside
            if (r.size && *r.size > kMaxChunkBytes)
                throw damaged(pos, "is a chunk of " + std::to_string(*r.size) +
                                       " bytes, over the limit of " + std::to_string(kMaxChunkBytes));
            inner.clear();
            inner_known = r.compression == "none";
            if (inner_known) {
                if (!r.size || *r.size != r.data_len)
                    throw damaged(pos, "is a plain chunk whose size is not its data's");
                for (std::uint64_t at = data; at < next;) {
                    const Record m = read_record(at, next);
                    inner.push_back(at - data);
                    at += 8 + std::uint64_t{m.header_len} + m.data_len;
                }
            }
        } else if (r.op == 0x04 && inner_known) {  // the chunk's index: (time, offset) each
            if (r.data_len % 12 != 0) throw damaged(pos, "is an index of a broken size");
            std::vector<char> entries(r.data_len);
            in.seekg(std::streamoff(data)).read(entries.data(), std::streamsize(r.data_len));
            if (!in) throw damaged(pos, "is cut short");
            for (std::size_t e = 0; e < entries.size(); e += 12) {
                if (!std::binary_search(inner.begin(), inner.end(), le32(entries.data() + e + 8)))
                    throw damaged(pos, "indexes a message where its chunk holds none");
            }
        }
        starts.push_back(pos);
        pos = next;
    }
    for (const std::uint64_t to : targets) {
        if (!std::binary_search(starts.begin(), starts.end(), to)) {
            throw InputError(path + ": cannot read the bag (its index points to byte " +
                             std::to_string(to) + ", where no record starts; damaged)");
        }
    }
}

}  // namespace

bool bag_support() { return true; }

std::unique_ptr<FrameSource> open_bag(const std::string& path, const SourceOptions& options) {
    // librosbag reports through console_bridge too; its errors reach the user as one line.
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    if (!is_bag_file(path)) {
        throw InputError(path + ": not a ROS bag (no '#ROSBAG V2.0' at its start)");
    }
    if (!(options.bag_max_dt_s >= 0.0) || !std::isfinite(options.bag_max_dt_s)) {
        throw ParamError("SourceOptions.bag_max_dt_s = " + std::to_string(options.bag_max_dt_s) +
                         ": must be >= 0");
    }
    check_records(path);
    return std::make_unique<BagSource>(path, options);
}

}  // namespace wul3d
