// The unseen-object instance segmentation metric (overlap and boundary P/R/F under a
// Hungarian matching, %>=75) and the temporal report. Definitions: docs/EVAL.md.
#include "wul3d/eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>

#include "wul3d/error.hpp"

namespace wul3d {

namespace {

std::string size_str(const LabelImage& l) {
    return std::to_string(l.width) + "x" + std::to_string(l.height);
}

void check_image(const LabelImage& l, const char* what) {
    if (l.width < 0 || l.height < 0 ||
        l.labels.size() != static_cast<std::size_t>(l.width) * static_cast<std::size_t>(l.height))
        throw InputError(std::string(what) + " label image is " + size_str(l) + " but holds " +
                         std::to_string(l.labels.size()) + " labels");
}

/// Dense, 0-based indices of the nonzero label values of an image, in increasing value.
struct Compact {
    std::vector<int> index;          ///< label value -> object index, -1 for absent and 0
    std::vector<std::uint16_t> ids;  ///< object index -> label value
    int size() const { return static_cast<int>(ids.size()); }
};

Compact compact(const std::vector<std::uint16_t>& labels) {
    std::uint16_t max_id = 0;
    for (const std::uint16_t l : labels) max_id = std::max(max_id, l);
    Compact c;
    c.index.assign(static_cast<std::size_t>(max_id) + 1, -1);
    for (const std::uint16_t l : labels)
        if (l != 0) c.index[l] = 0;
    for (std::size_t id = 1; id < c.index.size(); ++id) {
        if (c.index[id] == 0) {
            c.index[id] = c.size();
            c.ids.push_back(static_cast<std::uint16_t>(id));
        }
    }
    return c;
}

/// A boundary pixel is an object pixel (label != 0) with at least one 4-neighbour inside the
/// image whose label differs; the image border itself is no boundary.
inline bool is_boundary(const std::uint16_t* lab, int w, int h, int u, int v) {
    const std::size_t p = static_cast<std::size_t>(v) * w + u;
    const std::uint16_t a = lab[p];
    return a != 0 && ((u > 0 && lab[p - 1] != a) || (u + 1 < w && lab[p + 1] != a) ||
                      (v > 0 && lab[p - w] != a) || (v + 1 < h && lab[p + w] != a));
}

/// The boundary pixels of an image (indices v * w + u, in raster order); `count[i]` gets
/// those of object i. Lists, not full-size maps: a fresh W x H buffer per image costs more
/// in page faults than the whole metric.
void boundary_pixels(const LabelImage& l, const Compact& c, std::vector<int>& out,
                     std::vector<std::int64_t>& count) {
    out.clear();
    count.assign(static_cast<std::size_t>(c.size()), 0);
    for (int v = 0; v < l.height; ++v)
        for (int u = 0; u < l.width; ++u)
            if (is_boundary(l.labels.data(), l.width, l.height, u, v)) {
                const int p = v * l.width + u;
                out.push_back(p);
                ++count[static_cast<std::size_t>(c.index[l.labels[static_cast<std::size_t>(p)]])];
            }
}

struct Offset {
    int du, dv;
};

/// The pixels of the disk of radius r: du^2 + dv^2 <= r^2 (the structuring element of the
/// reference's dilation).
std::vector<Offset> disk(int r) {
    std::vector<Offset> d;
    // 64-bit squares: EvalParams bounds r, but this must not overflow for any int.
    const std::int64_t r2 = std::int64_t{r} * r;
    for (int dv = -r; dv <= r; ++dv)
        for (int du = -r; du <= r; ++du)
            if (std::int64_t{du} * du + std::int64_t{dv} * dv <= r2) d.push_back({du, dv});
    return d;
}

/// For every boundary pixel of `from` whose object a has a partner b = partner[a] in `to`
/// (-1: none), adds 1 to hits[a] when a boundary pixel of b lies within the disk around it:
/// hits[a] = |boundary(a) AND dilate(boundary(b), disk)|, for the matched pairs only (the
/// score needs no other pair, and a table of every pair grows as objects squared).
void boundary_hits(const LabelImage& from, const Compact& cfrom, const std::vector<int>& bfrom,
                   const LabelImage& to, const Compact& cto, const std::vector<int>& partner,
                   const std::vector<Offset>& offsets, std::vector<std::int64_t>& hits) {
    const int w = from.width, h = from.height;
    const std::uint16_t* lt = to.labels.data();
    hits.assign(partner.size(), 0);
    for (const int p : bfrom) {
        const int u = p % w, v = p / w;
        const std::size_t a =
            static_cast<std::size_t>(cfrom.index[from.labels[static_cast<std::size_t>(p)]]);
        if (partner[a] < 0) continue;
        const std::uint16_t lb = cto.ids[static_cast<std::size_t>(partner[a])];
        for (const Offset& o : offsets) {
            const int uu = u + o.du, vv = v + o.dv;
            if (uu < 0 || uu >= w || vv < 0 || vv >= h) continue;
            if (lt[static_cast<std::size_t>(vv) * w + uu] != lb) continue;
            if (!is_boundary(lt, w, h, uu, vv)) continue;
            ++hits[a];
            break;  // this pixel counts once
        }
    }
}

double ratio(double num, double den) { return den > 0 ? num / den : 0.0; }
double harmonic(double p, double r) { return p + r > 0 ? 2.0 * p * r / (p + r) : 0.0; }

void set_all(ImageScore& s, double p, double r, double f, double detected_share) {
    s.overlap_p = s.boundary_p = p;
    s.overlap_r = s.boundary_r = r;
    s.overlap_f = s.boundary_f = f;
    s.detected_share = detected_share;
}

/// A (ground truth, prediction) pair of object indices as one key: g << 16 | p.
using PairKey = std::uint32_t;
inline PairKey pair_key(int g, int p) {
    return static_cast<PairKey>(g) << 16 | static_cast<PairKey>(p);
}
inline int key_g(PairKey k) { return static_cast<int>(k >> 16); }
inline int key_p(PairKey k) { return static_cast<int>(k & 0xffffu); }

/// Overlap: each object's pixels, and the common pixels of the (ground truth, prediction)
/// pairs that have any, sorted by key: at most one entry per pixel, never np x ng (20,000
/// objects on each side made that 12.5 GB). One pass over the image.
struct OverlapTable {
    std::vector<std::int64_t> size_p, size_g;
    std::int64_t all_p = 0, all_g = 0;
    std::vector<std::pair<PairKey, std::int64_t>> pairs;  ///< (key, tp > 0), by key

