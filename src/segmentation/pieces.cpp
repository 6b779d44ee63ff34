// Pieces (segment_objects, after the stack rule): a segment is one connected region. The
// rules that cut (the colour cue, the stack rule) cut by colour or by height, not by place:
// what lies above a stack's cut can be the top of the object resting on it and, apart, the
// upper half of a box leaning on its other side, one label for both. Each 4-connected piece
// of a segment becomes a segment of its own, the largest keeping the label; a piece under
// min_points is then dropped as any small segment is (a fragment apart from its object:
// kept with it, it cost boundary precision on the generated scenes). A container joined
// across its rim stays whole (the rim hides what joins its inside to its wall), and the
// occlusion rule, which runs after, joins again the parts of one surface that a nearer object
// divides.
//
// By runs, not pixels: each row's runs of one label, joined (union-find) to the runs of the
// same label that they touch in the row above. A segment is a few runs a row.
#include <algorithm>
#include <vector>

#include "internal.hpp"

namespace wul3d::detail {

namespace {

/// The runs of equal labels (> 0) of every row into ws.runs, each row's first into
/// ws.row_runs. Cost: one pass over the rows with labels.
void find_runs(const Ctx& x, SegmentBuffers& ws) {
    const int W = x.W, H = x.H;
    ws.runs.clear();
    ws.row_runs.resize(static_cast<std::size_t>(H) + 1);
    for (int v = 0; v < H; ++v) {
        ws.row_runs[static_cast<std::size_t>(v)] = static_cast<int>(ws.runs.size());
        const int* const row = ws.label.data() + static_cast<std::size_t>(v) * static_cast<std::size_t>(W);
        if (!row_has_label(row, 0, W)) continue;
        for (int u = 0; u < W;) {
            const int l = row[u];
            int last = u;
            while (last + 1 < W && row[last + 1] == l) ++last;
            if (l > 0) ws.runs.push_back({v, u, last, l});
            u = last + 1;
        }
    }
    ws.row_runs[static_cast<std::size_t>(H)] = static_cast<int>(ws.runs.size());
}

/// Joins every run to the runs of its label it touches in the row above (4-neighbours: their
/// columns overlap), two pointers over the two rows. The root of a piece is its first run in
/// raster order (join_sets keeps the smaller). Cost: O(runs).
void join_runs(const Ctx& x, SegmentBuffers& ws) {
    reset_sets(ws.run_parent, static_cast<int>(ws.runs.size()) - 1);
    for (int v = 1; v < x.H; ++v) {
        int i = ws.row_runs[static_cast<std::size_t>(v - 1)], j = ws.row_runs[static_cast<std::size_t>(v)];
        const int i_end = j, j_end = ws.row_runs[static_cast<std::size_t>(v) + 1];
        while (i < i_end && j < j_end) {
            const LabelRun &a = ws.runs[static_cast<std::size_t>(i)], &b = ws.runs[static_cast<std::size_t>(j)];
            if (a.label == b.label && a.u0 <= b.u1 && b.u0 <= a.u1) join_sets(ws.run_parent, i, j);
            if (a.u1 < b.u1)
                ++i;
            else
                ++j;
        }
    }
}

}  // namespace

void split_pieces(const Ctx& x, const Plane*, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    find_runs(x, ws);
    if (ws.runs.empty()) return;
    join_runs(x, ws);
    const int R = static_cast<int>(ws.runs.size());
    // Each piece's pixels at its root run, and each segment's largest piece (of equal ones,
    // the first in raster order).
    ws.run_pixels.assign(static_cast<std::size_t>(R), 0);
    for (int r = 0; r < R; ++r) {
        const LabelRun& run = ws.runs[static_cast<std::size_t>(r)];
        ws.run_pixels[static_cast<std::size_t>(find_root(ws.run_parent, r))] += run.u1 - run.u0 + 1;
    }
    std::vector<int>& largest = ws.order;
    largest.assign(static_cast<std::size_t>(n) + 1, -1);
    for (int r = 0; r < R; ++r) {
        if (ws.run_parent[static_cast<std::size_t>(r)] != r) continue;  // not a piece's root
        int& best = largest[static_cast<std::size_t>(ws.runs[static_cast<std::size_t>(r)].label)];
        if (best < 0 || ws.run_pixels[static_cast<std::size_t>(r)] > ws.run_pixels[static_cast<std::size_t>(best)])
            best = r;
    }
    // The other pieces take n + 1, ... in raster order of their first run; those under
    // min_points are dropped at the end with the other small segments (compact).
    std::vector<int>& new_label = ws.remap;
    new_label.assign(static_cast<std::size_t>(R), 0);
    int added = 0;
    auto rim_joined = [&](int l) {
        return static_cast<std::size_t>(l) < ws.rim_joined.size() && ws.rim_joined[static_cast<std::size_t>(l)];
    };
    for (int r = 0; r < R; ++r) {
        const int l = ws.runs[static_cast<std::size_t>(r)].label;
        if (ws.run_parent[static_cast<std::size_t>(r)] == r && largest[static_cast<std::size_t>(l)] != r &&
            !rim_joined(l))
            new_label[static_cast<std::size_t>(r)] = n + ++added;
    }
    stats.pieces.splits = added;
    if (added == 0) return;
    for (int r = 0; r < R; ++r) {
        const int l = new_label[static_cast<std::size_t>(find_root(ws.run_parent, r))];
        if (l == 0) continue;
        const LabelRun& run = ws.runs[static_cast<std::size_t>(r)];
        int* const row = ws.label.data() + static_cast<std::size_t>(run.v) * static_cast<std::size_t>(x.W);
        std::fill(row + run.u0, row + run.u1 + 1, l);
    }
    n += added;
}

}  // namespace wul3d::detail
