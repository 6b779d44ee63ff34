// The stack rule (src/segmentation/stacks.cpp): objects resting on each other parted by the heights
// of their tops.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {

/// Segments `in` with no crease cuts, as where sensor noise blurs a low side into the top
/// beside it (generated scenes; osd_mosd test56's book on a book): the renderer has no
/// depth noise, so its creases are crisp and would split every pair here. With the stack
/// rule off (the test's premise) `ta` and `tb` are one object; on, they are two, each
/// holding `share` of its truth, with one stack cut. `params`: the rest (the defaults).
void expect_split_by_height(const PlaneStage& in, int ta, int tb, double share, const char* what,
                            const SegmentParams& params = {}) {
    SegmentParams no_creases = params;
    no_creases.cuts.concavity = 100;  // above any (n_p - n_q) . direction: no pixel is a crease
    SegmentParams without = no_creases;
    without.stacks.min_step_m = 0;
    const LabelImage one = segment(in, without);
    int a = 0, b = 0;
    dominant_share(one.labels, in.truth, ta, &a);
    dominant_share(one.labels, in.truth, tb, &b);
    ASSERT_NE(a, 0);
    ASSERT_EQ(a, b) << "without creases or the stack rule the two boxes should be one (test premise)";
    SegmentStats stats;
    const LabelImage two = segment(in, no_creases, &stats);
    expect_separate(two, in.truth, ta, tb, share, what);
    EXPECT_EQ(stats.stacks.splits, 1);
}

/// The colour cue splits nothing, as where 2-means follows a print: no boundary is short
/// enough.
SegmentParams without_colour_splits() {
    SegmentParams p;
    p.colour.max_boundary = 1e-6f;
    p.colour.max_compact = 0;
    return p;
}

}  // namespace

// A box lying on a larger box of the same colour: no colour to split. Their tops face up
// at two heights, with nothing facing up between: the stack rule cuts just over the lower top.
TEST(SegmentObjects, SameColourBoxLyingOnABox_SeparatedByTheirHeights) {
    Scene s = pitched_tabletop_scene();
    const SceneBox base{.z = 1.0f, .w = 0.26f, .h = 0.08f, .d = 0.24f, .r = 60, .g = 90, .b = 200};
    const SceneBox flat{.z = 1.0f, .w = 0.12f, .h = 0.03f, .d = 0.1f, .lift = base.h, .r = 60, .g = 90, .b = 200};
    s.boxes = {base, flat};
    expect_split_by_height(up_to_the_plane(s), kTruthBox0, kTruthBox0 + 1, 0.8,
                           "the box was not split from the box it lies on");
}

// A box standing on a larger box of the same colour, flush with its front and left side:
// the lower box's top shows only beside and behind the upper one, and its front wall runs
// on under the upper one. The cut by height leaves that wall to the lower box, on which the
// upper one rests; a rule giving the walls under the upper top to the upper box, right for
// two boxes side by side, would take it (docs/ABLATION.md, "Stacks").
TEST(SegmentObjects, BoxStandingFlushOnTheCornerOfABox_TheLowerKeepsItsFront) {
    Scene s = pitched_tabletop_scene();
    const SceneBox base{.z = 1.0f, .w = 0.24f, .h = 0.08f, .d = 0.24f, .r = 60, .g = 150, .b = 90};
    const SceneBox upper{.x = -0.05f, .z = 0.94f, .w = 0.14f, .h = 0.05f, .d = 0.12f, .lift = base.h, .r = 60, .g = 150, .b = 90};
    s.boxes = {base, upper};
    expect_split_by_height(up_to_the_plane(s), kTruthBox0, kTruthBox0 + 1, 0.9, "the two boxes are one object");
}

// The same with a box of another colour on the corner, the colour cue splitting nothing (as
// where 2-means follows a print): the walls under the upper box's walls have the lower box's
// colour, so they stay with it.
TEST(SegmentObjects, BoxOfAnotherColourFlushOnTheCornerOfABox_TheLowerKeepsItsFront) {
    Scene s = pitched_tabletop_scene();
    const SceneBox base{.z = 1.0f, .w = 0.24f, .h = 0.08f, .d = 0.24f, .r = 60, .g = 150, .b = 90};
    const SceneBox upper{.x = -0.05f, .z = 0.94f, .w = 0.14f, .h = 0.05f, .d = 0.12f, .lift = base.h, .r = 200, .g = 60, .b = 50};
    s.boxes = {base, upper};
    expect_split_by_height(up_to_the_plane(s), kTruthBox0, kTruthBox0 + 1, 0.9, "the two boxes are one object",
                           without_colour_splits());
}

