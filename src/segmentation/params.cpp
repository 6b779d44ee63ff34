// SegmentParams: the segmenter's and the scope's names, and validate(), the one check of every
// field's hard limits (what the rules' maths needs), run before any frame is segmented.
#include <sstream>

#include "../param_check.hpp"
#include "wul3d/error.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d {

Scope parse_scope(const std::string& name) {
    if (name == "support") return Scope::Support;
    if (name == "scene") return Scope::Scene;
    throw ParamError("scope", "'" + name + "'", "unknown (known: support, scene)");
}

const char* scope_name(Scope s) { return s == Scope::Support ? "support" : "scene"; }

Segmenter parse_segmenter(const std::string& name) {
    if (name == "geometric") return Segmenter::Geometric;
    if (name == "kmeans") return Segmenter::Kmeans;
    if (name == "hybrid") return Segmenter::Hybrid;
    throw ParamError("segmenter", "'" + name + "'", "unknown (known: geometric, kmeans, hybrid)");
}

const char* segmenter_name(Segmenter s) {
    switch (s) {
        case Segmenter::Geometric: return "geometric";
        case Segmenter::Kmeans: return "kmeans";
        case Segmenter::Hybrid: return "hybrid";
    }
    return "?";
}

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "SegmentParams", name, value, range);
}
}  // namespace

void SegmentParams::validate() const {
    require(min_points >= 1, "min_points", min_points, ">= 1");
    require(depth_jump_m > 0, "depth_jump_m", depth_jump_m, "> 0");
    require(depth_jump_rel >= 0, "depth_jump_rel", depth_jump_rel, ">= 0");
    require(cuts.normal_smooth_px >= 0 && cuts.normal_smooth_px <= 16, "cuts.normal_smooth_px", cuts.normal_smooth_px, "in [0, 16]");
    require(cuts.crease_step_px >= 1 && cuts.crease_step_px <= 16, "cuts.crease_step_px", cuts.crease_step_px, "in [1, 16]");
    require(cuts.concavity > 0, "cuts.concavity", cuts.concavity, "> 0");
    require(cuts.reattach_px >= 0, "cuts.reattach_px", cuts.reattach_px, ">= 0");
    require(cuts.min_seed_points >= 1, "cuts.min_seed_points", cuts.min_seed_points, ">= 1");
    require(merge.max_concave >= 0 && merge.max_concave <= 1, "merge.max_concave", merge.max_concave, "in [0, 1]");
    require(merge.min_boundary >= 1, "merge.min_boundary", merge.min_boundary, ">= 1");
    require(colour.alpha >= 0.002f && colour.alpha <= 0.1f, "colour.alpha", colour.alpha,
            "in [0.002, 0.1] (the paper's range of alpha)");
    require(colour.min_distance > 0, "colour.min_distance", colour.min_distance, "> 0");
    require(colour.min_share > 0 && colour.min_share <= 0.5f, "colour.min_share", colour.min_share, "in (0, 0.5]");
    require(colour.max_boundary > 0 && colour.max_boundary <= 1, "colour.max_boundary", colour.max_boundary, "in (0, 1]");
    require(colour.max_compact >= 0, "colour.max_compact", colour.max_compact, ">= 0");
    require(colour.max_crease_deg > 0, "colour.max_crease_deg", colour.max_crease_deg, "> 0");
    require(colour.min_hue_deg > 0 && colour.min_hue_deg < 90, "colour.min_hue_deg", colour.min_hue_deg, "in (0, 90)");
    require(colour.min_step >= 0 && colour.min_step < 100, "colour.min_step", colour.min_step, "in [0, 100), <= 1 = off");
    require(colour.round_deg >= 0 && colour.round_deg < 90, "colour.round_deg", colour.round_deg, "in [0, 90)");
    require(colour.round_max_radius_m > 0, "colour.round_max_radius_m", colour.round_max_radius_m, "> 0");
    require(stacks.min_step_m >= 0 && stacks.min_step_m <= 0.5f, "stacks.min_step_m", stacks.min_step_m,
            "in [0, 0.5], 0 = off");
    require(stacks.min_share > 0 && stacks.min_share <= 0.5f, "stacks.min_share", stacks.min_share, "in (0, 0.5]");
    require(containers.min_boundary == 0 || containers.min_boundary >= 3, "containers.min_boundary", containers.min_boundary, ">= 3, or 0 = off");
    require(containers.max_residual_m > 0, "containers.max_residual_m", containers.max_residual_m, "> 0");
    require(containers.min_arc > 0 && containers.min_arc <= 1, "containers.min_arc", containers.min_arc, "in (0, 1]");
    require(containers.inside_share > 0 && containers.inside_share <= 1, "containers.inside_share", containers.inside_share, "in (0, 1]");
    require(containers.height_tol_m > 0, "containers.height_tol_m", containers.height_tol_m, "> 0");
    require(containers.far_agree > 0, "containers.far_agree", containers.far_agree, "> 0");
    require(containers.gap_max_px >= 0, "containers.gap_max_px", containers.gap_max_px, ">= 0");
    require(occlusion.min_lines >= 0, "occlusion.min_lines", occlusion.min_lines, ">= 0");
    require(occlusion.max_offset > 0, "occlusion.max_offset", occlusion.max_offset, "> 0");
    require(occlusion.max_gap_m > 0, "occlusion.max_gap_m", occlusion.max_gap_m, "> 0");
    require(occlusion.max_deg > 0 && occlusion.max_deg < 90, "occlusion.max_deg", occlusion.max_deg, "in (0, 90)");
    require(scope.contact_m > 0, "scope.contact_m", scope.contact_m, "> 0");
    require(scope.max_height_m > 0, "scope.max_height_m", scope.max_height_m, "> 0");
    require(scope.low_support_max_m >= 0 && scope.low_support_max_m <= 0.5f, "scope.low_support_max_m", scope.low_support_max_m,
            "in [0, 0.5]");
    require(scope.low_support_min_area_m2 > 0, "scope.low_support_min_area_m2", scope.low_support_min_area_m2, "> 0");
    require(scope.max_outside >= 0 && scope.max_outside <= 1, "scope.max_outside", scope.max_outside, "in [0, 1]");
    require(scope.upright_share >= 0 && scope.upright_share <= 1, "scope.upright_share", scope.upright_share, "in [0, 1]");
}

}  // namespace wul3d
