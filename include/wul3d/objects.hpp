#pragma once
/// @file objects.hpp
/// Objects and their tracks. ObjectTracker turns each frame's segments (segmentation.hpp)
/// into objects with stable track ids and smooths their pixels over time with the paper's
/// weights: every pixel keeps one membership weight per track slot and updates it exactly
/// as ClusterState does for clusters (eq. 2, 7, 8 with psi, update_weights); its object is
/// the arg-max weight. SelectedObject is the paper's user-defined object (its third
/// contribution): the label under a picked pixel, followed from frame to frame; it follows
/// clusters (labels.png) or objects (objects.png) alike.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "wul3d/cloud.hpp"
#include "wul3d/image.hpp"
#include "wul3d/weights.hpp"

namespace wul3d {

struct ObjectParams {
    float psi = 0.5f;          ///< weight increment of eq. (2) for object tracks; (0, 1]. Below 1
                               ///< a pixel changes object only after two frames of evidence
    int max_tracks = 32;       ///< tracks held at once; [2, 255]. Each pixel keeps its 6 largest
                               ///< track weights (PixelWeights, 24 bytes), whatever this is
    float min_overlap = 0.2f;  ///< a segment continues a track when its weight mass on the track
                               ///< (over its pixels whose surface did not change) is at least
                               ///< this share of the smaller of the two; (0, 1]
    float max_jump_m = 0.15f;  ///< else a lost track within this distance (centroids) is taken
                               ///< back; >= 0
    int max_lost_frames = 15;  ///< a track unseen this many frames is retired; >= 0
    int min_points = 100;      ///< an object left with fewer pixels after weighting is dropped; >= 1
    float scene_cut_share = 0.5f;  ///< when more than this share of the pixels with depth in
                                   ///< both frames moved by over 5 cm, the scene changed (a cut
                                   ///< in the recording, or a folder of unrelated frames): the
                                   ///< weights and tracks start afresh (new track ids); (0, 1]
    float rearranged_share = 0.4f;  ///< ... and so when more than this share of the pixels
                                    ///< that held objects saw their surface move (objects
                                    ///< rearranged between two shots; an object sliding at
                                    ///< video rate moves a quarter at most); (0, 1]
    float surface_change_m = 0.02f;    ///< a pixel whose depth moved by more than this plus
    float surface_change_rel = 0.01f;  ///< this times z^2 since the last frame sees another
                                       ///< surface: its weights are history of something else
                                       ///< and are forgotten; > 0 and >= 0
    float surface_change_rgb = 80.0f;  ///< ... the same when its colour moved by more than
                                       ///< this (RGB distance, 0-255): a new object at the
                                       ///< depth of the old one; > 0

    void validate() const;  ///< throws ParamError naming the field
};

/// One object of a frame. Positions in metres, camera frame; colours 0-255.
struct DetectedObject {
    int id = 0;        ///< the value in objects.png; equal to track_id (stable across frames)
    int track_id = 0;  ///< 1, 2, ... in order of first appearance
    std::size_t pixels = 0;
    std::array<float, 3> centroid{};
    std::array<float, 3> aabb_min{}, aabb_max{};  ///< axis-aligned box (camera axes)
    std::array<float, 3> obb_centre{};            ///< oriented box: centre,
    std::array<float, 9> obb_axes{};              ///< unit axes (rows; principal directions),
    std::array<float, 3> obb_half_extent{};       ///< half sizes along them
    int u_min = 0, v_min = 0, u_max = 0, v_max = 0;  ///< 2D box, inclusive pixels
    std::array<float, 3> mean_rgb{};
    std::vector<int> source_clusters;  ///< clusters (labels.png) covering >= 5 % of its pixels
    std::vector<int> source_segments;  ///< this frame's segments that fed it
};

/// State across frames for objects: tracks and per-pixel weights. Construct once per
/// sequence; step() once per frame.
class ObjectTracker {
public:
    explicit ObjectTracker(const ObjectParams& params);  ///< validates params
    ~ObjectTracker();
    ObjectTracker(ObjectTracker&&) noexcept;
    ObjectTracker& operator=(ObjectTracker&&) noexcept;

