// The table of the pipeline's user-facing parameters (parameters.hpp): one row each, read by
// the command, the Python module, summary.json and the batch.
#include "wul3d/parameters.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>

#include "wul3d/error.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d {
namespace {

constexpr double kNoLimit = std::numeric_limits<double>::infinity();

using Get = ParamValue (*)(const PipelineParams&);
using Set = void (*)(PipelineParams&, const ParamValue&);

ParamSpec row(const char* name, const char* stage, ParamKind kind, const char* unit, double lo,
              double hi, const char* help, Get get, Set set) {
    ParamSpec s{name, stage, kind, unit};
    s.lo = lo;
    s.hi = hi;
    s.help = help;
    s.get = get;
    s.set = set;
    return s;
}

ParamSpec open_at(ParamSpec s, bool lo_open, bool hi_open) {
    s.lo_open = lo_open;
    s.hi_open = hi_open;
    return s;
}

ParamSpec choice(const char* name, const char* stage, const char* choices, const char* help,
                 Get get, Set set) {
    ParamSpec s = row(name, stage, ParamKind::Choice, "", 0, 0, help, get, set);
    s.choices = choices;
    return s;
}

std::int64_t as_int(const ParamValue& v) { return std::get<std::int64_t>(v); }
float as_float(const ParamValue& v) { return static_cast<float>(std::get<double>(v)); }
ParamValue int_value(int v) { return std::int64_t{v}; }
ParamValue float_value(float v) { return static_cast<double>(v); }

std::vector<ParamSpec> make_table() {
    using K = ParamKind;
    using P = PipelineParams;
    using V = ParamValue;
    return {
        // Steps 6-7: the weighted clustering (clustering.hpp), the paper's symbols.
        row("k", "clustering", K::Int, "", 1, 65535, "Number of clusters",
            [](const P& p) { return int_value(p.cluster.k); },
            [](P& p, const V& v) { p.cluster.k = static_cast<int>(as_int(v)); }),
        row("alpha", "clustering", K::Float, "", 0.002, 0.1, "Colour scale, eq. 4",
            [](const P& p) { return float_value(p.cluster.alpha); },
            [](P& p, const V& v) { p.cluster.alpha = as_float(v); }),
        open_at(row("delta", "clustering", K::Float, "", 0, 1,
                    "Position scale, eq. 4 (alpha + delta <= 1, eq. 5; alpha alone sets delta "
                    "= 1 - alpha)",
                    [](const P& p) { return float_value(p.cluster.delta); },
                    [](P& p, const V& v) { p.cluster.delta = as_float(v); }),
                true, false),
        row("gamma", "clustering", K::Float, "", 0.0001, 0.01, "Normal scale, eq. 6",
            [](const P& p) { return float_value(p.cluster.gamma); },
            [](P& p, const V& v) { p.cluster.gamma = as_float(v); }),
        open_at(row("psi", "clustering", K::Float, "", 0, 1, "Weight increment, eq. 2",
                    [](const P& p) { return float_value(p.cluster.psi); },
                    [](P& p, const V& v) { p.cluster.psi = as_float(v); }),
                true, false),
        row("iters", "clustering", K::Int, "", 1, 1000, "k-means iterations per frame",
            [](const P& p) { return int_value(p.cluster.iters); },
            [](P& p, const V& v) { p.cluster.iters = static_cast<int>(as_int(v)); }),
        row("stride", "clustering", K::Int, "", 1, 64, "Sampling stride, pixels",
            [](const P& p) { return int_value(p.cluster.stride); },
            [](P& p, const V& v) { p.cluster.stride = static_cast<int>(as_int(v)); }),
        row("seed", "clustering", K::UInt64, "", 0, 0, "k-means++ seed",
            [](const P& p) { return V{p.cluster.seed}; },
            [](P& p, const V& v) { p.cluster.seed = std::get<std::uint64_t>(v); }),
        // Step 5: the depth range (background.hpp).
        open_at(row("zmin", "range", K::Float, "m", 0, 1000, "Nearest depth kept, metres",
                    [](const P& p) { return float_value(p.range.zmin_m); },
                    [](P& p, const V& v) { p.range.zmin_m = as_float(v); }),
                false, true),
        open_at(row("zmax", "range", K::Float, "m", 0, 1000, "Farthest depth kept, metres",
                    [](const P& p) { return float_value(p.range.zmax_m); },
                    [](P& p, const V& v) { p.range.zmax_m = as_float(v); }),
                true, false),
        // Step 4: normals (normals.hpp).
        row("normal_radius", "normals", K::Int, "px", 1, 64, "Least normal neighbour distance, pixels (more where the depth is noisy: normal_tilt_noise)",
            [](const P& p) { return int_value(p.normals.radius_px); },
            [](P& p, const V& v) { p.normals.radius_px = static_cast<int>(as_int(v)); }),
        open_at(row("normal_tilt_noise", "normals", K::Float, "deg", 0, 90,
                    "Normals: the radius grows with the depth's measured noise until it tilts a "
                    "normal by at most this, degrees (0: --normal-radius always)",
                    [](const P& p) { return float_value(p.normals.max_tilt_noise_deg); },
                    [](P& p, const V& v) { p.normals.max_tilt_noise_deg = as_float(v); }),
                false, true),
        // The object stages: segmentation (segmentation.hpp), the plane, the tracks.
        choice("segmenter", "segmentation", "geometric|kmeans|hybrid",
               "Object segmentation: geometric, kmeans or hybrid",
               [](const P& p) { return V{std::string(segmenter_name(p.segmentation.segmenter))}; },
               [](P& p, const V& v) {
                   p.segmentation.segmenter = parse_segmenter(std::get<std::string>(v));
               }),
        choice("scope", "segmentation", "support|scene",
               "Objects: support (what the support holds; the whole scene when no support is "
               "found) or scene (every segment)",
               [](const P& p) { return V{std::string(scope_name(p.segmentation.scope.mode))}; },
               [](P& p, const V& v) { p.segmentation.scope.mode = parse_scope(std::get<std::string>(v)); }),
        [] {
            ParamSpec s = row("remove_plane", "plane", K::Switch, "", 0, 0,
                              "Remove the support plane (off: the paper's background step, "
                              "depth range only)",
                              [](const P& p) { return V{p.remove_plane}; },
                              [](P& p, const V& v) { p.remove_plane = std::get<bool>(v); });
            s.flag = "--no-plane";
            s.flag_help = "Keep the support plane (the paper's background step: depth range only)";
            return s;
        }(),
        row("min_points", "segmentation", K::Int, "", 1, kNoLimit, "Smallest object, pixels",
            [](const P& p) { return int_value(p.segmentation.min_points); },
            [](P& p, const V& v) { p.segmentation.min_points = static_cast<int>(as_int(v)); }),
        open_at(row("object_psi", "objects", K::Float, "", 0, 1,
                    "Weight increment of eq. 2 for object tracks (1 = no smoothing)",
                    [](const P& p) { return float_value(p.objects.psi); },
                    [](P& p, const V& v) { p.objects.psi = as_float(v); }),
                true, false),
        row("decimate", "decimation", K::Int, "", 1, 8,
            "Run the stages on every N-th pixel in u and v (N^2 times fewer points), results "
            "at the input's size",
            [](const P& p) { return int_value(p.decimation); },
            [](P& p, const V& v) { p.decimation = static_cast<int>(as_int(v)); }),
    };
}

std::string number_text(double v) {
    std::ostringstream out;
    out << std::setprecision(7) << v;  // a float's digits: 0.0033, not 0.0032999999821186066
    return out.str();
}

/// Whether `v` is within the row's limits (NaN is not).
bool in_range(const ParamSpec& s, double v) {
    const bool above = s.lo_open ? v > s.lo : v >= s.lo;
    const bool below = s.hi_open ? v < s.hi : v <= s.hi;
    return above && below;
}

/// Throws the row's ParamError unless `value` is of its kind and within its limits.
void check(const ParamSpec& s, const ParamValue& value) {
    const auto refuse = [&](const std::string& why) {
        throw ParamError(s.name, value_text(value), why);
    };
    switch (s.kind) {
        case ParamKind::Int:
            if (!std::holds_alternative<std::int64_t>(value)) refuse("must be a whole number");
            if (!in_range(s, static_cast<double>(std::get<std::int64_t>(value))))
                refuse("must be " + range_text(s));
            break;
        case ParamKind::UInt64:
            if (!std::holds_alternative<std::uint64_t>(value))
                refuse("must be a whole number in [0, 2^64)");
            break;
        case ParamKind::Float:
            if (!std::holds_alternative<double>(value)) refuse("must be a number");
            if (!in_range(s, std::get<double>(value))) refuse("must be " + range_text(s));
            break;
        case ParamKind::Choice: {
            if (!std::holds_alternative<std::string>(value)) refuse("must be " + range_text(s));
            const std::string name = std::get<std::string>(value);
            const std::string all = std::string("|") + s.choices + "|";
            if (name.empty() || name.find('|') != std::string::npos ||
                all.find("|" + name + "|") == std::string::npos)
                refuse("unknown (known: " + range_text(s) + ")");
            break;
        }
        case ParamKind::Switch:
            if (!std::holds_alternative<bool>(value)) refuse("must be true or false");
            break;
    }
}

}  // namespace

