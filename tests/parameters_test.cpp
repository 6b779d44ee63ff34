// The table of user-facing parameters (src/parameters.cpp): every row reads and writes its
// own field, refuses what its range refuses and so does the stage's own validate(), the
// presets, the one coupling (alpha alone sets delta), and the command respelling the table's
// messages with its flags.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/parameters.hpp"

using namespace wul3d;

namespace {

/// A value of the row's kind other than its default, inside its range.
ParamValue other_value(const ParamSpec& s, const ParamValue& def) {
    switch (s.kind) {
        case ParamKind::Int: {
            const auto v = std::get<std::int64_t>(def);
            return static_cast<double>(v + 1) <= s.hi ? v + 1 : v - 1;
        }
        case ParamKind::UInt64: return std::get<std::uint64_t>(def) + 41;
        case ParamKind::Float: {
            // Halfway to a limit, as the float the field stores.
            const double v = std::get<double>(def);
            const double hi = std::isinf(s.hi) ? v + 2 : s.hi;
            const double to = hi - v > 1e-6 ? 0.5 * (v + hi) : 0.5 * (s.lo + v);
            return static_cast<double>(static_cast<float>(to));
        }
        case ParamKind::Choice: {
            const std::string all = s.choices;
            const std::string first = all.substr(0, all.find('|'));
            const std::string second = all.substr(all.find('|') + 1, all.find('|', all.find('|') + 1) - all.find('|') - 1);
            return std::get<std::string>(def) == first ? second : first;
        }
        case ParamKind::Switch: return !std::get<bool>(def);
    }
    return def;
}

/// Values just outside the row's range (none for a kind without one).
std::vector<ParamValue> outside(const ParamSpec& s) {
    std::vector<ParamValue> out;
    if (s.kind == ParamKind::Int) {
        out.push_back(static_cast<std::int64_t>(s.lo) - 1);
        if (!std::isinf(s.hi)) out.push_back(static_cast<std::int64_t>(s.hi) + 1);
    } else if (s.kind == ParamKind::Float) {
        out.push_back(s.lo_open ? s.lo : s.lo - 1e-3 * std::max(1.0, std::abs(s.lo)));
        if (!std::isinf(s.hi)) out.push_back(s.hi_open ? s.hi : s.hi + 1e-3 * std::max(1.0, std::abs(s.hi)));
        out.push_back(std::nan(""));
    }
    return out;
}

}  // namespace

TEST(Parameters, RowsAreNamedOnceAndReadTheirOwnField) {
    std::set<std::string> names, flags, keys;
    const PipelineParams defaults;
    for (const ParamSpec& s : pipeline_parameters()) {
        SCOPED_TRACE(s.name);
        EXPECT_TRUE(names.insert(s.name).second);
        EXPECT_TRUE(flags.insert(flag_of(s)).second);
        EXPECT_TRUE(keys.insert(summary_key(s)).second);
        EXPECT_GT(std::string(s.help).size(), 5u);
        EXPECT_GT(std::string(s.stage).size(), 3u);
        EXPECT_EQ(find_parameter(s.name), &s);
        // Setting a row changes its value and no other row's.
        const ParamValue def = s.get(defaults), other = other_value(s, def);
        ASSERT_NE(def, other);
        PipelineParams p = defaults;
        s.set(p, other);
        EXPECT_EQ(s.get(p), other);
        for (const ParamSpec& t : pipeline_parameters()) {
            if (&t == &s) continue;
            EXPECT_EQ(t.get(p), t.get(defaults)) << t.name;
        }
    }
    EXPECT_EQ(find_parameter("no_such"), nullptr);
    EXPECT_EQ(flag_of(*find_parameter("object_psi")), "--object-psi");
    EXPECT_EQ(flag_of(*find_parameter("remove_plane")), "--no-plane");
    EXPECT_EQ(summary_key(*find_parameter("zmin")), "zmin_m");
    EXPECT_EQ(summary_key(*find_parameter("normal_radius")), "normal_radius_px");
}

TEST(Parameters, TheTableAndTheStagesRefuseTheSameValues) {
    for (const ParamSpec& s : pipeline_parameters())
        for (const ParamValue& bad : outside(s)) {
            SCOPED_TRACE(std::string(s.name) + " = " + value_text(bad));
            try {
                make_params("", {{s.name, bad}});
                ADD_FAILURE() << "accepted";
            } catch (const ParamError& e) {
                EXPECT_EQ(e.parameter(), s.name);
                EXPECT_EQ(std::string(e.what()).rfind(std::string(s.name) + " = ", 0), 0u) << e.what();
            }
            // The stage's own check, for a library user who fills the structs directly.
            PipelineParams p;
            s.set(p, bad);
            EXPECT_THROW(p.validate(), ParamError);
        }
}

