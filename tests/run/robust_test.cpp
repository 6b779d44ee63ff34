// run_sequence under hostile conditions (issue 24): summary.json in every ending, frame
// statistics streamed to frames.jsonl, and resident memory flat over a 100,000-frame run.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"
#include "wul3d/run.hpp"

// Under AddressSanitizer freed memory waits in a quarantine (256 MB by default) before it
// is reused, which would read as growth: a small one here. Without ASan this is unused.
extern "C" const char* __asan_default_options() { return "quarantine_size_mb=1"; }

namespace wul3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

nlohmann::json read_json(const fs::path& p) {
    std::ifstream f(p);
    return nlohmann::json::parse(f);
}

std::size_t count_lines(const fs::path& p) {
    std::ifstream f(p);
    std::size_t n = 0;
    for (std::string line; std::getline(f, line);) ++n;
    return n;
}

/// Resident memory now, in kB (/proc/self/statm: pages).
long rss_kb() {
    std::ifstream statm("/proc/self/statm");
    long size = 0, resident = 0;
    statm >> size >> resident;
    return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

/// An 8 x 8 frame: a tilted surface 1-1.5 m away with a box on it, so that every stage runs.
void write_tiny_frame(const fs::path& depth, const fs::path& color) {
    DepthImage d;
    d.width = d.height = 8;
    d.scale_m_per_unit = 0.001f;
    ColorImage c;
    c.width = c.height = 8;
    for (int v = 0; v < 8; ++v)
        for (int u = 0; u < 8; ++u) {
            const bool box = u >= 3 && u <= 5 && v >= 2 && v <= 4;
            d.data.push_back(static_cast<std::uint16_t>(box ? 900 : 1000 + 60 * v));
            for (int ch = 0; ch < 3; ++ch)
                c.rgb.push_back(static_cast<std::uint8_t>(box ? 40 + 80 * ch : 180));
        }
    write_depth_png(depth.string(), d);
    write_color_png(color.string(), c);
}

/// A TUM sequence of `n` frames, all the same 8 x 8 images and the same time stamp: each frame
/// rewrites the same OUT/<stamp>/, so the disk stays small whatever n.
fs::path tiny_tum(const fs::path& dir, std::size_t n) {
    fs::create_directories(dir / "rgb");
    fs::create_directories(dir / "depth");
    write_tiny_frame(dir / "depth" / "d.png", dir / "rgb" / "c.png");
    std::ofstream(dir / "rgb.txt") << "1.000000 rgb/c.png\n";
    std::ofstream depth(dir / "depth.txt");
    for (std::size_t i = 0; i < n; ++i) depth << "1.000000 depth/d.png\n";
    return dir;
}

RunOptions tiny_run(const fs::path& input, const fs::path& out) {
    RunOptions o;
    o.feed.input = input.string();
    o.feed.source.intrinsics = PinholeIntrinsics{0, 0, 8.0, 8.0, 3.5, 3.5};
    o.out_dir = out.string();
    o.params.decimation = 1;
    o.params.cluster.k = 3;
    o.params.segmentation.min_points = 2;
    o.params.objects.min_points = 2;
    return o;
}

struct RssProbe : RunObserver {
    std::size_t at = 0;
    long first_kb = 0, last_kb = 0;
    void frame(const RunFrame& f) override {
        if (f.index == at) first_kb = rss_kb();
        last_kb = rss_kb();
    }
};

TEST(RunMemory, FlatOverALongRun) {
    // main kept every frame's statistics for summary.json: 1.6 KB a frame, 40 MB over the
    // 25,000 frames after the probe. Now they go to frames.jsonl and the medians keep a
    // bounded sample. (30,000 frames keep this test near 15 s on 2 cores: one thread, tmpfs.
    // docs/OUTPUTS.md gives a 100,000-frame run of the command.)
    TempDir dir;
    constexpr std::size_t kFrames = 30000;
    const fs::path input = tiny_tum(dir / "seq", kFrames);
    // The frame folders on tmpfs where there is one: the disk's latency is not the subject.
    std::error_code ec;
    const fs::path out = fs::is_directory("/dev/shm", ec)
                             ? fs::path("/dev/shm") / ("wul3d_run_memory_" + std::to_string(::getpid()))
                             : dir / "out";
    struct Cleanup {
        fs::path p;
        ~Cleanup() {
            std::error_code e;
            fs::remove_all(p, e);
        }
    } cleanup{out};
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);  // no parallel region's start-up per 8 x 8 frame
    RssProbe probe;
    probe.at = 5000;  // after the first allocations and the medians' sample filling
    const RunSummary s = run_sequence(tiny_run(input, out), &probe);
    omp_set_num_threads(threads);
    ASSERT_EQ(s.frames, kFrames);
    EXPECT_EQ(count_lines(out / "frames.jsonl"), kFrames);
    const long growth_kb = probe.last_kb - probe.first_kb;
    std::cout << "RSS at frame " << probe.at << ": " << probe.first_kb << " kB, at frame "
              << kFrames << ": " << probe.last_kb << " kB (" << growth_kb << " kB)\n";
    EXPECT_LT(growth_kb, 2048) << "resident memory grew over the run";
    EXPECT_FALSE(read_json(out / "summary.json").contains("per_frame"));
}

