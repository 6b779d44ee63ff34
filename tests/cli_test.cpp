// End-to-end tests of `wul3d run`: real sample frames in, files out, and every kind of bad
// input rejected with exit code 2, one stderr line naming the culprit, and no half-written
// output (no *.tmp* file, no frame folder missing one of its files).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::CommandResult;
using wul3d::test::list_files;
using wul3d::test::run_cli;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;

// The depth range of the end-to-end tests, as passed on the command line and as a number. No
// millimetre value lies within 0.4 mm of a bound, so float rounding in the library cannot move
// a pixel across it.
constexpr const char* kZmin = "0.4005";
constexpr double kZminM = 0.4005;
constexpr const char* kZmaxTabletop = "2.0005";
constexpr double kZmaxTabletopM = 2.0005;
constexpr const char* kZmaxPairwise = "3.0005";  // pairwise_seq lies in 1.37-3.74 m
constexpr double kZmaxPairwiseM = 3.0005;
constexpr int kK = 7;

fs::path tabletop() { return sample_dir() / "uois_tabletop"; }
fs::path tabletop_frame() { return tabletop() / "image_0000"; }
fs::path pairwise_seq() { return sample_dir() / "pcl_kinect" / "pairwise_seq"; }

std::string join(const std::vector<std::string>& args) {
    std::string s = "wul3d";
    for (const auto& a : args) s += " " + a;
    return s;
}

/// Copies a frame folder (color.png, depth.png, intrinsics.json) to `dst`.
void copy_frame(const fs::path& src, const fs::path& dst) {
    fs::create_directories(dst);
    for (const auto& e : fs::directory_iterator(src))
        fs::copy_file(e.path(), dst / e.path().filename());
}

/// The frame folders directly under an output folder.
std::set<std::string> frame_dirs(const fs::path& out) {
    std::set<std::string> dirs;
    if (!fs::exists(out)) return dirs;
    for (const auto& e : fs::directory_iterator(out))
        if (e.is_directory()) dirs.insert(e.path().filename().string());
    return dirs;
}

/// No temporary file anywhere under `out`, and every frame folder holds all of `per_frame`.
void expect_no_partial_outputs(const fs::path& out, const std::vector<std::string>& per_frame) {
    for (const auto& f : list_files(out))
        EXPECT_EQ(f.find(".tmp"), std::string::npos) << "temporary file left behind: " << f;
    for (const auto& d : frame_dirs(out))
        for (const auto& f : per_frame)
            EXPECT_TRUE(fs::is_regular_file(out / d / f))
                << "frame folder " << d << " lacks " << f;
}

// No std::regex here: under the sanitizers, GCC 12's -Wmaybe-uninitialized fires inside
// <regex> and -Werror turns it into a build failure.
bool is_word_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

bool contains_word(const std::string& text, const std::string& word) {
    for (auto at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
        const bool starts = at == 0 || !is_word_char(text[at - 1]);
        const std::size_t end = at + word.size();
        const bool ends = end == text.size() || !is_word_char(text[end]);
        if (starts && ends) return true;
    }
    return false;
}

/// Exit code 2 and stderr exactly one non-empty line that contains one of `names` (as a
/// substring) or one of `words` (as a whole word, for short names such as "k").
void expect_one_line_error(const CommandResult& r, const std::vector<std::string>& names,
                           const std::vector<std::string>& words = {}) {
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    std::string line = r.err;
    if (!line.empty() && line.back() == '\n') line.pop_back();
    EXPECT_FALSE(line.empty()) << "stderr is empty\n" << describe(r);
    EXPECT_EQ(line.find('\n'), std::string::npos) << "stderr has more than one line\n"
                                                  << describe(r);
    bool named = false;
    for (const auto& n : names) named = named || line.find(n) != std::string::npos;
    for (const auto& w : words) named = named || contains_word(line, w);
    std::string expected;
    for (const auto& n : names) expected += " '" + n + "'";
    for (const auto& w : words) expected += " word '" + w + "'";
    EXPECT_TRUE(named) << "stderr names none of" << expected << ": " << line;
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

int count_lines(const std::string& s) {
    int n = 0;
    std::istringstream in(s);
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) ++n;
    return n;
}

