// `wul3d bench`: frames per second and peak memory of the pipeline against k and the number
// of threads, one fresh process per (threads, k) (so that one k's peak memory cannot hide
// another's), as in the paper's Figure 7, with each stage's median time (for the scaling
// curve and the stages' serial shares: bench/scaling.py). Parsing, timing and reporting
// only; the pipeline is the library's.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "pipeline_options.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/pipeline.hpp"
#include "wul3d/threads.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {
namespace {

struct BenchOptions {
    std::string input;
    std::string ks = "2,5,7,10,15,20,30,50,75,100";
    std::string resolution = "native";
    std::string csv;
    std::size_t frames = 5;  // distinct frames loaded
    int passes = 4;          // times the frames are run through the pipeline
    std::string pipeline = "objects";  // objects: the default object pipeline; paper: its steps only
    std::string segmenter;             // empty: the default
    std::string threads = "0";         // comma-separated; 0: all cores
    int decimate = 0;                  // PipelineParams::decimation; 0: decimation_of()
    bool no_colors = false;            // PipelineParams::render_colors off
    int single_k = 0;        // internal: measure this k in this process and print one row
};

/// The stages of StageTimes in the order of the CSV's ms_<stage> columns.
const std::vector<std::pair<const char*, double StageTimes::*>>& stage_columns() {
    static const std::vector<std::pair<const char*, double StageTimes::*>> columns = {
        {"registration", &StageTimes::registration}, {"decimation", &StageTimes::decimation},
        {"backprojection", &StageTimes::backprojection}, {"normals", &StageTimes::normals},
        {"background", &StageTimes::background}, {"clustering", &StageTimes::clustering},
        {"colors", &StageTimes::colors}, {"plane", &StageTimes::plane},
        {"segmentation", &StageTimes::segmentation}, {"objects", &StageTimes::objects}};
    return columns;
}

std::string csv_header() {
    std::string header = "k,threads,width,height,points,fps_median,ms_median,peak_rss_mb";
    for (const auto& column : stage_columns()) header += std::string(",ms_") + column.first;
    return header;
}

/// A comma-separated list of integers, each in [lo, hi], in the order given.
std::vector<int> parse_int_list(const std::string& text, const char* flag, int lo, int hi) {
    std::vector<int> values;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            std::size_t used = 0;
            const int v = std::stoi(item, &used);
            if (used != item.size() || v < lo || v > hi) throw std::invalid_argument(item);
            values.push_back(v);
        } catch (const std::exception&) {
            const std::string range =
                hi == std::numeric_limits<int>::max()
                    ? " >= " + std::to_string(lo)
                    : " in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
            throw ParamError(std::string(flag) + " '" + text + "': '" + item +
                             "' is not an integer" + range);
        }
    }
    if (values.empty() || text.back() == ',')
        throw ParamError(std::string(flag) + " '" + text + "': expected a comma-separated list");
    return values;
}

/// --decimate, or its default: the library's for the object pipeline, every pixel for the
/// paper's steps (the paper clusters every point).
int decimation_of(const BenchOptions& o) {
    if (o.decimate > 0) return o.decimate;
    return o.pipeline == "objects" ? PipelineParams{}.decimation : 1;
}

/// "native" or "WxH", within the readers' image limit (--max-pixels, io.hpp): checked
/// before anything is allocated (99999x99999 allocated for a minute, then bad_alloc).
void parse_resolution(const std::string& text, int& w, int& h) {
    w = h = 0;
    if (text == "native") return;
    char x = 0;
    std::istringstream in(text);
    if (!(in >> w >> x >> h) || x != 'x' || w <= 0 || h <= 0 || !in.eof())
        throw ParamError("--resolution '" + text + "': expected native or WxH, e.g. 1920x1080");
    const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    if (static_cast<std::uint64_t>(w) > kMaxImageSide ||
        static_cast<std::uint64_t>(h) > kMaxImageSide || pixels > max_image_pixels())
        throw ParamError("--resolution '" + text + "': " + std::to_string(pixels) +
                         " pixels, more than the largest image (--max-pixels " +
                         std::to_string(max_image_pixels()) + ", sides at most " +
                         std::to_string(kMaxImageSide) + ")");
}

