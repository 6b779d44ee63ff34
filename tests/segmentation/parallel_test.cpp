// Segmentation on several threads (src/segmentation/components.cpp and the other phases that
// run in parallel): the labels and the statistics do not depend on the number of threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "segment_scene.hpp"
#include "segmentation/internal.hpp"  // src/: label_components, tested against a search of its own
#include "test_support.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/threads.hpp"

using namespace wul3d;
using namespace wul3d::test;
using wul3d::detail::Ctx;
using wul3d::detail::label_components;

namespace {

/// Restores the thread count the test found.
class ThreadsGuard {
    int saved_ = num_threads();

public:
    ~ThreadsGuard() { set_num_threads(saved_); }
};

/// A frame of random depths for the labeller: the test needs only z (and the sizes).
struct RandomFrame {
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> classes, seedable;
};

/// W x H pixels, each seedable with probability `fill`; depths on a lattice whose step (1.61
/// cm near 1 m) lies between the sensor's step at the near and at the far pixel of many
/// pairs, so that many pairs are continuous seen from one side only, with some jumps.
RandomFrame random_frame(int W, int H, double fill, std::uint32_t seed) {
    RandomFrame f;
    const std::size_t N = static_cast<std::size_t>(W) * H;
    f.cloud.width = W;
    f.cloud.height = H;
    f.cloud.x.assign(N, 0.0f);
    f.cloud.y.assign(N, 0.0f);
    f.cloud.z.resize(N);
    f.cloud.valid.assign(N, 1);
    f.classes.assign(N, kPlaneObject);
    f.seedable.resize(N);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int> level(0, 3);
    for (std::size_t p = 0; p < N; ++p) {
        f.seedable[p] = unit(rng) < fill ? 1 : 0;
        const double jump = unit(rng) < 0.05 ? 0.2 : 0.0;
        f.cloud.z[p] = static_cast<float>(1.0 + 0.0161 * level(rng) + jump);
    }
    return f;
}

/// The reference: a breadth-first search from each seedable pixel in raster order that no
/// component holds yet, a neighbour joining where |z_p - z_q| <= the sensor's step at z_p
/// (p the pixel already in the component). Written apart from the library's.
std::vector<int> reference_components(const RandomFrame& f, const SegmentParams& prm, std::vector<int>& sizes) {
    const int W = f.cloud.width, H = f.cloud.height;
    std::vector<int> label(f.seedable.size(), 0), queue;
    sizes.assign(1, 0);
    int n = 0;
    for (int seed = 0; seed < W * H; ++seed) {
        if (!f.seedable[seed] || label[seed]) continue;
        label[seed] = ++n;
        queue.assign(1, seed);
        for (std::size_t head = 0; head < queue.size(); ++head) {
            const int p = queue[head], u = p % W, v = p / W;
            const int nb[4][2] = {{u - 1, v}, {u + 1, v}, {u, v - 1}, {u, v + 1}};
            for (const auto& uv : nb) {
                if (uv[0] < 0 || uv[0] >= W || uv[1] < 0 || uv[1] >= H) continue;
                const int q = uv[1] * W + uv[0];
                if (!f.seedable[q] || label[q]) continue;
                const float z = f.cloud.z[p];
                if (std::fabs(z - f.cloud.z[q]) > prm.depth_jump_m + prm.depth_jump_rel * z * z) continue;
                label[q] = n;
                queue.push_back(q);
            }
        }
        sizes.push_back(static_cast<int>(queue.size()));
    }
    return label;
}

/// Pairs of 4-neighbours, both seedable, continuous seen from one side only: the test's
/// premise that the one-way path of the labeller is exercised.
int one_way_pairs(const RandomFrame& f, const SegmentParams& prm) {
    const int W = f.cloud.width, H = f.cloud.height;
    auto conn = [&](int p, int q) {
        const float z = f.cloud.z[p];
        return std::fabs(z - f.cloud.z[q]) <= prm.depth_jump_m + prm.depth_jump_rel * z * z;
    };
    int count = 0;
    for (int p = 0; p < W * H; ++p) {
        if (!f.seedable[p]) continue;
        if (p % W + 1 < W && f.seedable[p + 1]) count += conn(p, p + 1) != conn(p + 1, p);
        if (p / W + 1 < H && f.seedable[p + W]) count += conn(p, p + W) != conn(p + W, p);
    }
    return count;
}

}  // namespace

