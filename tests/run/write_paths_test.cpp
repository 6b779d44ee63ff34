// The command line's other ways to write and to fail (issue 46): every flag that names an
// output goes through the write guard (write_guard.hpp) against the command's own inputs; a
// --video that cannot be written is refused before the first frame, or ends the run with its
// summary.json; limits of threads, label counts and resolutions; names that are not UTF-8;
// duplicate TUM timestamps; and the messages of bad numbers. Every command runs under
// `timeout 60`, so a hang fails as exit 124 instead of stalling the suite.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::CommandResult;
using wul3d::test::EnvChange;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;
using wul3d::test::copy_frame;
using wul3d::test::describe;
using wul3d::test::expect_one_line;
using wul3d::test::run_bounded;
using wul3d::test::slurp;
using wul3d::test::write_text;

/// The largest resident memory of any command this test process has run and waited for
/// (getrusage counts every waited descendant, so `timeout`'s child too), in MB.
double peak_child_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

fs::path tabletop() { return sample_dir() / "uois_tabletop"; }

/// Every entry under `dir` (links not followed): its kind and bytes, or a link's target.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> s;
    for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
        const std::string rel = fs::relative(it->path(), dir).string();
        const auto st = it->symlink_status();
        if (fs::is_symlink(st)) {
            s[rel] = "link " + fs::read_symlink(it->path()).string();
        } else if (fs::is_directory(st)) {
            s[rel] = "folder";
        } else {
            s[rel] = "file " + slurp(it->path());
        }
    }
    return s;
}

