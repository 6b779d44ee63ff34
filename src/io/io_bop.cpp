// BOP scenes as downloaded (docs/INPUTS.md, section 6; the BOP toolkit's "scenewise"
// format): scene_camera.json (per image id: cam_K, depth_scale in mm per unit),
// depth/IMID.png, rgb/IMID.png|jpg or gray/IMID.png|jpg, and mask_visib/IMID_GTID.png,
// the ground truth `wul3d eval` combines into one instance label image per image.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "io_detail.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

namespace fs = std::filesystem;
using detail::size_str;

namespace {

bool all_digits(const std::string& s) {
    return !s.empty() && s.size() <= 9 &&
           std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::string lower_ext(const fs::path& p) {
    std::string e = p.extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e;
}

/// One image of a scene: its depth and colour files and its camera.
struct BopFrame {
    fs::path depth, color;
    PinholeIntrinsics K;      ///< unsized: each frame's own size
    float scale_m_per_unit;   ///< depth_scale / 1000
    std::string camera_what;  ///< names the camera in errors (made once, not per read)
};

nlohmann::json read_scene_camera(const fs::path& file) {
    std::vector<unsigned char> bytes;
    detail::read_regular_file(file.string(), kMaxBopJsonBytes, bytes);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::exception& e) {
        throw InputError(file.string() + ": invalid JSON (" + e.what() + ")");
    }
    if (!j.is_object())
        throw InputError(file.string() + ": must be a JSON object of image ids");
    return j;
}

/// cam_K (9 numbers, row-major, [fx 0 cx; 0 fy cy; 0 0 1]) and depth_scale (mm per unit)
/// of image `id`.
void parse_camera(const std::string& where, const nlohmann::json& cam, BopFrame& f) {
    if (!cam.is_object()) throw InputError(where + " must be a JSON object");
    const auto k = cam.find("cam_K");
    if (k == cam.end()) throw InputError(where + " has no cam_K");
    if (!k->is_array() || k->size() != 9 ||
        !std::all_of(k->begin(), k->end(), [](const nlohmann::json& v) {
            return v.is_number() && std::isfinite(v.get<double>());
        }))
        throw InputError(where + ": cam_K must be 9 finite numbers (3x3, row-major)");
    double m[9];
    for (int i = 0; i < 9; ++i) m[i] = (*k)[static_cast<std::size_t>(i)].get<double>();
    // A pinhole without skew: what the BOP datasets give, and all wul3d models.
    if (m[3] != 0.0 || m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0 ||
        std::abs(m[1]) > 1e-6 * std::abs(m[0]))
        throw InputError(where + ": cam_K must be [fx, 0, cx, 0, fy, cy, 0, 0, 1]");
    f.K = PinholeIntrinsics{};
    f.K.fx = m[0];
    f.K.cx = m[2];
    f.K.fy = m[4];
    f.K.cy = m[5];
    f.K.width = f.K.height = 0;
    f.K.validate_unsized(where + ": cam_K");
    const auto s = cam.find("depth_scale");
    if (s == cam.end()) throw InputError(where + " has no depth_scale");
    const double mm = s->is_number() ? s->get<double>() : std::nan("");
    // Millimetres per unit; the limits of depth_scale_m_per_unit, [1e-6, 1] m.
    if (!(mm >= 1e-3 && mm <= 1000.0))
        throw InputError(where + ": depth_scale " +
                         (s->is_number() ? detail::number_str(mm) : s->dump()) +
                         " must be a number in [0.001, 1000] millimetres per unit");
    f.scale_m_per_unit = static_cast<float>(mm / 1000.0);
}

/// The colour files of a scene by stem (png or jpg), from rgb/ or gray/.
std::vector<fs::path> list_colour(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string ext = lower_ext(e.path());
        if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") files.push_back(e.path());
    }
    if (ec) throw InputError(dir.string() + ": cannot list the folder (" + ec.message() + ")");
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
        return a.stem().string() < b.stem().string();
    });
    return files;
}

