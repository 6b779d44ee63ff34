// ROS 1 bags (wul3d/bag.hpp): bags written here with librosbag from the shipped frames, in
// both layouts the reader detects, read back and compared with the frame-folder reader.
#include <geometry_msgs/Transform.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <std_msgs/Float32.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "ros_frames.hpp"
#include "test_support.hpp"
#include "wul3d/bag.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace fs = std::filesystem;
using namespace wul3d;
using wul3d::test::color_msg;
using wul3d::test::depth_msg;
using wul3d::test::info_msg;
using wul3d::test::ros_header;

namespace {

fs::path tabletop() { return wul3d::test::sample_dir() / "uois_tabletop"; }

/// The shipped tabletop frames as the folder reader gives them.
const std::vector<RgbdFrame>& folder_frames() {
    static const std::vector<RgbdFrame> frames = [] {
        auto source = open_source(tabletop().string(), {});
        std::vector<RgbdFrame> out;
        SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            out.push_back(item.frame);
        }
        return out;
    }();
    return frames;
}

ros::Time frame_time(std::size_t i) { return ros::Time(1700000000.0 + 0.1 * double(i)); }

/// Plain topics, as `rosbag record` of a RealSense driver with aligned depth writes them
/// (plus its unaligned depth, which the reader must pass over). Colour in bgr8 with padded
/// rows, recorded 5 ms after its depth.
void write_plain_bag(const fs::path& path) {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    const auto& frames = folder_frames();
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const ros::Time t = frame_time(i), tc = t + ros::Duration(0.005);
        const auto h = ros_header(t, "camera_color_optical_frame", unsigned(i));
        bag.write("/camera/aligned_depth_to_color/camera_info", t, info_msg(frames[i].intrinsics, h));
        bag.write("/camera/aligned_depth_to_color/image_raw", t, depth_msg(frames[i], h));
        bag.write("/camera/depth/image_rect_raw", t, depth_msg(frames[i], h));
        bag.write("/camera/color/image_raw", tc, color_msg(frames[i], ros_header(tc, h.frame_id), "bgr8", 8));
    }
}

geometry_msgs::Transform transform(double x) {
    geometry_msgs::Transform tf;
    tf.rotation.w = 1;
    tf.translation.x = x;
    return tf;
}

/// RealSense Viewer's layout; `color_x_m`: the colour stream's offset (0: aligned already).
void write_realsense_bag(const fs::path& path, double color_x_m = 0) {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    const auto& frames = folder_frames();
    const ros::Time t0 = frame_time(0);
    std_msgs::Float32 units;
    units.data = frames[0].depth.scale_m_per_unit;
    bag.write("/device_0/sensor_0/option/Depth Units/value", t0, units);
    bag.write("/device_0/sensor_0/Depth_0/info/camera_info", t0,
              info_msg(frames[0].intrinsics, ros_header(t0, "")));
    bag.write("/device_0/sensor_1/Color_0/info/camera_info", t0,
              info_msg(frames[0].intrinsics, ros_header(t0, "")));
    bag.write("/device_0/sensor_0/Depth_0/tf/0", t0, transform(0));
    bag.write("/device_0/sensor_1/Color_0/tf/0", t0, transform(color_x_m));
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const ros::Time t = frame_time(i);
        const auto h = ros_header(t, "0", unsigned(i));
        bag.write("/device_0/sensor_0/Depth_0/image/data", t, depth_msg(frames[i], h, "mono16"));
        bag.write("/device_0/sensor_1/Color_0/image/data", t, color_msg(frames[i], h, "rgb8"));
    }
}

