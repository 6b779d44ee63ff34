#include "wul3d/objects.hpp"

#include <algorithm>
#include <sstream>

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
