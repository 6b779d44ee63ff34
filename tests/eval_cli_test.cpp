// End-to-end tests of `wul3d eval`: tiny synthetic PRED/GT folder pairs written to a temp
// folder, the printed table and JSON checked against hand-computed numbers, and bad input
// rejected with exit code 2 and one stderr line.
#include <gtest/gtest.h>

#include "synthetic_scene.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/io.hpp"

using wul3d::test::blank_labels;
using wul3d::test::fill_rect;

namespace {

namespace fs = std::filesystem;
using wul3d::LabelImage;
using wul3d::test::CommandResult;
using wul3d::test::run_cli;
using wul3d::test::TempDir;

void write(const fs::path& path, const LabelImage& l) {
    fs::create_directories(path.parent_path());
    wul3d::write_label_png(path.string(), l);
}

int lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

/// GT and PRED folders with two frames: f0 predicted perfectly (all 100), f1 with one of two
/// objects missed (overlap P 100, R 50, F 66.7, %>=75 50). Means: P 100, R 75, F 83.3,
/// %>=75 75; 4 ground-truth objects.
struct Fixture {
    TempDir dir;
    fs::path gt = dir / "gt", pred = dir / "pred";
    Fixture() {
        LabelImage a = blank_labels(20, 12);
        fill_rect(a, 1, 1, 4, 5, 1);
        fill_rect(a, 12, 1, 15, 5, 2);
        write(gt / "f0" / "label.png", a);
        write(gt / "f1" / "label.png", a);
        LabelImage p0 = blank_labels(20, 12);
        fill_rect(p0, 1, 1, 4, 5, 3);
        fill_rect(p0, 12, 1, 15, 5, 9);
        write(pred / "f0" / "objects.png", p0);
        LabelImage p1 = blank_labels(20, 12);
        fill_rect(p1, 1, 1, 4, 5, 7);
        write(pred / "f1" / "objects.png", p1);
    }
};

}  // namespace

