#include "wul3d/decimation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>

#include <omp.h>

#include "stages/decimated_source.hpp"
#include "synthetic_scene.hpp"
#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/eval.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {
// A 5 x 3 frame (odd sizes: the last block column is partial), depth = 100 + p and colour
// (p, 2p, 3p) at pixel p, with holes where `holes` says.
RgbdFrame small_frame(const std::vector<int>& holes) {
    RgbdFrame f;
    f.name = "small";
    f.intrinsics = PinholeIntrinsics{5, 3, 500.0, 400.0, 2.0, 1.0};
    f.depth.width = 5;
    f.depth.height = 3;
    f.color.width = 5;
    f.color.height = 3;
    for (int p = 0; p < 15; ++p) {
        f.depth.data.push_back(static_cast<std::uint16_t>(100 + p));
        for (int c = 1; c <= 3; ++c) f.color.rgb.push_back(static_cast<std::uint8_t>(c * p));
    }
    for (int p : holes) f.depth.data[static_cast<std::size_t>(p)] = 0;
    return f;
}

DepthImage depth_image(int width, int height, std::vector<std::uint16_t> data) {
    DepthImage d;
    d.width = width;
    d.height = height;
    d.data = std::move(data);
    return d;
}
}  // namespace

TEST(DecimateFrame, EachBlockTakesItsFirstPixelWithDepthAndThatPixelsColour) {
    // Blocks of 2 x 2 over 5 x 3: (0,1,5,6) (2,3,7,8) (4,9) / (10,11) (12,13) (14).
    const RgbdFrame f = small_frame({0, 2, 3, 7, 12, 13});
    RgbdFrame d;
    decimate_frame(f, 2, d);
    ASSERT_EQ(d.width(), 3);
    ASSERT_EQ(d.height(), 2);
    ASSERT_EQ(d.color.width, 3);
    // Block 0: pixel 0 has no depth, 1 has; block 1: 2, 3, 7 none, 8 has; block 4: none.
    const std::vector<int> picked = {1, 8, 4, 10, -1, 14};
    for (std::size_t o = 0; o < picked.size(); ++o) {
        SCOPED_TRACE(o);
        if (picked[o] < 0) {
            EXPECT_EQ(d.depth.data[o], 0);
            EXPECT_EQ(d.color.rgb[3 * o], 12);  // the top-left pixel's colour
            continue;
        }
        EXPECT_EQ(d.depth.data[o], 100 + picked[o]);
        EXPECT_EQ(d.color.rgb[3 * o + 1], 2 * picked[o]);
    }
    // Intrinsics of the top-left samples: u_in = N u.
    EXPECT_DOUBLE_EQ(d.intrinsics.fx, 250.0);
    EXPECT_DOUBLE_EQ(d.intrinsics.fy, 200.0);
    EXPECT_DOUBLE_EQ(d.intrinsics.cx, 1.0);
    EXPECT_DOUBLE_EQ(d.intrinsics.cy, 0.5);
    EXPECT_EQ(d.intrinsics.width, 3);
    EXPECT_EQ(d.depth.scale_m_per_unit, f.depth.scale_m_per_unit);

    RgbdFrame same;
    decimate_frame(f, 1, same);
    EXPECT_EQ(same.depth.data, f.depth.data);
    EXPECT_EQ(same.color.rgb, f.color.rgb);
}

// With the depth range, a block takes its first pixel in range, so that a pixel in range
// always has a block in range (the coverage rule at --decimate N); a block with none in range
// keeps its first pixel with depth.
TEST(DecimateFrame, WithTheDepthRangeEachBlockTakesItsFirstPixelInRange) {
    const RgbdFrame f = small_frame({0});
    DepthRange range;
    range.zmin_m = 103.5f * f.depth.scale_m_per_unit;  // pixels 104 and up are in range
    range.zmax_m = 1000.0f;
    RgbdFrame d;
    decimate_frame(f, 2, d, &range);
    // Blocks (0,1,5,6) (2,3,7,8) (4,9) / (10,11) (12,13) (14): block 0's 1 is out of range,
    // 5 in; block 1's 2 and 3 out, 7 in; the rest start in range.
    const std::vector<int> picked = {5, 7, 4, 10, 12, 14};
    for (std::size_t o = 0; o < picked.size(); ++o) {
        SCOPED_TRACE(o);
        EXPECT_EQ(d.depth.data[o], 100 + picked[o]);
        EXPECT_EQ(d.color.rgb[3 * o + 1], 2 * picked[o]);
    }
    range.zmin_m = 200.0f * f.depth.scale_m_per_unit;  // none in range: first with depth
    decimate_frame(f, 2, d, &range);
    EXPECT_EQ(d.depth.data[0], 101);
    EXPECT_EQ(d.depth.data[1], 102);
}

