#include "wul3d/pipeline.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>

#include "stages/side_by_side.hpp"  // src/stages/: the pipeline's private choice, tested here
#include "synthetic_scene.hpp"
#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"

using namespace wul3d;
using namespace wul3d::test;

// Real frames shipped in the repository (data/samples, MIT and BSD licensed).
// At every pixel and at the default --decimate 2, where each pixel's results come from a
// block.
class RealTabletop : public ::testing::TestWithParam<int> {};

TEST_P(RealTabletop, FramesGetLabelsOnEveryValidInRangePixel) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    ASSERT_EQ(source->size(), 4u);
    PipelineParams params;
    params.cluster.k = 10;
    params.decimation = GetParam();
    Pipeline pipeline(params);
    SourceItem item;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        ASSERT_FALSE(item.is_raw);
        const FrameResult& r = pipeline.process(item.frame);
        ASSERT_EQ(r.labels.width, 640);
        ASSERT_EQ(r.labels.height, 480);
        std::size_t in_range = 0;
        std::vector<bool> used(11, false);
        for (std::size_t p = 0; p < r.labels.labels.size(); ++p) {
            const float z = static_cast<float>(item.frame.depth.data[p]) * item.frame.depth.scale_m_per_unit;
            const bool expect = item.frame.depth.data[p] != 0 && z >= params.range.zmin_m &&
                                z <= params.range.zmax_m;
            in_range += expect;
            if (expect) {
                ASSERT_GE(r.labels.labels[p], 1);
                ASSERT_LE(r.labels.labels[p], 10);
                used[r.labels.labels[p]] = true;
            } else {
                ASSERT_EQ(r.labels.labels[p], 0);
            }
        }
        EXPECT_EQ(in_range, r.active_points);
        EXPECT_GT(in_range, 100000u);
        // Seeding gives every cluster points; later frames are other scenes, where a cluster
        // may empty out (and be re-seeded) for a frame.
        if (i == 0) {
            EXPECT_EQ(std::count(used.begin() + 1, used.end(), true), 10) << "a cluster is empty";
        }
        EXPECT_GE(std::count(used.begin() + 1, used.end(), true), 7);
        EXPECT_EQ(r.colors.rgb.size(), 3u * 640 * 480);
        EXPECT_GT(pipeline.normals().valid.size(), 0u);
    }
    EXPECT_EQ(pipeline.state().tau(), 4);
}

TEST(Pipeline, RealDepthOnlySequence) {
    auto source = open_source((sample_dir() / "pcl_kinect" / "pairwise_seq").string(), SourceOptions{});
    ASSERT_EQ(source->size(), 5u);
    Pipeline pipeline(PipelineParams::paper());
    SourceItem item;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        ASSERT_FALSE(item.frame.has_color());
        const FrameResult& r = pipeline.process(item.frame);
        std::size_t labelled = 0;
        for (auto l : r.labels.labels) labelled += l != 0;
        EXPECT_EQ(labelled, r.active_points);
        EXPECT_GT(labelled, 100000u);
    }
}

TEST(Pipeline, AllInvalidDepthIsAnInputError) {
    RgbdFrame f;
    f.name = "zeros";
    f.intrinsics = intrinsics_preset("kinect_v1");
    f.depth.width = 640;
    f.depth.height = 480;
    f.depth.data.assign(640 * 480, 0);
    Pipeline pipeline(PipelineParams{});
    EXPECT_THROW(pipeline.process(f), InputError);
}

TEST(PipelineParams, PaperPresetValidates) {
    const PipelineParams p = PipelineParams::paper();
    EXPECT_NO_THROW(p.validate());
    EXPECT_FLOAT_EQ(p.range.zmin_m, 0.5f);
    EXPECT_FLOAT_EQ(p.range.zmax_m, 4.5f);
    EXPECT_EQ(p.decimation, 1);  // the paper clusters every point
}

// The object stages on the real tabletop frames: a support plane in every frame, objects
// that cover a part of the scene (not the room), ids that are the labels of objects.png,
// and a time for every object stage.
TEST_P(RealTabletop, Frames_ObjectsOnTheSupport) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    PipelineParams params;
    params.decimation = GetParam();
    Pipeline pipeline(params);
    PipelineParams no_plane_params = params;
    no_plane_params.remove_plane = false;
    Pipeline no_plane(no_plane_params);
    SourceItem item;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        SCOPED_TRACE(item.frame.name);
        const FrameResult& r = pipeline.process(item.frame);
        EXPECT_TRUE(r.plane.found);
        // Known weakness: in image_0005 a fringe of the (warped) table joins the bag and the red
        // box, so two objects of three are found there.
        ASSERT_GE(r.object_list.size(), 2u);
        std::size_t object_pixels = 0;
        for (const DetectedObject& d : r.object_list) {
            object_pixels += d.pixels;
            EXPECT_GE(d.pixels, static_cast<std::size_t>(pipeline.params().objects.min_points));
            const auto n = static_cast<std::size_t>(std::count(
                r.objects.labels.begin(), r.objects.labels.end(), static_cast<std::uint16_t>(d.id)));
            EXPECT_EQ(n, d.pixels);
            EXPECT_GT(d.centroid[2], 0.3f);
        }
        EXPECT_LT(static_cast<double>(object_pixels), 0.5 * static_cast<double>(r.active_points));
        EXPECT_GT(r.times.plane, 0.0);
        EXPECT_GT(r.times.segmentation, 0.0);
        EXPECT_GT(r.times.objects, 0.0);
        // Without plane removal the table is no longer taken away.
        const FrameResult& rn = no_plane.process(item.frame);
        EXPECT_FALSE(rn.plane.found);
        EXPECT_GT(rn.plane.kept, r.plane.kept);
    }
}

