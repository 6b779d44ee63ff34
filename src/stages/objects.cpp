#include "wul3d/objects.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "branch_free.hpp"
#include "param_check.hpp"
#include "point_moments.hpp"
#include "team_tasks.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

SelectedObject::SelectedObject(int u, int v, int search_radius_px)
    : u_(u), v_(v), radius_(search_radius_px) {}

void SelectedObject::update(const LabelImage& labels, std::vector<std::uint8_t>& mask) {
    const int W = labels.width, H = labels.height;
    const std::size_t n = labels.labels.size();
    if (cluster_ == 0) {
        if (u_ < 0 || v_ < 0 || u_ >= W || v_ >= H) {
            std::ostringstream msg;
            msg << "select " << u_ << "," << v_ << ": outside the " << W << "x" << H
                << " image";
            throw InputError(msg.str());
        }
        // The picked pixel, or the nearest labelled one (a click often lands on a hole).
        int best_d2 = radius_ * radius_ + 1;
        for (int dv = -radius_; dv <= radius_; ++dv)
            for (int du = -radius_; du <= radius_; ++du) {
                const int u = u_ + du, v = v_ + dv, d2 = du * du + dv * dv;
                if (u < 0 || v < 0 || u >= W || v >= H || d2 >= best_d2) continue;
                const int label = labels.labels[static_cast<std::size_t>(v) * W + u];
                if (label != 0) {
                    best_d2 = d2;
                    cluster_ = label;
                }
            }
        if (cluster_ == 0) {
            std::ostringstream msg;
            msg << "select " << u_ << "," << v_ << ": no point within " << radius_
                << " px of that pixel in the first frame (no depth, or outside the depth range)";
            throw InputError(msg.str());
        }
    } else if (previous_.size() == n) {
        // Follow the object: the cluster that now covers most of its previous pixels.
        std::fill(votes_.begin(), votes_.end(), 0);
        for (std::size_t p = 0; p < n; ++p) {
            if (!previous_[p]) continue;
            const std::uint16_t label = labels.labels[p];
            if (label == 0) continue;
            if (label >= votes_.size()) votes_.resize(label + 1u, 0);
            ++votes_[label];
        }
        const auto best = std::max_element(votes_.begin(), votes_.end());
        if (best != votes_.end() && *best > 0) cluster_ = static_cast<int>(best - votes_.begin());
    }

    mask.resize(n);
    pixels_ = 0;
    for (std::size_t p = 0; p < n; ++p) {
        const bool in = labels.labels[p] == cluster_;
        mask[p] = in ? 255 : 0;
        pixels_ += in;
    }
    // An object that vanished for a frame keeps its last mask as the reference.
    if (pixels_ > 0) previous_ = mask;
}

// ---- objects and tracks -----------------------------------------------------------------

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "ObjectParams", name, value, range);
}
// Per-segment sums: count, x, y, z.
constexpr int kSegSums = 4;
// Per-object sums: the point moments (point_moments.hpp), then r, g, b.
constexpr int kObjSums = detail::kMoments + 3;
// The per-pixel passes are summed per fixed band of rows, then in band order, so that the
// results do not depend on the number of threads.
constexpr int kBands = 16;
// Per object, the extents: aabb min (3), OBB projection min (3), aabb max (3), OBB max (3).
constexpr int kExt = 12;
// Scratch::changed's bits. kForget: the pixel held weights and its surface moved (they are
// another surface's history); kNearer: its surface came nearer, whether it held weights or
// not (something put down there; a surface that an object moved away from, seen again,
// lies farther).
constexpr std::uint8_t kForget = 1, kNearer = 2;
// A segment's new surface starts a track of its own only where the track it continues lost
// less than this share of that surface, and of its own size (start_arrivals): an object that
// moves within one segment vacates about what it gains. Without the test, osd_moving's
// slide_learn38 and enterleave_learn43 fall from 98.6 and 98.3 Overlap F to 89.6 and 90.3,
// their movers cut in two; at 0.25 and 0.5 every set scores alike, at 0.1 ocid_sample loses
// its arrivals (docs/ABLATION.md, "Objects and tracks").
constexpr double kArrivalVacatedShare = 0.25;

/// The slot of w's largest weight (the first of equals).
int favoured_track(const PixelWeights& w) {
    int best = 0;
    for (int q = 1; q < PixelWeights::kSlots; ++q)
        if (w.mu[q] > w.mu[best]) best = q;
    return w.cluster[best];
}
}  // namespace

void ObjectParams::validate() const {
    require(psi > 0 && psi <= 1.0f, "psi", psi, "in (0, 1] (paper eq. 2)");
    require(max_tracks >= 2 && max_tracks <= 255, "max_tracks", max_tracks, "in [2, 255]");
    require(min_overlap > 0 && min_overlap <= 1, "min_overlap", min_overlap, "in (0, 1]");
    require(max_jump_m >= 0, "max_jump_m", max_jump_m, ">= 0");
    require(max_lost_frames >= 0, "max_lost_frames", max_lost_frames, ">= 0");
    require(min_points >= 1, "min_points", min_points, ">= 1");
    require(scene_cut_share > 0 && scene_cut_share <= 1, "scene_cut_share", scene_cut_share, "in (0, 1]");
    require(rearranged_share > 0 && rearranged_share <= 1, "rearranged_share", rearranged_share, "in (0, 1]");
    require(surface_change_m > 0, "surface_change_m", surface_change_m, "> 0");
    require(surface_change_rel >= 0, "surface_change_rel", surface_change_rel, ">= 0");
    require(surface_change_rgb > 0, "surface_change_rgb", surface_change_rgb, "> 0");
}

