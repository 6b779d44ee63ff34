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
    /// A parameter of the table (parameters.hpp) that is not allowed: what() is
    /// "name = value: requirement"; the command respells it with its flag
    /// ("--name value: requirement").
    ParamError(const std::string& parameter, const std::string& value,
               const std::string& requirement)
        : Error(parameter + " = " + value + ": " + requirement),
          parameter_(parameter),
          value_(value),
          requirement_(requirement) {}
    /// The table's name of the parameter; empty for any other ParamError.
    const std::string& parameter() const noexcept { return parameter_; }
    const std::string& value() const noexcept { return value_; }
    const std::string& requirement() const noexcept { return requirement_; }

private:
    std::string parameter_, value_, requirement_;
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
