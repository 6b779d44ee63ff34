// The pieces phase (src/segmentation/pieces.cpp): a segment is one connected region, whatever
// a rule that cuts by colour or by height left under one label.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Two flat boxes of the base's colour lie on a large box, one at each end. Without creases
// (as where sensor noise blurs their low sides) the three are one segment, and the stack rule
// cuts it once, over the base's top: both flat boxes lie above the cut, one label for two
// regions apart. Each becomes an object of its own.
TEST(SegmentObjects, TwoBoxesApartOnOneBase_AfterTheStackCut_TwoObjects) {
    Scene s = pitched_tabletop_scene();
    const SceneBox base{.z = 1.0f, .w = 0.34f, .h = 0.08f, .d = 0.22f, .r = 60, .g = 90, .b = 200};
    const SceneBox left{.x = -0.11f, .z = 1.0f, .w = 0.09f, .h = 0.03f, .d = 0.1f, .lift = base.h,
                        .r = 60, .g = 90, .b = 200};
    SceneBox right = left;
    right.x = 0.11f;
    s.boxes = {base, left, right};
    SegmentParams no_creases;
    no_creases.cuts.concavity = 100;  // above any (n_p - n_q) . direction: no pixel is a crease
    SegmentStats stats;
    const PlaneStage in = up_to_the_plane(s);
    const LabelImage out = segment(in, no_creases, &stats);
    EXPECT_EQ(stats.stacks.splits, 1) << "the stack rule should cut once (test premise)";
    EXPECT_GE(stats.pieces.splits, 1);
    expect_separate(out, in.truth, kTruthBox0 + 1, kTruthBox0 + 2, 0.8, "the two boxes on the base are one object");
    expect_separate(out, in.truth, kTruthBox0, kTruthBox0 + 1, 0.8, "a box on the base was not parted from it");
}
