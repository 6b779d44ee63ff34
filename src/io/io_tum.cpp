// TUM RGB-D sequences (io.hpp, InputFormat::Tum): rgb.txt and depth.txt paired by
// timestamp, intrinsics from a preset named by the folder or given.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "wul3d/camera.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d::detail {

namespace fs = std::filesystem;

namespace {

struct Stamped {
    double t = 0;
    std::string stamp;  ///< as written in the file: the frame name
    std::string file;   ///< relative to the sequence folder
    int line = 0;       ///< in its list
};

/// `rgb.txt` / `depth.txt`: "timestamp filename" lines, '#' comments, blank lines skipped.
std::vector<Stamped> read_tum_list(const fs::path& file) {
    const std::string path = file.string();
    std::vector<unsigned char> bytes;
    detail::read_regular_file(path, kMaxListBytes, bytes);
    std::istringstream in(std::string(bytes.begin(), bytes.end()));
    std::vector<Stamped> list;
    std::string line;
    for (int lineno = 1; std::getline(in, line); ++lineno) {
        const auto first = line.find_first_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') continue;
        std::istringstream fields(line);
        Stamped s;
        char* end = nullptr;
        if (fields >> s.stamp >> s.file) s.t = std::strtod(s.stamp.c_str(), &end);
        if (end == nullptr || *end != '\0' || !std::isfinite(s.t)) {
            throw InputError(path + ":" + std::to_string(lineno) +
                             ": expected 'timestamp filename', got '" + line + "'");
        }
        s.line = lineno;
        list.push_back(std::move(s));
    }
    return list;
}

/// Refuses one timestamp for two depth images: both would be the frame of that name
/// (OUT/<t>/), the second replacing the first unseen. A line written again whole (the same
/// timestamp and image) is the same frame again, and stays allowed (a long run of one
/// small frame, as the memory tests make).
void check_unique_stamps(const fs::path& file, const std::vector<Stamped>& list) {
    std::unordered_map<std::string_view, const Stamped*> first;
    first.reserve(list.size());
    for (const Stamped& s : list) {
        const auto [it, added] = first.emplace(s.stamp, &s);
        if (!added && it->second->file != s.file)
            throw InputError(file.string() + ":" + std::to_string(s.line) + ": timestamp " +
                             s.stamp + " again, for " + s.file + " (first on line " +
                             std::to_string(it->second->line) + ", for " + it->second->file +
                             "): two frames of one name; remove one of them");
    }
}

struct TumPair {
    std::string name;
    fs::path depth, color;
};

/// Each depth frame takes the colour frame nearest in time, if within max_dt_s; depth
/// frames without one are dropped. (A colour frame may serve two depth frames; at TUM's
/// 30 Hz that does not happen within the default 20 ms.)
std::vector<TumPair> associate(const fs::path& root, std::vector<Stamped> depth,
                               std::vector<Stamped> rgb, double max_dt_s) {
    auto by_time = [](const Stamped& a, const Stamped& b) { return a.t < b.t; };
    std::stable_sort(depth.begin(), depth.end(), by_time);
    std::stable_sort(rgb.begin(), rgb.end(), by_time);
    std::vector<TumPair> pairs;
    for (const Stamped& d : depth) {
        auto it = std::lower_bound(rgb.begin(), rgb.end(), d, by_time);
        const Stamped* best = nullptr;
        if (it != rgb.end()) best = &*it;
        if (it != rgb.begin()) {
            const Stamped& prev = *(it - 1);
            if (best == nullptr || d.t - prev.t <= best->t - d.t) best = &prev;
        }
        if (best != nullptr && std::abs(best->t - d.t) <= max_dt_s) {
            pairs.push_back({d.stamp, root / d.file, root / best->file});
        }
    }
    return pairs;
}

class TumSource final : public FrameSource {
public:
    TumSource(std::vector<TumPair> pairs, PinholeIntrinsics K, std::string intrinsics_from)
        : pairs_(std::move(pairs)), K_(K), intrinsics_from_(std::move(intrinsics_from)) {}

