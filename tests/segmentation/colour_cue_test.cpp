// The colour cue (src/segmentation/colour_cue.cpp): flush objects parted by colour or
// brightness, and what it leaves whole (one box, a printed cup, a striped box).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Two boxes side by side, flush: front and top faces coplanar and touching. Geometry cannot
// tell them apart; the colour cue (hybrid) can, because they differ in colour and meet along
// a straight boundary across a flat surface.
TEST(SegmentObjects, FlushBoxesOfDifferentColours_SeparatedByTheColourCue) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 7;
    SceneBox red;
    red.x = -0.075f;
    red.z = 1.0f;
    SceneBox blue = red;
    blue.x = 0.075f;
    blue.r = 30;
    blue.g = 60;
    blue.b = 220;
    s.boxes = {red, blue};
    std::vector<int> truth;
    int a = 0, b = 0;
    const LabelImage geo = segment(s, Segmenter::Geometric, truth);
    dominant_share(geo.labels, truth, kTruthBox0, &a);
    dominant_share(geo.labels, truth, kTruthBox0 + 1, &b);
    EXPECT_EQ(a, b) << "geometry alone should not separate flush boxes (test premise)";

    SegmentStats stats;
    const LabelImage hyb = segment(s, Segmenter::Hybrid, truth, &stats);
    EXPECT_GT(dominant_share(hyb.labels, truth, kTruthBox0, &a), 0.9);
    EXPECT_GT(dominant_share(hyb.labels, truth, kTruthBox0 + 1, &b), 0.9);
    EXPECT_NE(a, 0);
    EXPECT_NE(a, b) << "the colour cue did not split the flush boxes";
    EXPECT_EQ(stats.colour.splits, 1);
}

// Two flush boxes of one hue, a light one and a dark one: their chromaticities lie closer
// than the colour cue's distance, so only the step in brightness where their contact
// crosses the shared front and top planes tells the two materials apart.
TEST(SegmentObjects, FlushBoxesOfOneHue_SeparatedByTheBrightnessStep) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 7;
    const SceneBox light{.x = -0.075f, .z = 1.0f, .r = 200, .g = 120, .b = 60};
    const SceneBox dark{.x = 0.075f, .z = 1.0f, .r = 80, .g = 65, .b = 20};
    s.boxes = {light, dark};
    std::vector<int> truth;
    int a = 0, b = 0;
    SegmentParams no_step;
    no_step.colour.min_step = 0;
    const LabelImage without = segment(s, no_step, truth);
    dominant_share(without.labels, truth, kTruthBox0, &a);
    dominant_share(without.labels, truth, kTruthBox0 + 1, &b);
    EXPECT_EQ(a, b) << "the chromaticity alone should not separate the boxes (test premise)";

    SegmentStats stats;
    const LabelImage out = segment(s, SegmentParams{}, truth, &stats);
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0, &a), 0.9);
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0 + 1, &b), 0.9);
    EXPECT_NE(a, 0);
    EXPECT_NE(a, b) << "the brightness step did not split the flush boxes";
    EXPECT_EQ(stats.colour.splits, 1);
}

// The colour cue leaves a box alone whose faces differ in shade: the colour boundary runs
// along a convex edge, not across a flat surface.
TEST(SegmentObjects, ColourCue_DoesNotSplitOneBox) {
    Scene s = pitched_tabletop_scene();
    SceneBox box;
    box.z = 1.0f;
    s.boxes = {box};
    std::vector<int> truth;
    SegmentStats stats;
    const LabelImage out = segment(s, Segmenter::Hybrid, truth, &stats);
    EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0), 0.95);
    EXPECT_EQ(stats.colour.splits, 0);
    EXPECT_EQ(stats.segments, 1);
}