/// depth/IMID.png paired with the colour of the same image id; either without the other
/// is an error naming it.
std::vector<BopFrame> pair_bop_frames(const std::string& path, const fs::path& scene,
                                      const std::string& colour_dir) {
    const std::vector<fs::path> depth = detail::list_pngs(scene / "depth");
    const std::vector<fs::path> colour = list_colour(scene / colour_dir);
    if (depth.empty()) throw InputError(path + ": no frames found (depth/ holds no .png)");
    std::vector<BopFrame> frames;
    std::size_t c = 0;
    for (const fs::path& d : depth) {
        const std::string id = d.stem().string();
        if (!all_digits(id))
            throw InputError(d.string() + ": not a BOP image (depth/IMID.png, IMID a number)");
        if (c < colour.size() && colour[c].stem().string() < id)
            throw InputError(path + ": " + colour_dir + "/" + colour[c].filename().string() +
                             " has no depth/" + colour[c].stem().string() + ".png");
        if (c >= colour.size() || colour[c].stem().string() != id)
            throw InputError(path + ": depth/" + d.filename().string() + " has no " + colour_dir +
                             "/" + id + ".png or .jpg");
        frames.push_back({d, colour[c++], {}, 0.0f, {}});
    }
    if (c < colour.size())
        throw InputError(path + ": " + colour_dir + "/" + colour[c].filename().string() +
                         " has no depth/" + colour[c].stem().string() + ".png");
    return frames;
}

/// One BOP scene: every frame its own camera (cam_K may change from image to image, as in
/// T-LESS) and depth unit.
class BopSource final : public FrameSource {
public:
    explicit BopSource(std::vector<BopFrame> frames) : frames_(std::move(frames)) {}

    std::size_t size() const override { return frames_.size(); }
    std::string name(std::size_t i) const override {
        detail::check_index(i, size());
        return frames_[i].depth.stem().string();
    }
    InputFormat format() const override { return InputFormat::Bop; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<BopSource>(*this); }

    void read(std::size_t i, SourceItem& item) override {
        detail::check_index(i, size());
        const BopFrame& b = frames_[i];
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.name = name(i);
        detail::read_depth_png_into(b.depth.string(), b.scale_m_per_unit, depth_scratch_, f.depth);
        f.intrinsics = b.K;
        f.intrinsics.width = f.depth.width;
        f.intrinsics.height = f.depth.height;
        f.intrinsics.validate(b.camera_what);
        const std::string color = b.color.string();
        detail::read_color_image_into(color, color_scratch_, f.color, [&](int w, int h) {
            detail::check_same_size(color, w, h, f.depth.width, f.depth.height);
        });
    }

private:
    std::vector<BopFrame> frames_;
    detail::ImageScratch depth_scratch_, color_scratch_;
};

/// IMID and GTID of mask_visib/IMID_GTID.png, or false.
bool parse_mask_name(const std::string& stem, std::string& image, int& gt_id) {
    const std::size_t sep = stem.find('_');
    if (sep == std::string::npos) return false;
    image = stem.substr(0, sep);
    const std::string gt = stem.substr(sep + 1);
    if (!all_digits(image) || !all_digits(gt)) return false;
    gt_id = std::stoi(gt);
    return true;
}

}  // namespace

namespace detail {

bool is_bop_scene(const fs::path& dir) {
    std::error_code ec;
    if (fs::exists(dir / "scene_camera.json", ec)) return true;
    // Without its cameras, still a scene (which open_bop then refuses with the reason):
    // depth/ beside rgb/ or gray/ and BOP's own ground truth.
    return is_dir(dir / "depth") && (is_dir(dir / "rgb") || is_dir(dir / "gray")) &&
           (is_dir(dir / "mask_visib") || is_dir(dir / "mask") ||
            fs::exists(dir / "scene_gt.json", ec));
}

fs::path find_bop_scene(const fs::path& root, int levels) {
    if (levels <= 0) return {};
    std::vector<fs::path> subs;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(root, ec))
        if (is_dir(e.path())) subs.push_back(e.path());
    std::sort(subs.begin(), subs.end());
    for (const fs::path& s : subs)
        if (is_bop_scene(s)) return s;
    for (const fs::path& s : subs) {
        fs::path deeper = find_bop_scene(s, levels - 1);
        if (!deeper.empty()) return deeper;
    }
    return {};
}

