// Readers, writers and frame sources of io.hpp: round trips, every reader error, atomic
// writes, and open_source on the shipped samples and on small sequences written here.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::list_files;
using wul3d::test::sample_dir;
using wul3d::test::TempDir;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void spit(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << bytes;
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// Runs `f`, expects an InputError whose message holds every one of `parts`, and nothing
/// printed on stderr (libpng and OpenCV must stay quiet: the CLI prints one line).
template <class F>
void expect_input_error(F&& f, const std::vector<std::string>& parts) {
    testing::internal::CaptureStderr();
    std::string msg;
    try {
        f();
    } catch (const wul3d::InputError& e) {
        msg = e.what();
    }
    const std::string err = testing::internal::GetCapturedStderr();
    ASSERT_FALSE(msg.empty()) << "no InputError";
    for (const auto& p : parts) EXPECT_TRUE(contains(msg, p)) << "'" << p << "' not in: " << msg;
    EXPECT_EQ(err, "") << "stderr was not quiet";
}

wul3d::DepthImage ramp_depth(int w, int h) {
    wul3d::DepthImage d;
    d.width = w;
    d.height = h;
    d.data.resize(static_cast<std::size_t>(w) * h);
    for (std::size_t p = 0; p < d.data.size(); ++p) d.data[p] = static_cast<std::uint16_t>(p * 997 % 65536);
    return d;
}

wul3d::ColorImage solid_color(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    wul3d::ColorImage c;
    c.width = w;
    c.height = h;
    c.rgb.resize(3 * static_cast<std::size_t>(w) * h);
    for (std::size_t p = 0; p < c.rgb.size(); p += 3) c.rgb[p] = r, c.rgb[p + 1] = g, c.rgb[p + 2] = b;
    return c;
}

void expect_no_temp_files(const fs::path& dir) {
    for (const auto& f : list_files(dir)) EXPECT_FALSE(contains(f, ".tmp-")) << f;
}

// ---- single files -------------------------------------------------------------------

TEST(IoImages, DepthRoundTrip) {
    TempDir tmp;
    const wul3d::DepthImage d = ramp_depth(37, 23);
    const std::string path = (tmp / "depth.png").string();
    wul3d::write_depth_png(path, d);
    const wul3d::DepthImage back = wul3d::read_depth_png(path, 0.0002f);
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.data, d.data);
    EXPECT_FLOAT_EQ(back.scale_m_per_unit, 0.0002f);
    expect_no_temp_files(tmp.path());
}

TEST(IoImages, ColorRoundTrip_IsRgbNotBgr) {
    TempDir tmp;
    wul3d::ColorImage c = solid_color(5, 4, 250, 10, 0);
    c.rgb[3] = 1, c.rgb[4] = 2, c.rgb[5] = 3;
    const std::string path = (tmp / "color.png").string();
    wul3d::write_color_png(path, c);
    const wul3d::ColorImage back = wul3d::read_color_image(path);
    EXPECT_EQ(back.width, 5);
    EXPECT_EQ(back.height, 4);
    EXPECT_EQ(back.rgb, c.rgb);
}

