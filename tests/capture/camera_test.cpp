#include "wul3d/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "wul3d/error.hpp"

using namespace wul3d;

TEST(FovCamera, ToPinhole_KinectV2Colour) {
    const FovCamera fov = kinect_v2_color_fov();
    const PinholeIntrinsics K = fov.to_pinhole();
    EXPECT_EQ(K.width, 1920);
    EXPECT_EQ(K.height, 1080);
    // fx = R_w / (2 tan(35 deg)), cx = R_w / 2
    EXPECT_NEAR(K.fx, 1920.0 / (2.0 * std::tan(fov.fov_x_rad / 2.0)), 1e-9);
    EXPECT_NEAR(K.fy, 1080.0 / (2.0 * std::tan(fov.fov_y_rad / 2.0)), 1e-9);
    // the paper's radians are 70 and 60 degrees
    EXPECT_NEAR(K.fx, 1920.0 / (2.0 * std::tan(35.0 * M_PI / 180.0)), 1e-3);
    EXPECT_NEAR(K.fy, 1080.0 / (2.0 * std::tan(30.0 * M_PI / 180.0)), 1e-3);
    EXPECT_DOUBLE_EQ(K.cx, 960.0);
    EXPECT_DOUBLE_EQ(K.cy, 540.0);
}

TEST(FovCamera, BackProjectEqualsDerivedPinhole) {
    for (const FovCamera fov : {kinect_v2_color_fov(), FovCamera{640, 480, 1.014468, 0.7898094}}) {
        const PinholeIntrinsics K = fov.to_pinhole();
        for (double py : {0.0, 17.5, fov.height / 2.0, fov.height - 1.0})
            for (double px : {0.0, 3.25, fov.width / 2.0, fov.width - 1.0})
                for (double z : {0.5, 1.7, 4.5}) {
                    double xf, yf, xp, yp;
                    fov.back_project(px, py, z, xf, yf);
                    back_project(K, px, py, z, xp, yp);
                    EXPECT_NEAR(xf, xp, 1e-9) << px << "," << py << "," << z;
                    EXPECT_NEAR(yf, yp, 1e-9) << px << "," << py << "," << z;
                }
    }
}

TEST(FovCamera, EdgesOfImageSeeHalfTheFieldOfView) {
    const FovCamera fov = kinect_v2_color_fov();
    double x, y;
    fov.back_project(fov.width, fov.height, 1.0, x, y);  // right/bottom edge
    EXPECT_NEAR(std::atan(x), fov.fov_x_rad / 2, 1e-9);
    EXPECT_NEAR(std::atan(y), fov.fov_y_rad / 2, 1e-9);
}

TEST(Pinhole, ProjectInvertsBackProject) {
    const PinholeIntrinsics K = intrinsics_preset("kinect_v1");
    double x, y, u, v;
    back_project(K, 100.0, 400.0, 2.0, x, y);
    project(K, x, y, 2.0, u, v);
    EXPECT_NEAR(u, 100.0, 1e-9);
    EXPECT_NEAR(v, 400.0, 1e-9);
}

TEST(Pinhole, Presets) {
    EXPECT_DOUBLE_EQ(intrinsics_preset("kinect_v1").fx, 525.0);
    EXPECT_DOUBLE_EQ(intrinsics_preset("tum_fr1").cy, 255.3);
    EXPECT_EQ(intrinsics_preset("kinect_v2_color").width, 1920);
    EXPECT_THROW(intrinsics_preset("nope"), ParamError);
}

TEST(Pinhole, ValidateRejectsNonPositive) {
    PinholeIntrinsics K{640, 480, 525, 525, 320, 240};
    EXPECT_NO_THROW(K.validate());
    K.fx = 0;
    EXPECT_THROW(K.validate(), ParamError);
    K.fx = 525;
    K.width = 0;
    EXPECT_THROW(K.validate(), ParamError);
}
