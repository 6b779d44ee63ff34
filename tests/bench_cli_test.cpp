// `wul3d bench`: one fresh process per (threads, k), a CSV row each. Checks the shape of the
// output, not the timings (speed belongs to bench/, not to tests).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
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
constexpr std::size_t kColumns = 18;  // k, threads, 6 figures, 10 stages
constexpr std::size_t kFirstStage = 8;
const std::vector<std::string> kStages = {"registration", "decimation", "backprojection",
                                          "normals",      "background", "clustering",
                                          "colors",       "plane",      "segmentation",
                                          "objects"};
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
    std::string header = "k,threads,width,height,points,fps_median,ms_median,peak_rss_mb";
    for (const auto& stage : kStages) header += ",ms_" + stage;
    EXPECT_EQ(line, header);
    for (const char* k : {"2", "3"}) {
        ASSERT_TRUE(std::getline(in, line));
        const auto cols = split(line, ',');
        ASSERT_EQ(cols.size(), kColumns) << line;
        EXPECT_EQ(cols[0], k);
        EXPECT_GE(std::stoi(cols[1]), 1);  // all cores: however many this machine has
        EXPECT_EQ(cols[2], "640");
        EXPECT_EQ(cols[3], "480");
        // points: the decimated frame's (320 x 240 at the default --decimate 2)
        EXPECT_GT(std::stod(cols[4]), 25000.0);
        EXPECT_LE(std::stod(cols[4]), 320.0 * 240.0);
        EXPECT_GT(std::stod(cols[5]), 0.0);       // fps
        EXPECT_GT(std::stod(cols[7]), 10.0);      // peak MB of that process
    }
    EXPECT_FALSE(std::getline(in, line));
}

TEST(CliBench, ResamplesToTheRequestedResolution) {
    const auto r = run_cli({"bench", (sample_dir() / "uois_tabletop").string(), "--k", "2",
                            "--frames", "1", "--passes", "1", "--resolution", "320x240"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(",320,240,"), std::string::npos) << r.out;
}

TEST(CliBench, OneRowPerThreadCountWithEachStagesTime) {
    const auto r = run_cli({"bench", (sample_dir() / "uois_tabletop").string(), "--k", "4",
                            "--threads", "1,2", "--frames", "1", "--passes", "2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto lines = split(r.out, '\n');
    ASSERT_EQ(lines.size(), 3u) << r.out;
    for (std::size_t i = 1; i < 3; ++i) {
        const auto cols = split(lines[i], ',');
        ASSERT_EQ(cols.size(), kColumns) << lines[i];
        EXPECT_EQ(cols[0], "4");
        EXPECT_EQ(cols[1], std::to_string(i));  // the count the measuring process ran on
        std::map<std::string, double> ms;
        for (std::size_t s = 0; s < kStages.size(); ++s) ms[kStages[s]] = std::stod(cols[kFirstStage + s]);
        // Registered frames: no registration. Every stage of the object pipeline ran.
        EXPECT_EQ(ms["registration"], 0.0);
        for (const char* stage : {"decimation", "backprojection", "clustering", "plane",
                                  "segmentation", "objects"})
            EXPECT_GT(ms[stage], 0.0) << stage;
        // Each stage is a part of the frame: none alone exceeds the frame's median by much
        // (medians of different frames, so not a strict sum).
        for (const auto& [stage, value] : ms) EXPECT_LT(value, 2.0 * std::stod(cols[6])) << stage;
    }
    // The paper's steps stop before the plane: those stages are 0.
    const auto paper = run_cli({"bench", (sample_dir() / "uois_tabletop").string(), "--k", "4",
                                "--threads", "1", "--frames", "1", "--passes", "1", "--pipeline", "paper"});
    ASSERT_EQ(paper.exit_code, 0) << paper.err;
    const auto plines = split(paper.out, '\n');
    ASSERT_EQ(plines.size(), 2u) << paper.out;
    const auto cols = split(plines[1], ',');
    ASSERT_EQ(cols.size(), kColumns);
    EXPECT_GT(std::stod(cols[kFirstStage + 5]), 0.0);   // clustering
    for (std::size_t s : {7u, 8u, 9u}) EXPECT_EQ(std::stod(cols[kFirstStage + s]), 0.0) << kStages[s];
}

// --no-colors reaches the measuring process: the colours' stage does not run, the others do.
TEST(CliBench, NoColours_TheColoursStageIsZero) {
    for (const bool without : {false, true}) {
        std::vector<std::string> args = {"bench", (sample_dir() / "uois_tabletop").string(), "--k", "4",
                                         "--threads", "1", "--frames", "1", "--passes", "2"};
        if (without) args.emplace_back("--no-colors");
        const auto r = run_cli(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto lines = split(r.out, '\n');
        ASSERT_EQ(lines.size(), 2u) << r.out;
        const auto cols = split(lines[1], ',');
        ASSERT_EQ(cols.size(), kColumns) << lines[1];
        const double colours = std::stod(cols[kFirstStage + 6]), clustering = std::stod(cols[kFirstStage + 5]);
        EXPECT_EQ(kStages[6], std::string("colors"));
        EXPECT_GT(clustering, 0.0);
        if (without)
            EXPECT_EQ(colours, 0.0);
        else
            EXPECT_GT(colours, 0.0);
    }
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
    ASSERT_EQ(paper.size(), kColumns);
    ASSERT_EQ(objects.size(), kColumns);
    EXPECT_EQ(paper[4], objects[4]);  // the same points clustered
    EXPECT_LT(std::stod(paper[7]) + 10.0, std::stod(objects[7]));
    // By default the paper's steps run on every pixel, as the paper does, and the object
    // pipeline on a quarter of them (--decimate 2).
    const auto paper_default = row("paper", {}), objects_default = row("objects", {});
    ASSERT_EQ(paper_default.size(), kColumns);
    ASSERT_EQ(objects_default.size(), kColumns);
    EXPECT_EQ(paper_default[4], paper[4]);
    EXPECT_GT(std::stod(paper_default[4]), 3.5 * std::stod(objects_default[4]));
    EXPECT_LT(std::stod(paper_default[4]), 4.5 * std::stod(objects_default[4]));
}

TEST(CliBench, BadArgumentsAreOneLineErrors) {
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"--k", "2,x"}, {"--k", "0"}, {"--resolution", "big"}, {"--pipeline", "fast"},
             {"--segmenter", "magic"}, {"--threads", "1,,2"}, {"--threads", "2,"},
             {"--threads", "one"}}) {
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