void expect_same_frames(FrameSource& source) {
    const auto& frames = folder_frames();
    ASSERT_EQ(source.size(), frames.size());
    SourceItem item;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        source.read(i, item);
        ASSERT_FALSE(item.is_raw);
        const RgbdFrame& got = item.frame;
        const RgbdFrame& want = frames[i];
        EXPECT_EQ(source.name(i), got.name);
        EXPECT_EQ(got.intrinsics.width, want.intrinsics.width);
        EXPECT_EQ(got.intrinsics.height, want.intrinsics.height);
        EXPECT_DOUBLE_EQ(got.intrinsics.fx, want.intrinsics.fx);
        EXPECT_DOUBLE_EQ(got.intrinsics.fy, want.intrinsics.fy);
        EXPECT_DOUBLE_EQ(got.intrinsics.cx, want.intrinsics.cx);
        EXPECT_DOUBLE_EQ(got.intrinsics.cy, want.intrinsics.cy);
        EXPECT_FLOAT_EQ(got.depth.scale_m_per_unit, want.depth.scale_m_per_unit);
        EXPECT_EQ(got.depth.width, want.depth.width);
        EXPECT_EQ(got.depth.height, want.depth.height);
        EXPECT_TRUE(got.depth.data == want.depth.data) << "depth of frame " << i;
        EXPECT_EQ(got.color.width, want.color.width);
        EXPECT_EQ(got.color.height, want.color.height);
        EXPECT_TRUE(got.color.rgb == want.color.rgb) << "colour of frame " << i;
    }
}

std::size_t lines(const std::string& s) { return std::size_t(std::count(s.begin(), s.end(), '\n')); }

/// `wul3d run BAG` fails with exit 2 and one line that holds `what`.
void expect_refused(const std::vector<std::string>& args, const std::string& what) {
    wul3d::test::TempDir out;
    std::vector<std::string> a = {"run"};
    a.insert(a.end(), args.begin(), args.end());
    a.insert(a.end(), {"--out", (out / "o").string(), "--quiet"});
    const auto r = wul3d::test::run_cli(a);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
}

}  // namespace

TEST(BagSource, PlainTopics_FramesIntrinsicsAndPixelsEqualTheFolderReader) {
    ASSERT_TRUE(bag_support());
    wul3d::test::TempDir dir;
    write_plain_bag(dir / "plain.bag");
    EXPECT_TRUE(is_bag_file((dir / "plain.bag").string()));
    auto source = open_source((dir / "plain.bag").string(), {});
    EXPECT_EQ(source->format(), InputFormat::Bag);
    EXPECT_EQ(source->name(0), "1700000000.000000000");
    expect_same_frames(*source);
}

TEST(BagSource, RealSenseViewerLayout_ReadWithNoOptions) {
    wul3d::test::TempDir dir;
    write_realsense_bag(dir / "rs.bag");
    auto source = open_source((dir / "rs.bag").string(), {});
    EXPECT_EQ(source->calibration(), nullptr);  // colour and depth cameras are one: registered
    expect_same_frames(*source);
}

TEST(BagSource, RealSenseViewerLayout_UnalignedStreamsGiveRawFramesAndTheirCalibration) {
    wul3d::test::TempDir dir;
    write_realsense_bag(dir / "rs.bag", 0.015);
    auto source = open_source((dir / "rs.bag").string(), {});
    const StereoCalibration* calib = source->calibration();
    ASSERT_NE(calib, nullptr);
    // The colour stream 15 mm along x of the depth stream: depth -> colour is t = -15 mm.
    EXPECT_NEAR(calib->translation_m[0], -0.015, 1e-12);
    EXPECT_NEAR(calib->translation_m[1], 0.0, 1e-12);
    EXPECT_DOUBLE_EQ(calib->rotation[0], 1.0);
    EXPECT_DOUBLE_EQ(calib->depth.fx, folder_frames()[0].intrinsics.fx);
    SourceItem item;
    source->read(1, item);
    EXPECT_TRUE(item.is_raw);
    EXPECT_TRUE(item.raw.depth.data == folder_frames()[1].depth.data);
    EXPECT_TRUE(item.raw.color.rgb == folder_frames()[1].color.rgb);
}

