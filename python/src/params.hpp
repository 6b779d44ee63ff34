#pragma once
// wul3d.Pipeline's keyword arguments and wul3d.run's options: the flags of `wul3d run`,
// turned into library parameters by the same rules as the command.
#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>

#include "convert.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::python {
namespace py = pybind11;

/// The keyword arguments of wul3d.Pipeline, as the flags of `wul3d run`: None keeps the
/// preset's value.
struct ParamArgs {
    std::optional<std::string> preset, segmenter, scope;
    std::optional<int> k, iters, stride, normal_radius, min_points, decimate;
    std::optional<float> alpha, delta, gamma, psi, zmin, zmax, object_psi;
    std::optional<std::uint64_t> seed;
    bool remove_plane = true;
};

/// Removes `key` from `options` and returns its value as T (None or absent: nullopt); a
/// wrong type raises TypeError naming the key (convert.hpp).
template <typename T>
std::optional<T> take(py::dict& options, const char* key) {
    if (!options.contains(key)) return std::nullopt;
    const py::object v = options[key];
    PyDict_DelItemString(options.ptr(), key);
    return to_optional<T>(v, key);
}

/// The pipeline's parameters among `options` (preset, k, alpha, ..., decimate; not the
/// plane switch, which Pipeline and run spell apart), removed from it as they are taken.
ParamArgs take_param_args(py::dict& options);

/// The same rules as `wul3d run`'s options (apps/wul3d/pipeline_options.cpp), so that a
/// Pipeline built from the same settings gives the same outputs: the preset first, then each
/// given parameter; alpha without delta sets delta = 1 - alpha (eq. 5 at equality).
PipelineParams make_params(const ParamArgs& a);

/// The parameters in force as a dict (summary.json's names, without units).
py::dict params_dict(const PipelineParams& p);

}  // namespace wul3d::python
