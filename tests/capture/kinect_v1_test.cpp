// The Kinect v1 depth model both ways (kinect_v1.hpp): raw disparity <-> metres, the stereo
// round trip through the IR camera, and the fakenect dump layout.
#include "wul3d/kinect_v1.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "test_support.hpp"
#include "wul3d/error.hpp"

using namespace wul3d;

TEST(KinectV1, RawToMetresToRaw_IsExactForEveryReading) {
    for (int d = 0; d <= kKinectV1MaxRaw; ++d) {
        const double z = kinect_v1_raw_to_m(static_cast<std::uint16_t>(d));
        ASSERT_GT(z, 0.0) << d;
        ASSERT_EQ(kinect_v1_m_to_raw(z), d) << d;
    }
}

TEST(KinectV1, MetresToRawToMetres_WithinHalfAStep) {
    for (double z = 0.35; z < 9.0; z += 0.0037) {
        const std::uint16_t d = kinect_v1_m_to_raw(z);
        ASSERT_NE(d, kKinectV1NoDepth) << z;
        const double back = kinect_v1_raw_to_m(d);
        // Half a step at z, with a little slack for the step growing across the interval.
        EXPECT_LE(std::abs(back - z), 0.5 * kinect_v1_step_m(z) * 1.02) << z;
    }
}

TEST(KinectV1, NoReading_BothWays) {
    EXPECT_EQ(kinect_v1_raw_to_m(kKinectV1NoDepth), 0.0);
    EXPECT_EQ(kinect_v1_raw_to_m(kKinectV1MaxRaw + 1), 0.0);
    EXPECT_EQ(kinect_v1_m_to_raw(0.0), kKinectV1NoDepth);
    EXPECT_EQ(kinect_v1_m_to_raw(-1.0), kKinectV1NoDepth);
    EXPECT_EQ(kinect_v1_m_to_raw(NAN), kKinectV1NoDepth);
    EXPECT_EQ(kinect_v1_m_to_raw(0.2), kKinectV1NoDepth);   // nearer than raw 0 (0.30 m)
    EXPECT_EQ(kinect_v1_m_to_raw(20.0), kKinectV1NoDepth);  // beyond raw 1050 (9.4 m)
}

TEST(KinectV1, ModelValues_MatchTheSources) {
    EXPECT_NEAR(kinect_v1_raw_to_m(0), 1.0 / 3.3309495161, 1e-12);
    EXPECT_NEAR(kinect_v1_step_m(1.0), 0.0030711016, 1e-12);  // 3.1 mm per raw unit at 1 m
    const StereoCalibration c = kinect_v1_calibration();
    EXPECT_NO_THROW(c.validate());
    const double baseline = std::hypot(c.translation_m[0], c.translation_m[1], c.translation_m[2]);
    EXPECT_NEAR(baseline, 0.0228, 0.001);  // about 2.3 cm between IR and RGB (Burrus)
    EXPECT_EQ(c.depth.width, 640);
    EXPECT_EQ(c.color.height, 480);
}

TEST(KinectV1, RawToDepth_IsTheModelInMillimetres) {
    std::vector<std::uint16_t> raw(640 * 480, kKinectV1NoDepth);
    raw[0] = 0;
    raw[1] = 700;
    raw[2] = 1050;
    DepthImage d;
    kinect_v1_raw_to_depth(raw.data(), d);
    ASSERT_EQ(d.width, 640);
    ASSERT_EQ(d.data.size(), raw.size());
    EXPECT_FLOAT_EQ(d.scale_m_per_unit, 0.001f);
    EXPECT_EQ(d.data[0], std::lround(kinect_v1_raw_to_m(0) * 1000));
    EXPECT_EQ(d.data[1], std::lround(kinect_v1_raw_to_m(700) * 1000));
    EXPECT_EQ(d.data[2], std::lround(kinect_v1_raw_to_m(1050) * 1000));
    EXPECT_EQ(d.data[3], 0);
}

// A plane facing the colour camera at 1.2 m, moved into the IR camera and back as replay does:
// away from the borders every pixel comes back within half a raw step (plus 1 mm rounding).
TEST(KinectV1, StereoRoundTrip_PlaneComesBackWithinTheQuantization) {
    DepthImage plane;
    plane.width = 640;
    plane.height = 480;
    plane.data.assign(640 * 480, 1200);
    RegistrationWorkspace ws;
    std::vector<std::uint16_t> raw;
    kinect_v1_depth_to_raw(plane, ws, raw);
    ASSERT_EQ(raw.size(), plane.data.size());
    std::size_t holes = 0;
    for (std::uint16_t r : raw) holes += r == kKinectV1NoDepth;
    EXPECT_LT(holes, raw.size() / 5);  // the IR camera sees a bit beside the colour camera's view

    RawRgbdFrame captured;
    kinect_v1_raw_to_depth(raw.data(), captured.depth);
    RgbdFrame back;
    register_depth_to_color(kinect_v1_calibration(), captured, ws, back);
    const double tol_mm = 0.5 * kinect_v1_step_m(1.2) * 1000 + 1.0;
    std::size_t checked = 0;
    for (int v = 80; v < 440; ++v) {  // the IR camera does not see the top rows
        for (int u = 60; u < 580; ++u) {
            const std::uint16_t z = back.depth.data[static_cast<std::size_t>(v) * 640 + u];
            ASSERT_NE(z, 0) << u << "," << v;
            EXPECT_LE(std::abs(z - 1200.0), tol_mm) << u << "," << v;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 360u * 520u);
}

TEST(KinectV1, DepthToRaw_RejectsOtherSizes) {
    DepthImage d;
    d.width = 320;
    d.height = 240;
    d.data.assign(320 * 240, 1000);
    RegistrationWorkspace ws;
    std::vector<std::uint16_t> raw;
    EXPECT_THROW(kinect_v1_depth_to_raw(d, ws, raw), InputError);
}

TEST(FakenectDumpWriter, WritesTheLayoutFakenectReads) {
    wul3d::test::TempDir tmp;
    const std::string dir = (tmp / "dump").string();
    FakenectDumpWriter w(dir);
    ColorImage c;
    c.width = 640;
    c.height = 480;
    c.rgb.assign(3 * 640 * 480, 7);
    std::vector<std::uint16_t> raw(640 * 480, 0x0123);
    w.add(c, raw);
    w.add(c, raw);
    w.finish();
    std::ifstream index(dir + "/INDEX.txt");
    std::vector<std::string> lines;
    for (std::string line; std::getline(index, line);) lines.push_back(line);
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0].substr(0, 2), "r-");
    EXPECT_EQ(lines[1].substr(0, 2), "d-");
    EXPECT_LT(lines[0], lines[2]);  // time order
    std::ifstream d(dir + "/" + lines[1], std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(d)), std::istreambuf_iterator<char>());
    const std::string header = "P5 640 480 65535\n";
    ASSERT_EQ(bytes.size(), header.size() + 2 * 640 * 480);
    EXPECT_EQ(bytes.substr(0, header.size()), header);
    EXPECT_EQ(static_cast<unsigned char>(bytes[header.size()]), 0x23);  // little-endian
    EXPECT_EQ(static_cast<unsigned char>(bytes[header.size() + 1]), 0x01);

    c.width = 320;
    EXPECT_THROW(w.add(c, raw), InputError);
    EXPECT_THROW(FakenectDumpWriter{dir}, IoError);  // not empty
}
