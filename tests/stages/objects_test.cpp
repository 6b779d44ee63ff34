#include "wul3d/objects.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <utility>

#include "synthetic_scene.hpp"
#include "wul3d/background.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/error.hpp"
#include "wul3d/normals.hpp"

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

// ---- objects and tracks ----------------------------------------------------------------

#include "wul3d/plane.hpp"
#include "wul3d/segmentation.hpp"

namespace {
struct ObjectRun {
    std::vector<std::vector<std::uint16_t>> objects;  ///< per frame
    std::vector<std::vector<int>> truth;
    int tracks_started = 0;
};

/// A synthetic sequence: a red box slides 2.5 cm a frame past a static blue one, seen by a
/// camera pitched down over the table; every stage from normals to objects runs per frame.
ObjectRun run_moving_sequence(float psi, int frames) {
    ObjectParams op;
    op.psi = psi;
    ObjectTracker tracker(op);
    ObjectRun run;
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active, classes;
    PlaneWorkspace pws;
    SegmentWorkspace sws;
    LabelImage segments, objects;
    std::vector<DetectedObject> list;
    for (int t = 0; t < frames; ++t) {
        Scene s = pitched_tabletop_scene();
        s.noise_seed = static_cast<std::uint32_t>(t + 1);
        SceneBox red;
        red.x = -0.3f + 0.025f * static_cast<float>(t);
        red.z = 0.9f;
        SceneBox blue;
        blue.x = 0.3f;
        blue.z = 1.2f;
        blue.r = 30; blue.g = 60; blue.b = 220;
        s.boxes = {red, blue};
        std::vector<int> truth;
        const RgbdFrame f = render_scene(s, &truth);
        back_project(f, cloud);
        estimate_normals(NormalParams{}, cloud, normals);
        select_depth_range(DepthRange{}, cloud, active);
        const PlaneResult plane =
            remove_support_plane(PlaneParams{}, f.intrinsics, cloud, normals, active, pws, classes);
        const SegmentStats st = segment_objects(SegmentParams{}, cloud, normals, classes,
                                                plane.found ? &plane.support : nullptr,
                                                plane.found && plane.low_found ? &plane.low_support : nullptr,
                                                LabelImage{}, sws, segments);
        tracker.step(cloud, segments, st.segments, LabelImage{}, objects, list);
        // Every listed object is in the label image with its pixel count.
        for (const DetectedObject& d : list) {
            const auto n = static_cast<std::size_t>(std::count(
                objects.labels.begin(), objects.labels.end(), static_cast<std::uint16_t>(d.id)));
            EXPECT_EQ(n, d.pixels);
            EXPECT_EQ(d.id, d.track_id);
            EXPECT_LE(d.u_min, d.u_max);
            for (int a = 0; a < 3; ++a) EXPECT_LE(d.aabb_min[a], d.aabb_max[a]);
        }
        run.objects.push_back(objects.labels);
        run.truth.push_back(truth);
    }
    run.tracks_started = tracker.tracks_started();
    return run;
}

/// Share of pixels whose object changes between consecutive frames while the truth does not.
double flicker(const ObjectRun& run) {
    std::size_t changed = 0, stable = 0;
    for (std::size_t t = 1; t < run.objects.size(); ++t)
        for (std::size_t p = 0; p < run.truth[t].size(); ++p) {
            if (run.truth[t][p] != run.truth[t - 1][p]) continue;
            ++stable;
            changed += run.objects[t][p] != run.objects[t - 1][p];
        }
    return static_cast<double>(changed) / static_cast<double>(stable);
}
}  // namespace

TEST(ObjectParams, Validate_RejectsOutOfRangeFields) {
    ObjectParams p;
    EXPECT_NO_THROW(p.validate());
    p.psi = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p = ObjectParams{};
    p.max_tracks = 1;
    EXPECT_THROW(p.validate(), ParamError);
    EXPECT_THROW(ObjectTracker{p}, ParamError);
}