    std::int64_t tp(int g, int p) const {
        const PairKey k = pair_key(g, p);
        const auto it = std::lower_bound(pairs.begin(), pairs.end(), k,
                                         [](const auto& e, PairKey x) { return e.first < x; });
        return it != pairs.end() && it->first == k ? it->second : 0;
    }
    /// The overlap F of the pair: the harmonic mean of tp / |p| and tp / |g|.
    double f(int g, int p, std::int64_t tp) const {
        return 2.0 * static_cast<double>(tp) /
               static_cast<double>(size_p[static_cast<std::size_t>(p)] +
                                   size_g[static_cast<std::size_t>(g)]);
    }
};
OverlapTable overlap_table(const LabelImage& pred, const Compact& cp, const LabelImage& gt, const Compact& cg) {
    OverlapTable t;
    t.size_p.assign(static_cast<std::size_t>(cp.size()), 0);
    t.size_g.assign(static_cast<std::size_t>(cg.size()), 0);
    std::unordered_map<PairKey, std::int64_t> common;
    // Runs of one pair are counted locally: a map look-up per run, not per pixel.
    PairKey run_key = 0;
    std::int64_t run = 0;
    for (std::size_t q = 0; q < gt.labels.size(); ++q) {
        const std::uint16_t a = pred.labels[q], b = gt.labels[q];
        const int i = a ? cp.index[a] : -1;
        const int k = b ? cg.index[b] : -1;
        if (i >= 0) ++t.size_p[static_cast<std::size_t>(i)];
        if (k >= 0) ++t.size_g[static_cast<std::size_t>(k)];
        if (i < 0 || k < 0) continue;
        const PairKey key = pair_key(k, i);
        if (run > 0 && key != run_key) {
            common[run_key] += run;
            run = 0;
        }
        run_key = key;
        ++run;
    }
    if (run > 0) common[run_key] += run;
    for (const auto n : t.size_p) t.all_p += n;
    for (const auto n : t.size_g) t.all_g += n;
    t.pairs.assign(common.begin(), common.end());
    std::sort(t.pairs.begin(), t.pairs.end());
    return t;
}

/// Up to this many (ground truth x prediction) pairs the matching is one Hungarian over
/// every pair, as it always was; above, one per group of objects that overlap (the pairs
/// without a common pixel weigh 0 and change no score), each and all of them bounded.
constexpr std::size_t kWholeMatchPairs = std::size_t{1} << 20;

/// The matching that maximises the sum of overlap F: ground-truth index -> prediction
/// index, -1 none (or a pair of F = 0, which scores as none).
std::vector<int> best_matching(const OverlapTable& ot, int np, int ng) {
    if (static_cast<std::size_t>(np) * static_cast<std::size_t>(ng) <= kWholeMatchPairs) {
        std::vector<double> f(static_cast<std::size_t>(np) * static_cast<std::size_t>(ng), 0.0);
        for (const auto& [key, tp] : ot.pairs)
            f[static_cast<std::size_t>(key_g(key)) * static_cast<std::size_t>(np) +
              static_cast<std::size_t>(key_p(key))] = ot.f(key_g(key), key_p(key), tp);
        return hungarian_max(f, ng, np);
    }
    // Groups: the connected parts of the graph of pairs with common pixels (union-find over
    // ground-truth nodes 0..ng-1 and prediction nodes ng..ng+np-1).
    std::vector<int> parent(static_cast<std::size_t>(ng + np));
    for (std::size_t n = 0; n < parent.size(); ++n) parent[n] = static_cast<int>(n);
    const auto root = [&](int n) {
        while (parent[static_cast<std::size_t>(n)] != n)
            n = parent[static_cast<std::size_t>(n)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(n)])];
        return n;
    };
    for (const auto& e : ot.pairs) {
        const int a = root(key_g(e.first)), b = root(ng + key_p(e.first));
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
    // Each group's objects, in increasing index (so in increasing label value).
    std::map<int, std::pair<std::vector<int>, std::vector<int>>> groups;
    for (int n = 0; n < ng + np; ++n) {
        auto& [rows, cols] = groups[root(n)];
        (n < ng ? rows : cols).push_back(n < ng ? n : n - ng);
    }
    std::size_t all_pairs = 0;
    for (const auto& [id, g] : groups) {
        const std::size_t pairs = g.first.size() * g.second.size();
        all_pairs += pairs;
        if (pairs > kMaxEvalGroupPairs || all_pairs > kMaxEvalMatchPairs)
            throw InputError(
                std::to_string(ng) + " ground-truth and " + std::to_string(np) +
                " predicted objects overlap in " +
                (pairs > kMaxEvalGroupPairs
                     ? "a group of " + std::to_string(g.first.size()) + " x " +
                           std::to_string(g.second.size()) + " objects"
                     : "groups of more than " + std::to_string(kMaxEvalMatchPairs) + " pairs") +
                ": more than eval matches (at most " + std::to_string(kMaxEvalGroupPairs) +
                " pairs in a group, " + std::to_string(kMaxEvalMatchPairs) + " in an image)");
    }
    std::vector<int> match(static_cast<std::size_t>(ng), -1);
    std::vector<double> f;
    for (const auto& [id, g] : groups) {
        const auto& [rows, cols] = g;
        if (rows.empty() || cols.empty()) continue;  // an object overlapping none
        f.assign(rows.size() * cols.size(), 0.0);
        for (std::size_t r = 0; r < rows.size(); ++r)
            for (std::size_t c = 0; c < cols.size(); ++c)
                if (const std::int64_t tp = ot.tp(rows[r], cols[c]); tp > 0)
                    f[r * cols.size() + c] = ot.f(rows[r], cols[c], tp);
        const std::vector<int> m =
            hungarian_max(f, static_cast<int>(rows.size()), static_cast<int>(cols.size()));
        for (std::size_t r = 0; r < rows.size(); ++r)
            if (m[r] >= 0) match[static_cast<std::size_t>(rows[r])] = cols[static_cast<std::size_t>(m[r])];
    }
    return match;
}

/// The scores of the matched pairs (`match`: ground truth -> prediction, -1 none) into `s`:
/// its matches, detected objects, and the overlap and boundary precision, recall and F over
/// all objects. The boundaries: the boundary pixels of both images, and for each matched
/// pair those of one within `tolerance_px` of the other's. Cost: O(boundary pixels x disk
/// area).
void score_matches(const OverlapTable& ot, const std::vector<int>& match, const LabelImage& pred,
                   const Compact& cp, const LabelImage& gt, const Compact& cg,
                   const EvalParams& params, ImageScore& s) {
    const int np = cp.size(), ng = cg.size();
    std::vector<int> partner_p(static_cast<std::size_t>(np), -1), partner_g(static_cast<std::size_t>(ng), -1);
    std::vector<std::int64_t> tps(static_cast<std::size_t>(ng), 0);
    std::int64_t tp_sum = 0;
    for (int k = 0; k < ng; ++k) {
        const int i = match[static_cast<std::size_t>(k)];
        if (i < 0) continue;
        // F = 0 (no common pixel) is no match. The reference keeps such Hungarian pairs and
        // adds their boundary hits; which F = 0 pairs it picks is an arbitrary tie-break.
        const std::int64_t tp = ot.tp(k, i);
        if (tp == 0) continue;
        partner_g[static_cast<std::size_t>(k)] = i;
        partner_p[static_cast<std::size_t>(i)] = k;
        MatchedPair m;
        m.gt_id = cg.ids[static_cast<std::size_t>(k)];
        m.pred_id = cp.ids[static_cast<std::size_t>(i)];
        m.true_positives = tp;
        m.overlap_f = ot.f(k, i, tp);
        s.matches.push_back(m);
        if (m.overlap_f > params.detected_f) ++s.detected;
        tp_sum += tp;
    }
    std::vector<int> bp, bg;
    std::vector<std::int64_t> bcount_p, bcount_g, hit_p, hit_g;
    boundary_pixels(pred, cp, bp, bcount_p);
    boundary_pixels(gt, cg, bg, bcount_g);
    std::int64_t all_bp = 0, all_bg = 0;
    for (const auto n : bcount_p) all_bp += n;
    for (const auto n : bcount_g) all_bg += n;
    const std::vector<Offset> offsets = disk(s.boundary_tolerance_px);
    boundary_hits(pred, cp, bp, gt, cg, partner_p, offsets, hit_p);
    boundary_hits(gt, cg, bg, pred, cp, partner_g, offsets, hit_g);
    std::int64_t bp_sum = 0, bg_sum = 0;
    for (const auto n : hit_p) bp_sum += n;
    for (const auto n : hit_g) bg_sum += n;
    s.overlap_p = ratio(static_cast<double>(tp_sum), static_cast<double>(ot.all_p));
    s.overlap_r = ratio(static_cast<double>(tp_sum), static_cast<double>(ot.all_g));
    s.overlap_f = harmonic(s.overlap_p, s.overlap_r);
    s.boundary_p = ratio(static_cast<double>(bp_sum), static_cast<double>(all_bp));
    s.boundary_r = ratio(static_cast<double>(bg_sum), static_cast<double>(all_bg));
    s.boundary_f = harmonic(s.boundary_p, s.boundary_r);
    s.detected_share = static_cast<double>(s.detected) / ng;
}

}  // namespace