nlohmann::json read_json(const fs::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

// ---- item 4: every flag that writes, against its own input ------------------------------

/// A recording of two frames with a label image each, a prediction folder and a symlink to
/// an input file, all under `tmp`/data, so that one snapshot covers every input.
struct Inputs {
    fs::path data, rec, frame, pred, link;
    explicit Inputs(const TempDir& tmp)
        : data(tmp / "data"), rec(data / "rec"), frame(rec / "image_0000"), pred(data / "pred"),
          link(data / "link.png") {
        for (const char* name : {"image_0000", "image_0002"}) {
            copy_frame(tabletop() / name, rec / name);
            wul3d::LabelImage l;
            l.width = 640;
            l.height = 480;
            l.labels.assign(640 * 480, 0);
            for (int v = 100; v < 200; ++v)
                for (int u = 100; u < 200; ++u) l.labels[static_cast<std::size_t>(v) * 640 + u] = 1;
            wul3d::write_label_png((rec / name / "label.png").string(), l);
            fs::create_directories(pred / name);
            wul3d::write_label_png((pred / name / "objects.png").string(), l);
        }
        fs::create_symlink(frame / "depth.png", link);
    }
};

TEST(WritePaths, EveryFlagThatWritesRefusesItsOwnInput) {
    TempDir tmp;
    const Inputs in(tmp);
    const auto before = snapshot(in.data);
    const std::string rec = in.rec.string(), frame = in.frame.string(), pred = in.pred.string();
    const std::string depth = (in.frame / "depth.png").string(), link = in.link.string();
    const std::string label = (in.frame / "label.png").string();
    const std::string out = (tmp / "out").string();
    const std::vector<EnvChange> no_display = {{"DISPLAY", std::nullopt},
                                               {"WAYLAND_DISPLAY", std::nullopt}};
    struct Case {
        std::vector<std::string> args;
        std::string flag;  // in the error line
        std::vector<EnvChange> env;
    };
    std::vector<Case> cases;
    // The output folder of run, record and export-fakenect: the input, a folder inside it,
    // a file of it, a link to one of its files.
    for (const std::string& target : {rec, frame + "/out", depth, link}) {
        cases.push_back({{"run", rec, "--out", target, "-q"}, "output folder", {}});
        cases.push_back({{"export-fakenect", rec, target}, "DUMPDIR", {}});
        // Under fakenect the dump is record's input: no camera is opened before the refusal.
        cases.push_back({{"record", "--camera", "freenect", "--out", target, "-q"}, "--out",
                         {{"FAKENECT_PATH", rec}}});
    }
    // The files of run --video, view --screenshot, bench --csv and eval --json: a file of
    // the input (a name the flag would take), the input folder, a link to an input file.
    const std::string video = frame + "/clip.mp4";
    write_text(in.frame / "clip.mp4", "the user's video");
    for (const std::string& target : {video, rec, link, depth}) {
        cases.push_back({{"run", rec, "--out", out, "-q", "--video", target}, "--video", {}});
        cases.push_back({{"view", rec, "--exit-after", "1", "--screenshot", target}, "", no_display});
        cases.push_back({{"bench", frame, "--k", "2", "--frames", "1", "--passes", "1", "--csv", target},
                         "--csv", {}});
    }
    for (const std::string& target : {label, (in.pred / "image_0000" / "objects.png").string(), rec, pred, link})
        cases.push_back({{"eval", pred, rec, "--json", target}, "--json", {}});
    for (const Case& c : cases) {
        const auto snap = snapshot(in.data);
        const CommandResult r = run_bounded(c.args, c.env);
        std::string cmd;
        for (const auto& a : c.args) cmd += a + " ";
        SCOPED_TRACE(cmd);
        // view: the guard, or a build without the viewer; either says so in one line.
        expect_one_line(r, 2, c.flag.empty() ? std::vector<std::string>{} : std::vector<std::string>{c.flag});
        EXPECT_TRUE(snapshot(in.data) == snap) << "the input changed";
        EXPECT_FALSE(fs::exists(out)) << "the refused run wrote its output folder";
        EXPECT_EQ(r.out, "") << "a refused command measured or wrote something";
    }
    auto expected = before;
    expected["rec/image_0000/clip.mp4"] = "file the user's video";
    EXPECT_TRUE(snapshot(in.data) == expected);
}

// The guard's message for a dangling symbolic link as OUT (it said "File exists", exit 1).
TEST(WritePaths, DanglingLinkAsOutIsNamedAsSuch) {
    TempDir tmp;
    fs::create_directory_symlink(tmp / "gone", tmp / "out");
    const CommandResult r =
        run_bounded({"run", (tabletop() / "image_0000").string(), "--out", (tmp / "out").string(), "-q"});
    expect_one_line(r, 2, {"symbolic link to nothing"});
    EXPECT_FALSE(fs::exists(tmp / "gone"));
}

// ---- item 6: threads ---------------------------------------------------------------------

// bench --threads 65536 died on signal 11 in its measuring child.
TEST(WritePaths, BenchRefusesHugeThreadCounts) {
    const std::string frame = (tabletop() / "image_0000").string();
    for (const std::string t : {"65536", "1025", "-1"}) {
        CommandResult r = run_bounded({"bench", frame, "--k", "2", "--frames", "1", "--passes", "1",
                                       "--threads", t});
        expect_one_line(r, 2, {"--threads", t});
        EXPECT_EQ(r.out, "");
        // The measuring child's own command line (bench --single-k) has the same bound.
        r = run_bounded({"bench", frame, "--single-k", "2", "--frames", "1", "--passes", "1",
                         "--threads", t});
        expect_one_line(r, 2, {"--threads", t});
    }
}

// ---- item 11: a --video that cannot be written ----------------------------------------------

TEST(WritePaths, VideoThatCannotBeWrittenIsRefusedBeforeTheFirstFrame) {
    TempDir tmp;
    const std::string in = (tabletop() / "image_0000").string();
    fs::create_directories(tmp / "folder.mp4");
    fs::create_symlink("/dev/full", tmp / "full.mp4");
    ASSERT_EQ(::mkfifo((tmp / "fifo.mp4").c_str(), 0600), 0);
    for (const std::string& video :
         {(tmp / "clip.xyz").string(), (tmp / "noext").string(), (tmp / "folder.mp4").string(),
          (tmp / "full.mp4").string(), (tmp / "fifo.mp4").string(), std::string("/dev/full")}) {
        const CommandResult r =
            run_bounded({"run", in, "--out", (tmp / "out").string(), "-q", "--video", video});
        expect_one_line(r, 2, {"--video", video});
        EXPECT_FALSE(fs::exists(tmp / "out")) << video;
    }
    EXPECT_FALSE(fs::exists(tmp / "clip.xyz"));
}

TEST(WritePaths, VideoFailingMidRunLeavesTheSummary) {
    // 1x1 frames have no video frame (H.264 wants even sizes of at least 2): known only
    // at the first frame. Before: exit 1 with "no frame was written", and no summary.json.
    TempDir tmp;
    const fs::path frame = tmp / "tiny" / "f";
    fs::create_directories(frame);
    wul3d::DepthImage d;
    d.width = d.height = 1;
    d.data = {1000};
    wul3d::write_depth_png((frame / "depth.png").string(), d);
    write_text(frame / "intrinsics.json",
               R"({"fx": 1, "fy": 1, "cx": 0, "cy": 0, "width": 1, "height": 1, "depth_scale_m_per_unit": 0.001})");
    const fs::path out = tmp / "out";
    const CommandResult r = run_bounded({"run", (tmp / "tiny").string(), "--out", out.string(), "-q",
                                         "--k", "1", "--min-points", "1", "--decimate", "1",
                                         "--video", (tmp / "v.mp4").string()});
    expect_one_line(r, 2, {"v.mp4", "1x1"});
    ASSERT_TRUE(fs::is_regular_file(out / "summary.json")) << describe(r);
    const nlohmann::json summary = read_json(out / "summary.json");
    EXPECT_EQ(summary["stopped_by"], "error");
    EXPECT_NE(summary["error"].get<std::string>().find("1x1"), std::string::npos);
    EXPECT_FALSE(fs::exists(tmp / "v.mp4"));
    for (const auto& e : fs::directory_iterator(tmp.path()))
        EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos) << e.path();
}

