// The OSD/OCID segmentation metric (eval.hpp) on hand-made label images whose answers are
// worked out by hand in the comments, the Hungarian matching against brute force, and the
// temporal report on a synthetic sequence.
#include "wul3d/eval.hpp"

#include <gtest/gtest.h>

#include "synthetic_scene.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "wul3d/error.hpp"

using namespace wul3d;

using wul3d::test::blank_labels;
using wul3d::test::fill_rect;

namespace {

void expect_all(const ImageScore& s, double p, double r, double f) {
    EXPECT_DOUBLE_EQ(s.overlap_p, p);
    EXPECT_DOUBLE_EQ(s.overlap_r, r);
    EXPECT_DOUBLE_EQ(s.overlap_f, f);
    EXPECT_DOUBLE_EQ(s.boundary_p, p);
    EXPECT_DOUBLE_EQ(s.boundary_r, r);
    EXPECT_DOUBLE_EQ(s.boundary_f, f);
}

double total(const std::vector<double>& w, int cols, const std::vector<int>& assignment) {
    double t = 0;
    for (std::size_t r = 0; r < assignment.size(); ++r)
        if (assignment[r] >= 0) t += w[r * static_cast<std::size_t>(cols) + assignment[r]];
    return t;
}

}  // namespace

// ---- parameters ---------------------------------------------------------------------

TEST(EvalParams, Validate_RejectsOutOfRange) {
    EvalParams p;
    EXPECT_NO_THROW(p.validate());
    p.boundary_fraction = 0;
    EXPECT_THROW(p.validate(), ParamError);
    p = {};
    p.boundary_tolerance_px = -2;
    EXPECT_THROW(p.validate(), ParamError);
    p = {};
    p.detected_f = 1.5;
    EXPECT_THROW(p.validate(), ParamError);
}

TEST(BoundaryTolerance, CeilOfDiagonalFraction) {
    const EvalParams p;
    EXPECT_EQ(boundary_tolerance_px(p, 640, 480), 3);    // ceil(0.003 * 800) = ceil(2.4)
    EXPECT_EQ(boundary_tolerance_px(p, 1920, 1080), 7);  // ceil(0.003 * 2202.9) = ceil(6.6)
    EXPECT_EQ(boundary_tolerance_px(p, 20, 12), 1);      // ceil(0.07)
    EvalParams fixed;
    fixed.boundary_tolerance_px = 0;
    EXPECT_EQ(boundary_tolerance_px(fixed, 640, 480), 0);
}

// ---- Hungarian ----------------------------------------------------------------------

TEST(Hungarian, BeatsGreedy_TwoByTwo) {
    // Greedy takes 0.9 first and is left with 0.0: total 0.9. The best is 0.8 + 0.8.
    const std::vector<double> w = {0.9, 0.8,  //
                                   0.8, 0.0};
    const auto a = hungarian_max(w, 2, 2);
    ASSERT_EQ(a.size(), 2u);
    EXPECT_EQ(a[0], 1);
    EXPECT_EQ(a[1], 0);
}

TEST(Hungarian, BeatsGreedy_ThreeByFour) {
    // Greedy takes 10 (0,0), then 8 (2,2), then 6 (1,1): 24. The best: (0,1) 9 + (1,0) 9 +
    // (2,2) 8 = 26; column 3 stays free.
    const std::vector<double> w = {10, 9, 0, 0,  //
                                   9,  6, 0, 0,  //
                                   0,  0, 8, 1};
    const auto a = hungarian_max(w, 3, 4);
    EXPECT_EQ(a, (std::vector<int>{1, 0, 2}));
    EXPECT_DOUBLE_EQ(total(w, 4, a), 26.0);
}

