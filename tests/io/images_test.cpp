// Readers and writers of io.hpp: round trips, PNGs of every kind made byte by byte and JPEGs
// made with libjpeg, every reader error, atomic writes and the readers' limits (open_source:
// sources_test.cpp).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>  // before jpeglib.h, which needs FILE and size_t
#include <jpeglib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io_expect.hpp"
#include "png_bytes.hpp"
#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::test::contains;
using wul3d::test::expect_input_error;
using wul3d::test::expect_no_temp_files;
using wul3d::test::list_files;
using wul3d::test::ramp_depth;
using wul3d::test::sample_dir;
using wul3d::test::slurp;
using wul3d::test::solid_color;
using wul3d::test::write_text;
using namespace wul3d::test::png_bytes;
using wul3d::test::TempDir;

// ---- single files -------------------------------------------------------------------

// Found by fuzz/fuzz_jpeg.cpp in CI: an 80 x 60 JPEG with a second frame header after its
// scan. Finishing the decode rewrote libjpeg's size, and the image came back as 0 x 55296
// over 80 x 60 pixels. The size is the first header's, and matches the pixels.
TEST(IoImages, JpegWithASecondFrameHeaderKeepsItsSize) {
    const std::string path =
        (fs::path(WUL3D_TEST_DATA_DIR) / "fuzz" / "jpeg-second-frame-header.jpg").string();
    try {
        const wul3d::ColorImage c = wul3d::read_color_image(path);
        EXPECT_EQ(c.width, 80);
        EXPECT_EQ(c.height, 60);
        EXPECT_EQ(c.rgb.size(), 3u * 80u * 60u);
    } catch (const wul3d::InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

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
        write_text(cut, bytes.substr(0, keep));
        expect_input_error([&] { wul3d::read_depth_png(cut.string(), 0.001f); },
                           {cut.string(), "cannot decode"});
        expect_input_error([&] { wul3d::read_color_image(cut.string()); },
                           {cut.string(), "cannot decode"});
    }
    std::string flipped = bytes;
    flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x5a);
    const fs::path corrupt = tmp / "corrupt.png";
    write_text(corrupt, flipped);
    expect_input_error([&] { wul3d::read_depth_png(corrupt.string(), 0.001f); },
                       {corrupt.string(), "cannot decode"});

    const fs::path text = tmp / "text.png";
    write_text(text, "this is not an image\n");
    expect_input_error([&] { wul3d::read_depth_png(text.string(), 0.001f); },
                       {text.string(), "cannot decode"});
    expect_input_error([&] { wul3d::read_color_image(text.string()); },
                       {text.string(), "cannot decode"});
    const fs::path empty = tmp / "empty.png";
    write_text(empty, "");
    expect_input_error([&] { wul3d::read_label_png(empty.string()); },
                       {empty.string(), "cannot decode"});
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
    write_text(path, bytes);
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

// ---- PNG and JPEG made here, byte by byte or with libjpeg ---------------------------------

TEST(IoImages, Png16BitSamplesAreBigEndianInTheFile) {
    TempDir tmp;
    // 3x2 16-bit grey, samples chosen so that a byte swap shows.
    const std::vector<std::uint16_t> v = {0x0102, 0xff00, 0x00ff, 0xabcd, 1, 65535};
    std::vector<std::string> rows(2);
    for (std::size_t p = 0; p < v.size(); ++p) rows[p / 3] += be16(v[p]);
    const fs::path path = tmp / "depth.png";
    write_text(path, png_file(3, 2, 16, 0, zlib_stored(unfiltered(rows))));
    EXPECT_EQ(wul3d::read_depth_png(path.string(), 0.001f).data, v);
    EXPECT_EQ(wul3d::read_label_png(path.string()).labels, v);
}