TEST(IoImages, LabelAndMaskRoundTrip) {
    TempDir tmp;
    wul3d::LabelImage labels;
    labels.width = 6;
    labels.height = 3;
    labels.labels = {0, 1, 2, 3, 60000, 7, 0, 0, 1, 1, 2, 2, 9, 9, 9, 4, 4, 65535};
    const std::string lpath = (tmp / "labels.png").string();
    wul3d::write_label_png(lpath, labels);
    const wul3d::LabelImage back = wul3d::read_label_png(lpath);
    EXPECT_EQ(back.width, 6);
    EXPECT_EQ(back.height, 3);
    EXPECT_EQ(back.labels, labels.labels);

    // A mask is written as 8-bit 0 / 255; read back as (8-bit) labels, and as grey colour.
    const std::vector<std::uint8_t> mask = {0, 1, 1, 0, 5, 0};
    const std::string mpath = (tmp / "mask.png").string();
    wul3d::write_mask_png(mpath, 3, 2, mask);
    const wul3d::LabelImage m = wul3d::read_label_png(mpath);
    EXPECT_EQ(m.labels, (std::vector<std::uint16_t>{0, 255, 255, 0, 255, 0}));
    const wul3d::ColorImage grey = wul3d::read_color_image(mpath);
    EXPECT_EQ(grey.rgb.size(), 18u);
    EXPECT_EQ(grey.rgb[3], 255);
    EXPECT_EQ(grey.rgb[5], 255);
    EXPECT_EQ(grey.rgb[0], 0);
    expect_no_temp_files(tmp.path());
}

TEST(IoImages, PlyHeaderAndVertices) {
    TempDir tmp;
    wul3d::OrganizedCloud cloud;
    cloud.width = 3;
    cloud.height = 2;
    cloud.x = {0.f, 1.f, 2.f, 3.f, 4.f, 5.f};
    cloud.y = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    cloud.z = {1.f, 1.25f, 1.5f, 1.75f, 2.f, 2.25f};
    cloud.r = cloud.g = cloud.b = std::vector<std::uint8_t>(6, 0);
    cloud.valid = {1, 1, 0, 1, 1, 1};
    wul3d::LabelImage labels;
    labels.width = 3;
    labels.height = 2;
    labels.labels = {1, 0, 2, 3, 7, 0};  // pixel 2 is labelled but invalid: not written
    const wul3d::ColorImage colors = solid_color(3, 2, 10, 20, 30);
    const fs::path path = tmp / "objects.ply";
    wul3d::write_ply(path.string(), cloud, labels, colors);

    const std::string bytes = slurp(path);
    const std::string end = "end_header\n";
    const auto header_end = bytes.find(end);
    ASSERT_NE(header_end, std::string::npos);
    const std::string header = bytes.substr(0, header_end + end.size());
    EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u) << header;
    EXPECT_TRUE(contains(header, "element vertex 3\n")) << header;
    for (const char* prop : {"property float x\n", "property float y\n", "property float z\n",
                             "property uchar red\n", "property uchar green\n",
                             "property uchar blue\n", "property ushort label\n"}) {
        EXPECT_TRUE(contains(header, prop)) << prop;
    }
    ASSERT_EQ(bytes.size(), header.size() + 3 * 17);
    // Vertices in pixel order: pixels 0, 3, 4.
    const char* v = bytes.data() + header.size();
    const float expect_x[3] = {0.f, 3.f, 4.f};
    const std::uint16_t expect_label[3] = {1, 3, 7};
    for (int i = 0; i < 3; ++i, v += 17) {
        float xyz[3];
        std::uint16_t label;
        std::memcpy(xyz, v, 12);
        std::memcpy(&label, v + 15, 2);
        EXPECT_FLOAT_EQ(xyz[0], expect_x[i]);
        EXPECT_FLOAT_EQ(xyz[1], 0.5f);
        EXPECT_EQ(static_cast<std::uint8_t>(v[12]), 10);
        EXPECT_EQ(static_cast<std::uint8_t>(v[14]), 30);
        EXPECT_EQ(label, expect_label[i]);
    }
}

