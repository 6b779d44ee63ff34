// `wul3d view`: under a virtual X server (Xvfb, Mesa's software OpenGL) the viewer plays
// three sample frames, writes its window to a PNG and exits 0; the picture is not blank and
// its clusters panel shows the cluster colours (wul3d::cluster_color) where the frame has
// points; its objects panel shows each object's colour (wul3d::object_color) on the object
// and not on the table; a click (--select) selects the object under it and follows it. Without a display it says so in one line and exits 2.
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
#include <map>
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

/// `xvfb-run` on a free display with a 1600x900 screen, its X authority file in `tmp`.
/// Given its own file, xvfb-run makes and removes no temporary directory of its own: once,
/// in CI, its `rm -r` of that directory failed after the viewer had exited, and xvfb-run
/// then exits 5 in place of the viewer's status. The test's TempDir removes the file.
std::vector<std::string> xvfb_run(const TempDir& tmp) {
    return {"xvfb-run", "-a", "-f", (tmp / "Xauthority").string(), "-s", "-screen 0 1600x900x24"};
}

/// `prefix` followed by `rest`.
std::vector<std::string> concat(std::vector<std::string> prefix, const std::vector<std::string>& rest) {
    prefix.insert(prefix.end(), rest.begin(), rest.end());
    return prefix;
}

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
        concat(xvfb_run(tmp), {cli_path().string(), "view", input.string(), "--screenshot",
                               shot.string(), "--exit-after", "3"}),
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

// ---- objects mode --------------------------------------------------------------------------

/// The viewer's screenshot under Xvfb after `frames` frames of `input`, with `extra`
/// arguments; the rectangle of its output's "PANEL panel at X,Y WxH".
struct Shot {
    CommandResult run;
    wul3d::ColorImage image;
    int px = 0, py = 0, pw = 0, ph = 0;
};

Shot view_screenshot(const TempDir& tmp, const fs::path& input, const std::string& name,
                     int frames, const std::vector<std::string>& extra, const std::string& panel) {
    Shot s;
    const fs::path shot = tmp / (name + ".png");
    std::vector<std::string> args =
        concat(xvfb_run(tmp), {cli_path().string(), "view", input.string(), "--screenshot",
                               shot.string(), "--exit-after", std::to_string(frames)});
    args.insert(args.end(), extra.begin(), extra.end());
    s.run = run_with_env(args, {{"LIBGL_ALWAYS_SOFTWARE", "1"}, {"ASAN_OPTIONS", "detect_leaks=0"}});
    if (s.run.exit_code != 0 || !fs::is_regular_file(shot)) return s;
    const auto at = s.run.out.find(panel + " panel at ");
    if (at == std::string::npos ||
        std::sscanf(s.run.out.c_str() + at + panel.size(), " panel at %d,%d %dx%d", &s.px, &s.py,
                    &s.pw, &s.ph) != 4)
        return s;
    s.image = wul3d::read_color_image(shot.string());
    return s;
}

/// Frame pixels whose 5 x 5 neighbourhood holds one object label (or none): away from the
/// outlines, where the panel's scaling cannot mix two labels. -1 for mixed.
std::vector<int> interior_labels(const wul3d::LabelImage& objects) {
    const int W = objects.width, H = objects.height;
    std::vector<int> out(objects.labels.size(), -1);
    for (int v = 2; v < H - 2; ++v)
        for (int u = 2; u < W - 2; ++u) {
            const int l = objects.labels[static_cast<std::size_t>(v) * W + u];
            bool same = true;
            for (int dv = -2; dv <= 2 && same; ++dv)
                for (int du = -2; du <= 2 && same; ++du)
                    same = objects.labels[static_cast<std::size_t>(v + dv) * W + u + du] == l;
            if (same) out[static_cast<std::size_t>(v) * W + u] = l;
        }
    return out;
}