// Synthetic (rendered) sequence: the moving box keeps one track id in every frame, the
// static box another, no other track is started, and pixels whose truth does not change
// keep their object.
TEST(ObjectTracker, MovingBox_KeepsItsTrackIdAndLabelsDoNotFlicker) {
    const ObjectRun run = run_moving_sequence(0.5f, 16);
    int red0 = 0, blue0 = 0;
    for (std::size_t t = 0; t < run.objects.size(); ++t) {
        SCOPED_TRACE(t);
        int red = 0, blue = 0;
        EXPECT_GT(dominant_share(run.objects[t], run.truth[t], kTruthBox0, &red), 0.9);
        EXPECT_GT(dominant_share(run.objects[t], run.truth[t], kTruthBox0 + 1, &blue), 0.9);
        if (t == 0) {
            red0 = red;
            blue0 = blue;
            EXPECT_NE(red0, 0);
            EXPECT_NE(blue0, 0);
            EXPECT_NE(red0, blue0);
        }
        EXPECT_EQ(red, red0) << "the moving box changed track";
        EXPECT_EQ(blue, blue0) << "the static box changed track";
    }
    EXPECT_EQ(run.tracks_started, 2);
    EXPECT_LT(flicker(run), 0.002);
}

// step() on another cloud than the one observe() saw would mix two frames: an error, and
// the tracker goes on (the next step observes its own cloud).
TEST(ObjectTracker, StepOnAnotherCloudThanObserved_Throws) {
    ObjectTracker tracker(ObjectParams{});
    OrganizedCloud a, b;
    a.resize(40, 30);
    b.resize(40, 30);
    LabelImage segments{40, 30, std::vector<std::uint16_t>(1200, 0)}, objects;
    std::vector<DetectedObject> list;
    tracker.observe(a);
    EXPECT_THROW(tracker.step(b, segments, 0, LabelImage{}, objects, list), std::invalid_argument);
    EXPECT_NO_THROW(tracker.step(b, segments, 0, LabelImage{}, objects, list));
}

// A folder of unrelated frames is a sequence of scene cuts: each frame starts new tracks.
TEST(ObjectTracker, SceneCut_StartsNewTracks) {
    ObjectTracker tracker(ObjectParams{});
    OrganizedCloud cloud;
    cloud.resize(40, 30);
    LabelImage segments{40, 30, std::vector<std::uint16_t>(1200, 0)}, objects;
    std::vector<DetectedObject> list;
    for (int frame = 0; frame < 2; ++frame) {
        for (std::size_t p = 0; p < 1200; ++p) {
            cloud.valid[p] = 1;
            cloud.z[p] = frame == 0 ? 1.0f : 2.0f;  // everything moved by 1 m: a cut
            segments.labels[p] = p % 40 < 20 ? 1 : 0;
        }
        tracker.step(cloud, segments, 1, LabelImage{}, objects, list);
        ASSERT_EQ(list.size(), 1u);
        EXPECT_EQ(list[0].track_id, frame + 1);
    }
    EXPECT_EQ(tracker.scene_cuts(), 1);
}

// Objects rearranged between two shots while the table stays (the OSD captures): most
// object pixels see another surface, so the tracks restart although most of the image (the
// table) did not move; one object sliding a little does not.
TEST(ObjectTracker, ObjectsRearranged_StartNewTracks_ASlidingObjectDoesNot) {
    auto run = [](int shift_px) {
        ObjectTracker tracker(ObjectParams{});
        OrganizedCloud cloud;
        cloud.resize(80, 60);
        const std::size_t N = 80 * 60;
        LabelImage segments{80, 60, std::vector<std::uint16_t>(N, 0)}, objects;
        std::vector<DetectedObject> list;
        for (int frame = 0; frame < 2; ++frame) {
            const int x0 = 20 + frame * shift_px;
            for (std::size_t p = 0; p < N; ++p) {
                const int u = static_cast<int>(p % 80), v = static_cast<int>(p / 80);
                const bool object = u >= x0 && u < x0 + 20 && v >= 20 && v < 40;
                cloud.valid[p] = 1;
                cloud.z[p] = object ? 1.0f : 1.3f;  // a 20 x 20 px block 30 cm before the table
                segments.labels[p] = object ? 1 : 0;
            }
            tracker.step(cloud, segments, 1, LabelImage{}, objects, list);
            EXPECT_EQ(list.size(), 1u);
        }
        return std::pair(tracker.scene_cuts(), list.empty() ? 0 : list[0].track_id);
    };
    const auto moved_far = run(30);   // the block is elsewhere: all its pixels changed
    EXPECT_EQ(moved_far.first, 1);
    EXPECT_EQ(moved_far.second, 2);
    const auto slid = run(3);         // 3 of 20 columns changed: the same object, moved
    EXPECT_EQ(slid.first, 0);
    EXPECT_EQ(slid.second, 1);
}