TEST(Hungarian, MatchesBruteForce_RandomRectangular) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    for (int trial = 0; trial < 300; ++trial) {
        const int rows = 1 + trial % 5, cols = 1 + (trial / 5) % 5;
        std::vector<double> w(static_cast<std::size_t>(rows * cols));
        for (double& x : w) x = (trial % 3 == 0) ? std::floor(uni(rng) * 3) : uni(rng);  // ties too
        const auto a = hungarian_max(w, rows, cols);
        // one-to-one, every row matched when rows <= cols
        std::vector<int> used(static_cast<std::size_t>(cols), 0);
        int matched = 0;
        for (int c : a) {
            if (c < 0) continue;
            ASSERT_LT(c, cols);
            ASSERT_EQ(used[static_cast<std::size_t>(c)]++, 0);
            ++matched;
        }
        EXPECT_EQ(matched, std::min(rows, cols));
        // brute force over all injections of the smaller side
        double best = 0;
        if (rows <= cols) {
            std::vector<int> perm(static_cast<std::size_t>(cols));
            std::iota(perm.begin(), perm.end(), 0);
            do {
                double t = 0;
                for (int r = 0; r < rows; ++r)
                    t += w[static_cast<std::size_t>(r * cols + perm[static_cast<std::size_t>(r)])];
                best = std::max(best, t);
            } while (std::next_permutation(perm.begin(), perm.end()));
        } else {
            std::vector<int> perm(static_cast<std::size_t>(rows));
            std::iota(perm.begin(), perm.end(), 0);
            do {
                double t = 0;
                for (int c = 0; c < cols; ++c)
                    t += w[static_cast<std::size_t>(perm[static_cast<std::size_t>(c)] * cols + c)];
                best = std::max(best, t);
            } while (std::next_permutation(perm.begin(), perm.end()));
        }
        EXPECT_NEAR(total(w, cols, a), best, 1e-12) << rows << "x" << cols << " trial " << trial;
    }
}

TEST(Hungarian, EmptyAndBadSizes) {
    EXPECT_TRUE(hungarian_max({}, 0, 3).empty());
    EXPECT_EQ(hungarian_max({}, 2, 0), (std::vector<int>{-1, -1}));
    EXPECT_THROW(hungarian_max({1.0, 2.0}, 2, 2), ParamError);
}

// ---- one image, hand-computed -------------------------------------------------------
// Images of 20 x 12 have a tolerance of ceil(0.003 * 23.3) = 1 px; 640 x 480 ones 3 px.
// A boundary pixel is an object pixel with a 4-neighbour of another label inside the image,
// so a w x h rectangle in the open has 2w + 2h - 4 of them.

TEST(ScoreImage, Perfect_AllOneWhateverTheIds) {
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 1, 1, 6, 8, 1);
    fill_rect(gt, 7, 1, 12, 8, 2);  // touching object 1
    fill_rect(gt, 15, 3, 18, 10, 5);
    fill_rect(pred, 1, 1, 6, 8, 9);
    fill_rect(pred, 7, 1, 12, 8, 3);
    fill_rect(pred, 15, 3, 18, 10, 1);
    const ImageScore s = score_image(pred, gt);
    expect_all(s, 1, 1, 1);
    EXPECT_DOUBLE_EQ(s.detected_share, 1.0);
    EXPECT_EQ(s.gt_objects, 3);
    EXPECT_EQ(s.pred_objects, 3);
    EXPECT_EQ(s.detected, 3);
    ASSERT_EQ(s.matches.size(), 3u);
    EXPECT_EQ(s.matches[0].gt_id, 1);
    EXPECT_EQ(s.matches[0].pred_id, 9);
    EXPECT_EQ(s.matches[2].gt_id, 5);
    EXPECT_EQ(s.matches[2].pred_id, 1);
}