TEST(IoImages, CalibrationJsonRoundTrip) {
    TempDir tmp;
    wul3d::StereoCalibration c = wul3d::kinect_v2_default_calibration();
    const double a = 0.05;
    c.rotation = {std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a)};
    c.translation_m = {0.0521, -0.0013, 0.0007};
    c.depth.cx = 254.878;
    c.depth_scale_m_per_unit = 0.001f;
    const std::string path = (tmp / "calibration.json").string();
    wul3d::write_calibration_json(path, c);
    const wul3d::StereoCalibration back = wul3d::read_calibration_json(path);
    EXPECT_EQ(back.depth.width, 512);
    EXPECT_EQ(back.depth.height, 424);
    EXPECT_EQ(back.depth.cx, 254.878);
    EXPECT_EQ(back.color.fx, c.color.fx);
    EXPECT_EQ(back.color.width, 1920);
    EXPECT_EQ(back.rotation, c.rotation);
    EXPECT_EQ(back.translation_m, c.translation_m);
    EXPECT_EQ(back.depth_scale_m_per_unit, 0.001f);
    EXPECT_TRUE(contains(slurp(path), "\"depth_scale_m_per_unit\": 0.001,")) << slurp(path);
    expect_no_temp_files(tmp.path());
}

TEST(IoImages, IntrinsicsJsonOfASample) {
    const auto f = wul3d::read_intrinsics_json(
        (sample_dir() / "uois_tabletop/image_0000/intrinsics.json").string());
    EXPECT_EQ(f.intrinsics.width, 640);
    EXPECT_EQ(f.intrinsics.height, 480);
    EXPECT_DOUBLE_EQ(f.intrinsics.fx, 612.937);
    EXPECT_DOUBLE_EQ(f.intrinsics.cy, 248.158);
    EXPECT_FLOAT_EQ(f.depth_scale_m_per_unit, 0.001f);
}

TEST(IoImages, ReaderErrors_MissingFile) {
    TempDir tmp;
    const std::string path = (tmp / "nope.png").string();
    expect_input_error([&] { wul3d::read_depth_png(path, 0.001f); }, {path, "no such file"});
    expect_input_error([&] { wul3d::read_color_image(path); }, {path, "no such file"});
    expect_input_error([&] { wul3d::read_label_png(path); }, {path, "no such file"});
    expect_input_error([&] { wul3d::read_intrinsics_json(path); }, {path, "no such file"});
    expect_input_error([&] { wul3d::read_calibration_json(path); }, {path, "no such file"});
}

TEST(IoImages, ReaderErrors_TruncatedAndCorruptPng) {
    TempDir tmp;
    const fs::path good = tmp / "good.png";
    wul3d::write_depth_png(good.string(), ramp_depth(64, 48));
    const std::string bytes = slurp(good);
    ASSERT_GT(bytes.size(), 200u);

    for (std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{40}, std::size_t{8}}) {
        const fs::path cut = tmp / ("cut" + std::to_string(keep) + ".png");
        spit(cut, bytes.substr(0, keep));
        expect_input_error([&] { wul3d::read_depth_png(cut.string(), 0.001f); },
                           {cut.string(), "cannot decode"});
        expect_input_error([&] { wul3d::read_color_image(cut.string()); },
                           {cut.string(), "cannot decode"});
    }
    std::string flipped = bytes;
    flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x5a);
    const fs::path corrupt = tmp / "corrupt.png";
    spit(corrupt, flipped);
    expect_input_error([&] { wul3d::read_depth_png(corrupt.string(), 0.001f); },
                       {corrupt.string(), "cannot decode"});

    const fs::path text = tmp / "text.png";
    spit(text, "this is not an image\n");
    expect_input_error([&] { wul3d::read_depth_png(text.string(), 0.001f); },
                       {text.string(), "cannot decode"});
    expect_input_error([&] { wul3d::read_color_image(text.string()); },
                       {text.string(), "cannot decode"});
    const fs::path empty = tmp / "empty.png";
    spit(empty, "");
    expect_input_error([&] { wul3d::read_label_png(empty.string()); },
                       {empty.string(), "cannot decode"});
}

/// CRC-32 of the PNG specification, to build chunks by hand.
std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffu;
}

std::string be32(std::uint32_t v) {
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
            static_cast<char>(v)};
}