TEST(EvalCli, PrintsTableOfTwoFrames) {
    Fixture f;
    const CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string()});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap P   100.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Overlap R   75.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Overlap F   83.3\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Boundary F  83.3\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("%>=75       75.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("images      2\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("objects     4\n"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(EvalCli, JsonHoldsPerImageScores) {
    Fixture f;
    const fs::path json = f.dir / "scores.json";
    const CommandResult r =
        run_cli({"eval", f.pred.string(), f.gt.string(), "--json", json.string(), "--per-image"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("f1: overlap P/R/F 100.0 50.0 66.7"), std::string::npos) << r.out;
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_EQ(j["images"].size(), 2u);
    EXPECT_EQ(j["images"][0]["name"], "f0");
    EXPECT_DOUBLE_EQ(j["images"][1]["overlap_r"].get<double>(), 0.5);
    EXPECT_EQ(j["images"][1]["matches"][0]["pred_id"], 7);
    EXPECT_NEAR(j["summary"]["overlap_f"].get<double>(), (1.0 + 2.0 / 3.0) / 2.0, 1e-12);
    EXPECT_EQ(j["summary"]["gt_objects"], 4);
}

TEST(EvalCli, OnlyPrefixAndPredFile) {
    Fixture f;
    // labels.png beside objects.png: --pred-file picks it (here, a perfect f1).
    LabelImage a = blank_labels(20, 12);
    fill_rect(a, 1, 1, 4, 5, 1);
    fill_rect(a, 12, 1, 15, 5, 2);
    write(f.pred / "f1" / "labels.png", a);
    CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string(), "--only", "f1"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   66.7\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("images      1\n"), std::string::npos) << r.out;
    r = run_cli({"eval", f.pred.string(), f.gt.string(), "--only", "f1", "--pred-file",
                 "labels.png"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   100.0\n"), std::string::npos) << r.out;
}

TEST(EvalCli, SingleFrameFolderAndEightBitLabels) {
    Fixture f;
    // An 8-bit ground truth (same ids) is as good as a 16-bit one.
    std::vector<std::uint8_t> mask(20 * 12, 0);
    for (int v = 1; v <= 5; ++v)
        for (int u = 1; u <= 4; ++u) mask[static_cast<std::size_t>(v) * 20 + u] = 1;
    fs::create_directories(f.dir / "one");
    wul3d::write_mask_png((f.dir / "one" / "label.png").string(), 20, 12, mask);
    const CommandResult r =
        run_cli({"eval", (f.pred / "f1").string(), (f.dir / "one").string()});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   100.0\n"), std::string::npos) << r.out;
}

TEST(EvalCli, TemporalReport) {
    Fixture f;
    // f0 -> f1: the partner of object 1 changes from 3 to 7: one switch; object 2 is found
    // only in f0: none.
    const CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string(), "--temporal"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("ID switches          1\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("ID switches max      1\n"), std::string::npos) << r.out;
    // Counted pixels: both objects (40), all change (3 -> 7, 9 -> 0): flicker 100.
    EXPECT_NE(r.out.find("Flicker              100.0\n"), std::string::npos) << r.out;
}

// --where-depth: pixels without depth are not scored. f1's second object lies where its depth
// image has no reading, so the object the prediction missed is not counted: 100 where 83.3
// over all pixels. Without a depth image beside the labels, or of another size: exit 2.
TEST(EvalCli, WhereDepthScoresOnlyPixelsWithDepth) {
    Fixture f;
    auto depth = [](int hole_u0, int hole_u1, int width) {
        wul3d::DepthImage d;
        d.width = width;
        d.height = 12;
        d.data.assign(static_cast<std::size_t>(width) * 12, 1000);
        for (int v = 1; v <= 5; ++v)
            for (int u = hole_u0; u <= hole_u1; ++u) d.data[static_cast<std::size_t>(v) * width + u] = 0;
        return d;
    };
    wul3d::write_depth_png((f.gt / "f0" / "depth.png").string(), depth(0, -1, 20));  // no hole
    wul3d::write_depth_png((f.gt / "f1" / "depth.png").string(), depth(12, 15, 20));
    CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string()});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   83.3\n"), std::string::npos) << r.out;
    r = run_cli({"eval", f.pred.string(), f.gt.string(), "--where-depth"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find(", where depth)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Overlap F   100.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Boundary F  100.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("objects     3\n"), std::string::npos) << r.out;

    wul3d::write_depth_png((f.gt / "f1" / "depth.png").string(), depth(12, 15, 21));
    r = run_cli({"eval", f.pred.string(), f.gt.string(), "--where-depth"});
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("21x12"), std::string::npos) << r.err;
    fs::remove(f.gt / "f1" / "depth.png");
    r = run_cli({"eval", f.pred.string(), f.gt.string(), "--where-depth"});
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--where-depth"), std::string::npos) << r.err;

    // An OSD tree as downloaded: the depth of annotation/f1.png is disparity/f1.png.
    const fs::path tree = f.dir / "osd";
    fs::create_directories(tree / "image_color");
    fs::create_directories(tree / "disparity");
    write(tree / "annotation" / "f1.png", wul3d::read_label_png((f.gt / "f1" / "label.png").string()));
    wul3d::write_depth_png((tree / "disparity" / "f1.png").string(), depth(12, 15, 20));
    r = run_cli({"eval", f.pred.string(), tree.string(), "--where-depth"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   100.0\n"), std::string::npos) << r.out;
    r = run_cli({"eval", f.pred.string(), tree.string()});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.out.find("Overlap F   66.7\n"), std::string::npos) << r.out;
}

TEST(EvalCli, MissingPrediction_ExitTwoUnlessAllowed) {
    Fixture f;
    fs::remove_all(f.pred / "f1");
    CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string()});
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("f1"), std::string::npos) << r.err;
    r = run_cli({"eval", f.pred.string(), f.gt.string(), "--allow-missing"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    // f1 empty: P 1, R 0, F 0 by the reference's convention; means P 100, R 50, F 50.
    EXPECT_NE(r.out.find("Overlap P   100.0\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Overlap F   50.0\n"), std::string::npos) << r.out;
}

TEST(EvalCli, BadInput_ExitTwoOneLine) {
    Fixture f;
    const std::string missing = (f.dir / "nowhere").string();
    std::vector<std::vector<std::string>> cases = {
        {"eval", missing, f.gt.string()},
        {"eval", f.pred.string(), missing},
        {"eval", f.pred.string(), f.pred.string()},                 // no label.png anywhere
        {"eval", f.pred.string(), f.gt.string(), "--only", "zz"},  // nothing left
        {"eval", f.pred.string(), f.gt.string(), "--tolerance", "-5"},
    };
    for (const auto& args : cases) {
        const CommandResult r = run_cli(args);
        EXPECT_EQ(r.exit_code, 2) << describe(r);
        EXPECT_EQ(lines(r.err), 1) << r.err;
    }
    // A prediction of another size.
    write(f.pred / "f0" / "objects.png", blank_labels(12, 20));
    const CommandResult r = run_cli({"eval", f.pred.string(), f.gt.string()});
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("12x20"), std::string::npos) << r.err;
}