TEST(ScoreImage, SplitObject) {
    // GT: one 10 x 10 square (100 px). Prediction: its left 6 columns (60 px, id 1) and right
    // 4 (40 px, id 2). F(gt, 1) = 2*60/160 = 0.75, F(gt, 2) = 80/140: id 1 is matched.
    // Overlap P = 60/100, R = 60/100, F = 0.6. %>=75: 0.75 is not > 0.75, so 0.
    // Boundaries: GT 36 px; pred 1 (6 x 10) 28 px, pred 2 (4 x 10) 24 px, 52 in all.
    // Pred 1's right column u = 10 lies 4 px from the GT's right column; only its rows
    // v = 2 and v = 9 are within 1 px of the GT's top or bottom row: 6 of 28 miss -> 22.
    // The GT's boundary misses pred 1's at u = 12..14 on the top and bottom rows (3 + 3)
    // and on the right column v = 2..9 (8): 14 of 36 miss -> 22.
    // Boundary P = 22/52, R = 22/36, F = 2*22/(52 + 36) = 0.5.
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 5, 1, 14, 10, 1);
    fill_rect(pred, 5, 1, 10, 10, 1);
    fill_rect(pred, 11, 1, 14, 10, 2);
    const ImageScore s = score_image(pred, gt);
    EXPECT_EQ(s.boundary_tolerance_px, 1);
    EXPECT_DOUBLE_EQ(s.overlap_p, 0.6);
    EXPECT_DOUBLE_EQ(s.overlap_r, 0.6);
    EXPECT_NEAR(s.overlap_f, 0.6, 1e-12);
    EXPECT_DOUBLE_EQ(s.boundary_p, 22.0 / 52.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 22.0 / 36.0);
    EXPECT_NEAR(s.boundary_f, 0.5, 1e-12);
    EXPECT_EQ(s.detected, 0);
    EXPECT_DOUBLE_EQ(s.detected_share, 0.0);
    ASSERT_EQ(s.matches.size(), 1u);
    EXPECT_EQ(s.matches[0].pred_id, 1);
    EXPECT_DOUBLE_EQ(s.matches[0].overlap_f, 0.75);
}

TEST(ScoreImage, MergedObjects) {
    // GT: A = 4 x 10 (40 px) and B = 8 x 10 (80 px) side by side; prediction one 12 x 10
    // object (120 px). F(A) = 80/160 = 0.5, F(B) = 160/200 = 0.8: B is matched.
    // Overlap P = 80/120, R = 80/120, F = 2/3; %>=75 = 1 of 2.
    // Boundaries: A 24, B 32 (56 in all), prediction 40 px. Prediction pixels away from B's
    // boundary: its left column (10) and u = 3, 4 on the top and bottom rows (4): 26 hit.
    // B's boundary pixels away from the prediction's: its left column at v = 3..8 (6):
    // 26 hit. Boundary P = 26/40, R = 26/56, F = 52/96.
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 2, 1, 5, 10, 1);
    fill_rect(gt, 6, 1, 13, 10, 2);
    fill_rect(pred, 2, 1, 13, 10, 4);
    const ImageScore s = score_image(pred, gt);
    EXPECT_DOUBLE_EQ(s.overlap_p, 80.0 / 120.0);
    EXPECT_DOUBLE_EQ(s.overlap_r, 80.0 / 120.0);
    EXPECT_NEAR(s.overlap_f, 2.0 / 3.0, 1e-12);
    EXPECT_DOUBLE_EQ(s.boundary_p, 26.0 / 40.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 26.0 / 56.0);
    EXPECT_NEAR(s.boundary_f, 52.0 / 96.0, 1e-12);
    EXPECT_EQ(s.detected, 1);
    EXPECT_DOUBLE_EQ(s.detected_share, 0.5);
    ASSERT_EQ(s.matches.size(), 1u);
    EXPECT_EQ(s.matches[0].gt_id, 2);
}

TEST(ScoreImage, MissedObject) {
    // GT: two 4 x 5 objects far apart; the prediction finds only the first, exactly.
    // Overlap P = 20/20, R = 20/40, F = 2/3; boundaries 14 px each: P = 1, R = 1/2, F = 2/3.
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 1, 1, 4, 5, 1);
    fill_rect(gt, 12, 1, 15, 5, 2);
    fill_rect(pred, 1, 1, 4, 5, 7);
    const ImageScore s = score_image(pred, gt);
    EXPECT_DOUBLE_EQ(s.overlap_p, 1.0);
    EXPECT_DOUBLE_EQ(s.overlap_r, 0.5);
    EXPECT_NEAR(s.overlap_f, 2.0 / 3.0, 1e-12);
    EXPECT_DOUBLE_EQ(s.boundary_p, 1.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 0.5);
    EXPECT_NEAR(s.boundary_f, 2.0 / 3.0, 1e-12);
    EXPECT_DOUBLE_EQ(s.detected_share, 0.5);
}

