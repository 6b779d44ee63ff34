// `wul3d view`: under a virtual X server (Xvfb, Mesa's software OpenGL) the viewer plays
// three sample frames, writes its window to a PNG and exits 0; the picture is not blank and
// its clusters panel shows the cluster colours (wul3d::cluster_color) where the frame has
// points. Without a display it says so in one line and exits 2.
// Needs xvfb-run (Debian's xvfb and xauth; scripts/install-deps.sh installs them): without it
// the screenshot test fails rather than skips, so a missing package cannot pass unseen.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_support.hpp"
#include "wul3d/io.hpp"
#include "wul3d/visualization.hpp"

#ifndef WUL3D_VIEWER_BUILT
#error "cmake/Viewer.cmake defines WUL3D_VIEWER_BUILT for this test"
#endif

namespace {

namespace fs = std::filesystem;
using wul3d::test::CommandResult;
using wul3d::test::cli_path;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;

/// Runs argv[0] (looked up in PATH) with `env` set (a value) or unset (nullopt).
CommandResult run_with_env(const std::vector<std::string>& args,
                           const std::vector<wul3d::test::EnvChange>& env) {
    return wul3d::test::run_command(args, env);
}

bool in_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::stringstream ss(path ? path : "");
    std::string dir;
    while (std::getline(ss, dir, ':'))
        if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
    return false;
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(ViewCommand, NoDisplay_OneLineExitTwo) {
    const auto r = run_with_env(
        {cli_path().string(), "view", (sample_dir() / "uois_tabletop").string()},
        {{"DISPLAY", std::nullopt}, {"WAYLAND_DISPLAY", std::nullopt}});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    const char* expected = WUL3D_VIEWER_BUILT ? "no display" : "built without viewer support";
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
}

TEST(ViewCommand, ScreenshotWithoutExitAfter_IsABadParameter) {
    const auto r = run_with_env({cli_path().string(), "view",
                                 (sample_dir() / "uois_tabletop").string(), "--screenshot",
                                 "x.png"},
                                {{"DISPLAY", std::nullopt}});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
}

#if WUL3D_VIEWER_BUILT
TEST(ViewCommand, ScreenshotUnderXvfb_ClusterColoursWhereTheObjectsAre) {
    ASSERT_TRUE(in_path("xvfb-run")) << "xvfb-run not found: install xvfb and xauth "
                                        "(scripts/install-deps.sh)";
    TempDir tmp;
    const fs::path shot = tmp / "view.png";
    const fs::path input = sample_dir() / "uois_tabletop";
    const auto r = run_with_env(
        {"xvfb-run", "-a", "-s", "-screen 0 1600x900x24", cli_path().string(), "view",
         input.string(), "--screenshot", shot.string(), "--exit-after", "3"},
        {{"LIBGL_ALWAYS_SOFTWARE", "1"},
         // Leak checking is off for this one process: Mesa's software driver keeps
         // allocations until exit and is unloaded before LeakSanitizer reports, so its
         // frames show as an unknown module that no suppression can name (and the slow
         // unwinder that would name them takes minutes under a software GL). The library
         // code the viewer runs is leak-checked by every other test.
         {"ASAN_OPTIONS", "detect_leaks=0"}});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    ASSERT_TRUE(fs::is_regular_file(shot)) << r.out;

    // "wul3d: screenshot FILE (WxH), clusters panel at X,Y WxH"
    const auto at = r.out.find("clusters panel at ");
    ASSERT_NE(at, std::string::npos) << r.out;
    int px = 0, py = 0, pw = 0, ph = 0;
    ASSERT_EQ(std::sscanf(r.out.c_str() + at, "clusters panel at %d,%d %dx%d", &px, &py, &pw, &ph),
              4)
        << r.out;

    const wul3d::ColorImage image = wul3d::read_color_image(shot.string());
    ASSERT_EQ(image.width, 1600);
    ASSERT_EQ(image.height, 900);
    ASSERT_GT(pw, 100);
    ASSERT_GT(ph, 75);
    ASSERT_LE(px + pw, image.width);
    ASSERT_LE(py + ph, image.height);

    // Not blank: many distinct colours over the whole window.
    std::set<int> colours;
    for (std::size_t p = 0; p < image.rgb.size(); p += 3 * 7)
        colours.insert(image.rgb[p] << 16 | image.rgb[p + 1] << 8 | image.rgb[p + 2]);
    EXPECT_GT(colours.size(), 2000u);

    // The third frame played is image_0005. Where it has depth in range (0.2-4.5 m, the
    // default) the panel must show cluster colours (eq. 9 mixes them where the scenes of the
    // three frames differ, so only a share is pure); where it has none, grey.
    const wul3d::DepthImage depth =
        wul3d::read_depth_png((input / "image_0005" / "depth.png").string(), 0.001f);
    std::vector<std::array<std::uint8_t, 3>> palette;
    for (int j = 0; j < 7; ++j) palette.push_back(wul3d::cluster_color(j));
    std::vector<int> hits(palette.size(), 0);
    int with_depth = 0, pure = 0, without_depth = 0, grey = 0;
    for (int y = 2; y < ph - 2; ++y) {
        for (int x = 2; x < pw - 2; ++x) {
            const int u = x * depth.width / pw, v = y * depth.height / ph;
            const float z = depth.data[static_cast<std::size_t>(v) * depth.width + u] * 0.001f;
            const std::uint8_t* c =
                &image.rgb[3 * (static_cast<std::size_t>(py + y) * image.width + px + x)];
            if (z >= 0.2f && z <= 4.5f) {
                ++with_depth;
                for (std::size_t j = 0; j < palette.size(); ++j) {
                    if (std::abs(c[0] - palette[j][0]) <= 12 && std::abs(c[1] - palette[j][1]) <= 12 &&
                        std::abs(c[2] - palette[j][2]) <= 12) {
                        ++pure;
                        ++hits[j];
                        break;
                    }
                }
            } else {
                ++without_depth;
                if (std::abs(c[0] - c[1]) <= 8 && std::abs(c[1] - c[2]) <= 8) ++grey;
            }
        }
    }
    ASSERT_GT(with_depth, pw * ph / 2);
    EXPECT_GT(pure, with_depth / 5) << pure << " of " << with_depth << " pixels with depth";
    EXPECT_GE(std::count_if(hits.begin(), hits.end(), [](int n) { return n > 200; }), 4);
    if (without_depth > 500) {
        EXPECT_GT(grey, without_depth * 7 / 10);
    }
}
#endif

}  // namespace