// --min-points counts the input's pixels at every N: at N = 2 the stages check a quarter
// of it on blocks, and an object can come back from the blocks a few pixels short of it.
TEST_P(RealTabletop, ObjectsHaveAtLeastMinPointsPixels) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    SourceItem item;
    int objects = 0;
    for (int min_points = 150; min_points <= 2250; min_points += 150) {
        PipelineParams params;
        params.decimation = GetParam();
        params.segmentation.min_points = params.objects.min_points = min_points;
        Pipeline pipeline(params);
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            const FrameResult& r = pipeline.process(item.frame);
            for (const DetectedObject& d : r.object_list) {
                SCOPED_TRACE(item.frame.name + ", --min-points " + std::to_string(min_points));
                EXPECT_GE(d.pixels, static_cast<std::size_t>(min_points));
                EXPECT_EQ(static_cast<std::size_t>(std::count(r.objects.labels.begin(), r.objects.labels.end(),
                                                              static_cast<std::uint16_t>(d.id))),
                          d.pixels);
                ++objects;
            }
            std::set<std::uint16_t> ids(r.objects.labels.begin(), r.objects.labels.end());
            ids.erase(0);
            EXPECT_EQ(ids.size(), r.object_list.size());
        }
    }
    EXPECT_GT(objects, 30);
}

INSTANTIATE_TEST_SUITE_P(Pipeline, RealTabletop, ::testing::Values(1, 2),
                         [](const ::testing::TestParamInfo<int>& p) { return "Decimate" + std::to_string(p.param); });

TEST(PipelineParams, ObjectStagesValidate) {
    PipelineParams p;
    p.segmentation.min_points = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p = PipelineParams{};
    p.objects.psi = 2;
    EXPECT_THROW(Pipeline{p}, ParamError);
}

// On two threads the clustering runs beside the plane and segmentation stages in the first,
// third, ... frames of a sequence (SideBySideChoice's trials; here the shipped tabletop frames
// decimated to 320 x 240): every result must be the one the stages give one after the other,
// on one thread, over the whole sequence.
TEST(Pipeline, ClusteringBesideTheObjectStages_SameResultsAsOneAfterTheOther) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    PipelineParams params;
    params.decimation = 2;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Pipeline one(params);
    omp_set_num_threads(2);
    Pipeline two(params);
    SourceItem item;
    int side_by_side = 0;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        SCOPED_TRACE(item.frame.name);
        omp_set_num_threads(1);
        const FrameResult a = one.process(item.frame);
        EXPECT_EQ(a.times.overlap, 0.0);
        EXPECT_FALSE(a.times.side_by_side);
        omp_set_num_threads(2);
        const FrameResult& b = two.process(item.frame);
        side_by_side += b.times.side_by_side;
        EXPECT_GE(b.times.overlap, 0.0);
        if (!b.times.side_by_side) {
            EXPECT_EQ(b.times.overlap, 0.0);
        }
        EXPECT_EQ(a.labels.labels, b.labels.labels);
        EXPECT_EQ(a.colors.rgb, b.colors.rgb);
        EXPECT_EQ(a.segments.labels, b.segments.labels);
        EXPECT_EQ(a.objects.labels, b.objects.labels);
        ASSERT_EQ(a.object_list.size(), b.object_list.size());
        for (std::size_t o = 0; o < a.object_list.size(); ++o) {
            EXPECT_EQ(a.object_list[o].track_id, b.object_list[o].track_id);
            EXPECT_EQ(a.object_list[o].pixels, b.object_list[o].pixels);
        }
        EXPECT_NEAR(b.times.total(),
                    b.times.decimation + b.times.backprojection + b.times.normals + b.times.background +
                        b.times.clustering + b.times.colors + b.times.plane + b.times.segmentation +
                        b.times.objects - b.times.overlap,
                    1e-9);
    }
    omp_set_num_threads(threads);
    // The premise, whatever the machine's load: a period starts with frames each way.
    EXPECT_GT(side_by_side, 0) << "the stages did not run side by side (test premise)";
}

