#include "wul3d/plane.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <cstddef>
#include <string>
#include <utility>

#include "synthetic_scene.hpp"
#include "test_support.hpp"
#include "wul3d/background.hpp"
#include "wul3d/decimation.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/normals.hpp"
#include "wul3d/segmentation.hpp"

using namespace wul3d;
using namespace wul3d::test;

namespace {
struct Prepared {
    RgbdFrame frame;
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;

    PlaneResult remove_plane(const PlaneParams& params, PlaneWorkspace& ws, std::vector<std::uint8_t>& classes,
                             float noise_widening = 1.0f) const {
        return remove_support_plane(params, frame.intrinsics, cloud, normals, active, ws, classes, noise_widening);
    }
};

/// The frame back-projected, with its normals and depth-range mask (the pipeline's defaults;
/// with `radius_from_noise` the normals' radius chosen by the measured noise, as the pipeline
/// chooses it).
Prepared prepared(RgbdFrame frame, bool radius_from_noise = false) {
    Prepared f;
    f.frame = std::move(frame);
    back_project(f.frame, f.cloud);
    NormalParams normal_params;
    if (radius_from_noise) {
        std::vector<float> scratch;
        const float noise = measure_depth_noise(f.cloud, static_cast<float>(f.frame.intrinsics.fx), scratch);
        normal_params.radius_px = normal_radius_for(normal_params, noise);
    }
    estimate_normals(normal_params, f.cloud, f.normals);
    select_depth_range(DepthRange{}, f.cloud, f.active);
    return f;
}

/// Six books 2 cm thick lying flat, 0.3 m deep and `width` wide, at x in `xs` and z in `zs`
/// (ground-truth ids kTruthBox0 to kTruthBox0 + 5).
void add_books(Scene& s, const float (&xs)[3], const float (&zs)[2], float width) {
    for (float x : xs)
        for (float z : zs) {
            SceneBox book;
            book.x = x;
            book.z = z;
            book.w = width;
            book.d = 0.3f;
            book.h = 0.02f;
            s.boxes.push_back(book);
        }
}

/// The table's active points, their heights over the support, and the books' points kept.
struct TableAndBooks {
    std::size_t table = 0, books = 0, books_kept = 0;
    double height_sum = 0, height_sum2 = 0;
    double mean_height() const { return height_sum / static_cast<double>(table); }
    double height_spread() const {
        const double m = mean_height();
        return std::sqrt(height_sum2 / static_cast<double>(table) - m * m);
    }
    double books_kept_share() const {
        return static_cast<double>(books_kept) / static_cast<double>(books);
    }
};

/// Of `f`'s active pixels whose ground truth is `id`: how many, and how many plane removal
/// kept (`classes`).
struct KeptCount {
    std::size_t points = 0, kept = 0;
    double share() const { return static_cast<double>(kept) / static_cast<double>(points); }
};
KeptCount kept_of(const Prepared& f, const std::vector<std::uint8_t>& classes, const std::vector<int>& truth,
                  int id) {
    KeptCount k;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (!f.active[p] || truth[p] != id) continue;
        ++k.points;
        k.kept += classes[p] != kPlaneRemoved;
    }
    return k;
}

/// Pixels of ground truth `id` on row v of a w-wide truth image, and on column u of one h high.
int truth_on_row(const std::vector<int>& truth, int w, int v, int id) {
    const auto row = truth.begin() + static_cast<std::ptrdiff_t>(v) * w;
    return static_cast<int>(std::count(row, row + w, id));
}
int truth_on_column(const std::vector<int>& truth, int w, int h, int u, int id) {
    int n = 0;
    for (int v = 0; v < h; ++v) n += truth[static_cast<std::size_t>(v) * w + u] == id;
    return n;
}

/// Plane removal on `f` with the default parameters.
struct Removal {
    PlaneResult result;
    std::vector<std::uint8_t> classes;
};
Removal remove_with_defaults(const Prepared& f) {
    PlaneWorkspace ws;
    Removal out;
    out.result = f.remove_plane(PlaneParams{}, ws, out.classes);
    return out;
}

/// Tallies `f` after plane removal; `truth_of(p)` gives pixel p's ground-truth id.
template <class TruthOf>
TableAndBooks tally(const Prepared& f, const PlaneResult& r, const std::vector<std::uint8_t>& classes,
                    TruthOf&& truth_of) {
    TableAndBooks t;
    for (std::size_t p = 0; p < f.cloud.size(); ++p) {
        if (!f.active[p]) continue;
        const int truth = truth_of(p);
        if (truth == kTruthTable) {
            ++t.table;
            const double h = r.support.height(f.cloud.x[p], f.cloud.y[p], f.cloud.z[p]);
            t.height_sum += h;
            t.height_sum2 += h * h;
        } else if (truth >= kTruthBox0 && truth < kTruthBox0 + 6) {
            ++t.books;
            t.books_kept += classes[p] != kPlaneRemoved;
        }
    }
    return t;
}
}  // namespace

