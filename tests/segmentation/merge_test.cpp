// The convexity merge (src/segmentation/merge.cpp), run alone on labels the test sets: two
// segments that meet along a convex edge (a box's top and its front face, as noise cuts
// them) are joined; two objects that meet at a concave fold are not, nor (with colour) two
// whose boundary steps in depth and changes colour: one's outline over the other.
#include <gtest/gtest.h>

#include <algorithm>
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

/// The box's top (1) and front face (2) as two segments, from the normals; their sizes in
/// `top` and `front`.
std::vector<int> top_and_front(const PlaneStage& st, int& top, int& front) {
    std::vector<int> labels(st.truth.size(), 0);
    top = front = 0;
    for (std::size_t p = 0; p < labels.size(); ++p) {
        if (st.truth[p] != kTruthBox0 || !st.normals.valid[p]) continue;
        const bool up = st.normals.ny[p] < -0.7f;  // camera y points down
        labels[p] = up ? 1 : 2;
        (up ? top : front) += 1;
    }
    return labels;
}

/// Paints segment 2 of `labels` red and the rest of the cloud green.
void two_colours(PlaneStage& st, const std::vector<int>& labels) {
    OrganizedCloud& c = st.cloud;
    for (std::size_t p = 0; p < labels.size(); ++p) {
        const bool two = labels[p] == 2;
        c.r[p] = two ? 200 : 40;
        c.g[p] = two ? 40 : 200;
        c.b[p] = 40;
    }
    c.has_color = true;
}

/// A box of 20 x 12 x 15 cm on the pitched tabletop before the camera, which looks down on
/// it; up to the plane stage.
PlaneStage front_box_on_the_table() {
    SceneBox box;
    box.z = 0.9f;
    box.w = 0.2f;
    box.h = 0.12f;
    Scene s = pitched_tabletop_scene();
    s.boxes = {box};
    return up_to_the_plane(s);
}

}  // namespace

// The box's top (normals up) and its front face, two segments: a convex edge, one object.
TEST(Merge, BoxTopAndFrontFace_Joined) {
    const PlaneStage st = front_box_on_the_table();
    int top = 0, front = 0;
    const std::vector<int> labels = top_and_front(st, top, front);
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

// The box's top and front in two colours. The camera looks down on the front face nearly
// edge-on, so depth steps between neighbours across the boundary as it does where one
// object's outline lies over another it touches (a ball against a lying can): with colour
// (hybrid) the merge reads a silhouette and keeps them apart; without (geometric) the convex
// boundary joins them. The box's top cut into a left and a right half of two colours (print
// on one face) steps no more than the top's slope along the cut, and is joined.
TEST(Merge, TwoColoursAcrossADepthStep_AreASilhouette_NotJoined) {
    const PlaneStage plain = front_box_on_the_table();
    int top = 0, front = 0;
    const std::vector<int> labels = top_and_front(plain, top, front);
    ASSERT_GT(top, 300);
    ASSERT_GT(front, 300);
    const SegmentParams hybrid;
    ASSERT_EQ(hybrid.segmenter, Segmenter::Hybrid);
    SegmentParams geometric;
    geometric.segmenter = Segmenter::Geometric;
    int joins = -1;

    PlaneStage coloured = plain;
    two_colours(coloured, labels);
    merged(coloured, hybrid, labels, 2, joins);
    EXPECT_EQ(joins, 0) << "two colours across a depth step: a silhouette";
    merged(coloured, geometric, labels, 2, joins);
    EXPECT_EQ(joins, 1) << "without colour the convex boundary joins (test premise)";

    // The top alone, its left and right halves.
    std::vector<int> halves(labels.size(), 0);
    int u_min = plain.cloud.width, u_max = -1;
    for (std::size_t p = 0; p < labels.size(); ++p)
        if (labels[p] == 1) {
            const int u = static_cast<int>(p % static_cast<std::size_t>(plain.cloud.width));
            u_min = std::min(u_min, u);
            u_max = std::max(u_max, u);
        }
    const int u_mid = (u_min + u_max) / 2;
    for (std::size_t p = 0; p < labels.size(); ++p)
        if (labels[p] == 1)
            halves[p] = static_cast<int>(p % static_cast<std::size_t>(plain.cloud.width)) < u_mid ? 1 : 2;
    PlaneStage printed = plain;
    two_colours(printed, halves);
    merged(printed, hybrid, halves, 2, joins);
    EXPECT_EQ(joins, 1) << "print on one face: two colours without a step";
}
