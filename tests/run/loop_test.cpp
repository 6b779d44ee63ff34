// The library's run loop (run.hpp) and output helpers (output.hpp) on the shipped samples:
// what run_sequence writes, what its observer hears, a stop request, and that `wul3d run`
// writes the same bytes as the library call.
#include "wul3d/run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"
#include "wul3d/threads.hpp"
#include "wul3d/visualization.hpp"

namespace wul3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

RunOptions sample_run(const fs::path& out) {
    RunOptions o;
    o.feed.input = (test::sample_dir() / "uois_tabletop").string();
    o.out_dir = out.string();
    return o;
}

struct Recorder : RunObserver {
    std::size_t total = 99;
    std::vector<std::string> names;
    std::vector<std::size_t> indices;
    bool done = false, finished_after_done = false;
    void started(std::size_t t) override { total = t; }
    void frame(const RunFrame& f) override {
        names.push_back(f.name);
        indices.push_back(f.index);
        EXPECT_EQ(f.result.labels.width, f.frame.depth.width);
        EXPECT_GT(f.fps, 0.0);
        EXPECT_TRUE(fs::is_directory(fs::path(out) / f.name)) << "written before the call";
    }
    void frames_done() override { done = true; }
    void finished(const RunSummary&) override {
        finished_after_done = done && fs::exists(fs::path(out) / "summary.json");
    }
    std::string out;
};

TEST(RunSequence, WritesEveryFrameAndTheSummary_ObserverHearsEach) {
    TempDir dir;
    RunOptions o = sample_run(dir / "out");
    Recorder rec;
    rec.out = o.out_dir;
    const RunSummary s = run_sequence(o, &rec);
    std::size_t n = 0;  // the frame folders of the sample
    for (const auto& e : fs::directory_iterator(test::sample_dir() / "uois_tabletop"))
        n += fs::exists(e.path() / "depth.png");
    EXPECT_EQ(s.frames, rec.names.size());
    EXPECT_EQ(rec.total, s.frames);
    EXPECT_EQ(s.frames, n);
    EXPECT_GE(n, 2u);
    EXPECT_EQ(s.stopped_by, "end");
    EXPECT_TRUE(rec.finished_after_done);
    for (std::size_t i = 0; i < rec.names.size(); ++i) {
        EXPECT_EQ(rec.indices[i], i);
        for (const char* f : {"labels.png", "colors.png", "objects.png", "objects.json"})
            EXPECT_TRUE(fs::exists(dir / "out" / rec.names[i] / f)) << rec.names[i] << "/" << f;
    }
    const auto summary = nlohmann::json::parse(slurp(dir / "out" / "summary.json"));
    EXPECT_EQ(summary["frames"].get<std::size_t>(), s.frames);
    // One line per frame in frames.jsonl, in order; summary.json keeps none of them.
    std::ifstream lines(dir / "out" / "frames.jsonl");
    std::size_t i = 0;
    for (std::string line; std::getline(lines, line); ++i)
        if (i < rec.names.size()) {
            EXPECT_EQ(nlohmann::json::parse(line)["name"], rec.names[i]);
        }
    EXPECT_EQ(i, s.frames);
    EXPECT_FALSE(summary.contains("per_frame"));
    EXPECT_EQ(summary["frames_file"], "frames.jsonl");
    EXPECT_EQ(summary["parameters"]["preset"], "default");
    EXPECT_EQ(summary["input"], o.feed.input);
}

TEST(RunSequence, MaxFramesAndStopEndTheRun) {
    TempDir dir;
    RunOptions o = sample_run(dir / "a");
    o.max_frames = 1;
    EXPECT_EQ(run_sequence(o).stopped_by, "frames");
    EXPECT_EQ(test::list_files(dir / "a").size(), 6u);  // 4 of one frame, summary, frames.jsonl

    RunOptions stop = sample_run(dir / "b");
    int polls = 0;
    stop.stop = [&polls] { return ++polls > 1; };  // after the first frame
    const RunSummary s = run_sequence(stop);
    EXPECT_EQ(s.stopped_by, "signal");
    EXPECT_EQ(s.frames, 1u);
}