// The rule on wide random rows (a block row longer than the pass's chunks, a last block cut
// by the width): holes, depths out of the range, every factor.
TEST(DecimateFrame, WideRowsTakeEachBlocksFirstPixelInRange) {
    std::mt19937 rng(5);
    const int W = 1103, H = 7;
    RgbdFrame f;
    f.intrinsics = PinholeIntrinsics{W, H, 500.0, 500.0, W / 2.0, H / 2.0};
    f.depth.width = f.color.width = W;
    f.depth.height = f.color.height = H;
    f.depth.scale_m_per_unit = 0.001f;
    f.depth.data.resize(static_cast<std::size_t>(W) * H);
    for (auto& z : f.depth.data) {
        const int kind = std::uniform_int_distribution<int>(0, 9)(rng);
        z = static_cast<std::uint16_t>(kind == 0 ? 0 : kind == 1 ? 100 : std::uniform_int_distribution<int>(500, 3000)(rng));
    }
    f.color.rgb.resize(3 * f.depth.data.size());
    for (auto& c : f.color.rgb) c = static_cast<std::uint8_t>(std::uniform_int_distribution<int>(0, 255)(rng));
    DepthRange range;  // 0.2-4.5 m: the 0.1 m depths are out
    for (int factor : {2, 3, 8}) {
        SCOPED_TRACE(factor);
        RgbdFrame d;
        decimate_frame(f, factor, d, &range);
        const int w = d.width(), h = d.height();
        for (int bv = 0; bv < h; ++bv)
            for (int bu = 0; bu < w; ++bu) {
                std::size_t pick = static_cast<std::size_t>(bv) * factor * W + static_cast<std::size_t>(bu) * factor;
                bool found_in = false, found_any = false;
                for (int v = bv * factor; v < std::min(H, (bv + 1) * factor) && !found_in; ++v)
                    for (int u = bu * factor; u < std::min(W, (bu + 1) * factor) && !found_in; ++u) {
                        const std::size_t q = static_cast<std::size_t>(v) * W + u;
                        const std::uint16_t z = f.depth.data[q];
                        if (z == 0) continue;
                        found_in = range.contains(static_cast<float>(z) * 0.001f);
                        if (found_in || !found_any) pick = q;
                        found_any = true;
                    }
                const std::size_t o = static_cast<std::size_t>(bv) * w + bu;
                ASSERT_EQ(d.depth.data[o], f.depth.data[pick]) << bu << ", " << bv;
                for (int c = 0; c < 3; ++c) ASSERT_EQ(d.color.rgb[3 * o + c], f.color.rgb[3 * pick + c]) << bu << ", " << bv;
            }
    }
}

TEST(DecimateFrame, RejectsBadFactorsAndMismatchedColour) {
    RgbdFrame f = small_frame({}), d;
    EXPECT_THROW(decimate_frame(f, 0, d), ParamError);
    EXPECT_THROW(decimate_frame(f, 9, d), ParamError);
    f.color.width = 4;
    EXPECT_THROW(decimate_frame(f, 2, d), InputError);
    f.color = ColorImage{};  // depth-only frames decimate too
    decimate_frame(f, 2, d);
    EXPECT_FALSE(d.has_color());
    EXPECT_EQ(d.depth.data.size(), 6u);
}

TEST(DecimatedSource, OwnBlockOnTheSameSurfaceElseTheNearestNeighbourInDepth) {
    // Input 4 x 2 (two blocks): a near surface (1000 mm) on the left, far (2000) on the right,
    // with pixel (2, 0) near although its block was sampled far.
    const DepthImage in = depth_image(4, 2, {1000, 1001, 1002, 2000, 1000, 0, 2000, 2001});
    // Block 1's first pixel with depth would be 1002: made far here.
    DepthImage small = depth_image(2, 1, {1000, 2000});
    const DecimatedSource source(in, small, 2, 0.004f, 0.0f);
    EXPECT_EQ(source(0, 0), 0);
    EXPECT_EQ(source(1, 0), 0);   // 1 mm off: the same surface
    EXPECT_EQ(source(2, 0), 0);   // near pixel in the far block: the near neighbour
    EXPECT_EQ(source(3, 0), 1);
    EXPECT_EQ(source(1, 1), -1);  // no depth
    EXPECT_EQ(source(3, 1), 1);
    EXPECT_EQ(source.in_block(2, 0, 1, 0), source(2, 0));
    // No neighbouring block with depth: none.
    small.data = {0, 0};
    EXPECT_EQ(DecimatedSource(in, small, 2, 0.004f, 0.0f)(0, 0), -1);
    // A decimated image of the wrong size is an input error.
    small.width = 3;
    small.data = {1, 2, 3};
    EXPECT_THROW(DecimatedSource(in, small, 2, 0.004f, 0.0f), InputError);
}

TEST(DecimatedSource, AtEdgeBlocksTheColourPlacesTheOutline) {
    // One flat surface, 4 x 2 input: red at u = 0, blue at u = 1..3. Block 0 was sampled red
    // at (0, 0), block 1 blue at (2, 0); pixel (1, 0) is blue but lies in block 0.
    const DepthImage in = depth_image(4, 2, std::vector<std::uint16_t>(8, 1000));
    ColorImage rgb;
    rgb.width = 4;
    rgb.height = 2;
    for (int p = 0; p < 8; ++p) {
        const bool red = p % 4 == 0;
        rgb.rgb.insert(rgb.rgb.end(), {std::uint8_t(red ? 200 : 10), 10, std::uint8_t(red ? 10 : 200)});
    }
    RgbdFrame f;
    f.depth = in;
    f.color = rgb;
    f.intrinsics = PinholeIntrinsics{4, 2, 100.0, 100.0, 2.0, 1.0};
    RgbdFrame small;
    decimate_frame(f, 2, small);
    DecimatedSource source(in, small.depth, 2, 0.004f, 0.0f);
    EXPECT_EQ(source(1, 0), 0);  // depth alone: its own block
    const std::vector<std::uint8_t> edges = {1, 1}, no_edges = {0, 0};
    const std::vector<std::uint16_t> labels = {1, 2};
    VoteBuffers voted;
    source.use_colour_at_edges(rgb, small.color, edges.data(), labels.data(), voted);
    EXPECT_EQ(source(1, 0), 1);  // the blue block beside it
    EXPECT_EQ(source(0, 0), 0);
    EXPECT_EQ(source(3, 1), 1);
    source.use_colour_at_edges(rgb, small.color, no_edges.data(), labels.data(), voted);
    EXPECT_EQ(source(1, 0), 0);  // not an edge block: its own
    // The colour never overrides the surface: the blue block 6 cm farther is not taken.
    const DepthImage stepped = depth_image(4, 2, {1000, 1000, 1060, 1060, 1000, 1000, 1060, 1060});
    RgbdFrame g = f;
    g.depth = stepped;
    decimate_frame(g, 2, small);
    DecimatedSource on_surface(stepped, small.depth, 2, 0.004f, 0.0f);
    on_surface.use_colour_at_edges(rgb, small.color, edges.data(), labels.data(), voted);
    EXPECT_EQ(on_surface(1, 0), 0);
    // Colour of another size: an input error; no colour: depth decides alone.
    ColorImage wrong = rgb;
    wrong.width = 3;
    EXPECT_THROW(on_surface.use_colour_at_edges(wrong, small.color, edges.data(), labels.data(), voted), InputError);
    wrong = rgb;
    wrong.height = 1;
    wrong.rgb.resize(12);
    EXPECT_THROW(on_surface.use_colour_at_edges(wrong, small.color, edges.data(), labels.data(), voted), InputError);
    DecimatedSource depth_only(in, small.depth, 2, 0.004f, 0.0f);
    depth_only.use_colour_at_edges(ColorImage{}, ColorImage{}, edges.data(), labels.data(), voted);
    EXPECT_EQ(depth_only(1, 0), 0);
}

