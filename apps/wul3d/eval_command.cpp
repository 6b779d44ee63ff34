// `wul3d eval PRED GT`: pair predicted and ground-truth label images by frame name, score
// them with the library's metric (eval.hpp), print the table and optionally write JSON.
// Parsing and output only; the metric is the library's.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "json_text.hpp"
#include "pipeline_options.hpp"
#include "wul3d/error.hpp"
#include "wul3d/eval.hpp"
#include "wul3d/io.hpp"
#include "wul3d/write_guard.hpp"

namespace wul3d::cli {
namespace fs = std::filesystem;

namespace {

struct EvalOptions {
    std::string pred;
    std::string gt;
    std::string gt_file = "label.png";
    std::string pred_file = "objects.png";
    std::string json;
    std::vector<std::string> only;  // frame-name prefixes kept; empty = all
    int gt_background_max = 0;
    int tolerance_px = -1;
    bool per_image = false;
    bool temporal = false;
    bool allow_missing = false;
    bool where_depth = false;
};

/// One frame to score: its name, the ground-truth file and the prediction file (empty when
/// missing and --allow-missing).
struct FramePair {
    std::string name;
    fs::path gt;
    fs::path pred;
    std::optional<BopImageMasks> bop;  ///< a BOP image: its masks make the ground truth
};

bool is_file(const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec);
}
bool is_dir(const fs::path& p) {
    std::error_code ec;
    return fs::is_directory(p, ec);
}

/// An OCID sequence folder as downloaded: rgb/, depth/ and label/.
bool is_ocid_sequence(const fs::path& p) {
    return is_dir(p / "label") && is_dir(p / "depth") && is_dir(p / "rgb");
}

/// OCID's background ids: 0 (no depth), 1 (floor or wall) and, on tables, 2 (the table).
/// The sequence's path says which: .../floor/... or .../table/....
int ocid_background_max(const fs::path& seq) {
    for (const fs::path& part : fs::absolute(seq).lexically_normal())
        if (part == "floor") return 1;
    return 2;
}

/// An OSD-0.2-depth tree: image_color/ and annotation/ (labels, 0 background).
bool is_osd_tree(const fs::path& p) { return is_dir(p / "image_color") && is_dir(p / "annotation"); }

/// A BOP scene: scene_camera.json (list_bop_masks then wants mask_visib/).
bool is_bop_scene(const fs::path& p) { return is_file(p / "scene_camera.json"); }

/// The PNGs of `dir` (stems starting with `prefix`) as ground-truth frames named by stem.
std::vector<FramePair> label_files(const std::string& what, const fs::path& dir,
                                   const std::string& prefix) {
    std::vector<FramePair> frames;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string n = e.path().filename().string();
        if (n.rfind(prefix, 0) == 0 && e.path().extension() == ".png" && is_file(e.path()))
            frames.push_back({e.path().stem().string(), e.path(), {}, {}});
    }
    if (ec) throw InputError(dir.string() + ": cannot list the folder (" + ec.message() + ")");
    if (frames.empty()) throw InputError(what + ": no " + prefix + "*.png in " + dir.string());
    std::sort(frames.begin(), frames.end(),
              [](const FramePair& a, const FramePair& b) { return a.name < b.name; });
    return frames;
}

bool kept(const EvalOptions& o, const std::string& name) {
    if (o.only.empty()) return true;
    return std::any_of(o.only.begin(), o.only.end(),
                       [&](const std::string& prefix) { return name.rfind(prefix, 0) == 0; });
}

