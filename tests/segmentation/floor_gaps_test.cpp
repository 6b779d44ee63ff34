// Floor gaps (src/segmentation/floor_gaps.cpp): holes in a container's floor filled, holes in its
// wall kept.
#include <gtest/gtest.h>

#include "segment_scene.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Gaps in a container's floor: floor points the plane step left out (here a 3 x 3 block of
// the cup's inside, taken back out of it) are filled into the cup; a hole in its wall, which
// touches no inside, stays a hole (a mug's handle shows the table the same way).
TEST(SegmentObjects, Cup_FloorGapsFilledWallHoleKept) {
    Scene s = pitched_tabletop_scene();
    SceneCup cup;
    cup.z = 0.9f;
    cup.radius = 0.1f;
    s.cups = {cup};
    PlaneStage in = up_to_the_plane(s);
    ASSERT_TRUE(in.plane.found);
    const std::vector<int>& truth = in.truth;
    std::vector<std::uint8_t>& classes = in.classes;
    // A pixel whose 5 x 5 neighbourhood is all of one class: the centre of a block to punch.
    const int W = in.cloud.width, H = in.cloud.height;
    auto block_of = [&](std::uint8_t cls) {
        for (int v = 2; v + 2 < H; ++v)
            for (int u = 2; u + 2 < W; ++u) {
                bool all = true;
                for (int dv = -2; dv <= 2 && all; ++dv)
                    for (int du = -2; du <= 2 && all; ++du)
                        all = classes[static_cast<std::size_t>(v + dv) * W + u + du] == cls &&
                              truth[static_cast<std::size_t>(v + dv) * W + u + du] == kTruthCup0;
                if (all) return static_cast<std::size_t>(v) * W + u;
            }
        return std::size_t{0};
    };
    const std::size_t floor = block_of(kPlaneInside), wall = block_of(kPlaneObject);
    ASSERT_NE(floor, 0u) << "no 5 x 5 patch of the cup's inside (test premise)";
    ASSERT_NE(wall, 0u);
    std::vector<std::size_t> floor_gap, wall_hole;
    for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
            const std::ptrdiff_t d = static_cast<std::ptrdiff_t>(dv) * W + du;
            floor_gap.push_back(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(floor) + d));
            wall_hole.push_back(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(wall) + d));
        }
    for (std::size_t p : floor_gap) classes[p] = kPlaneRemoved;
    for (std::size_t p : wall_hole) classes[p] = kPlaneRemoved;

    for (const int max_px : {0, 500}) {
        SegmentParams params;
        params.containers.gap_max_px = max_px;
        SegmentStats st;
        const LabelImage out = segment(in, params, &st);
        int cup_label = 0;
        EXPECT_GT(dominant_share(out.labels, truth, kTruthCup0, &cup_label), 0.9);
        ASSERT_NE(cup_label, 0);
        for (std::size_t p : wall_hole) EXPECT_EQ(out.labels[p], 0) << "max " << max_px;
        for (std::size_t p : floor_gap)
            EXPECT_EQ(out.labels[p], max_px ? cup_label : 0) << "max " << max_px;
        EXPECT_EQ(st.containers.gaps_filled, max_px ? floor_gap.size() : 0u);
    }
}