TEST(DecimatedSource, TheColourVoteGivesANotchInTheOutlineBackToItsColour) {
    // One flat surface, 16 x 16 input, 8 x 8 blocks: red left of u = 8 (block columns 0-3),
    // blue right of it. The decimated stages labelled the red blocks 1 and the blue ones 2,
    // but for a notch: block (3, 4), red, went to label 2.
    const int W = 16, w = 8;
    const DepthImage flat = depth_image(W, W, std::vector<std::uint16_t>(W * W, 1000));
    ColorImage rgb;
    rgb.width = W;
    rgb.height = W;
    for (int p = 0; p < W * W; ++p) {
        const bool red = p % W < 8;
        rgb.rgb.insert(rgb.rgb.end(), {std::uint8_t(red ? 200 : 10), 10, std::uint8_t(red ? 10 : 200)});
    }
    RgbdFrame f;
    f.depth = flat;
    f.color = rgb;
    f.intrinsics = PinholeIntrinsics{W, W, 100.0, 100.0, 8.0, 8.0};
    RgbdFrame small;
    decimate_frame(f, 2, small);
    std::vector<std::uint16_t> labels(w * w);
    for (int q = 0; q < w * w; ++q) labels[static_cast<std::size_t>(q)] = q % w < 4 ? 1 : 2;
    const int notch = 4 * w + 3;
    labels[notch] = 2;
    const std::vector<std::uint8_t> edges(w * w, 1);  // every block votes
    VoteBuffers voted;
    DecimatedSource source(flat, small.depth, 2, 0.004f, 0.0f);
    source.use_colour_at_edges(rgb, small.color, edges.data(), labels.data(), voted);
    ASSERT_EQ(voted.block_source.size(), static_cast<std::size_t>(w * w));
    auto label_of = [&](int u, int v) { return labels[static_cast<std::size_t>(source(u, v))]; };
    // The notch's red blocks on the grid around it are label 1: its pixels go back to 1.
    EXPECT_EQ(labels[static_cast<std::size_t>(voted.block_source[notch])], 1);
    for (int v = 8; v < 10; ++v)
        for (int u = 6; u < 8; ++u) EXPECT_EQ(label_of(u, v), 1) << u << ", " << v;
    // Every other block keeps its own results, blue pixels label 2 and red ones label 1.
    for (int q = 0; q < w * w; ++q) {
        if (q != notch) {
            EXPECT_EQ(voted.block_source[static_cast<std::size_t>(q)], q);
        }
    }
    for (int v = 0; v < W; ++v)
        for (int u = 0; u < W; ++u) EXPECT_EQ(label_of(u, v), u < 8 ? 1 : 2) << u << ", " << v;

    // A block on another surface does not vote: with the red label-1 blocks 3 cm farther,
    // the notch hears only itself and the blue blocks, and stays label 2.
    std::vector<std::uint16_t> stepped(W * W, 1000);
    for (int p = 0; p < W * W; ++p) {
        const int u = p % W, v = p / W;
        if (u < 8 && !(u >= 6 && v >= 8 && v < 10)) stepped[static_cast<std::size_t>(p)] = 1030;
    }
    RgbdFrame g = f;
    g.depth = depth_image(W, W, stepped);
    decimate_frame(g, 2, small);
    DecimatedSource on_surface(g.depth, small.depth, 2, 0.004f, 0.0f);
    on_surface.use_colour_at_edges(rgb, small.color, edges.data(), labels.data(), voted);
    EXPECT_EQ(voted.block_source[notch], notch);
    EXPECT_EQ(labels[static_cast<std::size_t>(on_surface(6, 8))], 2);
}

// End to end at N = 2 on a synthetic tabletop whose answer is known, 640x480: three boxes
// of different colours, two of them flush side by side, and a cup. The outlines come back
// at the input's pixels within a pixel of the truth (boundary F at 1 px: 0.95; 0.86 with
// the colour vote turned off).
TEST(Pipeline, DecimateTwo_OutlinesWithinAPixelOfTheTruth) {
    Scene s = pitched_tabletop_scene();
    s.width = 640;
    s.height = 480;
    s.noise_seed = 7;
    // Red and blue flush side by side; a smaller green box and a cup nearer the camera.
    const SceneBox red{.x = -0.075f, .z = 1.0f};
    const SceneBox blue{.x = 0.075f, .z = 1.0f, .r = 30, .g = 60, .b = 200};
    const SceneBox green{.x = -0.25f, .z = 0.8f, .w = 0.1f, .h = 0.12f, .d = 0.1f, .r = 40, .g = 180, .b = 60};
    const SceneCup cup{.x = 0.22f, .z = 0.75f};
    s.boxes = {red, blue, green};
    s.cups = {cup};
    std::vector<int> truth;
    const RgbdFrame f = render_scene(s, &truth);
    LabelImage gt = blank_labels(s.width, s.height);
    for (std::size_t p = 0; p < truth.size(); ++p)
        gt.labels[p] = static_cast<std::uint16_t>(truth[p] >= kTruthBox0 ? truth[p] : 0);
    PipelineParams params;
    params.decimation = 2;
    Pipeline pipeline(params);
    const FrameResult& r = pipeline.process(f);
    EvalParams within_a_pixel;
    within_a_pixel.boundary_tolerance_px = 1;
    const ImageScore score = score_image(r.objects, gt, within_a_pixel);
    EXPECT_EQ(r.object_list.size(), 4u);
    EXPECT_GT(score.overlap_f, 0.97);
    EXPECT_GT(score.boundary_f, 0.90);
}