std::unique_ptr<FrameSource> open_bop(const std::string& path, const fs::path& scene,
                                      const SourceOptions& options) {
    if (!options.calibration.empty())
        throw ParamError("a calibration is for unregistered input, but " + path +
                         " is read as a BOP scene (registered)");
    const fs::path camera_file = scene / "scene_camera.json";
    std::error_code ec;
    if (!fs::exists(camera_file, ec)) {
        if (is_bop_scene(scene))
            throw InputError(path + ": a BOP scene without scene_camera.json (the cam_K and "
                                    "depth_scale of each image)");
        const fs::path inner = find_bop_scene(scene, 2);
        if (!inner.empty())
            throw InputError(path + ": holds BOP scenes; give one scene folder (e.g. " +
                             inner.string() + "), or run them all with python3 -m wul3d.batch");
        throw InputError(path + ": not a BOP scene (expected scene_camera.json, depth/ and rgb/ "
                                "or gray/)");
    }
    if (!is_dir(scene / "depth")) throw InputError(path + ": a BOP scene without depth/");
    const std::string colour_dir = is_dir(scene / "rgb") ? "rgb" : "gray";
    if (!is_dir(scene / colour_dir))
        throw InputError(path + ": a BOP scene without rgb/ or gray/");
    std::vector<BopFrame> frames = pair_bop_frames(path, scene, colour_dir);

    // Every image's camera, before any frame is read: a missing or bad one is found at
    // once, not after an hour of frames.
    const nlohmann::json cameras = read_scene_camera(camera_file);
    for (BopFrame& f : frames) {
        const std::string id = std::to_string(std::stol(f.depth.stem().string()));
        const auto cam = cameras.find(id);
        if (cam == cameras.end())
            throw InputError(camera_file.string() + ": no image id " + id + " (depth/" +
                             f.depth.filename().string() + ")");
        parse_camera(camera_file.string() + ": image " + id, *cam, f);
        f.camera_what = camera_file.string() + ": image " + id + ": cam_K";
        if (options.intrinsics) {
            f.K = *options.intrinsics;  // sized or not, checked with each frame's size
            f.K.width = f.K.height = 0;
            f.K.validate_unsized("the given intrinsics");
            f.camera_what = "the given intrinsics";
        }
    }
    return std::make_unique<BopSource>(std::move(frames));
}

}  // namespace detail

std::vector<BopImageMasks> list_bop_masks(const std::string& scene) {
    const fs::path dir = fs::path(scene) / "mask_visib";
    if (!detail::is_dir(dir))
        throw InputError(scene + ": a BOP scene without mask_visib/ (its ground truth)");
    std::vector<BopImageMasks> images;
    for (const fs::path& p : detail::list_pngs(dir)) {
        std::string image;
        int gt_id = 0;
        if (!parse_mask_name(p.stem().string(), image, gt_id)) continue;
        if (gt_id > 65534)
            throw InputError(p.string() + ": gt id " + std::to_string(gt_id) +
                             " over 65534 (labels are 16-bit)");
        if (images.empty() || images.back().name != image) images.push_back({image, {}, {}});
        images.back().gt_ids.push_back(gt_id);
        images.back().masks.push_back(p.string());
    }
    if (images.empty())
        throw InputError(dir.string() + ": no masks (IMID_GTID.png) in the folder");
    // list_pngs sorts by path: IMID_GTID with zero-padded ids is already (image, gt id)
    // order; ids of other widths are put in order here.
    std::sort(images.begin(), images.end(),
              [](const BopImageMasks& a, const BopImageMasks& b) { return a.name < b.name; });
    for (BopImageMasks& m : images) {
        std::vector<std::size_t> order(m.gt_ids.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return m.gt_ids[a] < m.gt_ids[b]; });
        BopImageMasks sorted{m.name, {}, {}};
        for (std::size_t i : order) {
            sorted.gt_ids.push_back(m.gt_ids[i]);
            sorted.masks.push_back(m.masks[i]);
        }
        m = std::move(sorted);
    }
    return images;
}

LabelImage combine_bop_masks(const BopImageMasks& image) {
    LabelImage out;
    LabelImage mask;
    detail::ImageScratch scratch;
    for (std::size_t k = 0; k < image.masks.size(); ++k) {
        detail::read_label_png_into(image.masks[k], scratch, mask);
        if (k == 0) {
            out.width = mask.width;
            out.height = mask.height;
            out.labels.assign(mask.labels.size(), 0);
        } else if (mask.width != out.width || mask.height != out.height) {
            throw InputError(image.masks[k] + ": mask is " + size_str(mask.width, mask.height) +
                             " but " + image.masks[0] + " is " + size_str(out.width, out.height));
        }
        const auto label = static_cast<std::uint16_t>(image.gt_ids[k] + 1);
        // Ascending gt ids: a pixel already taken keeps the lower id.
        for (std::size_t i = 0; i < mask.labels.size(); ++i)
            if (mask.labels[i] != 0 && out.labels[i] == 0) out.labels[i] = label;
    }
    return out;
}

}  // namespace wul3d