TEST(IoImages, WrittenPngs_HeaderAndExactRoundTrip) {
    TempDir tmp;
    // Bit depth and colour type of IHDR (bytes 24, 25), no interlace (byte 28).
    auto header = [&](const fs::path& p) {
        const std::string b = slurp(p);
        EXPECT_EQ(b.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
        EXPECT_EQ(b.substr(12, 4), "IHDR");
        EXPECT_EQ(b[28], 0) << p;
        return std::pair<int, int>{b[24], b[25]};
    };
    const int w = 67, h = 45;  // odd sizes: no row is a multiple of 4 bytes
    const wul3d::DepthImage depth = ramp_depth(w, h);
    wul3d::write_depth_png((tmp / "depth.png").string(), depth);
    EXPECT_EQ(header(tmp / "depth.png"), (std::pair<int, int>{16, 0}));
    EXPECT_EQ(wul3d::read_depth_png((tmp / "depth.png").string(), 0.001f).data, depth.data);

    wul3d::LabelImage labels;
    labels.width = w;
    labels.height = h;
    labels.labels.assign(depth.data.rbegin(), depth.data.rend());
    wul3d::write_label_png((tmp / "labels.png").string(), labels);
    EXPECT_EQ(header(tmp / "labels.png"), (std::pair<int, int>{16, 0}));
    EXPECT_EQ(wul3d::read_label_png((tmp / "labels.png").string()).labels, labels.labels);

    wul3d::ColorImage color = solid_color(w, h, 0, 0, 0);
    for (std::size_t i = 0; i < color.rgb.size(); ++i) color.rgb[i] = static_cast<std::uint8_t>(i * 31 % 251);
    wul3d::write_color_png((tmp / "color.png").string(), color);
    EXPECT_EQ(header(tmp / "color.png"), (std::pair<int, int>{8, 2}));
    const wul3d::ColorImage back = wul3d::read_color_image((tmp / "color.png").string());
    EXPECT_EQ(back.width, w);
    EXPECT_EQ(back.height, h);
    EXPECT_EQ(back.rgb, color.rgb);

    wul3d::write_mask_png((tmp / "mask.png").string(), 3, 1, {0, 1, 0});
    EXPECT_EQ(header(tmp / "mask.png"), (std::pair<int, int>{8, 0}));
}

// A palette PNG is colour for read_color_image, and its indices for read_label_png (the
// annotations of PASCAL VOC and of many datasets: the index is the id, the palette shows it).
TEST(IoImages, PalettePngs_AreColourWithAlphaDropped_AndTheirIndicesAreLabels) {
    TempDir tmp;
    // 2-bit palette, 4 pixels: entries 3, 0, 1, 2 packed into one byte.
    const std::string plte = png_chunk("PLTE", std::string("\x0a\x14\x1e\x28\x32\x3c\x46\x50\x5a\xc8\x64\x00", 12));
    const std::string idat = zlib_stored(unfiltered({"\xc6"}));
    const std::vector<std::uint8_t> expect = {200, 100, 0, 10, 20, 30, 40, 50, 60, 70, 80, 90};
    const fs::path opaque = tmp / "palette.png";
    write_text(opaque, png_file(4, 1, 2, 3, idat, plte));
    const wul3d::ColorImage c = wul3d::read_color_image(opaque.string());
    EXPECT_EQ(c.width, 4);
    EXPECT_EQ(c.rgb, expect);
    const std::vector<std::uint16_t> indices = {3, 0, 1, 2};
    const wul3d::LabelImage l = wul3d::read_label_png(opaque.string());
    EXPECT_EQ(l.width, 4);
    EXPECT_EQ(l.height, 1);
    EXPECT_EQ(l.labels, indices);
    // 8 bits an index, the same entries.
    const fs::path wide = tmp / "palette8.png";
    write_text(wide, png_file(4, 1, 8, 3, zlib_stored(unfiltered({std::string("\x03\x00\x01\x02", 4)})), plte));
    EXPECT_EQ(wul3d::read_label_png(wide.string()).labels, indices);
    EXPECT_EQ(wul3d::read_color_image(wide.string()).rgb, expect);

    // With tRNS (alpha for the first two entries): four channels, the alpha is dropped.
    const fs::path transparent = tmp / "palette_trns.png";
    write_text(transparent, png_file(4, 1, 2, 3, idat, plte + png_chunk("tRNS", std::string("\x00\x80", 2))));
    EXPECT_EQ(wul3d::read_color_image(transparent.string()).rgb, expect);
    EXPECT_EQ(wul3d::read_label_png(transparent.string()).labels, indices);
    expect_input_error([&] { wul3d::read_depth_png(transparent.string(), 0.001f); },
                       {transparent.string(), "got 8-bit 4-channel"});
}

TEST(IoImages, GreyAlphaLowBitAndInterlacedPngs) {
    TempDir tmp;
    // Grey + alpha, 8-bit: colour is the grey three times; not labels (4 channels, as OpenCV had it).
    const fs::path ga = tmp / "grey_alpha.png";
    write_text(ga, png_file(2, 1, 8, 4, zlib_stored(unfiltered({std::string("\x10\xff\xe0\x00", 4)}))));
    EXPECT_EQ(wul3d::read_color_image(ga.string()).rgb, (std::vector<std::uint8_t>{16, 16, 16, 224, 224, 224}));
    expect_input_error([&] { wul3d::read_label_png(ga.string()); }, {ga.string(), "got 8-bit 4-channel"});
    const fs::path ga16 = tmp / "grey_alpha16.png";
    write_text(ga16, png_file(1, 1, 16, 4, zlib_stored(unfiltered({be16(1000) + be16(65535)}))));
    expect_input_error([&] { wul3d::read_depth_png(ga16.string(), 0.001f); },
                       {ga16.string(), "got 16-bit 4-channel"});

    // 1-bit and 4-bit grey are scaled to 8 bits: as labels, as colour.
    const fs::path g1 = tmp / "grey1.png";
    write_text(g1, png_file(8, 1, 1, 0, zlib_stored(unfiltered({"\xb1"}))));
    EXPECT_EQ(wul3d::read_label_png(g1.string()).labels,
              (std::vector<std::uint16_t>{255, 0, 255, 255, 0, 0, 0, 255}));
    const fs::path g4 = tmp / "grey4.png";
    write_text(g4, png_file(3, 1, 4, 0, zlib_stored(unfiltered({"\x1f\x70"}))));
    EXPECT_EQ(wul3d::read_label_png(g4.string()).labels, (std::vector<std::uint16_t>{17, 255, 119}));
    EXPECT_EQ(wul3d::read_color_image(g4.string()).rgb,
              (std::vector<std::uint8_t>{17, 17, 17, 255, 255, 255, 119, 119, 119}));

    // RGB with a tRNS colour: four channels, read as its RGB.
    const fs::path rgbt = tmp / "rgb_trns.png";
    write_text(rgbt, png_file(1, 1, 8, 2, zlib_stored(unfiltered({"\x01\x02\x03"})),
                        png_chunk("tRNS", be16(1) + be16(2) + be16(3))));
    EXPECT_EQ(wul3d::read_color_image(rgbt.string()).rgb, (std::vector<std::uint8_t>{1, 2, 3}));
    expect_input_error([&] { wul3d::read_label_png(rgbt.string()); }, {rgbt.string(), "got 8-bit 4-channel"});

    // Adam7 interlaced 16-bit depth, 5x4: the passes hold the pixels in their own order.
    const int w = 5, h = 4;
    auto value = [](int x, int y) { return static_cast<std::uint16_t>(1000 * y + 10 * x + 1); };
    const int pass[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                            {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};  // x0, y0, dx, dy
    std::vector<std::string> rows;
    for (const auto& p : pass) {
        if (p[0] >= w || p[1] >= h) continue;  // an empty pass has no rows
        for (int y = p[1]; y < h; y += p[3]) {
            std::string row;
            for (int x = p[0]; x < w; x += p[2]) row += be16(value(x, y));
            rows.push_back(row);
        }
    }
    const fs::path interlaced = tmp / "interlaced.png";
    write_text(interlaced, png_file(w, h, 16, 0, zlib_stored(unfiltered(rows)), "", true));
    const wul3d::DepthImage d = wul3d::read_depth_png(interlaced.string(), 0.001f);
    ASSERT_EQ(d.data.size(), static_cast<std::size_t>(w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) EXPECT_EQ(d.data[y * w + x], value(x, y)) << x << "," << y;
}

TEST(IoImages, DamagedImageDataWithValidCrc_OneQuietInputError) {
    TempDir tmp;
    // A written depth PNG whose IDAT data is garbage after the zlib header, CRC recomputed:
    // check_png passes it, zlib fails inside libpng.
    const fs::path good = tmp / "good.png";
    wul3d::write_depth_png(good.string(), ramp_depth(64, 48));
    std::string bytes = slurp(good);
    const std::size_t idat = bytes.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    const std::uint32_t len = (std::uint32_t{static_cast<unsigned char>(bytes[idat - 4])} << 24) |
                              (std::uint32_t{static_cast<unsigned char>(bytes[idat - 3])} << 16) |
                              (std::uint32_t{static_cast<unsigned char>(bytes[idat - 2])} << 8) |
                              static_cast<unsigned char>(bytes[idat - 1]);
    ASSERT_GT(len, 100u);
    for (std::uint32_t i = 2; i < len; ++i) bytes[idat + 4 + i] = static_cast<char>(0xff - i * 7 % 256);
    bytes.replace(idat + 4 + len, 4, be32(crc32(bytes.substr(idat, 4 + len))));
    const fs::path garbage = tmp / "garbage.png";
    write_text(garbage, bytes);
    expect_input_error([&] { wul3d::read_depth_png(garbage.string(), 0.001f); },
                       {garbage.string(), "cannot decode PNG ("});
    expect_input_error([&] { wul3d::read_label_png(garbage.string()); }, {garbage.string(), "cannot decode PNG ("});

    // Too little image data: an error. Too much: libpng warns and reads the image; quietly.
    const std::string row = be16(7) + be16(8);
    const fs::path short_data = tmp / "short.png";
    write_text(short_data, png_file(2, 3, 16, 0, zlib_stored(unfiltered({row, row}))));
    expect_input_error([&] { wul3d::read_depth_png(short_data.string(), 0.001f); },
                       {short_data.string(), "cannot decode PNG (Not enough image data)"});
    const fs::path long_data = tmp / "long.png";
    write_text(long_data, png_file(2, 1, 16, 0, zlib_stored(unfiltered({row, row, row}))));
    testing::internal::CaptureStderr();
    const wul3d::DepthImage d = wul3d::read_depth_png(long_data.string(), 0.001f);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    EXPECT_EQ(d.data, (std::vector<std::uint16_t>{7, 8}));
}

TEST(OpenSource, DamagedFrame_LeavesItsImageEmpty) {
    TempDir tmp;
    for (const char* name : {"f0", "f1"}) {
        fs::create_directories(tmp / name);
        wul3d::write_depth_png((tmp / name / "depth.png").string(), ramp_depth(8, 6));
        wul3d::write_text_file((tmp / name / "intrinsics.json").string(),
                               R"({"fx": 5, "fy": 5, "cx": 4, "cy": 3, "width": 8, "height": 6})");
    }
    // f1's image data stops after two of its six rows.
    write_text(tmp / "f1" / "depth.png", png_file(8, 6, 16, 0, zlib_stored(unfiltered({std::string(16, 'a'), std::string(16, 'b')}))));
    auto src = wul3d::open_source(tmp.path().string(), {});
    wul3d::SourceItem item;
    src->read(0, item);
    EXPECT_EQ(item.frame.depth.width, 8);
    expect_input_error([&] { src->read(1, item); }, {"f1", "cannot decode PNG"});
    // Not f0's size over half of f1's pixels.
    EXPECT_EQ(item.frame.depth.width, 0);
    EXPECT_EQ(item.frame.depth.height, 0);
    EXPECT_TRUE(item.frame.depth.data.empty());
}

/// Writes a JPEG with libjpeg: `components` 1 (grey), 3 (RGB) or 4 (CMYK) per pixel,
/// quality 100 without chroma subsampling, so that the pixels come back within a step or two.
void write_jpeg(const fs::path& path, int w, int h, int components, const std::vector<std::uint8_t>& pixels) {
    jpeg_compress_struct c{};
    jpeg_error_mgr err{};
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    unsigned char* buf = nullptr;
    unsigned long size = 0;
    jpeg_mem_dest(&c, &buf, &size);
    c.image_width = static_cast<JDIMENSION>(w);
    c.image_height = static_cast<JDIMENSION>(h);
    c.input_components = components;
    c.in_color_space = components == 1 ? JCS_GRAYSCALE : components == 3 ? JCS_RGB : JCS_CMYK;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    for (int i = 0; i < c.num_components; ++i) c.comp_info[i].h_samp_factor = c.comp_info[i].v_samp_factor = 1;
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = const_cast<std::uint8_t*>(pixels.data()) + std::size_t{c.next_scanline} * w * components;
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    write_text(path, std::string(reinterpret_cast<const char*>(buf), size));
    jpeg_destroy_compress(&c);
    std::free(buf);
}

/// Every channel of every pixel within `tol` of `rgb`.
void expect_near_rgb(const wul3d::ColorImage& c, const std::array<int, 3>& rgb, int tol) {
    ASSERT_FALSE(c.rgb.empty());
    for (std::size_t i = 0; i < c.rgb.size(); ++i) {
        ASSERT_NEAR(c.rgb[i], rgb[i % 3], tol) << "pixel " << i / 3 << " channel " << i % 3;
    }
}

TEST(IoImages, JpegRgbGreyAndCmyk) {
    TempDir tmp;
    const int w = 24, h = 17;  // not whole 8x8 blocks
    const auto n = static_cast<std::size_t>(w * h);
    std::vector<std::uint8_t> rgb(3 * n);
    for (std::size_t p = 0; p < n; ++p) rgb[3 * p] = 200, rgb[3 * p + 1] = 50, rgb[3 * p + 2] = 10;
    write_jpeg(tmp / "rgb.jpg", w, h, 3, rgb);
    const wul3d::ColorImage c = wul3d::read_color_image((tmp / "rgb.jpg").string());
    EXPECT_EQ(c.width, w);
    EXPECT_EQ(c.height, h);
    expect_near_rgb(c, {200, 50, 10}, 2);  // RGB, not BGR

    write_jpeg(tmp / "grey.jpg", w, h, 1, std::vector<std::uint8_t>(n, 77));
    const wul3d::ColorImage g = wul3d::read_color_image((tmp / "grey.jpg").string());
    expect_near_rgb(g, {77, 77, 77}, 1);
    for (std::size_t p = 0; p < n; ++p) {
        ASSERT_EQ(g.rgb[3 * p], g.rgb[3 * p + 1]);
        ASSERT_EQ(g.rgb[3 * p], g.rgb[3 * p + 2]);
    }

    // CMYK as OpenCV converted it: R = K - (255 - C) K / 256, G from M, B from Y.
    std::vector<std::uint8_t> cmyk(4 * n);
    for (std::size_t p = 0; p < n; ++p) cmyk[4 * p] = 200, cmyk[4 * p + 1] = 100, cmyk[4 * p + 2] = 0, cmyk[4 * p + 3] = 220;
    write_jpeg(tmp / "cmyk.jpg", w, h, 4, cmyk);
    expect_near_rgb(wul3d::read_color_image((tmp / "cmyk.jpg").string()),
                    {220 - 55 * 220 / 256, 220 - 155 * 220 / 256, 220 - 255 * 220 / 256}, 2);

    // Depth and labels are PNG only.
    expect_input_error([&] { wul3d::read_depth_png((tmp / "rgb.jpg").string(), 0.001f); },
                       {"rgb.jpg", "not a PNG file"});
}

TEST(IoImages, DamagedJpeg_OneQuietInputErrorOrQuietPixels) {
    TempDir tmp;
    std::vector<std::uint8_t> rgb(3 * 32 * 32);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 13 % 256);
    write_jpeg(tmp / "good.jpg", 32, 32, 3, rgb);
    const std::string good = slurp(tmp / "good.jpg");

    // No end-of-image marker: the check before libjpeg.
    write_text(tmp / "cut.jpg", good.substr(0, good.size() / 2));
    expect_input_error([&] { wul3d::read_color_image((tmp / "cut.jpg").string()); },
                       {"cut.jpg", "cannot decode JPEG (truncated"});
    // A frame header of 0 x 0 pixels: libjpeg's error, on one line.
    std::string bad = good;
    const std::size_t sof = bad.find("\xff\xc0");
    ASSERT_NE(sof, std::string::npos);
    bad.replace(sof + 5, 4, std::string(4, '\0'));
    write_text(tmp / "sof.jpg", bad);
    expect_input_error([&] { wul3d::read_color_image((tmp / "sof.jpg").string()); },
                       {"sof.jpg", "cannot decode JPEG ("});
    // Damaged scan data: libjpeg warns and decodes what it can, as before; quietly.
    bad = good;
    const std::size_t sos = bad.find("\xff\xda");
    ASSERT_NE(sos, std::string::npos);
    const std::size_t mid = sos + (bad.size() - sos) / 2;
    for (std::size_t i = mid; i < mid + 40; ++i) bad[i] = static_cast<char>(0x5a);
    write_text(tmp / "scan.jpg", bad);
    testing::internal::CaptureStderr();
    const wul3d::ColorImage c = wul3d::read_color_image((tmp / "scan.jpg").string());
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    EXPECT_EQ(c.width, 32);
}

TEST(IoImages, ReaderErrors_BadJsonAndMissingKeys) {
    TempDir tmp;
    const fs::path bad = tmp / "bad.json";
    write_text(bad, "{\"fx\": 525, ");
    expect_input_error([&] { wul3d::read_intrinsics_json(bad.string()); },
                       {bad.string(), "invalid JSON"});
    expect_input_error([&] { wul3d::read_calibration_json(bad.string()); },
                       {bad.string(), "invalid JSON"});

    const fs::path no_fx = tmp / "intrinsics.json";
    write_text(no_fx, R"({"fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); },
                       {no_fx.string(), "missing key 'fx'"});
    write_text(no_fx, R"({"fx": "525", "fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); },
                       {no_fx.string(), "'fx'", "number"});
    write_text(no_fx, R"({"fx": 0, "fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480})");
    expect_input_error([&] { wul3d::read_intrinsics_json(no_fx.string()); }, {no_fx.string(), "fx 0"});

    // Calibration: a missing nested key is named with its path; a non-rotation is rejected.
    const fs::path calib = tmp / "calibration.json";
    wul3d::write_calibration_json(calib.string(), wul3d::kinect_v2_default_calibration());
    std::string text = slurp(calib);
    const std::string good = text;
    text.replace(text.find("\"translation_m\""), 15, "\"translation\"");
    write_text(calib, text);
    expect_input_error([&] { wul3d::read_calibration_json(calib.string()); },
                       {calib.string(), "missing key 'depth_to_color.translation_m'"});
    text = good;
    text.replace(text.rfind("\"fy\""), 4, "\"fz\"");  // keys are sorted: colour, then depth
    write_text(calib, text);
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

}  // namespace

