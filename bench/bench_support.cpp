#include "bench_support.hpp"

#include <algorithm>
#include <string>

#include "wul3d/io.hpp"

namespace wul3d::bench {

namespace {
RgbdFrame load_frame(const std::string& name) {
    auto source = open_source(sample_path("uois_tabletop/" + name), SourceOptions{});
    SourceItem item;
    source->read(0, item);
    return item.frame;
}
}  // namespace

std::string sample_path(const std::string& relative) { return std::string(WUL3D_SAMPLE_DIR) + "/" + relative; }

const std::vector<RgbdFrame>& tabletop_frames() {
    static const std::vector<RgbdFrame> frames = [] {
        std::vector<RgbdFrame> out;
        for (const char* name : {"image_0000", "image_0002", "image_0005", "image_0007"})
            out.push_back(load_frame(name));
        return out;
    }();
    return frames;
}

const RgbdFrame& tabletop_frame() { return tabletop_frames().front(); }

const ProcessedFrame& processed_tabletop() {
    // Nothing else ever calls process() on this pipeline, so the result reference of the
    // second frame stays valid for the whole run.
    static Pipeline pipeline{[] {
        PipelineParams p;
        p.decimation = 1;  // the cloud and the result on one grid (bench_support.hpp)
        return p;
    }()};
    static const ProcessedFrame processed = [] {
        pipeline.process(tabletop_frame());
        const FrameResult& second = pipeline.process(tabletop_frame());
        return ProcessedFrame{tabletop_frame(), pipeline, second};
    }();
    return processed;
}

const std::vector<StageInputs>& tabletop_inputs() {
    static const std::vector<StageInputs> inputs = [] {
        std::vector<StageInputs> out(tabletop_frames().size());
        for (std::size_t i = 0; i < out.size(); ++i) {
            back_project(tabletop_frames()[i], out[i].cloud);
            estimate_normals(NormalParams{}, out[i].cloud, out[i].normals);
            select_depth_range(DepthRange{}, out[i].cloud, out[i].active);
        }
        return out;
    }();
    return inputs;
}

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const std::size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid),
                     values.end());
    const double upper = values[mid];
    if (values.size() % 2 == 1) return upper;
    const double lower = *std::max_element(values.begin(),
                                           values.begin() + static_cast<std::ptrdiff_t>(mid));
    return 0.5 * (lower + upper);
}

void PeerTimes::reserve(std::size_t n) {
    ours_.reserve(n);
    theirs_.reserve(n);
    ratio_.reserve(n);
}

void PeerTimes::add(double ours_ms, double theirs_ms) {
    ours_.push_back(ours_ms);
    theirs_.push_back(theirs_ms);
    ratio_.push_back(theirs_ms > 0 ? ours_ms / theirs_ms : 0.0);
}

void PeerTimes::report(benchmark::State& state) const {
    state.counters["ours_ms"] = median(ours_);
    state.counters["theirs_ms"] = median(theirs_);
    state.counters["ratio"] = median(ratio_);
}

}  // namespace wul3d::bench