namespace {

/// A tall box (kTruthBox0, colour `tall_rgb`) and a short one (kTruthBox0 + 1, `low_rgb`)
/// flush side by side, the colour cue splitting nothing. Premise: a cut by height alone
/// (the geometric segmenter, which reads no colour) halves the tall box. Then, in hybrid,
/// the tall box's walls below the cut go up with it: two objects.
void expect_taller_keeps_its_walls(const std::uint8_t (&tall_rgb)[3], const std::uint8_t (&low_rgb)[3]) {
    Scene s = pitched_tabletop_scene();
    SceneBox tall{.x = -0.07f, .z = 1.0f, .w = 0.14f, .h = 0.16f, .d = 0.14f};
    tall.r = tall_rgb[0], tall.g = tall_rgb[1], tall.b = tall_rgb[2];
    SceneBox low = tall;
    low.x = 0.07f;
    low.h = 0.07f;
    low.r = low_rgb[0], low.g = low_rgb[1], low.b = low_rgb[2];
    s.boxes = {tall, low};
    const PlaneStage in = up_to_the_plane(s);
    SegmentParams geometric = without_colour_splits();
    geometric.cuts.concavity = 100;
    geometric.segmenter = Segmenter::Geometric;  // the walls' colour is not read: a cut by height
    SegmentStats cut_stats;
    const LabelImage cut = segment(in, geometric, &cut_stats);
    ASSERT_EQ(cut_stats.stacks.splits, 1) << "(test premise)";
    ASSERT_LT(dominant_share(cut.labels, in.truth, kTruthBox0), 0.8) << "the cut should halve the tall box (test premise)";
    expect_split_by_height(in, kTruthBox0, kTruthBox0 + 1, 0.9, "the boxes side by side are one object",
                           without_colour_splits());
}

}  // namespace

// A tall box and a short one of two colours, flush side by side, the colour cue splitting
// nothing: two layers, and the cut by height alone would halve the tall box. Its walls below
// the cut stand under its walls above it and have its colour, not the short box's, so they
// go up with it.
TEST(SegmentObjects, TallAndShortBoxesOfTwoColoursSideBySide_TheTallerKeepsItsWalls) {
    expect_taller_keeps_its_walls({60, 150, 90}, {200, 60, 50});
}

// The same boxes in one colour: colour cannot tell the tall box's walls below the cut from
// the short box. The short box's top shows beyond one side of the tall box only (a box
// resting on a corner of a larger one shows the larger one's top beyond two:
// BoxStandingFlushOnTheCornerOfABox_TheLowerKeepsItsFront), so the walls go up with it.
TEST(SegmentObjects, TallAndShortBoxesOfOneColourSideBySide_TheTallerKeepsItsWalls) {
    expect_taller_keeps_its_walls({60, 150, 90}, {60, 150, 90});
}

// A can standing on the right end of a long box of its colour, as deep as the box: the box's
// top shows beside it on the left, as a lower box's does beside a taller one, but the can's
// walls face every way, not along two axes, so its footprint has no sides to be beside
// (kBoxAxes) and the box's front wall under the can's wall stays with the box. Without that
// test this fails: the shipped RealSense frames' soup can on a tin.
TEST(SegmentObjects, CanOfOneColourOnTheEndOfABox_TheBoxKeepsItsFront) {
    Scene s = pitched_tabletop_scene();
    const SceneBox base{.z = 1.0f, .w = 0.5f, .h = 0.08f, .d = 0.13f, .r = 60, .g = 150, .b = 90};
    SceneCup can;  // a closed top: a bottle whose neck is as wide as its body
    can.x = 0.185f;
    can.z = 1.0f;
    can.radius = 0.065f;
    can.h = 0.08f;
    can.neck_radius = can.radius;
    can.neck_h = 0.001f;
    can.lift = base.h;
    can.r = 60; can.g = 150; can.b = 90;
    s.boxes = {base};
    s.cups = {can};
    expect_split_by_height(up_to_the_plane(s), kTruthBox0, kTruthCup0, 0.9, "the can and the box are one object",
                           without_colour_splits());
}
