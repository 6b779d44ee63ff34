// A recording read ahead by several readers at once (feed.hpp, src/run/read_ahead.cpp): the
// frames come in order, each as one reader alone reads it, and a damaged frame ends the feed
// in its turn with its own error, whatever the number of readers.
#include "wul3d/feed.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

constexpr int kFrames = 24;

/// kFrames frame folders f00..f23 of 64 x 48 pixels, each with depths and colours of its own
/// (frame i's depth ramps from 1000 + 10 i mm), so that a frame read out of turn is seen.
fs::path write_sequence(const TempDir& tmp) {
    const fs::path seq = tmp / "seq";
    PinholeIntrinsics K;
    K.width = 64;
    K.height = 48;
    K.fx = K.fy = 60;
    K.cx = 32;
    K.cy = 24;
    for (int i = 0; i < kFrames; ++i) {
        const fs::path dir = seq / (std::string(i < 10 ? "f0" : "f") + std::to_string(i));
        fs::create_directories(dir);
        DepthImage d;
        d.width = K.width;
        d.height = K.height;
        d.data.resize(static_cast<std::size_t>(d.width) * d.height);
        ColorImage c;
        c.width = K.width;
        c.height = K.height;
        c.rgb.resize(3 * d.data.size());
        for (std::size_t p = 0; p < d.data.size(); ++p) {
            d.data[p] = static_cast<std::uint16_t>(1000 + 10 * i + p % 7);
            c.rgb[3 * p] = static_cast<std::uint8_t>(i * 9);
            c.rgb[3 * p + 1] = static_cast<std::uint8_t>(p % 251);
            c.rgb[3 * p + 2] = static_cast<std::uint8_t>(255 - i);
        }
        write_depth_png((dir / "depth.png").string(), d);
        write_color_png((dir / "color.png").string(), c);
        write_intrinsics_json((dir / "intrinsics.json").string(), K, 0.001f);
    }
    return seq;
}

/// The feed's frames in the order it gives them; throws what the feed throws.
std::vector<RgbdFrame> read_all(FrameFeed& feed) {
    std::vector<RgbdFrame> frames;
    SourceItem item;
    while (feed.next(item) == FrameFeed::Status::Frame) frames.push_back(item.frame);
    return frames;
}

FeedOptions options(const fs::path& seq, std::size_t readers) {
    FeedOptions o;
    o.input = seq.string();
    o.read_ahead = 2;
    o.readers = readers;
    return o;
}

TEST(FrameFeed, SeveralReaders_FramesInOrderAsOneReaderReadsThem) {
    TempDir tmp;
    const fs::path seq = write_sequence(tmp);
    const std::unique_ptr<FrameSource> alone = open_source(seq.string(), {});
    for (const std::size_t readers : {1u, 2u, 4u}) {
        SCOPED_TRACE(readers);
        FrameFeed feed(options(seq, readers));
        EXPECT_EQ(feed.readers(), readers);
        const std::vector<RgbdFrame> frames = read_all(feed);
        ASSERT_EQ(frames.size(), static_cast<std::size_t>(kFrames));
        SourceItem expected;
        for (std::size_t i = 0; i < frames.size(); ++i) {
            alone->read(i, expected);
            EXPECT_EQ(frames[i].name, expected.frame.name);
            EXPECT_EQ(frames[i].depth.data, expected.frame.depth.data) << "frame " << i;
            EXPECT_EQ(frames[i].color.rgb, expected.frame.color.rgb) << "frame " << i;
        }
    }
}

TEST(FrameFeed, SeveralReaders_ADamagedFrameEndsTheFeedInItsTurn) {
    TempDir tmp;
    const fs::path seq = write_sequence(tmp);
    test::write_text(seq / "f07" / "depth.png", "not a png");
    for (const std::size_t readers : {1u, 3u}) {
        SCOPED_TRACE(readers);
        FrameFeed feed(options(seq, readers));
        SourceItem item;
        std::vector<std::string> names;
        std::string error;
        try {
            while (feed.next(item) == FrameFeed::Status::Frame) names.push_back(item.frame.name);
        } catch (const InputError& e) {
            error = e.what();
        }
        ASSERT_EQ(names.size(), 7u) << "the frames before the damaged one, and only those";
        EXPECT_EQ(names.back(), "f06");
        EXPECT_NE(error.find("f07"), std::string::npos) << error;
        EXPECT_EQ(feed.next(item), FrameFeed::Status::End) << "nothing follows the damaged frame";
    }
}

// More readers than frames: one reader a frame at most; a single frame folder still reads.
TEST(FrameFeed, ReadersNoMoreThanFrames) {
    FrameFeed feed(options(test::sample_dir() / "uois_tabletop" / "image_0000", 4));
    EXPECT_EQ(feed.readers(), 1u);
    EXPECT_EQ(read_all(feed).size(), 1u);
}

}  // namespace
}  // namespace wul3d