TEST(IoImages, PngWithAncillaryChunksReadsQuietly) {
    TempDir tmp;
    const fs::path path = tmp / "depth.png";
    const wul3d::DepthImage d = ramp_depth(16, 9);
    wul3d::write_depth_png(path.string(), d);
    std::string bytes = slurp(path);
    // A tEXt chunk and an unknown private ancillary chunk after IHDR (8 + 25 bytes).
    std::string chunks;
    using namespace std::string_literals;
    for (const std::string& body : {"tEXtComment\0made by io_test"s, "prVtanything at all"s}) {
        chunks += be32(static_cast<std::uint32_t>(body.size() - 4)) + body + be32(crc32(body));
    }
    bytes.insert(33, chunks);
    spit(path, bytes);
    testing::internal::CaptureStderr();
    const wul3d::DepthImage back = wul3d::read_depth_png(path.string(), 0.001f);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    EXPECT_EQ(back.data, d.data);
}

TEST(IoImages, ReaderErrors_WrongBitDepth) {
    TempDir tmp;
    const fs::path mask = tmp / "mask.png";
    wul3d::write_mask_png(mask.string(), 4, 4, std::vector<std::uint8_t>(16, 1));
    expect_input_error([&] { wul3d::read_depth_png(mask.string(), 0.001f); },
                       {mask.string(), "depth must be 16-bit single-channel PNG, got 8-bit"});
    const fs::path rgb = tmp / "rgb.png";
    wul3d::write_color_png(rgb.string(), solid_color(4, 4, 1, 2, 3));
    expect_input_error([&] { wul3d::read_depth_png(rgb.string(), 0.001f); },
                       {rgb.string(), "got 8-bit 3-channel"});
    expect_input_error([&] { wul3d::read_label_png(rgb.string()); }, {rgb.string(), "3-channel"});
    const fs::path depth = tmp / "depth.png";
    wul3d::write_depth_png(depth.string(), ramp_depth(4, 4));
    expect_input_error([&] { wul3d::read_color_image(depth.string()); },
                       {depth.string(), "8-bit", "got 16-bit"});
}

TEST(IoImages, ReaderErrors_BadJsonAndMissingKeys) {
    TempDir tmp;
    const fs::path bad = tmp / "bad.json";
    spit(bad, "{\"fx\": 525, ");
    expect_input_error([&] { wul3d::read_intrinsics_json(bad.string()); },
                       {bad.string(), "invalid JSON"});
    expect_input_error([&] { wul3d::read_calibration_json(bad.string()); },
                       {bad.string(), "invalid JSON"});

    const fs::path no_fx = tmp / "intrinsics.json";
    spit(no_fx, R"({"fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); },
                       {no_fx.string(), "missing key 'fx'"});
    spit(no_fx, R"({"fx": "525", "fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); },
                       {no_fx.string(), "'fx'", "number"});
    spit(no_fx, R"({"fx": 0, "fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); }, {no_fx.string(), "fx 0"});

    // Calibration: a missing nested key is named with its path; a non-rotation is rejected.
    const fs::path calib = tmp / "calibration.json";
    wul3d::write_calibration_json(calib.string(), wul3d::kinect_v2_default_calibration());
    std::string text = slurp(calib);
    const std::string good = text;
    text.replace(text.find("\"translation_m\""), 15, "\"translation\"");
    spit(calib, text);
    expect_input_error([&] { wul3d::read_calibration_json(calib.string()); },
                       {calib.string(), "missing key 'depth_to_color.translation_m'"});
    text = good;
    text.replace(text.rfind("\"fy\""), 4, "\"fz\"");  // keys are sorted: colour, then depth
    spit(calib, text);
    expect_input_error([&] { wul3d::read_calibration_json(calib.string()); },
                       {calib.string(), "missing key 'depth.fy'"});
    wul3d::StereoCalibration skew = wul3d::kinect_v2_default_calibration();
    skew.rotation[1] = 0.5;
    ASSERT_THROW(skew.validate(), wul3d::ParamError);
    // write_calibration_json does not validate, so the reader's check can be tested.
    wul3d::write_calibration_json(calib.string(), skew);
    expect_input_error([&] { wul3d::read_calibration_json(calib.string()); },
                       {calib.string(), "not a rotation"});
}

