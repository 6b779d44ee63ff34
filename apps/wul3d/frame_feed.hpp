#pragma once
// The CLI's side of the frame feed (wul3d/feed.hpp): the stop request of SIGINT/SIGTERM,
// so that a stopped run still finalizes its outputs, and the feed options of the shared
// command-line options.
#include "pipeline_options.hpp"
#include "wul3d/feed.hpp"

namespace wul3d::cli {

/// Catches SIGINT and SIGTERM: the first sets the stop request (a second one kills, as by
/// default). Call once before a loop that polls stop_requested().
void install_stop_signals();
bool stop_requested();
/// Puts the default handlers back.
void restore_signals();

/// The input (or --camera, --lossless) of `o`, read with `source`.
FeedOptions feed_options(const PipelineOptions& o, const SourceOptions& source);

}  // namespace wul3d::cli
