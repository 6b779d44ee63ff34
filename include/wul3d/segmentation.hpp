#pragma once
/// @file segmentation.hpp
/// Object instances on the pixel grid, from the points left after support-plane removal
/// (plane.hpp, support_plane.hpp). The geometric segmenter cuts the surface where it folds inward (a concave
/// crease: a per-pixel version of LCCP's convexity test between neighbouring normals) and
/// where depth jumps, takes connected components, then re-attaches the cut pixels and the
/// objects' feet to the component they touch, merges segments that meet along a boundary
/// that is mostly not concave, joins a container's inside, seen over its rim, to its outer
/// wall, and joins the two parts of a surface that a nearer object divides in view. The
/// hybrid segmenter adds the colour cue of the paper's weighted clustering where geometry
/// is silent (two flush boxes of different colours). The kmeans segmenter is the paper's
/// clustering alone, split into connected parts.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "wul3d/cloud.hpp"
#include "wul3d/image.hpp"
#include "wul3d/support_plane.hpp"

namespace wul3d {

enum class Segmenter {
    Geometric,  ///< crease and depth cuts, connected components, re-attachment
    Kmeans,     ///< the paper's clusters (ClusterState labels), connected parts of each
    Hybrid,     ///< Geometric, then the colour cue splits segments geometry cannot
};
Segmenter parse_segmenter(const std::string& name);  ///< geometric|kmeans|hybrid, else ParamError
const char* segmenter_name(Segmenter s);

/// Which segments are objects (--scope). Someone pointing a camera at a table wants what
/// stands on the table, not the wall behind it or the chair beside it.
enum class Scope {
    Support,  ///< what the support holds (the default); the whole scene when no support is found
    Scene,    ///< every segment
};
Scope parse_scope(const std::string& name);  ///< support|scene, else ParamError
const char* scope_name(Scope s);

/// The crease cuts and the components (cuts.cpp, components.cpp): a pixel seeds a component
/// unless a concave crease or a depth jump runs through it; cut pixels and feet re-attach.
struct CutParams {
    int crease_step_px = 5;    ///< normals compared this many pixels apart; [1, 16]; the
                               ///< pipeline widens it to the normals' radius when wider
    int normal_smooth_px = 3;  ///< the crease tests use normals averaged over a window of
                               ///< this radius (sensor noise); [0, 16], 0 = raw normals
    float concavity = 0.3f;    ///< (n_p - n_q) . (X_q - X_p) / |X_q - X_p| above this is a
                               ///< concave crease (LCCP's test, per pixel); > 0
    int reattach_px = 8;       ///< cut pixels and feet join a segment up to this far; >= 0
    int min_seed_points = 40;  ///< components smaller than this before re-attachment are
                               ///< cut pixels too; >= 1
};

/// Merge (merge.cpp; LCCP's merge on segments): two segments that meet, with continuous
/// depth, along a boundary that is mostly not concave were split by noise or a thin convex
/// edge (a bowl's rim, a box's front edge), not by a junction of two objects. With colour
/// (hybrid), a pair that steps a little in depth and changes colour is a junction too: one
/// object's outline over another's (they touch in a pile).
struct MergeParams {
    float max_concave = 0.3f;  ///< largest share of junction pairs (concave; with colour, or
                               ///< silhouette pairs) on such a boundary; [0, 1], 0 = never
                               ///< merge
    int min_boundary = 6;      ///< boundary pairs with a crease test at least; >= 1
};

/// Colour cue (colour_cue.cpp; hybrid): a segment is split in two by the paper's distance
/// (eq. 4, 6) with a colour-heavy alpha when the two parts differ in colour, are each large,
/// meet along a short boundary, and that boundary crosses a smooth surface (no crease:
/// shading on two faces of one box is not a second object).
struct ColourCueParams {
    float alpha = 0.02f;       ///< alpha of eq. (4) for the split; [0.002, 0.1]
    float min_distance = 25;   ///< chromaticity distance (0-255 scale) between the parts'
                               ///< means; > 0
    float min_share = 0.05f;   ///< each part holds at least this share (and min_points): a
                               ///< flat box lying on a larger one may show only its rim;
                               ///< (0, 0.5]
    float max_boundary = 0.5f; ///< boundary pairs / the smaller part's outline pairs at
                               ///< most: a contact is one side of it; (0, 1]
    float max_compact = 6;     ///< ... or boundary pairs / sqrt(the smaller part's pixels)
                               ///< at most: a compact piece that the larger part encloses
                               ///< in view (a box lying on a box); a texture's parts run
                               ///< far longer; >= 0, 0 = off
    float max_crease_deg = 15; ///< 70 % of the boundary pairs have normals (a crease step
                               ///< away on either side) within this angle; > 0
    float min_hue_deg = 10;    ///< ... or else (the boundary follows a fold) the parts' mean
                               ///< RGB vectors differ by this angle: shading scales a
                               ///< colour, only another material turns it; (0, 90)
    float min_step = 1.15f;    ///< ... or, either way: of the boundary pairs that cross a
                               ///< smooth surface, half or more (6 at least) lie on one
                               ///< plane, and 70 % of those are this many times brighter
                               ///< (r + g + b) a crease step away on one part's side than on
                               ///< the other's: two materials of one hue; <= 1: off
    float round_deg = 25;      ///< no split of a segment that stands round on the support (a
                               ///< can, a bottle, a cup: its colours are print): its walls,
                               ///< normals within this of the support plane, lie on one
                               ///< upright circle (the containers' fit's residual and arc)
                               ///< and face within this of its radii; [0, 90), 0 = off
    float round_max_radius_m = 0.15f;  ///< ... a circle of at most this radius; > 0
    bool textures = true;      ///< where 2-means follows a texture (its boundary runs round
                               ///< many pieces), four colours, and two whose contact is
                               ///< longer than max_compact allows are one material (they
                               ///< interleave); the same tests judge the split between two
                               ///< materials: stripes beside a plain box
};

/// Stacks (stacks.cpp; needs the support plane; not kmeans): a segment whose upward faces
/// lie at two heights over the support, nothing facing up between them, is two objects, one
/// resting on the other; it is cut just over the lower one's top.
struct StackParams {
    float min_step_m = 0.02f;  ///< the layers lie this far apart at least, and the lower this
                               ///< far above the support (a book's thickness); [0, 0.5],
                               ///< 0 = off
    float min_share = 0.04f;   ///< each layer holds this share of the segment's pixels (and
                               ///< min_points); (0, 0.5]
};

/// Containers (containers.cpp, floor_gaps.cpp; need the support plane): a bowl or a cup
/// seen from above shows its outer wall and, over the front rim, its inside; the rim hides
/// the inside's lower part, so the two meet only across a depth step, where no crease test
/// or merge can join them. The rim gives it away: the nearer segment's edge along that step
/// is a level circular arc, and the farther segment lies inside the circle and reaches up
/// to the rim (its far side). Such a pair is joined.
struct ContainerParams {
    int min_boundary = 10;          ///< depth-step boundary pairs at least; >= 3, or 0 = off
    float max_residual_m = 0.0035f; ///< RMS distance of the edge from its fitted circle to
                                    ///< 1 m, growing as z^2 beyond (the sensor's noise); the
                                    ///< colour cue's round test's at any depth; > 0
    float min_arc = 0.4f;           ///< widest chord of the edge / the circle's diameter at
                                    ///< least (0.4: an arc of 47 degrees); (0, 1]
    float inside_share = 0.95f;     ///< share of the inside's feet within the circle (radius
                                    ///< + 10 % + 1 cm); (0, 1]
    float height_tol_m = 0.01f;     ///< the inside's top within this of the rim's height; > 0
    bool far_rim = true;            ///< a second candidate circle per pair, fitted to the
                                    ///< front's edge and the inside's far outline at the
                                    ///< rim's height (its far rim), when the front spans a
                                    ///< radius across the view and the far rim agrees
    float far_agree = 1.0f / 3;     ///< the far rim's own circle: radius and centre within
                                    ///< this share of the radius of the circle through both
                                    ///< edges (it is the same rim); > 0
    /// Gaps in a container's floor (floor_gaps.cpp): a patch of unlabelled points enclosed by
    /// one segment and touching its inside (kPlaneInside: floor points whose patch was too
    /// noisy to pass the plane's island test) joins that segment. A true hole (a mug's
    /// handle, the table seen through it) touches no inside and stays. Patches up to this
    /// many pixels; 0 = off.
    int gap_max_px = 500;
};

/// Occlusion (occlusion.cpp): a nearer object that hides the middle of a surface (a box
/// standing before a lying one) leaves two segments, one each side, where there is one
/// object. The two parts lie on one plane and face the same way, and what lies between them
/// in view stands in front of that plane. Lines of pixels that cross from one part, over
/// the occluder, onto the other part's surface are the evidence; such a pair is joined.
struct OcclusionParams {
    int min_lines = 8;         ///< crossing lines to join two parts; >= 0, 0 = off
    float max_offset = 1.0f;   ///< their mean height over the first part's plane, in sensor
                               ///< steps (depth_jump_m + depth_jump_rel z^2), at most; > 0
    float max_gap_m = 0.3f;    ///< a line spans at most this much of the plane it starts on
                               ///< (each pixel where its ray meets the plane: the width
                               ///< hidden, not the occluder's height in front); > 0
    float max_deg = 20;        ///< the normals at a line's two ends within this; (0, 90)
};

/// Scope (scope.cpp; needs the support plane; docs/DESIGN.md, "Scope"): with Scope::Support a
/// segment is an object when it stands on the support, or rests on a segment that does, and
/// stays within the support's volume: over its hull (PlaneParams::hull_margin_px) and up to
/// a height limit. A segment that runs on, with continuous depth, into points the plane
/// stage removed although they lie above the support (off its hull) is part of something
/// bigger than the table holds: a wall, a chair, the next table.
struct ScopeParams {
    Scope mode = Scope::Support;
    float contact_m = 0.03f;     ///< a segment whose lowest point is this close to the support
                                 ///< stands on it (so does one whose foot the camera cannot
                                 ///< see: its sides unseen); > 0
    float max_height_m = 0.5f;   ///< a segment with over 2 % of its points higher than this
                                 ///< over the support, or spanning more than this on it (its
                                 ///< widest extent, the outer 5 % of its points left out at
                                 ///< either end: a cabinet, a chair, a wall), is not held by
                                 ///< it; > 0
    float max_outside = 0.1f;    ///< largest share of a segment's outline that continues into
                                 ///< removed points above the support, or into the frame's
                                 ///< edge beyond the support's middle; [0, 1]
    float upright_share = 0.7f;  ///< the frame's edges count for a segment only when this
                                 ///< share of its pixels face sideways (within 25 degrees of
                                 ///< the support plane): a wall; an object on the table the
                                 ///< frame cuts shows its top; [0, 1]
    /// Low supports: a kept segment no higher than scope.low_support_max_m over the support that
    /// covers scope.low_support_min_area_m2 of it and holds two kept segments or more (they touch
    /// it and rise contact_m above it) is a board or a tray lying on the floor, a second
    /// support under the objects: background, not an object. 0.1 m: a 3 cm board on a
    /// carpet, a tray's 4 cm rim, and the noise of the segment's highest point; [0, 0.5],
    /// 0 = off.
    float low_support_max_m = 0.1f;
    float low_support_min_area_m2 = 0.07f;  ///< ... its area on the support at least (a book is
                                            ///< 0.06); > 0
};

/// segment_objects' parameters: what every phase shares, then one struct per phase or rule,
/// in the order the driver runs them (segmentation.cpp).
struct SegmentParams {
    Segmenter segmenter = Segmenter::Hybrid;
    int min_points = 300;           ///< objects with fewer pixels are dropped; >= 1
    float depth_jump_m = 0.004f;    ///< neighbours whose depths differ by more than
    float depth_jump_rel = 0.012f;  ///< depth_jump_m + depth_jump_rel * z^2 are not connected;
                                    ///< > 0 and >= 0 (Kinect depth noise grows with z^2)
    CutParams cuts;
    MergeParams merge;
    ContainerParams containers;
    ColourCueParams colour;
    StackParams stacks;
    OcclusionParams occlusion;
    ScopeParams scope;