/// Nearest-neighbour resampling of a registered frame to w x h, intrinsics scaled per axis:
/// the way to get the paper's 1920x1080 point count from a 640x480 recording.
RgbdFrame resample(const RgbdFrame& f, int w, int h) {
    RgbdFrame out;
    out.name = f.name;
    const double sx = static_cast<double>(w) / f.width(), sy = static_cast<double>(h) / f.height();
    out.intrinsics = PinholeIntrinsics{w, h, f.intrinsics.fx * sx, f.intrinsics.fy * sy,
                                       (f.intrinsics.cx + 0.5) * sx - 0.5,
                                       (f.intrinsics.cy + 0.5) * sy - 0.5};
    out.depth.width = w;
    out.depth.height = h;
    out.depth.scale_m_per_unit = f.depth.scale_m_per_unit;
    out.depth.data.resize(static_cast<std::size_t>(w) * h);
    if (f.has_color()) {
        out.color.width = w;
        out.color.height = h;
        out.color.rgb.resize(3 * out.depth.data.size());
    }
    for (int v = 0; v < h; ++v) {
        const int sv = std::min(f.height() - 1, static_cast<int>((v + 0.5) / sy));
        for (int u = 0; u < w; ++u) {
            const int su = std::min(f.width() - 1, static_cast<int>((u + 0.5) / sx));
            const std::size_t p = static_cast<std::size_t>(v) * w + u;
            const std::size_t q = static_cast<std::size_t>(sv) * f.width() + su;
            out.depth.data[p] = f.depth.data[q];
            if (f.has_color())
                for (int c = 0; c < 3; ++c) out.color.rgb[3 * p + c] = f.color.rgb[3 * q + c];
        }
    }
    return out;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// Measures one k in this process; prints "k,width,height,points,fps_median,ms_median,peak_rss_mb".
void measure_one(const BenchOptions& o) {
    int w = 0, h = 0;
    parse_resolution(o.resolution, w, h);
    auto source = open_source(o.input, SourceOptions{});
    std::vector<RgbdFrame> frames;
    SourceItem item;
    for (std::size_t i = 0; i < std::min(o.frames, source->size()); ++i) {
        source->read(i, item);
        if (item.is_raw)
            throw InputError(o.input + ": bench takes registered frames (frames or tum input)");
        frames.push_back(w ? resample(item.frame, w, h) : item.frame);
    }
    PipelineParams params;
    params.cluster.k = o.single_k;
    params.detect_objects = o.pipeline == "objects";
    if (!o.segmenter.empty()) params.segmentation.segmenter = parse_segmenter(o.segmenter);
    params.decimation = decimation_of(o);
    params.render_colors = !o.no_colors;
    const int threads = parse_int_list(o.threads, "--threads", 0, kMaxThreads).front();
    if (threads > 0) wul3d::set_num_threads(threads);
    Pipeline pipeline(params);
    try {
        pipeline.process(frames.front());  // seeding is a one-off: not timed
    } catch (const InputError& e) {  // as `run` says it: naming the frame
        const std::string what = e.what(), name = frames.front().name;
        if (what.rfind(name + ": ", 0) == 0) throw;
        throw InputError(name + ": " + what);
    }
    std::vector<double> ms;
    std::vector<std::vector<double>> stage_ms(stage_columns().size());
    std::size_t points = 0;
    for (int pass = 0; pass < o.passes; ++pass)
        for (const RgbdFrame& f : frames) {
            const auto t0 = std::chrono::steady_clock::now();
            const FrameResult& r = pipeline.process(f);
            ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            points = std::max(points, r.stats.points);
            for (std::size_t s = 0; s < stage_columns().size(); ++s)
                stage_ms[s].push_back(r.times.*stage_columns()[s].second);
        }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double m = median(ms);
    std::cout << o.single_k << ',' << wul3d::num_threads() << ',' << frames.front().width() << ','
              << frames.front().height() << ',' << points << ',' << std::fixed
              << std::setprecision(2) << 1000.0 / m << ',' << m << ',' << std::setprecision(1)
              << static_cast<double>(usage.ru_maxrss) / 1024.0 << std::setprecision(3);
    for (const auto& values : stage_ms) std::cout << ',' << median(values);
    std::cout << '\n';
}

/// Reads `fd` to its end.
std::string read_all(int fd) {
    std::string text;
    char buf[512];
    for (;;) {
        const ssize_t got = ::read(fd, buf, sizeof buf);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        text.append(buf, static_cast<std::size_t>(got));
    }
    return text;
}

/// Runs this program again as `bench ... --single-k k` and returns the row it printed. A
/// failed measurement throws the child's own one-line error with its kind (so its exit code:
/// 2 bad input, 3 lost device, 1 otherwise), with the k it was measuring.
std::string run_child(const BenchOptions& o, int threads, int k) {
    int out[2], err[2];
    if (::pipe(out) != 0) throw Error("bench: cannot create a pipe");
    if (::pipe(err) != 0) {
        ::close(out[0]);
        ::close(out[1]);
        throw Error("bench: cannot create a pipe");
    }
    const pid_t pid = ::fork();
    if (pid < 0) throw Error("bench: cannot fork");
    if (pid == 0) {
        ::dup2(out[1], STDOUT_FILENO);
        ::dup2(err[1], STDERR_FILENO);
        for (int fd : {out[0], out[1], err[0], err[1]}) ::close(fd);
        std::vector<std::string> args = {"wul3d", "bench", o.input, "--single-k", std::to_string(k),
                                         "--resolution", o.resolution, "--frames",
                                         std::to_string(o.frames), "--passes",
                                         std::to_string(o.passes), "--pipeline", o.pipeline,
                                         "--threads", std::to_string(threads),
                                         "--decimate", std::to_string(decimation_of(o)),
                                         "--max-pixels", std::to_string(max_image_pixels())};
        if (!o.segmenter.empty()) args.insert(args.end(), {"--segmenter", o.segmenter});
        if (o.no_colors) args.emplace_back("--no-colors");
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv("/proc/self/exe", argv.data());
        ::_exit(127);
    }
    ::close(out[1]);
    ::close(err[1]);
    // The child writes its one error line at its end, far below a pipe's buffer: stdout to
    // its end first cannot block it.
    std::string text = read_all(out[0]);
    std::string error = read_all(err[0]);
    ::close(out[0]);
    ::close(err[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const std::string what = " (bench, measuring k = " + std::to_string(k) + " on " +
                             std::to_string(threads) + " threads)";
    if (WIFSIGNALED(status))
        throw Error("bench: the measurement of k = " + std::to_string(k) + " was killed by signal " +
                    std::to_string(WTERMSIG(status)));
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
    if (code != 0 || text.empty()) {
        // The child's last line, without its "wul3d: ".
        while (!error.empty() && (error.back() == '\n' || error.back() == '\r')) error.pop_back();
        error = error.substr(error.find_last_of('\n') == std::string::npos ? 0 : error.find_last_of('\n') + 1);
        if (error.rfind("wul3d: ", 0) == 0) error.erase(0, 7);
        if (error.empty()) error = "the measurement failed with exit code " + std::to_string(code);
        if (code == 2) throw InputError(error + what);
        if (code == 3) throw DeviceLost(error + what);
        throw Error(error + what);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return text;
}

void run(const BenchOptions& o) {
    if (o.single_k > 0) {
        measure_one(o);
        return;
    }
    int w = 0, h = 0;
    parse_resolution(o.resolution, w, h);  // fail before forking
    if (o.pipeline != "objects" && o.pipeline != "paper")
        throw ParamError("--pipeline '" + o.pipeline + "': expected objects or paper");
    if (!o.segmenter.empty()) parse_segmenter(o.segmenter);
    const std::vector<int> ks = parse_int_list(o.ks, "--k", 1, std::numeric_limits<int>::max());
    const std::vector<int> threads = parse_int_list(o.threads, "--threads", 0, kMaxThreads);
    open_source(o.input, SourceOptions{});  // a bad input fails here, once, with its message
    if (!o.csv.empty()) check_write_target(o.csv, WriteTarget::File, {o.input}, "--csv");
    const std::string header = csv_header();
    std::vector<std::string> rows;
    std::cout << header << std::endl;
    for (int t : threads)
        for (int k : ks) {
            rows.push_back(run_child(o, t, k));
            std::cout << rows.back() << std::endl;
        }
    if (!o.csv.empty()) {
        std::ostringstream text;
        text << header << '\n';
        for (const auto& r : rows) text << r << '\n';
        write_text_file(o.csv, text.str());
    }
}

}  // namespace

void add_bench_command(CLI::App& app) {
    auto opts = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bench",
        "Frames per second, peak memory and each stage's time against k and threads, one "
        "process per (threads, k) (paper Figure 7)");
    cmd->add_option("input", opts->input, "Frame folder(s) or TUM sequence")->required();
    cmd->add_option("--k", opts->ks, "Comma-separated k values")->capture_default_str();
    cmd->add_option("--resolution", opts->resolution,
                    "native, or WxH to resample each frame (1920x1080: the paper's point count)")
        ->capture_default_str();
    cmd->add_option("--csv", opts->csv, "Also write the rows as CSV");
    cmd->add_option("--frames", opts->frames, "Distinct frames loaded")
        ->capture_default_str()
        ->check(NumberIn(1, 1000));
    cmd->add_option("--passes", opts->passes, "Passes over the frames")
        ->capture_default_str()
        ->check(NumberIn(1, 1000));
    cmd->add_option("--pipeline", opts->pipeline,
                    "objects: the default object pipeline; paper: the paper's steps only "
                    "(back-projection to eq. 9 colours)")
        ->capture_default_str();
    cmd->add_option("--segmenter", opts->segmenter, "geometric|kmeans|hybrid (default: hybrid)");
    cmd->add_option("--threads", opts->threads,
                    "Comma-separated worker thread counts, each in [1, 1024], e.g. 1,2,4,8 "
                    "for the scaling curve (default: all cores)");
    cmd->add_option("--decimate", opts->decimate,
                    "Run the stages on every N-th pixel in u and v, results at the input's size "
                    "(default: 2 with --pipeline objects, 1 with paper)")
        ->check(NumberIn(1, 8));
    cmd->add_flag("--no-colors", opts->no_colors,
                  "Without eq. 9's colours, as `wul3d run --outputs` without colors, ply or "
                  "--video runs");
    add_max_pixels_option(cmd);
    cmd->add_option("--single-k", opts->single_k, "Internal: measure one k in this process")
        ->group("");
    cmd->callback([opts]() { run(*opts); });
}

}  // namespace wul3d::cli