/// Marks -1 the pixels under each object's id tag: up to 45 x 32 px from its 2D box's
/// top-left corner (the tag of a two-digit id at 640x480 is about 30 x 25).
void drop_tags(const wul3d::LabelImage& objects, std::vector<int>& interior) {
    std::map<int, std::pair<int, int>> corner;  // id -> (u_min, v_min)
    for (int v = 0; v < objects.height; ++v)
        for (int u = 0; u < objects.width; ++u) {
            const int l = objects.labels[static_cast<std::size_t>(v) * objects.width + u];
            if (l == 0) continue;
            auto [it, fresh] = corner.try_emplace(l, u, v);
            if (!fresh) it->second.first = std::min(it->second.first, u);
        }
    for (const auto& [id, c] : corner)
        for (int v = c.second; v < std::min(objects.height, c.second + 32); ++v)
            for (int u = c.first; u < std::min(objects.width, c.first + 45); ++u)
                interior[static_cast<std::size_t>(v) * objects.width + u] = -1;
}

bool near_rgb(const std::uint8_t* c, const double* expect, int tolerance) {
    for (int q = 0; q < 3; ++q)
        if (std::abs(c[q] - expect[q]) > tolerance) return false;
    return true;
}

TEST(ViewCommand, ObjectsModeUnderXvfb_ObjectColoursOnTheObjectsNotOnTheTable) {
    ASSERT_TRUE(in_path("xvfb-run")) << "xvfb-run not found (scripts/install-deps.sh)";
    TempDir tmp;
    // The objects the viewer shows on its third frame (image_0005), from `wul3d run` on the
    // same frames with the same (default) parameters.
    const fs::path input = sample_dir() / "uois_tabletop";
    const auto ran = wul3d::test::run_cli({"run", input.string(), "--out", (tmp / "run").string(), "-q"});
    ASSERT_EQ(ran.exit_code, 0) << ran.err;
    const wul3d::LabelImage objects = wul3d::read_label_png((tmp / "run" / "image_0005" / "objects.png").string());
    const wul3d::ColorImage colour = wul3d::read_color_image((input / "image_0005" / "color.png").string());
    const wul3d::DepthImage depth = wul3d::read_depth_png((input / "image_0005" / "depth.png").string(), 0.001f);
    std::vector<int> interior = interior_labels(objects);
    drop_tags(objects, interior);

    const Shot s = view_screenshot(tmp, input, "objects", 3, {}, "objects");
    ASSERT_EQ(s.run.exit_code, 0) << s.run.out << s.run.err;
    ASSERT_GT(s.pw, 100) << s.run.out;
    ASSERT_GT(s.ph, 75) << s.run.out;
    ASSERT_LE(s.px + s.pw, s.image.width);
    ASSERT_LE(s.py + s.ph, s.image.height);

    // Each panel pixel against its frame pixel: inside object i, 45 % colour + 55 %
    // object_color(i); on the table and elsewhere off the objects, the frame's colour.
    std::map<int, int> on_object, tinted;  // per object id
    int table = 0, table_plain = 0, table_tinted = 0;
    for (int y = 0; y < s.ph; ++y) {
        for (int x = 0; x < s.pw; ++x) {
            const int u = (2 * x + 1) * objects.width / (2 * s.pw);
            const int v = (2 * y + 1) * objects.height / (2 * s.ph);
            const std::size_t p = static_cast<std::size_t>(v) * objects.width + u;
            const int l = interior[p];
            if (l < 0) continue;
            const std::uint8_t* c = &s.image.rgb[3 * (static_cast<std::size_t>(s.py + y) * s.image.width + s.px + x)];
            const std::uint8_t* f = &colour.rgb[3 * p];
            const auto tint = [&](int id) {
                const auto oc = wul3d::object_color(id);
                return std::array<double, 3>{0.45 * f[0] + 0.55 * oc[0], 0.45 * f[1] + 0.55 * oc[1],
                                             0.45 * f[2] + 0.55 * oc[2]};
            };
            if (l > 0) {
                ++on_object[l];
                tinted[l] += near_rgb(c, tint(l).data(), 20);
            } else if (depth.data[p] != 0) {
                ++table;
                const double plain[3] = {double(f[0]), double(f[1]), double(f[2])};
                table_plain += near_rgb(c, plain, 20);
                // Tinted like an object: no object's colour lies on the table.
                for (const auto& [id, n] : on_object) {
                    (void)n;
                    if (near_rgb(c, tint(id).data(), 12) && !near_rgb(c, plain, 12)) {
                        ++table_tinted;
                        break;
                    }
                }
            }
        }
    }
    ASSERT_GE(on_object.size(), 3u) << "objects in image_0005";
    for (const auto& [id, n] : on_object) {
        if (n < 100) continue;  // too small in the panel to count on
        EXPECT_GT(tinted[id], n * 8 / 10) << "object " << id << ": " << tinted[id] << " of " << n;
    }
    ASSERT_GT(table, s.pw * s.ph / 4);
    EXPECT_GT(table_plain, table * 9 / 10) << table_plain << " of " << table;
    EXPECT_LT(table_tinted, table / 100) << table_tinted << " of " << table;
}