TEST(RunEndings, BadFrameStillWritesTheSummary) {
    TempDir dir;
    const fs::path seq = dir / "seq";
    for (const char* f : {"a", "b", "c"}) {
        fs::create_directories(seq / f);
        for (const auto& e : fs::directory_iterator(test::sample_dir() / "uois_tabletop" / "image_0000"))
            fs::copy_file(e.path(), seq / f / e.path().filename());
    }
    std::ofstream(seq / "c" / "depth.png", std::ios::trunc) << "\x89PNG\r\n\x1a\ntruncated";
    RunOptions o;
    o.feed.input = seq.string();
    o.out_dir = (dir / "out").string();
    EXPECT_THROW(run_sequence(o), InputError);
    const auto summary = read_json(dir / "out" / "summary.json");
    EXPECT_EQ(summary["stopped_by"], "error");
    EXPECT_EQ(summary["frames"], 2);
    EXPECT_NE(summary["error"].get<std::string>().find("c/depth.png"), std::string::npos);
    EXPECT_EQ(count_lines(dir / "out" / "frames.jsonl"), 2u);
    EXPECT_TRUE(fs::exists(dir / "out" / "b" / "objects.json"));
    EXPECT_FALSE(fs::exists(dir / "out" / "c"));
}

TEST(RunEndings, MissingTumFileStillWritesTheSummary) {
    TempDir dir;
    const fs::path seq = tiny_tum(dir / "seq", 3);
    std::ofstream(seq / "depth.txt", std::ios::app) << "2.000000 depth/missing.png\n";
    std::ofstream(seq / "rgb.txt", std::ios::app) << "2.000000 rgb/c.png\n";
    EXPECT_THROW(run_sequence(tiny_run(seq, dir / "out")), InputError);
    const auto summary = read_json(dir / "out" / "summary.json");
    EXPECT_EQ(summary["stopped_by"], "error");
    EXPECT_EQ(summary["frames"], 3);
    EXPECT_NE(summary["error"].get<std::string>().find("missing.png"), std::string::npos);
}

TEST(RunEndings, StopRequestIsASignalEnding) {
    TempDir dir;
    const fs::path seq = tiny_tum(dir / "seq", 50);
    RunOptions o = tiny_run(seq, dir / "out");
    int polls = 0;
    o.stop = [&polls] { return ++polls > 3; };
    const RunSummary s = run_sequence(o);
    EXPECT_EQ(s.stopped_by, "signal");
    const auto summary = read_json(dir / "out" / "summary.json");
    EXPECT_EQ(summary["stopped_by"], "signal");
    EXPECT_TRUE(summary["error"].is_null());
    EXPECT_EQ(count_lines(dir / "out" / "frames.jsonl"), s.frames);
}

TEST(RunOutputs, OutNeverTheInputNorAroundIt) {
    TempDir dir;
    const fs::path seq = tiny_tum(dir / "seq", 2);
    for (const fs::path& out : {seq, seq / "out", dir.path()}) {
        RunOptions o = tiny_run(seq, out);
        EXPECT_THROW(run_sequence(o), InputError) << out;
    }
    EXPECT_FALSE(fs::exists(seq / "out"));
    EXPECT_EQ(test::list_files(seq).size(), 4u);  // rgb.txt, depth.txt and the two images
}

TEST(RunOutputs, ForeignFilesRefusedOrKept) {
    TempDir dir;
    const fs::path seq = tiny_tum(dir / "seq", 2);
    const fs::path out = dir / "out";
    fs::create_directories(out / "1.000000");
    std::ofstream(out / "notes.txt") << "mine\n";
    RunOptions o = tiny_run(seq, out);
    EXPECT_THROW(run_sequence(o), InputError);
    EXPECT_FALSE(fs::exists(out / "summary.json"));
    o.overwrite = true;
    std::ofstream(out / "1.000000" / "mine.png") << "mine\n";
    run_sequence(o);
    EXPECT_TRUE(fs::exists(out / "notes.txt"));
    EXPECT_TRUE(fs::exists(out / "1.000000" / "mine.png"));
    EXPECT_TRUE(fs::exists(out / "1.000000" / "labels.png"));
    // A run into an output folder of wul3d's own needs no --overwrite.
    fs::remove(out / "notes.txt");
    fs::remove(out / "1.000000" / "mine.png");
    o.overwrite = false;
    EXPECT_NO_THROW(run_sequence(o));
}

TEST(RunOutputs, FrameNamesCannotBeWul3dsFiles) {
    for (const char* bad : {"summary.json", "frames.jsonl", ".hidden", "..", "", "a/b"})
        EXPECT_THROW(check_frame_name(bad), InputError) << bad;
    EXPECT_THROW(check_frame_name(std::string(256, 'a')), InputError);
    EXPECT_NO_THROW(check_frame_name(std::string(255, 'a')));
    EXPECT_NO_THROW(check_frame_name("1305031102.175304"));
}

}  // namespace
}  // namespace wul3d
