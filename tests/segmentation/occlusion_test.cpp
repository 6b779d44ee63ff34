// The occlusion rule (src/segmentation/occlusion.cpp): the parts of a surface seen either side of a
// nearer object joined.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {
/// A long box lying across the table, and a narrow tall box standing before its middle: the
/// lying box shows one part each side of the standing one. With `two_boxes`, two short
/// boxes stand there instead, the right one 2.5 cm farther back and 2.5 cm taller: two
/// objects whose faces are parallel but not one plane. The standing box is `occluder_z` from
/// the camera and `occluder_h` tall.
Scene box_behind_an_occluder(bool two_boxes, float occluder_z = 0.88f, float occluder_h = 0.22f) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 3;
    const SceneBox occluder{.x = 0.0f, .z = occluder_z, .w = 0.07f, .h = occluder_h, .d = 0.06f, .r = 60, .g = 160, .b = 60};
    if (!two_boxes) {
        s.boxes = {SceneBox{.x = 0.0f, .z = 1.0f, .w = 0.4f, .h = 0.08f, .d = 0.1f}, occluder};
    } else {
        s.boxes = {SceneBox{.x = -0.11f, .z = 1.0f, .w = 0.18f, .h = 0.08f, .d = 0.1f},
                   SceneBox{.x = 0.11f, .z = 1.025f, .w = 0.18f, .h = 0.105f, .d = 0.1f}, occluder};
    }
    return s;
}

/// The lying box of `scene` (box_behind_an_occluder) comes out as one object, apart from the
/// standing one, by the occlusion rule. Its premise is asserted: without the rule the lying
/// box comes out in parts.
void expect_joined_behind_the_occluder(const Scene& scene) {
    const PlaneStage st = up_to_the_plane(scene);
    SegmentParams off;
    off.occlusion.min_lines = 0;
    const LabelImage apart = segment(st, off);
    ASSERT_LT(dominant_share(apart.labels, st.truth, kTruthBox0), 0.7)
        << "the standing box should divide the lying one (test premise)";

    SegmentStats stats;
    const LabelImage out = segment(st, SegmentParams{}, &stats);
    expect_separate(out, st.truth, kTruthBox0, kTruthBox0 + 1, 0.9, "the lying box was joined to the standing one");
    EXPECT_GE(stats.occlusion.joins, 1);
}
}  // namespace

// A box lying behind a standing one: the sensor sees two parts, left and right, with the
// standing box between them in view. They lie on one surface, and what lies between stands
// in front of it: the occlusion rule joins them.
TEST(SegmentObjects, BoxSeenBothSidesOfAnOccluder_IsOneObject) {
    expect_joined_behind_the_occluder(box_behind_an_occluder(false));
}

// The same with the standing box 0.4 m nearer the camera than the lying one (and taller, to
// hide its middle still): its points lie farther from the lying box than occlusion.max_gap_m,
// but that bounds the width a line spans on the lying box's plane, which is what the
// occluder hides, not its height in front of it.
TEST(SegmentObjects, BoxBehindAnOccluderNearTheCamera_IsOneObject) {
    expect_joined_behind_the_occluder(box_behind_an_occluder(false, 0.6f, 0.4f));
}

// The same view with two boxes behind the standing one, their faces parallel and 2.5 cm
// apart: each line lands within the sensor's tolerance, and only the lines' mean offset
// (occlusion.max_offset) tells two surfaces from one; the rule leaves them apart.
TEST(SegmentObjects, TwoBoxesBehindAnOccluder_StayApart) {
    const PlaneStage st = up_to_the_plane(box_behind_an_occluder(true));
    SegmentStats stats;
    const LabelImage out = segment(st, SegmentParams{}, &stats);
    expect_separate(out, st.truth, kTruthBox0, kTruthBox0 + 1, 0.9, "two boxes behind the occluder were joined");
    EXPECT_GT(dominant_share(out.labels, st.truth, kTruthBox0 + 2), 0.9);
    EXPECT_EQ(stats.occlusion.joins, 0);
}