TEST(ScoreImage, EmptyPrediction_PrecisionOneRecallZero) {
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 1, 1, 4, 5, 1);
    const ImageScore s = score_image(pred, gt);
    expect_all(s, 1, 0, 0);
    EXPECT_DOUBLE_EQ(s.detected_share, 0.0);
    EXPECT_EQ(s.pred_objects, 0);
    EXPECT_EQ(s.gt_objects, 1);
    EXPECT_TRUE(s.matches.empty());
}

TEST(ScoreImage, EmptyGroundTruth_PrecisionZeroRecallOne) {
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(pred, 1, 1, 4, 5, 3);
    const ImageScore s = score_image(pred, gt);
    expect_all(s, 0, 1, 0);
    EXPECT_DOUBLE_EQ(s.detected_share, 0.0);
    EXPECT_EQ(s.gt_objects, 0);
}

TEST(ScoreImage, BothEmpty_AllOne) {
    const ImageScore s = score_image(blank_labels(20, 12), blank_labels(20, 12));
    expect_all(s, 1, 1, 1);
    EXPECT_DOUBLE_EQ(s.detected_share, 1.0);
}

TEST(ScoreImage, BoundaryShiftedTwoPixels_WithinTolerance) {
    // 640 x 480: tolerance 3 px. A 20 x 20 square, predicted 2 px to the right.
    // Overlap: 18 x 20 = 360 of 400 on both sides: P = R = F = 0.9. Every boundary pixel of
    // either square lies within 2 px of the other's boundary: boundary P = R = F = 1.
    LabelImage gt = blank_labels(640, 480), pred = blank_labels(640, 480);
    fill_rect(gt, 100, 100, 119, 119, 1);
    fill_rect(pred, 102, 100, 121, 119, 1);
    const ImageScore s = score_image(pred, gt);
    EXPECT_EQ(s.boundary_tolerance_px, 3);
    EXPECT_DOUBLE_EQ(s.overlap_p, 0.9);
    EXPECT_DOUBLE_EQ(s.overlap_r, 0.9);
    EXPECT_NEAR(s.overlap_f, 0.9, 1e-12);
    EXPECT_DOUBLE_EQ(s.boundary_p, 1.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 1.0);
    EXPECT_DOUBLE_EQ(s.boundary_f, 1.0);
    EXPECT_DOUBLE_EQ(s.detected_share, 1.0);
}

TEST(ScoreImage, BoundaryShiftedFourPixels_OutsideTolerance) {
    // Shifted 4 px: overlap 16 x 20 = 320 of 400: P = R = F = 0.8. Of the prediction's 76
    // boundary pixels, its left column u = 104 is 4 px from the GT's left column and meets
    // the GT's top/bottom rows only at v = 100..103 and 116..119 (8 of 20); its right column
    // u = 123 is 4 px from everything (0 of 20); its top and bottom rows without the corners
    // (u = 105..122, 18 each) are on the GT's rows or within 3 px of their end: 8 + 36 = 44.
    // The GT's side is the mirror image: 44 of 76. Boundary P = R = F = 44/76.
    LabelImage gt = blank_labels(640, 480), pred = blank_labels(640, 480);
    fill_rect(gt, 100, 100, 119, 119, 1);
    fill_rect(pred, 104, 100, 123, 119, 1);
    const ImageScore s = score_image(pred, gt);
    EXPECT_DOUBLE_EQ(s.overlap_p, 0.8);
    EXPECT_DOUBLE_EQ(s.overlap_r, 0.8);
    EXPECT_NEAR(s.overlap_f, 0.8, 1e-12);
    EXPECT_DOUBLE_EQ(s.boundary_p, 44.0 / 76.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 44.0 / 76.0);
    EXPECT_NEAR(s.boundary_f, 44.0 / 76.0, 1e-12);
}

