#include "wul3d/backprojection.hpp"

#include <gtest/gtest.h>

#include "wul3d/error.hpp"

using namespace wul3d;

namespace {
RgbdFrame tiny_frame() {
    RgbdFrame f;
    f.name = "tiny";
    f.intrinsics = PinholeIntrinsics{4, 3, 2.0, 4.0, 1.5, 1.0};
    f.depth.width = f.color.width = 4;
    f.depth.height = f.color.height = 3;
    f.depth.scale_m_per_unit = 0.001f;
    f.depth.data = {1000, 0, 2000, 500,  //
                    1000, 1000, 0, 3000,  //
                    250, 0, 0, 1500};
    f.color.rgb.resize(3 * 12);
    for (std::size_t i = 0; i < f.color.rgb.size(); ++i) f.color.rgb[i] = static_cast<std::uint8_t>(i * 7);
    return f;
}
}  // namespace

TEST(BackProject, KnownPixelsByHand) {
    const RgbdFrame f = tiny_frame();
    OrganizedCloud c;
    EXPECT_EQ(back_project(f, c), 8u);
    ASSERT_EQ(c.size(), 12u);
    // pixel (u=0, v=0), z = 1 m: x = (0 - 1.5) * 1 / 2 = -0.75, y = (0 - 1) * 1 / 4 = -0.25
    EXPECT_FLOAT_EQ(c.x[0], -0.75f);
    EXPECT_FLOAT_EQ(c.y[0], -0.25f);
    EXPECT_FLOAT_EQ(c.z[0], 1.0f);
    // pixel (u=3, v=1), z = 3 m: x = 1.5 * 3 / 2 = 2.25, y = 0
    EXPECT_FLOAT_EQ(c.x[7], 2.25f);
    EXPECT_FLOAT_EQ(c.y[7], 0.0f);
    EXPECT_FLOAT_EQ(c.z[7], 3.0f);
    // pixel (u=0, v=2), z = 0.25 m: x = -1.5 * 0.25 / 2, y = 1 * 0.25 / 4
    EXPECT_FLOAT_EQ(c.x[8], -0.1875f);
    EXPECT_FLOAT_EQ(c.y[8], 0.0625f);
    // invalid pixels are flagged, not made up
    EXPECT_EQ(c.valid[1], 0);
    EXPECT_EQ(c.valid[6], 0);
    EXPECT_EQ(c.valid[3], 1);
    // colours keep 0-255 units
    EXPECT_FLOAT_EQ(c.r[7], static_cast<float>(f.color.rgb[21]));
    EXPECT_FLOAT_EQ(c.b[7], static_cast<float>(f.color.rgb[23]));
    EXPECT_TRUE(c.has_color);
}

TEST(BackProject, DepthOnlyFrameHasNoColour) {
    RgbdFrame f = tiny_frame();
    f.color = ColorImage{};
    OrganizedCloud c;
    back_project(f, c);
    EXPECT_FALSE(c.has_color);
    EXPECT_FLOAT_EQ(c.r[0], 0.0f);
    EXPECT_FLOAT_EQ(c.z[0], 1.0f);
}

TEST(BackProject, ColourSizeMismatchThrows) {
    RgbdFrame f = tiny_frame();
    f.color.width = 8;
    OrganizedCloud c;
    EXPECT_THROW(back_project(f, c), InputError);
}