TEST(IoImages, AtomicWrites_FailureLeavesNoFile) {
    TempDir tmp;
    // The target is an existing folder: the rename fails after the temporary was written.
    const fs::path blocked = tmp / "labels.png";
    fs::create_directory(blocked);
    wul3d::LabelImage labels;
    labels.width = labels.height = 2;
    labels.labels = {1, 2, 3, 4};
    try {
        wul3d::write_label_png(blocked.string(), labels);
        ADD_FAILURE() << "no IoError";
    } catch (const wul3d::IoError& e) {
        EXPECT_TRUE(contains(e.what(), blocked.string())) << e.what();
    }
    expect_no_temp_files(tmp.path());
    EXPECT_TRUE(list_files(tmp.path()).empty());

    const fs::path missing_dir = tmp / "no" / "such" / "dir" / "summary.json";
    EXPECT_THROW(wul3d::write_text_file(missing_dir.string(), "{}"), wul3d::IoError);

    const fs::path text = tmp / "summary.json";
    wul3d::write_text_file(text.string(), "{\"a\": 1}\n");
    wul3d::write_text_file(text.string(), "{}\n");  // replaces
    EXPECT_EQ(slurp(text), "{}\n");
    EXPECT_EQ(list_files(tmp.path()), (std::vector<std::string>{"summary.json"}));
}

// ---- sources ------------------------------------------------------------------------

TEST(OpenSource, ParseInputFormat) {
    EXPECT_EQ(wul3d::parse_input_format("auto"), wul3d::InputFormat::Auto);
    EXPECT_EQ(wul3d::parse_input_format("frames"), wul3d::InputFormat::Frames);
    EXPECT_EQ(wul3d::parse_input_format("tum"), wul3d::InputFormat::Tum);
    EXPECT_EQ(wul3d::parse_input_format("unregistered"), wul3d::InputFormat::Unregistered);
    EXPECT_THROW(wul3d::parse_input_format("bag"), wul3d::ParamError);
}

TEST(OpenSource, SampleFolderOfFrameFolders) {
    auto src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), {});
    ASSERT_EQ(src->size(), 4u);
    EXPECT_EQ(src->format(), wul3d::InputFormat::Frames);
    EXPECT_EQ(src->calibration(), nullptr);
    EXPECT_EQ(src->name(0), "image_0000");
    EXPECT_EQ(src->name(1), "image_0002");
    EXPECT_EQ(src->name(3), "image_0007");
    wul3d::SourceItem item;
    src->read(0, item);
    EXPECT_FALSE(item.is_raw);
    EXPECT_EQ(item.frame.name, "image_0000");
    EXPECT_EQ(item.frame.width(), 640);
    EXPECT_EQ(item.frame.height(), 480);
    EXPECT_TRUE(item.frame.has_color());
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 612.937);
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 0.001f);
    const std::uint16_t* depth = item.frame.depth.data.data();
    const std::uint8_t* color = item.frame.color.rgb.data();
    src->read(3, item);
    EXPECT_EQ(item.frame.name, "image_0007");
    EXPECT_EQ(item.frame.depth.data.data(), depth) << "depth buffer not reused";
    EXPECT_EQ(item.frame.color.rgb.data(), color) << "colour buffer not reused";
}

TEST(OpenSource, SampleDepthOnlySequence) {
    auto src = wul3d::open_source((sample_dir() / "pcl_kinect/pairwise_seq").string(), {});
    ASSERT_EQ(src->size(), 5u);
    EXPECT_EQ(src->name(0), "capture0001");
    EXPECT_EQ(src->name(4), "capture0005");
    wul3d::SourceItem item;
    src->read(2, item);
    EXPECT_FALSE(item.frame.has_color());
    EXPECT_EQ(item.frame.width(), 640);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);
}