/// GT: a label PNG, a frame folder holding --gt-file, or a folder of such frame folders
/// (sorted by name, as `wul3d run` orders them). PRED: a label PNG, a frame folder holding
/// --pred-file, or a folder of frame folders named like the ground truth's.
std::vector<FramePair> pair_frames(const EvalOptions& o) {
    const fs::path gt(o.gt), pred(o.pred);
    if (!is_file(gt) && !is_dir(gt)) throw InputError(o.gt + ": ground truth not found");
    if (!is_file(pred) && !is_dir(pred)) throw InputError(o.pred + ": prediction not found");

    if (is_dir(gt / "image_color") && !is_dir(gt / "annotation"))
        throw InputError(o.gt + ": an OSD tree without annotation/ (its labels)");
    std::vector<FramePair> frames;
    const bool dataset = is_ocid_sequence(gt) || is_osd_tree(gt) || is_bop_scene(gt);
    const bool single = !dataset && (is_file(gt) || is_file(gt / o.gt_file));
    if (is_ocid_sequence(gt)) {
        // Datasets as downloaded, their frames named as `wul3d run` names them: OCID's
        // label/result_*.png and OSD's annotation/NAME.png by their stem, BOP's images by
        // the image id of mask_visib/IMID_GTID.png.
        frames = label_files(o.gt, gt / "label", "result_");
    } else if (is_osd_tree(gt)) {
        frames = label_files(o.gt, gt / "annotation", "");
    } else if (is_bop_scene(gt)) {
        for (BopImageMasks& m : list_bop_masks(o.gt)) {
            FramePair f;
            f.name = m.name;
            f.gt = gt / "mask_visib" / (m.name + "_*.png");
            f.bop = std::move(m);
            frames.push_back(std::move(f));
        }
    } else if (single) {
        FramePair f;
        f.gt = is_file(gt) ? gt : gt / o.gt_file;
        const fs::path folder = is_file(gt) ? gt.parent_path() : gt;
        f.name = fs::absolute(folder).lexically_normal().filename().string();
        if (f.name.empty()) f.name = fs::absolute(folder).lexically_normal().parent_path().filename().string();
        frames.push_back(f);
    } else {
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(gt, ec))
            if (e.is_directory() && is_file(e.path() / o.gt_file))
                frames.push_back({e.path().filename().string(), e.path() / o.gt_file, {}, {}});
        if (ec) throw InputError(o.gt + ": cannot list the folder (" + ec.message() + ")");
        if (frames.empty())
            throw InputError(o.gt + ": no " + o.gt_file +
                             " found, neither in the folder nor in its sub-folders");
        std::sort(frames.begin(), frames.end(),
                  [](const FramePair& a, const FramePair& b) { return a.name < b.name; });
    }
    frames.erase(std::remove_if(frames.begin(), frames.end(),
                                [&](const FramePair& f) { return !kept(o, f.name); }),
                 frames.end());
    if (frames.empty()) throw InputError(o.gt + ": no frame name starts with the --only prefixes");

    for (FramePair& f : frames) {
        if (is_file(pred)) {
            if (!single) throw InputError(o.pred + ": a single file, but the ground truth " + o.gt +
                                          " is a folder of frames");
            f.pred = pred;
        } else if (single && is_file(pred / o.pred_file)) {
            f.pred = pred / o.pred_file;
        } else if (is_file(pred / f.name / o.pred_file)) {
            f.pred = pred / f.name / o.pred_file;
        } else if (!o.allow_missing) {
            throw InputError((pred / f.name / o.pred_file).string() +
                             ": no prediction for ground-truth frame " + f.name +
                             " (--allow-missing scores it as empty)");
        }
    }
    return frames;
}

std::string pct(double x) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << 100.0 * x;
    return s.str();
}

nlohmann::json score_json(const ImageScore& s) {
    nlohmann::json matches = nlohmann::json::array();
    for (const MatchedPair& m : s.matches)
        matches.push_back({{"gt_id", m.gt_id},
                           {"pred_id", m.pred_id},
                           {"true_positives", m.true_positives},
                           {"overlap_f", m.overlap_f}});
    return {{"overlap_p", s.overlap_p},
            {"overlap_r", s.overlap_r},
            {"overlap_f", s.overlap_f},
            {"boundary_p", s.boundary_p},
            {"boundary_r", s.boundary_r},
            {"boundary_f", s.boundary_f},
            {"detected_share", s.detected_share},
            {"gt_objects", s.gt_objects},
            {"pred_objects", s.pred_objects},
            {"detected", s.detected},
            {"boundary_tolerance_px", s.boundary_tolerance_px},
            {"matches", matches}};
}

