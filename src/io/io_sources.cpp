// Frame sequences of io.hpp: frame folders, unregistered frame folders, OCID sequences, PCD
// files, and open_source, which picks the reader (TUM RGB-D: io_tum.cpp; OSD: io_osd.cpp;
// BOP: io_bop.cpp).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <unordered_map>

#include "io_detail.hpp"
#include "wul3d/bag.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

namespace fs = std::filesystem;
using detail::size_str;

namespace detail {

bool is_file(const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec);
}

bool is_dir(const fs::path& p) {
    std::error_code ec;
    return fs::is_directory(p, ec);
}

bool present(const fs::path& p) {
    std::error_code ec;
    const auto status = fs::status(p, ec);
    if (!fs::exists(status)) return false;
    if (!fs::is_regular_file(status))
        throw InputError(p.string() + ": is not a regular file (a FIFO, device or folder)");
    return true;
}

void check_same_size(const std::string& what, int w, int h, int depth_w, int depth_h) {
    if (w != depth_w || h != depth_h)
        throw InputError(what + ": colour is " + size_str(w, h) + " but depth is " +
                         size_str(depth_w, depth_h));
}

void clear_colour(ColorImage& c) {
    c.width = c.height = 0;
    c.rgb.clear();  // keeps the capacity for the next frame that has colour
}

void check_index(std::size_t i, std::size_t n) {
    if (i >= n) {
        throw std::out_of_range("frame " + std::to_string(i) + " of a sequence of " +
                                std::to_string(n));
    }
}

std::vector<fs::path> list_pngs(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.path().extension() == ".png") files.push_back(e.path());
    if (ec) throw InputError(dir.string() + ": cannot list the folder (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    return files;
}

void read_mm_depth_with_intrinsics(const std::string& path, const PinholeIntrinsics& K,
                                   const std::string& from, ImageScratch& scratch, RgbdFrame& f) {
    f.intrinsics = K;
    read_depth_png_into(path, 0.001f, scratch, f.depth, [&](int w, int h) {
        if (K.sized() && !K.same_size(w, h))
            throw InputError(path + ": depth is " + size_str(w, h) + " but the intrinsics (" +
                             from + ") are " + size_str(K.width, K.height));
    });
    if (!K.sized()) {
        f.intrinsics.width = f.depth.width;
        f.intrinsics.height = f.depth.height;
        f.intrinsics.validate(path + ": the intrinsics (" + from + ")");
    }
}

bool given_or_pcd_intrinsics(const SourceOptions& options, const fs::path& pcd,
                             PinholeIntrinsics& K, std::string& from) {
    if (options.intrinsics) {
        K = *options.intrinsics;
        from = "given";
        if (K.sized())
            K.validate("the given intrinsics");
        else
            K.validate_unsized("the given intrinsics");
        return true;
    }
    std::error_code ec;
    if (!fs::exists(pcd, ec)) return false;  // anything there: read_pcd_frame refuses a non-file
    K = read_pcd_frame(pcd.string()).intrinsics;
    from = "recovered from " + pcd.string();
    return true;
}

fs::path normalized(const fs::path& p) {
    fs::path n = fs::absolute(p).lexically_normal();
    if (n.filename().empty() && n.has_parent_path() && n != n.root_path()) n = n.parent_path();
    return n;
}

}  // namespace detail