TEST(OpenSource, SampleSingleFrameFolder_AndSubFoldersThatAreNotFrames) {
    for (const std::string suffix : {"", "/"}) {
        auto src = wul3d::open_source((sample_dir() / "uois_tabletop/image_0002").string() + suffix, {});
        ASSERT_EQ(src->size(), 1u);
        EXPECT_EQ(src->name(0), "image_0002");
    }
    // pcl_kinect holds two frame folders and pairwise_seq, a folder of frames, not a frame.
    auto src = wul3d::open_source((sample_dir() / "pcl_kinect").string(), {});
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "milk_cartoon_all_small_clorox");
    EXPECT_EQ(src->name(1), "region_growing_rgb_tutorial");
}

TEST(OpenSource, IntrinsicsOverride) {
    wul3d::SourceOptions opt;
    opt.intrinsics = wul3d::PinholeIntrinsics{640, 480, 500, 501, 320, 240};
    auto src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), opt);
    wul3d::SourceItem item;
    src->read(1, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 500);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fy, 501);
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 0.001f);

    // No size given (as the CLI's --intrinsics fx,fy,cx,cy): each frame's own.
    opt.intrinsics = wul3d::PinholeIntrinsics{0, 0, 500, 501, 320, 240};
    src = wul3d::open_source((sample_dir() / "pcl_kinect/pairwise_seq").string(), opt);
    src->read(0, item);
    EXPECT_EQ(item.frame.intrinsics.width, 640);
    EXPECT_EQ(item.frame.intrinsics.height, 480);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fy, 501);

    opt.intrinsics = wul3d::PinholeIntrinsics{512, 424, 365, 365, 256, 212};
    src = wul3d::open_source((sample_dir() / "uois_tabletop").string(), opt);
    expect_input_error([&] { src->read(0, item); }, {"image_0000", "640x480", "512x424"});
}

TEST(OpenSource, Errors) {
    TempDir tmp;
    const std::string missing = (tmp / "missing").string();
    expect_input_error([&] { wul3d::open_source(missing, {}); }, {missing, "no such file or directory"});
    expect_input_error([&] { wul3d::open_source(tmp.path().string(), {}); },
                       {tmp.path().string(), "no frames found (expected"});

    // A frame folder without depth.png, in a sequence and on its own.
    fs::create_directories(tmp / "seq" / "f0");
    fs::create_directories(tmp / "seq" / "f1");
    wul3d::write_depth_png((tmp / "seq/f0/depth.png").string(), ramp_depth(8, 6));
    wul3d::write_color_png((tmp / "seq/f1/color.png").string(), solid_color(8, 6, 1, 2, 3));
    expect_input_error([&] { wul3d::open_source((tmp / "seq").string(), {}); },
                       {(tmp / "seq" / "f1").string(), "no depth.png"});
    expect_input_error([&] { wul3d::open_source((tmp / "seq/f1").string(), {}); },
                       {"f1", "no depth.png"});

    // Missing intrinsics.json is found when the frame is read.
    auto src = wul3d::open_source((tmp / "seq/f0").string(), {});
    wul3d::SourceItem item;
    expect_input_error([&] { src->read(0, item); }, {"intrinsics.json", "no such file"});

    // Colour and depth of different sizes without a calibration.
    wul3d::write_depth_png((tmp / "seq/f1/depth.png").string(), ramp_depth(4, 3));
    wul3d::write_text_file((tmp / "seq/f1/intrinsics.json").string(),
                           R"({"fx": 5, "fy": 5, "cx": 2, "cy": 1.5, "width": 4, "height": 3})");
    src = wul3d::open_source((tmp / "seq/f1").string(), {});
    expect_input_error([&] { src->read(0, item); },
                       {"f1", "color.png is 8x6 but depth.png is 4x3", "--calibration"});
}