TEST(PlaneParams, Validate_RejectsOutOfRangeFields) {
    PlaneParams p;
    EXPECT_NO_THROW(p.validate());
    p.on_plane_m = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p = PlaneParams{};
    p.grid_stride_px = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p = PlaneParams{};
    p.min_up = 2;
    EXPECT_THROW(p.validate(), ParamError);
}

// A camera pitched down 35 degrees over a table with two boxes and a back wall: the
// support is the table (not the wall, which faces the camera), its normal is the table's,
// the table goes and the boxes stay, their feet included.
namespace {
/// A camera pitched down 35 degrees over a table from 0.4 to 1.6 m, two boxes on it
/// (kTruthBox0 at x = -0.15 m, z = 0.9 m; the next at 0.2 m, 1.1 m).
Scene tilted_table_scene() {
    Scene s;
    s.width = 320;
    s.height = 240;
    s.pitch_rad = 35.0f * 3.14159265f / 180.0f;
    s.table_y = 0.6f;
    s.table_near = 0.4f;
    s.table_far = 1.6f;
    SceneBox a;
    a.x = -0.15f;
    a.z = 0.9f;
    SceneBox b = a;
    b.x = 0.2f;
    b.z = 1.1f;
    b.r = 30; b.g = 60; b.b = 220;
    s.boxes = {a, b};
    return s;
}
}  // namespace

TEST(RemoveSupportPlane, TiltedTable_RemovesTableKeepsBoxesAndTheirFeet) {
    Scene s = tilted_table_scene();
    s.wall = true;
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
    ASSERT_TRUE(r.found);
    // The table's normal in the camera frame: up in the scene is -y; the camera pitched down
    // by theta sees it as (0, -cos theta, -sin theta).
    EXPECT_NEAR(r.support.nx, 0.0f, 0.02f);
    EXPECT_NEAR(r.support.ny, -std::cos(s.pitch_rad), 0.02f);
    EXPECT_NEAR(r.support.nz, -std::sin(s.pitch_rad), 0.02f);
    std::size_t table = 0, table_kept = 0, wall = 0, wall_kept = 0;
    std::size_t box[2] = {0, 0}, box_kept[2] = {0, 0};
    for (std::size_t p = 0; p < truth.size(); ++p) {
        const bool kept = classes[p] != kPlaneRemoved;
        if (truth[p] == kTruthTable) { ++table; table_kept += kept; }
        if (truth[p] == kTruthWall) { ++wall; wall_kept += kept; }
        for (int i = 0; i < 2; ++i)
            if (truth[p] == kTruthBox0 + i) { ++box[i]; box_kept[i] += kept; }
    }
    ASSERT_GT(table, 10000u);
    EXPECT_LT(static_cast<double>(table_kept) / static_cast<double>(table), 0.005);
    // The wall stands off the table's extent: not an object on it.
    if (wall > 0) {
        EXPECT_LT(static_cast<double>(wall_kept) / static_cast<double>(wall), 0.02);
    }
    for (int i = 0; i < 2; ++i) {
        ASSERT_GT(box[i], 500u);
        EXPECT_GT(static_cast<double>(box_kept[i]) / static_cast<double>(box[i]), 0.97) << "box " << i;
    }
}

namespace {

/// A camera 1 m over a wide table, pitched down by `pitch_deg`, the table from 0.8 m behind
/// it to `table_far` before it, one box (kTruthBox0) at x = 0.1 m, z = `box_z`.
Scene looking_down_scene(float pitch_deg, float table_far, float box_z) {
    Scene s = pitched_tabletop_scene();
    s.pitch_rad = pitch_deg * 3.14159265f / 180.0f;
    s.table_y = 1.0f;
    s.table_near = -0.8f;
    s.table_far = table_far;
    s.table_half_width = 1.0f;
    SceneBox a;
    a.x = 0.1f;
    a.z = box_z;
    s.boxes = {a};
    return s;
}

}  // namespace

// A camera looking down at 80 degrees (an OCID-like pile seen from above): the table faces
// up in the image only by cos 80 = 0.17, which the support's facing test must still take,
// while a wall facing any camera that looks down has -n_y <= 0.
TEST(RemoveSupportPlane, CameraLookingAlmostStraightDown_TheTableIsTheSupport) {
    const Scene s = looking_down_scene(80.0f, 1.2f, 0.2f);
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
    ASSERT_TRUE(r.found);
    EXPECT_GE(r.support.up, PlaneParams{}.min_up);  // taken as facing up
    EXPECT_NEAR(r.support.ny, -std::cos(s.pitch_rad), 0.02f);
    EXPECT_NEAR(r.support.nz, -std::sin(s.pitch_rad), 0.02f);
    std::size_t table = 0, table_kept = 0, box = 0, box_kept = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        const bool kept = classes[p] != kPlaneRemoved;
        if (truth[p] == kTruthTable) { ++table; table_kept += kept; }
        if (truth[p] == kTruthBox0) { ++box; box_kept += kept; }
    }
    ASSERT_GT(table, 10000u);
    EXPECT_LT(static_cast<double>(table_kept) / static_cast<double>(table), 0.005);
    ASSERT_GT(box, 500u);
    EXPECT_GT(static_cast<double>(box_kept) / static_cast<double>(box), 0.97);
}

