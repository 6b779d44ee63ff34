// The convexity merge (src/segmentation/merge.cpp), run alone on labels the test sets: two
// segments that meet along a convex edge (a box's top and its front face, as noise cuts
// them) are joined; two objects that meet at a concave fold are not.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <vector>

#include "segment_scene.hpp"
#include "segmentation/internal.hpp"  // src/: Ctx and the rule, run on labels of the test's own

using namespace wul3d;
using namespace wul3d::test;

namespace {

/// Runs merge_segments on `labels` (0 none, 1..n) over the scene's cloud and raw normals;
/// returns the labels after it and its joins in `joins`.
std::vector<int> merged(const PlaneStage& st, const SegmentParams& params, const std::vector<int>& labels, int n,
                        int& joins) {
    SegmentWorkspace workspace;
    SegmentWorkspace::Buffers& ws = workspace.buffers();
    ws.label = labels;
    const detail::Ctx x{params, st.cloud, st.normals, st.classes, st.cloud.width, st.cloud.height};
    SegmentStats stats;
    detail::merge_segments(x, &st.plane.support, ws, n, stats);
    joins = stats.merge.joins;
    return ws.label;
}

std::set<int> labels_of(const std::vector<int>& labels, const std::vector<int>& truth, int object) {
    std::set<int> found;
    for (std::size_t p = 0; p < labels.size(); ++p)
        if (truth[p] == object && labels[p] != 0) found.insert(labels[p]);
    return found;
}

/// A box of 20 x 12 x 15 cm before the camera, which looks down on the table.
SceneBox front_box() {
    SceneBox box;
    box.z = 0.9f;
    box.w = 0.2f;
    box.h = 0.12f;
    return box;
}

}  // namespace

// The box's top (normals up) and its front face, two segments: a convex edge, one object.
TEST(Merge, BoxTopAndFrontFace_Joined) {
    Scene s = pitched_tabletop_scene();
    s.boxes = {front_box()};
    const PlaneStage st = up_to_the_plane(s);
    std::vector<int> labels(st.truth.size(), 0);
    int top = 0, front = 0;
    for (std::size_t p = 0; p < labels.size(); ++p) {
        if (st.truth[p] != kTruthBox0 || !st.normals.valid[p]) continue;
        const bool up = st.normals.ny[p] < -0.7f;  // camera y points down
        labels[p] = up ? 1 : 2;
        (up ? top : front) += 1;
    }
    ASSERT_GT(top, 300) << "the camera should see the box's top (test premise)";
    ASSERT_GT(front, 300) << "the camera should see the box's front (test premise)";
    int joins = 0;
    const std::vector<int> out = merged(st, SegmentParams{}, labels, 2, joins);
    EXPECT_EQ(joins, 1);
    EXPECT_EQ(labels_of(out, st.truth, kTruthBox0).size(), 1u);

    SegmentParams off;
    off.merge.max_concave = 0;
    const std::vector<int> apart = merged(st, off, labels, 2, joins);
    EXPECT_EQ(joins, 0);
    EXPECT_EQ(labels_of(apart, st.truth, kTruthBox0).size(), 2u);
}

// A small box standing against a tall one of the same colour: their faces meet at a concave
// fold, which the merge does not cross.
TEST(Merge, BoxesAtAConcaveFold_StayApart) {
    const Scene s = small_box_before_tall_box();
    const PlaneStage st = up_to_the_plane(s);
    std::vector<int> labels(st.truth.size(), 0);
    for (std::size_t p = 0; p < labels.size(); ++p) {
        if (st.truth[p] == kTruthBox0) labels[p] = 1;
        if (st.truth[p] == kTruthBox0 + 1) labels[p] = 2;
    }
    int joins = -1;
    const std::vector<int> out = merged(st, SegmentParams{}, labels, 2, joins);
    EXPECT_EQ(joins, 0);
    const std::set<int> a = labels_of(out, st.truth, kTruthBox0), b = labels_of(out, st.truth, kTruthBox0 + 1);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_NE(*a.begin(), *b.begin()) << "the two boxes were merged";

    SegmentParams any_share;  // the boundary is tested: only its concave share parts them
    any_share.merge.max_concave = 1;
    merged(st, any_share, labels, 2, joins);
    EXPECT_EQ(joins, 1) << "the boxes' boundary should hold tested pairs (test premise)";
}