TEST(ViewCommand, ObjectsModeUnderXvfb_AClickSelectsAnObjectAndFollowsIt) {
    ASSERT_TRUE(in_path("xvfb-run")) << "xvfb-run not found (scripts/install-deps.sh)";
    // Three frames of one scene moving: image_0000 shifted left by 0, 8 and 16 px (the
    // shipped frames are four different scenes, whose objects get new ids).
    TempDir tmp;
    const fs::path input = tmp / "moving";
    const fs::path source = sample_dir() / "uois_tabletop" / "image_0000";
    const char* frames[3] = {"frame_0", "frame_1", "frame_2"};
    for (int i = 0; i < 3; ++i) {
        wul3d::RgbdFrame f;
        f.name = frames[i];
        f.color = wul3d::read_color_image((source / "color.png").string());
        f.depth = wul3d::read_depth_png((source / "depth.png").string(), 0.001f);
        f.intrinsics = wul3d::read_intrinsics_json((source / "intrinsics.json").string()).intrinsics;
        const int W = f.width(), shift = 8 * i;
        for (int v = 0; v < f.height(); ++v)
            for (int u = 0; u < W; ++u) {
                const std::size_t to = static_cast<std::size_t>(v) * W + u;
                const bool in = u + shift < W;
                f.depth.data[to] = in ? f.depth.data[to + shift] : 0;
                for (int q = 0; q < 3; ++q) f.color.rgb[3 * to + q] = in ? f.color.rgb[3 * (to + shift) + q] : 0;
            }
        wul3d::write_frame_folder((input / frames[i]).string(), f);
    }
    const auto ran = wul3d::test::run_cli({"run", input.string(), "--out", (tmp / "run").string(), "-q"});
    ASSERT_EQ(ran.exit_code, 0) << ran.err;
    std::vector<wul3d::LabelImage> objects;
    for (const char* f : frames)
        objects.push_back(wul3d::read_label_png((tmp / "run" / f / "objects.png").string()));

    // Click the middle of the largest object of the first frame: the interior pixel nearest
    // its mean pixel.
    const wul3d::LabelImage& first = objects[0];
    std::map<int, std::size_t> count;
    for (const auto l : first.labels)
        if (l) ++count[l];
    ASSERT_FALSE(count.empty());
    const int id = std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
    double mu = 0, mv = 0;
    for (int v = 0; v < first.height; ++v)
        for (int u = 0; u < first.width; ++u)
            if (first.labels[static_cast<std::size_t>(v) * first.width + u] == id) mu += u, mv += v;
    mu /= static_cast<double>(count[id]);
    mv /= static_cast<double>(count[id]);
    const std::vector<int> interior = interior_labels(first);
    int cu = -1, cv = -1;
    double best = 1e30;
    for (int v = 0; v < first.height; ++v)
        for (int u = 0; u < first.width; ++u) {
            const double d = (u - mu) * (u - mu) + (v - mv) * (v - mv);
            if (interior[static_cast<std::size_t>(v) * first.width + u] == id && d < best)
                best = d, cu = u, cv = v;
        }
    ASSERT_GE(cu, 0);

    const Shot s = view_screenshot(tmp, input, "select", 3,
                                   {"--select", std::to_string(cu) + "," + std::to_string(cv)}, "objects");
    ASSERT_EQ(s.run.exit_code, 0) << s.run.out << s.run.err;
    // The click selected the object under it, and each frame after follows it with the
    // pixels `wul3d run` found for it.
    // The click lands on the screen pixel nearest the asked one: a 640-pixel frame shown
    // 412 pixels wide reaches every 1.55th frame pixel.
    const auto at = s.run.out.find("frame_0: clicked (");
    ASSERT_NE(at, std::string::npos) << s.run.out;
    int ku = -1, kv = -1, kid = -1;
    ASSERT_EQ(std::sscanf(s.run.out.c_str() + at, "frame_0: clicked (%d, %d): selected object %d",
                          &ku, &kv, &kid),
              3)
        << s.run.out;
    EXPECT_LE(std::abs(ku - cu), 2) << ku << " for " << cu;
    EXPECT_LE(std::abs(kv - cv), 2) << kv << " for " << cv;
    EXPECT_EQ(kid, id) << s.run.out;
    for (int i = 1; i < 3; ++i) {
        std::size_t n = 0;
        for (const auto l : objects[static_cast<std::size_t>(i)].labels) n += l == id;
        ASSERT_GT(n, 0u) << frames[i];
        const std::string line = std::string(frames[i]) + ": following object " + std::to_string(id) + ", " +
                                 std::to_string(n) + " px, tracked " + std::to_string(i + 1) + " frames\n";
        EXPECT_NE(s.run.out.find(line), std::string::npos) << line << "in\n" << s.run.out;
    }

    // On screen, the third frame's objects panel: the followed object tinted, the other
    // objects darkened like the rest.
    const wul3d::ColorImage colour = wul3d::read_color_image((input / "frame_2" / "color.png").string());
    std::vector<int> last = interior_labels(objects[2]);
    drop_tags(objects[2], last);
    const auto oc = wul3d::object_color(id);
    int on = 0, on_tinted = 0, others = 0, others_dark = 0;
    for (int y = 0; y < s.ph; ++y)
        for (int x = 0; x < s.pw; ++x) {
            const int u = (2 * x + 1) * colour.width / (2 * s.pw);
            const int v = (2 * y + 1) * colour.height / (2 * s.ph);
            const std::size_t p = static_cast<std::size_t>(v) * colour.width + u;
            const int l = last[p];
            if (l <= 0) continue;
            const std::uint8_t* c = &s.image.rgb[3 * (static_cast<std::size_t>(s.py + y) * s.image.width + s.px + x)];
            const std::uint8_t* f = &colour.rgb[3 * p];
            if (l == id) {
                ++on;
                const double t[3] = {0.45 * f[0] + 0.55 * oc[0], 0.45 * f[1] + 0.55 * oc[1], 0.45 * f[2] + 0.55 * oc[2]};
                on_tinted += near_rgb(c, t, 20);
            } else {
                ++others;
                const double d[3] = {f[0] / 4.0, f[1] / 4.0, f[2] / 4.0};
                others_dark += near_rgb(c, d, 12);
            }
        }
    ASSERT_GT(on, 100);
    EXPECT_GT(on_tinted, on * 8 / 10) << on_tinted << " of " << on;
    ASSERT_GT(others, 100);
    EXPECT_GT(others_dark, others * 8 / 10) << others_dark << " of " << others;
}

TEST(ViewCommand, SelectOutsideTheFrame_OneLineExitTwo) {
    ASSERT_TRUE(in_path("xvfb-run")) << "xvfb-run not found (scripts/install-deps.sh)";
    TempDir tmp;
    const auto r = run_with_env(
        concat(xvfb_run(tmp), {cli_path().string(), "view", (sample_dir() / "uois_tabletop").string(),
                               "--select", "700,10", "--exit-after", "1"}),
        {{"LIBGL_ALWAYS_SOFTWARE", "1"}, {"ASAN_OPTIONS", "detect_leaks=0"}});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("--select 700,10 is outside the 640x480 frame"), std::string::npos) << r.err;
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
        concat(concat({"timeout", "120"}, xvfb_run(tmp)),
               {"fakenect", dump.string(), cli_path().string(), "view", "--camera", "freenect",
                "--lossless", "--screenshot", shot.string(), "--exit-after", "3"}),
        {{"LIBGL_ALWAYS_SOFTWARE", "1"}, {"ASAN_OPTIONS", "detect_leaks=0"}});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_TRUE(fs::is_regular_file(shot)) << r.out;
    EXPECT_NE(r.out.find("clusters panel at "), std::string::npos) << r.out;
}