namespace {

// `frames` frames of a W x 20 scene, pixel(frame, u, v) -> {z, segment label} (every pixel
// has depth; the segments are counted as the largest label), through `tracker`. Returns the
// last frame's object labels, its objects in `list`. `observe_ahead`: each frame's surfaces
// observed (ObjectTracker::observe) before step(), as the pipeline does beside the
// segmentation.
template <class Pixel>
LabelImage track_frames(ObjectTracker& tracker, int W, int frames, Pixel pixel, std::vector<DetectedObject>& list,
                        bool observe_ahead) {
    OrganizedCloud cloud;
    cloud.resize(W, 20);
    const std::size_t N = static_cast<std::size_t>(W) * 20;
    LabelImage segments{W, 20, std::vector<std::uint16_t>(N, 0)}, objects;
    for (int frame = 0; frame < frames; ++frame) {
        int n = 0;
        for (std::size_t p = 0; p < N; ++p) {
            const auto [z, label] = pixel(frame, static_cast<int>(p % static_cast<std::size_t>(W)),
                                          static_cast<int>(p / static_cast<std::size_t>(W)));
            cloud.valid[p] = 1;
            cloud.z[p] = z;
            segments.labels[p] = label;
            n = std::max<int>(n, label);
        }
        if (observe_ahead) tracker.observe(cloud);
        tracker.step(cloud, segments, n, LabelImage{}, objects, list);
    }
    return objects;
}

// track_frames of a scene that depends on the column only: column(frame, u) -> {z, label}.
template <class Column>
LabelImage track_column_frames(ObjectTracker& tracker, int W, int frames, Column column,
                               std::vector<DetectedObject>& list, bool observe_ahead = false) {
    return track_frames(tracker, W, frames, [&](int frame, int u, int) { return column(frame, u); }, list,
                        observe_ahead);
}

// The label of column u on row 10 (track_inner_frames' objects cover it).
std::uint16_t at_row10(const LabelImage& objects, int u) {
    return objects.labels[static_cast<std::size_t>(10 * objects.width + u)];
}

// track_column_frames for objects that do not reach the frame's border: the columns on rows
// 2-17, the table (1.1 m, no segment) on the rows above and below.
template <class Column>
LabelImage track_inner_frames(ObjectTracker& tracker, int W, int frames, Column column,
                              std::vector<DetectedObject>& list) {
    return track_frames(tracker, W, frames, [&](int frame, int u, int v) {
        return v < 2 || v >= 18 ? std::pair<float, std::uint16_t>(1.1f, 0) : column(frame, u);
    }, list, false);
}

}  // namespace

// A pixel whose surface changed forgets its weights: with psi = 0.5 a pixel that held the
// left object for many frames would need two frames of evidence to change object, but when
// the other object arrives over it (depth moved) it changes at once. The same with the
// surfaces observed ahead of step(), as the pipeline does.
TEST(ObjectTracker, PixelWhoseSurfaceChanged_TakesTheNewObjectAtOnce) {
    for (const bool observe_ahead : {false, true}) {
        SCOPED_TRACE(observe_ahead);
        ObjectTracker tracker(ObjectParams{});
        std::vector<DetectedObject> list;
        // Two blocks side by side at 1 m; then the right one grows over columns 25-29, which
        // come 10 cm nearer (a new surface), while the left one keeps columns 10-24.
        const LabelImage objects = track_column_frames(tracker, 60, 6, [](int frame, int u) {
            const int boundary = frame < 5 ? 30 : 25;
            const float z = (frame == 5 && u >= 25 && u < 30) ? 0.9f : 1.0f;
            return std::pair<float, std::uint16_t>(z, u < 10 ? 0 : (u < boundary ? 1 : 2));
        }, list, observe_ahead);
        ASSERT_EQ(list.size(), 2u);
        const std::uint16_t right = objects.labels[45], left = objects.labels[15];
        EXPECT_NE(right, left);
        for (int u = 25; u < 30; ++u) EXPECT_EQ(objects.labels[static_cast<std::size_t>(u)], right) << u;
        EXPECT_EQ(tracker.scene_cuts(), 0);
    }
}

