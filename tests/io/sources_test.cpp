// open_source (src/io/io_sources.cpp) on the shipped samples and on small sequences written
// here: folders of frame folders, depth-only and single frames, intrinsics overrides, TUM
// sequences, unregistered frames, and every error a source reports.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io_expect.hpp"
#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::expect_input_error;
using wul3d::test::ramp_depth;
using wul3d::test::sample_dir;
using wul3d::test::solid_color;
using wul3d::test::TempDir;

TEST(OpenSource, ParseInputFormat) {
    EXPECT_EQ(wul3d::parse_input_format("auto"), wul3d::InputFormat::Auto);
    EXPECT_EQ(wul3d::parse_input_format("frames"), wul3d::InputFormat::Frames);
    EXPECT_EQ(wul3d::parse_input_format("tum"), wul3d::InputFormat::Tum);
    EXPECT_EQ(wul3d::parse_input_format("unregistered"), wul3d::InputFormat::Unregistered);
    EXPECT_EQ(wul3d::parse_input_format("bag"), wul3d::InputFormat::Bag);
    EXPECT_STREQ(wul3d::input_format_name(wul3d::InputFormat::Bag), "bag");
    EXPECT_THROW(wul3d::parse_input_format("rosbag"), wul3d::ParamError);
}

TEST(OpenSource, SampleFolderOfFrameFolders) {
    auto src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), {});
    ASSERT_EQ(src->size(), 4u);
    EXPECT_EQ(src->format(), wul3d::InputFormat::Frames);
    EXPECT_EQ(src->calibration(), nullptr);
    EXPECT_EQ(src->name(0), "image_0000");
    EXPECT_EQ(src->name(1), "image_0002");
    EXPECT_EQ(src->name(3), "image_0007");
    wul3d::SourceItem item;
    src->read(0, item);
    EXPECT_FALSE(item.is_raw);
    EXPECT_EQ(item.frame.name, "image_0000");
    EXPECT_EQ(item.frame.width(), 640);
    EXPECT_EQ(item.frame.height(), 480);
    EXPECT_TRUE(item.frame.has_color());
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 612.937);
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 0.001f);
    const std::uint16_t* depth = item.frame.depth.data.data();
    const std::uint8_t* color = item.frame.color.rgb.data();
    src->read(3, item);
    EXPECT_EQ(item.frame.name, "image_0007");
    EXPECT_EQ(item.frame.depth.data.data(), depth) << "depth buffer not reused";
    EXPECT_EQ(item.frame.color.rgb.data(), color) << "colour buffer not reused";
}

TEST(OpenSource, SampleDepthOnlySequence) {
    auto src = wul3d::open_source((sample_dir() / "pcl_kinect/pairwise_seq").string(), {});
    ASSERT_EQ(src->size(), 5u);
    EXPECT_EQ(src->name(0), "capture0001");
    EXPECT_EQ(src->name(4), "capture0005");
    wul3d::SourceItem item;
    src->read(2, item);
    EXPECT_FALSE(item.frame.has_color());
    EXPECT_EQ(item.frame.width(), 640);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);
}

TEST(OpenSource, SampleSingleFrameFolder_AndSubFoldersThatAreNotFrames) {
    for (const std::string suffix : {"", "/"}) {
        auto src = wul3d::open_source((sample_dir() / "uois_tabletop/image_0002").string() + suffix, {});
        ASSERT_EQ(src->size(), 1u);
        EXPECT_EQ(src->name(0), "image_0002");
    }
    // pcl_kinect holds two frame folders and pairwise_seq, a folder of frames, not a frame.
    auto src = wul3d::open_source((sample_dir() / "pcl_kinect").string(), {});
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "milk_cartoon_all_small_clorox");
    EXPECT_EQ(src->name(1), "region_growing_rgb_tutorial");
}

TEST(OpenSource, IntrinsicsOverride) {
    wul3d::SourceOptions opt;
    opt.intrinsics = wul3d::PinholeIntrinsics{640, 480, 500, 501, 320, 240};
    auto src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), opt);
    wul3d::SourceItem item;
    src->read(1, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 500);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fy, 501);
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 0.001f);

    // No size given (as the CLI's --intrinsics fx,fy,cx,cy): each frame's own.
    opt.intrinsics = wul3d::PinholeIntrinsics{0, 0, 500, 501, 320, 240};
    src = wul3d::open_source((sample_dir() / "pcl_kinect/pairwise_seq").string(), opt);
    src->read(0, item);
    EXPECT_EQ(item.frame.intrinsics.width, 640);
    EXPECT_EQ(item.frame.intrinsics.height, 480);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fy, 501);

    opt.intrinsics = wul3d::PinholeIntrinsics{512, 424, 365, 365, 256, 212};
    src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), opt);
    expect_input_error([&] { src->read(0, item); }, {"image_0000", "640x480", "512x424"});
}