TEST(BagSource, Topics_PickOthersAndCompressedColourAndFloatDepth) {
    wul3d::test::TempDir dir;
    const fs::path path = dir / "other.bag";
    {
        rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
        const auto& frames = folder_frames();
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const ros::Time t = frame_time(i);
            const auto h = ros_header(t, "cam");
            // The colour as a PNG CompressedImage, as image_transport's "compressed" sends it.
            write_color_png((dir / "c.png").string(), frames[i].color);
            std::ifstream in(dir / "c.png", std::ios::binary);
            sensor_msgs::CompressedImage c;
            c.header = h;
            c.format = "rgb8; png compressed bgr8";
            c.data.assign(std::istreambuf_iterator<char>(in), {});
            bag.write("/rgb/compressed", t, c);
            bag.write("/a/depth", t, depth_msg(frames[i], h));
            bag.write("/b/depth", t, wul3d::test::depth_msg_float(frames[i], h));
            bag.write("/info", t, info_msg(frames[i].intrinsics, h));
        }
    }
    // Two depth topics, neither aligned by name: the reader asks which.
    EXPECT_THROW(open_source(path.string(), {}), InputError);
    SourceOptions options;
    options.bag_topics = "/rgb/compressed,/b/depth,/info";
    auto source = open_source(path.string(), options);
    expect_same_frames(*source);
    options.bag_topics = "/rgb/compressed,/nope";
    EXPECT_THROW(open_source(path.string(), options), InputError);
    options.bag_topics = "/rgb/compressed";
    EXPECT_THROW(open_source(path.string(), options), ParamError);
}

TEST(BagSource, Pairing_DropsDepthWithNoColourWithinTheTolerance) {
    wul3d::test::TempDir dir;
    write_plain_bag(dir / "plain.bag");  // colour 5 ms after depth
    SourceOptions options;
    options.bag_max_dt_s = 0.004;
    EXPECT_THROW(open_source((dir / "plain.bag").string(), options), InputError);
    options.bag_max_dt_s = 0.006;
    EXPECT_EQ(open_source((dir / "plain.bag").string(), options)->size(), folder_frames().size());
}