/// ObjectTracker's per-frame results, passed from phase to phase and reused from frame to
/// frame. S segments, K = max_tracks slots.
struct ObjectTracker::Scratch {
    std::vector<std::uint8_t> changed;      ///< per pixel, kForget and kNearer: how its surface moved
    std::vector<double> votes, seg_sums;   ///< per segment: weight mass per slot; count, x, y, z
    std::vector<int> seg_slot;              ///< per segment, its slot (-1: none)
    std::vector<int> seg_left;              ///< the segments no track continues, in the order they start one
    std::vector<std::uint8_t> slot_taken;   ///< per slot, 1 where a segment took it (or it is held)
    std::vector<double> slot_mass;          ///< per slot, its weight mass over the unchanged pixels
    std::vector<double> seg_nearer;         ///< per segment, its pixels whose surface came nearer;
                                            ///< -1 at the frame's border
    std::vector<int> seg_arrival;           ///< per segment, the slot of its arrival (-1: none)
    std::vector<std::uint8_t> slot_of;      ///< per pixel, its arg-max slot + 1, 0 none
    std::vector<double> obj_sums;           ///< per slot, point moments and colour sums
    std::vector<int> obj_boxes;             ///< per slot, u_min, v_min, u_max, v_max
    std::vector<int> object_of_slot;        ///< per slot, its index in step's `out` (-1: none)
    // Per band of rows (kBands), reduced in band order:
    std::vector<std::uint64_t> band_votes, band_nearer;
    std::vector<double> band_seg_sums, band_obj_sums;
    std::vector<int> band_boxes, band_cluster_count;
    std::vector<float> band_extents;
    std::vector<std::uint8_t> band_segment_seen;
};

ObjectTracker::~ObjectTracker() = default;
ObjectTracker::ObjectTracker(ObjectTracker&&) noexcept = default;
ObjectTracker& ObjectTracker::operator=(ObjectTracker&&) noexcept = default;

ObjectTracker::ObjectTracker(const ObjectParams& params)
    : params_(params), s_(std::make_unique<Scratch>()) {
    params_.validate();
    tracks_.resize(static_cast<std::size_t>(params_.max_tracks));
}

void ObjectTracker::reset() {
    observed_ = nullptr;
    std::fill(mu_.begin(), mu_.end(), PixelWeights{});
    std::fill(has_mu_.begin(), has_mu_.end(), 0);
    tracks_.assign(static_cast<std::size_t>(params_.max_tracks), Track{});
    tau_ = 0;
    next_id_ = 1;
    scene_cuts_ = 0;
}

void ObjectTracker::free_slot(int slot) {
    for (PixelWeights& w : mu_)
        for (int s = 0; s < PixelWeights::kSlots; ++s)
            if (w.cluster[s] == slot) w.mu[s] = 0;
    tracks_[static_cast<std::size_t>(slot)] = Track{};
}

// One frame, in phases. N pixels, S segments, K = max_tracks slots, O objects out, C the
// largest cluster label, B = kBands. The per-pixel phases run on all threads; their sums
// are made per band of rows and reduced in band order, so no result depends on the
// number of threads.
void ObjectTracker::step(const OrganizedCloud& cloud, const LabelImage& segments, int n_segments,
                         const LabelImage& clusters, LabelImage& objects,
                         std::vector<DetectedObject>& out) {
    if (observed_ == nullptr) observe(cloud);
    if (observed_ != &cloud) {
        observed_ = nullptr;
        throw std::invalid_argument("ObjectTracker::step: not the cloud that observe() was given");
    }
    observed_ = nullptr;
    ++tau_;

    // Segments to track slots: by the weight mass they overlap, else by distance, else new.
    measure_segments(cloud, segments, n_segments);
    match_by_overlap(n_segments);
    match_by_distance_or_start(n_segments);
    hold_covered_tracks();
    start_arrivals(n_segments);

    // The paper's weights on the slots give each pixel its object.
    weigh_pixels(cloud, segments);

    // The objects: sums, then their description, then the label image and what needs the
    // description (extents along the oriented box's axes).
    sum_objects(cloud);
    describe_objects(out);
    const std::size_t n_cluster_labels =
        write_labels_and_extents(cloud, segments, n_segments, clusters, objects, out);
    finish_objects(n_segments, n_cluster_labels, out);

    // What the next frame matches against.
    follow_tracks();
}

void ObjectTracker::observe(const OrganizedCloud& cloud) {
    if (!s_) s_ = std::make_unique<Scratch>();  // a moved-from tracker, used again
    if (cloud.width != width_ || cloud.height != height_) allocate(cloud.width, cloud.height);
    // Pixels whose surface changed neither vote for the matching nor keep their weights (in
    // measure_segments and weigh_pixels); a scene cut forgets everything.
    if (mark_surface_changes(cloud)) start_afresh();
    observed_ = &cloud;
}

// New resolution: per-pixel state sized to N and everything forgotten, as reset().
void ObjectTracker::allocate(int width, int height) {
    const std::size_t N = static_cast<std::size_t>(width) * height;
    width_ = width;
    height_ = height;
    mu_.assign(N, PixelWeights{});
    has_mu_.assign(N, 0);
    s_->slot_of.assign(N, 0);
    prev_z_.assign(N, 0.0f);
    prev_r_.assign(N, 0);
    prev_g_.assign(N, 0);
    prev_b_.assign(N, 0);
    s_->changed.assign(N, 0);
    reset();
}

