// The option parsers shared by the command and the Python module (wul3d/parse.hpp).
#include "wul3d/parse.hpp"

#include <gtest/gtest.h>

#include <string>

#include "wul3d/error.hpp"

namespace {

std::string message_of(const std::string& select) {
    try {
        wul3d::parse_select(select);
    } catch (const wul3d::ParamError& e) {
        return e.what();
    }
    return "accepted";
}

TEST(ParseSelect, PixelsInRange) {
    EXPECT_EQ(wul3d::parse_select("320,240"), std::make_pair(320, 240));
    EXPECT_EQ(wul3d::parse_select("0,65535.9"), std::make_pair(0, 65535));  // cut toward zero
    EXPECT_EQ(wul3d::select_pixel(1.5, 2, "(1.5, 2)"), std::make_pair(1, 2));
}

TEST(ParseSelect, NumbersWithoutAnIntValueAreRefusedBeforeTheConversion) {
    // Issue 46, item 14: wul3d.run(select="1e20,1") became -2147483648.
    for (const char* text : {"1e20,1", "nan,1", "inf,2", "1,-inf", "-1,5", "65536,0"})
        EXPECT_EQ(message_of(text), "--select '" + std::string(text) +
                                        "': U and V must be pixels in [0, 65536)")
            << text;
    EXPECT_THROW(wul3d::select_pixel(1e300, 0, "(1e300, 0)"), wul3d::ParamError);
}

TEST(ParseSelect, TextThatIsNotTwoNumbers) {
    EXPECT_EQ(message_of("3abc,1"), "--select '3abc,1': '3abc' is not a number");
    EXPECT_EQ(message_of("1,2,3"), "--select '1,2,3': expected 2 comma-separated numbers");
    EXPECT_EQ(message_of(""), "--select '': expected 2 comma-separated numbers");
}

TEST(ParseIntrinsics, OverrideOfAnySize) {
    const wul3d::PinholeIntrinsics K = wul3d::parse_intrinsics_override("525,526,319.5,239.5");
    EXPECT_EQ(K.fx, 525);
    EXPECT_EQ(K.fy, 526);
    EXPECT_EQ(K.cx, 319.5);
    EXPECT_EQ(K.cy, 239.5);
    EXPECT_EQ(K.width, 0);
    EXPECT_THROW(wul3d::parse_intrinsics_override("525,525,nan,1"), wul3d::ParamError);
    EXPECT_THROW(wul3d::parse_intrinsics_override("525,525,1,2x"), wul3d::ParamError);
    EXPECT_THROW(wul3d::parse_intrinsics_override("0,525,1,2"), wul3d::ParamError);
}

}  // namespace