// `view --camera freenect` under fakenect: the live path of the viewer plays the replayed
// sample frames (exported with export-fakenect) and writes its screenshot.
TEST(ViewCommand, LiveCameraUnderFakenect_PlaysAndScreenshots) {
    if (!WUL3D_VIEWER_BUILT) GTEST_SKIP() << "built without viewer support";
    ASSERT_TRUE(in_path("xvfb-run")) << "xvfb-run not found (scripts/install-deps.sh)";
    ASSERT_TRUE(in_path("fakenect")) << "fakenect not found: install libfreenect-bin";
    TempDir tmp;
    const fs::path dump = tmp / "dump", shot = tmp / "live.png";
    const CommandResult e = wul3d::test::run_cli(
        {"export-fakenect", (sample_dir() / "uois_tabletop").string(), dump.string()});
    ASSERT_EQ(e.exit_code, 0) << e.err;
    const auto r = run_with_env(
        {"timeout", "120", "xvfb-run", "-a", "-s", "-screen 0 1600x900x24", "fakenect",
         dump.string(), cli_path().string(), "view", "--camera", "freenect", "--lossless",
         "--screenshot", shot.string(), "--exit-after", "3"},
        {{"LIBGL_ALWAYS_SOFTWARE", "1"}, {"ASAN_OPTIONS", "detect_leaks=0"}});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_TRUE(fs::is_regular_file(shot)) << r.out;
    EXPECT_NE(r.out.find("clusters panel at "), std::string::npos) << r.out;
}
