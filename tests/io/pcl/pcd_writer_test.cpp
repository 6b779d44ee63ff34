// The PCD reader (io.hpp read_pcd_frame) on organized clouds that PCL's own writer made, in
// its three encodings, with and without colour: a shipped frame back-projected into a
// pcl::PointCloud (NaN where there is no depth), saved with pcl::io, read back as the same
// depth, colour and intrinsics. PCL writes rgb as an unsigned integer field, where wul3d's
// writer writes a float. Built where cmake/Pcl.cmake found PCL's io module.
#include <gtest/gtest.h>

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "io/pcd_expect.hpp"
#include "test_support.hpp"
#include "wul3d/io.hpp"

namespace {

using wul3d::RgbdFrame;
using wul3d::test::expect_same_pcd_frame;
using wul3d::test::TempDir;

/// The frame's pixels as an organized cloud of PointT, camera frame, metres.
template <class PointT>
pcl::PointCloud<PointT> to_cloud(const RgbdFrame& f) {
    const int W = f.depth.width, H = f.depth.height;
    pcl::PointCloud<PointT> cloud(static_cast<std::uint32_t>(W), static_cast<std::uint32_t>(H));
    cloud.is_dense = false;
    const wul3d::PinholeIntrinsics& K = f.intrinsics;
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(W) + static_cast<std::size_t>(u);
            PointT& p = cloud.at(u, v);
            const float z = static_cast<float>(f.depth.data[i]) * f.depth.scale_m_per_unit;
            if (f.depth.data[i] == 0) {
                p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
            } else {
                p.x = static_cast<float>((u - K.cx) / K.fx) * z;
                p.y = static_cast<float>((v - K.cy) / K.fy) * z;
                p.z = z;
            }
            if constexpr (std::is_same_v<PointT, pcl::PointXYZRGB>) {
                p.r = f.color.rgb[3 * i];
                p.g = f.color.rgb[3 * i + 1];
                p.b = f.color.rgb[3 * i + 2];
            }
        }
    return cloud;
}

}  // namespace

TEST(PcdFromPcl, EveryEncodingWithAndWithoutColourReadsBack) {
    TempDir tmp;
    const RgbdFrame want = wul3d::test::read_sample_frame("image_0002");
    const auto rgb = to_cloud<pcl::PointXYZRGB>(want);
    const auto xyz = to_cloud<pcl::PointXYZ>(want);
    const std::string ascii = (tmp / "ascii.pcd").string(), binary = (tmp / "binary.pcd").string(),
                      compressed = (tmp / "compressed.pcd").string(), plain = (tmp / "xyz.pcd").string();
    ASSERT_EQ(pcl::io::savePCDFileASCII(ascii, rgb), 0);
    ASSERT_EQ(pcl::io::savePCDFileBinary(binary, rgb), 0);
    ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(compressed, rgb), 0);
    ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(plain, xyz), 0);
    for (const std::string& path : {ascii, binary, compressed}) {
        SCOPED_TRACE(path);
        expect_same_pcd_frame(want, wul3d::read_pcd_frame(path), true);
    }
    expect_same_pcd_frame(want, wul3d::read_pcd_frame(plain), false);
}