// Without render_colors the colours are left empty and everything else is the same, at every
// pixel and with decimation, one after the other and side by side (two threads). Switched
// back on mid-sequence (set_render_colors, as the Python module does per call), they are
// again those of a pipeline that always made them: they are made from the weights, which
// run on either way.
TEST(Pipeline, WithoutColours_TheSameLabelsAndObjects_ColoursEmpty) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    const int threads = omp_get_max_threads();
    for (const int decimation : {1, 2})
        for (const int team : {1, 2}) {
            SCOPED_TRACE("decimation " + std::to_string(decimation) + ", threads " + std::to_string(team));
            omp_set_num_threads(team);
            PipelineParams params;
            params.decimation = decimation;
            Pipeline with(params);
            params.render_colors = false;
            Pipeline without(params);
            SourceItem item;
            for (std::size_t pass = 0; pass < 2; ++pass)
                for (std::size_t i = 0; i < source->size(); ++i) {
                    source->read(i, item);
                    SCOPED_TRACE(item.frame.name);
                    const bool colours_back = pass == 1 && i % 2 == 1;  // on, off, on, ... in pass 2
                    without.set_render_colors(colours_back);
                    const FrameResult a = with.process(item.frame);
                    const FrameResult& b = without.process(item.frame);
                    EXPECT_EQ(a.labels.labels, b.labels.labels);
                    EXPECT_EQ(a.active, b.active);
                    EXPECT_EQ(a.objects.labels, b.objects.labels);
                    EXPECT_EQ(a.segments.labels, b.segments.labels);
                    ASSERT_EQ(a.object_list.size(), b.object_list.size());
                    for (std::size_t o = 0; o < a.object_list.size(); ++o)
                        EXPECT_EQ(a.object_list[o].pixels, b.object_list[o].pixels);
                    ASSERT_FALSE(a.colors.rgb.empty());
                    if (colours_back) {
                        EXPECT_EQ(a.colors.rgb, b.colors.rgb);
                        EXPECT_EQ(a.colors.width, b.colors.width);
                    } else {
                        EXPECT_TRUE(b.colors.rgb.empty());
                        EXPECT_EQ(b.colors.width, 0);
                        EXPECT_EQ(b.colors.height, 0);
                        EXPECT_EQ(b.times.colors, 0.0);
                    }
                }
        }
    omp_set_num_threads(threads);
}

// swap_images hands the images over and takes any vectors in their place (scribbled over, of
// other sizes): the next frames' images are those of a pipeline that never swapped, every
// pixel written again. At decimation 1 nothing is swapped.
TEST(Pipeline, SwapImages_TheNextFrameWritesEveryPixelOfWhatItGets) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    PipelineParams params;
    params.decimation = 2;
    Pipeline plain(params), swapping(params);
    SourceItem item;
    for (std::size_t pass = 0; pass < 2; ++pass) {
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            SCOPED_TRACE(item.frame.name);
            const FrameResult& a = plain.process(item.frame);
            swapping.process(item.frame);
            // Scribbled vectors: the same size, a smaller and a larger one in turn.
            const std::size_t n = a.labels.labels.size(), sizes[] = {n, n / 3, 2 * n};
            std::vector<std::uint16_t> labels(sizes[i % 3], 0x4d4d), objects(sizes[(i + 1) % 3], 0x4d4d);
            std::vector<std::uint8_t> rgb(3 * sizes[(i + 2) % 3], 0x4d);
            ASSERT_TRUE(swapping.swap_images(labels, rgb, objects));
            EXPECT_EQ(labels, a.labels.labels);
            EXPECT_EQ(rgb, a.colors.rgb);
            EXPECT_EQ(objects, a.objects.labels);
        }
    }
    params.decimation = 1;
    Pipeline every_pixel(params);
    source->read(0, item);
    const FrameResult& r = every_pixel.process(item.frame);
    std::vector<std::uint16_t> labels(3, 7), objects;
    std::vector<std::uint8_t> rgb;
    EXPECT_FALSE(every_pixel.swap_images(labels, rgb, objects));
    EXPECT_EQ(labels, std::vector<std::uint16_t>(3, 7));
    EXPECT_EQ(r.labels.labels.size(), static_cast<std::size_t>(r.labels.width) * r.labels.height);
}

// An error inside the stages that run side by side reaches the caller as itself (an exception
// may not leave an OpenMP region): a first frame with fewer points in range than k.
TEST(Pipeline, ErrorBesideTheObjectStagesReachesTheCaller) {
    RgbdFrame f;
    f.name = "far";
    f.intrinsics = {320, 240, 300.0, 300.0, 160.0, 120.0};
    f.depth.width = 320;
    f.depth.height = 240;
    f.depth.scale_m_per_unit = 0.001f;
    f.depth.data.assign(320 * 240, 9000);  // 9 m: out of the default range
    for (int i = 0; i < 3; ++i) f.depth.data[static_cast<std::size_t>(120 * 320 + 100 + i)] = 1000;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(2);
    Pipeline pipeline(PipelineParams{});
    EXPECT_THROW(pipeline.process(f), InputError);
    omp_set_num_threads(threads);
}

// The choice of the way to run the two parts: trial frames alternate (side by side first),
// the fastest frame of each way decides for the rest of the period, and the next period
// tries again.
TEST(SideBySideChoice, TriesBothWaysThenKeepsTheFaster) {
    using detail::SideBySideChoice;
    SideBySideChoice choice;
    // Side by side: 9 (a seeding frame), 5, 5; one after the other: 6, 5.5, 7.
    const double trial_ms[] = {9, 6, 5, 5.5, 5, 7};
    for (int i = 0; i < 2 * SideBySideChoice::kTrials; ++i) {
        const bool way = choice.next();
        EXPECT_EQ(way, i % 2 == 0) << i;
        choice.record(way, trial_ms[i]);
    }
    for (int i = 2 * SideBySideChoice::kTrials; i < SideBySideChoice::kPeriod; ++i) {
        ASSERT_TRUE(choice.next()) << i;
        choice.record(true, 100);  // kept for the period, whatever these frames take
    }
    // Next period: tried again; now one after the other is faster.
    for (int i = 0; i < 2 * SideBySideChoice::kTrials; ++i) {
        const bool way = choice.next();
        EXPECT_EQ(way, i % 2 == 0) << i;
        choice.record(way, way ? 8.0 : 4.0);
    }
    EXPECT_FALSE(choice.next());
}

