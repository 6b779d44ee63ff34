#pragma once
/// @file eval.hpp
/// Scoring an instance segmentation against ground truth with the metric of unseen-object
/// instance segmentation on OSD and OCID (Xie et al., "Unseen Object Instance Segmentation for
/// Robotic Environments", T-RO 2021; Xiang et al., "Learning RGB-D Feature Embeddings for
/// Unseen Object Instance Segmentation", CoRL 2020), plus a temporal report for sequences
/// (id switches, label flicker). Exact definitions and conventions: docs/EVAL.md.
///
/// Label 0 is background in both images; every other value is one object. Scores are
/// fractions in [0, 1]; nothing here prints.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "wul3d/image.hpp"

namespace wul3d {

/// The largest boundary tolerance, in pixels: the work per boundary pixel grows with its
/// square (50 px: 7845 neighbours; the reference's is 3 px at 640x480, 7 at 1920x1080).
inline constexpr int kMaxBoundaryTolerancePx = 50;

/// Parameters of the metric; the defaults are the reference's.
struct EvalParams {
    /// Boundary tolerance as a fraction of the image diagonal: tol = ceil(fraction * diag) px
    /// (3 px at 640x480), at most kMaxBoundaryTolerancePx. In (0, 0.01].
    double boundary_fraction = 0.003;
    /// In [0, kMaxBoundaryTolerancePx]: the boundary tolerance in pixels, overriding
    /// boundary_fraction (0 = boundary pixels must coincide); -1 (default): from
    /// boundary_fraction.
    int boundary_tolerance_px = -1;
    /// A ground-truth object counts as detected (%>=75) when its matched overlap F is
    /// strictly above this; [0, 1].
    double detected_f = 0.75;