// ---- limits (issue 24): regular files only, sizes checked before allocation ----------------

TEST(IoLimits, FifoAndFolderAreRefusedByType) {
    wul3d::test::TempDir tmp;
    const fs::path fifo = tmp / "intrinsics.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    try {
        wul3d::read_intrinsics_json(fifo.string());  // would block in open() if opened
        FAIL() << "no error";
    } catch (const wul3d::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("FIFO"), std::string::npos) << e.what();
    }
    EXPECT_THROW(wul3d::read_depth_png(fifo.string(), 0.001f), wul3d::InputError);
    EXPECT_THROW(wul3d::read_color_image(tmp.path().string()), wul3d::InputError);
    EXPECT_THROW(wul3d::read_label_png("/dev/zero"), wul3d::InputError);
}

TEST(IoLimits, OversizedJsonIsRefusedBeforeReading) {
    wul3d::test::TempDir tmp;
    const fs::path big = tmp / "intrinsics.json";
    {
        std::ofstream out(big, std::ios::binary);
        out << R"({"fx": 500, "fy": 500, "cx": 320, "cy": 240, "width": 640, "height": 480})";
    }
    EXPECT_NO_THROW(wul3d::read_intrinsics_json(big.string()));
    fs::resize_file(big, wul3d::kMaxJsonBytes + 1);  // sparse: no disk used
    try {
        wul3d::read_intrinsics_json(big.string());
        FAIL() << "no error";
    } catch (const wul3d::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("1 MiB"), std::string::npos) << e.what();
    }
}