// The white bowl of data/samples/uois_tabletop/image_0000 (lower right) is one object. Its
// floor lies partly in its own shadow, and 2-means parts the shadow from the lit floor:
// along that boundary every pair on one plane is a brightness step, but those are 6 of 52
// pairs across the smooth curved floor, so the colour cue's brightness step (DESIGN.md, "The
// brightness step") must not split there. (372, 410) lies in the part it would split off,
// (427, 359) in the rest; both are bowl at the default --decimate 2.
TEST(RealTabletopBowl, ShadowOnTheFloor_DoesNotSplitIt) {
    auto source = open_source((sample_dir() / "uois_tabletop" / "image_0000").string(), SourceOptions{});
    SourceItem item;
    source->read(0, item);
    Pipeline pipeline(PipelineParams{});
    const FrameResult& r = pipeline.process(item.frame);
    const int W = r.objects.width;
    const std::uint16_t shadow_side = r.objects.labels[410 * W + 372];
    const std::uint16_t lit_side = r.objects.labels[359 * W + 427];
    EXPECT_NE(shadow_side, 0);
    EXPECT_EQ(shadow_side, lit_side) << "the bowl was split along its floor's shadow";
}

#ifdef WUL3D_SCENEGEN
namespace {

/// eval/scenegen.py's scene `seed`, rendered into `dir`: its frame and its truth labels.
struct GeneratedFrame {
    RgbdFrame frame;
    LabelImage truth;
};

GeneratedFrame render_generated(const TempDir& dir, int seed, const std::string& sensor = "structured_light",
                                const std::string& family = "tabletop") {
    const CommandResult gen = run_command({WUL3D_PYTHON3, WUL3D_SCENEGEN, "--out", dir.path().string(), "--seeds",
                                           std::to_string(seed), "--sensor", sensor, "--family", family});
    EXPECT_EQ(gen.exit_code, 0) << gen.err;
    char name[32];
    std::snprintf(name, sizeof name, "scene_%05d", seed);
    GeneratedFrame g;
    g.truth = read_label_png((dir.path() / name / "label.png").string());
    auto source = open_source(dir.path().string(), SourceOptions{});
    SourceItem item;
    source->read(0, item);
    g.frame = item.frame;
    return g;
}

/// The object holding most of truth label t's pixels, background left out, and the share
/// of them it holds (0 when no object holds any). Not synthetic_scene.hpp's dominant_share:
/// that one counts background as a candidate and reads the ray-cast scenes' int truth.
std::pair<int, double> dominant_object(const LabelImage& objects, const LabelImage& truth, int t) {
    std::map<int, int> counts;
    int total = 0;
    for (std::size_t p = 0; p < truth.labels.size(); ++p)
        if (truth.labels[p] == t) {
            ++counts[objects.labels[p]];
            ++total;
        }
    std::pair<int, int> best{0, 0};
    for (const auto& [id, n] : counts)
        if (id != 0 && n > best.second) best = {id, n};
    return {best.first, total > 0 ? static_cast<double>(best.second) / total : 0.0};
}

/// The ids of g's true objects (its truth labels other than 0).
std::set<int> truth_objects(const GeneratedFrame& g) {
    std::set<int> ids;
    for (const std::uint16_t t : g.truth.labels)
        if (t != 0) ids.insert(t);
    return ids;
}

/// The share of g's background (truth 0: the support, the room, what is not an object) that
/// lies in an object of `objects`.
double background_in_objects(const LabelImage& objects, const GeneratedFrame& g) {
    std::size_t background = 0, in_object = 0;
    for (std::size_t p = 0; p < g.truth.labels.size(); ++p) {
        if (g.truth.labels[p] != 0) continue;
        ++background;
        in_object += objects.labels[p] != 0;
    }
    return static_cast<double>(in_object) / static_cast<double>(background);
}

/// How many of g's true objects one predicted object holds the most of (more than half).
std::size_t objects_found(const LabelImage& objects, const GeneratedFrame& g) {
    std::size_t found = 0;
    for (const int t : truth_objects(g)) found += dominant_object(objects, g.truth, t).second > 0.5;
    return found;
}

/// How many predicted objects hold the most (more than half) of one or more of g's true
/// objects, each counted once: objects_found less the true objects merged into another's.
std::size_t objects_apart(const LabelImage& objects, const GeneratedFrame& g) {
    std::set<int> holders;
    for (const int t : truth_objects(g)) {
        const auto [id, share] = dominant_object(objects, g.truth, t);
        if (share > 0.5) holders.insert(id);
    }
    return holders.size();
}

/// g's frame through a pipeline with the default parameters.
FrameResult process_default(const GeneratedFrame& g) {
    Pipeline pipeline{PipelineParams{}};
    return pipeline.process(g.frame);
}

/// A generated scene: eval/scenegen.py's seed, sensor and family.
struct SceneSeed {
    int seed;
    const char* sensor;
    const char* family;
};

/// The share of truth label t that one object holds (dominant_object) when the default
/// pipeline runs on `scene`, whose truth label t must hold `pixels` pixels (the premise that
/// the generator drew the object a test names; a failure and 0 otherwise), and whose depth
/// noise must be measured.
double one_object_share(const SceneSeed& scene, int t, long pixels) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, scene.seed, scene.sensor, scene.family);
    const long drawn = std::count(g.truth.labels.begin(), g.truth.labels.end(), t);
    EXPECT_EQ(drawn, pixels) << "premise: the object of truth label " << t;
    if (drawn != pixels) return 0.0;
    const FrameResult r = process_default(g);
    EXPECT_GT(r.depth_noise_px, 0.0f);
    return dominant_object(r.objects, g.truth, t).second;
}