TEST(BagCli, RunOnABag_ObjectsEqualRunOnTheFolder) {
    wul3d::test::TempDir dir;
    write_plain_bag(dir / "plain.bag");
    write_realsense_bag(dir / "rs.bag");
    const auto folder = wul3d::test::run_cli(
        {"run", tabletop().string(), "--out", (dir / "folder").string(), "--quiet"});
    ASSERT_EQ(folder.exit_code, 0) << folder.err;
    std::vector<std::string> want;
    for (const auto& e : fs::directory_iterator(dir / "folder"))
        if (e.is_directory()) want.push_back(e.path().filename().string());
    std::sort(want.begin(), want.end());
    ASSERT_EQ(want.size(), folder_frames().size());
    for (const char* bag : {"plain.bag", "rs.bag"}) {
        const fs::path out = dir / (std::string(bag) + ".out");
        const auto r = wul3d::test::run_cli({"run", (dir / bag).string(), "--out", out.string(), "--quiet"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        std::vector<std::string> got;
        for (const auto& e : fs::directory_iterator(out))
            if (e.is_directory()) got.push_back(e.path().filename().string());
        std::sort(got.begin(), got.end());
        ASSERT_EQ(got.size(), want.size());
        for (std::size_t i = 0; i < want.size(); ++i) {
            const LabelImage a = read_label_png((dir / "folder" / want[i] / "objects.png").string());
            const LabelImage b = read_label_png((out / got[i] / "objects.png").string());
            EXPECT_EQ(a.width, b.width);
            EXPECT_TRUE(a.labels == b.labels) << bag << " frame " << got[i];
            EXPECT_GT(*std::max_element(b.labels.begin(), b.labels.end()), 0) << "no object found";
        }
    }
}

TEST(BagCli, BadBags_OneLineAndExit2) {
    wul3d::test::TempDir dir;
    const auto& frames = folder_frames();
    {  // a bag with no image topic
        rosbag::Bag bag((dir / "noimage.bag").string(), rosbag::bagmode::Write);
        bag.write("/info", frame_time(0), info_msg(frames[0].intrinsics, ros_header(frame_time(0), "")));
    }
    expect_refused({(dir / "noimage.bag").string()}, "no depth image topic");

    write_plain_bag(dir / "plain.bag");  // truncated: its second half (and its index) lost
    const auto full = fs::file_size(dir / "plain.bag");
    fs::copy_file(dir / "plain.bag", dir / "truncated.bag");
    fs::resize_file(dir / "truncated.bag", full / 2);
    expect_refused({(dir / "truncated.bag").string()}, "truncated.bag");

    // A record that declares a header of 2 GB (librosbag would allocate it; fuzz_bag found it).
    fs::copy_file(dir / "plain.bag", dir / "huge.bag");
    {
        std::fstream f(dir / "huge.bag", std::ios::in | std::ios::out | std::ios::binary);
        const char len[4] = {0, 0, 0, 0x7f};
        f.seekp(13).write(len, 4);
    }
    expect_refused({(dir / "huge.bag").string()}, "declares a header of 2130706432 bytes");

    // The bag's header pointing its index into the middle of a record (fuzz_bag found it).
    fs::copy_file(dir / "plain.bag", dir / "index.bag");
    {
        std::fstream f(dir / "index.bag", std::ios::in | std::ios::out | std::ios::binary);
        std::string head(4096, '\0');
        f.read(head.data(), 4096);
        const auto at = head.find("index_pos=");
        ASSERT_NE(at, std::string::npos);
        head[at + 10] = char(head[at + 10] + 1);
        f.clear();
        f.seekp(std::streamoff(at + 10)).write(&head[at + 10], 1);
    }
    expect_refused({(dir / "index.bag").string()}, "where no record starts");

    {  // colour of another size than depth; depth data shorter than its size says
        rosbag::Bag bag((dir / "sizes.bag").string(), rosbag::bagmode::Write);
        const ros::Time t = frame_time(0);
        const auto h = ros_header(t, "");
        RgbdFrame small = frames[0];
        small.color.width /= 2;
        small.color.height /= 2;
        small.color.rgb.resize(3 * std::size_t(small.color.width) * std::size_t(small.color.height));
        bag.write("/depth", t, depth_msg(frames[0], h));
        bag.write("/color", t, color_msg(small, h));
        bag.write("/camera_info", t, info_msg(frames[0].intrinsics, h));
        auto cut = depth_msg(frames[0], h);
        cut.data.resize(cut.data.size() / 2);
        bag.write("/cut/depth", t, cut);
    }
    expect_refused({(dir / "sizes.bag").string(), "--topics", "/color,/depth"}, "same size");
    expect_refused({(dir / "sizes.bag").string(), "--topics", ",/cut/depth,/camera_info"},
                   "bytes but has");
    expect_refused({(dir / "sizes.bag").string(), "--topics", "/color,/nope"}, "no topic /nope");
    expect_refused({tabletop().string(), "--topics", "/color,/depth"}, "no bag");
}

TEST(BagCli, FuzzFindings_OneLineAndExit2) {
    // fuzz_bag's findings (docs/FUZZING.md): librosbag allocated 2 GB, or read past a buffer.
    for (const char* name : {"bag-record-header-of-538-mb.bag", "bag-index-into-a-record.bag",
                             "bag-message-past-its-chunk.bag", "bag-header-field-past-its-header.bag",
                             "bag-connection-field-past-its-header.bag"}) {
        expect_refused({(fs::path(WUL3D_TEST_DATA_DIR) / "fuzz" / name).string()},
                       "cannot read the bag");
    }
}