/// Checks labels.png of one frame against its input depth: 16-bit, the frame's size, labels
/// in 0..k, at least two clusters used, and label != 0 exactly where depth is valid and
/// within [kZminM, zmax_m]. Also checks colors.png's size.
void check_labels(const fs::path& frame_in, const fs::path& frame_out, double zmax_m) {
    SCOPED_TRACE(frame_out.string());
    const auto intr = wul3d::read_intrinsics_json((frame_in / "intrinsics.json").string());
    const auto depth = wul3d::read_depth_png((frame_in / "depth.png").string(),
                                             intr.depth_scale_m_per_unit);
    // read_label_png rejects anything but a 16-bit single-channel PNG.
    const auto labels = wul3d::read_label_png((frame_out / "labels.png").string());
    ASSERT_EQ(labels.width, depth.width);
    ASSERT_EQ(labels.height, depth.height);
    ASSERT_EQ(labels.labels.size(), depth.data.size());

    std::size_t in_range = 0, missing = 0, extra = 0, out_of_k = 0;
    std::set<int> used;
    for (std::size_t p = 0; p < depth.data.size(); ++p) {
        const double z = depth.data[p] * static_cast<double>(intr.depth_scale_m_per_unit);
        const bool active = depth.data[p] != 0 && z >= kZminM && z <= zmax_m;
        const int l = labels.labels[p];
        if (active) ++in_range;
        if (active && l == 0) ++missing;
        if (!active && l != 0) ++extra;
        if (l > kK) ++out_of_k;
        if (l != 0) used.insert(l);
    }
    EXPECT_GT(in_range, 1000u) << "test frame has too few points in range";
    EXPECT_EQ(missing, 0u) << "pixels in the depth range without a label";
    EXPECT_EQ(extra, 0u) << "labelled pixels with invalid or out-of-range depth";
    EXPECT_EQ(out_of_k, 0u) << "labels above k = " << kK;
    EXPECT_GE(used.size(), 2u) << "all points in one cluster";

    const auto colors = wul3d::read_color_image((frame_out / "colors.png").string());
    EXPECT_EQ(colors.width, depth.width);
    EXPECT_EQ(colors.height, depth.height);
}

void check_summary(const fs::path& out, int frames) {
    const fs::path path = out / "summary.json";
    ASSERT_TRUE(fs::is_regular_file(path));
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(read_text(path))) << read_text(path);
    ASSERT_TRUE(j.is_object());
    ASSERT_TRUE(j.contains("parameters"));
    EXPECT_TRUE(j["parameters"].is_object());
    EXPECT_FALSE(j["parameters"].empty());
    ASSERT_TRUE(j.contains("frames"));
    EXPECT_EQ(j["frames"], frames);
    ASSERT_TRUE(j.contains("stage_ms_median"));
    ASSERT_TRUE(j["stage_ms_median"].is_object());
    for (const char* stage :
         {"registration", "backprojection", "normals", "background", "clustering", "output", "overlap"}) {
        ASSERT_TRUE(j["stage_ms_median"].contains(stage)) << stage;
        ASSERT_TRUE(j["stage_ms_median"][stage].is_number()) << stage;
        EXPECT_GE(j["stage_ms_median"][stage].get<double>(), 0.0) << stage;
    }
    ASSERT_TRUE(j.contains("fps"));
    ASSERT_TRUE(j["fps"].is_number());
    EXPECT_GT(j["fps"].get<double>(), 0.0);
    ASSERT_TRUE(j.contains("peak_rss_mb"));
    ASSERT_TRUE(j["peak_rss_mb"].is_number());
    EXPECT_GT(j["peak_rss_mb"].get<double>(), 0.0);
}

