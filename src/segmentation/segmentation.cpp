// segment_objects: the phases in order, each a file of its own in src/segmentation/ (the
// crease cuts, the components, then the rules on segments), timed into SegmentStats::ms.
#include "wul3d/segmentation.hpp"

#include <chrono>
#include <memory>

#include "internal.hpp"  // Ctx, the phases and the rules

namespace wul3d {
namespace {

/// Milliseconds since the last call (or the construction), for SegmentStats::ms.
class Lap {
    using Clock = std::chrono::steady_clock;
    Clock::time_point t_ = Clock::now();

public:
    double operator()() {
        const auto now = Clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - t_).count();
        t_ = now;
        return ms;
    }
};

}  // namespace

SegmentWorkspace::SegmentWorkspace() : b_(std::make_unique<Buffers>()) {}
SegmentWorkspace::~SegmentWorkspace() = default;
SegmentWorkspace::SegmentWorkspace(SegmentWorkspace&&) noexcept = default;
SegmentWorkspace& SegmentWorkspace::operator=(SegmentWorkspace&&) noexcept = default;
SegmentWorkspace::Buffers& SegmentWorkspace::buffers() {
    if (!b_) b_ = std::make_unique<Buffers>();
    return *b_;
}

/// Labels stay in 1..n with gaps (dropped fragments, merged or joined segments) until
/// `compact`: every phase between works per pixel, per pair or per segment, whatever the
/// numbers. Rules that add segments number them n + 1, ... and add them to n. A new rule is
/// a file in src/segmentation/ and a line here.
SegmentStats segment_objects(const SegmentParams& params, const OrganizedCloud& cloud,
                             const NormalMap& normals, const std::vector<std::uint8_t>& classes,
                             const Plane* support, const Plane* low_support, const LabelImage& clusters,
                             SegmentWorkspace& workspace, LabelImage& out, float depth_noise_rel) {
    using namespace detail;
    SegmentBuffers& ws = workspace.buffers();
    const int W = cloud.width, H = cloud.height;
    SegmentStats stats;
    SegmentStats::Phases& ms = stats.ms;
    Lap lap;
    const Ctx x{params, cloud, crease_normals(params, normals, classes, W, H, ws), classes, W, H, low_support,
                depth_noise_rel};
    ms.smoothing = lap();
    find_seeds(x, normals.valid.data(), clusters, ws);
    ms.cuts = lap();
    int n = seed_components(x, ws);
    ms.components = lap();
    stats.reattached = reattach_foreground(x, ws);
    n = seed_orphans(x, ws, n);
    ms.reattach = lap();
    // The rules on segments (docs/DESIGN.md, "Objects", a section each), in this order. One
    // that does not run leaves its time to the next that does.
    auto rule = [&](bool on, double& phase_ms, Rule run) {
        if (!on) return;
        run(x, support, ws, n, stats);
        phase_ms += lap();
    };
    const bool geometric = params.segmenter != Segmenter::Kmeans, hybrid = params.segmenter == Segmenter::Hybrid;
    rule(geometric, ms.merge, merge_segments);
    rule(geometric, ms.containers, join_containers);
    rule(hybrid, ms.color, split_by_colour);
    rule(geometric && support, ms.stacks, split_stacks);
    rule(geometric, ms.pieces, split_pieces);
    rule(geometric, ms.gaps, fill_floor_gaps);
    rule(geometric, ms.occluded, join_occluded);
    rule(geometric && support, ms.necks, join_necks);
    rule(support && params.scope.mode == Scope::Support, ms.scope, restrict_to_support);
    out.width = W;
    out.height = H;
    out.labels.resize(cloud.size());
    stats.segments = compact(ws, n, params.min_points, out.labels.data());
    ms.compact += lap();
    return stats;
}

}  // namespace wul3d
