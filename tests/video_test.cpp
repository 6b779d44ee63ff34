// `wul3d run --video`: the side-by-side video (colour | clusters | selected object) is read
// back with OpenCV's VideoCapture: one video frame per input frame, three panels wide.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::run_cli;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;

TEST(RunVideo, OneVideoFramePerInputFrame_ThreePanelsWide) {
    TempDir tmp;
    const fs::path video = tmp / "clips" / "tabletop.mp4";  // the folder is created
    const auto r = run_cli({"run", (sample_dir() / "uois_tabletop").string(), "--out",
                            (tmp / "out").string(), "--select", "420,260", "--video",
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

}  // namespace