std::vector<std::string> range_args(const char* zmax) {
    return {"--zmin", kZmin, "--zmax", zmax, "--k", std::to_string(kK), "--stride", "1"};
}

CommandResult run_logged(const std::vector<std::string>& args) {
    const CommandResult r = run_cli(args);
    std::cerr << "[ cmd      ] " << join(args) << " -> exit " << r.exit_code << "\n";
    if (!r.err.empty()) std::cerr << "[ stderr   ] " << r.err << (r.err.back() == '\n' ? "" : "\n");
    return r;
}

// ---- end to end ------------------------------------------------------------------------

TEST(CliRun, Tabletop_TwoFrames_WritesLabelsColorsSummary) {
    TempDir tmp;
    const fs::path out = tmp / "out";
    std::vector<std::string> args = {"run", tabletop().string(), "--out", out.string(),
                                     "--frames", "2"};
    const auto extra = range_args(kZmaxTabletop);
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = run_logged(args);
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_EQ(count_lines(r.out), 1) << "stdout should be one summary line:\n" << r.out;

    // The first two frames in name order, and only those.
    EXPECT_EQ(frame_dirs(out), (std::set<std::string>{"image_0000", "image_0002"}));
    expect_no_partial_outputs(out, {"labels.png", "colors.png"});
    for (const char* name : {"image_0000", "image_0002"}) check_labels(tabletop() / name, out / name, kZmaxTabletopM);
    check_summary(out, 2);
}

TEST(CliRun, PairwiseSeq_DepthOnly_WritesLabelsColorsSummary) {
    TempDir tmp;
    const fs::path out = tmp / "out";
    std::vector<std::string> args = {"run", pairwise_seq().string(), "--out", out.string(),
                                     "--frames", "3"};
    const auto extra = range_args(kZmaxPairwise);
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = run_logged(args);
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_EQ(count_lines(r.out), 1) << "stdout should be one summary line:\n" << r.out;

    EXPECT_EQ(frame_dirs(out),
              (std::set<std::string>{"capture0001", "capture0002", "capture0003"}));
    expect_no_partial_outputs(out, {"labels.png", "colors.png"});
    for (const char* name : {"capture0001", "capture0002", "capture0003"})
        check_labels(pairwise_seq() / name, out / name, kZmaxPairwiseM);
    check_summary(out, 3);
}

TEST(CliRun, Select_WritesMaskOfOneClusterPerFrame) {
    TempDir tmp;
    const fs::path out = tmp / "out";
    std::vector<std::string> args = {"run",      tabletop().string(), "--out", out.string(),
                                     "--frames", "2",                 "--select", "320,240"};
    const auto extra = range_args(kZmaxTabletop);
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = run_logged(args);
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    ASSERT_EQ(frame_dirs(out).size(), 2u);
    expect_no_partial_outputs(out, {"labels.png", "colors.png", "selected.png"});

    for (const auto& name : frame_dirs(out)) {
        SCOPED_TRACE(name);
        const auto labels = wul3d::read_label_png((out / name / "labels.png").string());
        // An 8-bit grey PNG comes back expanded to RGB; the mask is its first channel.
        const auto mask = wul3d::read_color_image((out / name / "selected.png").string());
        ASSERT_EQ(mask.width, labels.width);
        ASSERT_EQ(mask.height, labels.height);
        // The mask is exactly the pixels of one cluster (objects.hpp: the cluster under the
        // picked pixel, followed frame to frame).
        std::map<int, std::size_t> selected_by_label;
        std::size_t selected = 0;
        for (std::size_t p = 0; p < labels.labels.size(); ++p) {
            if (mask.rgb[3 * p] != 0) {
                ++selected;
                ++selected_by_label[labels.labels[p]];
            }
        }
        ASSERT_GT(selected, 0u) << "selected.png is empty";
        ASSERT_EQ(selected_by_label.size(), 1u) << "mask spans several labels";
        const int c = selected_by_label.begin()->first;
        EXPECT_NE(c, 0) << "mask covers unlabelled pixels";
        const auto all_of_c = static_cast<std::size_t>(
            std::count(labels.labels.begin(), labels.labels.end(), static_cast<std::uint16_t>(c)));
        EXPECT_EQ(selected, all_of_c) << "mask misses pixels of its cluster " << c;
    }
    // On the first frame, the picked pixel itself belongs to the object when it is labelled.
    const auto labels0 = wul3d::read_label_png((out / "image_0000" / "labels.png").string());
    const auto mask0 = wul3d::read_color_image((out / "image_0000" / "selected.png").string());
    const std::size_t p = 240u * static_cast<std::size_t>(labels0.width) + 320u;
    if (labels0.labels[p] != 0) {
        EXPECT_NE(mask0.rgb[3 * p], 0);
    }
}

