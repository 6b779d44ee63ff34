#pragma once
// Synthetic RGB-D scenes whose answer is known: a table, coloured boxes and open cups
// standing on it and a back wall, ray-cast exactly from a pinhole camera (x right, y down, z forward).
#include <cstdint>
#include <vector>

#include "wul3d/backprojection.hpp"
#include "wul3d/clustering.hpp"
#include "wul3d/frame.hpp"

namespace wul3d::test {

struct SceneBox {
    float x = 0, z = 1.2f;              ///< centre of the footprint on the table, metres
    float w = 0.15f, h = 0.15f, d = 0.15f;  ///< size along x, y, z, metres
    float lift = 0.0f;                  ///< its bottom this far over the surface (hanging), metres
    std::uint8_t r = 200, g = 30, b = 30;
};

/// An open container standing on the table: a vertical tube (a cup, a pot) with a floor; or,
/// with a neck, a bottle.
struct SceneCup {
    float x = 0, z = 1.0f;          ///< centre of the footprint on the table, metres
    float radius = 0.08f;           ///< outer radius, metres
    float h = 0.08f;                ///< height, metres
    float wall = 0.005f;            ///< wall and floor thickness, metres
    std::uint8_t r = 230, g = 200, b = 60;
    float band_lo = 0, band_hi = 0;  ///< a printed band round the outer wall (and the neck),
                                     ///< heights over the table, metres (none when equal)
    std::uint8_t band_r = 40, band_g = 60, band_b = 200;
    float neck_radius = 0, neck_h = 0;  ///< a bottle: a shoulder at 45 degrees on its wall up to
                                        ///< a closed neck of this radius and height (none when 0)
    float lift = 0;                     ///< its foot this high over the table (on a box), metres
};

struct Scene {
    std::vector<SceneBox> boxes;
    std::vector<SceneCup> cups;
    bool wall = false;          ///< a back wall at z = 2.4 m
    float floor_y = 0.0f;       ///< a floor this far below the camera (0: none), out to the
                                ///< wall when there is one
    std::vector<SceneBox> floor_boxes;  ///< boxes standing on the floor (a table's legs)
    float table_half_width = 0.6f;            ///< table spans x in [-w, w]
    float table_near = 0.7f, table_far = 1.7f;  ///< and z in [near, far], metres
    float table_y = 0.35f;      ///< table top height below the camera, metres
    int width = 320, height = 240;
    std::uint32_t noise_seed = 0;  ///< colour noise of +-3 levels when non-zero
    float pitch_rad = 0.0f;     ///< camera pitched down by this angle about its x axis (the
                                ///< scene's axes stay put; 0 = looking straight ahead)
};

/// Ground-truth ids: 0 nothing, 1 table, 2 wall, 3 floor, 10 + i box i, 50 + i cup i,
/// 80 + i floor box i.
constexpr int kTruthTable = 1, kTruthWall = 2, kTruthFloor = 3, kTruthBox0 = 10, kTruthCup0 = 50,
              kTruthFloorBox0 = 80;

/// Intrinsics used for every synthetic scene of that size.
PinholeIntrinsics scene_intrinsics(int width, int height);

/// Renders the scene; depth in 0.1 mm units. `truth` gets one id per pixel.
RgbdFrame render_scene(const Scene& scene, std::vector<int>* truth = nullptr);

/// The tilted tabletop used by the plane, segmentation and object tests: the camera pitched
/// down 0.5 rad over a table 0.6 m below it, from 0.4 to 1.6 m away; no boxes yet.
Scene pitched_tabletop_scene();

/// pitched_tabletop_scene() with two boxes of one colour: a small one (12 x 10 x 10 cm,
/// truth kTruthBox0 + 1) standing in front of a tall one (20 x 25 x 10 cm, kTruthBox0),
/// its back face against the tall one's front face: a concave junction.
Scene small_box_before_tall_box();

/// pitched_tabletop_scene() with a board lying on the table (`w` x `d` metres, 2 cm thick,
/// kTruthBox0), two boxes standing on it (kTruthBox0 + 1, + 2) and one on the table beside
/// it (kTruthBox0 + 3): a low support (DESIGN.md, "Support plane").
Scene board_on_table_scene(float w, float d);

/// A w x h label image, all 0.
LabelImage blank_labels(int w, int h);
/// Sets the pixels u0 <= u <= u1, v0 <= v <= v1 (inclusive) to `id`.
void fill_rect(LabelImage& l, int u0, int v0, int u1, int v1, std::uint16_t id);

/// The share of the pixels with truth id `id` whose label is the most common label among
/// them; `dominant` gets that label.
double dominant_share(const std::vector<std::uint16_t>& labels, const std::vector<int>& truth,
                      int id, int* dominant = nullptr);

}  // namespace wul3d::test