// A box standing where the frame's bottom cuts it, on a table that runs on out of the
// frame toward the camera: its nearest points' feet (moved down the table's normal) fall
// below the frame, off the image. They are tested on the frame's bottom row, which the
// table's extent reaches: the box is kept whole, the table under it still removed.
TEST(RemoveSupportPlane, BoxCutByTheFramesBottom_KeptWhereTheTableRunsOn) {
    Scene s = pitched_tabletop_scene();
    SceneBox near_box;
    near_box.z = 0.5f;
    near_box.d = 0.1f;
    near_box.h = 0.1f;
    SceneBox far_box = near_box;
    far_box.x = 0.25f;
    far_box.z = 1.1f;
    s.boxes = {near_box, far_box};
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    // Premise: the frame's bottom row shows the near box and the table beside it.
    ASSERT_GT(truth_on_row(truth, s.width, s.height - 1, kTruthBox0), 10);
    ASSERT_GT(truth_on_row(truth, s.width, s.height - 1, kTruthTable), 100);
    const Removal rm = remove_with_defaults(f);
    ASSERT_TRUE(rm.result.found);
    EXPECT_LT(kept_of(f, rm.classes, truth, kTruthTable).share(), 0.005);
    for (int i = 0; i < 2; ++i) {
        const KeptCount box = kept_of(f, rm.classes, truth, kTruthBox0 + i);
        ASSERT_GT(box.points, 500u);
        EXPECT_GT(box.share(), 0.97) << "box " << i;
    }
}

// A large box in the frame's bottom-right corner, on a table that runs out of the frame at
// the bottom and at the right: the table's points reach both edges but not the corner,
// which the box hides, and the hull of those points cuts across the box. The corner joins
// the hull where the table reaches both edges: the box is kept whole.
TEST(RemoveSupportPlane, BoxInTheFramesNearCorner_KeptWhereTheTableRunsOutOnBothSides) {
    Scene s = pitched_tabletop_scene();
    SceneBox corner_box;
    corner_box.x = 0.24f;
    corner_box.z = 0.58f;
    corner_box.w = 0.3f;
    corner_box.d = 0.25f;
    corner_box.h = 0.15f;
    s.boxes = {corner_box};
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    // Premise: the box fills the corner, and the table shows on the bottom row and on the
    // right column.
    ASSERT_EQ(truth[truth.size() - 1], kTruthBox0);
    ASSERT_GT(truth_on_row(truth, s.width, s.height - 1, kTruthTable), 20);
    ASSERT_GT(truth_on_column(truth, s.width, s.height, s.width - 1, kTruthTable), 20);
    const Removal rm = remove_with_defaults(f);
    ASSERT_TRUE(rm.result.found);
    EXPECT_LT(kept_of(f, rm.classes, truth, kTruthTable).share(), 0.005);
    const KeptCount box = kept_of(f, rm.classes, truth, kTruthBox0);
    ASSERT_GT(box.points, 2000u);
    EXPECT_GT(box.share(), 0.97);
}

// A camera looking straight down on the table (OCID's and the pile family's steepest views):
// the table faces the camera as a wall would, up in the image by nothing. No plane faces up,
// and among those that face any way, the one that holds the box is the support.
TEST(RemoveSupportPlane, CameraLookingStraightDown_TheTableHoldingTheBoxIsTheSupport) {
    const Scene s = looking_down_scene(90.0f, 0.8f, 0.1f);
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    const Removal r = remove_with_defaults(f);
    ASSERT_TRUE(r.result.found);
    EXPECT_LT(r.result.support.up, PlaneParams{}.min_up) << "the fallback to any facing took it";
    EXPECT_NEAR(r.result.support.nz, -1.0f, 0.02f);
    EXPECT_LT(kept_of(f, r.classes, truth, kTruthTable).share(), 0.005);
    const KeptCount box = kept_of(f, r.classes, truth, kTruthBox0);
    ASSERT_GT(box.points, 500u);
    EXPECT_GT(box.share(), 0.95);
}

// Only a wall in view, nothing in front of it: no plane faces up, and none holds anything.
TEST(RemoveSupportPlane, NoUpFacingPlane_KeepsEveryActivePoint) {
    // Only a wall in view: nothing faces up, so there is no support.
    Scene s;
    s.wall = true;
    s.table_half_width = 0.0f;
    Prepared f = prepared(render_scene(s));
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
    EXPECT_FALSE(r.found);
    std::size_t active = 0;
    for (auto a : f.active) active += a;
    EXPECT_EQ(r.kept, active);
}