namespace {

/// mark_surface_changes' counts over a range of pixels.
struct SurfaceCounts {
    std::size_t both = 0, moved = 0, held = 0, held_moved = 0;
};

/// mark_surface_changes on pixels [p0, p1): changed[p] and the counts, and this frame's
/// depth and colour into the previous planes. Branch-free on planes, so that it vectorizes
/// (built for AVX2 and baseline x86-64, no FMA either way: the same bits).
WUL3D_AVX2_CLONES
SurfaceCounts surface_changes(std::size_t p0, std::size_t p1, const std::uint8_t* __restrict valid,
                              const float* __restrict cz, const std::uint8_t* __restrict cr,
                              const std::uint8_t* __restrict cg, const std::uint8_t* __restrict cb,
                              const std::uint8_t* __restrict has_mu, float rgb2, float change_m, float change_rel,
                              float* __restrict prev_z, std::uint8_t* __restrict prev_r,
                              std::uint8_t* __restrict prev_g, std::uint8_t* __restrict prev_b,
                              std::uint8_t* __restrict changed) {
    unsigned both = 0, moved = 0, held = 0, held_moved = 0;
    for (std::size_t p = p0; p < p1; ++p) {
        const float z = detail::pick(valid[p] != 0, cz[p], 0.0f), before = prev_z[p];
        const bool seen = (z > 0) & (before > 0);  // a surface in both frames
        const float dz = std::fabs(z - before);
        const int dr = cr[p] - prev_r[p], dg = cg[p] - prev_g[p], db = cb[p] - prev_b[p];
        const bool depth_moved = dz > change_m + change_rel * z * z;
        const bool mine = seen & (has_mu[p] != 0);
        both += seen;
        moved += seen & (dz > 0.05f);
        held += mine;
        held_moved += mine & depth_moved;
        // A changed pixel's weights are another surface's history: it does not vote for the
        // matching (measure_segments), and forgets them (weigh_pixels). A segment's pixels
        // that came nearer may be an arrival (start_arrivals).
        const bool moved_here = depth_moved | (static_cast<float>(dr * dr + dg * dg + db * db) > rgb2);
        const bool nearer = depth_moved & (z < before);
        changed[p] = static_cast<std::uint8_t>((mine & moved_here) * kForget | (seen & nearer) * kNearer);
        prev_z[p] = z;
        prev_r[p] = cr[p];
        prev_g[p] = cg[p];
        prev_b[p] = cb[p];
    }
    return {both, moved, held, held_moved};
}

}  // namespace

// In: the cloud, prev_z_, the prev_ colour planes, has_mu_. Out: s_->changed (1 where a
// pixel that held weights now sees another surface: an object arrived, left or moved over
// it), prev_z_ and the colour planes set to this frame. Returns true on a scene cut: most
// surfaces moved at once. Cost: one pass over N pixels (surface_changes), no allocation.
bool ObjectTracker::mark_surface_changes(const OrganizedCloud& cloud) {
    const std::size_t N = cloud.size();
    std::size_t both = 0, moved = 0, held = 0, held_moved = 0;
    const float rgb2 = params_.surface_change_rgb * params_.surface_change_rgb;
    // Bands of pixels spread over the threads (as tasks inside a team: observe() may run
    // beside the segmentation); each call counts in unsigned, the sums are size_t.
    SurfaceCounts band_counts[kBands];
    detail::for_each_part(kBands, detail::Spread::kStatic, [&](std::ptrdiff_t band) {
        const std::size_t p0 = N * static_cast<std::size_t>(band) / kBands,
                          p1 = N * static_cast<std::size_t>(band + 1) / kBands;
        band_counts[band] = surface_changes(
            p0, p1, cloud.valid.data(), cloud.z.data(), cloud.r.data(), cloud.g.data(), cloud.b.data(),
            has_mu_.data(), rgb2, params_.surface_change_m, params_.surface_change_rel, prev_z_.data(),
            prev_r_.data(), prev_g_.data(), prev_b_.data(), s_->changed.data());
    });
    for (const SurfaceCounts& c : band_counts) {
        both += c.both;
        moved += c.moved;
        held += c.held;
        held_moved += c.held_moved;
    }
    // Most of the surfaces the objects held moved: the objects were rearranged (a folder
    // of separate scenes), not moved along.
    const bool objects_moved = held > 0 && static_cast<double>(held_moved) >
                                               params_.rearranged_share * static_cast<double>(held);
    return tau_ > 0 && (both == 0 || objects_moved ||
                        static_cast<double>(moved) > params_.scene_cut_share * static_cast<double>(both));
}

// A scene cut: weights, changes and tracks forgotten; track ids go on counting.
// Cost: O(N), in ranges of pixels that fall to the threads as weigh_pixels' do (where the
// weights are read next), no allocation.
void ObjectTracker::start_afresh() {
    const std::size_t N = mu_.size();
    detail::for_each_part(kBands, detail::Spread::kStatic, [&](std::ptrdiff_t band) {
        const std::size_t p0 = N * static_cast<std::size_t>(band) / kBands,
                          p1 = N * static_cast<std::size_t>(band + 1) / kBands;
        std::fill(mu_.data() + p0, mu_.data() + p1, PixelWeights{});
        std::fill(has_mu_.data() + p0, has_mu_.data() + p1, std::uint8_t{0});
        std::fill(s_->changed.data() + p0, s_->changed.data() + p1, std::uint8_t{0});
    });
    tracks_.assign(static_cast<std::size_t>(params_.max_tracks), Track{});
    ++scene_cuts_;
}