void EvalParams::validate() const {
    if (!(boundary_fraction > 0 && boundary_fraction <= 0.01))
        throw ParamError("EvalParams.boundary_fraction = " + std::to_string(boundary_fraction) +
                         ": must be in (0, 0.01]");
    if (boundary_tolerance_px < -1 || boundary_tolerance_px > kMaxBoundaryTolerancePx)
        throw ParamError("EvalParams.boundary_tolerance_px = " +
                         std::to_string(boundary_tolerance_px) + ": must be in [0, " +
                         std::to_string(kMaxBoundaryTolerancePx) +
                         "], or -1 for the fraction of the diagonal");
    if (!(detected_f >= 0 && detected_f <= 1))
        throw ParamError("EvalParams.detected_f = " + std::to_string(detected_f) +
                         ": must be in [0, 1]");
}

int boundary_tolerance_px(const EvalParams& params, int width, int height) {
    if (params.boundary_tolerance_px >= 0) return params.boundary_tolerance_px;
    // As the reference: ceil(0.003 * norm((H, W))), the norm taken as sqrt of the squares.
    const double diag = std::sqrt(static_cast<double>(width) * width +
                                  static_cast<double>(height) * height);
    const double t = std::ceil(params.boundary_fraction * diag);
    return static_cast<int>(std::min(t, static_cast<double>(kMaxBoundaryTolerancePx)));
}

