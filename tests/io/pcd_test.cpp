// Organized PCD files as frames (io.hpp read_pcd_frame): PCDs written from a shipped frame's
// depth and intrinsics read back as the same depth, colour and intrinsics; headers that lie
// about the data's size are one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "pcd_expect.hpp"
#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::PcdData;
using wul3d::RgbdFrame;
using wul3d::test::TempDir;

RgbdFrame sample_frame() { return wul3d::test::read_sample_frame("image_0000"); }

using wul3d::test::expect_same_pcd_frame;

struct Case {
    PcdData data;
    bool rgb;
};

class PcdRoundTrip : public testing::TestWithParam<Case> {};

TEST_P(PcdRoundTrip, ReadsBackTheDepthColourAndIntrinsics) {
    TempDir tmp;
    const RgbdFrame want = sample_frame();
    const std::string path = (tmp / "cloud.pcd").string();
    wul3d::write_pcd(path, want, GetParam().data, GetParam().rgb);
    expect_same_pcd_frame(want, wul3d::read_pcd_frame(path), GetParam().rgb);
}

INSTANTIATE_TEST_SUITE_P(Pcd, PcdRoundTrip,
                         testing::Values(Case{PcdData::Ascii, false}, Case{PcdData::Ascii, true},
                                         Case{PcdData::Binary, false}, Case{PcdData::Binary, true},
                                         Case{PcdData::BinaryCompressed, false},
                                         Case{PcdData::BinaryCompressed, true}),
                         [](const testing::TestParamInfo<Case>& param_info) {
                             const char* data = param_info.param.data == PcdData::Ascii    ? "Ascii"
                                                : param_info.param.data == PcdData::Binary ? "Binary"
                                                                                     : "BinaryCompressed";
                             return std::string(data) + (param_info.param.rgb ? "Rgb" : "");
                         });

/// A binary PCD of the sample with its header's `from` replaced by `to`, or cut to `keep` bytes.
std::string edited(const fs::path& dir, const std::string& from, const std::string& to,
                   std::size_t keep = std::string::npos, PcdData data = PcdData::Binary) {
    const std::string path = (dir / "orig.pcd").string();
    wul3d::write_pcd(path, sample_frame(), data, true);
    std::string bytes = wul3d::test::slurp(path);
    if (!from.empty()) bytes.replace(bytes.find(from), from.size(), to);
    if (keep != std::string::npos) bytes.resize(keep);
    const std::string out = (dir / "bad.pcd").string();
    wul3d::test::write_text(out, bytes);
    return out;
}