/// The one-line error for an image of `path` whose size differs from the ground truth's.
InputError size_mismatch(const fs::path& path, int width, int height, const fs::path& gt_path, const LabelImage& gt) {
    return InputError(path.string() + " is " + std::to_string(width) + "x" + std::to_string(height) + " but " +
                      gt_path.string() + " is " + std::to_string(gt.width) + "x" + std::to_string(gt.height));
}

/// The depth image of frame `f`: depth.png beside its labels (a frame folder); in a dataset
/// as downloaded, the same name under depth/ (an OCID sequence's label/, a BOP scene's
/// mask_visib/) or disparity/ (an OSD tree's annotation/: depth in millimetres). Else an
/// InputError: --where-depth needs it.
fs::path depth_of(const FramePair& f) {
    const fs::path folder = f.gt.parent_path(), root = folder.parent_path();
    const fs::path beside = folder / "depth.png";
    fs::path in_dataset;
    if (f.bop) in_dataset = root / "depth" / (f.name + ".png");
    else if (folder.filename() == "label") in_dataset = root / "depth" / f.gt.filename();
    else if (folder.filename() == "annotation") in_dataset = root / "disparity" / f.gt.filename();
    if (!in_dataset.empty() && is_file(in_dataset)) return in_dataset;
    if (is_file(beside)) return beside;
    throw InputError(f.gt.string() + ": --where-depth: no depth image for the frame (" +
                     (in_dataset.empty() ? beside : in_dataset).string() + ")");
}

/// Both label images 0 where the frame's depth image has no reading: those pixels are not
/// scored, as in OSD's and OCID's labels, which were drawn on the points.
void keep_where_depth(const FramePair& f, LabelImage& gt, LabelImage& pred) {
    const fs::path path = depth_of(f);
    const DepthImage depth = read_depth_png(path.string(), 0.001f);  // only 0 or not matters
    if (depth.width != gt.width || depth.height != gt.height)
        throw size_mismatch(path, depth.width, depth.height, f.gt, gt);
    for (std::size_t p = 0; p < depth.data.size(); ++p)
        if (depth.data[p] == 0) gt.labels[p] = pred.labels[p] = 0;
}

/// One pair's ground truth (BOP's masks combined; ids up to `bg_max` as background) and
/// prediction (all background when there is none: `missing` counts it), of one size; with
/// `where_depth`, both kept only where the frame has depth (keep_where_depth).
std::pair<LabelImage, LabelImage> read_pair(const FramePair& f, int bg_max, bool where_depth, int& missing) {
    LabelImage gt = f.bop ? combine_bop_masks(*f.bop) : read_label_png(f.gt.string());
    if (bg_max > 0)
        for (std::uint16_t& l : gt.labels)
            if (l <= bg_max) l = 0;
    LabelImage pred;
    if (f.pred.empty()) {
        ++missing;
        pred.width = gt.width;
        pred.height = gt.height;
        pred.labels.assign(gt.labels.size(), 0);
    } else {
        pred = read_label_png(f.pred.string());
    }
    if (pred.width != gt.width || pred.height != gt.height)
        throw size_mismatch(f.pred, pred.width, pred.height, f.gt, gt);
    if (where_depth) keep_where_depth(f, gt, pred);
    return {std::move(gt), std::move(pred)};
}

/// --per-image's line of one frame.
void print_image(const FramePair& f, const ImageScore& s) {
    std::cout << f.name << ": overlap P/R/F " << pct(s.overlap_p) << " " << pct(s.overlap_r)
              << " " << pct(s.overlap_f) << ", boundary P/R/F " << pct(s.boundary_p) << " "
              << pct(s.boundary_r) << " " << pct(s.boundary_f) << ", %>=75 "
              << pct(s.detected_share) << ", objects " << s.gt_objects << " (predicted "
              << s.pred_objects << ")" << (f.pred.empty() ? ", no prediction" : "") << "\n";
}