// Two flush boxes of different colours and heights: the colour boundary runs up the front
// faces and then along the lower box's top edge, a fold, so it is not "across a smooth
// surface" for most of its length. The parts' colours differ in chromaticity, which shading
// alone cannot do, and their boundary is one side of the smaller part: the colour cue
// splits them.
TEST(SegmentObjects, FlushBoxesOfTwoHeights_SeparatedAcrossTheFold) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 5;
    SceneBox tall;
    tall.x = -0.06f;
    tall.z = 1.0f;
    tall.w = 0.12f;
    tall.h = 0.16f;
    tall.d = 0.12f;
    tall.r = 40; tall.g = 170; tall.b = 60;
    SceneBox low = tall;
    low.x = 0.06f;
    low.h = 0.07f;
    low.r = 220; low.g = 40; low.b = 160;
    s.boxes = {tall, low};
    std::vector<int> truth;
    SegmentStats stats;
    const LabelImage hyb = segment(s, Segmenter::Hybrid, truth, &stats);
    expect_separate(hyb, truth, kTruthBox0, kTruthBox0 + 1, 0.9, "the two boxes are one object");
}

// A flat box lying on a larger box of another colour, seen from above: the larger box's top
// encloses the flat one in view, so their colour boundary is the flat box's whole outline,
// not one side of it. It is short for the piece's area (a compact piece, not a texture),
// and the colour cue splits them (colour.max_compact).
TEST(SegmentObjects, FlatBoxLyingOnABox_SeparatedAsACompactPiece) {
    Scene s = pitched_tabletop_scene();
    // The base near the table's colour, as its feet are; the flat box lying on its top.
    const SceneBox base{.z = 1.0f, .w = 0.26f, .h = 0.08f, .d = 0.24f, .r = 180, .g = 150, .b = 100};
    const SceneBox flat{.z = 1.0f, .w = 0.12f, .h = 0.015f, .d = 0.1f, .lift = base.h, .r = 40, .g = 90, .b = 200};
    s.boxes = {base, flat};
    std::vector<int> truth;
    const PlaneStage in = up_to_the_plane(s);
    int a = 0, b = 0;
    SegmentParams without;
    without.colour.max_compact = 0;
    const LabelImage one = segment(in, without);
    dominant_share(one.labels, in.truth, kTruthBox0, &a);
    dominant_share(one.labels, in.truth, kTruthBox0 + 1, &b);
    ASSERT_EQ(a, b) << "without the compact-piece test the two boxes should be one (test premise)";

    SegmentStats stats;
    const LabelImage two = segment(in, SegmentParams{}, &stats);
    expect_separate(two, in.truth, kTruthBox0, kTruthBox0 + 1, 0.8, "the flat box was not split from the box it lies on");
    EXPECT_EQ(stats.colour.splits, 1);
}

// One round container or bottle on the tilted tabletop whose second colour the colour cue
// cuts off without the round test (the premise, with `premise_share`, where given, the most
// of it one segment then keeps) and keeps whole with it.
namespace {
void expect_round_test_keeps_whole(const SceneCup& cup, std::optional<double> premise_share, const char* what) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 5;
    s.cups = {cup};
    const PlaneStage in = up_to_the_plane(s);
    SegmentParams without;
    without.colour.round_deg = 0;
    SegmentStats split_stats;
    const LabelImage split = segment(in, without, &split_stats);
    ASSERT_GE(split_stats.colour.splits, 1) << "without the round test it should be cut (test premise)";
    if (premise_share) {
        ASSERT_LT(dominant_share(split.labels, in.truth, kTruthCup0), *premise_share) << "(test premise)";
    }

    SegmentStats stats;
    const LabelImage one = segment(in, SegmentParams{}, &stats);
    EXPECT_EQ(stats.colour.splits, 0);
    EXPECT_GE(dominant_share(one.labels, in.truth, kTruthCup0), 0.95) << what;
}
}  // namespace

// A cup with a printed band round its outer wall: two colours on one solid of revolution,
// as a can's or a bottle's label. The band is a compact piece the colour cue would cut off;
// the cup's walls lie on one upright circle and face along its radii, so it stays one
// object (colour.round_deg).
TEST(SegmentObjects, CupWithAPrintedBand_StaysOneObject) {
    expect_round_test_keeps_whole(SceneCup{.z = 0.9f, .radius = 0.045f, .h = 0.13f, .band_lo = 0.03f, .band_hi = 0.1f},
                                  0.9, "the printed cup was split");
}

namespace {
/// A bottle on the tilted tabletop: body 10 cm, a 45-degree shoulder, a neck of another colour.
constexpr SceneCup kBottle{.z = 0.8f, .radius = 0.05f, .h = 0.1f, .band_lo = 0.101f, .band_hi = 0.2f,
                           .neck_radius = 0.025f, .neck_h = 0.09f};
}  // namespace

