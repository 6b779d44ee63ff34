#include "params.hpp"

#include "wul3d/error.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d::python {

ParamArgs take_param_args(py::dict& o) {
    ParamArgs a;
    a.preset = take<std::string>(o, "preset");
    a.k = take<int>(o, "k");
    a.alpha = take<float>(o, "alpha");
    a.delta = take<float>(o, "delta");
    a.gamma = take<float>(o, "gamma");
    a.psi = take<float>(o, "psi");
    a.iters = take<int>(o, "iters");
    a.stride = take<int>(o, "stride");
    a.seed = take<std::uint64_t>(o, "seed");
    a.zmin = take<float>(o, "zmin");
    a.zmax = take<float>(o, "zmax");
    a.normal_radius = take<int>(o, "normal_radius");
    a.segmenter = take<std::string>(o, "segmenter");
    a.scope = take<std::string>(o, "scope");
    a.min_points = take<int>(o, "min_points");
    a.object_psi = take<float>(o, "object_psi");
    a.decimate = take<int>(o, "decimate");
    return a;
}

PipelineParams make_params(const ParamArgs& a) {
    PipelineParams p;
    if (a.preset && *a.preset == "paper") {
        p = PipelineParams::paper();
    } else if (a.preset && *a.preset != "default") {
        throw ParamError("preset '" + *a.preset + "': unknown (known: default, paper)");
    }
    if (a.k) p.cluster.k = *a.k;
    if (a.alpha) {
        p.cluster.alpha = *a.alpha;
        if (!a.delta) p.cluster.delta = 1.0f - *a.alpha;
    }
    if (a.delta) p.cluster.delta = *a.delta;
    if (a.gamma) p.cluster.gamma = *a.gamma;
    if (a.psi) p.cluster.psi = *a.psi;
    if (a.iters) p.cluster.iters = *a.iters;
    if (a.stride) p.cluster.stride = *a.stride;
    if (a.seed) p.cluster.seed = *a.seed;
    if (a.zmin) p.range.zmin_m = *a.zmin;
    if (a.zmax) p.range.zmax_m = *a.zmax;
    if (a.normal_radius) p.normals.radius_px = *a.normal_radius;
    if (a.segmenter) p.segmentation.segmenter = parse_segmenter(*a.segmenter);
    if (a.scope) p.segmentation.scope = parse_scope(*a.scope);
    p.remove_plane = a.remove_plane;
    if (a.min_points) p.segmentation.min_points = *a.min_points;
    if (a.object_psi) p.objects.psi = *a.object_psi;
    if (a.decimate) p.decimation = *a.decimate;
    p.validate();
    return p;
}

py::dict params_dict(const PipelineParams& p) {
    const auto& c = p.cluster;
    py::dict d;
    d["k"] = c.k;
    d["alpha"] = c.alpha;
    d["delta"] = c.delta;
    d["gamma"] = c.gamma;
    d["psi"] = c.psi;
    d["iters"] = c.iters;
    d["stride"] = c.stride;
    d["seed"] = c.seed;
    d["zmin"] = p.range.zmin_m;
    d["zmax"] = p.range.zmax_m;
    d["normal_radius"] = p.normals.radius_px;
    d["segmenter"] = segmenter_name(p.segmentation.segmenter);
    d["scope"] = scope_name(p.segmentation.scope);
    d["remove_plane"] = p.remove_plane;
    d["min_points"] = p.segmentation.min_points;
    d["object_psi"] = p.objects.psi;
    d["decimate"] = p.decimation;
    return d;
}

}  // namespace wul3d::python