// The labeller on strips against the reference, on odd sizes (a row, a column, sizes that no
// strip count divides), empty and full masks, at 1, 2, 3, 5, 8 and 13 strips.
TEST(LabelComponents, StripsGiveTheSearchsLabels_RandomMasksOfOddSizes) {
    const SegmentParams prm;
    struct Case {
        int W, H;
        double fill;
    };
    const Case cases[] = {{1, 1, 1.0},  {1, 37, 0.7}, {41, 1, 0.7},  {1, 50, 1.0}, {17, 13, 0.0},
                          {17, 13, 1.0}, {23, 19, 0.6}, {64, 47, 0.55}, {97, 61, 0.8}, {160, 121, 0.65}};
    int one_way = 0;
    std::uint32_t seed = 1;
    for (const Case& c : cases) {
        for (int rep = 0; rep < 3; ++rep, ++seed) {
            const RandomFrame f = random_frame(c.W, c.H, c.fill, seed);
            one_way += one_way_pairs(f, prm);
            std::vector<int> ref_sizes;
            const std::vector<int> ref = reference_components(f, prm, ref_sizes);
            const Ctx x{prm, f.cloud, f.normals, f.classes, c.W, c.H};
            for (const int strips : {1, 2, 3, 5, 8, 13}) {
                SegmentWorkspace::Buffers ws;
                ws.label.assign(f.seedable.size(), -7);  // stale labels: every pixel is written
                ws.queue.resize(f.seedable.size());
                const int n = label_components(x, f.seedable.data(), ws, strips);
                const std::string what = std::to_string(c.W) + "x" + std::to_string(c.H) + " fill " +
                                         std::to_string(c.fill) + " seed " + std::to_string(seed) +
                                         ", strips " + std::to_string(strips);
                EXPECT_EQ(n, static_cast<int>(ref_sizes.size()) - 1) << what;
                EXPECT_EQ(ws.label, ref) << what;
                ws.sizes.resize(static_cast<std::size_t>(n) + 1);
                EXPECT_EQ(ws.sizes, ref_sizes) << what;
            }
        }
    }
    EXPECT_GT(one_way, 1000) << "premise: pairs continuous from one side only";
}

// Workspaces reused across frames of other sizes and thread counts give what fresh ones do.
TEST(LabelComponents, WorkspaceReusedAcrossSizesAndStrips) {
    const SegmentParams prm;
    SegmentWorkspace::Buffers ws;
    std::uint32_t seed = 100;
    for (const int strips : {5, 2, 8, 1, 3}) {
        for (const int W : {90, 33, 120}) {
            const int H = W * 2 / 3 + 1;
            const RandomFrame f = random_frame(W, H, 0.6, ++seed);
            std::vector<int> ref_sizes;
            const std::vector<int> ref = reference_components(f, prm, ref_sizes);
            const Ctx x{prm, f.cloud, f.normals, f.classes, W, H};
            ws.label.resize(f.seedable.size());
            ws.queue.resize(f.seedable.size());
            const int n = label_components(x, f.seedable.data(), ws, strips);
            EXPECT_EQ(n, static_cast<int>(ref_sizes.size()) - 1);
            EXPECT_EQ(ws.label, ref) << W << " strips " << strips;
        }
    }
}