// An object put down on another (a box on a board) covers most of it: its pixels held the
// board's weights, but their surface changed, so they do not vote for the matching. The
// board keeps its track, and its pixels, which still hold that track, are not taken into
// the new object's. A third object stands by, unchanged: not a scene rearranged.
TEST(ObjectTracker, ObjectPutDownOnAnother_BothKeepTheirOwnTracks) {
    ObjectTracker tracker(ObjectParams{});
    std::vector<DetectedObject> list;
    // A board over columns 10-49 at 1 m, an object over 55-99; then a box on the board's
    // columns 20-49, 10 cm nearer.
    const LabelImage objects = track_column_frames(tracker, 100, 6, [](int frame, int u) {
        const bool on_box = frame == 5 && u >= 20 && u < 50;
        const std::uint16_t label = u < 10 || (u >= 50 && u < 55) ? 0 : (u >= 55 ? 1 : (on_box ? 3 : 2));
        return std::pair<float, std::uint16_t>(on_box ? 0.9f : 1.0f, label);
    }, list);
    ASSERT_EQ(list.size(), 3u);
    EXPECT_EQ(tracker.scene_cuts(), 0);
    const std::uint16_t board = objects.labels[15], on_top = objects.labels[35];
    EXPECT_EQ(board, 2) << "the board keeps its track";
    EXPECT_EQ(on_top, 3) << "the box starts a track of its own";
    for (int u = 10; u < 20; ++u) EXPECT_EQ(objects.labels[static_cast<std::size_t>(u)], board) << u;
}

// Objects put down one at a time against a pile (OCID's sequences): the segmentation joins
// the newcomer to the object it touches, but its surface came nearer (the table was there)
// while the old object lost nothing, so it starts a track of its own; in the frames after,
// the old object's track continues the joined segment and the newcomer's is held where its
// pixels' weights favour it.
TEST(ObjectTracker, ObjectPutDownAgainstAnother_StartsItsOwnTrackThoughOneSegment) {
    ObjectTracker tracker(ObjectParams{});
    std::vector<DetectedObject> list;
    std::vector<LabelImage> frames;
    // The table at 1.1 m; an object over columns 10-39 at 1 m; from frame 5 on another
    // against it over columns 40-59, both one segment.
    for (int frame = 0; frame < 9; ++frame) {
        const LabelImage objects = track_inner_frames(tracker, 100, 1, [frame](int, int u) {
            const bool old_one = u >= 10 && u < 40, newcomer = frame >= 5 && u >= 40 && u < 60;
            return std::pair<float, std::uint16_t>(old_one || newcomer ? 1.0f : 1.1f, old_one || newcomer ? 1 : 0);
        }, list);
        if (frame >= 5) frames.push_back(objects);
    }
    EXPECT_EQ(tracker.scene_cuts(), 0);
    for (std::size_t f = 0; f < frames.size(); ++f) {
        SCOPED_TRACE(f);
        const LabelImage& objects = frames[f];
        const std::uint16_t old_one = at_row10(objects, 20), newcomer = at_row10(objects, 50);
        EXPECT_NE(old_one, 0);
        EXPECT_NE(newcomer, 0);
        EXPECT_NE(newcomer, old_one) << "the newcomer is an object of its own";
        for (int u = 10; u < 40; ++u) EXPECT_EQ(at_row10(objects, u), old_one) << u;
        for (int u = 40; u < 60; ++u) EXPECT_EQ(at_row10(objects, u), newcomer) << u;
        if (f > 0) {
            EXPECT_EQ(newcomer, at_row10(frames[0], 50)) << "and keeps its track";
        }
    }
}

// An object that slides within its segment gains surface on one side (nearer than the table
// it covers) and vacates as much on the other: no arrival, one track.
TEST(ObjectTracker, ObjectSlidingInOneSegment_KeepsOneTrack) {
    ObjectTracker tracker(ObjectParams{});
    std::vector<DetectedObject> list;
    std::uint16_t first = 0;
    for (int frame = 0; frame < 8; ++frame) {
        SCOPED_TRACE(frame);
        const int left = 10 + 8 * frame;  // 8 columns (160 pixels) a frame
        const LabelImage objects = track_inner_frames(tracker, 120, 1, [left](int, int u) {
            const bool on = u >= left && u < left + 30;
            return std::pair<float, std::uint16_t>(on ? 1.0f : 1.1f, on ? 1 : 0);
        }, list);
        ASSERT_EQ(list.size(), 1u);
        if (frame == 0) first = at_row10(objects, left);
        for (int u = left; u < left + 30; ++u) EXPECT_EQ(at_row10(objects, u), first) << u;
    }
    EXPECT_EQ(tracker.tracks_started(), 1);
}