TEST(RunSequence, SameBytesAsTheCommand) {
    TempDir dir;
    RunOptions o = sample_run(dir / "lib");
    o.select = std::make_pair(320, 240);
    o.files.overlay = true;
    run_sequence(o);
    const auto cli = test::run_cli({"run", o.feed.input, "-o", (dir / "cli").string(), "-q",
                                    "--select", "320,240", "--overlay"});
    ASSERT_EQ(cli.exit_code, 0) << cli.err;
    const auto files = test::list_files(dir / "lib");
    ASSERT_EQ(files, test::list_files(dir / "cli"));
    for (const std::string& f : files) {
        if (f == "summary.json" || f == "frames.jsonl") continue;  // timings differ
        EXPECT_EQ(slurp(dir / "lib" / f), slurp(dir / "cli" / f)) << f;
    }
}

// The run's threads shared out (summary.json): on 8 threads 2 read, 2 write, 4 run the
// stages; on 2 one of each. The outputs are the same bytes either way.
TEST(RunSequence, ThreadsShared_ReadersAsManyAsWriters_SameBytes) {
    const int saved = num_threads();
    TempDir dir;
    const std::pair<int, std::array<int, 3>> cases[] = {{2, {1, 1, 1}}, {8, {2, 2, 4}}};
    for (const auto& [threads, split] : cases) {
        set_num_threads(threads);
        run_sequence(sample_run(dir / std::to_string(threads)));
        const nlohmann::json summary =
            nlohmann::json::parse(slurp(dir / std::to_string(threads) / "summary.json"));
        EXPECT_EQ(summary["threads"], threads);
        EXPECT_EQ(summary["threads_readers"], split[0]) << threads;
        EXPECT_EQ(summary["threads_writers"], split[1]) << threads;
        EXPECT_EQ(summary["threads_stages"], split[2]) << threads;
    }
    set_num_threads(saved);
    const auto files = test::list_files(dir / "2");
    ASSERT_EQ(files, test::list_files(dir / "8"));
    for (const std::string& f : files) {
        if (f == "summary.json" || f == "frames.jsonl") continue;  // timings differ
        EXPECT_EQ(slurp(dir / "2" / f), slurp(dir / "8" / f)) << f;
    }
}

TEST(RunSequence, OutputsWritesOnlyTheFilesAskedForWithTheSameBytes) {
    // --outputs objects,json: the two files, byte for byte those of the default run, and
    // summary.json says which files the frames hold.
    TempDir dir;
    RunOptions all = sample_run(dir / "all");
    all.max_frames = 2;
    run_sequence(all);
    RunOptions some = sample_run(dir / "some");
    some.max_frames = 2;
    some.files = parse_output_files("objects,json");
    run_sequence(some);
    std::vector<std::string> expected;
    for (const std::string& f : test::list_files(dir / "all")) {
        const std::string name = fs::path(f).filename().string();
        if (name == "objects.png" || name == "objects.json") expected.push_back(f);
        if (name != "labels.png" && name != "colors.png" && f.find('/') != std::string::npos &&
            name != "objects.png" && name != "objects.json")
            ADD_FAILURE() << "unexpected file of the default run: " << f;
    }
    expected.insert(expected.end(), {"frames.jsonl", "summary.json"});
    std::sort(expected.begin(), expected.end());
    auto written = test::list_files(dir / "some");
    std::sort(written.begin(), written.end());
    EXPECT_EQ(written, expected);
    for (const std::string& f : expected) {
        if (f == "summary.json" || f == "frames.jsonl") continue;
        EXPECT_EQ(slurp(dir / "some" / f), slurp(dir / "all" / f)) << f;
    }
    EXPECT_NE(slurp(dir / "some" / "summary.json").find("\"outputs\": \"objects,json\""),
              std::string::npos);
    EXPECT_NE(slurp(dir / "all" / "summary.json").find("\"outputs\": \"labels,colors,objects,json\""),
              std::string::npos);
}

