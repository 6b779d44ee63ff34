// Pipeline::process on the caller's memory (image_view.hpp): the same results as on owned
// frames for packed RGB, a strided BGR copy and float metres; in place when the layout
// allows; bad views rejected with one line.
#include "wul3d/image_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d {
namespace {

RgbdFrame sample(std::size_t i) {
    auto source = open_source((test::sample_dir() / "uois_tabletop").string(), SourceOptions{});
    SourceItem item;
    source->read(i, item);
    return item.frame;
}

FrameView packed_view(const RgbdFrame& f) {
    FrameView v;
    v.name = f.name;
    v.intrinsics = f.intrinsics;
    v.depth = {f.depth.data.data(), f.depth.width, f.depth.height, 0, DepthFormat::U16,
               f.depth.scale_m_per_unit};
    v.color = {f.color.rgb.data(), f.color.width, f.color.height, 0, ColorOrder::RGB};
    return v;
}

/// The caller's memory of another layout: BGR and float metres, each row padded.
struct OddLayout {
    std::vector<std::uint8_t> bgr;
    std::vector<float> metres;
    std::size_t color_stride, depth_stride;
    FrameView view;

    explicit OddLayout(const RgbdFrame& f) {
        const int W = f.width(), H = f.height();
        color_stride = 3 * static_cast<std::size_t>(W) + 13;  // not a multiple of anything
        depth_stride = 4 * static_cast<std::size_t>(W) + 8;
        bgr.assign(color_stride * H, 0xAB);
        metres.assign(depth_stride / 4 * H, std::numeric_limits<float>::quiet_NaN());
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const std::size_t p = static_cast<std::size_t>(y) * W + x;
                for (int c = 0; c < 3; ++c)
                    bgr[y * color_stride + 3 * x + c] = f.color.rgb[3 * p + 2 - c];
                metres[y * (depth_stride / 4) + x] =
                    static_cast<float>(f.depth.data[p]) * f.depth.scale_m_per_unit;
            }
        view.name = f.name;
        view.intrinsics = f.intrinsics;
        view.depth = {metres.data(), W, H, depth_stride, DepthFormat::F32Metres,
                      f.depth.scale_m_per_unit};
        view.color = {bgr.data(), W, H, color_stride, ColorOrder::BGR};
    }
};

void expect_same(const FrameResult& a, const FrameResult& b) {
    EXPECT_EQ(a.labels.labels, b.labels.labels);
    EXPECT_EQ(a.colors.rgb, b.colors.rgb);
    EXPECT_EQ(a.objects.labels, b.objects.labels);
    EXPECT_EQ(a.segments.labels, b.segments.labels);
    ASSERT_EQ(a.object_list.size(), b.object_list.size());
    for (std::size_t i = 0; i < a.object_list.size(); ++i) {
        EXPECT_EQ(a.object_list[i].pixels, b.object_list[i].pixels);
        EXPECT_EQ(a.object_list[i].centroid, b.object_list[i].centroid);
    }
}

class ViewInput : public ::testing::TestWithParam<int> {};  // decimation 1 and 2

TEST_P(ViewInput, SameResultsAsOwnedFrames_PackedStridedBgrFloat) {
    PipelineParams params;
    params.decimation = GetParam();
    Pipeline owned(params), packed(params), odd(params);
    for (std::size_t i = 0; i < 2; ++i) {  // two frames: the weights carry over
        const RgbdFrame f = sample(i);
        ASSERT_TRUE(f.has_color());
        const FrameResult& want = owned.process(f);
        ASSERT_FALSE(want.object_list.empty());
        expect_same(packed.process(packed_view(f)), want);
        OddLayout layout(f);
        expect_same(odd.process(layout.view), want);
    }
}

INSTANTIATE_TEST_SUITE_P(Decimation, ViewInput, ::testing::Values(1, 2));

TEST(StageView, PackedRgbU16IsReadInPlace_OtherLayoutsAreConverted) {
    const RgbdFrame f = sample(0);
    RgbdFrame staging;
    const RgbdView in_place = stage_view(packed_view(f), staging);
    EXPECT_EQ(in_place.depth, f.depth.data.data());
    EXPECT_EQ(in_place.rgb, f.color.rgb.data());
    EXPECT_TRUE(staging.depth.data.empty());
    EXPECT_TRUE(staging.color.rgb.empty());

    OddLayout layout(f);
    const RgbdView converted = stage_view(layout.view, staging);
    EXPECT_EQ(converted.depth, staging.depth.data.data());
    EXPECT_EQ(converted.rgb, staging.color.rgb.data());
    EXPECT_EQ(staging.depth.data, f.depth.data);  // metres back to the same units
    EXPECT_EQ(staging.color.rgb, f.color.rgb);    // BGR back to RGB

    FrameView depth_only = packed_view(f);
    depth_only.color = {};
    EXPECT_FALSE(stage_view(depth_only, staging).has_color());
}

TEST(StageView, FloatDepthThatCannotBeHeldIsInvalid) {
    const float z[6] = {0.5f, 0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
                        std::numeric_limits<float>::infinity(), 70.0f};  // 70 m > 65535 mm
    FrameView v;
    v.name = "f";
    v.intrinsics = {3, 2, 500, 500, 1, 1};
    v.depth = {z, 3, 2, 0, DepthFormat::F32Metres, 0.001f};
    RgbdFrame staging;
    const RgbdView s = stage_view(v, staging);
    EXPECT_EQ(std::vector<std::uint16_t>(s.depth, s.depth + 6),
              (std::vector<std::uint16_t>{500, 0, 0, 0, 0, 0}));
}

TEST(StageView, BadViewsAreOneLineInputErrors) {
    const RgbdFrame f = sample(0);
    RgbdFrame staging;
    auto expect_error = [&](FrameView v, const std::string& part) {
        try {
            stage_view(v, staging);
            ADD_FAILURE() << "no error for " << part;
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(part), std::string::npos) << msg;
            EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
    };
    FrameView v = packed_view(f);
    v.depth.data = nullptr;
    expect_error(v, "empty depth image");
    v = packed_view(f);
    v.depth.stride_bytes = 2 * static_cast<std::size_t>(f.width()) - 2;
    expect_error(v, "shorter than a row");
    v = packed_view(f);
    v.color.stride_bytes = 3;
    expect_error(v, "colour row stride");
    v = packed_view(f);
    v.color.width -= 1;
    expect_error(v, "colour is");
    v = packed_view(f);
    v.intrinsics.fx = std::nan("");
    expect_error(v, "invalid intrinsics");
    v = packed_view(f);
    v.depth.scale_m_per_unit = 0.0f;
    expect_error(v, "depth scale");
    Pipeline pipeline(PipelineParams{});
    EXPECT_THROW(pipeline.process(v), InputError);
}

}  // namespace
}  // namespace wul3d
