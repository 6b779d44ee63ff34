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
    require(normal_smooth_px >= 0 && normal_smooth_px <= 16, "normal_smooth_px", normal_smooth_px, "in [0, 16]");
    require(crease_step_px >= 1 && crease_step_px <= 16, "crease_step_px", crease_step_px, "in [1, 16]");
    require(concavity > 0, "concavity", concavity, "> 0");
    require(reattach_px >= 0, "reattach_px", reattach_px, ">= 0");
    require(min_seed_points >= 1, "min_seed_points", min_seed_points, ">= 1");
    require(merge_max_concave >= 0 && merge_max_concave <= 1, "merge_max_concave", merge_max_concave, "in [0, 1]");
    require(merge_min_boundary >= 1, "merge_min_boundary", merge_min_boundary, ">= 1");
    require(color_alpha >= 0.002f && color_alpha <= 0.1f, "color_alpha", color_alpha,
            "in [0.002, 0.1] (the paper's range of alpha)");
    require(color_min_distance > 0, "color_min_distance", color_min_distance, "> 0");
    require(color_min_share > 0 && color_min_share <= 0.5f, "color_min_share", color_min_share, "in (0, 0.5]");
    require(color_max_boundary > 0 && color_max_boundary <= 1, "color_max_boundary", color_max_boundary, "in (0, 1]");
    require(color_max_compact >= 0, "color_max_compact", color_max_compact, ">= 0");
    require(color_max_crease_deg > 0, "color_max_crease_deg", color_max_crease_deg, "> 0");
    require(color_min_hue_deg > 0 && color_min_hue_deg < 90, "color_min_hue_deg", color_min_hue_deg, "in (0, 90)");
    require(color_min_step >= 0 && color_min_step < 100, "color_min_step", color_min_step, "in [0, 100), <= 1 = off");
    require(color_round_deg >= 0 && color_round_deg < 90, "color_round_deg", color_round_deg, "in [0, 90)");
    require(color_round_max_radius_m > 0, "color_round_max_radius_m", color_round_max_radius_m, "> 0");
    require(stack_min_step_m >= 0 && stack_min_step_m <= 0.5f, "stack_min_step_m", stack_min_step_m,
            "in [0, 0.5], 0 = off");
    require(stack_min_share > 0 && stack_min_share <= 0.5f, "stack_min_share", stack_min_share, "in (0, 0.5]");
    require(rim_min_boundary == 0 || rim_min_boundary >= 3, "rim_min_boundary", rim_min_boundary, ">= 3, or 0 = off");
    require(rim_max_residual_m > 0, "rim_max_residual_m", rim_max_residual_m, "> 0");
    require(rim_min_arc > 0 && rim_min_arc <= 1, "rim_min_arc", rim_min_arc, "in (0, 1]");
    require(rim_inside_share > 0 && rim_inside_share <= 1, "rim_inside_share", rim_inside_share, "in (0, 1]");
    require(rim_height_tol_m > 0, "rim_height_tol_m", rim_height_tol_m, "> 0");
    require(rim_far_agree > 0, "rim_far_agree", rim_far_agree, "> 0");
    require(gap_max_px >= 0, "gap_max_px", gap_max_px, ">= 0");
    require(occluded_min_lines >= 0, "occluded_min_lines", occluded_min_lines, ">= 0");
    require(occluded_max_offset > 0, "occluded_max_offset", occluded_max_offset, "> 0");
    require(occluded_max_gap_m > 0, "occluded_max_gap_m", occluded_max_gap_m, "> 0");
    require(occluded_max_deg > 0 && occluded_max_deg < 90, "occluded_max_deg", occluded_max_deg, "in (0, 90)");
    require(scope_contact_m > 0, "scope_contact_m", scope_contact_m, "> 0");
    require(scope_max_height_m > 0, "scope_max_height_m", scope_max_height_m, "> 0");
    require(low_support_max_m >= 0 && low_support_max_m <= 0.5f, "low_support_max_m", low_support_max_m,
            "in [0, 0.5]");
    require(low_support_min_area_m2 > 0, "low_support_min_area_m2", low_support_min_area_m2, "> 0");
    require(scope_max_outside >= 0 && scope_max_outside <= 1, "scope_max_outside", scope_max_outside, "in [0, 1]");
    require(scope_upright_share >= 0 && scope_upright_share <= 1, "scope_upright_share", scope_upright_share, "in [0, 1]");
}

}  // namespace wul3d