const std::vector<ParamSpec>& pipeline_parameters() {
    static const std::vector<ParamSpec> table = make_table();
    return table;
}

const ParamSpec* find_parameter(const std::string& name) {
    for (const ParamSpec& s : pipeline_parameters())
        if (name == s.name) return &s;
    return nullptr;
}

std::string flag_of(const ParamSpec& spec) {
    if (spec.flag) return spec.flag;
    std::string flag = std::string("--") + spec.name;
    for (char& c : flag)
        if (c == '_') c = '-';
    return flag;
}

std::string summary_key(const ParamSpec& spec) {
    return *spec.unit ? std::string(spec.name) + "_" + spec.unit : std::string(spec.name);
}

std::string range_text(const ParamSpec& s) {
    switch (s.kind) {
        case ParamKind::Int:
        case ParamKind::Float:
            if (s.hi == kNoLimit) return (s.lo_open ? "> " : ">= ") + number_text(s.lo);
            return std::string("in ") + (s.lo_open ? "(" : "[") + number_text(s.lo) + ", " +
                   number_text(s.hi) + (s.hi_open ? ")" : "]");
        case ParamKind::UInt64: return "in [0, 2^64)";
        case ParamKind::Choice: {
            std::string names = s.choices, out;
            for (std::size_t i = 0, n = 0; i <= names.size(); ++i) {
                if (i < names.size() && names[i] != '|') continue;
                const std::string name = names.substr(n, i - n);
                const bool last = i == names.size();
                out += out.empty() ? name : (last ? " or " : ", ") + name;
                n = i + 1;
            }
            return out;
        }
        case ParamKind::Switch: return "true or false";
    }
    return "";
}

