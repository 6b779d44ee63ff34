// The decimation stage alone (--decimate 2) on real 640x480 frames: shrinking the frame, and
// the way back (expand_result) against the back-projection at the input's size.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include "bench_support.hpp"
#include "wul3d/backprojection.hpp"
#include "wul3d/decimation.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"

using namespace wul3d;

static void BM_DecimateFrame(benchmark::State& state) {
    const RgbdFrame& f = bench::tabletop_frame();
    RgbdFrame out;
    decimate_frame(f, 2, out);
    for (auto _ : state) {
        decimate_frame(f, 2, out);
        benchmark::DoNotOptimize(out.depth.data.data());
    }
}
BENCHMARK(BM_DecimateFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

namespace {

/// The four tabletop frames (or the first 8 of the sequence WUL3D_BENCH_EXPAND_INPUT names,
/// e.g. ../shared/data/osd_mosd) at the default decimation 2, each through the stages once
/// on its decimated frame (a Pipeline at decimation 1 with the default's stage parameters,
/// past its first frame): expand_result's inputs.
struct ExpandInputs {
    PipelineParams params;  ///< the default: decimation 2
    ExpandParams expand;    ///< what expand_result takes of it, as the pipeline sets it
    std::vector<RgbdFrame> frames;
    std::vector<RgbdFrame> decimated;
    std::vector<FrameResult> small;
};

const ExpandInputs& expand_inputs() {
    static const ExpandInputs inputs = [] {
        ExpandInputs in;
        const float n = static_cast<float>(in.params.decimation);
        in.expand.factor = in.params.decimation;
        in.expand.same_m = n * in.params.segmentation.depth_jump_m;
        in.expand.same_rel = n * in.params.segmentation.depth_jump_rel;
        in.expand.range = in.params.range;
        in.expand.min_object_pixels = static_cast<std::size_t>(in.params.objects.min_points);
        PipelineParams stages = in.params.stage_params();
        stages.decimation = 1;
        Pipeline pipeline(stages);
        if (const char* input = std::getenv("WUL3D_BENCH_EXPAND_INPUT")) {
            auto source = open_source(input, SourceOptions{});
            SourceItem item;
            for (std::size_t i = 0; i < std::min<std::size_t>(8, source->size()); ++i) {
                source->read(i, item);
                in.frames.push_back(item.frame);
            }
        } else {
            in.frames = bench::tabletop_frames();
        }
        for (const RgbdFrame& f : in.frames) {
            RgbdFrame d;
            decimate_frame(f, in.params.decimation, d, &in.params.range);
            pipeline.process(d);
            in.small.push_back(pipeline.process(d));
            in.decimated.push_back(std::move(d));
        }
        return in;
    }();
    return inputs;
}

}  // namespace

// The way back (expand_result) against the back-projection of the same input frame at its
// full size, in the same loop: ours_ms is the way back, theirs_ms the back-projection, ratio
// their per-iteration quotient (the way back should cost no more: ratio <= 1). colors:1 is
// the default; colors:0 the way back without eq. 9's colours (PipelineParams::render_colors).
static void BM_ExpandVsBackProject(benchmark::State& state) {
    const ExpandInputs& in = expand_inputs();
    ExpandParams expand = in.expand;
    expand.colors = state.range(0) != 0;
    const std::vector<RgbdFrame>& frames = in.frames;
    ExpandWorkspace ws;
    FrameResult out;
    OrganizedCloud cloud;
    for (std::size_t i = 0; i < frames.size(); ++i) {  // sizes every buffer once
        expand_result(expand, frames[i].view(), in.decimated[i], in.small[i], ws, out);
        back_project(frames[i], cloud);
    }
    bench::PeerTimes times;
    std::size_t i = 0;
    using Clock = std::chrono::steady_clock;
    for (auto _ : state) {
        const RgbdFrame& f = frames[i];
        auto t0 = Clock::now();
        expand_result(expand, f.view(), in.decimated[i], in.small[i], ws, out);
        benchmark::DoNotOptimize(out.labels.labels.data());
        auto t1 = Clock::now();
        benchmark::DoNotOptimize(back_project(f, cloud));
        auto t2 = Clock::now();
        times.add(std::chrono::duration<double, std::milli>(t1 - t0).count(),
                  std::chrono::duration<double, std::milli>(t2 - t1).count());
        i = (i + 1) % frames.size();
    }
    times.report(state);
}
BENCHMARK(BM_ExpandVsBackProject)->ArgName("colors")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