namespace {

using detail::check_index;
using detail::clear_colour;
using detail::is_dir;
using detail::is_file;
using detail::present;
using detail::normalized;
using detail::open_tum;

constexpr const char* kNoFramesHint =
    "expected depth.png in the folder or in its sub-folders, or rgb.txt and depth.txt of a "
    "TUM RGB-D sequence";

/// Anything at `p`: a file a reader then opens, or refuses by its type with a clear message
/// (a FIFO named depth.png is an error, not a folder without frames).
bool something_at(const fs::path& p) {
    std::error_code ec;
    return fs::exists(p, ec);
}


// ---- frame folders --------------------------------------------------------------------

struct FrameDirs {
    std::vector<fs::path> dirs;
    std::vector<std::string> names;
    bool single = false;  ///< `root` itself is the one frame folder
};

/// A folder looks like a frame folder (and so must hold depth.png) when it holds any of
/// the files of one.
bool looks_like_frame(const fs::path& dir) {
    return is_file(dir / "color.png") || is_file(dir / "intrinsics.json") ||
           is_file(dir / "label.png");
}

FrameDirs find_frame_dirs(const std::string& path, const fs::path& root) {
    FrameDirs found;
    if (something_at(root / "depth.png")) {
        found.single = true;
        found.dirs.push_back(root);
        found.names.push_back(normalized(root).filename().string());
        return found;
    }
    std::vector<fs::path> subs;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(root, ec)) {
        if (!is_dir(entry.path())) continue;
        if (something_at(entry.path() / "depth.png")) {
            subs.push_back(entry.path());
        } else if (looks_like_frame(entry.path())) {
            throw InputError(entry.path().string() + ": frame folder has no depth.png");
        }
    }
    if (ec) throw InputError(path + ": cannot list the folder (" + ec.message() + ")");
    if (subs.empty()) {
        if (looks_like_frame(root)) throw InputError(path + ": frame folder has no depth.png");
        throw InputError(path + ": no frames found (" + kNoFramesHint + ")");
    }
    std::sort(subs.begin(), subs.end(), [](const fs::path& a, const fs::path& b) {
        return a.filename().string() < b.filename().string();
    });
    for (const auto& s : subs) {
        found.dirs.push_back(s);
        found.names.push_back(s.filename().string());
    }
    return found;
}

/// A frame folder's colour of w x h against its depth: from the colour's header, before
/// its pixels are allocated.
void check_colour_size(const fs::path& dir, int w, int h, int depth_w, int depth_h) {
    if (w != depth_w || h != depth_h) {
        throw InputError(dir.string() + ": color.png is " + size_str(w, h) +
                         " but depth.png is " + size_str(depth_w, depth_h) +
                         "; give a calibration (--calibration) for unregistered input");
    }
}

/// Thrown by a header check to stop a read before its pixels; never leaves read().
struct StopBeforePixels {};

/// Registered frame folders: depth.png, intrinsics.json and optional color.png per frame.
class FramesSource final : public FrameSource {
public:
    FramesSource(FrameDirs dirs, std::optional<PinholeIntrinsics> intrinsics)
        : dirs_(std::move(dirs)), intrinsics_(std::move(intrinsics)) {}

