// Islands (src/segmentation/lone_islands.cpp): regions no segment reached, joined across a rim or
// kept alone.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "segment_scene.hpp"
#include "segmentation/internal.hpp"  // src/: keep_lone_islands, tested on a hand-built frame

using namespace wul3d;
using namespace wul3d::test;

// A small cup with a thin wall (0.5 mm: no rim ring joins inside and outside) seen from
// above: every pixel of its inside, or of its outer wall, lies within a crease step of the
// rim's or the floor's crease, so that region seeds no segment, and the rim's depth step
// keeps reattachment out of it. As an island (rim_islands) it meets the other part across
// the rim and the container rule joins them; without islands the cup is cut short (3.5 cm
// across) or lost (2.5 cm).
TEST(SegmentObjects, SmallThinCup_RegionNoSeedReachedJoinedAcrossTheRim) {
    for (const float radius : {0.035f, 0.025f}) {
        Scene s = pitched_tabletop_scene();
        SceneCup cup;
        cup.z = 1.0f;
        cup.radius = radius;
        cup.h = 0.09f;
        cup.wall = 0.0005f;
        s.cups = {cup};
        std::vector<int> truth;
        SegmentParams no_islands;
        no_islands.rim_islands = false;
        int label = 0;
        const LabelImage cut = segment(s, no_islands, truth);
        const double share = dominant_share(cut.labels, truth, kTruthCup0, &label);
        EXPECT_TRUE(label == 0 || share < 0.85)
            << radius << ": the cup was whole without islands (test premise), share " << share;

        SegmentStats stats;
        const LabelImage out = segment(s, SegmentParams{}, truth, &stats);
        EXPECT_GT(dominant_share(out.labels, truth, kTruthCup0, &label), 0.95) << radius;
        EXPECT_NE(label, 0) << radius;
        EXPECT_GE(stats.containers, 1) << radius;
        EXPECT_EQ(stats.segments, 1) << radius;

        // Islands that join nothing change nothing: with no rim fitting a circle, the labels
        // are those of the run without islands. (Nor is it kept as a lone island: at both
        // radii the one island is narrower than island_min_width_px, 4.4 and 3.3 pixels, and
        // smaller than min_points.)
        SegmentParams no_rims;
        no_rims.rim_max_residual_m = 1e-7f;
        SegmentParams no_rims_no_islands = no_rims;
        no_rims_no_islands.rim_islands = false;
        EXPECT_EQ(segment(s, no_rims, truth).labels, segment(s, no_rims_no_islands, truth).labels)
            << radius << ": an island no rule joined was kept";
    }
}

// Lone islands (keep_lone_islands) on a hand-built frame of 24 x 8 pixels: segment 1 in
// columns [0, 8) at 1 m, an island (label 3: n = 2, one island) in the columns after it,
// and beyond it segment 2 or nothing. An island is kept only when it lies behind every
// segment it meets, across a depth step, is wide enough (2 x pixels / outline pairs) and
// holds min_points.
TEST(SegmentObjects, LoneIslands_KeptWhenBehindEverySegmentAndWide) {
    struct Case {
        const char* what;
        float island_z;
        int island_cols;
        float beyond_z;  // segment 2's depth beyond the island; 0: no segment
        int min_width;
        bool kept;
        int min_points = 64;  // the island's size when 8 columns wide
    };
    const Case cases[] = {
        {"behind segment 1, nothing beyond", 1.2f, 8, 0, 3, true},
        {"behind segment 1 and a nearer segment 2", 1.2f, 8, 1.1f, 3, true},
        {"between segment 1 and a farther segment 2 in depth", 1.2f, 8, 1.4f, 3, false},
        {"continuous with segment 1", 1.001f, 8, 0, 3, false},
        {"a band 2 pixels wide", 1.2f, 2, 0, 3, false, 16},
        {"8 wide (64 pixels, 16 outline pairs) at a minimum of 8", 1.2f, 8, 0, 8, true},
        {"8 wide at a minimum of 9", 1.2f, 8, 0, 9, false},
        {"island_min_width_px 0", 1.2f, 8, 0, 0, false},
        {"smaller than min_points", 1.2f, 8, 0, 3, false, 65},
    };
    const int W = 24, H = 8, n = 2, island = n + 1;
    for (const Case& t : cases) {
        OrganizedCloud cloud;
        cloud.resize(W, H);
        SegmentWorkspace::Buffers ws;
        ws.label.assign(static_cast<std::size_t>(W) * H, 0);
        for (int v = 0; v < H; ++v)
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                const bool beyond = u >= 8 + t.island_cols && t.beyond_z > 0;
                ws.label[p] = u < 8 ? 1 : u < 8 + t.island_cols ? island : beyond ? 2 : 0;
                cloud.z[p] = u < 8 ? 1.0f : u < 8 + t.island_cols ? t.island_z : beyond ? t.beyond_z : 0.0f;
                cloud.valid[p] = cloud.z[p] > 0;
            }
        const std::vector<int> before = ws.label;
        SegmentParams prm;
        prm.island_min_width_px = t.min_width;
        prm.min_points = t.min_points;
        const NormalMap normals;
        const std::vector<std::uint8_t> classes;
        const detail::Ctx x{prm, cloud, normals, classes, W, H};
        EXPECT_EQ(detail::keep_lone_islands(x, ws, n, 1), t.kept ? 1 : 0) << t.what;
        for (std::size_t p = 0; p < before.size(); ++p)
            ASSERT_EQ(ws.label[p], before[p] == island && !t.kept ? 0 : before[p]) << t.what << ", pixel " << p;
    }
}