TEST(CliRun, Ply_WritesBinaryLittleEndianCloudOfLabelledPoints) {
    TempDir tmp;
    const fs::path out = tmp / "out";
    std::vector<std::string> args = {"run", tabletop_frame().string(), "--out", out.string(),
                                     "--ply"};
    const auto extra = range_args(kZmaxTabletop);
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = run_logged(args);
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    ASSERT_EQ(frame_dirs(out).size(), 1u);
    expect_no_partial_outputs(out, {"labels.png", "colors.png", "cloud.ply"});
    const fs::path frame = out / *frame_dirs(out).begin();

    const std::string ply = read_text(frame / "cloud.ply");
    const std::string end_marker = "end_header\n";
    const auto header_end = ply.find(end_marker);
    ASSERT_NE(header_end, std::string::npos) << "no end_header";
    const std::string header = ply.substr(0, header_end + end_marker.size());
    EXPECT_EQ(header.rfind("ply\n", 0), 0u) << header;
    EXPECT_NE(header.find("\nformat binary_little_endian 1.0\n"), std::string::npos) << header;

    // io.hpp: one vertex per labelled point, x y z float, red green blue uchar, label ushort.
    const std::string vertex_key = "\nelement vertex ";
    const auto vertex_at = header.find(vertex_key);
    ASSERT_NE(vertex_at, std::string::npos) << header;
    std::size_t vertices = 0;
    std::istringstream(header.substr(vertex_at + vertex_key.size())) >> vertices;
    ASSERT_GT(vertices, 0u) << header;
    const auto labels = wul3d::read_label_png((frame / "labels.png").string());
    const auto labelled = static_cast<std::size_t>(labels.labels.size()) -
                          static_cast<std::size_t>(std::count(labels.labels.begin(),
                                                              labels.labels.end(),
                                                              std::uint16_t{0}));
    EXPECT_EQ(vertices, labelled);
    EXPECT_EQ(ply.size() - header.size(), vertices * (3 * 4 + 3 + 2));
}

// --decimate 2: the stages run on a quarter of the pixels, every output at the input's size,
// and --ply writes the input's own points (the frame is back-projected again for it).
TEST(CliRun, Decimate_OutputsAtTheInputsSize) {
    TempDir tmp;
    const fs::path out = tmp / "out";
    const CommandResult r = run_logged({"run", tabletop_frame().string(), "--out", out.string(),
                                        "--decimate", "2", "--ply"});
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    ASSERT_EQ(frame_dirs(out).size(), 1u);
    const fs::path frame = out / *frame_dirs(out).begin();
    const auto input = wul3d::read_depth_png((tabletop_frame() / "depth.png").string(), 0.001f);
    for (const char* name : {"labels.png", "objects.png"}) {
        const auto l = wul3d::read_label_png((frame / name).string());
        EXPECT_EQ(l.width, input.width) << name;
        EXPECT_EQ(l.height, input.height) << name;
    }
    const auto objects = wul3d::read_label_png((frame / "objects.png").string());
    EXPECT_GT(std::count_if(objects.labels.begin(), objects.labels.end(),
                            [](std::uint16_t l) { return l != 0; }),
              1000);
    const std::string ply = read_text(frame / "cloud.ply");
    const auto labels = wul3d::read_label_png((frame / "labels.png").string());
    const auto labelled = labels.labels.size() - static_cast<std::size_t>(std::count(
                                                     labels.labels.begin(), labels.labels.end(), 0));
    EXPECT_NE(ply.find("element vertex " + std::to_string(labelled) + "\n"), std::string::npos);
    const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_GT(summary["stage_ms_median"]["decimation"].get<double>(), 0.0);
}