// The command makes eq. 9's colours only for a file or video that shows them: with
// --outputs objects,json their stage is 0 in summary.json, and the objects are the bytes of
// the default run; with colors.png or cloud.ply it runs.
TEST(RunSequence, CommandWithoutColourFiles_MakesNoColours_TheSameObjects) {
    TempDir dir;
    const std::string input = (test::sample_dir() / "uois_tabletop").string();
    auto colours_ms = [&](const std::string& out) {
        const auto summary = nlohmann::json::parse(slurp(dir / out / "summary.json"));
        return summary.at("stage_ms_median").at("colors").get<double>();
    };
    for (const auto& [out, outputs] : std::vector<std::pair<std::string, std::string>>{
             {"all", "labels,colors,objects,json"}, {"objects", "objects,json"}, {"ply", "objects,ply"}}) {
        const auto r = test::run_cli({"run", input, "-o", (dir / out).string(), "-q", "--frames", "2",
                                      "--outputs", outputs});
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    EXPECT_GT(colours_ms("all"), 0.0);
    EXPECT_EQ(colours_ms("objects"), 0.0);
    EXPECT_GT(colours_ms("ply"), 0.0);  // cloud.ply's points take their colours
    for (const char* frame : {"image_0000", "image_0002"})
        for (const char* f : {"objects.png", "objects.json"})
            EXPECT_EQ(slurp(dir / "objects" / frame / f), slurp(dir / "all" / frame / f)) << frame << "/" << f;
}

TEST(RunSequence, OutputNamesAreParsedStrictly) {
    const OutputFiles f = parse_output_files("overlay,labels,ply");
    EXPECT_TRUE(f.labels && f.ply && f.overlay);
    EXPECT_FALSE(f.colors || f.objects || f.json);
    EXPECT_EQ(output_files_names(f), "labels,ply,overlay");
    EXPECT_EQ(output_files_names(OutputFiles{}), "labels,colors,objects,json");
    for (const char* bad : {"", "objects,", ",objects", "objects,objects", "object", "OBJECTS",
                            "objects json"})
        EXPECT_THROW(parse_output_files(bad), ParamError) << bad;
    // The command: its flag named, exit 2, nothing written.
    TempDir dir;
    const auto r = test::run_cli({"run", (test::sample_dir() / "uois_tabletop").string(), "-o",
                                  (dir / "out").string(), "--outputs", "objects,masks"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--outputs 'objects,masks': 'masks' is not one of labels, colors"),
              std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "image_0000"));
}

TEST(RunSequence, OverlayTintsOutlinesAndNumbersTheObjectsOverTheColour) {
    TempDir dir;
    RunOptions o = sample_run(dir / "out");
    o.max_frames = 1;
    o.files.overlay = true;
    run_sequence(o);
    const fs::path frame = test::sample_dir() / "uois_tabletop" / "image_0000";
    const ColorImage colour = read_color_image((frame / "color.png").string());
    const ColorImage overlay = read_color_image((dir / "out" / "image_0000" / "overlay.png").string());
    const LabelImage objects = read_label_png((dir / "out" / "image_0000" / "objects.png").string());
    ASSERT_EQ(overlay.width, colour.width);
    ASSERT_EQ(overlay.height, colour.height);
    const int W = colour.width, H = colour.height;
    // Each object's id tag: up to 45 x 32 px from its 2D box's top-left corner.
    std::vector<std::uint8_t> tag(static_cast<std::size_t>(W) * H, 0);
    std::map<int, std::pair<int, int>> corner;
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u)
            if (const int l = objects.labels[static_cast<std::size_t>(v) * W + u]) {
                auto [it, fresh] = corner.try_emplace(l, u, v);
                if (!fresh) it->second.first = std::min(it->second.first, u);
            }
    ASSERT_GE(corner.size(), 5u);
    for (const auto& [id, c] : corner)
        for (int v = c.second; v < std::min(H, c.second + 32); ++v)
            for (int u = c.first; u < std::min(W, c.first + 45); ++u) tag[static_cast<std::size_t>(v) * W + u] = 1;
    std::size_t tinted = 0, inside = 0, untouched = 0, outside = 0, outline = 0;
    std::map<int, int> white_in_tag;
    for (int v = 1; v < H - 1; ++v)
        for (int u = 1; u < W - 1; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            const int l = objects.labels[p];
            const bool inner = objects.labels[p - 1] == l && objects.labels[p + 1] == l &&
                               objects.labels[p - W] == l && objects.labels[p + W] == l;
            const std::uint8_t* c = &colour.rgb[3 * p];
            const std::uint8_t* t = &overlay.rgb[3 * p];
            const bool white = t[0] == 255 && t[1] == 255 && t[2] == 255;
            if (tag[p]) {
                if (l != 0 && t[0] > 200 && t[1] > 200 && t[2] > 200) ++white_in_tag[l];
                continue;
            }
            if (l != 0 && !inner) {
                outline += white;  // the border of an object: white
                continue;
            }
            if (!inner) continue;
            if (l == 0) {
                ++outside;
                untouched += t[0] == c[0] && t[1] == c[1] && t[2] == c[2];
            } else {
                ++inside;
                const auto oc = object_color(l);
                bool ok = true;
                for (int q = 0; q < 3; ++q) ok &= std::abs(t[q] - (0.45 * c[q] + 0.55 * oc[q])) <= 1.0;
                tinted += ok;
            }
        }
    EXPECT_GT(inside, 20000u);
    EXPECT_EQ(tinted, inside);     // outside the tags and the box lines (boxes are off)
    EXPECT_EQ(untouched, outside);
    EXPECT_GT(outline, 1000u);
    // The ids: white text in the tags of most objects (a tag over a small object's corner
    // may fall on the background).
    EXPECT_GE(white_in_tag.size(), corner.size() / 2);
}