// Flat objects over much of the table (six books, 2 cm thick): their tops are within the
// merge distance of the table's pieces, and the plane fitted to both lay 7.6 mm above the
// table, in whose band 45 % of the books' points fell. The support is refined on the
// table's own points: they lie on it, and the books stand on it.
TEST(RemoveSupportPlane, BooksCoveringTheTable_SupportStaysOnTheTable) {
    Scene s = pitched_tabletop_scene();
    add_books(s, {-0.3f, 0.05f, 0.35f}, {0.8f, 1.15f}, 0.26f);
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
    ASSERT_TRUE(r.found);
    const TableAndBooks t = tally(f, r, classes, [&](std::size_t p) { return truth[p]; });
    ASSERT_GT(t.table, 5000u);
    ASSERT_GT(t.books, 10000u);
    EXPECT_LT(std::fabs(t.mean_height()), 0.001);
    EXPECT_GT(t.books_kept_share(), 0.95);
}

// Books over the far half of the table only: the plane fitted to the chain of the near
// table and the books' tops is tilted, a ramp from one to the other. Over it the table's
// points spread across several half bands and the densest band held the ramp: the table
// lay 2 mm under the support on average with a spread of 5 mm (standard deviation), and a
// third of the books' points went with it (two thirds at N = 2). The lowest band with many
// points is the table.
TEST(RemoveSupportPlane, BooksOnTheFarHalf_SupportIsTheTableNotARamp) {
    Scene s = pitched_tabletop_scene();
    add_books(s, {-0.3f, 0.05f, 0.35f}, {1.0f, 1.4f}, 0.3f);
    std::vector<int> full_truth;
    const RgbdFrame full = render_scene(s, &full_truth);
    for (int n : {1, 2}) {
        SCOPED_TRACE("decimation " + std::to_string(n));
        RgbdFrame frame;
        decimate_frame(full, n, frame);
        Prepared f = prepared(std::move(frame));
        PlaneWorkspace ws;
        std::vector<std::uint8_t> classes;
        const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
        ASSERT_TRUE(r.found);
        const std::size_t W = static_cast<std::size_t>(f.frame.width());
        const TableAndBooks t = tally(f, r, classes, [&](std::size_t p) {
            return full_truth[(p / W) * n * full.width() + (p % W) * n];
        });
        ASSERT_GT(t.table, 20000u / (n * n));
        ASSERT_GT(t.books, 10000u / (n * n));
        EXPECT_LT(std::fabs(t.mean_height()), 0.001);
        EXPECT_LT(t.height_spread(), 0.001);
        EXPECT_GT(t.books_kept_share(), 0.95);
    }
}

// Real uncropped tabletop frames (data/samples/uois_tabletop, MIT): floor, walls, chairs
// and other furniture are in view. The support must be the table under the objects: a
// patch of that table, picked by eye in each frame, is removed and the support's normal is
// the patch's; objects remain, and the room (floor, walls) does not.
TEST(RemoveSupportPlane, RealUncroppedTabletops_ChoosesTheTableUnderTheObjects) {
    struct TablePatch {
        const char* frame;
        int u, v;
    };
    const TablePatch patches[] = {{"image_0000", 320, 455}, {"image_0002", 320, 440},
                                  {"image_0005", 300, 250}, {"image_0007", 330, 380}};
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    ASSERT_EQ(source->size(), 4u);
    SourceItem item;
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    for (std::size_t i = 0; i < source->size(); ++i) {
        source->read(i, item);
        SCOPED_TRACE(item.frame.name);
        ASSERT_EQ(item.frame.name, patches[i].frame);
        Prepared f = prepared(item.frame);
        const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
        ASSERT_TRUE(r.found);
        EXPECT_GT(r.support.up, 0.5f);
        const int W = f.cloud.width;
        std::size_t patch = 0, removed = 0;
        double mx = 0, my = 0, mz = 0, height = 0;
        for (int v = patches[i].v - 10; v <= patches[i].v + 10; ++v)
            for (int u = patches[i].u - 10; u <= patches[i].u + 10; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                if (!f.active[p] || !f.normals.valid[p]) continue;
                ++patch;
                removed += classes[p] == kPlaneRemoved;
                mx += f.normals.nx[p];
                my += f.normals.ny[p];
                mz += f.normals.nz[p];
                height += r.support.height(f.cloud.x[p], f.cloud.y[p], f.cloud.z[p]);
            }
        ASSERT_GT(patch, 300u);
        EXPECT_GT(static_cast<double>(removed) / static_cast<double>(patch), 0.95);
        // The patch lies on the support ...
        EXPECT_LT(std::fabs(height / static_cast<double>(patch)), 0.003);
        // ... and faces like it, within what the sensor's depth wobble leaves of a 21 x 21
        // patch: image_0005's patch is 8 degrees off the plane of the whole table, and 2 off
        // that of the 61 x 61 pixels around it.
        const double len = std::sqrt(mx * mx + my * my + mz * mz);
        const double cos_angle = (mx * r.support.nx + my * r.support.ny + mz * r.support.nz) / len;
        EXPECT_GT(cos_angle, std::cos(10.0 * 3.14159265 / 180.0));
        std::size_t kept = 0, active = 0;
        for (std::size_t p = 0; p < classes.size(); ++p) {
            active += f.active[p];
            kept += classes[p] != kPlaneRemoved;
        }
        EXPECT_GT(kept, 5000u);
        EXPECT_LT(static_cast<double>(kept) / static_cast<double>(active), 0.45);
    }
}

