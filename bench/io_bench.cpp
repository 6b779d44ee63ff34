// Reading and writing a frame, what `wul3d run` does around the pipeline: a frame read
// from its PNGs (the reader threads' work) and its default outputs written (the writers').
// The shipped tabletop frames, or the first 8 of the sequence WUL3D_BENCH_IO_INPUT names
// (e.g. ../shared/data/osd_mosd, whose PNGs another encoder wrote).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "bench_support.hpp"
#include "io/png_encode.hpp"
#include "run/output_detail.hpp"
#include "wul3d/io.hpp"
#include "wul3d/output.hpp"

using namespace wul3d;

namespace {

std::string io_input() {
    if (const char* input = std::getenv("WUL3D_BENCH_IO_INPUT")) return input;
    return bench::sample_path("uois_tabletop");
}

/// The source of io_input() and its first (up to) 8 frames' indices.
struct IoInput {
    std::unique_ptr<FrameSource> source;
    std::size_t frames = 0;
};

IoInput& io_source() {
    static IoInput in = [] {
        IoInput s;
        s.source = open_source(io_input(), SourceOptions{});
        s.frames = std::min<std::size_t>(8, s.source->size());
        return s;
    }();
    return in;
}

}  // namespace

// One frame a time through FrameSource::read: depth and colour PNG decoded (with their
// checks), colour registered where the set needs it.
static void BM_ReadFrame(benchmark::State& state) {
    IoInput& in = io_source();
    SourceItem item;
    std::size_t i = 0;
    for (auto _ : state) {
        in.source->read(i, item);
        benchmark::DoNotOptimize(item.frame.depth.data.data());
        i = (i + 1) % in.frames;
    }
}
BENCHMARK(BM_ReadFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

// A frame's default outputs (labels.png, colors.png, objects.png, objects.json) written to a
// frame folder in the temporary directory, atomically, as a writer thread of `wul3d run`
// writes them (its encoder kept from frame to frame).
static void BM_WriteFrame(benchmark::State& state) {
    IoInput& in = io_source();
    std::vector<RgbdFrame> frames;
    std::vector<FrameResult> results;
    Pipeline pipeline{PipelineParams{}};
    SourceItem item;
    for (std::size_t i = 0; i < in.frames; ++i) {
        in.source->read(i, item);
        frames.push_back(item.frame);
        results.push_back(pipeline.process(item.frame));
    }
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("wul3d-io-bench-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    detail::PngEncoder encoder;
    std::size_t i = 0;
    for (auto _ : state) {
        detail::write_frame(dir.string(), "frame", nullptr, frames[i], results[i], FrameOutputs{}, encoder);
        i = (i + 1) % frames.size();
    }
    std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