std::vector<int> hungarian_max(const std::vector<double>& weights, int rows, int cols) {
    if (rows < 0 || cols < 0 ||
        weights.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols))
        throw ParamError("hungarian_max: " + std::to_string(weights.size()) +
                         " weights for a " + std::to_string(rows) + "x" + std::to_string(cols) +
                         " matrix");
    std::vector<int> row_to_col(static_cast<std::size_t>(rows), -1);
    if (rows == 0 || cols == 0) return row_to_col;

    // Solve min-cost with cost = -weight on an n x m matrix with n <= m (transposed if
    // needed). With n < m the m - n columns left free are the partners of the zero-weight
    // rows a square padding would add, so this equals padding without its cost.
    const bool transposed = rows > cols;
    const int n = transposed ? cols : rows;
    const int m = transposed ? rows : cols;
    auto cost = [&](int i, int j) {
        return transposed ? -weights[static_cast<std::size_t>(j) * cols + i]
                          : -weights[static_cast<std::size_t>(i) * cols + j];
    };

    // Shortest augmenting paths with dual potentials u (rows) and v (columns): every step
    // keeps cost(i, j) - u[i] - v[j] >= 0, with equality on the matched pairs, so the final
    // matching is optimal. Column m is a virtual start column holding the row being added.
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> u(static_cast<std::size_t>(n), 0.0), v(static_cast<std::size_t>(m) + 1, 0.0);
    std::vector<int> col_row(static_cast<std::size_t>(m) + 1, -1);  // row matched to column
    std::vector<int> prev_col(static_cast<std::size_t>(m) + 1, -1);  // path back to column m
    std::vector<double> slack(static_cast<std::size_t>(m) + 1);
    std::vector<char> in_tree(static_cast<std::size_t>(m) + 1);
    for (int i = 0; i < n; ++i) {
        col_row[m] = i;
        int j0 = m;
        std::fill(slack.begin(), slack.end(), inf);
        std::fill(in_tree.begin(), in_tree.end(), 0);
        do {
            in_tree[j0] = 1;
            const int i0 = col_row[j0];
            double step = inf;
            int j1 = -1;
            for (int j = 0; j < m; ++j) {
                if (in_tree[j]) continue;
                const double reduced = cost(i0, j) - u[i0] - v[j];
                if (reduced < slack[j]) {
                    slack[j] = reduced;
                    prev_col[j] = j0;
                }
                if (slack[j] < step) {
                    step = slack[j];
                    j1 = j;
                }
            }
            for (int j = 0; j <= m; ++j) {
                if (in_tree[j]) {
                    u[col_row[j]] += step;
                    v[j] -= step;
                } else {
                    slack[j] -= step;
                }
            }
            j0 = j1;
        } while (col_row[j0] != -1);
        // Flip the path: each column on it takes the row of the column before it.
        while (j0 != m) {
            const int j1 = prev_col[j0];
            col_row[j0] = col_row[j1];
            j0 = j1;
        }
    }
    for (int j = 0; j < m; ++j) {
        const int i = col_row[j];
        if (i < 0) continue;
        if (transposed)
            row_to_col[static_cast<std::size_t>(j)] = i;
        else
            row_to_col[static_cast<std::size_t>(i)] = j;
    }
    return row_to_col;
}