/// g's frame through a pipeline whose default segmentation parameters `set` changed.
template <class Set>
FrameResult process_with(const GeneratedFrame& g, Set&& set) {
    PipelineParams params;
    set(params.segmentation);
    Pipeline pipeline(params);
    return pipeline.process(g.frame);
}

}  // namespace

// A generated tabletop (eval/scenegen.py report seed 1000) seen by the generator's active-stereo
// camera, whose depth noise (0.7 pixel footprints across the surface at the decimated pixels,
// against 0.1-0.2 for a real Kinect v1) tilts the normals of radius 2 past the plane's grow
// angle: with that fixed radius no support is found and the table becomes an object. The
// radius the measured noise chooses finds it.
TEST(GeneratedScene, NoisyActiveStereoDepth_TheMeasuredNoiseWidensTheNormalsAndFindsTheTable) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 1000, "active_stereo");
    auto run = [&](float max_tilt_noise_deg) {
        PipelineParams params;
        params.normals.max_tilt_noise_deg = max_tilt_noise_deg;
        Pipeline pipeline(params);
        return pipeline.process(g.frame);
    };
    const FrameResult fixed = run(0.0f);
    ASSERT_FALSE(fixed.plane.found) << "radius 2 should miss the table (test premise)";
    EXPECT_EQ(fixed.normal_radius_px, 2);
    const FrameResult r = run(NormalParams{}.max_tilt_noise_deg);
    EXPECT_GT(r.depth_noise_px, 0.5f);
    EXPECT_GE(r.normal_radius_px, 4);
    EXPECT_TRUE(r.plane.found);
    // The table is background: hardly any of its pixels lie in an object.
    EXPECT_LT(background_in_objects(r.objects, g), 0.05);
}

// A generated tabletop (eval/scenegen.py tune seed 13) under the active-stereo camera, the
// table seen from 0.7 to 2 m: its noise grows with z^2, and the far table's normals tilt past
// the plane's grow angle even at the radius the frame's noise chooses. With the angle of a
// quiet camera no support is found and the table comes out as objects. The grow angle widens
// with the measured noise past the noise that tilts the least radius's normals by their
// angle, here 1.5 times: given as 8 degrees (widened to 12) the table is missed; given as the
// default 12, it is the support.
TEST(GeneratedScene, NoisyActiveStereoDepth_TheGrowAngleWidensAndTheFarTableIsTheSupport) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 13, "active_stereo");
    const std::size_t n_objects = truth_objects(g).size();
    ASSERT_GE(n_objects, 5u);
    auto run = [&](float grow_angle_deg) {
        PipelineParams params;
        params.plane.grow_angle_deg = grow_angle_deg;
        Pipeline pipeline(params);
        return pipeline.process(g.frame);
    };
    const FrameResult narrow = run(PlaneParams{}.grow_angle_deg / 1.5f);
    ASSERT_FALSE(narrow.plane.found) << "12 degrees should miss the table (test premise)";
    ASSERT_GT(background_in_objects(narrow.objects, g), 0.5);
    const FrameResult r = run(PlaneParams{}.grow_angle_deg);
    EXPECT_GT(r.depth_noise_px, 0.52f);  // 1.5 times the noise that tilts the least radius by 7 degrees
    ASSERT_TRUE(r.plane.found);
    EXPECT_LT(background_in_objects(r.objects, g), 0.05);
    EXPECT_GE(objects_found(r.objects, g), n_objects - 2);
}

// A generated pile (eval/scenegen.py pile tune seed 10039) under the structured-light camera:
// its noise (0.38 pixel footprints) tilts normals of the least radius past the 7 degrees that
// NormalParams allows, yet under the noise where normal_radius_for rounds up to radius 3. With
// the plane's angle and band widened only from that rounding on, no support was found and the
// table was one object with the pile (Overlap P 3 %). Widened from the noise that tilts the
// least radius's normals by the 7 degrees, the table is the support.
TEST(GeneratedScene, PileUnderStructuredLight_ThePlaneWidensOnceTheLeastRadiusTiltsPastItsAngle) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 10039, "structured_light", "pile");
    const FrameResult r = process_default(g);
    const NormalParams normals;
    const float tilt = std::tan(normals.max_tilt_noise_deg * std::numbers::pi_v<float> / 180.0f);
    ASSERT_EQ(r.normal_radius_px, normals.radius_px) << "premise: the least radius";
    ASSERT_GT(r.depth_noise_px, static_cast<float>(normals.radius_px) * std::sqrt(2.0f) * tilt)
        << "premise: its normals tilt past the angle";
    ASSERT_LT(r.depth_noise_px, (static_cast<float>(normals.radius_px) + 0.5f) * std::sqrt(2.0f) * tilt)
        << "premise: under the noise where the radius rounds up";
    ASSERT_TRUE(r.plane.found);
    EXPECT_LT(background_in_objects(r.objects, g), 0.05);
    const std::size_t found = objects_found(r.objects, g), n_objects = truth_objects(g).size();
    EXPECT_GE(found, n_objects - 2) << found << " of " << n_objects;
}