TEST(OpenSource, Errors) {
    TempDir tmp;
    const std::string missing = (tmp / "missing").string();
    expect_input_error([&] { wul3d::open_source(missing, {}); }, {missing, "no such file or directory"});
    expect_input_error([&] { wul3d::open_source(tmp.path().string(), {}); },
                       {tmp.path().string(), "no frames found (expected"});

    // A frame folder without depth.png, in a sequence and on its own.
    fs::create_directories(tmp / "seq" / "f0");
    fs::create_directories(tmp / "seq" / "f1");
    wul3d::write_depth_png((tmp / "seq/f0/depth.png").string(), ramp_depth(8, 6));
    wul3d::write_color_png((tmp / "seq/f1/color.png").string(), solid_color(8, 6, 1, 2, 3));
    expect_input_error([&] { wul3d::open_source((tmp / "seq").string(), {}); },
                       {(tmp / "seq" / "f1").string(), "no depth.png"});
    expect_input_error([&] { wul3d::open_source((tmp / "seq/f1").string(), {}); },
                       {"f1", "no depth.png"});

    // Missing intrinsics.json is found when the frame is read.
    auto src = wul3d::open_source((tmp / "seq/f0").string(), {});
    wul3d::SourceItem item;
    expect_input_error([&] { src->read(0, item); }, {"intrinsics.json", "no such file"});

    // Colour and depth of different sizes without a calibration.
    wul3d::write_depth_png((tmp / "seq/f1/depth.png").string(), ramp_depth(4, 3));
    wul3d::write_text_file((tmp / "seq/f1/intrinsics.json").string(),
                           R"({"fx": 5, "fy": 5, "cx": 2, "cy": 1.5, "width": 4, "height": 3})");
    src = wul3d::open_source((tmp / "seq/f1").string(), {});
    expect_input_error([&] { src->read(0, item); },
                       {"f1", "color.png is 8x6 but depth.png is 4x3", "--calibration"});
}

/// A tiny TUM RGB-D sequence: depth at t = 1.000, 1.033, 1.100; colour at t = 1.010,
/// 1.060, 1.119. With 20 ms, 1.000 pairs with 1.010 and 1.100 with 1.119; 1.033 is 23 and
/// 27 ms from its neighbours and is dropped.
fs::path write_tum(const fs::path& root) {
    fs::create_directories(root / "rgb");
    fs::create_directories(root / "depth");
    const char* rgb_stamps[3] = {"1.010000", "1.060000", "1.119000"};
    const char* depth_stamps[3] = {"1.000000", "1.033000", "1.100000"};
    std::string rgb_txt = "# color images\n# file: 'test'\n# timestamp filename\n";
    std::string depth_txt = "# depth maps\n# timestamp filename\n\n";
    for (int i = 0; i < 3; ++i) {
        const auto k = static_cast<std::uint8_t>(10 * (i + 1));
        wul3d::write_color_png((root / "rgb" / (std::string(rgb_stamps[i]) + ".png")).string(),
                               solid_color(640, 480, k, k, k));
        wul3d::DepthImage d;
        d.width = 640;
        d.height = 480;
        d.data.assign(640 * 480, static_cast<std::uint16_t>(5000 * (i + 1)));  // 1, 2, 3 m
        wul3d::write_depth_png((root / "depth" / (std::string(depth_stamps[i]) + ".png")).string(), d);
        rgb_txt += std::string(rgb_stamps[i]) + " rgb/" + rgb_stamps[i] + ".png\n";
        depth_txt += std::string(depth_stamps[i]) + " depth/" + depth_stamps[i] + ".png\n";
    }
    wul3d::write_text_file((root / "rgb.txt").string(), rgb_txt);
    wul3d::write_text_file((root / "depth.txt").string(), depth_txt);
    return root;
}