TEST(PipelineParams, DecimationScalesObjectSizesNotNeighbourhoods) {
    PipelineParams p;
    p.decimation = 2;
    const PipelineParams s = p.stage_params();
    EXPECT_EQ(s.segmentation.min_points, 75);
    EXPECT_EQ(s.segmentation.containers.gap_max_px, 125);
    EXPECT_EQ(s.segmentation.merge.min_boundary, 3);
    EXPECT_EQ(s.segmentation.containers.min_boundary, 5);
    EXPECT_EQ(s.objects.min_points, 25);
    EXPECT_EQ(s.plane.grid_stride_px, p.plane.grid_stride_px);
    EXPECT_EQ(s.plane.hull_margin_px, 6);
    EXPECT_EQ(s.normals.radius_px, p.normals.radius_px);
    EXPECT_EQ(s.segmentation.cuts.crease_step_px, p.segmentation.cuts.crease_step_px);
    EXPECT_EQ(s.segmentation.cuts.reattach_px, p.segmentation.cuts.reattach_px);
    EXPECT_EQ(s.segmentation.cuts.min_seed_points, p.segmentation.cuts.min_seed_points);
    p.segmentation.containers.gap_max_px = 0;  // off stays off
    EXPECT_EQ(p.stage_params().segmentation.containers.gap_max_px, 0);
    p.decimation = 1;
    EXPECT_EQ(p.stage_params().segmentation.min_points, p.segmentation.min_points);
    p.decimation = 9;
    EXPECT_THROW(p.validate(), ParamError);
}

namespace {
// Pixels of each object id, and whether each object's 2D box is the tight box of its pixels.
void expect_object_list_matches_image(const FrameResult& r) {
    std::map<int, std::size_t> count;
    std::map<int, std::array<int, 4>> box;
    for (int v = 0; v < r.objects.height; ++v)
        for (int u = 0; u < r.objects.width; ++u) {
            const int id = r.objects.labels[static_cast<std::size_t>(v) * r.objects.width + u];
            if (id == 0) continue;
            if (!count[id]++) box[id] = {u, v, u, v};
            auto& b = box[id];
            b = {std::min(b[0], u), std::min(b[1], v), std::max(b[2], u), std::max(b[3], v)};
        }
    ASSERT_EQ(count.size(), r.object_list.size());
    for (const DetectedObject& d : r.object_list) {
        SCOPED_TRACE(d.id);
        EXPECT_EQ(d.pixels, count[d.id]);
        EXPECT_EQ((std::array<int, 4>{d.u_min, d.v_min, d.u_max, d.v_max}), box[d.id]);
    }
}
}  // namespace

// A scene whose answer is known, at 640 x 480: with --decimate 2 every result comes back at
// the input's size, each box is one object, and objects.json's counts and boxes are those of
// objects.png.
TEST(Pipeline, Decimated_BoxesFoundAtTheInputsSize) {
    Scene s = pitched_tabletop_scene();
    s.width = 640;
    s.height = 480;
    s.noise_seed = 3;
    SceneBox red, blue, green;
    red.x = -0.3f;
    red.z = 0.9f;
    blue.x = 0.25f;
    blue.z = 1.2f;
    blue.r = 30; blue.g = 60; blue.b = 220;
    green.x = -0.05f;
    green.z = 1.4f;
    green.w = 0.08f;
    green.r = 40; green.g = 200; green.b = 60;
    s.boxes = {red, blue, green};
    std::vector<int> truth;
    const RgbdFrame f = render_scene(s, &truth);
    for (int n : {1, 2, 4}) {
        SCOPED_TRACE(n);
        PipelineParams p;
        p.decimation = n;
        Pipeline pipeline(p);
        const FrameResult& r = pipeline.process(f);
        ASSERT_EQ(r.objects.width, 640);
        ASSERT_EQ(r.objects.height, 480);
        ASSERT_EQ(r.labels.labels.size(), truth.size());
        ASSERT_EQ(r.colors.rgb.size(), 3 * truth.size());
        ASSERT_EQ(r.plane_classes.size(), truth.size());
        EXPECT_EQ(pipeline.cloud().width, (640 + n - 1) / n);
        if (n == 1) {
            EXPECT_EQ(r.times.decimation, 0.0);
        } else {
            EXPECT_GT(r.times.decimation, 0.0);
        }
        EXPECT_TRUE(r.plane.found);
        EXPECT_EQ(r.object_list.size(), 3u);
        std::set<int> ids;
        for (int b = 0; b < 3; ++b) {
            int id = 0;
            // Edge pixels of a box may take the table's block: a pixel's worth at N = 4.
            EXPECT_GE(dominant_share(r.objects.labels, truth, kTruthBox0 + b, &id), n < 4 ? 0.95 : 0.9) << b;
            EXPECT_NE(id, 0);
            ids.insert(id);
        }
        EXPECT_EQ(ids.size(), 3u);
        // Pixels without depth have no result.
        for (std::size_t q = 0; q < truth.size(); ++q) {
            if (f.depth.data[q] != 0) continue;
            ASSERT_EQ(r.labels.labels[q] | r.objects.labels[q], 0);
        }
        expect_object_list_matches_image(r);
    }
}