// A sliver is not the support. In image_0005 (a low table on a carpet), on the frame
// decimated 2 x 2, a few carpet points at the table's feet give a plane 4 degrees off the
// floor's: it cuts through the floor, and the table top, under 0.5 m above the floor,
// stood on it in greater number than the objects on the table. Most of its inliers are the
// floor's, so it is not scored: the support is the table, as at full resolution.
TEST(RemoveSupportPlane, RealTabletopHalfResolution_SliverOfTheFloorIsNotTheSupport) {
    auto source = open_source((sample_dir() / "uois_tabletop").string(), SourceOptions{});
    SourceItem item;
    source->read(2, item);
    ASSERT_EQ(item.frame.name, "image_0005");
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    Prepared full = prepared(item.frame);
    const PlaneResult at_full = full.remove_plane(PlaneParams{}, ws, classes);
    ASSERT_TRUE(at_full.found);
    RgbdFrame small;
    decimate_frame(item.frame, 2, small);
    const Prepared half = prepared(small);
    // A grid of every 2nd pixel, where the sliver forms (the pipeline's grid at N = 2 is
    // every 4th decimated pixel, too coarse for it to form at all).
    PlaneParams params;
    params.grid_stride_px = 2;
    params.hull_margin_px = 6;
    const PlaneResult r = half.remove_plane(params, ws, classes);
    ASSERT_TRUE(r.found);
    const Plane& s = r.support;
    EXPECT_GT(s.nx * at_full.support.nx + s.ny * at_full.support.ny + s.nz * at_full.support.nz,
              std::cos(2.0 * 3.14159265 / 180));
    EXPECT_NEAR(s.d, at_full.support.d, 0.01);
    // The sliver is there, and would have won: an upward candidate near the floor (within
    // 6 degrees and 5 cm) besides the floor itself, not counted.
    int near_floor = 0, not_counted = 0;
    for (const Plane& c : r.candidates) {
        if (c.up < params.min_up || std::fabs(c.d - 0.95f) > 0.05f) continue;
        ++near_floor;
        not_counted += c.above == 0;
    }
    EXPECT_EQ(near_floor, 2);
    EXPECT_EQ(not_counted, 1);
}

// A small table 0.75 m high with boxes on it, on a floor that runs out to a wall: the floor
// is larger than the table, and its legs and the wall's foot stand on it (as in the whole-room
// scenes of eval/scenegen.py, tune seeds 20, 38, 80). They rise higher over the floor than
// anything that stands on it (the table top over the legs, the wall), so they do not count:
// the support is the table that holds the boxes, which are kept.
TEST(RemoveSupportPlane, SmallTableOverALargerFloor_SupportIsTheTable) {
    Scene s = pitched_tabletop_scene();
    s.table_y = 0.7f;
    s.floor_y = 1.45f;
    s.wall = true;
    s.table_half_width = 0.4f;
    s.table_near = 0.9f;
    s.table_far = 1.5f;
    for (const float z : {1.05f, 1.3f})
        for (const float x : {-0.22f, 0.0f, 0.22f}) {
            SceneBox b;
            b.x = x;
            b.z = z;
            b.w = b.d = 0.12f;
            b.h = 0.15f;
            s.boxes.push_back(b);
        }
    for (const float x : {-0.37f, 0.37f})
        for (const float z : {0.93f, 1.47f}) {
            SceneBox leg;
            leg.x = x;
            leg.z = z;
            leg.w = leg.d = 0.05f;
            leg.h = s.floor_y - s.table_y;
            leg.r = leg.g = leg.b = 120;
            s.floor_boxes.push_back(leg);
        }
    std::vector<int> truth;
    Prepared f = prepared(render_scene(s, &truth));
    std::size_t table = 0, floor = 0, box = 0, box_kept = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (!f.active[p]) continue;
        table += truth[p] == kTruthTable;
        floor += truth[p] == kTruthFloor;
    }
    ASSERT_GT(floor, table * 3 / 2);  // the floor is the larger surface
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
    ASSERT_TRUE(r.found);
    // The table is 0.7 m under the camera: along the normal, d is that distance.
    EXPECT_NEAR(r.support.d, s.table_y, 0.01);
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (!f.active[p] || truth[p] < kTruthBox0 || truth[p] >= kTruthBox0 + 6) continue;
        ++box;
        box_kept += classes[p] != kPlaneRemoved;
    }
    ASSERT_GT(box, 300u);
    EXPECT_GT(static_cast<double>(box_kept) / static_cast<double>(box), 0.95);
}