// In: segments, the cloud, mu_, s_->changed. Out: s_->votes ((S+1) x K: each segment's sum of
// its pixels' weights per slot, i.e. its overlap with the previous frames' objects as the
// paper's weights remember them, over the pixels whose surface did not change),
// s_->slot_mass (K: each slot's votes over all segments), s_->seg_sums ((S+1) x kSegSums:
// pixel count and x, y, z sums) and s_->seg_nearer (S+1: pixels whose surface came nearer;
// -1 for a segment at the frame's border).
// Votes are summed in integer units of the weights: exact in any order.
// Cost: one pass over N pixels (6 weights each), then O(B x S x K) and the border; allocates
// only when S grows.
void ObjectTracker::measure_segments(const OrganizedCloud& cloud, const LabelImage& segments,
                                     int n_segments) {
    const int W = cloud.width, H = cloud.height;
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    const std::size_t S1 = static_cast<std::size_t>(n_segments + 1);
    s_->band_votes.assign(kBands * S1 * Kz, 0);
    s_->band_nearer.assign(kBands * S1, 0);
    s_->band_seg_sums.assign(kBands * S1 * kSegSums, 0.0);
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        std::uint64_t* const votes = s_->band_votes.data() + static_cast<std::size_t>(band) * S1 * Kz;
        double* const sums = s_->band_seg_sums.data() + static_cast<std::size_t>(band) * S1 * kSegSums;
        std::uint64_t* const nearer = s_->band_nearer.data() + static_cast<std::size_t>(band) * S1;
        const std::size_t p0 = static_cast<std::size_t>(H * band / kBands) * W;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kBands) * W;
        for (std::size_t p = p0; p < p1; ++p) {
            const int s = segments.labels[p];
            if (s == 0) continue;
            double* ss = sums + static_cast<std::size_t>(s) * kSegSums;
            ss[0] += 1;
            ss[1] += cloud.x[p];
            ss[2] += cloud.y[p];
            ss[3] += cloud.z[p];
            // A pixel whose surface changed holds another surface's history: an object put
            // down on another would take over that one's track by it.
            const std::uint8_t changed = s_->changed[p];
            nearer[s] += (changed & kNearer) != 0;
            if (!has_mu_[p] || (changed & kForget)) continue;
            std::uint64_t* vs = votes + static_cast<std::size_t>(s) * Kz;
            const PixelWeights& w = mu_[p];
            for (int q = 0; q < PixelWeights::kSlots; ++q) vs[w.cluster[q]] += w.mu[q];
        }
    }
    s_->votes.assign(S1 * Kz, 0.0);
    s_->seg_sums.assign(S1 * kSegSums, 0.0);
    s_->seg_nearer.assign(S1, 0.0);
    for (int band = 0; band < kBands; ++band) {
        const std::uint64_t* votes = s_->band_votes.data() + static_cast<std::size_t>(band) * S1 * Kz;
        const std::uint64_t* nearer = s_->band_nearer.data() + static_cast<std::size_t>(band) * S1;
        const double* sums = s_->band_seg_sums.data() + static_cast<std::size_t>(band) * S1 * kSegSums;
        for (std::size_t i = 0; i < S1 * Kz; ++i) s_->votes[i] += static_cast<double>(votes[i]);
        for (std::size_t i = 0; i < S1; ++i) s_->seg_nearer[i] += static_cast<double>(nearer[i]);
        for (std::size_t i = 0; i < S1 * kSegSums; ++i) s_->seg_sums[i] += sums[i];
    }
    for (double& v : s_->votes) v /= static_cast<double>(PixelWeights::kOne);
    s_->slot_mass.assign(Kz, 0.0);
    for (std::size_t s = 1; s < S1; ++s)
        for (std::size_t j = 0; j < Kz; ++j) s_->slot_mass[j] += s_->votes[s * Kz + j];
    // A segment cut by the frame's border may be coming into view: its new surface is no
    // arrival.
    auto at_border = [&](std::size_t p) { s_->seg_nearer[segments.labels[p]] = -1.0; };
    for (int u = 0; u < W; ++u) {
        at_border(static_cast<std::size_t>(u));
        at_border(static_cast<std::size_t>(H - 1) * W + static_cast<std::size_t>(u));
    }
    for (int v = 0; v < H; ++v) {
        at_border(static_cast<std::size_t>(v) * W);
        at_border(static_cast<std::size_t>(v) * W + static_cast<std::size_t>(W - 1));
    }
}

// In: s_->votes, s_->seg_sums, tracks_. Out: s_->seg_slot (S+1: the slot each segment continues,
// -1 none yet) and s_->slot_taken (K). A segment and a live track pair when the votes cover
// min_overlap of the smaller; pairs are taken greedily, one to one, largest vote first
// (ties: smaller segment, then smaller slot).
// Cost: O(S x K log(S x K)); allocates the list of pairs.
void ObjectTracker::match_by_overlap(int n_segments) {
    const int S = n_segments, K = params_.max_tracks;
    const std::size_t Kz = static_cast<std::size_t>(K);
    struct Pair {
        double vote;
        int s, j;
    };
    std::vector<Pair> pairs;
    for (int s = 1; s <= S; ++s)
        for (int j = 0; j < K; ++j) {
            const Track& t = tracks_[static_cast<std::size_t>(j)];
            const double v = s_->votes[static_cast<std::size_t>(s) * Kz + static_cast<std::size_t>(j)];
            if (t.id == 0 || v <= 0) continue;
            const double size = s_->seg_sums[static_cast<std::size_t>(s) * kSegSums];
            if (v >= params_.min_overlap * std::min(size, static_cast<double>(t.pixels)))
                pairs.push_back({v, s, j});
        }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
        return a.vote != b.vote ? a.vote > b.vote : (a.s != b.s ? a.s < b.s : a.j < b.j);
    });
    s_->seg_slot.assign(static_cast<std::size_t>(S + 1), -1);
    s_->slot_taken.assign(Kz, 0);
    for (const Pair& pr : pairs) {
        if (s_->seg_slot[static_cast<std::size_t>(pr.s)] >= 0 || s_->slot_taken[static_cast<std::size_t>(pr.j)]) continue;
        s_->seg_slot[static_cast<std::size_t>(pr.s)] = pr.j;
        s_->slot_taken[static_cast<std::size_t>(pr.j)] = 1;
    }
}

