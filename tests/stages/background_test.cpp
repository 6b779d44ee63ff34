#include "wul3d/background.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "wul3d/error.hpp"

using namespace wul3d;

TEST(DepthRange, KeepsOnlyValidPointsInsideTheRange) {
    OrganizedCloud c;
    c.resize(5, 1);
    c.z = {0.4f, 0.5f, 1.0f, 2.0f, 3.0f};
    c.valid = {1, 1, 0, 1, 1};
    std::vector<std::uint8_t> active;
    DepthRange r{0.5f, 2.0f};
    EXPECT_EQ(select_depth_range(r, c, active), 2u);
    EXPECT_EQ(active, (std::vector<std::uint8_t>{0, 1, 0, 1, 0}));
}

TEST(DepthRange, ValidateRejectsEmptyOrNegativeRange) {
    EXPECT_NO_THROW((DepthRange{0.0f, 1.0f}.validate()));
    EXPECT_THROW((DepthRange{1.0f, 1.0f}.validate()), ParamError);
    EXPECT_THROW((DepthRange{-0.1f, 1.0f}.validate()), ParamError);
    EXPECT_THROW((DepthRange{0.5f, NAN}.validate()), ParamError);
}
