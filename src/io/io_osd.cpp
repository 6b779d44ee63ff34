// OSD-0.2-depth trees as downloaded (docs/INPUTS.md, section 6): image_color/NAME.png,
// disparity/NAME.png (16-bit depth in millimetres, despite the folder's name),
// annotation/NAME.png (labels, read by `wul3d eval`) and pcd/NAME.pcd (organized clouds,
// which give the intrinsics).
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io_detail.hpp"
#include "wul3d/camera.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d::detail {

namespace fs = std::filesystem;

namespace {

/// OSD's frames: disparity/NAME.png beside image_color/NAME.png, sorted by name.
struct OsdFrames {
    std::vector<fs::path> depth, color;
};

/// Pairs disparity/ and image_color/ by name; a file on either side without its partner is
/// one error line naming it (a half-copied tree, not a tree to read in part).
OsdFrames pair_osd_frames(const std::string& path, const fs::path& root) {
    OsdFrames f;
    f.depth = list_pngs(root / "disparity");
    f.color = list_pngs(root / "image_color");
    if (f.depth.empty()) throw InputError(path + ": no frames found (disparity/ holds no .png)");
    const std::size_t n = std::max(f.depth.size(), f.color.size());
    for (std::size_t i = 0; i < n; ++i) {
        const bool has_depth = i < f.depth.size(), has_color = i < f.color.size();
        if (has_depth && has_color && f.depth[i].filename() == f.color[i].filename()) continue;
        // The first name in order without its partner.
        const bool depth_first =
            has_depth && (!has_color || f.depth[i].filename() < f.color[i].filename());
        const fs::path& lone = depth_first ? f.depth[i] : f.color[i];
        throw InputError(path + ": " + (depth_first ? "disparity/" : "image_color/") +
                         lone.filename().string() + " has no " +
                         (depth_first ? "image_color/" : "disparity/") + lone.filename().string() +
                         " (an OSD tree pairs them by name)");
    }
    return f;
}

/// An OSD-0.2-depth tree: every frame 16-bit millimetres and 8-bit colour, one camera.
class OsdSource final : public FrameSource {
public:
    OsdSource(OsdFrames frames, PinholeIntrinsics K, std::string from)
        : frames_(std::move(frames)), K_(K), from_(std::move(from)) {}

    std::size_t size() const override { return frames_.depth.size(); }
    std::string name(std::size_t i) const override {
        check_index(i, size());
        return frames_.depth[i].stem().string();
    }
    InputFormat format() const override { return InputFormat::Osd; }
    std::unique_ptr<FrameSource> clone() const override { return std::make_unique<OsdSource>(*this); }

    void read(std::size_t i, SourceItem& item) override {
        check_index(i, size());
        item.is_raw = false;
        RgbdFrame& f = item.frame;
        f.name = name(i);
        read_mm_depth_with_intrinsics(frames_.depth[i].string(), K_, from_, depth_scratch_, f);
        const std::string color = frames_.color[i].string();
        read_color_image_into(color, color_scratch_, f.color, [&](int w, int h) {
            check_same_size(color, w, h, f.depth.width, f.depth.height);
        });
    }

private:
    OsdFrames frames_;
    PinholeIntrinsics K_;
    std::string from_;
    ImageScratch depth_scratch_, color_scratch_;
};

}  // namespace

bool is_osd_tree(const fs::path& root) { return is_dir(root / "image_color"); }

std::unique_ptr<FrameSource> open_osd(const std::string& path, const fs::path& root,
                                      const SourceOptions& options) {
    if (!options.calibration.empty())
        throw ParamError("a calibration is for unregistered input, but " + path +
                         " is read as an OSD tree (registered)");
    if (!is_osd_tree(root))
        throw InputError(path + ": not an OSD tree (expected image_color/ and disparity/)");
    if (!is_dir(root / "disparity"))
        throw InputError(path + ": an OSD tree without disparity/ (its depth: 16-bit PNGs in "
                                "millimetres, named as in image_color/)");
    OsdFrames frames = pair_osd_frames(path, root);

    // The intrinsics: given; else fitted to the first frame's organized cloud, as for OCID;
    // else the Kinect v1 defaults OSD's clouds were made with (fx = fy = 525).
    PinholeIntrinsics K;
    std::string from;
    const fs::path pcd = root / "pcd" / (frames.depth.front().stem().string() + ".pcd");
    if (!given_or_pcd_intrinsics(options, pcd, K, from)) {
        K = intrinsics_preset("kinect_v1");
        from = "Kinect v1 defaults, no " + pcd.string();
    }
    return std::make_unique<OsdSource>(std::move(frames), K, std::move(from));
}

}  // namespace wul3d::detail