TEST(ScoreImage, ImageBorderIsNoBoundary) {
    // An object filling the left half: its boundary is the one column facing the right half.
    // Predicting one column too wide is 1 px off, within the 1 px tolerance.
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 0, 0, 9, 11, 1);
    fill_rect(pred, 0, 0, 10, 11, 1);
    const ImageScore s = score_image(pred, gt);
    EXPECT_DOUBLE_EQ(s.boundary_p, 1.0);
    EXPECT_DOUBLE_EQ(s.boundary_r, 1.0);
    EXPECT_DOUBLE_EQ(s.overlap_p, 120.0 / 132.0);
    EvalParams exact;
    exact.boundary_tolerance_px = 0;  // now the columns u = 9 and u = 10 never coincide
    const ImageScore t = score_image(pred, gt, exact);
    EXPECT_DOUBLE_EQ(t.boundary_p, 0.0);
    EXPECT_DOUBLE_EQ(t.boundary_f, 0.0);
}

TEST(ScoreImage, BoundaryMatchesBruteForceDilation) {
    // Random blobs: the boundary counts must equal a direct per-pair check of "a boundary
    // pixel of one within the tolerance disk of a boundary pixel of the other".
    std::mt19937 rng(3);
    const int w = 64, h = 48;
    for (int trial = 0; trial < 20; ++trial) {
        LabelImage gt = blank_labels(w, h), pred = blank_labels(w, h);
        std::uniform_int_distribution<int> pu(0, w - 1), pv(0, h - 1), sz(3, 20), id(1, 6);
        for (int k = 0; k < 8; ++k) {
            const int u = pu(rng), v = pv(rng);
            fill_rect(gt, u, v, std::min(w - 1, u + sz(rng)), std::min(h - 1, v + sz(rng)),
                 static_cast<std::uint16_t>(id(rng)));
            const int u2 = pu(rng), v2 = pv(rng);
            fill_rect(pred, u2, v2, std::min(w - 1, u2 + sz(rng)), std::min(h - 1, v2 + sz(rng)),
                 static_cast<std::uint16_t>(id(rng)));
        }
        EvalParams params;
        params.boundary_tolerance_px = 2;
        const ImageScore s = score_image(pred, gt, params);
        auto is_boundary = [&](const LabelImage& l, int u, int v) {
            const std::uint16_t a = l.labels[static_cast<std::size_t>(v) * w + u];
            if (a == 0) return false;
            const int du[4] = {-1, 1, 0, 0}, dv[4] = {0, 0, -1, 1};
            for (int n = 0; n < 4; ++n) {
                const int uu = u + du[n], vv = v + dv[n];
                if (uu < 0 || uu >= w || vv < 0 || vv >= h) continue;
                if (l.labels[static_cast<std::size_t>(vv) * w + uu] != a) return true;
            }
            return false;
        };
        auto label_at = [&](const LabelImage& l, int u, int v) {
            return l.labels[static_cast<std::size_t>(v) * w + u];
        };
        // hits(from, a, to, b): boundary pixels of a in `from` near a boundary pixel of b in `to`
        auto hits = [&](const LabelImage& from, std::uint16_t a, const LabelImage& to,
                        std::uint16_t b) {
            long n = 0;
            for (int v = 0; v < h; ++v)
                for (int u = 0; u < w; ++u) {
                    if (label_at(from, u, v) != a || !is_boundary(from, u, v)) continue;
                    bool near = false;
                    for (int vv = std::max(0, v - 2); vv <= std::min(h - 1, v + 2) && !near; ++vv)
                        for (int uu = std::max(0, u - 2); uu <= std::min(w - 1, u + 2); ++uu)
                            if ((uu - u) * (uu - u) + (vv - v) * (vv - v) <= 4 &&
                                label_at(to, uu, vv) == b && is_boundary(to, uu, vv)) {
                                near = true;
                                break;
                            }
                    n += near;
                }
            return n;
        };
        long all_p = 0, all_g = 0;
        for (int v = 0; v < h; ++v)
            for (int u = 0; u < w; ++u) {
                all_p += is_boundary(pred, u, v);
                all_g += is_boundary(gt, u, v);
            }
        long hp = 0, hg = 0;
        for (const MatchedPair& m : s.matches) {
            hp += hits(pred, m.pred_id, gt, m.gt_id);
            hg += hits(gt, m.gt_id, pred, m.pred_id);
        }
        if (s.gt_objects == 0 || s.pred_objects == 0) continue;
        EXPECT_DOUBLE_EQ(s.boundary_p, static_cast<double>(hp) / static_cast<double>(all_p));
        EXPECT_DOUBLE_EQ(s.boundary_r, static_cast<double>(hg) / static_cast<double>(all_g));
    }
}