// A container's inside seen through its opening: a patch enclosed by a box's pixels is
// replaced by the table surface raised by `lift` (a bowl's inner bottom). Raised by 6 mm it
// is given back to the objects (kPlaneInside) and segmentation joins it to the box; flush
// with the table it is table seen through a gap, and goes.
TEST(RemoveSupportPlane, EnclosedPatchAboveThePlane_IsAContainersInside) {
    for (const float lift : {0.006f, 0.0f}) {
        SCOPED_TRACE(lift);
        Scene s = pitched_tabletop_scene();
        SceneBox box;
        box.x = 0.0f;
        box.z = 1.0f;
        box.w = box.d = 0.25f;
        box.h = 0.1f;
        s.boxes = {box};
        std::vector<int> truth;
        Prepared f = prepared(render_scene(s, &truth));
        PlaneWorkspace ws;
        std::vector<std::uint8_t> classes;
        const PlaneResult first = f.remove_plane(PlaneParams{}, ws, classes);
        ASSERT_TRUE(first.found);
        // The patch: box pixels at least 12 px inside the box's image region.
        const int W = f.cloud.width, H = f.cloud.height;
        std::vector<std::uint8_t> patch(truth.size(), 0);
        std::size_t patch_size = 0;
        for (int v = 12; v < H - 12; ++v)
            for (int u = 12; u < W - 12; ++u) {
                bool inside = true;
                for (int d = -12; d <= 12 && inside; d += 3)
                    inside = truth[static_cast<std::size_t>(v + d) * W + u] == kTruthBox0 &&
                             truth[static_cast<std::size_t>(v) * W + u + d] == kTruthBox0;
                if (!inside) continue;
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                // Move the point along its ray onto the plane raised by `lift`.
                const Plane& pl = first.support;
                const float dx = f.cloud.x[p] / f.cloud.z[p], dy = f.cloud.y[p] / f.cloud.z[p];
                const float t = (lift - pl.d) / (pl.nx * dx + pl.ny * dy + pl.nz);
                f.cloud.x[p] = t * dx;
                f.cloud.y[p] = t * dy;
                f.cloud.z[p] = t;
                patch[p] = 1;
                ++patch_size;
            }
        ASSERT_GT(patch_size, 300u);
        estimate_normals(NormalParams{}, f.cloud, f.normals);
        f.remove_plane(PlaneParams{}, ws, classes);
        std::size_t inside = 0, removed = 0;
        for (std::size_t p = 0; p < patch.size(); ++p) {
            if (!patch[p]) continue;
            inside += classes[p] == kPlaneInside;
            removed += classes[p] == kPlaneRemoved;
        }
        if (lift > 0) {
            EXPECT_GT(static_cast<double>(inside) / static_cast<double>(patch_size), 0.9);
            SegmentWorkspace sws;
            LabelImage segments;
            segment_objects(SegmentParams{}, f.cloud, f.normals, classes, nullptr, nullptr, LabelImage{}, sws,
                            segments);
            int box_label = 0;
            EXPECT_GT(dominant_share(segments.labels, truth, kTruthBox0, &box_label), 0.95);
            std::size_t joined = 0;
            for (std::size_t p = 0; p < patch.size(); ++p)
                joined += patch[p] && segments.labels[p] == box_label;
            EXPECT_GT(static_cast<double>(joined) / static_cast<double>(patch_size), 0.9);
        } else {
            EXPECT_EQ(inside, 0u);
            EXPECT_GT(static_cast<double>(removed) / static_cast<double>(patch_size), 0.9);
        }
    }
}

// The pipeline runs the plane stage on one thread or on all, from frame to frame, by
// timing (Pipeline's side-by-side choice): the support must not depend on the thread count,
// to the bit, or a run's outputs would depend on the machine's load.
TEST(RemoveSupportPlane, SamePlaneToTheBitOnAnyNumberOfThreads) {
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const int threads_before = omp_get_max_threads();
    int compared = 0;
    for (const char* set : {"uois_tabletop", "pcl_kinect"}) {
        auto source = open_source((sample_dir() / set).string(), SourceOptions{});
        SourceItem item;
        for (std::size_t i = 0; i < source->size(); ++i) {
            source->read(i, item);
            for (int n : {1, 2, 3}) {
                SCOPED_TRACE(item.frame.name + " decimated " + std::to_string(n));
                RgbdFrame small;
                decimate_frame(item.frame, n, small);
                Prepared f = prepared(small);
                std::vector<Plane> planes;
                for (int threads : {1, 2, 3, 4}) {
                    omp_set_num_threads(threads);
                    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes);
                    if (r.found) planes.push_back(r.support);
                }
                if (planes.empty()) continue;
                ASSERT_EQ(planes.size(), 4u);
                ++compared;
                for (const Plane& pl : planes) {
                    EXPECT_EQ(pl.nx, planes[0].nx);
                    EXPECT_EQ(pl.ny, planes[0].ny);
                    EXPECT_EQ(pl.nz, planes[0].nz);
                    EXPECT_EQ(pl.d, planes[0].d);
                }
            }
        }
    }
    omp_set_num_threads(threads_before);
    EXPECT_GE(compared, 10);
}