// Real shipped frames: with --decimate 2 the support is the same plane as at full resolution
// (in image_0005 a sliver of the floor took it before slivers were left unscored, see
// plane_test), most objects of the full-resolution run larger than 3000 px are found
// again, overlapping by at least 75 % (intersection over union), and exactly the pixels in
// the depth range have a point and a label, as at full resolution (in image_0007, where the
// room reaches past 4.5 m, 337 pixels were on the wrong side of the limit while each pixel
// took its block's side).
TEST(Pipeline, Decimated_RealTabletopObjectsMatchFullResolution) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    PipelineParams full_params, half_params;
    full_params.decimation = 1;
    half_params.decimation = 2;
    Pipeline full(full_params), half(half_params);
    SourceItem item;
    int compared = 0, matched = 0;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        SCOPED_TRACE(item.frame.name);
        const FrameResult& a = full.process(item.frame);
        const std::vector<std::uint16_t> full_objects = a.objects.labels;
        const std::vector<DetectedObject> full_list = a.object_list;
        const Plane full_support = a.plane.support;
        const std::vector<std::uint8_t> full_active = a.active;
        const FrameResult& b = half.process(item.frame);
        expect_object_list_matches_image(b);
        std::size_t active_differs = 0, label_differs = 0;
        for (std::size_t p = 0; p < full_active.size(); ++p) {
            active_differs += b.active[p] != full_active[p];
            label_differs += (b.labels.labels[p] != 0) != (full_active[p] != 0);
        }
        EXPECT_EQ(active_differs, 0u);
        EXPECT_EQ(label_differs, 0u);
        EXPECT_EQ(b.active_points, a.active_points);
        ASSERT_TRUE(b.plane.found);
        const Plane& s = b.plane.support;
        EXPECT_GT(s.nx * full_support.nx + s.ny * full_support.ny + s.nz * full_support.nz,
                  std::cos(2.0 * 3.14159265 / 180));
        EXPECT_NEAR(s.d, full_support.d, 0.01);
        for (const DetectedObject& d : full_list) {
            if (d.pixels < 3000) continue;
            std::map<int, std::size_t> overlap;
            for (std::size_t p = 0; p < full_objects.size(); ++p)
                if (full_objects[p] == d.id && b.objects.labels[p] != 0) ++overlap[b.objects.labels[p]];
            double best = 0;
            for (const auto& [id, inter] : overlap) {
                const auto it = std::find_if(b.object_list.begin(), b.object_list.end(),
                                             [id = id](const DetectedObject& o) { return o.id == id; });
                ASSERT_NE(it, b.object_list.end());
                best = std::max(best, static_cast<double>(inter) /
                                          static_cast<double>(d.pixels + it->pixels - inter));
            }
            ++compared;
            matched += best >= 0.75;
        }
    }
    // 17 of 19 when written: the box at the back of image_0002 is lost in the decimated run.
    // 16 of 20 since the colour cue also splits across folds (issue 20): at every pixel it
    // cuts the container of image_0005 into lid and tray, at N = 2 it does not, and splits
    // image_0002's spray bottle at both: 20 objects compared, 16 matched.
    EXPECT_GE(compared, 17);
    EXPECT_GE(matched, compared * 80 / 100) << matched << " of " << compared;
}

