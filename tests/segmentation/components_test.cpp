// The components and their re-attachment (src/segmentation/components.cpp): foot candidates
// join an object only across the small steps of a surface that runs down into the support;
// object pixels that no seed reached become a segment where they make a blob of their own.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {

/// A camera 1.1 m over a table, pitched down 1.3 rad (75 degrees), as OCID's looks at its
/// piles; a flat box (12 x 3 x 8 cm) lies under it.
Scene flat_box_from_above() {
    Scene s;
    s.pitch_rad = 1.3f;
    s.table_y = 1.1f;
    s.table_near = 0.0f;
    s.table_far = 1.0f;
    s.noise_seed = 5;
    s.boxes = {SceneBox{.x = 0.0f, .z = 0.3f, .w = 0.12f, .h = 0.03f, .d = 0.08f}};
    return s;
}

/// Each valid depth replaced by the mean of the valid depths in its 3 x 3 window: a camera
/// that blurs depth (its correlation window) leaves a ramp round every occluding edge, while
/// its colour stays sharp.
void blur_depth(DepthImage& d) {
    const std::vector<std::uint16_t> in = d.data;
    for (int v = 1; v + 1 < d.height; ++v)
        for (int u = 1; u + 1 < d.width; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * d.width + u;
            if (in[p] == 0) continue;
            unsigned sum = 0, n = 0;
            for (int dv = -1; dv <= 1; ++dv)
                for (int du = -1; du <= 1; ++du) {
                    const std::uint16_t z = in[p + static_cast<std::ptrdiff_t>(dv) * d.width + du];
                    sum += z;
                    n += z != 0;
                }
            d.data[p] = static_cast<std::uint16_t>(sum / n);
        }
}

}  // namespace

// Seen from above, the blurred edge of a flat box steps down to the table in a ramp whose
// pixels lie on the support's band with tilted normals: foot candidates. They are table,
// not the box's feet, and most stay out of it; the box itself is whole.
TEST(SegmentObjects, FlatBoxFromAbove_BlurredEdgeIsNoFoot) {
    std::vector<int> truth;
    RgbdFrame f = render_scene(flat_box_from_above(), &truth);
    blur_depth(f.depth);
    const PlaneStage in = up_to_the_plane(f, std::move(truth));
    std::size_t feet = 0;
    for (std::size_t p = 0; p < in.classes.size(); ++p)
        feet += in.truth[p] == kTruthTable && in.classes[p] == kPlaneFoot;
    ASSERT_GT(feet, 50u) << "the ramp should hold foot candidates (test premise)";
    const LabelImage out = segment(in, SegmentParams{});
    int box = 0;
    EXPECT_GT(dominant_share(out.labels, in.truth, kTruthBox0, &box), 0.95);
    ASSERT_NE(box, 0);
    std::size_t box_px = 0, table_px = 0;
    for (std::size_t p = 0; p < out.labels.size(); ++p) {
        if (out.labels[p] != box) continue;
        box_px += in.truth[p] == kTruthBox0;
        table_px += in.truth[p] == kTruthTable;
    }
    // Without the limit the whole ring joins (278 table pixels to 672 of the box's); with it
    // only what the shallow ramp at the corners lets in and the ring carries on (110).
    EXPECT_LT(static_cast<double>(table_px), 0.25 * static_cast<double>(box_px))
        << table_px << " table pixels joined the box's " << box_px;
}

// Where no seed is left in an object (here: its normals taken away, as creases a wide step
// apart cut through a small object far off) and no segment reaches it, its object pixels
// form a segment when they make a blob: a box. A lath 8 mm thick and 3 cm tall, whose part
// over the table's band is a band two or three pixels wide, does not (a line of table behind
// an object's top edge looks like it).
TEST(SegmentObjects, NoSeedLeft_ABoxIsAnOrphanSegment_ALathIsNot) {
    Scene s = pitched_tabletop_scene();
    s.boxes = {SceneBox{.x = -0.15f, .z = 1.0f, .w = 0.08f, .h = 0.06f, .d = 0.08f},
               SceneBox{.x = 0.15f, .z = 1.0f, .w = 0.3f, .h = 0.03f, .d = 0.008f}};
    PlaneStage in = up_to_the_plane(s);
    std::size_t box_px = 0, lath_px = 0;
    for (std::size_t p = 0; p < in.truth.size(); ++p) {
        const bool box = in.truth[p] == kTruthBox0, lath = in.truth[p] == kTruthBox0 + 1;
        box_px += box && in.classes[p] == kPlaneObject;
        lath_px += lath && in.classes[p] == kPlaneObject;
        if (box || lath) in.normals.valid[p] = 0;  // no seed
    }
    ASSERT_GT(box_px, 300u) << "premise: the box in view";
    ASSERT_GT(lath_px, 60u) << "premise: the lath in view";
    SegmentParams params;
    params.min_points = 30;
    const LabelImage out = segment(in, params);
    std::size_t lath_labelled = 0;
    for (std::size_t p = 0; p < in.truth.size(); ++p)
        lath_labelled += in.truth[p] == kTruthBox0 + 1 && out.labels[p] != 0;
    int box = 0;
    EXPECT_GT(dominant_share(out.labels, in.truth, kTruthBox0, &box), 0.8);
    EXPECT_NE(box, 0) << "the box is in no segment";
    EXPECT_EQ(lath_labelled, 0u) << lath_labelled << " of the lath's " << lath_px << " pixels in a segment";
}