// A board or tray lying on the support, objects on it (the floor family of eval/scenegen.py,
// YCB-Video's board on a carpet): its top is a second, low support. It is removed as the
// table is, the boxes on it and beside it kept. Too small for a support (a book, a box lying
// flat), it stays an object.
TEST(RemoveSupportPlane, BoardOnTheTable_RemovedAsALowSupport_ItsBoxesKept) {
    std::vector<int> truth;
    const Prepared f = prepared(render_scene(board_on_table_scene(0.6f, 0.45f), &truth));
    const Removal r = remove_with_defaults(f);
    ASSERT_TRUE(r.result.found);
    ASSERT_TRUE(r.result.low_found);
    const Plane& table = r.result.support;
    const Plane& low = r.result.low_support;
    EXPECT_GT(table.nx * low.nx + table.ny * low.ny + table.nz * low.nz, 0.999f);
    std::size_t board = 0, board_object = 0;  // its sides' top centimetre may be feet, as the table's edge
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (truth[p] != kTruthBox0 || !f.active[p]) continue;
        ++board;
        board_object += r.classes[p] == kPlaneObject;
    }
    ASSERT_GT(board, 5000u);
    EXPECT_LT(static_cast<double>(board_object) / static_cast<double>(board), 0.03);
    double over_table = 0;  // the board's top over the table, over its pixels removed
    std::size_t n = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (truth[p] != kTruthBox0 || !f.active[p] || std::fabs(low.height(f.cloud.x[p], f.cloud.y[p], f.cloud.z[p])) > 0.003f)
            continue;
        over_table += table.height(f.cloud.x[p], f.cloud.y[p], f.cloud.z[p]);
        ++n;
    }
    ASSERT_GT(n, 1000u);
    EXPECT_NEAR(over_table / static_cast<double>(n), 0.02, 0.004);
    for (int box = 1; box <= 3; ++box) {
        const KeptCount k = kept_of(f, r.classes, truth, kTruthBox0 + box);
        ASSERT_GT(k.points, 300u) << "box " << box;
        EXPECT_GT(k.share(), 0.9) << "box " << box;
    }

    const Prepared small = prepared(render_scene(board_on_table_scene(0.25f, 0.25f), &truth));
    const Removal s = remove_with_defaults(small);
    ASSERT_TRUE(s.result.found);
    EXPECT_FALSE(s.result.low_found);
    EXPECT_GT(kept_of(small, s.classes, truth, kTruthBox0).share(), 0.9);
}

// A board parted in the image by what stands on it: a long box across its middle, end to end,
// leaves two halves of its top, each under the 0.1 m^2 of a low support (a book's size). The
// halves are one board: the piece reaches the other across the box and both lie on its plane.
TEST(RemoveSupportPlane, BoardPartedByABoxAcrossIt_OneLowSupport) {
    Scene scene = board_on_table_scene(0.5f, 0.32f);
    const SceneBox board = scene.boxes[0];
    const SceneBox across{.x = board.x, .z = board.z, .w = 0.08f, .h = 0.1f, .d = board.d, .lift = board.h,
                          .g = 120};
    scene.boxes = {board, across};
    std::vector<int> truth;
    const Prepared f = prepared(render_scene(scene, &truth));
    const Removal r = remove_with_defaults(f);
    ASSERT_TRUE(r.result.found);
    ASSERT_TRUE(r.result.low_found);
    for (const bool left : {true, false}) {  // each half of the board's top, removed
        std::size_t half = 0, half_object = 0;
        for (std::size_t p = 0; p < truth.size(); ++p) {
            if (truth[p] != kTruthBox0 || !f.active[p] || (f.cloud.x[p] < board.x) != left) continue;
            ++half;
            half_object += r.classes[p] == kPlaneObject;
        }
        ASSERT_GT(half, 1500u) << (left ? "left" : "right");
        EXPECT_LT(static_cast<double>(half_object) / static_cast<double>(half), 0.05) << (left ? "left" : "right");
    }
    const KeptCount k = kept_of(f, r.classes, truth, kTruthBox0 + 1);
    ASSERT_GT(k.points, 1000u);
    EXPECT_GT(k.share(), 0.9);
}

