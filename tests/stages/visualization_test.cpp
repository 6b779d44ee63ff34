#include "wul3d/visualization.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <set>
#include <utility>

#include "synthetic_scene.hpp"
#include "wul3d/background.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/error.hpp"
#include "wul3d/normals.hpp"
#include "wul3d/objects.hpp"

using namespace wul3d;
using namespace wul3d::test;

TEST(ClusterColor, DistinctForManyClusters) {
    std::set<std::array<std::uint8_t, 3>> seen;
    for (int j = 0; j < 100; ++j) seen.insert(cluster_color(j));
    EXPECT_EQ(seen.size(), 100u);
    EXPECT_EQ(cluster_color(3), cluster_color(3));  // fixed
}

namespace {

/// One box of side `size` at 0.9 m on the synthetic scene and the paper's clustering of k
/// clusters at `stride` over it: each step renders the scene, clusters it and renders the
/// eq. 9 colours into `out`.
struct WeightColourScene {
    Scene scene;
    ClusterState state;
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;
    LabelImage labels;
    ColorImage out;

    static ClusterParams params(int k, int stride) {
        ClusterParams p = ClusterParams::paper();
        p.k = k;
        p.stride = stride;
        return p;
    }
    WeightColourScene(float size, int k, int stride) : state(params(k, stride)) {
        SceneBox b;
        b.z = 0.9f;
        b.w = b.h = b.d = size;
        scene.boxes = {b};
    }
    RgbdFrame step(std::vector<int>* truth = nullptr) {
        RgbdFrame f = render_scene(scene, truth);
        back_project(f, cloud);
        estimate_normals(NormalParams{}, cloud, normals);
        select_depth_range(DepthRange{}, cloud, active);
        state.step(cloud, normals, active, labels);
        render_weight_colors(state, labels, f, out);
        return f;
    }
    /// Eq. (9) at pixel (u, v) from its grid point's weights, in double.
    std::array<double, 3> expected(int u, int v) const {
        const PixelWeights& mu = state.weights(state.grid_index(u, v));
        std::array<double, 3> c{};
        for (int j = 0; j < state.params().k; ++j)
            for (int q = 0; q < 3; ++q) c[static_cast<std::size_t>(q)] += mu.weight(j) * cluster_color(j)[q];
        return c;
    }
};

}  // namespace

TEST(RenderWeightColors, IsEquation9) {
    // Two frames: a box present, then gone. With psi = 1, its former pixels hold half the
    // box cluster's weight and half the new winner's: their colour is the average (eq. 9).
    WeightColourScene w(0.3f, 3, 1);
    std::vector<int> truth;
    RgbdFrame f = w.step(&truth);
    const std::size_t centre = static_cast<std::size_t>(200) * f.width() + f.width() / 2;
    ASSERT_EQ(truth[centre], kTruthBox0);
    const int before = w.labels.labels[centre];
    ASSERT_GT(before, 0);
    for (int q = 0; q < 3; ++q) EXPECT_EQ(w.out.rgb[3 * centre + q], cluster_color(before - 1)[q]);

    w.scene.boxes.clear();
    f = w.step();
    const int after = w.labels.labels[centre];
    ASSERT_GT(after, 0);
    ASSERT_NE(after, before);
    const std::array<double, 3> expect = w.expected(f.width() / 2, 200);
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(w.out.rgb[3 * centre + q], expect[static_cast<std::size_t>(q)], 1.0);
    const PixelWeights& mu = w.state.weights(w.state.grid_index(f.width() / 2, 200));
    EXPECT_NEAR(mu.weight(before - 1), 0.5, 1e-4);
    EXPECT_NEAR(mu.weight(after - 1), 0.5, 1e-4);

    // Pixels with no point show the scene's own colour as dim grey, not a cluster colour.
    f.color.rgb.assign(f.color.rgb.size(), 200);
    render_weight_colors(w.state, w.labels, f, w.out);
    ASSERT_EQ(w.labels.labels[0], 0);  // top-left: no table, no box
    EXPECT_EQ(w.out.rgb[0], static_cast<std::uint8_t>(200 * 0.35f));
}

// With a sampling stride, every pixel with a label takes the eq. 9 colour of its grid
// point's weights (u / s, v / s): along whole rows, the last cut short (a width that is
// not a multiple of s).
TEST(RenderWeightColors, AtAStrideEachPixelTakesItsGridPointsColour) {
    WeightColourScene w(0.25f, 4, 3);
    for (const float x : {0.05f, -0.05f}) {  // two frames: weights shared between clusters
        w.scene.boxes[0].x = x;
        w.step();
    }
    const int W = w.labels.width, H = w.labels.height;
    ASSERT_NE(W % 3, 0);
    std::size_t checked = 0;
    for (int v : {H / 3, H / 2, H - 1})
        for (int u = 0; u < W; ++u) {
            const std::size_t q = static_cast<std::size_t>(v) * W + u;
            if (w.labels.labels[q] == 0) continue;
            const std::array<double, 3> expect = w.expected(u, v);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(w.out.rgb[3 * q + c], expect[static_cast<std::size_t>(c)], 1.0) << u << ", " << v;
            ++checked;
        }
    EXPECT_GT(checked, 200u);
}