std::string value_text(const ParamValue& value) {
    if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const auto* i = std::get_if<std::int64_t>(&value)) return std::to_string(*i);
    if (const auto* u = std::get_if<std::uint64_t>(&value)) return std::to_string(*u);
    if (const double* d = std::get_if<double>(&value)) return number_text(*d);
    return "'" + std::get<std::string>(value) + "'";
}

ParamValue parse_parameter(const ParamSpec& spec, const std::string& text) {
    const char* first = text.data();
    const char* last = first + text.size();
    const std::string quoted = "'" + text + "'";
    switch (spec.kind) {
        case ParamKind::Int: {
            std::int64_t v = 0;
            const auto [ptr, ec] = std::from_chars(first, last, v);
            if (text.empty() || ec != std::errc() || ptr != last)
                throw ParamError(spec.name, quoted, "must be a whole number " + range_text(spec));
            return v;
        }
        case ParamKind::UInt64: {
            std::uint64_t v = 0;
            const auto [ptr, ec] = std::from_chars(first, last, v);
            if (text.empty() || ec != std::errc() || ptr != last)
                throw ParamError(spec.name, quoted, "must be a whole number in [0, 2^64)");
            return v;
        }
        case ParamKind::Float: {
            // strtod: from_chars for doubles needs GCC 11's libstdc++, and the locale is "C".
            char* end = nullptr;
            errno = 0;
            const double v = text.empty() ? 0 : std::strtod(first, &end);
            if (text.empty() || end != last || errno == ERANGE || !std::isfinite(v))
                throw ParamError(spec.name, quoted, "must be a number " + range_text(spec));
            return v;
        }
        case ParamKind::Choice: return text;
        case ParamKind::Switch:
            if (text == "true" || text == "1") return true;
            if (text == "false" || text == "0") return false;
            throw ParamError(spec.name, quoted, "must be true or false");
    }
    return text;
}

const std::vector<std::pair<std::string, std::string>>& preset_names_and_help() {
    static const std::vector<std::pair<std::string, std::string>> presets = {
        {"default", "this library's defaults"},
        {"paper", "the paper's setting: k 7, zmin 0.5 m (Kinect v2), every pixel (decimate 1)"}};
    return presets;
}

PipelineParams preset_params(const std::string& name) {
    if (name == "default") return PipelineParams{};
    if (name == "paper") return PipelineParams::paper();
    std::string known;
    for (const auto& preset : preset_names_and_help())
        known += (known.empty() ? "" : ", ") + preset.first;
    throw ParamError("preset", "'" + name + "'", "unknown (known: " + known + ")");
}

PipelineParams make_params(const std::string& preset,
                           const std::vector<std::pair<std::string, ParamValue>>& given) {
    PipelineParams p = preset_params(preset.empty() ? "default" : preset);
    bool alpha = false, delta = false;
    for (const auto& entry : given) {
        const ParamSpec* spec = find_parameter(entry.first);
        if (!spec) throw ParamError("unknown parameter '" + entry.first + "'");
        check(*spec, entry.second);
        spec->set(p, entry.second);
        alpha = alpha || entry.first == "alpha";
        delta = delta || entry.first == "delta";
    }
    if (alpha && !delta) p.cluster.delta = 1.0f - p.cluster.alpha;  // eq. (5) at equality
    p.validate();
    return p;
}

}  // namespace wul3d