    std::size_t size() const override { return dirs_.dirs.size(); }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return dirs_.names[i];
    }
    InputFormat format() const override { return InputFormat::Frames; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<FramesSource>(*this); }

    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        const fs::path& dir = dirs_.dirs[i];
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.name = dirs_.names[i];

        // Colour and depth first: a size mismatch is most likely unregistered input, and
        // then the hint matters more than a missing intrinsics.json. Sizes come from the
        // headers, before any pixel is allocated: a depth.png the intrinsics contradict is
        // refused without decoding it (a 32768 x 32768 one took 2.1 GB and 11 s), after
        // the colour's header has had its say.
        const fs::path intr = dir / "intrinsics.json";
        const fs::path color = dir / "color.png";
        std::optional<IntrinsicsFile> intr_file;  // read ahead, once, when it reads
        std::optional<PinholeIntrinsics> known;   // the size the frame must have, if known
        const char* intr_from = "intrinsics.json";
        if (intrinsics_) {
            if (intrinsics_->width != 0 || intrinsics_->height != 0) known = *intrinsics_;
            intr_from = "the given intrinsics";
        } else if (present(intr)) {
            try {
                intr_file = read_intrinsics_json(intr.string());
                known = intr_file->intrinsics;
            } catch (const std::exception&) {
                // Said below, where it always was, once the images are read.
            }
        }
        std::optional<std::pair<int, int>> contradicted;  // the depth's size, if not known's
        try {
            detail::read_depth_png_into((dir / "depth.png").string(), 0.001f, depth_scratch_,
                                        f.depth, [&](int w, int h) {
                                            if (!known || known->same_size(w, h)) return;
                                            contradicted.emplace(w, h);
                                            throw StopBeforePixels{};
                                        });
        } catch (const StopBeforePixels&) {
        }
        if (contradicted) {
            const int w = contradicted->first, h = contradicted->second;  // clang 14: no captured bindings
            if (present(color)) {
                try {
                    detail::read_color_image_into(color.string(), color_scratch_, f.color,
                                                  [&](int cw, int ch) {
                                                      check_colour_size(dir, cw, ch, w, h);
                                                      throw StopBeforePixels{};
                                                  });
                } catch (const StopBeforePixels&) {
                }
            }
            throw InputError(dir.string() + ": depth.png is " + size_str(w, h) + " but " +
                             intr_from + " says " + size_str(known->width, known->height));
        }
        if (present(color)) {
            detail::read_color_image_into(color.string(), color_scratch_, f.color, [&](int w, int h) {
                check_colour_size(dir, w, h, f.depth.width, f.depth.height);
            });
        } else {
            clear_colour(f.color);
        }

        if (intrinsics_) {
            // The override replaces the camera; the file, if present, still gives the units.
            f.intrinsics = *intrinsics_;
            if (f.intrinsics.width == 0 && f.intrinsics.height == 0) {
                f.intrinsics.width = f.depth.width;  // no size given: the frame's own
                f.intrinsics.height = f.depth.height;
            }
            f.intrinsics.validate(dir.string() + ": the given intrinsics");
            if (present(intr)) {
                f.depth.scale_m_per_unit = read_intrinsics_json(intr.string()).depth_scale_m_per_unit;
            }
        } else {
            const IntrinsicsFile file = intr_file ? *intr_file : read_intrinsics_json(intr.string());
            f.intrinsics = file.intrinsics;
            f.depth.scale_m_per_unit = file.depth_scale_m_per_unit;
        }
        if (!f.intrinsics.same_size(f.depth.width, f.depth.height)) {
            throw InputError(dir.string() + ": depth.png is " +
                             size_str(f.depth.width, f.depth.height) + " but " + intr_from +
                             " says " + size_str(f.intrinsics.width, f.intrinsics.height));
        }
    }

private:
    FrameDirs dirs_;
    std::optional<PinholeIntrinsics> intrinsics_;
    // One scratch per image kind: a shared one would be re-allocated at every type change.
    detail::ImageScratch depth_scratch_, color_scratch_;
};

/// Frame folders of a two-camera sensor: colour and depth at their own resolutions,
/// one StereoCalibration for the whole sequence. Items are raw; the pipeline registers them.
class UnregisteredSource final : public FrameSource {
public:
    UnregisteredSource(FrameDirs dirs, StereoCalibration calib)
        : dirs_(std::move(dirs)), calib_(calib) {}

    std::size_t size() const override { return dirs_.dirs.size(); }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return dirs_.names[i];
    }
    InputFormat format() const override { return InputFormat::Unregistered; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<UnregisteredSource>(*this); }
    const StereoCalibration* calibration() const override { return &calib_; }

    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        const fs::path& dir = dirs_.dirs[i];
        item.is_raw = true;
        RawRgbdFrame& raw = item.raw;
        raw.name = dirs_.names[i];
        // Each size against the calibration's from the header, before the pixels.
        detail::read_depth_png_into(
            (dir / "depth.png").string(), calib_.depth_scale_m_per_unit, depth_scratch_, raw.depth,
            [&](int w, int h) {
                if (!calib_.depth.same_size(w, h))
                    throw InputError(dir.string() + ": depth.png is " + size_str(w, h) +
                                     " but the calibration's depth camera is " +
                                     size_str(calib_.depth.width, calib_.depth.height));
            });
        const fs::path color = dir / "color.png";
        if (present(color)) {
            detail::read_color_image_into(color.string(), color_scratch_, raw.color, [&](int w, int h) {
                if (!calib_.color.same_size(w, h))
                    throw InputError(dir.string() + ": color.png is " + size_str(w, h) +
                                     " but the calibration's colour camera is " +
                                     size_str(calib_.color.width, calib_.color.height));
            });
        } else {
            clear_colour(raw.color);
        }
    }