// ---- bad input ---------------------------------------------------------------------------

/// A folder with one writable copy of a sample frame, named `frame_name`, and an output path.
struct BadFrame {
    TempDir tmp;
    fs::path frame;
    fs::path out;
    explicit BadFrame(const std::string& frame_name)
        : frame(tmp / frame_name), out(tmp / "out") {
        copy_frame(tabletop_frame(), frame);
    }
    CommandResult run(std::vector<std::string> more = {}) const {
        std::vector<std::string> args = {"run", frame.string(), "--out", out.string()};
        args.insert(args.end(), more.begin(), more.end());
        return run_logged(args);
    }
    void expect_clean() const { expect_no_partial_outputs(out, {"labels.png", "colors.png"}); }
};

TEST(CliRunBadInput, MissingPath) {
    TempDir tmp;
    const fs::path missing = tmp / "no_such_recording";
    const fs::path out = tmp / "out";
    const CommandResult r = run_logged({"run", missing.string(), "--out", out.string()});
    expect_one_line_error(r, {"no_such_recording"});
    expect_no_partial_outputs(out, {"labels.png", "colors.png"});
}

TEST(CliRunBadInput, TruncatedDepthPng) {
    BadFrame b("truncated_frame");
    const fs::path depth = b.frame / "depth.png";
    fs::resize_file(depth, fs::file_size(depth) / 2);
    expect_one_line_error(b.run(), {"depth.png"});
    b.expect_clean();
}

TEST(CliRunBadInput, UnreadableDepthPng) {
    BadFrame b("garbage_frame");
    std::ofstream(b.frame / "depth.png", std::ios::binary | std::ios::trunc) << "not a png";
    expect_one_line_error(b.run(), {"depth.png"});
    b.expect_clean();
}

TEST(CliRunBadInput, ColorDepthSizeMismatchWithoutCalibration) {
    BadFrame b("size_mismatch_frame");
    wul3d::ColorImage small;
    small.width = 320;
    small.height = 240;
    small.rgb.assign(3u * 320u * 240u, 128);
    wul3d::write_color_png((b.frame / "color.png").string(), small);
    expect_one_line_error(b.run(), {"color.png", "size_mismatch_frame"});
    b.expect_clean();
}

TEST(CliRunBadInput, EightBitDepth) {
    BadFrame b("eight_bit_frame");
    const std::vector<std::uint8_t> depth8(640u * 480u, 100);
    wul3d::write_mask_png((b.frame / "depth.png").string(), 640, 480, depth8);
    expect_one_line_error(b.run(), {"depth.png"});
    b.expect_clean();
}

TEST(CliRunBadInput, AllInvalidDepth) {
    BadFrame b("zero_depth_frame");
    wul3d::DepthImage depth;
    depth.width = 640;
    depth.height = 480;
    depth.data.assign(640u * 480u, 0);
    wul3d::write_depth_png((b.frame / "depth.png").string(), depth);
    expect_one_line_error(b.run(), {"depth.png", "zero_depth_frame"});
    b.expect_clean();
}

TEST(CliRunBadInput, EmptySequence) {
    TempDir tmp;
    const fs::path empty = tmp / "empty_sequence";
    fs::create_directories(empty);
    const fs::path out = tmp / "out";
    const CommandResult r = run_logged({"run", empty.string(), "--out", out.string()});
    expect_one_line_error(r, {"empty_sequence"});
    expect_no_partial_outputs(out, {"labels.png", "colors.png"});
}

