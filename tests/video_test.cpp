// `wul3d run --video`: the side-by-side video (colour | objects | clusters) is read back with
// OpenCV's VideoCapture: one video frame per input frame, three panels wide, the objects
// panel tinting the selected object and darkening the rest. The
// video is written by the plugin libwul3d_video.so, which wul3d loads from its own folder:
// a copy of wul3d in a folder without it must fail at once and leave nothing behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::cli_path;
using wul3d::test::list_files;
using wul3d::test::run_cli;
using wul3d::test::run_command;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;

TEST(RunVideo, OneVideoFramePerInputFrame_ThreePanelsWide) {
    TempDir tmp;
    const fs::path video = tmp / "clips" / "tabletop.mp4";  // the folder is created
    const auto r = run_cli({"run", (sample_dir() / "uois_tabletop").string(), "--out",
                            (tmp / "out").string(), "--select", "490,240", "--video",
                            video.string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::is_regular_file(video));
    for (const auto& e : fs::directory_iterator(video.parent_path()))
        EXPECT_EQ(e.path(), video) << "left behind: " << e.path();

    cv::VideoCapture capture(video.string(), cv::CAP_FFMPEG);
    ASSERT_TRUE(capture.isOpened());
    int frames = 0;
    cv::Mat image, first;
    while (capture.read(image)) {
        if (frames == 0) first = image.clone();
        ++frames;
    }
    EXPECT_EQ(frames, 4);  // uois_tabletop holds 4 frames of 640 x 480
    ASSERT_FALSE(first.empty());
    EXPECT_EQ(first.cols, 3 * 640);
    EXPECT_EQ(first.rows, 480);
    // Not blank: the colour panel shows the scene.
    cv::Scalar mean, stddev;
    cv::meanStdDev(first(cv::Rect(0, 100, 640, 380)), mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30.0);

    // The middle panel shows the objects over the colour: the selected one (the object
    // under 490,240) tinted, away from its outline and its id's tag; the rest darkened to a
    // quarter. Below the captions (row 40 on), within what the video's compression keeps.
    const wul3d::LabelImage objects =
        wul3d::read_label_png((tmp / "out" / "image_0000" / "objects.png").string());
    const int id = objects.labels[240 * 640 + 490];
    ASSERT_NE(id, 0);
    int inside = 0, tinted = 0, outside = 0, darkened = 0;
    for (int v = 40; v < 478; v += 2)
        for (int u = 2; u < 638; u += 2) {
            int same = 0, count = 0;
            for (int dv = -2; dv <= 2; ++dv)
                for (int du = -2; du <= 2; ++du, ++count)
                    same += objects.labels[static_cast<std::size_t>(v + dv) * 640 + u + du] == id;
            const cv::Vec3b c = first.at<cv::Vec3b>(v, u), o = first.at<cv::Vec3b>(v, 640 + u);
            int most = 0, off_quarter = 0;
            for (int q = 0; q < 3; ++q) {
                most = std::max(most, std::abs(int(o[q]) - int(c[q])));
                off_quarter = std::max(off_quarter, std::abs(int(o[q]) - int(c[q]) / 4));
            }
            if (same == count) {
                ++inside;
                tinted += most > 30;
            } else if (same == 0) {
                ++outside;
                darkened += off_quarter <= 16;
            }
        }
    ASSERT_GT(inside, 500);
    EXPECT_GT(tinted, inside * 7 / 10) << tinted << " of " << inside;
    EXPECT_GT(darkened, outside * 9 / 10) << darkened << " of " << outside;
}

TEST(RunVideo, FolderThatCannotBeCreated_OneLineAndNoFrames) {
    TempDir tmp;
    const fs::path blocker = tmp / "file";
    { std::FILE* f = std::fopen(blocker.c_str(), "w"); std::fclose(f); }
    const auto r = run_cli({"run", (sample_dir() / "uois_tabletop" / "image_0000").string(), "--out",
                            (tmp / "out").string(), "--video", (blocker / "v.mp4").string(),
                            "-q"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("v.mp4"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A copy of the wul3d executable in tmp/bin, with the plugin beside it when `with_plugin`.
fs::path copy_cli(const TempDir& tmp, bool with_plugin) {
    const fs::path bin = tmp / "bin";
    fs::create_directories(bin);
    fs::copy_file(cli_path(), bin / cli_path().filename());
    if (with_plugin) fs::copy_file(WUL3D_VIDEO_PLUGIN, bin / fs::path(WUL3D_VIDEO_PLUGIN).filename());
    return bin / cli_path().filename();
}

TEST(RunVideo, PluginMissing_OneLineNamingItAndNothingWritten) {
    TempDir tmp;
    const fs::path cli = copy_cli(tmp, false);
    const fs::path video = tmp / "clips" / "v.mp4";
    const auto r = run_command({cli.string(), "run", (sample_dir() / "uois_tabletop").string(),
                                "--out", (tmp / "out").string(), "--video", video.string(), "-q"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const std::string plugin = fs::path(WUL3D_VIDEO_PLUGIN).filename().string();
    EXPECT_NE(r.err.find(plugin + " not found next to wul3d"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("v.mp4"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    // Checked before the first frame: no video, no partial file, no frame outputs.
    EXPECT_FALSE(fs::exists(video.parent_path())) << "video folder created";
    EXPECT_TRUE(list_files(tmp / "out").empty()) << list_files(tmp / "out").front();
}

TEST(RunVideo, PluginThatIsNotOne_OneLineSayingItCannotBeLoaded) {
    TempDir tmp;
    const fs::path cli = copy_cli(tmp, false);
    const std::string plugin = fs::path(WUL3D_VIDEO_PLUGIN).filename().string();
    std::ofstream(cli.parent_path() / plugin) << "not a shared object\n";
    const fs::path video = tmp / "v.mp4";
    const auto r = run_command({cli.string(), "run",
                                (sample_dir() / "uois_tabletop" / "image_0000").string(), "--out",
                                (tmp / "out").string(), "--video", video.string(), "-q"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(plugin + " cannot be loaded"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(video));
}

TEST(RunVideo, PluginIsLookedUpBesideTheExecutable) {
    // The copy finds the copied plugin: wul3d looks in its own folder, not the build's.
    TempDir tmp;
    const fs::path cli = copy_cli(tmp, true);
    const fs::path video = tmp / "v.mp4";
    const auto r = run_command({cli.string(), "run",
                                (sample_dir() / "uois_tabletop" / "image_0000").string(), "--out",
                                (tmp / "out").string(), "--video", video.string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    cv::VideoCapture capture(video.string(), cv::CAP_FFMPEG);
    ASSERT_TRUE(capture.isOpened());
    cv::Mat image;
    EXPECT_TRUE(capture.read(image));
    EXPECT_EQ(image.cols, 3 * 640);
}

}  // namespace