TEST(ScoreImage, NoCommonPixel_IsNoMatch) {
    // Two predicted objects, one GT object overlapping only the first: one match.
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 1, 1, 4, 4, 1);
    fill_rect(gt, 10, 1, 13, 4, 2);
    fill_rect(pred, 1, 1, 4, 4, 1);
    fill_rect(pred, 1, 8, 4, 10, 2);  // touches no GT object
    const ImageScore s = score_image(pred, gt);
    ASSERT_EQ(s.matches.size(), 1u);
    EXPECT_EQ(s.matches[0].gt_id, 1);
    EXPECT_DOUBLE_EQ(s.overlap_p, 16.0 / 28.0);
    EXPECT_DOUBLE_EQ(s.overlap_r, 16.0 / 32.0);
}

TEST(ScoreImage, SizeMismatch_Throws) {
    EXPECT_THROW(score_image(blank_labels(20, 12), blank_labels(12, 20)), InputError);
    LabelImage broken = blank_labels(20, 12);
    broken.labels.pop_back();
    EXPECT_THROW(score_image(broken, blank_labels(20, 12)), InputError);
}

TEST(Summarize, MacroAverageOverImages) {
    LabelImage gt = blank_labels(20, 12), pred = blank_labels(20, 12);
    fill_rect(gt, 1, 1, 4, 5, 1);
    fill_rect(gt, 12, 1, 15, 5, 2);
    fill_rect(pred, 1, 1, 4, 5, 7);
    const ImageScore missed = score_image(pred, gt);            // F 2/3, P 1, R 1/2
    const ImageScore perfect = score_image(gt, gt);             // all 1
    const EvalSummary m = summarize({missed, perfect});
    EXPECT_EQ(m.images, 2);
    EXPECT_EQ(m.gt_objects, 4);
    EXPECT_EQ(m.pred_objects, 3);
    EXPECT_EQ(m.detected, 3);
    EXPECT_DOUBLE_EQ(m.overlap_p, 1.0);
    EXPECT_DOUBLE_EQ(m.overlap_r, 0.75);
    EXPECT_NEAR(m.overlap_f, (2.0 / 3.0 + 1.0) / 2.0, 1e-12);  // mean of F, not F of means
    EXPECT_DOUBLE_EQ(m.detected_share, 0.75);
    EXPECT_EQ(summarize({}).images, 0);
}

// ---- sequences (synthetic) ----------------------------------------------------------

namespace {

/// Five 10 x 4 frames. GT object 1 = columns 0-3, in every frame; object 2 = columns 6-7,
/// gone in frame 2. The prediction labels object 1 with ids 1, 1, 2, 2, 1 (two switches),
/// object 2 always with id 3, and pixel (9, 0) with id 5 in frame 0 only.
void moving_sequence(std::vector<LabelImage>& preds, std::vector<LabelImage>& gts) {
    const std::uint16_t id1[5] = {1, 1, 2, 2, 1};
    for (int t = 0; t < 5; ++t) {
        LabelImage gt = blank_labels(10, 4), pred = blank_labels(10, 4);
        fill_rect(gt, 0, 0, 3, 3, 1);
        fill_rect(pred, 0, 0, 3, 3, id1[t]);
        if (t != 2) {
            fill_rect(gt, 6, 0, 7, 3, 2);
            fill_rect(pred, 6, 0, 7, 3, 3);
        }
        if (t == 0) fill_rect(pred, 9, 0, 9, 0, 5);
        gts.push_back(gt);
        preds.push_back(pred);
    }
}

}  // namespace

