// Eq. (9)'s display colours in bands of rows (internal): render_weight_colors in two steps,
// for a caller that hands the rows out itself (the pipeline, as tasks beside the
// segmentation).
#pragma once

#include <vector>

#include "wul3d/clustering.hpp"
#include "wul3d/frame.hpp"
#include "wul3d/image.hpp"

namespace wul3d::detail {

class WeightColours {
public:
    /// The palette of the state's k clusters, and `out` sized to the labels'. Keeps pointers
    /// to all four until the rows are done. O(k); allocates only when k grows.
    void prepare(const ClusterState& state, const LabelImage& labels, const RgbdView& frame, ColorImage& out);
    /// Rows [v0, v1) of `out` (render_weight_colors' pixels). After prepare; bands may run in
    /// any order, on any threads. O(W (v1 - v0)).
    void rows(int v0, int v1) const;
    /// Every row, spread over the threads.
    void all_rows() const;
    int height() const { return labels_ ? labels_->height : 0; }

private:
    std::vector<float> colour_;  ///< four floats a cluster, the fourth 0, over kOne
    const ClusterState* state_ = nullptr;
    const LabelImage* labels_ = nullptr;
    const std::uint8_t* rgb_ = nullptr;  ///< the frame's colour where it matches, else nullptr
    ColorImage* out_ = nullptr;
};

}  // namespace wul3d::detail