// The scene's bottle as the renderer draws it (the test scenes' own geometry): each of its
// pixels, taken back to the scene's axes, lies on the body's wall, the shoulder's cone, the
// neck's wall or the neck's top, within 2 mm, and each part shows; its heights counted from
// its foot, `lift` over the table.
static void expect_bottle_where_it_should_be(float lift) {
    SceneCup bottle = kBottle;
    bottle.lift = lift;
    Scene s = pitched_tabletop_scene();
    s.cups = {bottle};
    std::vector<int> truth;
    const RgbdFrame f = render_scene(s, &truth);
    const auto& K = f.intrinsics;
    const float shoulder = kBottle.radius - kBottle.neck_radius, top = kBottle.h + shoulder + kBottle.neck_h;
    int body = 0, cone = 0, neck = 0, cap = 0, off = 0;
    for (int v = 0; v < f.depth.height; ++v)
        for (int u = 0; u < f.depth.width; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * f.depth.width + u;
            if (truth[p] != kTruthCup0) continue;
            // The renderer's ray, and its parameter t (the depth) back to a point.
            const float dx = static_cast<float>((u - K.cx) / K.fx), dy_cam = static_cast<float>((v - K.cy) / K.fy);
            const float cp = std::cos(s.pitch_rad), sp = std::sin(s.pitch_rad);
            const float t = f.depth.data[p] * f.depth.scale_m_per_unit;
            const float x = t * dx, y = t * (dy_cam * cp + sp), z = t * (-dy_cam * sp + cp);
            const float height = s.table_y - lift - y, r = std::hypot(x - kBottle.x, z - kBottle.z);
            constexpr float kTol = 0.002f;
            if (height < kBottle.h - kTol && std::fabs(r - kBottle.radius) < kTol) ++body;
            else if (height > kBottle.h + kTol && height < kBottle.h + shoulder - kTol &&
                     std::fabs(r - (kBottle.radius - (height - kBottle.h))) < kTol) ++cone;
            else if (height > kBottle.h + shoulder + kTol && height < top - kTol && std::fabs(r - kBottle.neck_radius) < kTol)
                ++neck;
            else if (std::fabs(height - top) < kTol && r < kBottle.neck_radius + kTol) ++cap;
            else if (std::fabs(height - kBottle.h) >= kTol && std::fabs(height - kBottle.h - shoulder) >= kTol) ++off;
        }
    EXPECT_GE(body, 200);
    EXPECT_GE(cone, 20);
    EXPECT_GE(neck, 50);
    EXPECT_GE(cap, 5);
    EXPECT_EQ(off, 0) << "bottle pixels on none of its surfaces";
}

TEST(SyntheticScene, Bottle_BodyShoulderAndNeckWhereTheyShouldBe) { expect_bottle_where_it_should_be(0.0f); }

// The same bottle standing 6 cm over the table (SceneCup::lift: on a box) is drawn 6 cm higher:
// measured from the table, every pixel would lie off its surfaces.
TEST(SyntheticScene, LiftedBottle_DrawnThatMuchHigher) { expect_bottle_where_it_should_be(0.06f); }

// A bottle whose neck is another colour than its body (a cap, a label round the neck): the
// neck is a compact piece the colour cue would cut off. Body and neck are circles of two
// radii about one axis, layer by layer (fit_coaxial), so the bottle stays one object.
// The cue's cut is the premise, not what the output keeps of it: the neck rule joins the
// shoulder with the neck it cuts off back to the body (within its radius, the neck at its top).
TEST(SegmentObjects, BottleWithANeckOfAnotherColour_StaysOneObject) {
    expect_round_test_keeps_whole(kBottle, std::nullopt, "the bottle's neck was split off");
}