TEST(Parameters, TheStagesTakeTheTablesLimits) {
    // The edges inside each range pass the stage's own validate() too, so the table is not
    // stricter than the stages. delta, zmin and zmax are held by a second row as well
    // (alpha + delta <= 1, zmin < zmax), checked in PresetsAndTheCouplingOfAlphaAndDelta.
    for (const ParamSpec& s : pipeline_parameters()) {
        if (s.kind != ParamKind::Int && s.kind != ParamKind::Float) continue;
        const std::string name = s.name;
        if (name == "delta" || name == "zmin" || name == "zmax") continue;
        const double lo = s.lo_open ? std::nextafter(static_cast<float>(s.lo), 1e9f) : s.lo;
        const double hi = std::isinf(s.hi) ? 1e6
                          : s.hi_open      ? std::nextafter(static_cast<float>(s.hi), -1e9f)
                                           : s.hi;
        for (const double edge : {lo, hi}) {
            const ParamValue v = s.kind == ParamKind::Int
                                     ? ParamValue{static_cast<std::int64_t>(edge)}
                                     : ParamValue{edge};
            EXPECT_NO_THROW(make_params("", {{s.name, v}})) << name << " = " << edge;
        }
    }
}

TEST(Parameters, KindsAreChecked) {
    EXPECT_THROW(make_params("", {{"k", 7.0}}), ParamError);
    EXPECT_THROW(make_params("", {{"alpha", std::int64_t{1}}}), ParamError);
    EXPECT_THROW(make_params("", {{"segmenter", std::string("watershed")}}), ParamError);
    EXPECT_THROW(make_params("", {{"segmenter", std::string("kmeans|hybrid")}}), ParamError);
    EXPECT_THROW(make_params("", {{"remove_plane", std::int64_t{0}}}), ParamError);
    EXPECT_THROW(make_params("", {{"no_such", true}}), ParamError);
    const ParamSpec& k = *find_parameter("k");
    EXPECT_EQ(parse_parameter(k, "12"), ParamValue{std::int64_t{12}});
    for (const char* text : {"", "1.5", "7x", " 7", "99999999999999999999"})
        EXPECT_THROW(parse_parameter(k, text), ParamError) << text;
    const ParamSpec& alpha = *find_parameter("alpha");
    EXPECT_EQ(parse_parameter(alpha, "1e-2"), ParamValue{0.01});
    for (const char* text : {"", "nan", "inf", "0.01x", "1e999"})
        EXPECT_THROW(parse_parameter(alpha, text), ParamError) << text;
    EXPECT_EQ(parse_parameter(*find_parameter("seed"), "18446744073709551615"),
              ParamValue{std::uint64_t{18446744073709551615ull}});
    EXPECT_THROW(parse_parameter(*find_parameter("seed"), "-1"), ParamError);
}

TEST(Parameters, PresetsAndTheCouplingOfAlphaAndDelta) {
    const PipelineParams paper = preset_params("paper"), ref = PipelineParams::paper();
    for (const ParamSpec& s : pipeline_parameters()) EXPECT_EQ(s.get(paper), s.get(ref)) << s.name;
    EXPECT_EQ(make_params("", {}).decimation, PipelineParams{}.decimation);
    EXPECT_EQ(make_params("paper", {}).decimation, 1);
    EXPECT_EQ(make_params("default", {}).range.zmin_m, PipelineParams{}.range.zmin_m);
    try {
        preset_params("fast");
        ADD_FAILURE() << "accepted";
    } catch (const ParamError& e) {
        EXPECT_EQ(e.parameter(), "preset");
        EXPECT_NE(std::string(e.what()).find("default, paper"), std::string::npos) << e.what();
    }
    // alpha alone: delta = 1 - alpha (eq. 5 at equality); both given: each as given.
    EXPECT_FLOAT_EQ(make_params("", {{"alpha", 0.01}}).cluster.delta, 1.0f - 0.01f);
    EXPECT_FLOAT_EQ(make_params("", {{"alpha", 0.01}, {"delta", 0.5}}).cluster.delta, 0.5f);
    EXPECT_FLOAT_EQ(make_params("", {{"delta", 0.5}, {"alpha", 0.01}}).cluster.delta, 0.5f);
    // Cross-row limits stay the stages' (validate()): alpha + delta <= 1.
    EXPECT_THROW(make_params("", {{"alpha", 0.05}, {"delta", 1.0}}), ParamError);
}

TEST(Parameters, TheCommandNamesItsFlagsAndSummaryJsonEveryRow) {
    using namespace wul3d::test;
    TempDir tmp;
    const std::string frame = (sample_dir() / "uois_tabletop" / "image_0000").string();
    for (const auto& [flag, value] : std::vector<std::pair<std::string, std::string>>{
             {"--object-psi", "2"}, {"--min-points", "0"}, {"--normal-radius", "x"}, {"--k", "0"}}) {
        const CommandResult r = run_cli({"run", frame, "--out", (tmp / "bad").string(), flag, value});
        EXPECT_EQ(r.exit_code, 2) << flag;
        EXPECT_NE(r.err.find("wul3d: " + flag + " "), std::string::npos) << r.err;
    }
    const CommandResult r = run_cli({"run", frame, "--out", (tmp / "ok").string(), "-q",
                                     "--object-psi", "0.25", "--no-plane", "--seed", "9"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto summary = nlohmann::json::parse(slurp(tmp / "ok" / "summary.json"));
    const auto& params = summary.at("parameters");
    EXPECT_EQ(params.size(), pipeline_parameters().size() + 1);  // and the preset
    EXPECT_FLOAT_EQ(params.at("object_psi").get<float>(), 0.25f);
    EXPECT_EQ(params.at("remove_plane"), false);
    EXPECT_EQ(params.at("seed"), 9u);
    EXPECT_EQ(params.at("zmin_m").get<float>(), PipelineParams{}.range.zmin_m);
    EXPECT_EQ(params.at("preset"), "default");
}
