// The crease cuts (src/segmentation/cuts.cpp): objects that meet at a concave fold seed apart.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Two boxes of one colour, the small one standing in front of the tall one and touching
// it: their surfaces meet at a concave junction, which is cut.
TEST(SegmentObjects, TouchingSameColourBoxes_SeparatedAtTheConcaveJunction) {
    Scene s = pitched_tabletop_scene();
    SceneBox tall;
    tall.x = 0.05f;
    tall.z = 1.0f;
    tall.w = 0.2f;
    tall.h = 0.25f;
    tall.d = 0.1f;
    SceneBox small = tall;  // same colour
    small.x = 0.0f;
    small.z = 0.9f;  // its back face touches the tall box's front face (z = 0.95)
    small.w = 0.12f;
    small.h = 0.1f;
    small.d = 0.1f;
    s.boxes = {tall, small};
    std::vector<int> truth;
    const LabelImage out = segment(s, Segmenter::Geometric, truth);
    int a = 0, b = 0;
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0, &a), 0.9);
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0 + 1, &b), 0.9);
    EXPECT_NE(a, 0);
    EXPECT_NE(b, 0);
    EXPECT_NE(a, b) << "the two boxes were merged";
}
