// OSD-0.2-depth trees as downloaded (image_color/, disparity/ in mm, annotation/, pcd/):
// built by the test from shipped frames; `wul3d run TREE` reads them with the intrinsics
// of pcd/ (else Kinect v1's), as the same frames read as frame folders, and `wul3d eval
// OUT TREE` reads annotation/.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/camera.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::expect_one_line;
using wul3d::test::run_cli;
using wul3d::test::TempDir;

// OSD's names, two shipped scenes (640x480, one RealSense-like camera).
const char* const kNames[] = {"learn0", "test1"};
const char* const kSamples[] = {"image_0000", "image_0002"};

wul3d::RgbdFrame sample_frame(int i) {
    return wul3d::test::read_sample_frame(kSamples[i]);
}

/// ROOT/OSD-0.2-depth with both frames; pcd/ unless `with_pcd` is false.
fs::path make_tree(const fs::path& root, bool with_pcd = true) {
    const fs::path tree = root / "OSD-0.2-depth";
    for (const char* sub : {"image_color", "disparity", "annotation", "pcd"})
        if (with_pcd || std::string(sub) != "pcd") fs::create_directories(tree / sub);
    for (int i = 0; i < 2; ++i) {
        const wul3d::RgbdFrame f = sample_frame(i);
        const std::string png = std::string(kNames[i]) + ".png";
        wul3d::write_depth_png((tree / "disparity" / png).string(), f.depth);
        wul3d::write_color_png((tree / "image_color" / png).string(), f.color);
        if (with_pcd)
            wul3d::write_pcd((tree / "pcd" / (std::string(kNames[i]) + ".pcd")).string(), f,
                             wul3d::PcdData::BinaryCompressed, true);
    }
    return tree;
}

TEST(Osd, ATreeReadsWithTheIntrinsicsOfItsPcd) {
    TempDir tmp;
    const fs::path tree = make_tree(tmp.path());
    auto source = wul3d::open_source(tree.string(), {});
    ASSERT_EQ(source->size(), 2u);
    EXPECT_EQ(source->format(), wul3d::InputFormat::Osd);
    EXPECT_EQ(source->name(0), kNames[0]);
    EXPECT_EQ(source->name(1), kNames[1]);
    wul3d::SourceItem item;
    source->read(1, item);
    const wul3d::RgbdFrame want = sample_frame(1);
    EXPECT_EQ(item.frame.name, kNames[1]);
    EXPECT_EQ(item.frame.depth.data, want.depth.data);
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 0.001f);  // disparity/ is millimetres
    EXPECT_EQ(item.frame.color.rgb, want.color.rgb);
    EXPECT_NEAR(item.frame.intrinsics.fx, want.intrinsics.fx, 0.005 * want.intrinsics.fx);
    EXPECT_NEAR(item.frame.intrinsics.fy, want.intrinsics.fy, 0.005 * want.intrinsics.fy);
    EXPECT_NEAR(item.frame.intrinsics.cx, want.intrinsics.cx, 0.5);
    EXPECT_NEAR(item.frame.intrinsics.cy, want.intrinsics.cy, 0.5);
    EXPECT_EQ(item.frame.intrinsics.width, 640);
    EXPECT_EQ(item.frame.intrinsics.height, 480);
}

TEST(Osd, WithoutPcdTheIntrinsicsAreKinectV1s) {
    TempDir tmp;
    const fs::path tree = make_tree(tmp.path(), false);
    auto source = wul3d::open_source(tree.string(), {});
    wul3d::SourceItem item;
    source->read(0, item);
    const wul3d::PinholeIntrinsics k = wul3d::intrinsics_preset("kinect_v1");
    EXPECT_EQ(item.frame.intrinsics.fx, k.fx);
    EXPECT_EQ(item.frame.intrinsics.cx, k.cx);
    EXPECT_EQ(item.frame.intrinsics.cy, k.cy);
    wul3d::SourceOptions o;
    o.intrinsics = sample_frame(0).intrinsics;  // --intrinsics wins
    wul3d::open_source(tree.string(), o)->read(0, item);
    EXPECT_EQ(item.frame.intrinsics.fx, o.intrinsics->fx);
}

/// Writes the frames of `tree` as frame folders under `dir`, each with `K`.
void write_plain(const fs::path& tree, const fs::path& dir, const wul3d::PinholeIntrinsics& K) {
    for (const char* name : kNames) {
        wul3d::RgbdFrame f;
        const std::string png = std::string(name) + ".png";
        f.depth = wul3d::read_depth_png((tree / "disparity" / png).string(), 0.001f);
        f.color = wul3d::read_color_image((tree / "image_color" / png).string());
        f.intrinsics = K;
        wul3d::write_frame_folder((dir / name).string(), f);
    }
}