namespace {

/// Everything segment_objects produced but the timings.
struct Segmented {
    std::vector<std::uint16_t> labels;
    std::vector<long long> stats;
    bool operator==(const Segmented& o) const { return labels == o.labels && stats == o.stats; }
};

Segmented segment_at(const SegmentParams& params, const OrganizedCloud& cloud, const NormalMap& normals,
                     const std::vector<std::uint8_t>& classes, const Plane* support, const LabelImage& clusters,
                     SegmentWorkspace& ws) {
    LabelImage out;
    const SegmentStats s = segment_objects(params, cloud, normals, classes, support, nullptr, clusters, ws, out);
    Segmented r;
    r.labels = out.labels;
    r.stats = {s.segments,    s.colour.splits, s.colour.texture_splits, s.stacks.splits, s.pieces.splits,
               s.merge.joins,      s.containers.joins,   s.occlusion.joins,
               static_cast<long long>(s.containers.gaps_filled), static_cast<long long>(s.reattached),
               s.scope.applied, s.scope.out_of_scope};
    return r;
}

/// segment_objects at 1, 2, 3, 5 and 8 threads, each segmenter, a workspace per thread count
/// reused over two calls, and called inside a team of 2 and of 3: the same labels and
/// statistics as one thread.
void expect_same_at_any_thread_count(const OrganizedCloud& cloud, const NormalMap& normals,
                                     const std::vector<std::uint8_t>& classes, const Plane* support,
                                     const LabelImage& clusters, const std::string& what) {
    ThreadsGuard guard;
    for (const Segmenter segmenter : {Segmenter::Hybrid, Segmenter::Geometric, Segmenter::Kmeans}) {
        if (segmenter == Segmenter::Kmeans && clusters.labels.empty()) continue;
        SegmentParams params;
        params.segmenter = segmenter;
        set_num_threads(1);
        SegmentWorkspace ws1;
        const Segmented one = segment_at(params, cloud, normals, classes, support, clusters, ws1);
        EXPECT_GT(one.stats[0], 0) << what << ": premise, objects found";
        for (const int threads : {2, 3, 5, 8}) {
            set_num_threads(threads);
            SegmentWorkspace ws;
            for (int call = 0; call < 2; ++call)
                EXPECT_TRUE(segment_at(params, cloud, normals, classes, support, clusters, ws) == one)
                    << what << ", " << segmenter_name(segmenter) << ", " << threads << " threads, call " << call;
        }
        // Called by one thread of a team, as beside the pipeline's clustering: the colour cue
        // hands its segments out as tasks, which the team's other threads take.
        for (const int team : {2, 3}) {
            SegmentWorkspace ws;
            Segmented inside;
#pragma omp parallel num_threads(team)
#pragma omp single
            inside = segment_at(params, cloud, normals, classes, support, clusters, ws);
            EXPECT_TRUE(inside == one) << what << ", " << segmenter_name(segmenter) << ", a team of " << team;
        }
    }
}

}  // namespace

// Synthetic scenes: boxes, cups (containers, islands), a wall and a floor (the scope).
TEST(SegmentObjects, SameLabelsAndStatsAtAnyThreadCount_SyntheticScenes) {
    std::vector<Scene> scenes;
    Scene a = pitched_tabletop_scene();
    a.boxes = {SceneBox{}, SceneBox{}};
    a.boxes[0].x = -0.2f;
    a.boxes[1].x = 0.15f;
    a.boxes[1].g = 180;
    SceneCup cup;
    cup.x = 0.3f;
    a.cups = {cup};
    a.noise_seed = 3;
    scenes.push_back(a);
    Scene b = pitched_tabletop_scene();
    b.wall = true;
    b.floor_y = 1.2f;
    b.boxes = {SceneBox{}};
    b.boxes[0].w = 0.3f;
    b.width = 331;  // odd sizes: strips of unequal rows
    b.height = 203;
    scenes.push_back(b);
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const PlaneStage st = up_to_the_plane(scenes[i]);
        expect_same_at_any_thread_count(st.cloud, st.normals, st.classes, &st.plane.support, LabelImage{},
                                        "scene " + std::to_string(i));
    }
}

// The shipped tabletop frames, through the pipeline up to the plane at every pixel
// (decimation 1: the result's per-pixel arrays share the cloud's grid), then segmented.
TEST(SegmentObjects, SameLabelsAndStatsAtAnyThreadCount_ShippedFrames) {
    const auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    ASSERT_GE(source->size(), 2u);
    PipelineParams params;
    params.decimation = 1;
    Pipeline pipeline(params);
    SourceItem item;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        const FrameResult& r = pipeline.process(item.frame);
        expect_same_at_any_thread_count(pipeline.cloud(), pipeline.normals(), r.plane_classes,
                                        r.plane.found ? &r.plane.support : nullptr, r.labels,
                                        source->name(i));
    }
}