// A generated floor scene (eval/scenegen.py floor tune seed 20024) under the ToF camera: a
// board 1.5-2 cm thick lies on the floor 1.5 m away with most of the objects on it. Its top
// lies in the support's band there (17 mm), so the support's classes took it for a
// container's inside, enclosed by the board's edge, and too few of its points stood over the
// band to make a low support's layer: the segmentation joined the board to its edge and the
// objects to it (Overlap P 21 %; 5.8 % of the background in objects, the eleven objects in
// five). The layer counts from three quarters of the band, and the low support's top takes
// those inside pixels: the board is background, and the objects on it stand apart.
TEST(GeneratedScene, BoardWithinTheSupportsBand_IsALowSupportNotAContainer) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 20024, "tof", "floor");
    const FrameResult r = process_default(g);
    ASSERT_TRUE(r.plane.found);
    EXPECT_TRUE(r.plane.low_found);
    EXPECT_LT(background_in_objects(r.objects, g), 0.01);  // 5.8 % before
    EXPECT_GE(objects_apart(r.objects, g), 8u) << "of " << truth_objects(g).size();  // 5 before
}

// A generated floor scene (eval/scenegen.py floor tune seed 20008) under the active-stereo
// camera (noise 1.9 pixel footprints, 1.5 m away): a tray on a carpet with five objects in
// it. Its bottom is found as a low support on the given band, but the camera scatters its
// points past that band, and half of them stayed objects, speckled over the tray, which grew
// into one object with the tray's rim and everything in it (10 % of the background in
// objects). Removed on the frame's band, widened with its noise as the support's is, most of
// the tray is background.
TEST(GeneratedScene, NoisyTray_ItsBottomRemovedOnTheFramesBand) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 20008, "active_stereo", "floor");
    const FrameResult r = process_default(g);
    ASSERT_GT(r.depth_noise_px, 1.0f) << "premise: a noisy camera, a band widened 1.5 times";
    ASSERT_TRUE(r.plane.low_found);
    EXPECT_LT(background_in_objects(r.objects, g), 0.04);  // 10.2 % before, 1.7 %
}

// A generated floor scene (eval/scenegen.py floor tune seed 20017) under the active-stereo
// camera, looking down on a tray with a 1.6 cm rim and a pile in it. The rim's outer walls,
// seen from above, spread in the image past two grid cells round the tray's bottom, and the
// camera's holes broke them into pieces too small for the scope's low supports: eight pieces
// of rim were objects (3.4 % of the background). The rim is taken on the plane instead: a
// foot within 5 cm of the bottom's outline.
TEST(GeneratedScene, TrayRimSeenFromAbove_FoundOnThePlane) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 20017, "active_stereo", "floor");
    const FrameResult r = process_default(g);
    ASSERT_TRUE(r.plane.low_found);
    EXPECT_LT(background_in_objects(r.objects, g), 0.015);  // 3.4 % before, 1.0 %
}

// A generated floor scene (eval/scenegen.py floor tune seed 20001) under the time-of-flight
// camera, 1.6-1.9 m away: beside a tray, objects on the carpet touch in two groups (a lying
// can against a box, a standing can behind it; a box against a stack). Where one's outline
// lies over the other, the convexity merge found the boundary not concave and joined them.
// Those boundaries step in depth and change colour: silhouette pairs, junction pairs as
// concave ones are, and a boundary of more than merge.max_concave of them is not merged.
TEST(GeneratedScene, ObjectsTouchingOnTheCarpet_ASilhouetteIsNoMerge) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 20001, "tof", "floor");
    const FrameResult r = process_default(g);
    ASSERT_TRUE(r.plane.found);
    EXPECT_GE(objects_apart(r.objects, g), 10u) << "of " << truth_objects(g).size();  // 7 before
}

// A generated pile (eval/scenegen.py pile tune seed 10005, eleven objects) seen by the
// active-stereo camera from afar: the measured noise chooses normals of radius 8 or more, and
// the crease tests, comparing normals 5 pixels apart, compared two normals of nearly the same
// neighbourhood: no crease, and the pile came out as three objects, two of them whole. The
// crease step widens to the normals' radius (crease_step_for), and two more come out whole.
TEST(GeneratedScene, NoisyActiveStereoPile_TheCreaseStepWidensWithTheNormalsRadius) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 10005, "active_stereo", "pile");
    const std::set<int> objects = truth_objects(g);
    ASSERT_EQ(objects.size(), 11u);
    const FrameResult r = process_default(g);
    ASSERT_GE(r.normal_radius_px, 8) << "premise: normals wider than the given crease step";
    // Found: one object holds most of it, and most of that object is it.
    int found = 0;
    for (const int t : objects) {
        const auto [id, share] = dominant_object(r.objects, g.truth, t);
        if (share <= 0.5) continue;
        std::size_t in_object = 0, of_t = 0;
        for (std::size_t p = 0; p < g.truth.labels.size(); ++p) {
            if (r.objects.labels[p] != id) continue;
            ++in_object;
            of_t += g.truth.labels[p] == t;
        }
        found += 2 * of_t > in_object;
    }
    EXPECT_GE(found, 4);  // 2 with the step of 5 pixels
}

// A generated floor scene (eval/scenegen.py floor tune seed 20043) under the active-stereo
// camera, 1.2 m away: a can standing on the floor, its label another colour than its top.
// The round test, which keeps a can's print from splitting it, fitted its walls to 3.7 mm
// RMS, over the 3.5 mm a Kinect's can fits; the camera's noise scatters the points along
// their rays. The test allows for the scatter the frame's measured noise gives the walls,
// and the can is one object (four before).
TEST(GeneratedScene, LabelledCanUnderActiveStereo_RoundWithinTheMeasuredNoise) {
    // Truth label 4, 3,014 pixels: the can.
    EXPECT_GT(one_object_share({20043, "active_stereo", "floor"}, 4, 3014), 0.9);  // 0.40 before
}