namespace {

// expand_result's inputs on a random frame with edges: an input of W x H pixels made of
// rectangles at different depths (some without depth, some past the range) with noise in
// depth and colour, decimated by `factor`, and stage results of random rectangles of labels,
// segments and objects (a few object ids, one of them missing from the list, one small) on
// the decimated grid.
struct RandomExpand {
    RgbdFrame frame, decimated;
    FrameResult small;
    ExpandParams params;
};

RandomExpand random_expand(unsigned seed, int W, int H, int factor, bool objects, bool colour) {
    std::mt19937 rng(seed);
    auto uniform = [&rng](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    RandomExpand e;
    RgbdFrame& f = e.frame;
    f.name = "random";
    f.intrinsics = PinholeIntrinsics{W, H, 500.0, 500.0, W / 2.0, H / 2.0};
    f.depth.width = W;
    f.depth.height = H;
    f.depth.scale_m_per_unit = 0.001f;
    f.depth.data.assign(static_cast<std::size_t>(W) * H, 1500);
    if (colour) {
        f.color.width = W;
        f.color.height = H;
        f.color.rgb.resize(3 * f.depth.data.size());
        for (auto& c : f.color.rgb) c = static_cast<std::uint8_t>(uniform(100, 140));
    }
    for (int r = 0; r < 12; ++r) {  // rectangles of depth (0: none; 6000: past the range)
        const int u0 = uniform(0, W - 1), v0 = uniform(0, H - 1), u1 = uniform(u0, W - 1), v1 = uniform(v0, H - 1);
        const int kind = uniform(0, 5);
        const int z = kind == 0 ? 0 : kind == 1 ? 6000 : uniform(400, 3000);
        const std::array<int, 3> rgb{uniform(0, 255), uniform(0, 255), uniform(0, 255)};
        for (int v = v0; v <= v1; ++v)
            for (int u = u0; u <= u1; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                f.depth.data[p] = static_cast<std::uint16_t>(z == 0 || z == 6000 ? z : z + uniform(-6, 6));
                if (colour)
                    for (int c = 0; c < 3; ++c)
                        f.color.rgb[3 * p + c] = static_cast<std::uint8_t>(std::clamp(rgb[c] + uniform(-30, 30), 0, 255));
            }
    }
    for (int k = 0; k < W * H / 50; ++k)  // scattered holes
        f.depth.data[static_cast<std::size_t>(uniform(0, W * H - 1))] = 0;
    e.params.factor = factor;
    e.params.same_m = static_cast<float>(factor) * 0.02f;
    e.params.same_rel = static_cast<float>(factor) * 0.01f;
    e.params.objects = objects;
    e.params.min_object_pixels = 40;
    decimate_frame(f, factor, e.decimated, &e.params.range);

    const int w = e.decimated.width(), h = e.decimated.height();
    const std::size_t n = static_cast<std::size_t>(w) * h;
    FrameResult& s = e.small;
    auto label_image = [&](int ww, int hh) {
        LabelImage l;
        l.width = ww;
        l.height = hh;
        l.labels.assign(static_cast<std::size_t>(ww) * hh, 0);
        return l;
    };
    s.labels = label_image(w, h);
    s.colors.width = w;
    s.colors.height = h;
    s.colors.rgb.resize(3 * n);
    for (auto& c : s.colors.rgb) c = static_cast<std::uint8_t>(uniform(0, 255));
    s.active.resize(n);
    for (std::size_t q = 0; q < n; ++q) {
        const float z = static_cast<float>(e.decimated.depth.data[q]) * 0.001f;
        // Mostly the depth range, with a few blocks off (as the plane or a stage may leave).
        s.active[q] = e.decimated.depth.data[q] != 0 && e.params.range.contains(z) && uniform(0, 19) != 0;
    }
    if (objects) {
        s.segments = label_image(w, h);
        s.objects = label_image(w, h);
        s.plane_classes.resize(n);
        for (auto& c : s.plane_classes) c = static_cast<std::uint8_t>(uniform(0, 3));
    }
    for (int r = 0; r < 10; ++r) {  // rectangles of labels, segments and objects
        const int u0 = uniform(0, w - 1), v0 = uniform(0, h - 1), u1 = uniform(u0, w - 1), v1 = uniform(v0, h - 1);
        const auto label = static_cast<std::uint16_t>(uniform(1, 7));
        const auto id = static_cast<std::uint16_t>(uniform(1, 6));
        for (int v = v0; v <= v1; ++v)
            for (int u = u0; u <= u1; ++u) {
                const std::size_t q = static_cast<std::size_t>(v) * w + u;
                s.labels.labels[q] = label;
                if (!objects) continue;
                s.segments.labels[q] = static_cast<std::uint16_t>(r + 1);
                s.objects.labels[q] = id;
            }
    }
    if (objects)
        for (int id = 1; id <= 5; ++id) {  // id 6 is in the image but not in the list
            DetectedObject d;
            d.id = id;
            s.object_list.push_back(d);
        }
    s.active_points = 0;
    return e;
}

// The edge blocks of `outline`: another label in the 3 x 3 neighbourhood (clamped at the
// borders), one flag per block.
std::vector<std::uint8_t> edge_blocks(const LabelImage& outline) {
    const int w = outline.width, h = outline.height;
    std::vector<std::uint8_t> edges(outline.labels.size());
    for (int bv = 0; bv < h; ++bv)
        for (int bu = 0; bu < w; ++bu) {
            const std::uint16_t l = outline.labels[static_cast<std::size_t>(bv) * w + bu];
            bool edge = false;
            for (int dv = -1; dv <= 1; ++dv)
                for (int du = -1; du <= 1; ++du) {
                    const int nu = std::clamp(bu + du, 0, w - 1), nv = std::clamp(bv + dv, 0, h - 1);
                    edge = edge || outline.labels[static_cast<std::size_t>(nv) * w + nu] != l;
                }
            edges[static_cast<std::size_t>(bv) * w + bu] = edge;
        }
    return edges;
}

// The colour vote as DecimatedSource's doc states it, one edge block at a time over the grid's
// blocks inside the image (-4, -2, 0, 2, 4 blocks from it each way), row by row: the reference
// the vote's lanes must equal. Weights exp(-d2 / (2 sigma^2)) at the centre of d2's bin of 16
// (the vote's table, the same floats).
std::vector<std::int32_t> reference_vote(const RandomExpand& e, const std::vector<std::uint8_t>& edges,
                                         const std::uint16_t* labels) {
    const int w = e.decimated.width(), h = e.decimated.height();
    const std::uint16_t* const depth = e.decimated.depth.data.data();
    const std::uint8_t* const rgb = e.decimated.color.rgb.data();
    const float same = e.params.same_m / e.frame.depth.scale_m_per_unit,
                same_rel = e.params.same_rel * e.frame.depth.scale_m_per_unit;
    const float sigma = DecimatedSource::kColourSigma, scale = -1.0f / (2.0f * sigma * sigma);
    std::vector<std::int32_t> source(static_cast<std::size_t>(w) * h, -1);
    for (int bv = 0; bv < h; ++bv)
        for (int bu = 0; bu < w; ++bu) {
            const std::int32_t b = bv * w + bu;
            if (!edges[static_cast<std::size_t>(b)]) continue;
            source[static_cast<std::size_t>(b)] = b;
            const float z = depth[b];
            if (z == 0) continue;
            float own = 0, other = 0;
            int nearest_d = std::numeric_limits<int>::max();
            std::int32_t nearest = b;
            for (int dv = -4; dv <= 4; dv += 2)
                for (int du = -4; du <= 4; du += 2) {
                    const int qu = bu + du, qv = bv + dv;
                    if (qu < 0 || qu >= w || qv < 0 || qv >= h) continue;
                    const std::int32_t q = qv * w + qu;
                    const float dq = depth[q];
                    if (dq == 0 || std::fabs(dq - z) > same + same_rel * z * z) continue;
                    int d = 0;
                    for (int c = 0; c < 3; ++c) d += (rgb[3 * b + c] - rgb[3 * q + c]) * (rgb[3 * b + c] - rgb[3 * q + c]);
                    const float weight = std::exp(scale * static_cast<float>(std::min(d >> 4, 4095) * 16 + 8));
                    if (labels[q] == labels[b]) {
                        own += weight;
                    } else {
                        other += weight;
                        if (d < nearest_d) {
                            nearest_d = d;
                            nearest = q;
                        }
                    }
                }
            if (other > own) source[static_cast<std::size_t>(b)] = nearest;
        }
    return source;
}

// The rules of expand_result pixel by pixel, straight from DecimatedSource (the reference
// the row passes must equal): each input pixel's source block, its results copied, each
// object's pixels and box counted, and the small objects dropped.
FrameResult reference_expand(const RandomExpand& e) {
    const RgbdFrame& f = e.frame;
    const FrameResult& s = e.small;
    const int W = f.width(), H = f.height(), factor = e.params.factor;
    DecimatedSource source(f.depth, e.decimated.depth, factor, e.params.same_m, e.params.same_rel);
    const LabelImage& outline = e.params.objects ? s.objects : s.labels;
    const std::vector<std::uint8_t> edges = edge_blocks(outline);
    VoteBuffers voted;
    source.use_colour_at_edges(f.color, e.decimated.color, edges.data(), outline.labels.data(), voted);

    FrameResult r;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    const bool objects = e.params.objects;
    r.labels.width = r.colors.width = W;
    r.labels.height = r.colors.height = H;
    r.labels.labels.resize(N);
    r.colors.rgb.resize(3 * N);
    r.active.resize(N);
    if (objects) {
        r.segments = r.objects = r.labels;
        r.plane_classes.resize(N);
    }
    r.object_list = s.object_list;
    std::map<int, DetectedObject> boxes;
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            const std::uint16_t z = f.depth.data[p];
            std::int32_t q = -1;
            if (z != 0 && e.params.range.contains(static_cast<float>(z) * f.depth.scale_m_per_unit)) {
                q = source(u, v);
                if (q >= 0 && !s.active[static_cast<std::size_t>(q)])
                    q = source.nearest_in_depth(u / factor, v / factor, z, s.active.data());
            }
            if (q < 0) {
                const std::uint8_t grey = f.color.empty() ? 0 : dimmed_grey(&f.color.rgb[3 * p]);
                for (int c = 0; c < 3; ++c) r.colors.rgb[3 * p + c] = grey;
                if (objects) r.plane_classes[p] = kPlaneRemoved;
                continue;  // the rest 0
            }
            const auto sq = static_cast<std::size_t>(q);
            r.labels.labels[p] = s.labels.labels[sq];
            for (int c = 0; c < 3; ++c) r.colors.rgb[3 * p + c] = s.colors.rgb[3 * sq + c];
            r.active[p] = s.active[sq];
            r.active_points += r.active[p];
            if (!objects) continue;
            r.plane_classes[p] = s.plane_classes[sq];
            r.segments.labels[p] = s.segments.labels[sq];
            const std::uint16_t id = r.objects.labels[p] = s.objects.labels[sq];
            if (id == 0) continue;
            DetectedObject& d = boxes.try_emplace(id, DetectedObject{}).first->second;
            if (d.pixels == 0) {
                d.u_min = d.u_max = u;
                d.v_min = d.v_max = v;
            }
            ++d.pixels;
            d.u_min = std::min(d.u_min, u);
            d.u_max = std::max(d.u_max, u);
            d.v_min = std::min(d.v_min, v);
            d.v_max = std::max(d.v_max, v);
        }
    std::vector<DetectedObject> kept;
    for (DetectedObject d : r.object_list) {
        const DetectedObject counted = boxes.count(d.id) ? boxes[d.id] : DetectedObject{};
        d.pixels = counted.pixels;
        if (d.pixels > 0) {
            d.u_min = counted.u_min;
            d.u_max = counted.u_max;
            d.v_min = counted.v_min;
            d.v_max = counted.v_max;
        }
        if (d.pixels >= e.params.min_object_pixels) {
            kept.push_back(d);
            continue;
        }
        for (auto& id : r.objects.labels)
            if (id == d.id) id = 0;
    }
    r.object_list = kept;
    return r;
}

void expect_same_pixels(const FrameResult& a, const FrameResult& b) {
    EXPECT_EQ(a.labels.labels, b.labels.labels);
    EXPECT_EQ(a.colors.rgb, b.colors.rgb);
    EXPECT_EQ(a.active, b.active);
    EXPECT_EQ(a.active_points, b.active_points);
    EXPECT_EQ(a.plane_classes, b.plane_classes);
    EXPECT_EQ(a.segments.labels, b.segments.labels);
    EXPECT_EQ(a.objects.labels, b.objects.labels);
    ASSERT_EQ(a.object_list.size(), b.object_list.size());
    for (std::size_t i = 0; i < a.object_list.size(); ++i) {
        const DetectedObject &x = a.object_list[i], &y = b.object_list[i];
        EXPECT_EQ(x.id, y.id);
        EXPECT_EQ(x.pixels, y.pixels) << x.id;
        if (x.pixels == 0) continue;
        const std::array<int, 4> box_x{x.u_min, x.v_min, x.u_max, x.v_max}, box_y{y.u_min, y.v_min, y.u_max, y.v_max};
        EXPECT_EQ(box_x, box_y) << x.id;
    }
}

}  // namespace

