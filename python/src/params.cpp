#include "params.hpp"

#include <variant>

namespace wul3d::python {

ParamArgs take_param_args(py::dict& o) {
    ParamArgs a;
    a.preset = take<std::string>(o, "preset").value_or("");
    for (const ParamSpec& s : pipeline_parameters()) {
        if (!o.contains(s.name)) continue;
        const py::object v = o[s.name];
        PyDict_DelItemString(o.ptr(), s.name);
        if (v.is_none()) continue;
        switch (s.kind) {
            case ParamKind::Int: a.given.emplace_back(s.name, std::int64_t{to_value<long long>(v, s.name)}); break;
            case ParamKind::UInt64: a.given.emplace_back(s.name, to_value<std::uint64_t>(v, s.name)); break;
            case ParamKind::Float: a.given.emplace_back(s.name, to_value<double>(v, s.name)); break;
            case ParamKind::Choice: a.given.emplace_back(s.name, to_value<std::string>(v, s.name)); break;
            case ParamKind::Switch: a.given.emplace_back(s.name, to_value<bool>(v, s.name)); break;
        }
    }
    return a;
}

PipelineParams make_params(const ParamArgs& a) { return wul3d::make_params(a.preset, a.given); }

py::dict params_dict(const PipelineParams& p) {
    py::dict d;
    for (const ParamSpec& s : pipeline_parameters())
        std::visit([&](const auto& value) { d[s.name] = value; }, s.get(p));
    return d;
}

namespace {

/// `text`'s last line wrapped at 92 columns, continued with 8 spaces (a docstring's Args:).
std::string wrap_last_line(const std::string& text) {
    const std::size_t start = text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1;
    std::string out = text.substr(0, start), line;
    std::size_t pos = start;
    while (pos < text.size()) {
        std::size_t end = text.find(' ', pos + 1);
        if (end == std::string::npos) end = text.size();
        const std::string word = text.substr(pos, end - pos);  // with its leading space
        if (line.size() + word.size() > 92 && !line.empty()) {
            out += line + "\n";
            line = "        " + word.substr(word[0] == ' ' ? 1 : 0);
        } else {
            line += word;
        }
        pos = end;
    }
    return out + line;
}

}  // namespace

const char* python_type(ParamKind kind) {
    switch (kind) {
        case ParamKind::Int:
        case ParamKind::UInt64: return "int";
        case ParamKind::Float: return "float";
        case ParamKind::Choice: return "str";
        case ParamKind::Switch: return "bool";
    }
    return "";
}

std::string params_doc() {
    const PipelineParams defaults;
    std::string presets, doc;
    for (const auto& [name, help] : preset_names_and_help())
        presets += (presets.empty() ? "" : "; ") + ("\"" + name + "\": " + help);
    doc = wrap_last_line("    preset (str): " + presets + ".") + "\n";
    for (const ParamSpec& s : pipeline_parameters()) {
        const ParamValue def = s.get(defaults);
        const std::string* name = std::get_if<std::string>(&def);
        const bool* on = std::get_if<bool>(&def);
        doc += std::string("    ") + s.name + " (" + python_type(s.kind) + "): " +
               s.help;
        if (s.kind == ParamKind::Int || s.kind == ParamKind::Float) doc += ", " + range_text(s);
        const std::string shown = name ? "\"" + *name + "\"" : on ? (*on ? "True" : "False") : value_text(def);
        doc += " (default " + shown + "; `wul3d run " + flag_of(s) + "`).";
        doc = wrap_last_line(doc) + "\n";
    }
    return doc;
}

}  // namespace wul3d::python