// In and out: s_->seg_slot, s_->slot_taken, tracks_. Each segment left over, in order, takes the
// nearest untaken track within max_jump_m of its centroid and of a similar size (an object
// that moved faster than its overlap), else a new track id in a free slot, else in the
// slot lost longest (whose weights are forgotten); with no slot left it is dropped. When
// more are left over than slots untaken, the largest go first (ties: in order): a crowded
// frame (many small segments, a low min_points) drops its smallest, not whatever lies low
// in the image.
// Cost: O(S x K), O(S log S) when crowded, and O(N) per slot taken over; no allocation once
// the buffers have grown.
void ObjectTracker::match_by_distance_or_start(int n_segments) {
    const int S = n_segments, K = params_.max_tracks;
    auto& left = s_->seg_left;
    left.clear();
    for (int s = 1; s <= S; ++s)
        if (s_->seg_slot[static_cast<std::size_t>(s)] < 0) left.push_back(s);
    const auto untaken = std::count(s_->slot_taken.begin(), s_->slot_taken.end(), std::uint8_t{0});
    if (static_cast<std::ptrdiff_t>(left.size()) > untaken) {
        const double* sums = s_->seg_sums.data();
        std::sort(left.begin(), left.end(), [sums](int a, int b) {
            const double na = sums[static_cast<std::size_t>(a) * kSegSums], nb = sums[static_cast<std::size_t>(b) * kSegSums];
            return na != nb ? na > nb : a < b;
        });
    }
    for (const int s : left) {
        const double* ss = s_->seg_sums.data() + static_cast<std::size_t>(s) * kSegSums;
        const double cx = ss[1] / ss[0], cy = ss[2] / ss[0], cz = ss[3] / ss[0];
        int best = -1;
        double best_d = params_.max_jump_m;
        for (int j = 0; j < K; ++j) {
            const Track& t = tracks_[static_cast<std::size_t>(j)];
            if (t.id == 0 || s_->slot_taken[static_cast<std::size_t>(j)]) continue;
            const double ratio = ss[0] / std::max<double>(1.0, static_cast<double>(t.pixels));
            if (ratio < 0.33 || ratio > 3.0) continue;
            const double d = std::sqrt((cx - t.x) * (cx - t.x) + (cy - t.y) * (cy - t.y) + (cz - t.z) * (cz - t.z));
            if (d <= best_d) {
                best_d = d;
                best = j;
            }
        }
        if (best < 0) {
            // A free slot, else the one lost longest (ties: the smallest).
            for (int j = 0; j < K && best < 0; ++j)
                if (tracks_[static_cast<std::size_t>(j)].id == 0) best = j;
            if (best < 0) {
                for (int j = 0; j < K; ++j) {
                    if (s_->slot_taken[static_cast<std::size_t>(j)]) continue;
                    const Track& t = tracks_[static_cast<std::size_t>(j)];
                    if (best < 0 || t.lost > tracks_[static_cast<std::size_t>(best)].lost ||
                        (t.lost == tracks_[static_cast<std::size_t>(best)].lost &&
                         t.pixels < tracks_[static_cast<std::size_t>(best)].pixels))
                        best = j;
                }
                if (best < 0) continue;  // more segments than slots: the segment is dropped
                free_slot(best);
            }
            tracks_[static_cast<std::size_t>(best)].id = next_id_++;
        }
        s_->seg_slot[static_cast<std::size_t>(s)] = best;
        s_->slot_taken[static_cast<std::size_t>(best)] = 1;
    }
}

// In and out: s_->slot_taken. A live track that no segment continues, but whose unchanged
// pixels still hold min_overlap of its size inside other tracks' segments (an object that a
// neighbour's segment took in: two objects touching in a pile), is held: taken this frame,
// so that its pixels keep it (weigh_pixels). Without this the larger track's segment would
// take them over in a frame or two.
// Cost: O(K).
void ObjectTracker::hold_covered_tracks() {
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    for (std::size_t j = 0; j < Kz; ++j) {
        const Track& t = tracks_[j];
        if (t.id != 0 && t.lost == 0 && !s_->slot_taken[j] &&
            s_->slot_mass[j] >= params_.min_overlap * static_cast<double>(t.pixels))
            s_->slot_taken[j] = 1;
    }
}

// In and out: s_->slot_taken, tracks_. Out: s_->seg_arrival (S+1: the slot of its arrival,
// -1 none). A segment that continues a track seen last frame and holds at least min_points
// pixels whose surface came nearer (the table or the floor there a frame ago), while that
// track lost (its pixels last frame less its weight mass on the unchanged ones now) less
// than kArrivalVacatedShare of those pixels and of its own size, grew by something put down
// against the object: those pixels start a track of their own (in a free slot; none free,
// no arrival). A segment at the frame's border may be coming into view and is left as it
// is. Objects put down one at a time against a pile (OCID's sequences) are told apart so,
// however the segmentation joins them.
// Cost: O(S + K) per segment that arrives.
void ObjectTracker::start_arrivals(int n_segments) {
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    s_->seg_arrival.assign(static_cast<std::size_t>(n_segments + 1), -1);
    for (int s = 1; s <= n_segments; ++s) {
        const int j = s_->seg_slot[static_cast<std::size_t>(s)];
        if (j < 0) continue;
        const Track& t = tracks_[static_cast<std::size_t>(j)];
        const double nearer = s_->seg_nearer[static_cast<std::size_t>(s)];
        const double vacated = static_cast<double>(t.pixels) - s_->slot_mass[static_cast<std::size_t>(j)];
        // t.pixels is 0 for a track that this frame started.
        if (t.pixels == 0 || t.lost > 0 || nearer < params_.min_points ||
            vacated > kArrivalVacatedShare * std::min(nearer, static_cast<double>(t.pixels)))
            continue;
        std::size_t slot = 0;
        while (slot < Kz && tracks_[slot].id != 0) ++slot;
        if (slot == Kz) return;
        tracks_[slot].id = next_id_++;
        s_->slot_taken[slot] = 1;
        s_->seg_arrival[static_cast<std::size_t>(s)] = static_cast<int>(slot);
    }
}