TEST(CliRunBadInput, KZero) {
    BadFrame b("k_zero_frame");
    expect_one_line_error(b.run({"--k", "0"}), {}, {"k"});
    b.expect_clean();
}

TEST(CliRunBadInput, KAboveValidPoints) {
    BadFrame b("three_points_frame");
    wul3d::DepthImage depth;
    depth.width = 640;
    depth.height = 480;
    depth.data.assign(640u * 480u, 0);
    depth.data[100u * 640u + 100u] = 1000;  // 1 m, inside any sensible depth range
    depth.data[200u * 640u + 300u] = 1100;
    depth.data[300u * 640u + 500u] = 1200;
    wul3d::write_depth_png((b.frame / "depth.png").string(), depth);
    expect_one_line_error(b.run({"--k", "5"}), {"three_points_frame"}, {"k"});
    b.expect_clean();
}

TEST(CliRunBadInput, UnknownFormat) {
    BadFrame b("format_frame");
    expect_one_line_error(b.run({"--format", "bogus"}), {"format", "bogus"});
    b.expect_clean();
}

TEST(CliRunBadInput, SelectOutsideImage) {
    BadFrame b("select_frame");
    const CommandResult r = b.run({"--select", "5000,5000"});
    expect_one_line_error(r, {"select", "5000"});
    expect_no_partial_outputs(b.out, {"labels.png", "colors.png", "selected.png"});
}

/// One out-of-range clustering parameter per case; the message must name it.
struct ParamCase {
    const char* test_name;
    std::vector<std::string> args;
    const char* param;
};

// Names the case in test listings (ctest shows GetParam() through this, not as raw bytes).
void PrintTo(const ParamCase& c, std::ostream* os) { *os << c.test_name; }

class CliRunBadParam : public ::testing::TestWithParam<ParamCase> {};

TEST_P(CliRunBadParam, RejectedWithExitCode2NamingTheParameter) {
    const ParamCase& c = GetParam();
    BadFrame b("param_frame");
    expect_one_line_error(b.run(c.args), {c.param});
    b.expect_clean();
}

// Paper ranges (section II.C, clustering.hpp): alpha in [0.002, 0.1]; delta > 0 and
// alpha + delta <= 1 (eq. 5); gamma in [0.0001, 0.01]; psi in (0, 1].
INSTANTIATE_TEST_SUITE_P(
    PaperRanges, CliRunBadParam,
    ::testing::Values(
        // alpha 0.5 with delta 0.5 keeps alpha + delta = 1, so only alpha's own range fails.
        ParamCase{"AlphaAboveRange", {"--alpha", "0.5", "--delta", "0.5"}, "alpha"},
        ParamCase{"AlphaBelowRange", {"--alpha", "0.001"}, "alpha"},
        ParamCase{"DeltaAlphaSumAboveOne", {"--delta", "1.5"}, "delta"},
        ParamCase{"DeltaZero", {"--delta", "0"}, "delta"},
        ParamCase{"GammaAboveRange", {"--gamma", "0.5"}, "gamma"},
        ParamCase{"GammaBelowRange", {"--gamma", "0.00001"}, "gamma"},
        ParamCase{"PsiZero", {"--psi", "0"}, "psi"},
        ParamCase{"PsiAboveOne", {"--psi", "1.5"}, "psi"}),
    [](const ::testing::TestParamInfo<ParamCase>& case_info) {
        return std::string(case_info.param.test_name);
    });

INSTANTIATE_TEST_SUITE_P(
    Decimation, CliRunBadParam,
    ::testing::Values(ParamCase{"DecimateZero", {"--decimate", "0"}, "decimate"},
                      ParamCase{"DecimateNine", {"--decimate", "9"}, "decimate"}),
    [](const ::testing::TestParamInfo<ParamCase>& case_info) {
        return std::string(case_info.param.test_name);
    });

}  // namespace