TEST(Osd, RunAndEvalTakeTheTreeAsTheSameFramesInFolders) {
    TempDir tmp;
    const fs::path tree = make_tree(tmp.path(), false);
    const fs::path out = tmp / "out";
    const auto run = run_cli({"run", tree.string(), "--out", out.string()});
    ASSERT_EQ(run.exit_code, 0) << wul3d::test::describe(run);

    // The same frames as frame folders with the same camera: the same objects.
    const fs::path plain = tmp / "plain", plain_out = tmp / "plain_out";
    write_plain(tree, plain, wul3d::intrinsics_preset("kinect_v1"));
    const auto run_plain = run_cli({"run", plain.string(), "--out", plain_out.string()});
    ASSERT_EQ(run_plain.exit_code, 0) << wul3d::test::describe(run_plain);
    for (const char* name : kNames) {
        const std::string got = wul3d::test::slurp(out / name / "objects.png");
        ASSERT_FALSE(got.empty()) << name;
        EXPECT_EQ(got, wul3d::test::slurp(plain_out / name / "objects.png")) << name;
    }

    // annotation/ as OSD labels the run's own objects (0 background): a perfect score.
    int objects = 0;
    for (const char* name : kNames) {
        const wul3d::LabelImage gt = wul3d::read_label_png((out / name / "objects.png").string());
        for (std::uint16_t l : gt.labels) objects = std::max(objects, int(l));
        wul3d::write_label_png((tree / "annotation" / (std::string(name) + ".png")).string(), gt);
    }
    ASSERT_GT(objects, 0);
    const auto eval = run_cli({"eval", out.string(), tree.string()});
    ASSERT_EQ(eval.exit_code, 0) << wul3d::test::describe(eval);
    EXPECT_NE(eval.out.find("Overlap F   100.0"), std::string::npos) << eval.out;
    EXPECT_NE(eval.out.find("images      2"), std::string::npos) << eval.out;

    // One object of one frame's annotation dropped: the score says so.
    wul3d::LabelImage gt = wul3d::read_label_png((out / kNames[0] / "objects.png").string());
    for (std::uint16_t& l : gt.labels) l = l == 1 ? 0 : l;
    wul3d::write_label_png((tree / "annotation" / (std::string(kNames[0]) + ".png")).string(), gt);
    const auto worse = run_cli({"eval", out.string(), tree.string()});
    ASSERT_EQ(worse.exit_code, 0) << wul3d::test::describe(worse);
    EXPECT_EQ(worse.out.find("Overlap F   100.0"), std::string::npos) << worse.out;
}

TEST(Osd, BadTreesAreOneLine) {
    TempDir tmp;
    const fs::path tree = make_tree(tmp.path(), false);
    const std::string out = (tmp / "out").string();

    fs::rename(tree / "image_color" / "test1.png", tree / "image_color" / "test2.png");
    expect_one_line(run_cli({"run", tree.string(), "--out", out}), 2,
                    {"disparity/test1.png", "has no image_color/test1.png"});
    fs::rename(tree / "image_color" / "test2.png", tree / "image_color" / "test1.png");
    fs::copy_file(tree / "image_color" / "test1.png", tree / "image_color" / "test0.png");
    expect_one_line(run_cli({"run", tree.string(), "--out", out}), 2,
                    {"image_color/test0.png", "has no disparity/"});
    fs::remove(tree / "image_color" / "test0.png");

    // A colour image of another size than its depth.
    wul3d::ColorImage small;
    small.width = 320;
    small.height = 240;
    small.rgb.assign(320 * 240 * 3, 128);
    wul3d::write_color_png((tree / "image_color" / "test1.png").string(), small);
    expect_one_line(run_cli({"run", tree.string(), "--out", out}), 2,
                    {"test1.png", "320x240", "640x480"});

    fs::remove_all(tree / "disparity");
    expect_one_line(run_cli({"run", tree.string(), "--out", out}), 2, {"without disparity/"});
    fs::remove_all(tree / "annotation");
    expect_one_line(run_cli({"eval", tmp.path().string(), tree.string()}), 2,
                    {"without annotation/"});
    fs::create_directories(tmp / "empty");
    expect_one_line(run_cli({"run", (tmp / "empty").string(), "--format", "osd", "--out", out}),
                    2, {"not an OSD tree"});
}

}  // namespace