    void validate() const;  ///< throws ParamError naming the field, value and range
};

/// The boundary tolerance in pixels for a width x height image: boundary_tolerance_px when
/// >= 0, else ceil(boundary_fraction * sqrt(width^2 + height^2)), at most
/// kMaxBoundaryTolerancePx.
int boundary_tolerance_px(const EvalParams& params, int width, int height);

/// One matched (ground truth, prediction) pair of an image.
struct MatchedPair {
    std::uint16_t gt_id = 0;    ///< ground-truth label value
    std::uint16_t pred_id = 0;  ///< predicted label value
    std::int64_t true_positives = 0;  ///< pixels labelled gt_id in GT and pred_id in prediction
    double overlap_f = 0;       ///< 2 tp / (|gt| + |pred|)
};

/// The metric on one image. All fractions in [0, 1].
struct ImageScore {
    double overlap_p = 0, overlap_r = 0, overlap_f = 0;
    double boundary_p = 0, boundary_r = 0, boundary_f = 0;
    double detected_share = 0;  ///< %>=75: detected / gt_objects (conventions in EVAL.md)
    int gt_objects = 0;         ///< distinct nonzero labels of the ground truth
    int pred_objects = 0;       ///< distinct nonzero labels of the prediction
    int detected = 0;           ///< ground-truth objects whose matched overlap F > detected_f
    int boundary_tolerance_px = 0;
    /// The Hungarian matching, pairs with F > 0 only (a pair with no common pixel is no
    /// match), sorted by gt_id.
    std::vector<MatchedPair> matches;
};

/// The objects of an image pair are matched in groups that overlap (objects with no common
/// pixel do not change the matching's score): at most this many (ground truth x prediction)
/// pairs in one group, and in all the groups of an image. Beyond, score_image throws
/// InputError before the matching allocates anything (a Hungarian over 20,000 x 20,000
/// objects took 12.5 GB).
inline constexpr std::size_t kMaxEvalGroupPairs = std::size_t{1} << 20;
inline constexpr std::size_t kMaxEvalMatchPairs = std::size_t{1} << 22;

/// Scores `pred` against `gt` (same size, else InputError). Overlap and boundary P/R/F of
/// the one-to-one matching that maximises the sum of overlap F (Hungarian), and %>=75.
/// Empty cases follow the reference code: no predicted object but some ground truth gives
/// P = 1, R = 0, F = 0 (overlap and boundary); predicted objects but no ground truth give
/// P = 0, R = 1, F = 0; neither gives every figure 1, %>=75 included.
ImageScore score_image(const LabelImage& pred, const LabelImage& gt,
                       const EvalParams& params = {});

/// The macro average over images: each figure is the mean of the per-image figures (so F is
/// not recomputed from the mean P and R).
struct EvalSummary {
    double overlap_p = 0, overlap_r = 0, overlap_f = 0;
    double boundary_p = 0, boundary_r = 0, boundary_f = 0;
    double detected_share = 0;  ///< mean of the per-image %>=75
    int images = 0;
    std::int64_t gt_objects = 0;    ///< sum over images
    std::int64_t pred_objects = 0;  ///< sum over images
    std::int64_t detected = 0;      ///< sum over images
};
EvalSummary summarize(const std::vector<ImageScore>& scores);

/// Kuhn-Munkres: the one-to-one assignment of rows to columns that maximises the total
/// weight of a rows x cols matrix (row-major, weights[r * cols + c]). Rectangular matrices
/// are solved as if padded to square with zero-weight rows or columns. Returns, for each
/// row, its column, or -1 for a row left without one (only when rows > cols). O(n^2 m),
/// n = min(rows, cols), m = max(rows, cols). Ties are broken deterministically.
std::vector<int> hungarian_max(const std::vector<double>& weights, int rows, int cols);

// ---- sequences ----------------------------------------------------------------------

/// Temporal behaviour of one ground-truth object over a sequence.
struct ObjectTrackScore {
    std::uint16_t gt_id = 0;
    int frames_visible = 0;  ///< frames where the ground truth holds this id
    int frames_matched = 0;  ///< of those, frames where the matching gave it a partner (F > 0)
    int switches = 0;        ///< changes of the partner's id between consecutive matched frames
};

/// The temporal report of a sequence.
struct TemporalReport {
    int frames = 0;
    int frame_pairs = 0;       ///< consecutive pairs whose flicker was defined (counted pixels)
    int id_switches = 0;       ///< sum over ground-truth objects
    double switches_per_object = 0;  ///< id_switches / objects seen
    int max_switches = 0;      ///< most switches of any one object
    /// Mean over frame pairs of the share of pixels whose predicted id changes while the
    /// ground truth id does not, among pixels with the same ground truth in both frames that
    /// are an object in the ground truth or in either prediction.
    double flicker = 0;
    /// The same restricted to pixels that are one ground-truth object in both frames.
    double object_flicker = 0;
    std::vector<ObjectTrackScore> objects;  ///< sorted by gt_id
};

/// Scores a sequence frame by frame: add() each (prediction, ground truth) pair in order,
/// then report(). Holds only the previous frame.
class SequenceScorer {
public:
    explicit SequenceScorer(const EvalParams& params = {});  ///< validates params

    /// Scores one frame (score_image) and folds it into the temporal report. Throws
    /// InputError if the size differs from the images' or from the previous frame's.
    ImageScore add(const LabelImage& pred, const LabelImage& gt);
    TemporalReport report() const;

private:
    struct Track {
        int frames_visible = 0;
        int frames_matched = 0;
        int switches = 0;
        std::uint16_t last_pred = 0;  ///< partner in the last matched frame, 0 = none yet
    };
    EvalParams params_;
    int frames_ = 0;
    LabelImage prev_pred_, prev_gt_;
    std::vector<Track> tracks_;  ///< indexed by gt id (65536 entries once used)
    double flicker_sum_ = 0, object_flicker_sum_ = 0;
    int flicker_pairs_ = 0, object_flicker_pairs_ = 0;
};

/// Convenience: the temporal report of a whole sequence held in memory.
TemporalReport score_sequence(const std::vector<LabelImage>& preds,
                              const std::vector<LabelImage>& gts, const EvalParams& params = {});

}  // namespace wul3d