/// A tiny TUM RGB-D sequence: depth at t = 1.000, 1.033, 1.100; colour at t = 1.010,
/// 1.060, 1.119. With 20 ms, 1.000 pairs with 1.010 and 1.100 with 1.119; 1.033 is 23 and
/// 27 ms from its neighbours and is dropped.
fs::path write_tum(const fs::path& root) {
    fs::create_directories(root / "rgb");
    fs::create_directories(root / "depth");
    const char* rgb_stamps[3] = {"1.010000", "1.060000", "1.119000"};
    const char* depth_stamps[3] = {"1.000000", "1.033000", "1.100000"};
    std::string rgb_txt = "# color images\n# file: 'test'\n# timestamp filename\n";
    std::string depth_txt = "# depth maps\n# timestamp filename\n\n";
    for (int i = 0; i < 3; ++i) {
        const auto k = static_cast<std::uint8_t>(10 * (i + 1));
        wul3d::write_color_png((root / "rgb" / (std::string(rgb_stamps[i]) + ".png")).string(),
                               solid_color(640, 480, k, k, k));
        wul3d::DepthImage d;
        d.width = 640;
        d.height = 480;
        d.data.assign(640 * 480, static_cast<std::uint16_t>(5000 * (i + 1)));  // 1, 2, 3 m
        wul3d::write_depth_png((root / "depth" / (std::string(depth_stamps[i]) + ".png")).string(), d);
        rgb_txt += std::string(rgb_stamps[i]) + " rgb/" + rgb_stamps[i] + ".png\n";
        depth_txt += std::string(depth_stamps[i]) + " depth/" + depth_stamps[i] + ".png\n";
    }
    wul3d::write_text_file((root / "rgb.txt").string(), rgb_txt);
    wul3d::write_text_file((root / "depth.txt").string(), depth_txt);
    return root;
}

TEST(OpenSource, TumAssociationScaleAndIntrinsics) {
    TempDir tmp;
    const fs::path root = write_tum(tmp / "rgbd_dataset_freiburg2_tiny");
    auto src = wul3d::open_source(root.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Tum);
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "1.000000");
    EXPECT_EQ(src->name(1), "1.100000");
    wul3d::SourceItem item;
    src->read(1, item);
    EXPECT_EQ(item.frame.name, "1.100000");
    EXPECT_FLOAT_EQ(item.frame.depth.scale_m_per_unit, 1.0f / 5000.0f);
    EXPECT_EQ(item.frame.depth.data[0], 15000);
    EXPECT_NEAR(item.frame.depth.data[0] * item.frame.depth.scale_m_per_unit, 3.0, 1e-6);
    EXPECT_EQ(item.frame.color.rgb[0], 30) << "1.100 must take the colour of 1.119";
    const wul3d::PinholeIntrinsics fr2 = wul3d::intrinsics_preset("tum_fr2");
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, fr2.fx);
    src->read(0, item);
    EXPECT_EQ(item.frame.color.rgb[0], 10);
    EXPECT_NEAR(item.frame.depth.data[0] * item.frame.depth.scale_m_per_unit, 1.0, 1e-6);

    // A wider tolerance keeps 1.033 too; a preset or explicit intrinsics win over the name.
    wul3d::SourceOptions opt;
    opt.tum_max_dt_s = 0.03;
    opt.tum_camera = "kinect_v1";
    src = wul3d::open_source(root.string(), opt);
    EXPECT_EQ(src->size(), 3u);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);
    opt.intrinsics = wul3d::PinholeIntrinsics{640, 480, 600, 600, 320, 240};
    src = wul3d::open_source(root.string(), opt);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 600.0);
    opt.intrinsics = wul3d::PinholeIntrinsics{0, 0, 610, 610, 320, 240};
    src = wul3d::open_source(root.string(), opt);
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 610.0);
    EXPECT_EQ(item.frame.intrinsics.width, 640);

    opt = {};
    opt.tum_max_dt_s = 0.001;
    expect_input_error([&] { wul3d::open_source(root.string(), opt); },
                       {root.string(), "no frames found"});

    // Without freiburgN in the name: the Kinect v1 default.
    const fs::path plain = write_tum(tmp / "my_recording");
    src = wul3d::open_source(plain.string(), {});
    src->read(0, item);
    EXPECT_DOUBLE_EQ(item.frame.intrinsics.fx, 525.0);

    wul3d::write_text_file((plain / "rgb.txt").string(), "1.0\n");
    expect_input_error([&] { wul3d::open_source(plain.string(), {}); }, {"rgb.txt:1", "timestamp"});
}