// The row passes of expand_result (a code per pixel, the results by masks, the searched pixels
// one by one) give what the rules give pixel by pixel, on random frames with edges, holes and
// depths past the range: every factor, sizes not a multiple of it, with and without colour
// and the object stages.
TEST(ExpandResult, EqualsThePixelByPixelRulesOnRandomFrames) {
    ExpandWorkspace ws;
    FrameResult out;
    unsigned seed = 1;
    for (int factor : {2, 3, 4, 8})
        for (const auto& [W, H] : {std::pair{97, 61}, std::pair{64, 48}, std::pair{150, 9}})
            for (int variant = 0; variant < 4; ++variant) {
                const bool objects = variant % 2 == 0, colour = variant < 2;
                SCOPED_TRACE(testing::Message() << "factor " << factor << ", " << W << " x " << H << ", objects "
                                                << objects << ", colour " << colour);
                const RandomExpand e = random_expand(seed++, W, H, factor, objects, colour);
                expand_result(e.params, e.frame.view(), e.decimated, e.small, ws, out);
                expect_same_pixels(out, reference_expand(e));
            }
}

// The colour vote, edge blocks a lane's worth at a time on a padded copy of the frame, gives
// every edge block the source the grid gives it block by block: frames smaller than the
// grid and larger, borders, holes and depths past the range, and a second frame of another
// size through the same buffers.
TEST(DecimatedSource, TheColourVoteEqualsTheGridBlockByBlock) {
    VoteBuffers voted;
    unsigned seed = 100;
    for (const auto& [W, H] : {std::pair{97, 61}, std::pair{12, 10}, std::pair{331, 243}, std::pair{150, 9}}) {
        SCOPED_TRACE(testing::Message() << W << " x " << H);
        const RandomExpand e = random_expand(seed++, W, H, 2, true, true);
        const std::vector<std::uint8_t> edges = edge_blocks(e.small.objects);
        DecimatedSource source(e.frame.depth, e.decimated.depth, 2, e.params.same_m, e.params.same_rel);
        source.use_colour_at_edges(e.frame.color, e.decimated.color, edges.data(), e.small.objects.labels.data(), voted);
        const std::vector<std::int32_t> expected = reference_vote(e, edges, e.small.objects.labels.data());
        std::size_t moved = 0, compared = 0;
        for (std::size_t b = 0; b < expected.size(); ++b) {
            if (expected[b] < 0) continue;  // not an edge block: no vote
            ++compared;
            moved += expected[b] != static_cast<std::int32_t>(b);
            EXPECT_EQ(voted.block_source[b], expected[b]) << "block " << b;
        }
        EXPECT_GT(compared, 0u);
        if (W > 20) {
            EXPECT_GT(moved, 0u);  // the vote moved some outline: the test can tell
        }
    }
}

