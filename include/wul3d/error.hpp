#pragma once
/// @file error.hpp
/// The error convention of wul3d: the library throws, the CLI maps to exit codes.
/// Messages are one line and name the offending file, flag or value.
#include <stdexcept>
#include <string>

namespace wul3d {

/// Base of every error wul3d throws.
struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A parameter outside its range ("ClusterParams.alpha = 0.5: must be in [0.002, 0.1]").
struct ParamError : Error {
    using Error::Error;
};

/// Input data that cannot be used: missing or unreadable file, wrong size or bit depth,
/// an empty sequence, a frame with no valid depth.
struct InputError : Error {
    using Error::Error;
};

/// Writing an output failed (disk full, permission denied).
struct IoError : Error {
    using Error::Error;
};

/// A stop request (stop.hpp: SIGINT, SIGTERM) ended a computation before its end.
struct Stopped : Error {
    using Error::Error;
};

/// A live camera disappeared mid-run.
struct DeviceLost : Error {
    using Error::Error;
};

}  // namespace wul3d