// Three flush boxes of three colours in a row: one 2-means split cuts one box off, and the
// second round splits the two that are left.
TEST(SegmentObjects, ThreeFlushBoxesOfThreeColours_SplitInTwoRounds) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 9;
    s.boxes = {SceneBox{.x = -0.12f, .z = 1.0f, .w = 0.12f, .r = 210, .g = 40, .b = 40},
               SceneBox{.x = 0.0f, .z = 1.0f, .w = 0.12f, .r = 40, .g = 180, .b = 60},
               SceneBox{.x = 0.12f, .z = 1.0f, .w = 0.12f, .r = 40, .g = 60, .b = 220}};
    std::vector<int> truth;
    SegmentStats stats;
    const LabelImage out = segment(s, Segmenter::Hybrid, truth, &stats);
    int id[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0 + i, &id[i]), 0.9) << "box " << i;
        EXPECT_NE(id[i], 0) << "box " << i;
    }
    EXPECT_NE(id[0], id[1]);
    EXPECT_NE(id[1], id[2]);
    EXPECT_NE(id[0], id[2]);
    EXPECT_EQ(stats.colour.splits, 2);
}

// Four flush boxes: a red one far in colour from three others, whose colours lie in a row
// (green, teal, blue). Each round of 2-means peels the part farthest in colour: red, then
// an end of the row, then the last pair, so the four need three rounds.
TEST(SegmentObjects, FourFlushBoxesOfFourColours_SplitInThreeRounds) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 9;
    s.boxes = {SceneBox{.x = -0.15f, .z = 1.0f, .w = 0.1f, .r = 220, .g = 30, .b = 30},
               SceneBox{.x = -0.05f, .z = 1.0f, .w = 0.1f, .r = 40, .g = 180, .b = 60},
               SceneBox{.x = 0.05f, .z = 1.0f, .w = 0.1f, .r = 40, .g = 160, .b = 150},
               SceneBox{.x = 0.15f, .z = 1.0f, .w = 0.1f, .r = 40, .g = 60, .b = 220}};
    std::vector<int> truth;
    SegmentStats stats;
    const LabelImage out = segment(s, Segmenter::Hybrid, truth, &stats);
    int id[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; ++i) {
        EXPECT_GT(dominant_share(out.labels, truth, kTruthBox0 + i, &id[i]), 0.9) << "box " << i;
        EXPECT_NE(id[i], 0) << "box " << i;
        for (int j = 0; j < i; ++j) EXPECT_NE(id[i], id[j]) << "boxes " << j << " and " << i;
    }
    EXPECT_EQ(stats.colour.splits, 3);
}

// Two flush boxes of different colours, one with a small sticker of a third colour (under
// 2 % of the pair) farther from each box's colour than they are from each other. 2-means
// seeded at the farthest colours starts one part at the sticker and keeps it there (both
// boxes are nearer the other seed), a part the share test rejects; seeded along the
// colours' principal axis it finds the two boxes.
TEST(SegmentObjects, FlushBoxesWithASticker_SplitAlongTheMainColours) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 11;
    // Muted colours: the sticker is farther from each than they are from each other.
    s.boxes = {SceneBox{.x = -0.075f, .z = 1.0f, .r = 190, .g = 70, .b = 60},
               SceneBox{.x = 0.075f, .z = 1.0f, .r = 60, .g = 80, .b = 190}};
    PlaneStage in = up_to_the_plane(s);
    // The sticker: a 6 x 6 px square of green in the middle of the red box's pixels.
    long su = 0, sv = 0, n = 0;
    for (int v = 0; v < in.cloud.height; ++v)
        for (int u = 0; u < in.cloud.width; ++u)
            if (in.truth[static_cast<std::size_t>(v) * in.cloud.width + u] == kTruthBox0) su += u, sv += v, ++n;
    ASSERT_GT(n, 1000);
    int painted = 0;
    for (int v = static_cast<int>(sv / n) - 3; v < static_cast<int>(sv / n) + 3; ++v)
        for (int u = static_cast<int>(su / n) - 3; u < static_cast<int>(su / n) + 3; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * in.cloud.width + u;
            if (in.truth[p] != kTruthBox0) continue;
            in.cloud.r[p] = 0; in.cloud.g[p] = 255; in.cloud.b[p] = 0;
            ++painted;
        }
    ASSERT_GT(painted, 20);
    SegmentStats stats;
    const LabelImage out = segment(in, SegmentParams{}, &stats);
    expect_separate(out, in.truth, kTruthBox0, kTruthBox0 + 1, 0.9, "the sticker hid the contact between the boxes");
    EXPECT_EQ(stats.colour.splits, 1);
}

