#include "wul3d/objects.hpp"

#include <algorithm>
#include <sstream>

#include "param_check.hpp"
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

}  // namespace wul3d

// ---- objects and tracks -----------------------------------------------------------------

#include <Eigen/Eigenvalues>
#include <cmath>

namespace wul3d {

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "ObjectParams", name, value, range);
}
// Per-segment sums: count, x, y, z.
constexpr int kSegSums = 4;
// Per-object sums: count, x, y, z, xx, xy, xz, yy, yz, zz, r, g, b.
constexpr int kObjSums = 13;
}  // namespace

void ObjectParams::validate() const {
    if (!(psi > 0 && psi <= 1.0f)) {
        std::ostringstream msg;
        msg << "--object-psi " << psi << ": must be in (0, 1] (paper eq. 2)";
        throw ParamError(msg.str());
    }
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

ObjectTracker::ObjectTracker(const ObjectParams& params) : params_(params) {
    params_.validate();
    tracks_.resize(static_cast<std::size_t>(params_.max_tracks));
}

void ObjectTracker::reset() {
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

void ObjectTracker::step(const OrganizedCloud& cloud, const LabelImage& segments, int n_segments,
                         const LabelImage& clusters, LabelImage& objects,
                         std::vector<DetectedObject>& out) {
    const int W = cloud.width, H = cloud.height;
    const std::size_t N = cloud.size();
    const int K = params_.max_tracks;
    const std::size_t Kz = static_cast<std::size_t>(K);
    if (W != width_ || H != height_) {
        width_ = W;
        height_ = H;
        mu_.assign(N, PixelWeights{});
        has_mu_.assign(N, 0);
        slot_of_.assign(N, 0);
        prev_z_.assign(N, 0.0f);
        prev_rgb_.assign(3 * N, 0);
        changed_.assign(N, 0);
        reset();
    }
    {
        // A scene cut: most surfaces moved at once. Weights and tracks start afresh.
        // A pixel whose surface changed (an object arrived, left or moved over it) forgets
        // its weights: they are the history of another surface.
        std::size_t both = 0, moved = 0, held = 0, held_moved = 0;
        const float rgb2 = params_.surface_change_rgb * params_.surface_change_rgb;
        const float change_m = params_.surface_change_m, change_rel = params_.surface_change_rel;
        // Raw pointers: byte stores would make the compiler reload every vector's data
        // pointer on each pixel (a char store may alias anything).
        const std::uint8_t* const valid = cloud.valid.data();
        const float* const cz = cloud.z.data();
        const std::uint8_t *const cr = cloud.r.data(), *const cg = cloud.g.data(),
                           *const cb = cloud.b.data();
        const std::uint8_t* const has_mu = has_mu_.data();
        float* const prev_z = prev_z_.data();
        std::uint8_t* const prev_rgb = prev_rgb_.data();
        std::uint8_t* const changed = changed_.data();
        const auto Nn = static_cast<std::ptrdiff_t>(N);
#pragma omp parallel for schedule(static) reduction(+ : both, moved, held, held_moved)
        for (std::ptrdiff_t i = 0; i < Nn; ++i) {
            const std::size_t p = static_cast<std::size_t>(i);
            const float z = valid[p] ? cz[p] : 0.0f;
            std::uint8_t* rgb = prev_rgb + 3 * p;
            if (z > 0 && prev_z[p] > 0) {
                ++both;
                const float dz = std::fabs(z - prev_z[p]);
                moved += dz > 0.05f;
                const int dr = cr[p] - rgb[0], dg = cg[p] - rgb[1], db = cb[p] - rgb[2];
                const bool depth_moved = dz > change_m + change_rel * z * z;
                held += has_mu[p];
                held_moved += has_mu[p] && depth_moved;
                // Reset after the votes below: the old weights still say which track was
                // here, evidence of overlap for a moving object.
                changed[p] = has_mu[p] && (depth_moved || static_cast<float>(dr * dr + dg * dg + db * db) > rgb2);
            } else {
                changed[p] = 0;
            }
            prev_z[p] = z;
            rgb[0] = cr[p];
            rgb[1] = cg[p];
            rgb[2] = cb[p];
        }
        // Most of the surfaces the objects held moved: the objects were rearranged (a folder
        // of separate scenes), not moved along.
        const bool objects_moved = held > 0 && static_cast<double>(held_moved) >
                                                   params_.rearranged_share * static_cast<double>(held);
        if (tau_ > 0 && (both == 0 || objects_moved ||
                         static_cast<double>(moved) > params_.scene_cut_share * static_cast<double>(both))) {
            std::fill(mu_.begin(), mu_.end(), PixelWeights{});
            std::fill(has_mu_.begin(), has_mu_.end(), 0);
            std::fill(changed_.begin(), changed_.end(), 0);
            tracks_.assign(Kz, Track{});
            ++scene_cuts_;
        }
    }
    ++tau_;
    const int S = n_segments;

    // 1. Each segment's votes for the track slots: the sum of its pixels' weights, i.e. the
    //    overlap with the previous frames' objects as the paper's weights remember them.
    votes_.assign(static_cast<std::size_t>(S + 1) * Kz, 0.0);
    seg_sums_.assign(static_cast<std::size_t>(S + 1) * kSegSums, 0.0);
    for (std::size_t p = 0; p < N; ++p) {
        const int s = segments.labels[p];
        if (s == 0) continue;
        double* ss = seg_sums_.data() + static_cast<std::size_t>(s) * kSegSums;
        ss[0] += 1;
        ss[1] += cloud.x[p];
        ss[2] += cloud.y[p];
        ss[3] += cloud.z[p];
        if (!has_mu_[p]) continue;
        double* vs = votes_.data() + static_cast<std::size_t>(s) * Kz;
        const PixelWeights& w = mu_[p];
        for (int q = 0; q < PixelWeights::kSlots; ++q)
            if (w.mu[q] > 0) vs[w.cluster[q]] += w.mu[q] / static_cast<double>(PixelWeights::kOne);
    }

    // 2. Greedy one-to-one matching by vote, largest first.
    struct Pair {
        double vote;
        int s, j;
    };
    std::vector<Pair> pairs;
    for (int s = 1; s <= S; ++s)
        for (int j = 0; j < K; ++j) {
            const Track& t = tracks_[static_cast<std::size_t>(j)];
            const double v = votes_[static_cast<std::size_t>(s) * Kz + static_cast<std::size_t>(j)];
            if (t.id == 0 || v <= 0) continue;
            const double size = seg_sums_[static_cast<std::size_t>(s) * kSegSums];
            if (v >= params_.min_overlap * std::min(size, static_cast<double>(t.pixels)))
                pairs.push_back({v, s, j});
        }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
        return a.vote != b.vote ? a.vote > b.vote : (a.s != b.s ? a.s < b.s : a.j < b.j);
    });
    seg_slot_.assign(static_cast<std::size_t>(S + 1), -1);
    std::vector<std::uint8_t> slot_taken(Kz, 0);
    for (const Pair& pr : pairs) {
        if (seg_slot_[static_cast<std::size_t>(pr.s)] >= 0 || slot_taken[static_cast<std::size_t>(pr.j)]) continue;
        seg_slot_[static_cast<std::size_t>(pr.s)] = pr.j;
        slot_taken[static_cast<std::size_t>(pr.j)] = 1;
    }
    // 3. Segments left over: a track not matched this frame whose last centroid is near
    //    (an object that moved faster than its overlap), else a new track.
    for (int s = 1; s <= S; ++s) {
        if (seg_slot_[static_cast<std::size_t>(s)] >= 0) continue;
        const double* ss = seg_sums_.data() + static_cast<std::size_t>(s) * kSegSums;
        const double cx = ss[1] / ss[0], cy = ss[2] / ss[0], cz = ss[3] / ss[0];
        int best = -1;
        double best_d = params_.max_jump_m;
        for (int j = 0; j < K; ++j) {
            const Track& t = tracks_[static_cast<std::size_t>(j)];
            if (t.id == 0 || slot_taken[static_cast<std::size_t>(j)]) continue;
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
                    if (slot_taken[static_cast<std::size_t>(j)]) continue;
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
        seg_slot_[static_cast<std::size_t>(s)] = best;
        slot_taken[static_cast<std::size_t>(best)] = 1;
    }

    // 4. The paper's weights on objects: each segment pixel adds psi to its track's weight
    //    (eq. 2, 7, 8, the same update_weights as the clusters); its object is the arg-max.
    //    A pixel with depth outside every object forgets its weights.
    // Raw pointers, as in the surface-change pass above.
    const std::uint16_t* const seg = segments.labels.data();
    const int* const seg_slot = seg_slot_.data();
    const std::uint8_t* const taken = slot_taken.data();
    const std::uint8_t* const valid = cloud.valid.data();
    std::uint8_t* const changed = changed_.data();
    std::uint8_t* const has_mu = has_mu_.data();
    std::uint8_t* const slot_of = slot_of_.data();
    PixelWeights* const mu = mu_.data();
    const float psi = params_.psi;
    const auto Nn = static_cast<std::ptrdiff_t>(N);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < Nn; ++i) {
        const std::size_t p = static_cast<std::size_t>(i);
        const int s = seg[p];
        const int slot = s ? seg_slot[s] : -1;
        if (changed[p]) {
            mu[p] = PixelWeights{};
            has_mu[p] = 0;
        }
        if (slot >= 0) {
            int label = update_weights(mu[p], slot, psi);
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

    // 5. Objects: sums per slot, then boxes.
    obj_sums_.assign(Kz * kObjSums, 0.0);
    std::vector<int> umin(Kz, W), vmin(Kz, H), umax(Kz, -1), vmax(Kz, -1);
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const std::size_t p = static_cast<std::size_t>(v) * W + u;
            if (!slot_of_[p]) continue;
            const std::size_t j = slot_of_[p] - 1u;
            double* o = obj_sums_.data() + j * kObjSums;
            const double x = cloud.x[p], y = cloud.y[p], z = cloud.z[p];
            o[0] += 1;
            o[1] += x; o[2] += y; o[3] += z;
            o[4] += x * x; o[5] += x * y; o[6] += x * z;
            o[7] += y * y; o[8] += y * z; o[9] += z * z;
            o[10] += cloud.r[p]; o[11] += cloud.g[p]; o[12] += cloud.b[p];
            umin[j] = std::min(umin[j], u); umax[j] = std::max(umax[j], u);
            vmin[j] = std::min(vmin[j], v); vmax[j] = std::max(vmax[j], v);
        }
    // Objects too small after weighting are dropped (their pixels become background).
    std::vector<std::uint8_t> keep(Kz, 0);
    for (std::size_t j = 0; j < Kz; ++j)
        keep[j] = obj_sums_[j * kObjSums] >= params_.min_points && tracks_[j].id != 0;

    objects.width = W;
    objects.height = H;
    objects.labels.resize(N);
    out.clear();
    std::vector<int> index_of(Kz, -1);
    for (std::size_t j = 0; j < Kz; ++j) {
        if (!keep[j]) continue;
        const double* o = obj_sums_.data() + j * kObjSums;
        const double n = o[0];
        DetectedObject d;
        d.track_id = d.id = tracks_[j].id;
        d.pixels = static_cast<std::size_t>(n);
        const Eigen::Vector3d c(o[1] / n, o[2] / n, o[3] / n);
        d.centroid = {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
        Eigen::Matrix3d m;
        m(0, 0) = o[4] / n - c.x() * c.x();
        m(0, 1) = m(1, 0) = o[5] / n - c.x() * c.y();
        m(0, 2) = m(2, 0) = o[6] / n - c.x() * c.z();
        m(1, 1) = o[7] / n - c.y() * c.y();
        m(1, 2) = m(2, 1) = o[8] / n - c.y() * c.z();
        m(2, 2) = o[9] / n - c.z() * c.z();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                d.obb_axes[static_cast<std::size_t>(3 * a + b)] =
                    static_cast<float>(eig.eigenvectors()(b, 2 - a));  // largest spread first
        d.u_min = umin[j]; d.u_max = umax[j]; d.v_min = vmin[j]; d.v_max = vmax[j];
        d.mean_rgb = {static_cast<float>(o[10] / n), static_cast<float>(o[11] / n), static_cast<float>(o[12] / n)};
        d.aabb_min = {INFINITY, INFINITY, INFINITY};
        d.aabb_max = {-INFINITY, -INFINITY, -INFINITY};
        index_of[j] = static_cast<int>(out.size());
        out.push_back(std::move(d));
    }
    // Second pass: boxes' extents, source clusters and segments, the label image.
    std::vector<std::array<float, 6>> proj(out.size(), {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY});
    int max_cluster = 0;
    for (std::uint16_t l : clusters.labels) max_cluster = std::max<int>(max_cluster, l);
    cluster_count_.assign(out.size() * static_cast<std::size_t>(max_cluster + 1), 0);
    std::vector<std::vector<int>> seg_count(out.size());
    for (std::size_t p = 0; p < N; ++p) {
        const int i = slot_of_[p] ? index_of[slot_of_[p] - 1u] : -1;
        if (i < 0) {
            objects.labels[p] = 0;
            continue;
        }
        DetectedObject& d = out[static_cast<std::size_t>(i)];
        objects.labels[p] = static_cast<std::uint16_t>(std::min(d.id, 65535));
        const float pt[3] = {cloud.x[p], cloud.y[p], cloud.z[p]};
        for (int a = 0; a < 3; ++a) {
            d.aabb_min[static_cast<std::size_t>(a)] = std::min(d.aabb_min[static_cast<std::size_t>(a)], pt[a]);
            d.aabb_max[static_cast<std::size_t>(a)] = std::max(d.aabb_max[static_cast<std::size_t>(a)], pt[a]);
            const float* ax = d.obb_axes.data() + 3 * a;
            const float t = ax[0] * (pt[0] - d.centroid[0]) + ax[1] * (pt[1] - d.centroid[1]) + ax[2] * (pt[2] - d.centroid[2]);
            auto& pr = proj[static_cast<std::size_t>(i)];
            pr[static_cast<std::size_t>(a)] = std::min(pr[static_cast<std::size_t>(a)], t);
            pr[static_cast<std::size_t>(a + 3)] = std::max(pr[static_cast<std::size_t>(a + 3)], t);
        }
        if (!clusters.labels.empty())
            ++cluster_count_[static_cast<std::size_t>(i) * static_cast<std::size_t>(max_cluster + 1) + clusters.labels[p]];
        const int s = segments.labels[p];
        if (s) {
            auto& sc = seg_count[static_cast<std::size_t>(i)];
            if (std::find(sc.begin(), sc.end(), s) == sc.end()) sc.push_back(s);
        }
    }
    for (std::size_t i = 0; i < out.size(); ++i) {
        DetectedObject& d = out[i];
        const auto& pr = proj[i];
        for (int a = 0; a < 3; ++a) {
            const float mid = 0.5f * (pr[static_cast<std::size_t>(a)] + pr[static_cast<std::size_t>(a + 3)]);
            d.obb_half_extent[static_cast<std::size_t>(a)] = 0.5f * (pr[static_cast<std::size_t>(a + 3)] - pr[static_cast<std::size_t>(a)]);
            for (int b = 0; b < 3; ++b) d.obb_centre[static_cast<std::size_t>(b)] += mid * d.obb_axes[static_cast<std::size_t>(3 * a + b)];
        }
        for (int b = 0; b < 3; ++b) d.obb_centre[static_cast<std::size_t>(b)] += d.centroid[static_cast<std::size_t>(b)];
        for (int l = 1; l <= max_cluster; ++l) {
            const int cnt = cluster_count_[i * static_cast<std::size_t>(max_cluster + 1) + static_cast<std::size_t>(l)];
            if (cnt > 0 && static_cast<double>(cnt) >= 0.05 * static_cast<double>(d.pixels)) d.source_clusters.push_back(l);
        }
        d.source_segments = seg_count[i];
        std::sort(d.source_segments.begin(), d.source_segments.end());
    }

    // 6. Tracks: remember where each object is; count frames unseen; retire the long lost.
    for (std::size_t j = 0; j < Kz; ++j) {
        Track& t = tracks_[j];
        if (t.id == 0) continue;
        const double* o = obj_sums_.data() + j * kObjSums;
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