private:
    FrameDirs dirs_;
    StereoCalibration calib_;
    // One scratch per image kind: a shared one would be re-allocated at every type change.
    detail::ImageScratch depth_scratch_, color_scratch_;
};

// ---- OCID sequences and PCD files --------------------------------------------------------

/// The depth/result_*.png of an OCID sequence folder, sorted by name; empty if not one.
std::vector<fs::path> ocid_depth_files(const fs::path& seq) {
    std::vector<fs::path> files;
    if (!is_dir(seq / "rgb") || !is_dir(seq / "depth")) return files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(seq / "depth", ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("result_", 0) == 0 && e.path().extension() == ".png") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

/// The first OCID sequence folder under `root` (at most four levels down:
/// ARID20/table/top/seq01), or empty.
fs::path find_ocid_sequence(const fs::path& root, int levels) {
    if (levels < 0) return {};
    std::vector<fs::path> subs;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(root, ec))
        if (is_dir(e.path())) subs.push_back(e.path());
    std::sort(subs.begin(), subs.end());
    for (const fs::path& s : subs) {
        if (!ocid_depth_files(s).empty()) return s;
        fs::path deeper = find_ocid_sequence(s, levels - 1);
        if (!deeper.empty()) return deeper;
    }
    return {};
}

/// One OCID sequence: depth/result_*.png (mm), rgb/ of the same names, intrinsics from
/// pcd/<first frame>.pcd or given.
class OcidSource final : public FrameSource {
public:
    OcidSource(fs::path seq, std::vector<fs::path> depth, PinholeIntrinsics K, std::string from)
        : seq_(std::move(seq)), depth_(std::move(depth)), K_(K), from_(std::move(from)) {}

    std::size_t size() const override { return depth_.size(); }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return depth_[i].stem().string();
    }
    InputFormat format() const override { return InputFormat::Ocid; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<OcidSource>(*this); }

    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.name = name(i);
        detail::read_mm_depth_with_intrinsics(depth_[i].string(), K_, from_, depth_scratch_, f);
        const fs::path color = seq_ / "rgb" / depth_[i].filename();
        if (present(color)) {
            detail::read_color_image_into(color.string(), color_scratch_, f.color, [&](int w, int h) {
                check_colour_size(seq_, w, h, f.depth.width, f.depth.height);
            });
        } else {
            clear_colour(f.color);
        }
    }

private:
    fs::path seq_;
    std::vector<fs::path> depth_;
    PinholeIntrinsics K_;
    std::string from_;
    detail::ImageScratch depth_scratch_, color_scratch_;
};

std::unique_ptr<FrameSource> open_ocid(const std::string& path, const fs::path& seq,
                                       std::vector<fs::path> depth, const SourceOptions& options) {
    if (!options.calibration.empty())
        throw ParamError("a calibration is for unregistered input, but " + path +
                         " is read as an OCID sequence (registered)");
    PinholeIntrinsics K;
    std::string from;
    const fs::path pcd = seq / "pcd" / (depth.front().stem().string() + ".pcd");
    if (!detail::given_or_pcd_intrinsics(options, pcd, K, from))
        throw InputError(path + ": an OCID sequence without " + pcd.string() +
                         " to recover the intrinsics from; give them (--intrinsics)");
    return std::make_unique<OcidSource>(seq, std::move(depth), K, from);
}