// A generated floor scene (eval/scenegen.py floor tune seed 20004) under the active-stereo
// camera: a bottle standing on the floor, its cap and neck parted from its body by the
// crease cuts. The neck rule joins them on the body's axis; the normals' meeting point put
// that axis 2.5 cm off (half the cap within 3 cm of it), the bottle's normals bending
// towards the camera at its outline. Circles fitted to its walls find the axis.
TEST(GeneratedScene, BottleUnderActiveStereo_ItsNeckOnTheAxisOfItsWalls) {
    // Truth label 4, 1,136 pixels: the bottle.
    EXPECT_GT(one_object_share({20004, "active_stereo", "floor"}, 4, 1136), 0.85);  // 0.66 before
}

// A generated floor scene (eval/scenegen.py floor tune seed 20025) under structured light: a
// bottle whose shoulder and neck the crease cuts off its body. The body's normals, estimated
// over much of its narrow width, agree at four times their angle by 0.28 (a box's walls by
// 0.56 and more): under the neck rule's own bound of 0.25 the body was taken for a box and
// the bottle stayed in two pieces (0.63 of it in one object). With the stack rule's bound
// (kBoxAxes, 0.4) the body is round and the neck joins it.
TEST(GeneratedScene, BottleWithANarrowBody_RoundThoughItsNormalsAreSmoothed) {
    // Truth label 3, 2,941 pixels: the bottle.
    EXPECT_GT(one_object_share({20025, "structured_light", "floor"}, 3, 2941), 0.85);  // 0.63 before
}

// A generated floor scene (eval/scenegen.py floor tune seed 20042) under the active-stereo
// camera: a bottle whose body the crease cuts below its shoulder, so that the upper segment
// holds the shoulder with the neck and cap, wider than a neck (0.50 and 0.42 of it in two
// objects). It lies within the body's radius and its top is the neck: it joins the body.
TEST(GeneratedScene, BottleCutBelowItsShoulder_TheShoulderWithItsNeckJoinsTheBody) {
    // Truth label 4, 1,862 pixels: the bottle.
    EXPECT_GT(one_object_share({20042, "active_stereo", "floor"}, 4, 1862), 0.85);  // 0.50 before
}

// A generated floor scene (eval/scenegen.py floor tune seed 20035) under the active-stereo
// camera: a can 0.76 m off at the frame's right edge, a strip 8 decimated pixels wide of it in
// view between a box and a ball. The creases on either side leave 28 of its 83 decimated
// pixels uncut, fewer than a seed holds (cuts.min_seed_points, 40), and the box beside it,
// apart in depth, cannot reach it: its pixels, an orphan region, are a segment now (0.13 of
// it went with the box without the orphans).
TEST(GeneratedScene, CanCutThroughByCreases_AnOrphanRegionIsASegment) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 20035, "active_stereo", "floor");
    // Truth label 10, 352 pixels: the can.
    ASSERT_EQ(std::count(g.truth.labels.begin(), g.truth.labels.end(), 10), 352) << "premise: the can";
    const FrameResult r = process_default(g);
    const auto [id, share] = dominant_object(r.objects, g.truth, 10);
    EXPECT_GT(share, 0.8);
    // Its own object, not a larger one that took it in.
    EXPECT_LT(std::count(r.objects.labels.begin(), r.objects.labels.end(), id), 1.5 * 352);
}

// A generated floor scene (eval/scenegen.py floor tune seed 20047) under the active-stereo
// camera: a ball 10 cm across on the floor, 1 m off. Its lowest visible point lies 3.3 cm
// over the floor (its contact is hidden under it) and the floor under its middle falls at
// its lower outline, which lies nearer than the floor there by less than a depth step, so
// the scope took it for something over the support and left it out. That pixel borders the
// ball's own: its body hides its foot.
TEST(GeneratedScene, BallOnTheFloor_ItsFootBesideItsOutlineIsHidden) {
    // Truth label 2, 3,175 pixels: the ball.
    EXPECT_GT(one_object_share({20047, "active_stereo", "floor"}, 2, 3175), 0.85);  // 0 before
}

// A generated scene (eval/scenegen.py tune seed 23): two plain boxes flush side by side, one
// hue, a light one and a dark one (chromaticities 17 apart, brightness 344 against 223).
// Their contact crosses their shared top and front planes, and the boundary runs along the
// fold between those faces too, where the normals differ by more than the plane's 5 degrees
// but less than the smooth test's 15: 11 of its 16 smooth pairs lie on one plane, every one
// of them a step. Counted against the smooth pairs (70 % needed) the step failed and the
// boxes were one object; counted against the pairs on one plane, they part.
TEST(GeneratedScene, FlushBoxesOfOneHue_PartedByTheStepOnTheirSharedPlanes) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 23);
    auto objects = [&](float min_step) {
        const FrameResult r = process_with(g, [&](SegmentParams& s) { s.colour.min_step = min_step; });
        return std::pair{dominant_object(r.objects, g.truth, 1), dominant_object(r.objects, g.truth, 2)};
    };
    const auto [light_off, dark_off] = objects(0);
    ASSERT_EQ(light_off.first, dark_off.first) << "without the step the boxes should be one object (test premise)";
    const auto [light, dark] = objects(SegmentParams{}.colour.min_step);
    EXPECT_NE(light.first, dark.first) << "the flush boxes were not parted";
    EXPECT_GT(light.second, 0.9);
    EXPECT_GT(dark.second, 0.9);
}