ImageScore score_image(const LabelImage& pred, const LabelImage& gt, const EvalParams& params) {
    params.validate();
    check_image(pred, "predicted");
    check_image(gt, "ground-truth");
    if (pred.width != gt.width || pred.height != gt.height)
        throw InputError("prediction is " + size_str(pred) + " but ground truth is " +
                         size_str(gt));
    const int w = gt.width, h = gt.height;
    ImageScore s;
    s.boundary_tolerance_px = boundary_tolerance_px(params, w, h);

    const Compact cp = compact(pred.labels), cg = compact(gt.labels);
    const int np = cp.size(), ng = cg.size();
    s.pred_objects = np;
    s.gt_objects = ng;
    // The reference's conventions for empty images (see the header).
    if (np == 0 && ng == 0) {
        set_all(s, 1, 1, 1, 1);
        return s;
    }
    if (np == 0) {
        set_all(s, 1, 0, 0, 0);
        return s;
    }
    if (ng == 0) {
        set_all(s, 0, 1, 0, 0);
        return s;
    }

    // Overlap, the best one-to-one matching by overlap F, then the boundaries.
    const OverlapTable ot = overlap_table(pred, cp, gt, cg);
    const std::vector<int> match = best_matching(ot, np, ng);
    score_matches(ot, match, pred, cp, gt, cg, params, s);
    return s;
}