// ---- render_object_overlay ------------------------------------------------------------

namespace {

/// A 120 x 90 grey picture with object 3 on u 20..59, v 30..69 and object 7 on u 80..99,
/// v 10..29; each object's 2D box is its rectangle.
struct OverlayScene {
    ColorImage base;
    LabelImage objects;
    std::vector<DetectedObject> list;
    PinholeIntrinsics K;
    OverlayScene() {
        base.width = objects.width = K.width = 120;
        base.height = objects.height = K.height = 90;
        base.rgb.assign(120 * 90 * 3, 100);
        objects.labels.assign(120 * 90, 0);
        K.fx = K.fy = 100;
        K.cx = 60;
        K.cy = 45;
        add(3, 20, 30, 59, 69);
        add(7, 80, 10, 99, 29);
    }
    void add(int id, int u0, int v0, int u1, int v1) {
        for (int v = v0; v <= v1; ++v)
            for (int u = u0; u <= u1; ++u) objects.labels[static_cast<std::size_t>(v) * 120 + u] =
                static_cast<std::uint16_t>(id);
        DetectedObject d;
        d.id = d.track_id = id;
        d.u_min = u0;
        d.v_min = v0;
        d.u_max = u1;
        d.v_max = v1;
        list.push_back(d);
    }
    static const std::uint8_t* at(const ColorImage& im, int u, int v) {
        return &im.rgb[3 * (static_cast<std::size_t>(v) * im.width + u)];
    }
};

}  // namespace

TEST(ObjectColor, StablePerIdAndDistinct) {
    std::set<std::array<std::uint8_t, 3>> seen;
    for (int id = 1; id <= 60; ++id) seen.insert(object_color(id));
    EXPECT_EQ(seen.size(), 60u);
    EXPECT_EQ(object_color(5), object_color(5));
    // Ids next to each other differ clearly (at least 60 apart on some channel).
    for (int id = 1; id < 60; ++id) {
        const auto a = object_color(id), b = object_color(id + 1);
        int most = 0;
        for (int q = 0; q < 3; ++q) most = std::max(most, std::abs(a[q] - b[q]));
        EXPECT_GE(most, 60) << id;
    }
}

TEST(RenderObjectOverlay, TintsObjectsOutlinesThemAndLeavesTheRest) {
    OverlayScene s;
    ColorImage out;
    OverlayStyle style;
    style.ids = false;
    render_object_overlay(s.base, s.objects, s.list, s.K, out, style);
    ASSERT_EQ(out.width, 120);
    ASSERT_EQ(out.height, 90);
    // Inside object 3: 45 % grey 100 and 55 % its colour.
    const auto c3 = object_color(3);
    for (const auto& [u, v] : {std::pair{40, 50}, std::pair{21, 31}, std::pair{58, 68}})
        for (int q = 0; q < 3; ++q)
            EXPECT_NEAR(OverlayScene::at(out, u, v)[q], 0.45 * 100 + 0.55 * c3[q], 1.0) << u << "," << v;
    // Its border pixels white, all the way round.
    int white = 0;
    for (int v = 30; v <= 69; ++v)
        for (int u = 20; u <= 59; ++u) {
            const bool border = u == 20 || u == 59 || v == 30 || v == 69;
            const std::uint8_t* o = OverlayScene::at(out, u, v);
            const bool is_white = o[0] == 255 && o[1] == 255 && o[2] == 255;
            if (border) {
                white += is_white;
            } else {
                EXPECT_FALSE(is_white) << u << "," << v;
            }
        }
    EXPECT_EQ(white, 4 * 40 - 4);
    // Object 7 in its own colour; no object: the picture unchanged.
    const auto c7 = object_color(7);
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(OverlayScene::at(out, 90, 20)[q], 0.45 * 100 + 0.55 * c7[q], 1.0);
    for (int v = 0; v < 90; ++v)
        for (int u = 0; u < 120; ++u)
            if (s.objects.labels[static_cast<std::size_t>(v) * 120 + u] == 0) {
                ASSERT_EQ(OverlayScene::at(out, u, v)[0], 100) << u << "," << v;
            }
}