// An object in front of another is taken away: the surface behind it comes back, farther
// than the object was. That is no arrival: the object behind stays one.
TEST(ObjectTracker, SurfaceSeenAgainBehindARemovedObject_IsNoArrival) {
    ObjectTracker tracker(ObjectParams{});
    std::vector<DetectedObject> list;
    // The table at 1.1 m; a board over columns 10-59 at 1 m, and until frame 5 a box in front
    // of it over columns 25-44 at 0.9 m.
    const LabelImage objects = track_inner_frames(tracker, 100, 8, [](int frame, int u) {
        const bool box = frame < 5 && u >= 25 && u < 45, board = u >= 10 && u < 60 && !box;
        return std::pair<float, std::uint16_t>(box ? 0.9f : (board ? 1.0f : 1.1f), box ? 2 : (board ? 1 : 0));
    }, list);
    ASSERT_EQ(list.size(), 1u);
    for (int u = 10; u < 60; ++u) EXPECT_EQ(at_row10(objects, u), at_row10(objects, 10)) << u;
    EXPECT_EQ(tracker.tracks_started(), 2) << "the board and the box, no third";
}

// An object coming into view at the frame's border grows by a surface nearer than the table
// without vacating any: its segment, cut by the border, is left as it is.
TEST(ObjectTracker, ObjectComingIntoView_KeepsOneTrack) {
    ObjectTracker tracker(ObjectParams{});
    std::vector<DetectedObject> list;
    const LabelImage objects = track_inner_frames(tracker, 100, 6, [](int frame, int u) {
        const bool on = u < 10 + 10 * frame;  // 10 columns (200 pixels) more a frame
        return std::pair<float, std::uint16_t>(on ? 1.0f : 1.1f, on ? 1 : 0);
    }, list);
    ASSERT_EQ(list.size(), 1u);
    EXPECT_EQ(tracker.tracks_started(), 1);
    for (int u = 0; u < 60; ++u) EXPECT_EQ(at_row10(objects, u), at_row10(objects, 0)) << u;
}

// Two objects seen apart, then joined by the segmentation (touching in a pile): each keeps
// its track, their unchanged pixels staying with the object their weights favour. Seen
// joined first and then apart, the part that splits off starts a track of its own: a
// segment that starts a track takes its pixels.
TEST(ObjectTracker, ObjectsJoinedBySegmentation_KeepTheirTracks_PartedStartOne) {
    for (const bool apart_first : {true, false}) {
        SCOPED_TRACE(apart_first);
        ObjectTracker tracker(ObjectParams{});
        std::vector<DetectedObject> list;
        std::uint16_t left = 0, right = 0;
        for (int frame = 0; frame < 9; ++frame) {
            const bool apart = (frame < 5) == apart_first;
            const LabelImage objects = track_inner_frames(tracker, 100, 1, [apart](int, int u) {
                const bool on = u >= 10 && u < 60;
                return std::pair<float, std::uint16_t>(on ? 1.0f : 1.1f, on ? (apart && u >= 35 ? 2 : 1) : 0);
            }, list);
            if (frame == 4 && apart_first) left = at_row10(objects, 20), right = at_row10(objects, 50);
            // Parted, from the frame after (psi = 0.5 asks two frames of evidence).
            if (frame < 5 || (!apart_first && frame == 5)) continue;
            SCOPED_TRACE(frame);
            EXPECT_NE(at_row10(objects, 20), at_row10(objects, 50));
            for (int u = 10; u < 35; ++u) EXPECT_EQ(at_row10(objects, u), at_row10(objects, 20)) << u;
            for (int u = 35; u < 60; ++u) EXPECT_EQ(at_row10(objects, u), at_row10(objects, 50)) << u;
            if (apart_first) {
                EXPECT_EQ(at_row10(objects, 20), left);
                EXPECT_EQ(at_row10(objects, 50), right);
            }
        }
    }
}

// More segments than track slots (a crowded frame, or a low min_points): the largest start
// tracks, the smallest are dropped. Here two slots, and two narrow segments on the left
// before a wide one in the order segments are numbered; the wide one took no slot before.
TEST(ObjectTracker, MoreSegmentsThanSlots_TheLargestStartTracks) {
    ObjectParams params;
    params.max_tracks = 2;
    params.min_points = 1;
    ObjectTracker tracker(params);
    std::vector<DetectedObject> list;
    const LabelImage objects = track_inner_frames(tracker, 60, 1, [](int, int u) {
        const std::uint16_t label = u >= 2 && u < 4 ? 1 : u >= 6 && u < 9 ? 2 : u >= 20 && u < 50 ? 3 : 0;
        return std::pair<float, std::uint16_t>(label ? 1.0f : 1.1f, label);
    }, list);
    ASSERT_EQ(list.size(), 2u);
    EXPECT_NE(at_row10(objects, 35), 0) << "the wide segment";
    EXPECT_NE(at_row10(objects, 7), 0) << "the wider of the narrow two";
    EXPECT_EQ(at_row10(objects, 2), 0) << "the narrowest, dropped";
}
