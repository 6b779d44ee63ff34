// The crease cuts (src/segmentation/cuts.cpp): objects that meet at a concave fold seed apart.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Two boxes of one colour, the small one standing in front of the tall one and touching
// it: their surfaces meet at a concave junction, which is cut.
TEST(SegmentObjects, TouchingSameColourBoxes_SeparatedAtTheConcaveJunction) {
    const Scene s = small_box_before_tall_box();
    std::vector<int> truth;
    const LabelImage out = segment(s, Segmenter::Geometric, truth);
    int a = 0, b = 0;
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0, &a), 0.9);
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0 + 1, &b), 0.9);
    EXPECT_NE(a, 0);
    EXPECT_NE(b, 0);
    EXPECT_NE(a, b) << "the two boxes were merged";
}