    void validate() const;  ///< throws ParamError naming the field (`colour.alpha`)
};

/// segment_objects' buffers, sized once per resolution and reused from frame to frame
/// (opaque: src/segmentation/internal.hpp).
class SegmentWorkspace {
public:
    SegmentWorkspace();
    ~SegmentWorkspace();
    SegmentWorkspace(SegmentWorkspace&&) noexcept;
    SegmentWorkspace& operator=(SegmentWorkspace&&) noexcept;

    struct Buffers;      ///< src/segmentation/internal.hpp
    Buffers& buffers();  ///< for segmentation's own code and its tests (made again after a move)

private:
    std::unique_ptr<Buffers> b_;
};

/// What segmentation did, as data: the counts of each rule in a struct of its own.
struct SegmentStats {
    int segments = 0;             ///< objects written to `out`
    std::size_t reattached = 0;   ///< cut pixels and feet re-attached (CutParams)
    struct MergeCounts {
        int joins = 0;  ///< segment pairs joined across a non-concave boundary
    } merge;
    struct ContainerCounts {
        int joins = 0;                ///< insides joined to their container across the rim
        std::size_t gaps_filled = 0;  ///< points of containers' floors filled in (containers.gap_max_px)
    } containers;
    struct ColourCueCounts {
        int splits = 0;          ///< splits the colour cue made, both rounds (each adds a
                                 ///< segment)
        int texture_splits = 0;  ///< of splits, those between a texture and another material
                                 ///< (ColourCueParams::textures)
    } colour;
    struct StackCounts {
        int splits = 0;  ///< segments the stack rule cut in two (each adds a segment)
    } stacks;
    struct PieceCounts {
        int splits = 0;  ///< pieces of a segment apart from its largest, made segments (those
                         ///< under min_points then dropped)
    } pieces;
    struct OcclusionCounts {
        int joins = 0;  ///< parts of one surface joined across the object before them
    } occlusion;
    struct NeckCounts {
        int joins = 0;  ///< necks (and caps) joined to the round body they stand on
    } necks;
    struct ScopeCounts {
        bool applied = false;  ///< Scope::Support was applied (a support was found)
        int out_of_scope = 0;  ///< segments of min_points or more the scope left out
    } scope;
    /// Milliseconds in each phase: normal smoothing, crease cuts (seedable pixels),
    /// components, re-attachment, convexity merge, container rule, colour cue, stack rule,
    /// pieces, floor gaps, occlusion, necks, the scope, and the renumbering passes with the output.
    /// For the profile in bench/.
    struct Phases {
        double smoothing = 0, cuts = 0, components = 0, reattach = 0, merge = 0, containers = 0,
               color = 0, stacks = 0, pieces = 0, gaps = 0, occluded = 0, necks = 0, scope = 0,
               compact = 0;
    } ms;
};

/// `classes` and `support` come from remove_support_plane (PlaneClass: 0 removed, 1 object,
/// 2 foot, 3 inside; `support` nullptr when no plane was found or removed: no container
/// joins), and so does `low_support`, the top of a board or tray lying on the support whose
/// points it removed (PlaneResult::low_support; nullptr when none), which the scope counts
/// inside the support's volume. `clusters` are the ClusterState labels of the same
/// frame (used by kmeans; may be empty for geometric and hybrid). `out` gets 0 =
/// background, 1..n = segment. `depth_noise_rel` is the depth's measured noise relative to
/// depth, sigma_z / z (the pipeline passes measure_depth_noise's noise_px over fx; 0: none):
/// the colour cue's round test allows for the scatter it gives the walls of a can.
SegmentStats segment_objects(const SegmentParams& params, const OrganizedCloud& cloud,
                             const NormalMap& normals, const std::vector<std::uint8_t>& classes,
                             const Plane* support, const Plane* low_support, const LabelImage& clusters,
                             SegmentWorkspace& ws, LabelImage& out, float depth_noise_rel = 0.0f);

}  // namespace wul3d