TEST(OpenSource, Unregistered) {
    TempDir tmp;
    const wul3d::StereoCalibration kinect = wul3d::kinect_v2_default_calibration();
    const fs::path seq = tmp / "seq";
    for (const char* name : {"b", "a"}) {
        fs::create_directories(seq / name);
        wul3d::DepthImage d;
        d.width = 512;
        d.height = 424;
        d.data.assign(512 * 424, 1234);
        wul3d::write_depth_png((seq / name / "depth.png").string(), d);
        wul3d::write_color_png((seq / name / "color.png").string(), solid_color(1920, 1080, 9, 8, 7));
    }
    // Without a calibration: the size mismatch is reported with the hint.
    auto src = wul3d::open_source(seq.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Frames);
    wul3d::SourceItem item;
    expect_input_error([&] { src->read(0, item); }, {"color.png is 1920x1080", "--calibration"});
    wul3d::SourceOptions explicit_format;
    explicit_format.format = wul3d::InputFormat::Unregistered;
    expect_input_error([&] { wul3d::open_source(seq.string(), explicit_format); },
                       {seq.string(), "calibration"});

    // The built-in preset.
    wul3d::SourceOptions opt;
    opt.calibration = "kinect_v2";
    src = wul3d::open_source(seq.string(), opt);
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    ASSERT_NE(src->calibration(), nullptr);
    EXPECT_EQ(src->calibration()->color.fx, kinect.color.fx);

    // calibration.json beside the frames is found by auto-detection.
    wul3d::StereoCalibration mine = kinect;
    mine.translation_m = {0.05, 0.001, -0.002};
    wul3d::write_calibration_json((seq / "calibration.json").string(), mine);
    src = wul3d::open_source(seq.string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    ASSERT_EQ(src->size(), 2u);
    EXPECT_EQ(src->name(0), "a");
    ASSERT_NE(src->calibration(), nullptr);
    EXPECT_EQ(src->calibration()->translation_m, mine.translation_m);
    src->read(1, item);
    EXPECT_TRUE(item.is_raw);
    EXPECT_EQ(item.raw.name, "b");
    EXPECT_EQ(item.raw.depth.width, 512);
    EXPECT_EQ(item.raw.color.width, 1920);
    EXPECT_EQ(item.raw.color.rgb[0], 9);
    EXPECT_EQ(item.raw.depth.data[7], 1234);

    // A single frame folder finds calibration.json in its parent.
    src = wul3d::open_source((seq / "a").string(), {});
    EXPECT_EQ(src->format(), wul3d::InputFormat::Unregistered);
    EXPECT_EQ(src->size(), 1u);

    // An explicit calibration file whose sizes do not fit the frames.
    wul3d::StereoCalibration wrong = kinect;
    wrong.depth.width = 640;
    wrong.depth.height = 480;
    opt.calibration = (tmp / "wrong.json").string();
    wul3d::write_calibration_json(opt.calibration, wrong);
    src = wul3d::open_source(seq.string(), opt);
    expect_input_error([&] { src->read(0, item); }, {"depth.png is 512x424", "640x480"});
}

}  // namespace