TEST(IoLimits, ImageLimitComesFromTheHeader) {
    const std::string depth =
        (wul3d::test::sample_dir() / "uois_tabletop" / "image_0000" / "depth.png").string();
    ASSERT_EQ(wul3d::max_image_pixels(), wul3d::kDefaultMaxImagePixels);
    wul3d::set_max_image_pixels(640 * 480 - 1);
    EXPECT_THROW(wul3d::read_depth_png(depth, 0.001f), wul3d::InputError);
    wul3d::set_max_image_pixels(640 * 480);
    EXPECT_EQ(wul3d::read_depth_png(depth, 0.001f).width, 640);
    EXPECT_THROW(wul3d::set_max_image_pixels(0), wul3d::ParamError);
    EXPECT_THROW(wul3d::set_max_image_pixels(wul3d::kMaxImagePixelsCeiling + 1), wul3d::ParamError);
    wul3d::set_max_image_pixels(wul3d::kDefaultMaxImagePixels);
}

TEST(IoLimits, IntrinsicsMustBePhysical) {
    wul3d::PinholeIntrinsics K{640, 480, 525, 525, 319.5, 239.5};
    EXPECT_NO_THROW(K.validate());
    for (double bad : {1e-300, 1e300, std::nan(""), double{INFINITY}, 10.0, 1e7}) {
        wul3d::PinholeIntrinsics k = K;
        k.fx = bad;
        EXPECT_THROW(k.validate(), wul3d::ParamError) << bad;
        k = K;
        k.cx = bad * 100;
        if (!(bad * 100 >= -640 && bad * 100 <= 1280)) {
            EXPECT_THROW(k.validate(), wul3d::ParamError) << bad;
        }
    }
    K.width = 100000;
    EXPECT_THROW(K.validate(), wul3d::ParamError);
}