// A generated scene (eval/scenegen.py tune seed 59) under the active-stereo camera: two boxes
// flush side by side, each checked in two colours (red on magenta, green on lilac). 2-means
// followed the checks; four colours made two materials, one of them too small to be tried
// again, and the boxes stayed one object. Where four colours leave a material that small,
// eight are tried, as where the four make one material, and the boxes part.
TEST(GeneratedScene, FlushCheckedBoxes_EightColoursWhereFourLeaveAMaterialTooSmall) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 59, "active_stereo");
    // Truth labels 1 and 2, 6,825 and 6,705 pixels: the boxes.
    ASSERT_EQ(std::count(g.truth.labels.begin(), g.truth.labels.end(), 1), 6825) << "premise: the first box";
    ASSERT_EQ(std::count(g.truth.labels.begin(), g.truth.labels.end(), 2), 6705) << "premise: the second box";
    const FrameResult r = process_default(g);
    const auto [first, first_share] = dominant_object(r.objects, g.truth, 1);
    const auto [second, second_share] = dominant_object(r.objects, g.truth, 2);
    EXPECT_NE(first, second) << "the checked boxes were one object";
    EXPECT_GT(first_share, 0.9);
    EXPECT_GT(second_share, 0.9);
}

// A generated scene (eval/scenegen.py seed 2001, of the range 2000-2099): a cup 3 cm in
// radius seen from above. Its front wall's edge along the inside meets it over 6 boundary
// pairs at --decimate 2, a 1 cm chord, too short an arc for the rim test, so the inside and
// the outer wall stay two objects. The inside's far outline lies on the same rim: with it
// the circle spans the rim and the inside joins.
TEST(GeneratedScene, SmallCup_JoinedAcrossItsFarRim) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 2001);
    auto cup_share = [&](bool far_rim) {
        const FrameResult r = process_with(g, [&](SegmentParams& s) { s.containers.far_rim = far_rim; });
        return dominant_object(r.objects, g.truth, 1).second;  // truth 1: the cup
    };
    ASSERT_LT(cup_share(false), 0.6) << "without the far rim the cup should be in two objects (test premise)";
    EXPECT_GT(cup_share(true), 0.85) << "the cup's inside did not join its outer wall";
}

// A generated scene (eval/scenegen.py seed 1028, of the report range 1000-1099): a cylinder
// stands behind a box, its top at the height of the box's top. The far rim is chosen at the
// front edge's height, so the cylinder's far outline is "a far rim", and a circle through it
// and the box's straight back edge passes the fit and the inside test. The far rim alone
// traces the cylinder's own circle (0.8 cm in radius, against 15.5 cm), so it does not
// agree, and the two stay apart.
TEST(GeneratedScene, CylinderBehindABox_NotJoinedAsItsInside) {
    TempDir dir;
    const GeneratedFrame g = render_generated(dir, 1028);
    auto one_object = [&](float agree) {
        const FrameResult r = process_with(g, [&](SegmentParams& s) { s.containers.far_agree = agree; });
        // truth 2: the cylinder; 3: the box in front of it
        return dominant_object(r.objects, g.truth, 2).first == dominant_object(r.objects, g.truth, 3).first;
    };
    ASSERT_TRUE(one_object(1e9f)) << "with any far rim agreeing, the cylinder should join the box (test premise)";
    EXPECT_FALSE(one_object(SegmentParams{}.containers.far_agree)) << "the cylinder was joined to the box";
}

#endif

// A board lying on the table with boxes on it (DESIGN.md, "Support plane": a low support),
// through the whole pipeline at 640x480 and the default decimation: the board is background,
// each box on it an object of its own, and objects.json gives the board's plane.
TEST(Pipeline, BoardOnTheTable_BackgroundUnderItsBoxes_InObjectsJson) {
    Scene s = board_on_table_scene(0.6f, 0.45f);
    s.width = 640;
    s.height = 480;
    std::vector<int> truth;
    const RgbdFrame frame = render_scene(s, &truth);
    Pipeline pipeline{PipelineParams{}};
    const FrameResult r = pipeline.process(frame);
    ASSERT_TRUE(r.plane.found);
    ASSERT_TRUE(r.plane.low_found);
    const std::vector<std::uint16_t>& objects = r.objects.labels;
    int board_label = -1, first = -1, second = -1;
    EXPECT_GT(dominant_share(objects, truth, kTruthBox0, &board_label), 0.9);
    EXPECT_EQ(board_label, 0);
    EXPECT_GT(dominant_share(objects, truth, kTruthBox0 + 1, &first), 0.8);
    EXPECT_GT(dominant_share(objects, truth, kTruthBox0 + 2, &second), 0.8);
    EXPECT_NE(first, 0);
    EXPECT_NE(second, 0);
    EXPECT_NE(first, second);
    const nlohmann::json doc = nlohmann::json::parse(objects_json(r));
    ASSERT_TRUE(doc["low_support"].is_object());
    EXPECT_FLOAT_EQ(doc["low_support"]["d_m"].get<float>(), r.plane.low_support.d);
    EXPECT_FLOAT_EQ(doc["low_support"]["normal"][1].get<float>(), r.plane.low_support.ny);
}