// The same bytes on 1, 2 and 3 threads (the bands' counts are reduced in a fixed order).
TEST(ExpandResult, TheSameOnAnyNumberOfThreads) {
    const RandomExpand e = random_expand(42, 331, 243, 2, true, true);
    const int threads = omp_get_max_threads();
    FrameResult one;
    ExpandWorkspace ws;
    omp_set_num_threads(1);
    expand_result(e.params, e.frame.view(), e.decimated, e.small, ws, one);
    for (int n : {2, 3}) {
        SCOPED_TRACE(n);
        omp_set_num_threads(n);
        FrameResult many;
        ExpandWorkspace fresh;
        expand_result(e.params, e.frame.view(), e.decimated, e.small, fresh, many);
        expect_same_pixels(many, one);
    }
    omp_set_num_threads(threads);
}

TEST(ExpandResult, RejectsResultsThatDoNotMatchTheDecimatedFrame) {
    RandomExpand e = random_expand(7, 40, 30, 2, true, true);
    e.small.objects.labels.pop_back();
    e.small.objects.height -= 1;
    ExpandWorkspace ws;
    FrameResult out;
    EXPECT_THROW(expand_result(e.params, e.frame.view(), e.decimated, e.small, ws, out), InputError);
    // Colours asked for of a result that has none (a pipeline that made none): refused, not
    // read; without them asked for, the same result is carried back, its colours left empty.
    RandomExpand no_colours = random_expand(7, 40, 30, 2, true, true);
    no_colours.small.colors = ColorImage{};
    EXPECT_THROW(expand_result(no_colours.params, no_colours.frame.view(), no_colours.decimated, no_colours.small,
                               ws, out),
                 InputError);
    no_colours.params.colors = false;
    expand_result(no_colours.params, no_colours.frame.view(), no_colours.decimated, no_colours.small, ws, out);
    EXPECT_TRUE(out.colors.rgb.empty());
    EXPECT_EQ(out.colors.width, 0);
    EXPECT_EQ(out.objects.labels.size(), static_cast<std::size_t>(out.objects.width) * out.objects.height);
}

// Without colours (ExpandParams::colors false) every other result is the same bytes.
TEST(ExpandResult, WithoutColours_EveryOtherResultTheSame) {
    for (const bool objects : {true, false}) {
        SCOPED_TRACE(objects);
        RandomExpand e = random_expand(11, 331, 243, 2, objects, true);
        ExpandWorkspace ws;
        FrameResult with, without;
        expand_result(e.params, e.frame.view(), e.decimated, e.small, ws, with);
        e.params.colors = false;
        expand_result(e.params, e.frame.view(), e.decimated, e.small, ws, without);
        EXPECT_EQ(without.labels.labels, with.labels.labels);
        EXPECT_EQ(without.active, with.active);
        EXPECT_EQ(without.objects.labels, with.objects.labels);
        EXPECT_EQ(without.segments.labels, with.segments.labels);
        EXPECT_EQ(without.plane_classes, with.plane_classes);
        EXPECT_EQ(without.active_points, with.active_points);
        EXPECT_FALSE(with.colors.rgb.empty());
        EXPECT_TRUE(without.colors.rgb.empty());
    }
}