EvalSummary summarize(const std::vector<ImageScore>& scores) {
    EvalSummary m;
    m.images = static_cast<int>(scores.size());
    for (const ImageScore& s : scores) {
        m.overlap_p += s.overlap_p;
        m.overlap_r += s.overlap_r;
        m.overlap_f += s.overlap_f;
        m.boundary_p += s.boundary_p;
        m.boundary_r += s.boundary_r;
        m.boundary_f += s.boundary_f;
        m.detected_share += s.detected_share;
        m.gt_objects += s.gt_objects;
        m.pred_objects += s.pred_objects;
        m.detected += s.detected;
    }
    if (m.images > 0) {
        const double n = m.images;
        for (double* x : {&m.overlap_p, &m.overlap_r, &m.overlap_f, &m.boundary_p, &m.boundary_r,
                          &m.boundary_f, &m.detected_share})
            *x /= n;
    }
    return m;
}

// ---- sequences ----------------------------------------------------------------------

SequenceScorer::SequenceScorer(const EvalParams& params) : params_(params) {
    params_.validate();
}

ImageScore SequenceScorer::add(const LabelImage& pred, const LabelImage& gt) {
    ImageScore s = score_image(pred, gt, params_);
    if (frames_ > 0 && (gt.width != prev_gt_.width || gt.height != prev_gt_.height))
        throw InputError("frame " + std::to_string(frames_) + " is " + size_str(gt) +
                         " but the sequence is " + size_str(prev_gt_));

    // (a) id switches: follow each visible ground-truth object's partner.
    if (tracks_.empty()) tracks_.resize(65536);
    std::vector<std::uint8_t> visible(65536, 0);
    for (const std::uint16_t b : gt.labels) visible[b] = 1;
    std::size_t next_match = 0;
    for (std::size_t id = 1; id < visible.size(); ++id) {
        if (!visible[id]) continue;
        Track& t = tracks_[id];
        ++t.frames_visible;
        while (next_match < s.matches.size() && s.matches[next_match].gt_id < id) ++next_match;
        if (next_match >= s.matches.size() || s.matches[next_match].gt_id != id) continue;
        const std::uint16_t partner = s.matches[next_match].pred_id;
        ++t.frames_matched;
        if (t.last_pred != 0 && t.last_pred != partner) ++t.switches;
        t.last_pred = partner;
    }

    // (b) flicker against the previous frame.
    if (frames_ > 0) {
        std::int64_t counted = 0, changed = 0, obj_counted = 0, obj_changed = 0;
        for (std::size_t q = 0; q < gt.labels.size(); ++q) {
            const std::uint16_t g0 = prev_gt_.labels[q], g1 = gt.labels[q];
            if (g0 != g1) continue;
            const std::uint16_t p0 = prev_pred_.labels[q], p1 = pred.labels[q];
            if (g1 == 0 && p0 == 0 && p1 == 0) continue;
            const bool flip = p0 != p1;
            ++counted;
            changed += flip;
            if (g1 != 0) {
                ++obj_counted;
                obj_changed += flip;
            }
        }
        if (counted > 0) {
            flicker_sum_ += static_cast<double>(changed) / static_cast<double>(counted);
            ++flicker_pairs_;
        }
        if (obj_counted > 0) {
            object_flicker_sum_ +=
                static_cast<double>(obj_changed) / static_cast<double>(obj_counted);
            ++object_flicker_pairs_;
        }
    }
    prev_pred_ = pred;
    prev_gt_ = gt;
    ++frames_;
    return s;
}

