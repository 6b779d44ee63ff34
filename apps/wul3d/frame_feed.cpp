#include "frame_feed.hpp"

#include <csignal>

#include "wul3d/stop.hpp"

namespace wul3d::cli {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;

// Also the library's stop request, which the pipeline's stages check mid-frame.
extern "C" void on_stop_signal(int sig) {
    g_stop_signal = sig;
    wul3d::request_stop();
}

}  // namespace

void install_stop_signals() {
    g_stop_signal = 0;
    wul3d::clear_stop_request();
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;  // a second Ctrl-C kills at once
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

bool stop_requested() { return g_stop_signal != 0; }

void restore_signals() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

FeedOptions feed_options(const PipelineOptions& o, const SourceOptions& source) {
    FeedOptions f;
    f.input = o.input;
    f.camera = o.camera;
    f.lossless = o.lossless;
    f.source = source;
    return f;
}

}  // namespace wul3d::cli
