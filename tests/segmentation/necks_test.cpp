// The neck rule (src/segmentation/necks.cpp): a narrow part standing on the axis of a round
// body joined to it (a bottle's neck and cap); a wider one stays apart.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {
/// The pitched tabletop with one bottle: body 5 cm in radius and 10 cm high, a 45-degree
/// shoulder, a neck of `neck_radius` and 9 cm, printed in another colour from just over the
/// shoulder up. Segmented without the colour cue's round test (colour.round_deg = 0), which
/// would keep it whole: the cue cuts the neck off its shoulder, as the crease cuts do where a
/// sensor's noise blurs a bottle (the generated piles' bottles). `stats` gets the counts.
double bottle_share(float neck_radius, SegmentStats& stats) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 5;
    const float radius = 0.05f, h = 0.1f, over_shoulder = h + (radius - neck_radius) + 0.005f;
    s.cups = {SceneCup{.z = 0.8f, .radius = radius, .h = h, .band_lo = over_shoulder, .band_hi = 0.25f,
                       .neck_radius = neck_radius, .neck_h = 0.09f}};
    const PlaneStage in = up_to_the_plane(s);
    SegmentParams params;
    params.colour.round_deg = 0;
    const LabelImage out = segment(in, params, &stats);
    return dominant_share(out.labels, in.truth, kTruthCup0);
}
}  // namespace

// A neck 2 cm in radius on the body's axis: joined back, and the bottle is one object.
TEST(SegmentObjects, BottleNeckCutOffItsShoulder_JoinedToItsBody) {
    SegmentStats stats;
    const double share = bottle_share(0.02f, stats);
    ASSERT_GE(stats.colour.splits, 1) << "the colour cue should cut the neck off (test premise)";
    EXPECT_EQ(stats.necks.joins, 1);
    EXPECT_GE(share, 0.95) << "the bottle is not one object";
}

// The same with the upper part 3.5 cm in radius, wider than a neck (kNeckRadiusM): a can of
// another colour standing on a round body's axis looks so, and stays apart.
TEST(SegmentObjects, WidePartOnARoundBody_StaysApart) {
    SegmentStats stats;
    const double share = bottle_share(0.035f, stats);
    ASSERT_GE(stats.colour.splits, 1) << "the colour cue should cut the upper part off (test premise)";
    EXPECT_EQ(stats.necks.joins, 0);
    EXPECT_LT(share, 0.8) << "the wide part was joined to the body";
}