TemporalReport SequenceScorer::report() const {
    TemporalReport r;
    r.frames = frames_;
    r.frame_pairs = flicker_pairs_;
    r.flicker = flicker_pairs_ ? flicker_sum_ / flicker_pairs_ : 0.0;
    r.object_flicker = object_flicker_pairs_ ? object_flicker_sum_ / object_flicker_pairs_ : 0.0;
    for (std::size_t id = 1; id < tracks_.size(); ++id) {
        const Track& t = tracks_[id];
        if (t.frames_visible == 0) continue;
        ObjectTrackScore o;
        o.gt_id = static_cast<std::uint16_t>(id);
        o.frames_visible = t.frames_visible;
        o.frames_matched = t.frames_matched;
        o.switches = t.switches;
        r.objects.push_back(o);
        r.id_switches += t.switches;
        r.max_switches = std::max(r.max_switches, t.switches);
    }
    if (!r.objects.empty())
        r.switches_per_object = static_cast<double>(r.id_switches) / static_cast<double>(r.objects.size());
    return r;
}

TemporalReport score_sequence(const std::vector<LabelImage>& preds,
                              const std::vector<LabelImage>& gts, const EvalParams& params) {
    if (preds.size() != gts.size())
        throw InputError("score_sequence: " + std::to_string(preds.size()) +
                         " predictions for " + std::to_string(gts.size()) + " ground truths");
    SequenceScorer scorer(params);
    for (std::size_t t = 0; t < preds.size(); ++t) scorer.add(preds[t], gts[t]);
    return scorer.report();
}

}  // namespace wul3d
