// The occlusion rule of segment_objects (SegmentParams, "Occlusion"): the two parts of a
// surface whose middle a nearer object hides are one object.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "internal.hpp"

namespace wul3d::detail {
namespace {

/// One line of evidence: from segment a's outline pixel (u, v) along (du, dv), across what
/// stands in front of a's tangent plane (the occluder), to the first pixel that does not.
/// The plane is a's tangent plane a crease step inside its outline, where the smoothed
/// normals are not bent by the occluder's. Returns that pixel's segment b when it lies on
/// the plane (within two sensor steps, and 5 % of the distance for the surface's curvature
/// and the normals' noise), faces the same way (normals within occlusion.max_deg) and is
/// not the occluder's own far edge; `offset` gets its height over the plane in sensor
/// steps. Returns 0 otherwise. Cost: the pixels crossed; a line ends after
/// occlusion.max_gap_m of a's plane (each pixel measured where its viewing ray meets it) or
/// after 4 crease steps without a point.
int cross_occluder(const Ctx& x, const int* label, int a, int u, int v, int du, int dv, float cos_max,
                   float& offset) {
    const OrganizedCloud& c = x.c;
    const int s = x.prm.cuts.crease_step_px;
    const int au = u - s * du, av = v - s * dv;
    if (au < 0 || av < 0) return 0;
    const std::size_t p = static_cast<std::size_t>(av) * x.W + au;  // the plane's anchor
    if (label[p] != a || !c.valid[p] || !x.n.valid[p]) return 0;
    float nx = x.n.nx[p], ny = x.n.ny[p], nz = x.n.nz[p];
    // Toward the camera: the normals are, but a smoothed one at a grazing angle may not be.
    if (nx * c.x[p] + ny * c.y[p] + nz * c.z[p] > 0) nx = -nx, ny = -ny, nz = -nz;
    const float anchor_side = nx * c.x[p] + ny * c.y[p] + nz * c.z[p];  // < 0: the plane faces the camera
    const float step = x.depth_step(c.z[p]);
    int crossed = 0, n_occ = 0, skipped = 0;
    int occluders[4] = {0, 0, 0, 0};  // the last four segments crossed, and their pixels
    int occluder_px[4] = {0, 0, 0, 0};
    for (int k = 1;; ++k) {
        const int ru = u + k * du, rv = v + k * dv;
        if (ru >= x.W || rv >= x.H) return 0;
        const std::size_t r = static_cast<std::size_t>(rv) * x.W + ru;
        const int b = label[r];
        if (b == a) return 0;
        // The occluder's shadow, and points left between segments (a depth edge's mixed
        // pixels), up to 4 crease steps in a row: a longer run without depth is no shadow
        // but the view past the depth range or a cropped frame, and it bounds the line.
        if (!c.valid[r] || (b == 0 && x.cls[r] != kPlaneRemoved)) {
            if (++skipped > 4 * s) return 0;
            continue;
        }
        skipped = 0;
        const float dx = c.x[r] - c.x[p], dy = c.y[r] - c.y[p], dz = c.z[r] - c.z[p];
        const float h = nx * dx + ny * dy + nz * dz;  // over a's plane, toward the camera
        // How far along a's surface the line has come: from the anchor to where r's
        // viewing ray meets a's plane. Not r's own distance, which for an occluder near
        // the camera is its height in front of a, not the width it hides.
        const float toward = nx * c.x[r] + ny * c.y[r] + nz * c.z[r];
        if (toward > -1e-6f) return 0;  // r's ray runs along a's plane or away from it
        const float t = anchor_side / toward;
        const float gx = t * c.x[r] - c.x[p], gy = t * c.y[r] - c.y[p], gz = t * c.z[r] - c.z[p];
        const float dist = std::sqrt(gx * gx + gy * gy + gz * gz);
        if (dist > x.prm.occlusion.max_gap_m) return 0;
        const float tol = 2.0f * step + 0.05f * dist;
        if (h > tol) {
            if (b == 0) return 0;  // in front of a but the support's: no occluder
            ++crossed;
            if (occluders[(n_occ + 3) & 3] != b) occluders[n_occ & 3] = b, occluder_px[n_occ++ & 3] = 0;
            ++occluder_px[(n_occ + 3) & 3];
            continue;
        }
        if (crossed == 0 || b == 0 || h < -tol || !x.n.valid[r]) return 0;
        for (int i = 0; i < 4; ++i)
            if (occluders[i] == b && occluder_px[i] > 2) return 0;  // the occluder's own far edge
        if (std::fabs(nx * x.n.nx[r] + ny * x.n.ny[r] + nz * x.n.nz[r]) < cos_max) return 0;
        offset = h / step;
        return b;
    }
}

/// The lines of evidence (cross_occluder) from every outline pixel of every segment whose
/// right or lower neighbour is nearer (a segment, or points between segments), into
/// ws.occluded_lines as (segment pair, offset). Cost: a branch-free pass per row with labels
/// to find the outline pixels, then the lines from those.
void collect_lines(const Ctx& x, SegmentBuffers& ws, float cos_max) {
    const int W = x.W, H = x.H;
    const int* const label = ws.label.data();
    const OrganizedCloud& c = x.c;
    auto& lines = ws.occluded_lines;
    lines.clear();
    // A line starts where a's outline meets a nearer segment, or points between segments.
    auto try_line = [&](int a, int u, int v, int du, int dv) {
        const std::size_t p = static_cast<std::size_t>(v) * W + u;
        const std::size_t q = p + static_cast<std::size_t>(du + dv * W);
        if (c.valid[q] && (label[q] == 0 ? x.cls[q] == kPlaneRemoved : c.z[q] >= c.z[p] - x.depth_step(c.z[p])))
            return;
        float offset = 0;
        const int b = cross_occluder(x, label, a, u, v, du, dv, cos_max, offset);
        if (b == 0) return;
        const auto lo = static_cast<std::uint64_t>(std::min(a, b));
        const auto hi = static_cast<std::uint64_t>(std::max(a, b));
        lines.push_back({(lo << 32) | hi, offset});
    };
    ws.occluded_outline.resize(static_cast<std::size_t>(W));
    std::uint8_t* const outline = ws.occluded_outline.data();
    for (int v = 0; v < H; ++v) {
        const int* const row = label + static_cast<std::ptrdiff_t>(v) * W;
        if (!row_has_label(row, 0, W)) continue;  // a row without labels starts no line
        // Outline pixels, whose right or lower neighbour is not of their segment, in a
        // branch-free pass; the lines start from those few.
        const int* const below = v + 1 < H ? row + W : row;
        mark_outline_row(row, below, W, outline);
        for (int u = 0;; ++u) {  // right, then down; each pair is met from one side
            const void* next = std::memchr(outline + u, 1, static_cast<std::size_t>(W - u));
            if (!next) break;
            u = static_cast<int>(static_cast<const std::uint8_t*>(next) - outline);
            const int a = row[u];
            if (u + 1 < W && row[u + 1] != a) try_line(a, u, v, 1, 0);
            if (v + 1 < H && row[u + W] != a) try_line(a, u, v, 0, 1);
        }
    }
}

/// The occlusion rule (SegmentParams, "Occlusion"). Each line of evidence (collect_lines,
/// cross_occluder) that lands on another segment b lying on a's plane says that a and b are
/// one surface with the occluder before its middle. A pair joins with occlusion.min_lines
/// lines or more whose mean offset from a's plane is at most occlusion.max_offset sensor
/// steps: one line's tolerance takes the sensor's noise, the mean takes two faces a little
/// apart. In: ws.label (1..n with gaps). Out: ws.label with the pairs joined. Cost:
/// collect_lines; a sort of the lines; a relabel pass when anything joined.
int join_across_occluders(const Ctx& x, SegmentBuffers& ws, int n) {
    const SegmentParams& prm = x.prm;
    if (prm.occlusion.min_lines <= 0 || n < 2) return 0;
    collect_lines(x, ws, std::cos(prm.occlusion.max_deg * kDegToRad));
    auto& lines = ws.occluded_lines;
    if (lines.empty()) return 0;
    std::sort(lines.begin(), lines.end());
    reset_sets(ws.parent, n);
    int joins = 0;
    for (std::size_t i = 0; i < lines.size();) {
        const std::uint64_t key = lines[i].first;
        double sum = 0;
        std::size_t j = i;
        for (; j < lines.size() && lines[j].first == key; ++j) sum += lines[j].second;
        const auto count = static_cast<double>(j - i);
        if (count >= prm.occlusion.min_lines && std::fabs(sum / count) <= prm.occlusion.max_offset)
            joins += join_sets(ws.parent, static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu));
        i = j;
    }
    if (joins > 0) relabel_to_roots(ws);
    return joins;
}

}  // namespace

void join_occluded(const Ctx& x, const Plane*, SegmentBuffers& ws, int& n, SegmentStats& stats) {
    stats.occlusion.joins = join_across_occluders(x, ws, n);
}

}  // namespace wul3d::detail