namespace {
/// Paints truth object `id`'s pixels p where `where(p)` holds with stripes of the N colours
/// in turn, `period_m` wide, fixed on its surfaces (the stripes follow x + y + z of the
/// points, as the generator's do).
template <std::size_t N, class Where>
void paint_bands(PlaneStage& in, int id, const std::uint8_t (&colours)[N][3], float period_m, Where&& where) {
    const auto n = static_cast<long>(N);
    for (std::size_t p = 0; p < in.truth.size(); ++p) {
        if (in.truth[p] != id || !where(p)) continue;
        const long stripe = static_cast<long>(std::floor((in.cloud.x[p] + in.cloud.y[p] + in.cloud.z[p]) / period_m));
        const auto& c = colours[(stripe % n + n) % n];
        in.cloud.r[p] = c[0], in.cloud.g[p] = c[1], in.cloud.b[p] = c[2];
    }
}

/// paint_bands with two colours over the whole object.
void paint_stripes(PlaneStage& in, int id, const std::uint8_t (&a)[3], const std::uint8_t (&b)[3], float period_m) {
    const std::uint8_t two[2][3] = {{a[0], a[1], a[2]}, {b[0], b[1], b[2]}};
    paint_bands(in, id, two, period_m, [](std::size_t) { return true; });
}

/// Three flush boxes in a row, 15 cm each, a metre away (the third's colour `third`).
PlaneStage three_flush_boxes(const std::uint8_t (&third)[3] = {200, 30, 30}) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 13;
    s.boxes = {SceneBox{.x = -0.15f, .z = 1.0f}, SceneBox{.x = 0.0f, .z = 1.0f},
               SceneBox{.x = 0.15f, .z = 1.0f, .r = third[0], .g = third[1], .b = third[2]}};
    return up_to_the_plane(s);
}

/// Each two of three_flush_boxes' boxes in objects of their own (expect_separate, 0.9 of
/// each); `why`: what failed for the first and second, the second and third, the first and
/// third.
void expect_three_apart(const LabelImage& out, const std::vector<int>& truth, const char* const (&why)[3]) {
    expect_separate(out, truth, kTruthBox0, kTruthBox0 + 1, 0.9, why[0]);
    expect_separate(out, truth, kTruthBox0 + 1, kTruthBox0 + 2, 0.9, why[1]);
    expect_separate(out, truth, kTruthBox0, kTruthBox0 + 2, 0.9, why[2]);
}

/// Two flush boxes, the left plain red, the right striped (blue and yellow, 2 cm).
PlaneStage plain_and_striped_boxes() {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 13;
    s.boxes = {SceneBox{.x = -0.075f, .z = 1.0f}, SceneBox{.x = 0.075f, .z = 1.0f}};
    PlaneStage in = up_to_the_plane(s);
    paint_stripes(in, kTruthBox0 + 1, {40, 60, 210}, {220, 200, 40}, 0.02f);
    return in;
}
}  // namespace

// A plain box flush beside a striped one: 2-means follows the stripes (its boundary runs
// round every stripe) and the split is rejected; the segment's four colours make two
// materials (the stripes' two interleave, the rest is the plain box's), and the split
// between them is kept.
TEST(SegmentObjects, PlainBoxFlushBesideAStripedBox_SplitByMaterial) {
    const PlaneStage in = plain_and_striped_boxes();
    SegmentParams without;
    without.colour.textures = false;
    SegmentStats stats;
    const LabelImage one = segment(in, without, &stats);
    int a = 0, b = 0;
    dominant_share(one.labels, in.truth, kTruthBox0, &a);
    dominant_share(one.labels, in.truth, kTruthBox0 + 1, &b);
    ASSERT_EQ(a, b) << "2-means alone should not part the boxes (test premise)";
    EXPECT_EQ(stats.colour.splits, 0);

    const LabelImage out = segment(in, SegmentParams{}, &stats);
    expect_separate(out, in.truth, kTruthBox0, kTruthBox0 + 1, 0.9, "the materials were not parted");
    EXPECT_EQ(stats.colour.splits, 1);
    EXPECT_EQ(stats.colour.texture_splits, 1);
}