// The paper's weights on objects. In: segments, s_->seg_slot, s_->slot_taken,
// s_->seg_arrival, s_->changed, the cloud's validity, tracks_. Out: mu_ and has_mu_ (each
// segment pixel adds psi to a track's weight: eq. 2, 7, 8, the same update_weights as the
// clusters; a changed pixel forgets first; a pixel with depth outside every segment
// forgets), s_->slot_of (arg-max slot + 1 among the slots taken this frame, 0 none). The
// track a pixel adds to: its segment's arrival's where its surface came nearer; else, in a
// segment that continues a track, the one its weights favour where that one is seen this
// frame (an unchanged surface stays with its object, whichever segment it falls in: objects
// in a pile are told apart by their history where the segmentation joins them); else its
// segment's. A segment that starts a track (split off) takes its pixels.
// Cost: one pass over N pixels, no allocation.
void ObjectTracker::weigh_pixels(const OrganizedCloud& cloud, const LabelImage& segments) {
    const std::size_t N = cloud.size();
    // Raw pointers, as in mark_surface_changes.
    const std::uint16_t* const seg = segments.labels.data();
    const int* const seg_slot = s_->seg_slot.data();
    const std::uint8_t* const taken = s_->slot_taken.data();
    const int* const arrival = s_->seg_arrival.data();
    const Track* const tracks = tracks_.data();
    const std::uint8_t* const valid = cloud.valid.data();
    std::uint8_t* const changed = s_->changed.data();
    std::uint8_t* const has_mu = has_mu_.data();
    std::uint8_t* const slot_of = s_->slot_of.data();
    PixelWeights* const mu = mu_.data();
    const float psi = params_.psi;
    const auto Nn = static_cast<std::ptrdiff_t>(N);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < Nn; ++i) {
        const std::size_t p = static_cast<std::size_t>(i);
        const int s = seg[p];
        const int slot = s ? seg_slot[s] : -1;
        if (changed[p] & kForget) {
            mu[p] = PixelWeights{};
            has_mu[p] = 0;
        }
        if (slot >= 0) {
            int winner = slot;
            if ((changed[p] & kNearer) && arrival[s] >= 0)
                winner = arrival[s];
            else if (has_mu[p] && tracks[slot].pixels > 0) {
                const int favoured = favoured_track(mu[p]);
                if (taken[favoured]) winner = favoured;
            }
            int label = update_weights(mu[p], winner, psi);
            // The arg-max runs over the objects seen in this frame: a track with no
            // segment now must not hold pixels as a ghost fragment of another object.
            if (!taken[label]) {
                const PixelWeights& w = mu[p];
                label = slot;
                int best = -1;
                for (int q = 0; q < PixelWeights::kSlots; ++q)
                    if (w.mu[q] > best && taken[w.cluster[q]]) {
                        best = w.mu[q];
                        label = w.cluster[q];
                    }
            }
            slot_of[p] = static_cast<std::uint8_t>(label + 1);
            has_mu[p] = 1;
        } else {
            if (valid[p] && has_mu[p]) {
                mu[p] = PixelWeights{};
                has_mu[p] = 0;
            }
            slot_of[p] = 0;
        }
    }
}

// In: s_->slot_of, the cloud. Out: s_->obj_sums (K x kObjSums: point moments and colour sums per
// slot) and s_->obj_boxes (K x 4: u_min, v_min, u_max, v_max; W, H, -1, -1 where empty).
// Cost: one pass over N pixels, then O(B x K); no allocation after the first frame.
void ObjectTracker::sum_objects(const OrganizedCloud& cloud) {
    const int W = cloud.width, H = cloud.height;
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    s_->band_obj_sums.assign(kBands * Kz * kObjSums, 0.0);
    s_->band_boxes.assign(kBands * Kz * 4, 0);
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        double* const sums = s_->band_obj_sums.data() + static_cast<std::size_t>(band) * Kz * kObjSums;
        int* const boxes = s_->band_boxes.data() + static_cast<std::size_t>(band) * Kz * 4;
        for (std::size_t j = 0; j < Kz; ++j) {
            boxes[4 * j] = W;  // umin, vmin, umax, vmax
            boxes[4 * j + 1] = H;
            boxes[4 * j + 2] = boxes[4 * j + 3] = -1;
        }
        for (int v = H * band / kBands; v < H * (band + 1) / kBands; ++v)
            for (int u = 0; u < W; ++u) {
                const std::size_t p = static_cast<std::size_t>(v) * W + u;
                if (!s_->slot_of[p]) continue;
                const std::size_t j = s_->slot_of[p] - 1u;
                double* o = sums + j * kObjSums;
                detail::add_moments(o, cloud.x[p], cloud.y[p], cloud.z[p]);
                o[10] += cloud.r[p]; o[11] += cloud.g[p]; o[12] += cloud.b[p];
                int* box = boxes + 4 * j;
                box[0] = std::min(box[0], u); box[2] = std::max(box[2], u);
                box[1] = std::min(box[1], v); box[3] = std::max(box[3], v);
            }
    }
    s_->obj_sums.assign(Kz * kObjSums, 0.0);
    s_->obj_boxes.resize(Kz * 4);
    for (std::size_t j = 0; j < Kz; ++j) {
        s_->obj_boxes[4 * j] = W;
        s_->obj_boxes[4 * j + 1] = H;
        s_->obj_boxes[4 * j + 2] = s_->obj_boxes[4 * j + 3] = -1;
    }
    for (int band = 0; band < kBands; ++band) {
        const double* sums = s_->band_obj_sums.data() + static_cast<std::size_t>(band) * Kz * kObjSums;
        const int* boxes = s_->band_boxes.data() + static_cast<std::size_t>(band) * Kz * 4;
        for (std::size_t i = 0; i < Kz * kObjSums; ++i) s_->obj_sums[i] += sums[i];
        for (std::size_t i = 0; i < Kz * 4; i += 4) {
            s_->obj_boxes[i] = std::min(s_->obj_boxes[i], boxes[i]);
            s_->obj_boxes[i + 1] = std::min(s_->obj_boxes[i + 1], boxes[i + 1]);
            s_->obj_boxes[i + 2] = std::max(s_->obj_boxes[i + 2], boxes[i + 2]);
            s_->obj_boxes[i + 3] = std::max(s_->obj_boxes[i + 3], boxes[i + 3]);
        }
    }
}