TEST(RunSequence, BadInputIsAnInputError_NoOutputFolder) {
    TempDir dir;
    RunOptions o = sample_run(dir / "out");
    o.feed.input = (dir / "missing").string();
    EXPECT_THROW(run_sequence(o), InputError);
    EXPECT_FALSE(fs::exists(dir / "out"));
    o.feed.camera = "freenect";
    EXPECT_THROW(run_sequence(o), ParamError);  // both an input and a camera
}

TEST(WriteFolderAtomic, CompleteOrAbsent) {
    TempDir dir;
    const std::string target = (dir / "frame").string();
    write_folder_atomic(target, [](const std::string& tmp) {
        write_text_file(tmp + "/a.txt", "one\n");
    });
    EXPECT_EQ(slurp(dir / "frame" / "a.txt"), "one\n");
    EXPECT_THROW(write_folder_atomic(target,
                                     [](const std::string& tmp) {
                                         write_text_file(tmp + "/b.txt", "two\n");
                                         throw IoError("disk full");
                                     }),
                 IoError);
    // The old folder stays as it was and no partial folder is left.
    EXPECT_EQ(test::list_files(dir.path()), std::vector<std::string>{"frame/a.txt"});
    // Replacing: the writer's own files (a.txt, b.txt) go, anything else in the folder stays.
    write_text_file((dir / "frame" / "mine.txt").string(), "the user's\n");
    write_folder_atomic(
        target, [](const std::string& tmp) { write_text_file(tmp + "/b.txt", "two\n"); },
        {"a.txt", "b.txt"});
    EXPECT_EQ(test::list_files(dir.path()), (std::vector<std::string>{"frame/b.txt", "frame/mine.txt"}));
}

TEST(WriteFileAtomic, UnwritablePathIsAnIoErrorNamingIt) {
    TempDir dir;
    const std::string path = (dir / "no" / "such" / "file.bin").string();
    try {
        write_file_atomic(path, "x", 1);
        FAIL() << "no error";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_TRUE(test::list_files(dir.path()).empty());
}

}  // namespace
}  // namespace wul3d