TEST(SequenceScorer, IdSwitchesAndFlicker_KnownSequence) {
    std::vector<LabelImage> preds, gts;
    moving_sequence(preds, gts);
    const TemporalReport r = score_sequence(preds, gts);
    EXPECT_EQ(r.frames, 5);
    EXPECT_EQ(r.frame_pairs, 4);
    // Object 1: 1 -> 1 -> 2 -> 2 -> 1, two switches; object 2: always 3, the gap is none.
    EXPECT_EQ(r.id_switches, 2);
    EXPECT_EQ(r.max_switches, 2);
    EXPECT_DOUBLE_EQ(r.switches_per_object, 1.0);
    ASSERT_EQ(r.objects.size(), 2u);
    EXPECT_EQ(r.objects[0].gt_id, 1);
    EXPECT_EQ(r.objects[0].frames_visible, 5);
    EXPECT_EQ(r.objects[0].switches, 2);
    EXPECT_EQ(r.objects[1].frames_visible, 4);
    EXPECT_EQ(r.objects[1].frames_matched, 4);
    EXPECT_EQ(r.objects[1].switches, 0);
    // Flicker per pair, counted pixels = same GT, and GT or either prediction nonzero:
    // 0->1: 16 + 8 + pixel (9,0) = 25 counted, (9,0) changes: 1/25.
    // 1->2: object 2 vanishes from the GT (excluded): 16 counted, all change: 1.
    // 2->3: 16 counted, none change: 0.   3->4: 24 counted, 16 change: 2/3.
    EXPECT_NEAR(r.flicker, (1.0 / 25.0 + 1.0 + 0.0 + 2.0 / 3.0) / 4.0, 1e-12);
    // Object pixels only: 0/24, 16/16, 0/16, 16/24.
    EXPECT_NEAR(r.object_flicker, (0.0 + 1.0 + 0.0 + 2.0 / 3.0) / 4.0, 1e-12);
}

TEST(SequenceScorer, MissesAreNoSwitches) {
    // GT object 1 in three frames; the prediction finds it as 4, misses it, finds it as 4
    // (no switch), and in a second sequence as 4, miss, 6 (one switch).
    for (const std::uint16_t last : {std::uint16_t{4}, std::uint16_t{6}}) {
        SequenceScorer scorer;
        const std::uint16_t ids[3] = {4, 0, last};
        for (int t = 0; t < 3; ++t) {
            LabelImage gt = blank_labels(10, 4), pred = blank_labels(10, 4);
            fill_rect(gt, 0, 0, 3, 3, 1);
            fill_rect(pred, 0, 0, 3, 3, ids[t]);
            scorer.add(pred, gt);
        }
        const TemporalReport r = scorer.report();
        ASSERT_EQ(r.objects.size(), 1u);
        EXPECT_EQ(r.objects[0].frames_visible, 3);
        EXPECT_EQ(r.objects[0].frames_matched, 2);
        EXPECT_EQ(r.id_switches, last == 4 ? 0 : 1);
    }
}

TEST(SequenceScorer, StableSequence_NoFlicker) {
    std::vector<LabelImage> preds, gts;
    for (int t = 0; t < 4; ++t) {
        LabelImage gt = blank_labels(10, 4);
        fill_rect(gt, 0, 0, 3, 3, 2);
        gts.push_back(gt);
        LabelImage pred = blank_labels(10, 4);
        fill_rect(pred, 0, 0, 4, 3, 8);  // one column too wide, but the same every frame
        preds.push_back(pred);
    }
    const TemporalReport r = score_sequence(preds, gts);
    EXPECT_EQ(r.id_switches, 0);
    EXPECT_DOUBLE_EQ(r.flicker, 0.0);
    EXPECT_DOUBLE_EQ(r.object_flicker, 0.0);
    EXPECT_EQ(r.frame_pairs, 3);
}

TEST(SequenceScorer, SizeChange_Throws) {
    SequenceScorer scorer;
    scorer.add(blank_labels(10, 4), blank_labels(10, 4));
    EXPECT_THROW(scorer.add(blank_labels(4, 10), blank_labels(4, 10)), InputError);
    EXPECT_THROW(score_sequence({blank_labels(10, 4)}, {}), InputError);
}
