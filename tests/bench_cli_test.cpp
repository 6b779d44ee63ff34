// `wul3d bench`: one fresh process per k, a CSV row per k. Checks the shape of the output,
// not the timings (speed belongs to bench/, not to tests).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "test_support.hpp"

using namespace wul3d::test;

namespace {
std::vector<std::string> split(const std::string& line, char sep) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    std::string item;
    while (std::getline(ss, item, sep)) out.push_back(item);
    return out;
}
}  // namespace

TEST(CliBench, OneRowPerKWithMemoryAndSpeed) {
    TempDir tmp;
    const auto csv = tmp / "bench.csv";
    const auto r = run_cli({"bench", (sample_dir() / "uois_tabletop").string(), "--k", "2,3",
                            "--frames", "1", "--passes", "1", "--csv", csv.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(csv);
    std::string line;
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, "k,width,height,points,fps_median,ms_median,peak_rss_mb");
    for (const char* k : {"2", "3"}) {
        ASSERT_TRUE(std::getline(in, line));
        const auto cols = split(line, ',');
        ASSERT_EQ(cols.size(), 7u) << line;
        EXPECT_EQ(cols[0], k);
        EXPECT_EQ(cols[1], "640");
        EXPECT_EQ(cols[2], "480");
        // points: the decimated frame's (320 x 240 at the default --decimate 2)
        EXPECT_GT(std::stod(cols[3]), 25000.0);
        EXPECT_LE(std::stod(cols[3]), 320.0 * 240.0);
        EXPECT_GT(std::stod(cols[4]), 0.0);       // fps
        EXPECT_GT(std::stod(cols[6]), 10.0);      // peak MB of that process
    }
    EXPECT_FALSE(std::getline(in, line));
}

TEST(CliBench, ResamplesToTheRequestedResolution) {
    const auto r = run_cli({"bench", (sample_dir() / "uois_tabletop").string(), "--k", "2",
                            "--frames", "1", "--passes", "1", "--resolution", "320x240"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\n2,320,240,"), std::string::npos) << r.out;
}

TEST(CliBench, PaperPipelineStopsAfterTheColoursAndHoldsLessMemory) {
    // The paper's steps alone keep no plane, segment or track buffers: at 640x480 that is
    // tens of MB (the tracker's weights alone are 24 bytes a pixel), far above noise.
    auto row = [](const std::string& pipeline, std::vector<std::string> more) {
        std::vector<std::string> args = {"bench", (sample_dir() / "uois_tabletop").string(), "--k", "5",
                                          "--frames", "1", "--passes", "1", "--pipeline", pipeline};
        args.insert(args.end(), more.begin(), more.end());
        const auto r = run_cli(args);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        const auto lines = split(r.out, '\n');
        return lines.size() == 2 ? split(lines[1], ',') : std::vector<std::string>{};
    };
    const auto paper = row("paper", {"--decimate", "1"}), objects = row("objects", {"--decimate", "1"});
    ASSERT_EQ(paper.size(), 7u);
    ASSERT_EQ(objects.size(), 7u);
    EXPECT_EQ(paper[3], objects[3]);  // the same points clustered
    EXPECT_LT(std::stod(paper[6]) + 10.0, std::stod(objects[6]));
    // By default the paper's steps run on every pixel, as the paper does, and the object
    // pipeline on a quarter of them (--decimate 2).
    const auto paper_default = row("paper", {}), objects_default = row("objects", {});
    ASSERT_EQ(paper_default.size(), 7u);
    ASSERT_EQ(objects_default.size(), 7u);
    EXPECT_EQ(paper_default[3], paper[3]);
    EXPECT_GT(std::stod(paper_default[3]), 3.5 * std::stod(objects_default[3]));
    EXPECT_LT(std::stod(paper_default[3]), 4.5 * std::stod(objects_default[3]));
}

TEST(CliBench, BadArgumentsAreOneLineErrors) {
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"--k", "2,x"}, {"--k", "0"}, {"--resolution", "big"}, {"--pipeline", "fast"},
             {"--segmenter", "magic"}}) {
        std::vector<std::string> all = {"bench", (sample_dir() / "uois_tabletop").string()};
        all.insert(all.end(), args.begin(), args.end());
        const auto r = run_cli(all);
        EXPECT_EQ(r.exit_code, 2) << args[1];
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    const auto missing = run_cli({"bench", "/nonexistent/frames"});
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.err.find("/nonexistent/frames"), std::string::npos);
}