// Three flush boxes, plain red, striped (blue and yellow, 2 cm) and plain green: the four
// colours make three materials (the stripes' two interleave). The one that touches the
// others least for its size is split off, then the rest in the second round: three objects.
TEST(SegmentObjects, ThreeFlushBoxesOneStriped_EachItsOwnMaterial) {
    PlaneStage in = three_flush_boxes({40, 170, 60});
    paint_stripes(in, kTruthBox0 + 1, {40, 60, 210}, {220, 200, 40}, 0.02f);
    SegmentStats stats;
    const LabelImage out = segment(in, SegmentParams{}, &stats);
    expect_three_apart(out, in.truth,
                       {"the red box stayed with the striped one", "the green box stayed with the striped one",
                        "the red and green boxes stayed one"});
    EXPECT_GE(stats.colour.texture_splits, 1);
}

// One striped box on its own: its stripes are one material, whatever four colours k-means
// finds in them; nothing is split.
TEST(SegmentObjects, StripedBox_StaysOneObject) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 13;
    s.boxes = {SceneBox{.z = 1.0f, .w = 0.25f}};
    PlaneStage in = up_to_the_plane(s);
    paint_stripes(in, kTruthBox0, {40, 60, 210}, {220, 200, 40}, 0.02f);
    SegmentStats stats;
    const LabelImage out = segment(in, SegmentParams{}, &stats);
    EXPECT_GT(dominant_share(out.labels, in.truth, kTruthBox0), 0.95);
    EXPECT_EQ(stats.colour.splits, 0);
    EXPECT_EQ(stats.segments, 1);
}

// Three flush boxes, each striped in its own two colours (2 cm): six colours, and the four
// of the texture clustering each span two boxes, so every pair interleaves and the four make
// one material. Eight colours tell the three textures apart: three materials, and each box
// its own object after the second round.
TEST(SegmentObjects, ThreeFlushStripedBoxes_PartedByEightColours) {
    PlaneStage in = three_flush_boxes();
    paint_stripes(in, kTruthBox0, {200, 30, 30}, {240, 240, 240}, 0.02f);
    paint_stripes(in, kTruthBox0 + 1, {40, 60, 210}, {220, 200, 40}, 0.02f);
    paint_stripes(in, kTruthBox0 + 2, {40, 170, 60}, {150, 40, 160}, 0.02f);
    SegmentStats stats;
    const LabelImage out = segment(in, SegmentParams{}, &stats);
    expect_three_apart(out, in.truth,
                       {"the first two striped boxes stayed one", "the last two striped boxes stayed one",
                        "the outer striped boxes stayed one"});
    EXPECT_GE(stats.colour.texture_splits, 2);
}

// One box printed in three colours on its top and three others on its sides (2 cm stripes):
// the four colours make one material, eight make two, the top and the sides. Their boundary
// runs along the box's edge, a convex fold, where two objects of a pile meet across a
// concave one: the split between them is refused, and the box stays one.
TEST(SegmentObjects, BoxPrintedOtherwiseOnTopAndSides_StaysOneAcrossItsEdge) {
    Scene s = pitched_tabletop_scene();
    s.noise_seed = 13;
    const SceneBox box{.z = 1.0f, .w = 0.25f};
    s.boxes = {box};
    PlaneStage in = up_to_the_plane(s);
    const std::uint8_t top[3][3] = {{200, 30, 30}, {240, 240, 240}, {30, 30, 30}};
    const std::uint8_t sides[3][3] = {{40, 60, 210}, {220, 200, 40}, {40, 170, 60}};
    const auto on_top = [&](std::size_t p) {
        return in.plane.support.height(in.cloud.x[p], in.cloud.y[p], in.cloud.z[p]) > box.h - 0.01f;
    };
    paint_bands(in, kTruthBox0, top, 0.02f, on_top);
    paint_bands(in, kTruthBox0, sides, 0.02f, [&](std::size_t p) { return !on_top(p); });
    SegmentStats stats;
    const LabelImage out = segment(in, SegmentParams{}, &stats);
    EXPECT_GT(dominant_share(out.labels, in.truth, kTruthBox0), 0.95);
    EXPECT_EQ(stats.colour.splits, 0);
    EXPECT_EQ(stats.segments, 1);
}
