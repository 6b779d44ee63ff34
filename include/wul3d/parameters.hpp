#pragma once
/// @file parameters.hpp
/// The pipeline's user-facing parameters, one row each (parameters.cpp): name, field, kind,
/// range, default, one line of help and the stage it belongs to. The command's options and
/// their --help, the Python keyword arguments and their docstrings, summary.json's
/// "parameters", the presets and wul3d.batch's pass-through flags are all built from this
/// table, so a new parameter is one row. The stages' own structs (PipelineParams and the
/// ones it holds) carry many more settings, for library users; these are the ones a user
/// turns.
#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "wul3d/pipeline.hpp"

namespace wul3d {

/// How a parameter's value is spelt: a whole number, a 64-bit seed, a real number, one of
/// a few names, or an on/off switch.
enum class ParamKind { Int, UInt64, Float, Choice, Switch };

/// A value of a parameter: bool (Switch), int64 (Int), uint64 (UInt64), double (Float),
/// string (Choice).
using ParamValue = std::variant<bool, std::int64_t, std::uint64_t, double, std::string>;

/// One row of the table.
struct ParamSpec {
    const char* name;   ///< Python keyword and summary.json's key: "object_psi"
    const char* stage;  ///< "clustering", "range", "normals", "plane", "segmentation", ...
    ParamKind kind;
    const char* unit;   ///< "m", "px" or "": summary.json's key is name_unit ("zmin_m")
    /// Int and Float: the values allowed, lo / hi inclusive unless *_open.
    double lo = 0, hi = 0;
    bool lo_open = false, hi_open = false;
    const char* choices = "";  ///< Choice: the names, "geometric|kmeans|hybrid"
    const char* help = "";     ///< one line, without the default (default_text() adds it)
    /// The command's spelling when it is not "--" + name with '-' for '_' (a Switch whose
    /// flag turns it off: "--no-plane").
    const char* flag = nullptr;
    const char* flag_help = nullptr;  ///< a switch's flag: what turning it off does
    ParamValue (*get)(const PipelineParams&) = nullptr;
    void (*set)(PipelineParams&, const ParamValue&) = nullptr;
};

/// Every row, in the order of --help and of the docstrings.
const std::vector<ParamSpec>& pipeline_parameters();
/// The row called `name`; nullptr when there is none.
const ParamSpec* find_parameter(const std::string& name);

/// "--object-psi", or the row's own flag.
std::string flag_of(const ParamSpec& spec);
/// summary.json's key: "zmin_m", "object_psi".
std::string summary_key(const ParamSpec& spec);
/// The allowed values as text: "in (0, 1]", ">= 1", "geometric, kmeans or hybrid".
std::string range_text(const ParamSpec& spec);
/// The value as text, as summary.json and --help spell it ("0.5", "hybrid", "true").
std::string value_text(const ParamValue& value);

/// `text` read as the row's kind ("7", "0.5", "hybrid"). Throws ParamError (naming the
/// parameter, parameter()) when it is not one.
ParamValue parse_parameter(const ParamSpec& spec, const std::string& text);

/// The presets, by name: "default" (the structs' own defaults) and "paper" (the paper's
/// setting: PipelineParams::paper()).
const std::vector<std::pair<std::string, std::string>>& preset_names_and_help();
/// The preset's parameters. Throws ParamError for an unknown name.
PipelineParams preset_params(const std::string& name);

/// The preset (empty: "default"), then every given parameter in turn, each checked against
/// its row (ParamError naming it: parameter()), then validate(). One rule couples two rows:
/// alpha given without delta sets delta = 1 - alpha (eq. 5 at equality, as the paper does).
/// Throws ParamError for a name not in the table.
PipelineParams make_params(const std::string& preset,
                           const std::vector<std::pair<std::string, ParamValue>>& given);

}  // namespace wul3d