/// The table of the whole set on stdout, and the same as --json's "summary".
nlohmann::json print_summary(const EvalOptions& o, const std::vector<ImageScore>& scores,
                             int missing) {
    const EvalSummary m = summarize(scores);
    std::cout << "wul3d eval: " << m.images << " image" << (m.images == 1 ? "" : "s") << ", "
              << m.gt_objects << " objects (" << o.pred_file << " vs " << o.gt_file
              << ", boundary tolerance " << scores.front().boundary_tolerance_px << " px"
              << (o.where_depth ? ", where depth" : "")
              << (missing ? ", " + std::to_string(missing) + " without prediction" : "")
              << ")\n";
    std::cout << "Overlap P   " << pct(m.overlap_p) << "\n"
              << "Overlap R   " << pct(m.overlap_r) << "\n"
              << "Overlap F   " << pct(m.overlap_f) << "\n"
              << "Boundary P  " << pct(m.boundary_p) << "\n"
              << "Boundary R  " << pct(m.boundary_r) << "\n"
              << "Boundary F  " << pct(m.boundary_f) << "\n"
              << "%>=75       " << pct(m.detected_share) << "\n"
              << "images      " << m.images << "\n"
              << "objects     " << m.gt_objects << "\n";
    return {{"overlap_p", m.overlap_p},
            {"overlap_r", m.overlap_r},
            {"overlap_f", m.overlap_f},
            {"boundary_p", m.boundary_p},
            {"boundary_r", m.boundary_r},
            {"boundary_f", m.boundary_f},
            {"detected_share", m.detected_share},
            {"images", m.images},
            {"gt_objects", m.gt_objects},
            {"pred_objects", m.pred_objects},
            {"detected", m.detected},
            {"missing_predictions", missing},
            {"where_depth", o.where_depth}};
}

/// --temporal's table on stdout, and the same as --json's "temporal".
nlohmann::json print_temporal(const TemporalReport& t) {
    std::cout << "Temporal: " << t.frames << " frames, " << t.objects.size()
              << " ground-truth objects\n"
              << "ID switches          " << t.id_switches << "\n"
              << "ID switches/object   " << std::fixed << std::setprecision(2)
              << t.switches_per_object << "\n"
              << "ID switches max      " << t.max_switches << "\n"
              << "Flicker              " << pct(t.flicker) << "\n"
              << "Object flicker       " << pct(t.object_flicker) << "\n";
    for (const ObjectTrackScore& s : t.objects)
        std::cout << "  object " << s.gt_id << ": visible " << s.frames_visible
                  << " frames, matched " << s.frames_matched << ", switches " << s.switches
                  << "\n";
    nlohmann::json objs = nlohmann::json::array();
    for (const ObjectTrackScore& s : t.objects)
        objs.push_back({{"gt_id", s.gt_id},
                        {"frames_visible", s.frames_visible},
                        {"frames_matched", s.frames_matched},
                        {"switches", s.switches}});
    return {{"frames", t.frames},
            {"frame_pairs", t.frame_pairs},
            {"id_switches", t.id_switches},
            {"switches_per_object", t.switches_per_object},
            {"max_switches", t.max_switches},
            {"flicker", t.flicker},
            {"object_flicker", t.object_flicker},
            {"objects", objs}};
}

