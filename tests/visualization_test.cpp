#include "wul3d/visualization.hpp"

#include <gtest/gtest.h>

#include <set>

#include "synthetic_scene.hpp"
#include "wul3d/background.hpp"
#include "wul3d/normals.hpp"

using namespace wul3d;
using namespace wul3d::test;

TEST(ClusterColor, DistinctForManyClusters) {
    std::set<std::array<std::uint8_t, 3>> seen;
    for (int j = 0; j < 100; ++j) seen.insert(cluster_color(j));
    EXPECT_EQ(seen.size(), 100u);
    EXPECT_EQ(cluster_color(3), cluster_color(3));  // fixed
}

TEST(RenderWeightColors, IsEquation9) {
    // Two frames: a box present, then gone. With psi = 1, its former pixels hold half the
    // box cluster's weight and half the new winner's: their colour is the average (eq. 9).
    Scene s;
    SceneBox b;
    b.x = 0.0f;
    b.z = 0.9f;
    b.w = b.h = b.d = 0.3f;
    s.boxes = {b};
    ClusterParams p = ClusterParams::paper();
    p.k = 3;
    ClusterState state(p);
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;
    LabelImage labels;
    ColorImage out;
    std::vector<int> truth;
    RgbdFrame f = render_scene(s, &truth);
    back_project(f, cloud);
    estimate_normals(NormalParams{}, cloud, normals);
    select_depth_range(DepthRange{}, cloud, active);
    state.step(cloud, normals, active, labels);
    render_weight_colors(state, labels, f, out);
    const std::size_t centre = static_cast<std::size_t>(200) * f.width() + f.width() / 2;
    ASSERT_EQ(truth[centre], kTruthBox0);
    const int before = labels.labels[centre];
    ASSERT_GT(before, 0);
    for (int q = 0; q < 3; ++q) EXPECT_EQ(out.rgb[3 * centre + q], cluster_color(before - 1)[q]);

    s.boxes.clear();
    f = render_scene(s);
    back_project(f, cloud);
    estimate_normals(NormalParams{}, cloud, normals);
    select_depth_range(DepthRange{}, cloud, active);
    state.step(cloud, normals, active, labels);
    render_weight_colors(state, labels, f, out);
    const int after = labels.labels[centre];
    ASSERT_GT(after, 0);
    ASSERT_NE(after, before);
    const PixelWeights& mu = state.weights(state.grid_index(f.width() / 2, 200));
    double expect[3] = {0, 0, 0};
    for (int j = 0; j < 3; ++j)
        for (int q = 0; q < 3; ++q) expect[q] += mu.weight(j) * cluster_color(j)[q];
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(out.rgb[3 * centre + q], expect[q], 1.0);
    EXPECT_NEAR(mu.weight(before - 1), 0.5, 1e-4);
    EXPECT_NEAR(mu.weight(after - 1), 0.5, 1e-4);

    // Pixels with no point show the scene's own colour as dim grey, not a cluster colour.
    f.color.rgb.assign(f.color.rgb.size(), 200);
    render_weight_colors(state, labels, f, out);
    ASSERT_EQ(labels.labels[0], 0);  // top-left: no table, no box
    EXPECT_EQ(out.rgb[0], static_cast<std::uint8_t>(200 * 0.35f));
}
