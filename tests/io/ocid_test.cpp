// OCID sequences as downloaded (rgb/, depth/ in mm, label/, pcd/ of result_*.png): built by
// the test from a shipped frame; `wul3d run SEQ` reads them with the intrinsics recovered
// from pcd/, and `wul3d eval OUT SEQ` treats OCID's background ids (0-2 on tables, 0-1 on the
// floor) as background.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::run_cli;
using wul3d::test::TempDir;

const char* const kStems[] = {"result_2018-08-20-11-25-02", "result_2018-08-20-11-25-10"};

wul3d::RgbdFrame sample_frame() {
    return wul3d::test::read_sample_frame("image_0000");
}

/// ROOT/ARID20/<place>/top/seq01 with two frames; pcd/ unless `with_pcd` is false.
fs::path make_sequence(const fs::path& root, const std::string& place, bool with_pcd = true) {
    const fs::path seq = root / "ARID20" / place / "top" / "seq01";
    for (const char* sub : {"rgb", "depth", "label", "pcd"})
        if (with_pcd || std::string(sub) != "pcd") fs::create_directories(seq / sub);
    const wul3d::RgbdFrame f = sample_frame();
    for (const char* stem : kStems) {
        const std::string png = std::string(stem) + ".png";
        wul3d::write_depth_png((seq / "depth" / png).string(), f.depth);
        wul3d::write_color_png((seq / "rgb" / png).string(), f.color);
        if (with_pcd)
            wul3d::write_pcd((seq / "pcd" / (std::string(stem) + ".pcd")).string(), f,
                             wul3d::PcdData::Binary, true);
    }
    return seq;
}

TEST(Ocid, ASequenceReadsWithTheIntrinsicsOfItsPcd) {
    TempDir tmp;
    const fs::path seq = make_sequence(tmp.path(), "table");
    auto source = wul3d::open_source(seq.string(), {});
    ASSERT_EQ(source->size(), 2u);
    EXPECT_EQ(source->format(), wul3d::InputFormat::Ocid);
    EXPECT_EQ(source->name(0), kStems[0]);
    wul3d::SourceItem item;
    source->read(1, item);
    const wul3d::RgbdFrame want = sample_frame();
    EXPECT_EQ(item.frame.depth.data, want.depth.data);
    EXPECT_EQ(item.frame.color.rgb, want.color.rgb);
    EXPECT_NEAR(item.frame.intrinsics.fx, want.intrinsics.fx, 0.005 * want.intrinsics.fx);
    EXPECT_NEAR(item.frame.intrinsics.cy, want.intrinsics.cy, 0.005 * want.intrinsics.cy);
}

TEST(Ocid, WithoutPcdTheIntrinsicsMustBeGiven) {
    TempDir tmp;
    const fs::path seq = make_sequence(tmp.path(), "table", false);
    EXPECT_THROW(wul3d::open_source(seq.string(), {}), wul3d::InputError);
    wul3d::SourceOptions o;
    o.intrinsics = sample_frame().intrinsics;
    EXPECT_EQ(wul3d::open_source(seq.string(), o)->size(), 2u);
    wul3d::test::expect_one_line(run_cli({"run", seq.string(), "--out", (tmp / "out").string()}), 2,
                                 {"--intrinsics"});
}

TEST(Ocid, ATreeAskForOneSequence) {
    TempDir tmp;
    make_sequence(tmp.path(), "table");
    wul3d::test::expect_one_line(run_cli({"run", tmp.path().string(), "--out", (tmp / "out").string()}),
                                 2, {"OCID", "one sequence"});
}

/// Runs the sequence, writes label/ as OCID would label the run's own objects (ids + 2 on a
/// table, + 1 on the floor; background 0 without depth, else 1 or 2), and evaluates.
void run_and_score(const std::string& place, int background_max) {
    TempDir tmp;
    const fs::path seq = make_sequence(tmp.path(), place);
    const fs::path out = tmp / "out";
    const auto run = run_cli({"run", seq.string(), "--out", out.string()});
    ASSERT_EQ(run.exit_code, 0) << wul3d::test::describe(run);
    const wul3d::RgbdFrame f = sample_frame();
    for (const char* stem : kStems) {
        wul3d::LabelImage gt = wul3d::read_label_png((out / stem / "objects.png").string());
        int objects = 0;
        for (std::size_t i = 0; i < gt.labels.size(); ++i) {
            std::uint16_t& l = gt.labels[i];
            if (l != 0) {
                objects = std::max(objects, int(l));
                l = static_cast<std::uint16_t>(l + background_max);
            } else {
                l = f.depth.data[i] == 0 ? 0 : static_cast<std::uint16_t>(1 + (i % 2) * (background_max - 1));
            }
        }
        ASSERT_GT(objects, 0);
        wul3d::write_label_png((seq / "label" / (std::string(stem) + ".png")).string(), gt);
    }
    const auto eval = run_cli({"eval", out.string(), seq.string()});
    ASSERT_EQ(eval.exit_code, 0) << wul3d::test::describe(eval);
    EXPECT_NE(eval.out.find("Overlap F   100.0"), std::string::npos) << eval.out;
    EXPECT_NE(eval.out.find("images      2"), std::string::npos) << eval.out;
}

TEST(Ocid, EvalTreatsTheTablesIdsAsBackground) { run_and_score("table", 2); }
TEST(Ocid, EvalTreatsTheFloorsIdsAsBackground) { run_and_score("floor", 1); }

}  // namespace
