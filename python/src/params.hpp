#pragma once
// wul3d.Pipeline's keyword arguments and wul3d.run's options: the rows of the library's table
// of parameters (wul3d/parameters.hpp), as the command takes them.
#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "convert.hpp"
#include "wul3d/parameters.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d::python {
namespace py = pybind11;

/// The preset and the parameters given (None: not given, the preset's value stays).
struct ParamArgs {
    std::string preset;  ///< empty: "default"
    std::vector<std::pair<std::string, ParamValue>> given;
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

/// "preset" and every row of the table among `options`, each converted by its kind (a
/// wrong type: TypeError naming it), removed from `options` as they are taken.
ParamArgs take_param_args(py::dict& options);

/// wul3d::make_params: the preset, then each given parameter, as `wul3d run` does
/// (ParamError, a ValueError in Python, names the keyword).
PipelineParams make_params(const ParamArgs& a);

/// The parameters in force as a dict, one key per row (without units: "zmin").
py::dict params_dict(const PipelineParams& p);

/// The Python type a row's values have: "int", "float", "str" or "bool".
const char* python_type(ParamKind kind);

/// The "Args:" lines of a docstring, one per row and the preset, from the table.
std::string params_doc();

}  // namespace wul3d::python
