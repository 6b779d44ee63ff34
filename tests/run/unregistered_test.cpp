// `wul3d run` on unregistered colour + depth (Kinect v2 sizes) with the built-in calibration:
// the cloud has one point per colour pixel (depth-to-colour, the paper's choice) or one per
// depth pixel (colour-to-depth).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "test_support.hpp"
#include "wul3d/io.hpp"
#include "wul3d/registration.hpp"

using namespace wul3d;
using namespace wul3d::test;
namespace fs = std::filesystem;

namespace {
// A wall 1.5 m in front of a Kinect v2, seen by both of its cameras.
void write_unregistered_frame(const fs::path& dir) {
    fs::create_directories(dir);
    const StereoCalibration calib = kinect_v2_default_calibration();
    DepthImage depth;
    depth.width = calib.depth.width;
    depth.height = calib.depth.height;
    depth.data.assign(static_cast<std::size_t>(depth.width) * depth.height, 1500);  // mm
    write_depth_png((dir / "depth.png").string(), depth);
    ColorImage color;
    color.width = calib.color.width;
    color.height = calib.color.height;
    color.rgb.resize(3u * color.width * color.height);
    for (int v = 0; v < color.height; ++v)
        for (int u = 0; u < color.width; ++u) {
            std::uint8_t* px = &color.rgb[3u * (static_cast<std::size_t>(v) * color.width + u)];
            px[0] = u < color.width / 2 ? 220 : 30;  // two halves of different colour
            px[1] = 60;
            px[2] = u < color.width / 2 ? 30 : 200;
        }
    write_color_png((dir / "color.png").string(), color);
}

std::size_t labelled(const LabelImage& l) {
    std::size_t n = 0;
    for (auto v : l.labels) n += v != 0;
    return n;
}
}  // namespace

TEST(RunUnregistered, DepthToColourGivesOnePointPerColourPixel) {
    TempDir tmp;
    write_unregistered_frame(tmp / "seq" / "frame_000");
    const auto r = run_cli({"run", (tmp / "seq").string(), "--calibration", "kinect_v2", "--k",
                            "3", "--out", (tmp / "out").string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const LabelImage labels = read_label_png((tmp / "out" / "frame_000" / "labels.png").string());
    EXPECT_EQ(labels.width, 1920);
    EXPECT_EQ(labels.height, 1080);
    // The depth camera's wider-than-tall view covers most of the colour image at 1.5 m.
    EXPECT_GT(labelled(labels), 1920u * 1080u / 2);
    // The two colour halves end up in different clusters.
    const int left = labels.labels[540u * 1920 + 700], right = labels.labels[540u * 1920 + 1220];
    EXPECT_NE(left, 0);
    EXPECT_NE(right, 0);
    EXPECT_NE(left, right);
}

TEST(RunUnregistered, ColourToDepthGivesOnePointPerDepthPixel) {
    TempDir tmp;
    write_unregistered_frame(tmp / "seq" / "frame_000");
    const auto r = run_cli({"run", (tmp / "seq").string(), "--calibration", "kinect_v2",
                            "--registration", "color-to-depth", "--k", "3", "--out",
                            (tmp / "out").string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const LabelImage labels = read_label_png((tmp / "out" / "frame_000" / "labels.png").string());
    EXPECT_EQ(labels.width, 512);
    EXPECT_EQ(labels.height, 424);
    EXPECT_GT(labelled(labels), 512u * 424u / 2);
}

TEST(RunUnregistered, SizesWithoutCalibrationAreAOneLineError) {
    TempDir tmp;
    write_unregistered_frame(tmp / "seq" / "frame_000");
    // intrinsics.json beside the images makes it look like a registered frame folder
    write_text_file((tmp / "seq" / "frame_000" / "intrinsics.json").string(),
                    R"({"fx": 365.5, "fy": 365.5, "cx": 255.5, "cy": 211.5, "width": 512,
                        "height": 424, "depth_scale_m_per_unit": 0.001})");
    const auto r = run_cli({"run", (tmp / "seq").string(), "--out", (tmp / "out").string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--calibration"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
}