// In: s_->obj_sums, s_->obj_boxes, tracks_. Out: `out`, one object per live slot with at least
// min_points pixels (smaller ones are dropped: their pixels become background), in slot
// order: id, pixels, centroid, OBB axes (largest spread first), 2D box, mean colour; and
// s_->object_of_slot (K: its index in `out`, -1 none).
// Cost: O(K) and a 3x3 eigen-decomposition per object; allocates the objects.
void ObjectTracker::describe_objects(std::vector<DetectedObject>& out) {
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    out.clear();
    s_->object_of_slot.assign(Kz, -1);
    for (std::size_t j = 0; j < Kz; ++j) {
        if (!(s_->obj_sums[j * kObjSums] >= params_.min_points && tracks_[j].id != 0)) continue;
        const double* o = s_->obj_sums.data() + j * kObjSums;
        const double n = o[0];
        DetectedObject d;
        d.track_id = d.id = tracks_[j].id;
        d.pixels = static_cast<std::size_t>(n);
        Eigen::Vector3d c;
        Eigen::Matrix3d m;
        detail::mean_and_covariance(o, c, m);
        d.centroid = {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                d.obb_axes[static_cast<std::size_t>(3 * a + b)] =
                    static_cast<float>(eig.eigenvectors()(b, 2 - a));  // largest spread first
        const int* box = s_->obj_boxes.data() + 4 * j;
        d.u_min = box[0]; d.u_max = box[2]; d.v_min = box[1]; d.v_max = box[3];
        d.mean_rgb = {static_cast<float>(o[10] / n), static_cast<float>(o[11] / n), static_cast<float>(o[12] / n)};
        s_->object_of_slot[j] = static_cast<int>(out.size());
        out.push_back(std::move(d));
    }
}

// In: s_->slot_of, s_->object_of_slot, `out`, the cloud, segments, clusters. Out: `objects` (the
// label image: track id, 0 background) and, per band of rows and object, the extents
// (axis-aligned and along the OBB axes), the pixels per cluster and the segments seen.
// Returns C + 1, the range of cluster labels counted.
// Cost: one pass over N pixels, then O(B x O x (C + S)) to clear the band buffers.
std::size_t ObjectTracker::write_labels_and_extents(const OrganizedCloud& cloud, const LabelImage& segments,
                                                    int n_segments, const LabelImage& clusters,
                                                    LabelImage& objects,
                                                    const std::vector<DetectedObject>& out) {
    const int W = cloud.width, H = cloud.height;
    objects.width = W;
    objects.height = H;
    objects.labels.resize(cloud.size());
    const std::size_t S1 = static_cast<std::size_t>(n_segments + 1);
    const std::size_t O = out.size();
    int max_cluster = 0;
    const auto Nc = static_cast<std::ptrdiff_t>(clusters.labels.size());
#pragma omp parallel for schedule(static) reduction(max : max_cluster)
    for (std::ptrdiff_t p = 0; p < Nc; ++p) max_cluster = std::max<int>(max_cluster, clusters.labels[static_cast<std::size_t>(p)]);
    const std::size_t C1 = static_cast<std::size_t>(max_cluster) + 1;
    s_->band_extents.assign(kBands * O * kExt, 0.0f);
    s_->band_cluster_count.assign(kBands * O * C1, 0);
    s_->band_segment_seen.assign(kBands * O * S1, 0);
    // Raw pointers, as in mark_surface_changes: the byte stores (labels' high bytes aside,
    // `seen`) would make the compiler reload every vector's data pointer on each pixel.
    const std::uint8_t* const slot_of = s_->slot_of.data();
    const int* const object_of_slot = s_->object_of_slot.data();
    std::uint16_t* const labels_out = objects.labels.data();
    const float *const cx = cloud.x.data(), *const cy = cloud.y.data(), *const cz = cloud.z.data();
    const std::uint16_t* const cluster_of = clusters.labels.empty() ? nullptr : clusters.labels.data();
    const std::uint16_t* const segment_of = segments.labels.data();
#pragma omp parallel for schedule(static)
    for (int band = 0; band < kBands; ++band) {
        float* const ext = s_->band_extents.data() + static_cast<std::size_t>(band) * O * kExt;
        int* const ccount = s_->band_cluster_count.data() + static_cast<std::size_t>(band) * O * C1;
        std::uint8_t* const seen = s_->band_segment_seen.data() + static_cast<std::size_t>(band) * O * S1;
        for (std::size_t i = 0; i < O; ++i)
            for (int a = 0; a < 6; ++a) {
                ext[i * kExt + static_cast<std::size_t>(a)] = INFINITY;
                ext[i * kExt + static_cast<std::size_t>(a) + 6] = -INFINITY;
            }
        const std::size_t p0 = static_cast<std::size_t>(H * band / kBands) * W;
        const std::size_t p1 = static_cast<std::size_t>(H * (band + 1) / kBands) * W;
        for (std::size_t p = p0; p < p1; ++p) {
            const int i = slot_of[p] ? object_of_slot[slot_of[p] - 1u] : -1;
            if (i < 0) {
                labels_out[p] = 0;
                continue;
            }
            const DetectedObject& d = out[static_cast<std::size_t>(i)];
            labels_out[p] = static_cast<std::uint16_t>(std::min(d.id, 65535));
            float* e = ext + static_cast<std::size_t>(i) * kExt;
            const float pt[3] = {cx[p], cy[p], cz[p]};
            for (int a = 0; a < 3; ++a) {
                const float* ax = d.obb_axes.data() + 3 * a;
                const float t = ax[0] * (pt[0] - d.centroid[0]) + ax[1] * (pt[1] - d.centroid[1]) + ax[2] * (pt[2] - d.centroid[2]);
                e[a] = std::min(e[a], pt[a]);
                e[a + 6] = std::max(e[a + 6], pt[a]);
                e[a + 3] = std::min(e[a + 3], t);
                e[a + 9] = std::max(e[a + 9], t);
            }
            if (cluster_of) ++ccount[static_cast<std::size_t>(i) * C1 + cluster_of[p]];
            seen[static_cast<std::size_t>(i) * S1 + segment_of[p]] = 1;
        }
    }
    return C1;
}

// In: the band buffers of write_labels_and_extents. Out: each object's aabb_min, aabb_max,
// obb_centre, obb_half_extent, source_clusters (>= 5 % of its pixels) and source_segments.
// Minima, maxima, counts and flags: exact in any order of the bands.
// Cost: O(B x O x (C + S)); allocates the source lists.
void ObjectTracker::finish_objects(int n_segments, std::size_t n_cluster_labels,
                                   std::vector<DetectedObject>& out) const {
    const std::size_t S1 = static_cast<std::size_t>(n_segments + 1);
    const std::size_t C1 = n_cluster_labels;
    const std::size_t O = out.size();
    for (std::size_t i = 0; i < O; ++i) {
        DetectedObject& d = out[i];
        float e[kExt];
        for (int a = 0; a < 6; ++a) {
            e[a] = INFINITY;
            e[a + 6] = -INFINITY;
        }
        for (int band = 0; band < kBands; ++band) {
            const float* be = s_->band_extents.data() + (static_cast<std::size_t>(band) * O + i) * kExt;
            for (int a = 0; a < 6; ++a) {
                e[a] = std::min(e[a], be[a]);
                e[a + 6] = std::max(e[a + 6], be[a + 6]);
            }
        }
        for (int a = 0; a < 3; ++a) {
            const std::size_t az = static_cast<std::size_t>(a);
            d.aabb_min[az] = e[a];
            d.aabb_max[az] = e[a + 6];
            const float lo = e[a + 3], hi = e[a + 9];
            const float mid = 0.5f * (lo + hi);
            d.obb_half_extent[az] = 0.5f * (hi - lo);
            for (int b = 0; b < 3; ++b) d.obb_centre[static_cast<std::size_t>(b)] += mid * d.obb_axes[static_cast<std::size_t>(3 * a + b)];
        }
        for (int b = 0; b < 3; ++b) d.obb_centre[static_cast<std::size_t>(b)] += d.centroid[static_cast<std::size_t>(b)];
        for (std::size_t l = 1; l < C1; ++l) {
            int cnt = 0;
            for (int band = 0; band < kBands; ++band)
                cnt += s_->band_cluster_count[(static_cast<std::size_t>(band) * O + i) * C1 + l];
            if (cnt > 0 && static_cast<double>(cnt) >= 0.05 * static_cast<double>(d.pixels))
                d.source_clusters.push_back(static_cast<int>(l));
        }
        for (std::size_t sgm = 1; sgm < S1; ++sgm)
            for (int band = 0; band < kBands; ++band)
                if (s_->band_segment_seen[(static_cast<std::size_t>(band) * O + i) * S1 + sgm]) {
                    d.source_segments.push_back(static_cast<int>(sgm));
                    break;
                }
    }
}

// In: s_->obj_sums. Out: tracks_: a slot with pixels this frame remembers its size and
// centroid; one without counts a frame lost, and is retired (weights forgotten) after
// max_lost_frames.
// Cost: O(K), and O(N) per slot retired; no allocation.
void ObjectTracker::follow_tracks() {
    const std::size_t Kz = static_cast<std::size_t>(params_.max_tracks);
    for (std::size_t j = 0; j < Kz; ++j) {
        Track& t = tracks_[j];
        if (t.id == 0) continue;
        const double* o = s_->obj_sums.data() + j * kObjSums;
        if (o[0] > 0) {
            t.lost = 0;
            t.pixels = static_cast<std::size_t>(o[0]);
            t.x = static_cast<float>(o[1] / o[0]);
            t.y = static_cast<float>(o[2] / o[0]);
            t.z = static_cast<float>(o[3] / o[0]);
        } else if (++t.lost > params_.max_lost_frames) {
            free_slot(static_cast<int>(j));
        }
    }
}

}  // namespace wul3d