/// One organized PCD file as a one-frame sequence.
class PcdSource final : public FrameSource {
public:
    PcdSource(fs::path file, std::optional<PinholeIntrinsics> K)
        : file_(std::move(file)), K_(std::move(K)) {}
    std::size_t size() const override { return 1; }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return file_.stem().string();
    }
    InputFormat format() const override { return InputFormat::Pcd; }
    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        item.is_raw = false;
        item.frame = read_pcd_frame(file_.string());
        item.frame.name = name(i);
        if (K_) {
            PinholeIntrinsics K = *K_;
            if (!K.sized()) K.width = item.frame.depth.width, K.height = item.frame.depth.height;
            K.validate(file_.string() + ": the given intrinsics");
            if (!K.same_size(item.frame.depth.width, item.frame.depth.height))
                throw InputError(file_.string() + ": the PCD is " +
                                 size_str(item.frame.depth.width, item.frame.depth.height) +
                                 " but the given intrinsics are " + size_str(K.width, K.height));
            item.frame.intrinsics = K;
        }
    }

private:
    fs::path file_;
    std::optional<PinholeIntrinsics> K_;
};

bool is_pcd_path(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext == ".pcd" && is_file(p);
}

// ---- calibration ------------------------------------------------------------------------

/// Where calibration.json is looked for: the input folder, then its parent (beside a
/// single frame folder, or above a sequence).
std::optional<fs::path> find_calibration_file(const fs::path& root) {
    const fs::path here = root / "calibration.json";
    if (something_at(here)) return here;
    const fs::path parent = normalized(root).parent_path() / "calibration.json";
    if (something_at(parent)) return parent;
    return std::nullopt;
}

}  // namespace

const char* input_format_name(InputFormat f) {
    switch (f) {
        case InputFormat::Auto: return "auto";
        case InputFormat::Frames: return "frames";
        case InputFormat::Tum: return "tum";
        case InputFormat::Unregistered: return "unregistered";
        case InputFormat::Bag: return "bag";
        case InputFormat::Ocid: return "ocid";
        case InputFormat::Pcd: return "pcd";
        case InputFormat::Osd: return "osd";
        case InputFormat::Bop: return "bop";
    }
    return "?";
}

InputFormat parse_input_format(const std::string& name) {
    if (name == "auto") return InputFormat::Auto;
    if (name == "frames") return InputFormat::Frames;
    if (name == "tum") return InputFormat::Tum;
    if (name == "unregistered") return InputFormat::Unregistered;
    if (name == "bag") return InputFormat::Bag;
    if (name == "ocid") return InputFormat::Ocid;
    if (name == "pcd") return InputFormat::Pcd;
    if (name == "osd") return InputFormat::Osd;
    if (name == "bop") return InputFormat::Bop;
    throw ParamError("unknown input format '" + name +
                     "' (known: auto, frames, tum, unregistered, bag, ocid, pcd, osd, bop)");
}

bool is_bag_file(const std::string& path) {
    if (!is_file(path)) return false;  // a FIFO is never opened here
    static constexpr char kMagic[] = "#ROSBAG V2.0";
    char head[sizeof kMagic - 1] = {};
    std::ifstream in(path, std::ios::binary);
    return in.read(head, sizeof head) && std::memcmp(head, kMagic, sizeof head) == 0;
}