TEST(Pcd, AHeaderThatLiesAboutItsSizeIsAnInputError) {
    TempDir tmp;
    const std::vector<std::string> bad = {
        edited(tmp.path(), "POINTS 307200", "POINTS 307201"),
        edited(tmp.path(), "HEIGHT 480", "HEIGHT 481"),  // POINTS no longer WIDTH x HEIGHT
        edited(tmp.path(), "", "", 300000),               // data shorter than declared
        edited(tmp.path(), "WIDTH 640\nHEIGHT 480\n", "WIDTH 65536\nHEIGHT 65536\n"),
        edited(tmp.path(), "", "", 300000, PcdData::BinaryCompressed),
        edited(tmp.path(), "", "", 300000, PcdData::Ascii),
        edited(tmp.path(), "DATA binary", "DATA zip"),
    };
    for (const std::string& path : bad) {
        try {
            wul3d::read_pcd_frame(path);
            ADD_FAILURE() << path << " was read";
        } catch (const wul3d::InputError& e) {
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
}

/// LZF with back references (the writer stores literal runs only): literals, and copies of
/// the bytes 4 back (NaN points, equal colours), short and long forms.
std::string lzf_compress(const std::string& in) {
    std::string out, lit;
    auto flush = [&] {
        for (std::size_t p = 0; p < lit.size(); p += 32) {
            const std::size_t n = std::min<std::size_t>(32, lit.size() - p);
            out.push_back(static_cast<char>(n - 1));
            out += lit.substr(p, n);
        }
        lit.clear();
    };
    std::size_t i = 0;
    while (i < in.size()) {
        std::size_t len = 0;
        while (i >= 4 && i + len < in.size() && len < 264 && in[i + len] == in[i + len - 4]) ++len;
        if (len >= 3) {
            flush();
            const std::size_t off = 3;  // back 4
            if (len - 2 < 7) {
                out.push_back(static_cast<char>(((len - 2) << 5) | (off >> 8)));
            } else {
                out.push_back(static_cast<char>((7 << 5) | (off >> 8)));
                out.push_back(static_cast<char>(len - 2 - 7));
            }
            out.push_back(static_cast<char>(off & 0xff));
            i += len;
        } else {
            lit.push_back(in[i++]);
        }
    }
    flush();
    return out;
}

TEST(Pcd, BinaryCompressedWithBackReferencesReadsBack) {
    TempDir tmp;
    const RgbdFrame want = sample_frame();
    const std::string path = (tmp / "c.pcd").string();
    wul3d::write_pcd(path, want, PcdData::BinaryCompressed, true);
    std::string bytes = wul3d::test::slurp(path);
    const std::size_t body = bytes.find("DATA binary_compressed\n") + 23;
    // The writer's literal runs back to the plain bytes, then compressed for real.
    std::string plain;
    for (std::size_t p = body + 8; p < bytes.size();) {
        const std::size_t n = static_cast<unsigned char>(bytes[p]) + 1u;
        plain += bytes.substr(p + 1, n);
        p += 1 + n;
    }
    const std::string packed = lzf_compress(plain);
    ASSERT_LT(packed.size(), plain.size() * 9 / 10);
    const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(packed.size()),
                                    static_cast<std::uint32_t>(plain.size())};
    bytes.resize(body);
    bytes.append(reinterpret_cast<const char*>(sizes), sizeof sizes);
    bytes += packed;
    wul3d::test::write_text(path, bytes);
    expect_same_pcd_frame(want, wul3d::read_pcd_frame(path), true);
    // A reference before the start of the data is refused.
    bytes[body + 8] = static_cast<char>((1 << 5) | 0x1f);
    wul3d::test::write_text(path, bytes);
    EXPECT_THROW(wul3d::read_pcd_frame(path), wul3d::InputError);
}

TEST(Pcd, PointsThatAreNoPinholeCameraAndTooFewPointsAreRefused) {
    TempDir tmp;
    std::string text = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                       "WIDTH 20\nHEIGHT 10\nPOINTS 200\nDATA ascii\n";
    unsigned seed = 1;
    for (int i = 0; i < 200; ++i) {
        seed = seed * 1103515245u + 12345u;
        text += std::to_string((seed >> 16) % 1000 / 1000.0 - 0.5) + " " +
                std::to_string((seed >> 8) % 1000 / 1000.0 - 0.5) + " 1\n";
    }
    wul3d::test::write_text(tmp / "random.pcd", text);
    wul3d::test::expect_one_line(wul3d::test::run_cli({"run", (tmp / "random.pcd").string(), "--out",
                                                       (tmp / "out").string()}),
                                 2, {"pinhole", "RMS"});
    std::string few = text;
    few.replace(few.find("WIDTH 20\nHEIGHT 10\nPOINTS 200"), 29, "WIDTH 20\nHEIGHT 2\nPOINTS 040");
    wul3d::test::write_text(tmp / "few.pcd", few);
    EXPECT_THROW(wul3d::read_pcd_frame((tmp / "few.pcd").string()), wul3d::InputError);
}

TEST(Pcd, AnUnorganizedCloudIsRefused) {
    TempDir tmp;
    const std::string path =
        edited(tmp.path(), "WIDTH 640\nHEIGHT 480\n", "WIDTH 307200\nHEIGHT 1\n");
    EXPECT_THROW(wul3d::read_pcd_frame(path), wul3d::InputError);
}

TEST(Pcd, TheCommandRunsAPcdAndSaysALyingHeaderInOneLine) {
    TempDir tmp;
    const std::string good = (tmp / "frame.pcd").string();
    wul3d::write_pcd(good, sample_frame(), PcdData::Binary, true);
    const auto ok = wul3d::test::run_cli({"run", good, "--out", (tmp / "out").string()});
    ASSERT_EQ(ok.exit_code, 0) << wul3d::test::describe(ok);
    EXPECT_TRUE(fs::exists(tmp / "out/frame/objects.png"));
    const std::string bad = edited(tmp.path(), "POINTS 307200", "POINTS 307201");
    wul3d::test::expect_one_line(wul3d::test::run_cli({"run", bad, "--out", (tmp / "out2").string()}),
                                 2, {"POINTS"});
}

}  // namespace