void run(EvalOptions o) {
    // An OCID sequence's own background ids, unless given.
    if (is_ocid_sequence(o.gt) && o.gt_background_max == 0)
        o.gt_background_max = ocid_background_max(o.gt);
    EvalParams params;
    params.boundary_tolerance_px = o.tolerance_px;
    params.validate();
    if (o.gt_background_max < 0 || o.gt_background_max > 65535)
        throw ParamError("--gt-background-max " + std::to_string(o.gt_background_max) +
                         ": must be in [0, 65535]");
    const std::vector<FramePair> frames = pair_frames(o);
    // Before scoring: a refused --json costs no time, and replaces no prediction or label.
    if (!o.json.empty()) check_write_target(o.json, WriteTarget::File, {o.pred, o.gt}, "--json");

    std::optional<SequenceScorer> sequence;
    if (o.temporal) sequence.emplace(params);
    std::vector<ImageScore> scores;
    nlohmann::json images = nlohmann::json::array();
    int missing = 0;
    for (const FramePair& f : frames) {
        const auto [gt, pred] = read_pair(f, o.gt_background_max, o.where_depth, missing);
        ImageScore s;
        try {
            s = sequence ? sequence->add(pred, gt) : score_image(pred, gt, params);
        } catch (const InputError& e) {
            throw InputError(f.name + " (" + f.gt.string() + "): " + e.what());
        }
        if (o.per_image) print_image(f, s);
        nlohmann::json j = score_json(s);
        j["name"] = f.name;
        j["gt_path"] = f.gt.string();
        j["pred_path"] = f.pred.empty() ? nlohmann::json(nullptr) : nlohmann::json(f.pred.string());
        images.push_back(std::move(j));
        scores.push_back(std::move(s));
    }

    nlohmann::json out;
    out["pred"] = o.pred;
    out["gt"] = o.gt;
    out["pred_file"] = o.pred_file;
    out["gt_file"] = o.gt_file;
    out["summary"] = print_summary(o, scores, missing);
    if (sequence) out["temporal"] = print_temporal(sequence->report());
    out["images"] = images;
    if (!o.json.empty()) write_text_file(o.json, json_text(out, 2) + "\n");
    std::cout << std::flush;
}

}  // namespace

void add_eval_command(CLI::App& app) {
    auto opts = std::make_shared<EvalOptions>();
    CLI::App* cmd = app.add_subcommand(
        "eval", "Score predicted object labels against ground truth (OSD/OCID metric)");
    cmd->add_option("pred", opts->pred,
                    "Predictions: a wul3d output folder (OUT/<frame>/objects.png), one frame "
                    "folder or one label PNG")
        ->required();
    cmd->add_option("gt", opts->gt,
                    "Ground truth: a folder of frame folders with label.png, one frame folder, "
                    "one label PNG, an OCID sequence (label/result_*.png; ids 0-2 on "
                    "tables, 0-1 on the floor are background), an OSD-0.2-depth tree "
                    "(annotation/) or a BOP scene (mask_visib/ combined, gt id g -> label g+1)")
        ->required();
    cmd->add_option("--pred-file", opts->pred_file,
                    "Prediction file in each frame folder (labels.png scores raw clusters)")
        ->capture_default_str();
    cmd->add_option("--gt-file", opts->gt_file,
                    "Ground-truth file in each frame folder (e.g. label_parts.png)")
        ->capture_default_str();
    cmd->add_option("--gt-background-max", opts->gt_background_max,
                    "Ground-truth labels up to this value are background (9 for OSD's "
                    "label_parts.png, whose 1-9 are the table)")
        ->capture_default_str()
        ->check(NumberIn(0, 65535));
    cmd->add_option("--only", opts->only,
                    "Score only frames whose name starts with this prefix (repeatable)");
    cmd->add_option("--tolerance", opts->tolerance_px,
                    "Boundary tolerance in pixels, [0, 50] (default: ceil(0.003 x image "
                    "diagonal), at most 50)")
        ->check(NumberIn(0, kMaxBoundaryTolerancePx));
    add_max_pixels_option(cmd);
    cmd->add_option("--json", opts->json, "Write the summary and per-image scores as JSON");
    cmd->add_flag("--per-image", opts->per_image, "Print one line per image");
    cmd->add_flag("--temporal", opts->temporal,
                  "Frames are one sequence: also report id switches and label flicker");
    cmd->add_flag("--allow-missing", opts->allow_missing,
                  "Score a ground-truth frame without prediction as an empty prediction");
    cmd->add_flag("--where-depth", opts->where_depth,
                  "Score only pixels with depth (the frame's depth.png; a dataset's depth/ or "
                  "OSD's disparity/): labels drawn on the points, as OSD's and OCID's were");
    cmd->callback([opts]() { run(*opts); });
}

}  // namespace wul3d::cli