    std::size_t size() const override { return pairs_.size(); }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return pairs_[i].name;
    }
    InputFormat format() const override { return InputFormat::Tum; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<TumSource>(*this); }

    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        const TumPair& pair = pairs_[i];
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.name = pair.name;
        f.intrinsics = K_;
        // TUM RGB-D: "depth images are scaled by a factor of 5000".
        // Sizes from the headers, before the pixels: against sized intrinsics, colour
        // against depth.
        detail::read_depth_png_into(pair.depth.string(), kTumDepthScale, depth_scratch_, f.depth,
                                    [&](int w, int h) {
                                        if ((K_.width != 0 || K_.height != 0) && !K_.same_size(w, h))
                                            throw InputError(
                                                pair.depth.string() + ": depth is " + size_str(w, h) +
                                                " but the intrinsics (" + intrinsics_from_ +
                                                ") are " + size_str(K_.width, K_.height));
                                    });
        if (K_.width == 0 && K_.height == 0) {
            f.intrinsics.width = f.depth.width;  // given intrinsics without a size
            f.intrinsics.height = f.depth.height;
            f.intrinsics.validate(pair.depth.string() + ": the intrinsics (" + intrinsics_from_ + ")");
        }
        if (!f.intrinsics.same_size(f.depth.width, f.depth.height)) {
            throw InputError(pair.depth.string() + ": depth is " +
                             size_str(f.depth.width, f.depth.height) + " but the intrinsics (" +
                             intrinsics_from_ + ") are " + size_str(K_.width, K_.height));
        }
        detail::read_color_image_into(pair.color.string(), color_scratch_, f.color, [&](int w, int h) {
            if (w != f.depth.width || h != f.depth.height)
                throw InputError(pair.color.string() + ": colour is " + size_str(w, h) +
                                 " but depth " + pair.depth.string() + " is " +
                                 size_str(f.depth.width, f.depth.height));
        });
    }

    static constexpr float kTumDepthScale = 1.0f / 5000.0f;

private:
    std::vector<TumPair> pairs_;
    PinholeIntrinsics K_;
    std::string intrinsics_from_;
    // One scratch per image kind: a shared one would be re-allocated at every type change.
    detail::ImageScratch depth_scratch_, color_scratch_;
};

}  // namespace

std::unique_ptr<FrameSource> open_tum(const std::string& path, const fs::path& root,
                                      const SourceOptions& options) {
    if (!(options.tum_max_dt_s >= 0.0) || !std::isfinite(options.tum_max_dt_s)) {
        throw ParamError("SourceOptions.tum_max_dt_s = " + std::to_string(options.tum_max_dt_s) +
                         ": must be >= 0");
    }
    std::vector<Stamped> rgb = read_tum_list(root / "rgb.txt");
    std::vector<Stamped> depth = read_tum_list(root / "depth.txt");
    check_unique_stamps(root / "depth.txt", depth);
    if (depth.empty()) throw InputError(path + ": no frames found (depth.txt lists none)");
    std::vector<TumPair> pairs = associate(root, std::move(depth), std::move(rgb), options.tum_max_dt_s);
    if (pairs.empty()) {
        std::ostringstream msg;
        msg << path << ": no frames found (no depth.txt entry has an rgb.txt entry within "
            << options.tum_max_dt_s << " s)";
        throw InputError(msg.str());
    }

    PinholeIntrinsics K;
    std::string from;
    if (options.intrinsics) {
        K = *options.intrinsics;
        from = "given";
    } else {
        std::string preset = options.tum_camera;
        if (preset.empty()) {
            // TUM folders are named rgbd_dataset_freiburgN_<scene>: N picks the sensor.
            const std::string folder = normalized(root).filename().string();
            preset = folder.find("freiburg1") != std::string::npos   ? "tum_fr1"
                     : folder.find("freiburg2") != std::string::npos ? "tum_fr2"
                     : folder.find("freiburg3") != std::string::npos ? "tum_fr3"
                                                                     : "kinect_v1";
        }
        K = intrinsics_preset(preset);
        from = preset;
    }
    if (K.sized())
        K.validate("TUM intrinsics (" + from + ")");
    else
        K.validate_unsized("TUM intrinsics (" + from + ")");  // checked with each frame's size
    return std::make_unique<TumSource>(std::move(pairs), K, from);
}

}  // namespace wul3d::detail