namespace {

/// A format that one file or one folder's layout says (a bag, a PCD, an OCID sequence, an
/// OSD tree, a BOP scene, a TUM sequence), or the one `options.format` names; nullptr when
/// none applies and the input is read as frame folders.
std::unique_ptr<FrameSource> open_recording(const std::string& path, const fs::path& root,
                                            const fs::file_status& status,
                                            const SourceOptions& options) {
    const InputFormat f = options.format;
    const bool any = f == InputFormat::Auto;
    if (f == InputFormat::Bag || (any && is_bag_file(path))) return open_bag(path, options);
    if (!options.bag_topics.empty())
        throw ParamError("topics are for ROS bags, but " + path + " is no bag");
    const auto registered = [&](const char* what) {
        if (!options.calibration.empty())
            throw ParamError("a calibration is for unregistered input, but " + path +
                             " is read as " + what + " (registered)");
    };
    if (f == InputFormat::Pcd || (any && is_pcd_path(root))) {
        registered("a PCD");
        return std::make_unique<PcdSource>(root, options.intrinsics);
    }
    if (!fs::is_directory(status)) throw InputError(path + ": not a folder (" + kNoFramesHint + ")");
    if (f == InputFormat::Ocid || any) {
        std::vector<fs::path> depth = ocid_depth_files(root);
        if (!depth.empty()) return open_ocid(path, root, std::move(depth), options);
        if (f == InputFormat::Ocid)
            throw InputError(path + ": not an OCID sequence (expected rgb/ and depth/ holding "
                                    "result_*.png)");
    }
    if (f == InputFormat::Osd || (any && detail::is_osd_tree(root)))
        return detail::open_osd(path, root, options);
    if (f == InputFormat::Bop || (any && detail::is_bop_scene(root)))
        return detail::open_bop(path, root, options);
    if (f == InputFormat::Tum ||
        (any && something_at(root / "rgb.txt") && something_at(root / "depth.txt"))) {
        registered("TUM RGB-D");
        return open_tum(path, root, options);
    }
    return nullptr;
}

/// The frame folders at `root`; a folder without any that holds OCID sequences or BOP
/// scenes further down gets a line that names one (one sequence at a time).
FrameDirs frame_dirs_or_hint(const std::string& path, const fs::path& root) {
    try {
        return find_frame_dirs(path, root);
    } catch (const InputError&) {
        const fs::path seq = find_ocid_sequence(root, 4);
        if (!seq.empty())
            throw InputError(path + ": an OCID tree; give one sequence folder (one with rgb/ "
                                    "and depth/, e.g. " + seq.string() + ")");
        const fs::path scene = detail::find_bop_scene(root, 2);
        if (!scene.empty())
            throw InputError(path + ": holds BOP scenes; give one scene folder (e.g. " +
                             scene.string() + "), or run them all with python3 -m wul3d.batch");
        throw;
    }
}

/// Unregistered frame folders' calibration: the one given (a file, or kinect_v2), else the
/// calibration.json found beside the frames.
StereoCalibration unregistered_calibration(const std::string& path, const SourceOptions& options,
                                           const std::optional<fs::path>& found) {
    if (options.intrinsics)
        throw ParamError("intrinsics cannot be given for unregistered input: the calibration "
                         "holds both cameras");
    if (options.calibration == "kinect_v2") return kinect_v2_default_calibration();
    if (!options.calibration.empty()) return read_calibration_json(options.calibration);
    if (found) return read_calibration_json(found->string());
    throw InputError(path + ": unregistered input needs a calibration: give a calibration "
                            "JSON file or 'kinect_v2' (--calibration), or put "
                            "calibration.json beside the frames");
}

}  // namespace

std::unique_ptr<FrameSource> open_source(const std::string& path, const SourceOptions& options) {
    const fs::path root(path);
    std::error_code ec;
    const auto status = fs::status(root, ec);
    if (!fs::exists(status)) throw InputError(path + ": no such file or directory");
    if (auto source = open_recording(path, root, status, options)) return source;

    FrameDirs dirs = frame_dirs_or_hint(path, root);
    // "Beside the frames": in the folder of a sequence's frame folders; for a single frame
    // folder, in it or in its parent.
    InputFormat format = options.format;
    std::optional<fs::path> calib_file;
    if (options.calibration.empty() && format != InputFormat::Frames) {
        if (format == InputFormat::Unregistered || dirs.single) {
            calib_file = find_calibration_file(root);
        } else if (something_at(root / "calibration.json")) {
            calib_file = root / "calibration.json";
        }
    }
    if (format == InputFormat::Auto) {
        format = (!options.calibration.empty() || calib_file) ? InputFormat::Unregistered
                                                              : InputFormat::Frames;
    }
    if (format == InputFormat::Frames) {
        if (!options.calibration.empty()) {
            throw ParamError("a calibration is for unregistered input, but " + path +
                             " is read as '" + input_format_name(format) + "'");
        }
        return std::make_unique<FramesSource>(std::move(dirs), options.intrinsics);
    }
    return std::make_unique<UnregisteredSource>(
        std::move(dirs), unregistered_calibration(path, options, calib_file));
}

}  // namespace wul3d
