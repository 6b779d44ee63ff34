#include "wul3d/objects.hpp"

#include <gtest/gtest.h>

#include "synthetic_scene.hpp"
#include "wul3d/background.hpp"
#include "wul3d/error.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {
Scene scene_with_box_at(float x) {
    Scene s;
    SceneBox red;
    red.x = x;
    red.z = 1.1f;
    SceneBox blue;
    blue.x = 0.45f;
    blue.z = 1.3f;
    blue.r = 30;
    blue.g = 60;
    blue.b = 220;
    s.boxes = {red, blue};
    return s;
}

// Pixel of the centre of the front face of the red box.
void box_pixel(const Scene& s, int& u, int& v) {
    const auto K = scene_intrinsics(s.width, s.height);
    const SceneBox& b = s.boxes[0];
    const double z = b.z - b.d / 2, y = s.table_y - b.h / 2;
    u = static_cast<int>(K.fx * b.x / z + K.cx);
    v = static_cast<int>(K.fy * y / z + K.cy);
}
}  // namespace

TEST(SelectedObject, FollowsAMovingObject) {
    ClusterState state(ClusterParams::paper());
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active, mask;
    LabelImage labels;
    int u0 = 0, v0 = 0;
    box_pixel(scene_with_box_at(-0.4f), u0, v0);
    SelectedObject selected(u0, v0);
    for (int frame = 0; frame < 12; ++frame) {
        const Scene s = scene_with_box_at(-0.4f + 0.04f * static_cast<float>(frame));
        std::vector<int> truth;
        const RgbdFrame f = render_scene(s, &truth);
        back_project(f, cloud);
        estimate_normals(NormalParams{}, cloud, normals);
        select_depth_range(DepthRange{}, cloud, active);
        state.step(cloud, normals, active, labels);
        selected.update(labels, mask);
        // The mask is the red box: it covers most of the box and little else.
        std::size_t on_box = 0, in_mask = 0, box = 0;
        for (std::size_t p = 0; p < mask.size(); ++p) {
            box += truth[p] == kTruthBox0;
            if (!mask[p]) continue;
            ++in_mask;
            on_box += truth[p] == kTruthBox0;
        }
        ASSERT_GT(in_mask, 0u) << "frame " << frame;
        EXPECT_GE(static_cast<double>(on_box) / static_cast<double>(box), 0.9) << "frame " << frame;
        EXPECT_GE(static_cast<double>(on_box) / static_cast<double>(in_mask), 0.9) << "frame " << frame;
    }
}

TEST(SelectedObject, RejectsPixelsOutsideTheImageOrWithoutPoints) {
    LabelImage labels{10, 10, std::vector<std::uint16_t>(100, 0)};
    std::vector<std::uint8_t> mask;
    SelectedObject outside(20, 3);
    EXPECT_THROW(outside.update(labels, mask), InputError);
    SelectedObject empty(5, 5, 3);
    EXPECT_THROW(empty.update(labels, mask), InputError);
    labels.labels[7 * 10 + 7] = 4;  // within 3 px of (5, 5)
    SelectedObject near(5, 5, 3);
    near.update(labels, mask);
    EXPECT_EQ(near.cluster(), 4);
    EXPECT_EQ(mask[7 * 10 + 7], 255);
    EXPECT_EQ(near.pixels(), 1u);
}