TEST(RenderObjectOverlay, IdsAreDrawnAtEachObjectsBox) {
    OverlayScene s;
    ColorImage plain, with_ids, other_id;
    OverlayStyle style;
    style.ids = false;
    render_object_overlay(s.base, s.objects, s.list, s.K, plain, style);
    render_object_overlay(s.base, s.objects, s.list, s.K, with_ids);
    // What the ids changed lies at the top-left corners of the two boxes, and holds white
    // text on each.
    int changed_near[2] = {0, 0}, white_near[2] = {0, 0};
    for (int v = 0; v < 90; ++v)
        for (int u = 0; u < 120; ++u) {
            const std::uint8_t* a = OverlayScene::at(plain, u, v);
            const std::uint8_t* b = OverlayScene::at(with_ids, u, v);
            if (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) continue;
            const int near = (u >= 20 && u < 50 && v >= 30 && v < 60)   ? 0
                             : (u >= 80 && u < 110 && v >= 10 && v < 40) ? 1
                                                                          : -1;
            ASSERT_NE(near, -1) << "changed far from both boxes at " << u << "," << v;
            ++changed_near[near];
            white_near[near] += b[0] > 200 && b[1] > 200 && b[2] > 200;
        }
    for (int i = 0; i < 2; ++i) {
        EXPECT_GT(changed_near[i], 40) << i;
        EXPECT_GT(white_near[i], 5) << i;
    }
    // The digits themselves: id 3 drawn as 8 looks different.
    s.list[0].id = 8;
    render_object_overlay(s.base, s.objects, s.list, s.K, other_id);
    int differ = 0;
    for (int v = 30; v < 60; ++v)
        for (int u = 20; u < 50; ++u) differ += OverlayScene::at(other_id, u, v)[0] != OverlayScene::at(with_ids, u, v)[0];
    EXPECT_GT(differ, 5);
}

TEST(RenderObjectOverlay, BoxesAreTheProjectedOrientedBox) {
    OverlayScene s;
    // A 20 cm cube 1 m in front of the camera, axes along the camera's: its near face
    // (z = 0.9 m) spans u, v = centre -+ 100 * 0.1 / 0.9 = 11.1 px.
    DetectedObject& d = s.list[0];
    d.obb_centre = {0, 0, 1};
    d.obb_axes = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    d.obb_half_extent = {0.1f, 0.1f, 0.1f};
    s.list.resize(1);
    for (auto& l : s.objects.labels) l = 0;
    ColorImage out;
    OverlayStyle style;
    style.ids = false;
    style.boxes = true;
    render_object_overlay(s.base, s.objects, s.list, s.K, out, style);
    const auto c = object_color(3);
    auto box_coloured = [&](int u, int v) {
        const std::uint8_t* o = OverlayScene::at(out, u, v);
        return std::abs(o[0] - c[0]) + std::abs(o[1] - c[1]) + std::abs(o[2] - c[2]) < 90;
    };
    // The near face's top and left edges, the far face's (9.1 px) top edge, the centre empty.
    EXPECT_TRUE(box_coloured(60, 34));
    EXPECT_TRUE(box_coloured(49, 45));
    EXPECT_TRUE(box_coloured(60, 36));
    EXPECT_FALSE(box_coloured(60, 45));
    EXPECT_EQ(OverlayScene::at(out, 60, 45)[0], 100);
    EXPECT_EQ(OverlayScene::at(out, 5, 5)[0], 100);
}

TEST(RenderObjectOverlay, SelectedObjectKeepsItsTintTheRestDarkened) {
    OverlayScene s;
    ColorImage out;
    OverlayStyle style;
    style.ids = false;
    style.selected = 7;
    render_object_overlay(s.base, s.objects, s.list, s.K, out, style);
    EXPECT_EQ(OverlayScene::at(out, 5, 5)[0], 25);     // background: a quarter
    EXPECT_EQ(OverlayScene::at(out, 40, 50)[0], 25);   // object 3, not selected: no tint
    const auto c7 = object_color(7);
    EXPECT_NEAR(OverlayScene::at(out, 90, 20)[1], 0.45 * 100 + 0.55 * c7[1], 1.0);
}

TEST(RenderObjectOverlay, SizesThatDiffer_ParamError) {
    OverlayScene s;
    ColorImage out;
    s.objects.width = 60;
    s.objects.labels.resize(60 * 90);
    EXPECT_THROW(render_object_overlay(s.base, s.objects, s.list, s.K, out), ParamError);
    OverlayScene t;
    OverlayStyle style;
    style.tint = 1.5f;
    EXPECT_THROW(render_object_overlay(t.base, t.objects, t.list, t.K, out, style), ParamError);
}
