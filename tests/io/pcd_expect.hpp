#pragma once
// What a PCD read back must be (tests/io/pcd_test.cpp, tests/io/pcl/pcd_writer_test.cpp):
// the frame it was written from, depth within 1 mm (the file holds metres as floats), the
// intrinsics fitted to its points within 0.5 %, the colour exact or absent.
#include <gtest/gtest.h>

#include <cstdlib>

#include "wul3d/frame.hpp"

namespace wul3d::test {

inline void expect_same_pcd_frame(const RgbdFrame& want, const RgbdFrame& got, bool with_rgb) {
    ASSERT_EQ(got.depth.width, want.depth.width);
    ASSERT_EQ(got.depth.height, want.depth.height);
    EXPECT_FLOAT_EQ(got.depth.scale_m_per_unit, 0.001f);
    std::size_t off = 0;
    for (std::size_t i = 0; i < want.depth.data.size(); ++i)
        off += std::abs(int(got.depth.data[i]) - int(want.depth.data[i])) > 1;
    EXPECT_EQ(off, 0u) << "pixels whose depth differs by over 1 mm";
    const PinholeIntrinsics& a = want.intrinsics;
    const PinholeIntrinsics& b = got.intrinsics;
    EXPECT_NEAR(b.fx, a.fx, 0.005 * a.fx);
    EXPECT_NEAR(b.fy, a.fy, 0.005 * a.fy);
    EXPECT_NEAR(b.cx, a.cx, 0.005 * a.cx);
    EXPECT_NEAR(b.cy, a.cy, 0.005 * a.cy);
    EXPECT_EQ(b.width, a.width);
    EXPECT_EQ(b.height, a.height);
    if (with_rgb)
        EXPECT_EQ(got.color.rgb, want.color.rgb);
    else
        EXPECT_TRUE(got.color.empty());
}

}  // namespace wul3d::test