    /// `segments`: 0 background, 1..n (segment_objects). `clusters` may be empty. Writes
    /// `objects` (0 background, else track id) and one DetectedObject per track present.
    /// A pixel with valid depth outside every segment forgets its weights (objects come and
    /// go; unlike clusters, objects do not cover every point); a pixel without depth keeps
    /// them, as in ClusterState.
    void step(const OrganizedCloud& cloud, const LabelImage& segments, int n_segments,
              const LabelImage& clusters, LabelImage& objects, std::vector<DetectedObject>& out);
    /// step()'s first phase, the one that needs only the frame's cloud: where the surfaces
    /// changed since the last frame, and whether the scene cut. A caller with a thread free
    /// before the segments are ready may call it then, with the cloud it passes to step()
    /// next; else step() calls it. The same results either way.
    void observe(const OrganizedCloud& cloud);
    void reset();

    const ObjectParams& params() const { return params_; }
    std::int64_t tau() const { return tau_; }
    int tracks_started() const { return next_id_ - 1; }
    int scene_cuts() const { return scene_cuts_; }  ///< frames on which the tracks restarted

private:
    struct Track {
        int id = 0;  ///< 0: slot free
        int lost = 0;
        std::size_t pixels = 0;
        float x = 0, y = 0, z = 0;
    };

    // The phases of step(), in order; objects.cpp states each one's inputs, outputs and cost.
    void allocate(int width, int height);
    bool mark_surface_changes(const OrganizedCloud& cloud);  ///< true: a scene cut
    void start_afresh();
    void measure_segments(const OrganizedCloud& cloud, const LabelImage& segments, int n_segments);
    void match_by_overlap(int n_segments);
    void match_by_distance_or_start(int n_segments);
    void hold_covered_tracks();
    void start_arrivals(int n_segments);
    void weigh_pixels(const OrganizedCloud& cloud, const LabelImage& segments);
    void sum_objects(const OrganizedCloud& cloud);
    void describe_objects(std::vector<DetectedObject>& out);
    std::size_t write_labels_and_extents(const OrganizedCloud& cloud, const LabelImage& segments,
                                         int n_segments, const LabelImage& clusters,
                                         LabelImage& objects, const std::vector<DetectedObject>& out);
    void finish_objects(int n_segments, std::size_t n_cluster_labels,
                        std::vector<DetectedObject>& out) const;
    void follow_tracks();
    void free_slot(int slot);  ///< retires a track and forgets its weights

    ObjectParams params_;
    // State across frames.
    int width_ = 0, height_ = 0;
    std::int64_t tau_ = 0;
    const OrganizedCloud* observed_ = nullptr;  ///< the cloud observe() saw, until step()
    int next_id_ = 1;
    int scene_cuts_ = 0;
    std::vector<Track> tracks_;           ///< max_tracks slots
    std::vector<PixelWeights> mu_;        ///< per pixel, the kept weights over track slots
    std::vector<std::uint8_t> has_mu_;    ///< 1 where a pixel's weights are not all zero
    std::vector<float> prev_z_;           ///< last frame's depth (0 = none), for scene cuts
    std::vector<std::uint8_t> prev_r_, prev_g_, prev_b_;  ///< last frame's colour, a plane each

    // This frame's results, passed from phase to phase, reused from frame to frame
    // (objects.cpp).
    struct Scratch;
    std::unique_ptr<Scratch> s_;
};

/// Follows one user-picked object through the labels of successive frames.
/// First frame: the cluster under (u, v), or under the nearest labelled pixel within
/// `search_radius_px`. Later frames: the cluster that covers most of the previous mask
/// (so the object is kept if its cluster id changes, e.g. after a re-seed); if the previous
/// mask overlaps no labelled pixel the cluster id is kept.
class SelectedObject {
public:
    SelectedObject(int u, int v, int search_radius_px = 15);

    /// Writes mask[p] = 255 where the object is, else 0. Throws InputError on the first
    /// frame if (u, v) is outside the image or no labelled pixel is near it.
    void update(const LabelImage& labels, std::vector<std::uint8_t>& mask);

    int cluster() const { return cluster_; }  ///< the followed label, 0 before the first update
    int label() const { return cluster_; }    ///< same as cluster(), for object labels
    std::size_t pixels() const { return pixels_; }

private:
    int u_, v_, radius_;
    int cluster_ = 0;
    std::size_t pixels_ = 0;
    std::vector<std::uint8_t> previous_;
    std::vector<std::int64_t> votes_;
};

}  // namespace wul3d