// ---- item 10: label counts and resolutions, bounded before allocation ---------------------

/// `n` objects of 2 x 2 pixels, ids first_id.. (wrapping within 1..65535), on a 400-wide
/// image.
wul3d::LabelImage blocks(int n, int first_id) {
    wul3d::LabelImage l;
    l.width = 400;
    l.height = 2 * ((n + 199) / 200);
    l.labels.assign(static_cast<std::size_t>(l.width) * l.height, 0);
    for (int i = 0; i < n; ++i) {
        const int u = 2 * (i % 200), v = 2 * (i / 200);
        const auto id = static_cast<std::uint16_t>((first_id - 1 + i) % 65535 + 1);
        for (int dv = 0; dv < 2; ++dv)
            for (int du = 0; du < 2; ++du)
                l.labels[static_cast<std::size_t>(v + dv) * l.width + u + du] = id;
    }
    return l;
}

// 20,000 ids took 56 s and 12.5 GB (a table of every pair), 65,535 ended in bad_alloc.
TEST(WritePaths, EvalOfTensOfThousandsOfObjectsIsQuick) {
    for (const int n : {20000, 65535}) {
        TempDir tmp;
        fs::create_directories(tmp / "gt" / "f");
        fs::create_directories(tmp / "pred" / "f");
        wul3d::write_label_png((tmp / "gt" / "f" / "label.png").string(), blocks(n, 1));
        wul3d::write_label_png((tmp / "pred" / "f" / "objects.png").string(), blocks(n, 7));
        const CommandResult r = run_bounded({"eval", (tmp / "pred").string(), (tmp / "gt").string(),
                                             "--json", (tmp / "e.json").string()});
        ASSERT_EQ(r.exit_code, 0) << n << "\n" << describe(r);
        // Memory, not time: the dense table took 12.5 GB at 20,000 ids (bad_alloc at 65,535).
        EXPECT_LT(peak_child_rss_mb(), 1024.0) << n << " objects";
        EXPECT_NE(r.out.find("Overlap F   100.0\n"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("Boundary F  100.0\n"), std::string::npos) << r.out;
        const nlohmann::json j = read_json(tmp / "e.json");
        EXPECT_EQ(j["summary"]["gt_objects"], n);
        EXPECT_EQ(j["images"][0]["matches"].size(), static_cast<std::size_t>(n));
    }
}

TEST(WritePaths, EvalRefusesATangleTooLargeToMatchNamingTheFile) {
    // 1200 vertical stripes against 1200 horizontal ones: every pair overlaps, one group of
    // 1.44 million pairs, more than the matching takes.
    TempDir tmp;
    wul3d::LabelImage v, h;
    v.width = h.width = v.height = h.height = 1200;
    v.labels.resize(1200 * 1200);
    h.labels.resize(1200 * 1200);
    for (int y = 0; y < 1200; ++y)
        for (int x = 0; x < 1200; ++x) {
            v.labels[static_cast<std::size_t>(y) * 1200 + x] = static_cast<std::uint16_t>(x + 1);
            h.labels[static_cast<std::size_t>(y) * 1200 + x] = static_cast<std::uint16_t>(y + 1);
        }
    fs::create_directories(tmp / "gt" / "f");
    fs::create_directories(tmp / "pred" / "f");
    wul3d::write_label_png((tmp / "gt" / "f" / "label.png").string(), v);
    wul3d::write_label_png((tmp / "pred" / "f" / "objects.png").string(), h);
    const CommandResult r = run_bounded({"eval", (tmp / "pred").string(), (tmp / "gt").string(),
                                         "--max-pixels", "2000000"});
    expect_one_line(r, 2, {(tmp / "gt" / "f" / "label.png").string(), "1200 x 1200",
                           "more than eval matches"});
}

// 99999x99999 allocated for 57 s, then bad_alloc.
TEST(WritePaths, BenchResolutionWithinTheImageLimit) {
    const std::string frame = (tabletop() / "image_0000").string();
    for (const std::vector<std::string>& extra :
         {std::vector<std::string>{"--resolution", "99999x99999"},
          {"--resolution", "4097x4097"},
          {"--resolution", "70000x2"},
          {"--resolution", "640x480", "--max-pixels", "300000"}}) {
        std::vector<std::string> args = {"bench", frame, "--k", "2", "--frames", "1", "--passes", "1"};
        args.insert(args.end(), extra.begin(), extra.end());
        const CommandResult r = run_bounded(args);
        expect_one_line(r, 2, {"--resolution", "--max-pixels"});
        EXPECT_EQ(r.out, "");
    }
}

// ---- item 12: names that are not UTF-8 -----------------------------------------------------

/// Every line of OUT/frames.jsonl, parsed (a line that is not valid UTF-8 JSON fails).
std::vector<nlohmann::json> frames_lines(const fs::path& out) {
    std::vector<nlohmann::json> lines;
    std::ifstream in(out / "frames.jsonl");
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
}

// A frame folder named "\xff\xfe" was written without its frames.jsonl line, and the run
// ended with exit 1 and a raw json.exception.type_error.316; the same byte in the input path
// left no summary.json.
TEST(WritePaths, NamesThatAreNotUtf8AreWrittenAsValidJson) {
    TempDir tmp;
    const std::string bad = "\xff\xfe";
    copy_frame(tabletop() / "image_0000", tmp / "seq" / bad);
    copy_frame(tabletop() / "image_0002", tmp / "seq" / "b");
    CommandResult r = run_bounded({"run", (tmp / "seq").string(), "--out", (tmp / "out").string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_TRUE(fs::is_regular_file(tmp / "out" / bad / "objects.json"));
    const auto lines = frames_lines(tmp / "out");
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0]["name"], "b");
    EXPECT_EQ(lines[1]["name"], "\xEF\xBF\xBD\xEF\xBF\xBD");  // U+FFFD for each byte
    EXPECT_EQ(read_json(tmp / "out" / "summary.json")["frames"], 2);

    const fs::path odd_input = tmp / ("in" + bad + "put");
    copy_frame(tabletop() / "image_0000", odd_input / "a");
    r = run_bounded({"run", odd_input.string(), "--out", (tmp / "out2").string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    const nlohmann::json summary = read_json(tmp / "out2" / "summary.json");
    EXPECT_EQ(summary["stopped_by"], "end");
    EXPECT_NE(summary["input"].get<std::string>().find("in\xEF\xBF\xBD\xEF\xBF\xBDput"), std::string::npos);
    EXPECT_EQ(frames_lines(tmp / "out2").size(), 1u);

    // eval --json names the frames and the files.
    fs::create_directories(tmp / "gt" / bad);
    fs::copy_file(tmp / "out" / bad / "objects.png", tmp / "gt" / bad / "label.png");
    r = run_bounded({"eval", (tmp / "out").string(), (tmp / "gt").string(), "--json",
                     (tmp / "e.json").string()});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_EQ(read_json(tmp / "e.json")["images"][0]["name"], "\xEF\xBF\xBD\xEF\xBF\xBD");
}

// ---- item 15: duplicate TUM timestamps ------------------------------------------------------

// Two depth frames of one timestamp were two frames of one name: the second replaced the
// first's folder, exit 0.
TEST(WritePaths, DuplicateTumTimestampIsRefused) {
    TempDir tmp;
    const fs::path seq = tmp / "tum";
    fs::create_directories(seq / "rgb");
    fs::create_directories(seq / "depth");
    for (const char* n : {"1", "2"}) {
        fs::copy_file(tabletop() / "image_0000" / "color.png", seq / "rgb" / (std::string(n) + ".png"));
        fs::copy_file(tabletop() / "image_0000" / "depth.png", seq / "depth" / (std::string(n) + ".png"));
    }
    write_text(seq / "rgb.txt", "1.0 rgb/1.png\n1.01 rgb/2.png\n");
    write_text(seq / "depth.txt", "# depth\n1.0 depth/1.png\n1.0 depth/2.png\n");
    const CommandResult r = run_bounded({"run", seq.string(), "--out", (tmp / "out").string(), "-q",
                                         "--tum-camera", "kinect_v1"});
    expect_one_line(r, 2, {(seq / "depth.txt").string() + ":3", "timestamp 1.0", "line 2",
                           "depth/1.png", "depth/2.png"});
    EXPECT_FALSE(fs::exists(tmp / "out"));
    // A line written again whole is the same frame again (the memory tests' long runs).
    write_text(seq / "depth.txt", "1.0 depth/1.png\n1.0 depth/1.png\n");
    const CommandResult again = run_bounded({"run", seq.string(), "--out", (tmp / "out").string(), "-q",
                                             "--tum-camera", "kinect_v1"});
    EXPECT_EQ(again.exit_code, 0) << describe(again);
}

// ---- item 17: messages -------------------------------------------------------------------

TEST(WritePaths, DepthScaleIsPrintedShort) {
    // std::to_string printed 1e300 as 301 digits and 1e-300 as 0.000000.
    TempDir tmp;
    const fs::path frame = tmp / "f";
    copy_frame(tabletop() / "image_0000", frame);
    for (const auto& [value, shown] : std::vector<std::pair<std::string, std::string>>{
             {"1e300", "1e+300"}, {"1e-300", "1e-300"}, {"2", "= 2:"}}) {
        write_text(frame / "intrinsics.json",
                   R"({"fx": 600, "fy": 600, "cx": 320, "cy": 240, "width": 640, "height": 480, "depth_scale_m_per_unit": )" +
                       value + "}");
        const CommandResult r = run_bounded({"run", frame.string(), "--out", (tmp / "out").string(), "-q"});
        expect_one_line(r, 2, {"depth_scale_m_per_unit", shown});
        EXPECT_LT(r.err.size(), 200u) << r.err;
    }
}

TEST(WritePaths, NegativeMaxPixelsIsShownAsGiven) {
    // -1 was shown as 18446744073709551615; 0x10 was taken as 16.
    for (const std::string n : {"-1", "0x10", "1e6", "", "2000000000"}) {
        const CommandResult r = run_bounded({"run", (tabletop() / "image_0000").string(), "--out",
                                             "/nonexistent/out", "-q", "--max-pixels", n});
        expect_one_line(r, 2, {"--max-pixels '" + n + "'"});
        EXPECT_EQ(r.err.find("18446744073709551615"), std::string::npos) << r.err;
    }
}

TEST(WritePaths, WordsWhereANumberBelongsAreNamedAsSuch) {
    // CLI::Range said "Value 3abc not in range 0 to 50".
    const std::string gt = (tabletop()).string();
    CommandResult r = run_bounded({"eval", gt, gt, "--tolerance", "3abc"});
    expect_one_line(r, 2, {"--tolerance", "'3abc' is not a whole number"});
    r = run_bounded({"eval", gt, gt, "--tolerance", "2.5"});
    expect_one_line(r, 2, {"--tolerance", "'2.5' is not a whole number"});
    r = run_bounded({"eval", gt, gt, "--tolerance", "99"});
    expect_one_line(r, 2, {"--tolerance", "not in range"});
    r = run_bounded({"run", gt, "--out", "/nonexistent/out", "--frames", "2x"});
    expect_one_line(r, 2, {"--frames", "'2x' is not a whole number"});
    r = run_bounded({"export-fakenect", gt, "/nonexistent/dump", "--fps", "nan"});
    expect_one_line(r, 2, {"--fps", "nan"});  // NaN passed CLI::Range
}

TEST(WritePaths, ViewOrbitMustBeFiniteDegrees) {
    for (const std::string orbit : {"nan,1", "1e308,0", "0,inf", "400,0", "0,91"}) {
        const CommandResult r = run_bounded({"view", (tabletop() / "image_0000").string(), "--orbit", orbit},
                                            {{"DISPLAY", std::nullopt}, {"WAYLAND_DISPLAY", std::nullopt}});
        if (r.err.find("built without viewer support") != std::string::npos) GTEST_SKIP() << r.err;
        expect_one_line(r, 2, {"--orbit", orbit});  // before "no display"
    }
}

TEST(WritePaths, TooFewPointsNamesTheFrame) {
    // "k = 7 is larger than the 0 valid points" named no frame.
    TempDir tmp;
    const CommandResult r = run_bounded({"run", tabletop().string(), "--out", (tmp / "out").string(), "-q",
                                         "--zmin", "100", "--zmax", "101"});
    expect_one_line(r, 2, {"image_0000: k = 7 is larger than the 0 valid points"});
    EXPECT_NE(read_json(tmp / "out" / "summary.json")["error"].get<std::string>().find("image_0000: k = 7"),
              std::string::npos);
}

TEST(WritePaths, DepthSizeIsCheckedAgainstTheIntrinsicsBeforeDecoding) {
    // With --max-pixels 2^30 a 32768 x 32768 depth.png beside a 640 x 480 intrinsics.json was
    // decoded (11 s, 2.1 GB) before its size was compared.
    TempDir tmp;
    const fs::path frame = tmp / "f";
    copy_frame(tabletop() / "image_0000", frame);
    fs::remove(frame / "color.png");
    write_text(frame / "depth.png", wul3d::test::bomb_png(32768, 32768));
    CommandResult r = run_bounded({"run", frame.string(), "--out", (tmp / "out").string(), "-q",
                                   "--max-pixels", "1073741824"});
    expect_one_line(r, 2, {"depth.png is 32768x32768 but intrinsics.json says 640x480"});
    EXPECT_LT(peak_child_rss_mb(), 1024.0);  // not decoded: decoding it took 2.1 GB
    // The colour's header still speaks first: its size against the depth's is the hint
    // for unregistered input.
    wul3d::ColorImage small;
    small.width = 4;
    small.height = 2;
    small.rgb.assign(4 * 2 * 3, 0);
    wul3d::write_color_png((frame / "color.png").string(), small);
    r = run_bounded({"run", frame.string(), "--out", (tmp / "out").string(), "-q", "--max-pixels", "1073741824"});
    expect_one_line(r, 2, {"color.png is 4x2 but depth.png is 32768x32768", "--calibration"});
}

}  // namespace
