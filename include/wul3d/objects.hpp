#pragma once
/// @file objects.hpp
/// The paper's user-defined object (its third contribution): the user picks a pixel of the
/// first frame; the cluster under it is the object, followed from frame to frame.
#include <cstdint>
#include <vector>

#include "wul3d/clustering.hpp"

namespace wul3d {

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

    int cluster() const { return cluster_; }  ///< 1..k, 0 before the first update
    std::size_t pixels() const { return pixels_; }

private:
    int u_, v_, radius_;
    int cluster_ = 0;
    std::size_t pixels_ = 0;
    std::vector<std::uint8_t> previous_;
    std::vector<std::int64_t> votes_;
};

}  // namespace wul3d
