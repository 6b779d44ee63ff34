#pragma once
// Real frames and stage inputs for the benchmarks, loaded once, and the counters of the peer
// comparisons. Every stage benchmark copies its inputs from here outside the timed loop.
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "wul3d/pipeline.hpp"

namespace wul3d::bench {

/// data/samples/<relative>: the shipped sample data.
std::string sample_path(const std::string& relative);

/// data/samples/uois_tabletop/image_0000: a real 640x480 tabletop frame (MIT licence).
const RgbdFrame& tabletop_frame();

/// The four shipped tabletop frames, image_0000, 0002, 0005 and 0007 (640x480 each).
const std::vector<RgbdFrame>& tabletop_frames();

/// A Pipeline with default PipelineParams but decimation 1 that has processed tabletop_frame()
/// twice, so its ClusterState and ObjectTracker are past their first frame. The inputs of
/// every stage come from here: pipeline.cloud(), pipeline.normals(), and result (active mask,
/// cluster labels, plane classes, segments) of the second frame. At decimation 1 the
/// pipeline's cloud and the result's per-pixel arrays share the frame's 640 x 480 grid; at
/// the default 2 the cloud is the quarter grid and the result comes back at the input's size,
/// and a stage fed both reads the wrong pixels. The stage benchmarks thus time every pixel;
/// pipeline_bench.cpp times the default.
struct ProcessedFrame {
    const RgbdFrame& frame;
    const Pipeline& pipeline;
    const FrameResult& result;
};
const ProcessedFrame& processed_tabletop();

/// Cloud, normals (default NormalParams) and depth-range mask (default DepthRange) of a frame,
/// as the pipeline computes them: the inputs of clustering and of the peers.
struct StageInputs {
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;
};
/// One per tabletop_frames() entry.
const std::vector<StageInputs>& tabletop_inputs();

/// Median of a sample (0 when empty); takes a copy, the caller's order is kept.
double median(std::vector<double> values);

/// Per-iteration times of our stage and of a peer on the same input. report() sets the
/// counters ours_ms and theirs_ms (medians over iterations) and ratio (median of the
/// per-iteration ours / theirs; below 1 means ours is faster).
class PeerTimes {
public:
    void reserve(std::size_t n);
    void add(double ours_ms, double theirs_ms);
    void report(benchmark::State& state) const;

private:
    std::vector<double> ours_, theirs_, ratio_;
};

}  // namespace wul3d::bench
