// SegmentParams (src/segmentation/params.cpp): validate(), the segmenters' and scopes' names.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "segment_scene.hpp"
#include "wul3d/error.hpp"

using namespace wul3d;
using namespace wul3d::test;

TEST(SegmentParams, Validate_NamesTheField) {
    SegmentParams p;
    EXPECT_NO_THROW(p.validate());
    p.min_points = 0;
    try {
        p.validate();
        FAIL() << "no throw";
    } catch (const ParamError& e) {
        // The library names its own field; the command respells the table's parameters
        // with their flags (parameters_test.cpp).
        EXPECT_NE(std::string(e.what()).find("SegmentParams.min_points = 0"), std::string::npos)
            << e.what();
    }
    SegmentParams stacks;
    stacks.stacks.min_step_m = std::nanf("");
    EXPECT_THROW(stacks.validate(), ParamError);
    stacks.stacks.min_step_m = 0;  // off
    EXPECT_NO_THROW(stacks.validate());
    EXPECT_THROW(parse_segmenter("watershed"), ParamError);
    EXPECT_EQ(parse_segmenter("kmeans"), Segmenter::Kmeans);
    EXPECT_STREQ(segmenter_name(Segmenter::Hybrid), "hybrid");
}

TEST(SegmentParams, Scope_ParsedAndNamed) {
    EXPECT_EQ(parse_scope("support"), Scope::Support);
    EXPECT_EQ(parse_scope("scene"), Scope::Scene);
    EXPECT_THROW(parse_scope("table"), ParamError);
    EXPECT_STREQ(scope_name(Scope::Scene), "scene");
    EXPECT_EQ(SegmentParams{}.scope.mode, Scope::Support);
}