TEST(OpenSource, TumAssociationScaleAndIntrinsics) {
    TempDir tmp;
    const fs::path root = write_tum(tmp / "rgbd_dataset_freiburg2_tiny");
    auto src = wul3d::open_source(root.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Tum);
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "1.000000");
    EXPECT_EQ(src->name(1), "1.100000");
    wul3d::SourceItem item;
    src->read(1, item);
    EXPECT_EQ(item.frame.name, "1.100000");
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 1.0f / 5000.0f);
    EXPECT_EQ(item.frame.depth.data[0], 15000);
    EXPECT_NEAR(item.frame.depth.data[0] * item.frame.depth.scale_m_per_unit, 3.0, 1e-6);
    EXPECT_EQ(item.frame.color.rgb[0], 30) << "1.100 must take the colour of 1.119";
    const wul3d::PinholeIntrinsics fr2 = wul3d::intrinsics_preset("tum_fr2");
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, fr2.fx);
    src->read(0, item);
    EXPECT_EQ(item.frame.color.rgb[0], 10);
    EXPECT_NEAR(item.frame.depth.data[0] * item.frame.depth.scale_m_per_unit, 1.0, 1e-6);

    // A wider tolerance keeps 1.033 too; a preset or explicit intrinsics win over the name.
    wul3d::SourceOptions opt;
    opt.tum_max_dt_s = 0.03;
    opt.tum_camera = "kinect_v1";
    src = wul3d::open_source(root.string(), opt);
    EXPECT_EQ(src->size(), 3u);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);
    opt.intrinsics = wul3d::PinholeIntrinsics{640, 480, 600, 600, 320, 240};
    src = wul3d::open_source(root.string(), opt);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 600.0);
    opt.intrinsics = wul3d::PinholeIntrinsics{0, 0, 610, 610, 320, 240};
    src = wul3d::open_source(root.string(), opt);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 610.0);
    EXPECT_EQ(item.frame.intrinsics.width, 640);

    opt = {};
    opt.tum_max_dt_s = 0.001;
    expect_input_error([&] { wul3d::open_source(root.string(), opt); },
                       {root.string(), "no frames found"});

    // Without freiburgN in the name: the Kinect v1 default.
    const fs::path plain = write_tum(tmp / "my_recording");
    src = wul3d::open_source(plain.string(), {});
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);

    wul3d::write_text_file((plain / "rgb.txt").string(), "1.0\n");
    expect_input_error([&] { wul3d::open_source(plain.string(), {}); }, {"rgb.txt:1", "timestamp"});
}

TEST(OpenSource, Unregistered) {
    TempDir tmp;
    const wul3d::StereoCalibration kinect = wul3d::kinect_v2_default_calibration();
    const fs::path seq = tmp / "seq";
    for (const char* name : {"b", "a"}) {
        fs::create_directories(seq / name);
        wul3d::DepthImage d;
        d.width = 512;
        d.height = 424;
        d.data.assign(512 * 424, 1234);
        wul3d::write_depth_png((seq / name / "depth.png").string(), d);
        wul3d::write_color_png((seq / name / "color.png").string(), solid_color(1920, 1080, 9, 8, 7));
    }
    // Without a calibration: the size mismatch is reported with the hint.
    auto src = wul3d::open_source(seq.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Frames);
    wul3d::SourceItem item;
    expect_input_error([&] { src->read(0, item); }, {"color.png is 1920x1080", "--calibration"});
    wul3d::SourceOptions explicit_format;
    explicit_format.format = wul3d::InputFormat::Unregistered;
    expect_input_error([&] { wul3d::open_source(seq.string(), explicit_format); },
                       {seq.string(), "calibration"});

    // The built-in preset.
    wul3d::SourceOptions opt;
    opt.calibration = "kinect_v2";
    src = wul3d::open_source(seq.string(), opt);
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    ASSERT_NE(src->calibration(), nullptr);
    EXPECT_EQ(src->calibration()->color.fx, kinect.color.fx);

    // calibration.json beside the frames is found by auto-detection.
    wul3d::StereoCalibration mine = kinect;
    mine.translation_m = {0.05, 0.001, -0.002};
    wul3d::write_calibration_json((seq / "calibration.json").string(), mine);
    src = wul3d::open_source(seq.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "a");
    ASSERT_NE(src->calibration(), nullptr);
    EXPECT_EQ(src->calibration()->translation_m, mine.translation_m);
    src->read(1, item);
    EXPECT_TRUE(item.is_raw);
    EXPECT_EQ(item.raw.name, "b");
    EXPECT_EQ(item.raw.depth.width, 512);
    EXPECT_EQ(item.raw.color.width, 1920);
    EXPECT_EQ(item.raw.color.rgb[0], 9);
    EXPECT_EQ(item.raw.depth.data[7], 1234);

    // A single frame folder finds calibration.json in its parent.
    src = wul3d::open_source((seq / "a").string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    EXPECT_EQ(src->size(), 1u);

    // An explicit calibration file whose sizes do not fit the frames.
    wul3d::StereoCalibration wrong = kinect;
    wrong.depth.width = 640;
    wrong.depth.height = 480;
    opt.calibration = (tmp / "wrong.json").string();
    wul3d::write_calibration_json(opt.calibration, wrong);
    src = wul3d::open_source(seq.string(), opt);
    expect_input_error([&] { src->read(0, item); }, {"depth.png is 512x424", "640x480"});
}

}  // namespace