// A noisy camera: the tilted table and boxes of the first test with depth noise growing with
// z^2 (1 mm at 1 m, 2.6 mm at 1.6 m; normals at the radius that noise chooses, 6 px), more
// than the band of the defaults takes.
namespace {
RgbdFrame noisy_tilted_table(std::vector<int>& truth) {
    RgbdFrame frame = render_scene(tilted_table_scene(), &truth);
    std::mt19937 rng(11);
    std::normal_distribution<float> unit(0.0f, 1.0f);
    for (std::uint16_t& d : frame.depth.data) {
        if (d == 0) continue;
        const float z = static_cast<float>(d) * 0.001f;
        d = static_cast<std::uint16_t>(std::lround(1000.0f * (z + 0.001f * z * z * unit(rng))));
    }
    return frame;
}

/// The share of `truth` label `id`'s active points that lie over the band `widening` times
/// the default one, above the plane `pl`, and the share left as objects in `classes`.
struct OverBand {
    double over = 0, objects = 0;
};
OverBand over_band(const Prepared& f, const std::vector<int>& truth, int id, const Plane& pl, float widening,
                   const std::vector<std::uint8_t>& classes) {
    const PlaneParams d;
    std::size_t n = 0, over = 0, objects = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (!f.active[p] || truth[p] != id) continue;
        const float z = f.cloud.z[p];
        const float band = widening * (d.on_plane_m + d.on_plane_rel * z * z);
        ++n;
        over += pl.nx * f.cloud.x[p] + pl.ny * f.cloud.y[p] + pl.nz * z + pl.d > band;
        objects += classes[p] == kPlaneObject;
    }
    return {static_cast<double>(over) / static_cast<double>(n), static_cast<double>(objects) / static_cast<double>(n)};
}
}  // namespace

// Given a widening of 1.5 (what the pipeline passes for such noise, plane_noise_widening)
// the band holds the table's points themselves: 0.6 % lie over it, 12.2 % over the given one.
// A low support's layer keeps the given band: the board 2 cm over the table is still one
// when the band widens.
TEST(RemoveSupportPlane, NoisyDepth_TheWidenedBandHoldsTheTable_ALowSupportKeepsTheGivenBand) {
    std::vector<int> truth;
    const Prepared f = prepared(noisy_tilted_table(truth), true);
    auto table = [&](float widening) {
        PlaneWorkspace ws;
        std::vector<std::uint8_t> classes;
        const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes, widening);
        EXPECT_TRUE(r.found) << "widening " << widening;
        return over_band(f, truth, kTruthTable, r.support, widening, classes);
    };
    const OverBand given = table(1.0f), widened = table(1.5f);
    EXPECT_GT(given.over, 0.05);  // test premise: the noise exceeds the given band
    EXPECT_LT(widened.over, 0.02);
    EXPECT_LT(widened.objects, 0.01);

    const Prepared board = prepared(render_scene(board_on_table_scene(0.6f, 0.45f), &truth));
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = board.remove_plane(PlaneParams{}, ws, classes, 1.5f);
    ASSERT_TRUE(r.found);
    EXPECT_TRUE(r.low_found);
    std::size_t board_pixels = 0, board_object = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (truth[p] != kTruthBox0 || !board.active[p]) continue;
        ++board_pixels;
        board_object += classes[p] == kPlaneObject;
    }
    ASSERT_GT(board_pixels, 5000u);
    EXPECT_LT(static_cast<double>(board_object) / static_cast<double>(board_pixels), 0.03);

    EXPECT_THROW(board.remove_plane(PlaneParams{}, ws, classes, 0.5f), ParamError);
}

// Pixels over the band among pixels on it are depth errors (mark_over_most in
// plane_pixels.cpp): on the noisy table at the given band, 12.2 % of the table's points lie
// over the band, and all but 0.3 % of the table have most of their 3 x 3 on it, so the table
// is removed (each such point was an object before the rule); the boxes, whose pixels lie
// over the band with their neighbours, stay whole (99.8 % of each).
TEST(RemoveSupportPlane, LonePixelsOverTheBand_TakenAsOnIt_TheBoxesKept) {
    std::vector<int> truth;
    const Prepared f = prepared(noisy_tilted_table(truth), true);
    PlaneWorkspace ws;
    std::vector<std::uint8_t> classes;
    const PlaneResult r = f.remove_plane(PlaneParams{}, ws, classes, 1.0f);
    ASSERT_TRUE(r.found);
    const OverBand table = over_band(f, truth, kTruthTable, r.support, 1.0f, classes);
    EXPECT_GT(table.over, 0.05);     // test premise: the noise exceeds the band
    EXPECT_LT(table.objects, 0.01);  // the lone ones taken as on it
    for (const int box : {kTruthBox0, kTruthBox0 + 1}) {
        const KeptCount k = kept_of(f, classes, truth, box);
        ASSERT_GT(k.points, 500u) << "box " << box;
        EXPECT_GT(k.share(), 0.97) << "box " << box;
    }
}
