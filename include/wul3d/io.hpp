#pragma once
/// @file io.hpp
/// Reading RGB-D recordings and writing outputs. Readers check everything a user can get
/// wrong (missing file, truncated PNG, bit depth, sizes) and throw InputError with the path;
/// writers write to a temporary name and rename, so no output is ever half-written.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wul3d/cloud.hpp"
#include "wul3d/frame.hpp"
#include "wul3d/image.hpp"
#include "wul3d/calibration.hpp"

namespace wul3d {

// ---- limits -------------------------------------------------------------------------
// Every reader opens regular files only (a FIFO, device or folder is refused by its type
// before it is opened, so nothing blocks), checks a file's size before reading it, and an
// image's size from its header before decoding it: no input can make wul3d allocate more
// than these limits allow (docs/INPUTS.md, "Limits").

/// The default largest image, width x height: 2^24 pixels (4096 x 4096, 5472 x 3072).
inline constexpr std::uint64_t kDefaultMaxImagePixels = std::uint64_t{1} << 24;
/// The most set_max_image_pixels accepts (and the old fixed limit): 2^30 pixels.
inline constexpr std::uint64_t kMaxImagePixelsCeiling = std::uint64_t{1} << 30;
/// The longest side of an image, in pixels.
inline constexpr std::uint64_t kMaxImageSide = std::uint64_t{1} << 16;
/// The largest JSON file read (intrinsics.json, a calibration): 1 MiB.
inline constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{1} << 20;
/// The largest TUM list (rgb.txt, depth.txt): 256 MiB, some 6 million frames.
inline constexpr std::uint64_t kMaxListBytes = std::uint64_t{1} << 28;

/// Sets the largest image the readers decode, process-wide (the CLI's --max-pixels).
/// ParamError outside [1, kMaxImagePixelsCeiling].
void set_max_image_pixels(std::uint64_t pixels);
std::uint64_t max_image_pixels();
/// The largest image file read: 64 MiB plus 8 bytes per pixel of the image limit (a PNG
/// stored without compression is at most about 6 bytes per 16-bit RGB pixel).
std::uint64_t max_image_file_bytes();

// ---- single files -------------------------------------------------------------------

/// A 16-bit single-channel PNG. Throws InputError if missing, unreadable, truncated or not
/// 16-bit (an 8-bit depth image is rejected: its units cannot be known).
DepthImage read_depth_png(const std::string& path, float scale_m_per_unit);
/// An 8-bit PNG or JPEG, colour (converted to RGB) or grey (expanded to RGB).
ColorImage read_color_image(const std::string& path);
/// A 16-bit single-channel PNG of labels (ground truth or our own labels.png).
LabelImage read_label_png(const std::string& path);

/// `intrinsics.json`: {"fx","fy","cx","cy","width","height","depth_scale_m_per_unit"}.
struct IntrinsicsFile {
    PinholeIntrinsics intrinsics;
    float depth_scale_m_per_unit = 0.001f;
};
IntrinsicsFile read_intrinsics_json(const std::string& path);

/// Calibration JSON of an unregistered sensor (format in docs/INPUTS.md):
/// {"depth": {intrinsics}, "color": {intrinsics},
///  "depth_to_color": {"rotation": [9, row-major], "translation_m": [3]},
///  "depth_scale_m_per_unit": 0.001}
StereoCalibration read_calibration_json(const std::string& path);
void write_calibration_json(const std::string& path, const StereoCalibration& calib);

/// An organized PCD file (PCL's format, v0.7; DATA ascii, binary or binary_compressed) as
/// a frame: fields x y z (float, metres) and optionally rgb or rgba (packed, 4 bytes); other
/// fields are skipped. HEIGHT must be > 1. Depth is z in millimetres (NaN or out of range
/// -> 0, depth_scale 0.001), colour from rgb (none without it), and the intrinsics are
/// recovered from the points (least squares of u = fx x/z + cx, v = fy y/z + cy). InputError
/// with one line for a header that lies about the data's size, an unorganized cloud, too
/// few valid points (kPcdMinFitPoints) or a fit whose RMS residual exceeds kPcdMaxFitRmsPx.
inline constexpr int kPcdMinFitPoints = 100;
inline constexpr double kPcdMaxFitRmsPx = 0.5;
/// The largest PCD header read, bytes.
inline constexpr std::uint64_t kMaxPcdHeaderBytes = std::uint64_t{1} << 16;
RgbdFrame read_pcd_frame(const std::string& path);
/// As read_pcd_frame, of a PCD already in memory; `what` names it in errors.
RgbdFrame parse_pcd_frame(const std::string& what, const unsigned char* data, std::size_t size);
enum class PcdData { Ascii, Binary, BinaryCompressed };
/// Writes `frame` as an organized PCD (x y z [rgb]; pixels without depth are NaN points),
/// the format read_pcd_frame reads: for tests, fuzz seeds and users' tools.
void write_pcd(const std::string& path, const RgbdFrame& frame, PcdData data, bool with_rgb);

// ---- BOP ground truth ----------------------------------------------------------------

/// The largest scene_camera.json read: 64 MiB (a scene of some 100,000 images).
inline constexpr std::uint64_t kMaxBopJsonBytes = std::uint64_t{1} << 26;

/// One image of a BOP scene with ground truth: its name (the image id's file stem, as a
/// FrameSource of the scene names the frame) and its masks, mask_visib/NAME_GTID.png, by
/// gt id.
struct BopImageMasks {
    std::string name;
    std::vector<int> gt_ids;          ///< ascending
    std::vector<std::string> masks;   ///< the files, in the order of gt_ids
};
/// The images of the BOP scene folder `scene` that have masks in mask_visib/, sorted by
/// name. InputError if mask_visib/ is missing or holds no IMID_GTID.png.
std::vector<BopImageMasks> list_bop_masks(const std::string& scene);
/// The masks of one image combined into an instance label image: the mask of gt id g
/// (8 or 16-bit, non-zero inside) is label g + 1, 0 elsewhere; where masks overlap, the
/// lowest gt id wins. InputError for masks of different sizes, or a gt id over 65534.
LabelImage combine_bop_masks(const BopImageMasks& image);

// ---- outputs (atomic: temporary name, then rename) ------------------------------------

void write_label_png(const std::string& path, const LabelImage& labels);      ///< 16-bit
void write_color_png(const std::string& path, const ColorImage& image);       ///< 8-bit RGB
void write_mask_png(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& mask);                   ///< 8-bit
void write_depth_png(const std::string& path, const DepthImage& depth);       ///< 16-bit
/// Binary little-endian PLY of the labelled points: x y z (float, metres), red green blue
/// (uchar, the eq. 9 display colour), label (ushort).
void write_ply(const std::string& path, const OrganizedCloud& cloud, const LabelImage& labels,
               const ColorImage& colors);
/// `intrinsics.json` (the format read_intrinsics_json reads), doubles written exactly.
void write_intrinsics_json(const std::string& path, const PinholeIntrinsics& intrinsics,
                           float depth_scale_m_per_unit);
/// One frame folder that `open_source` reads back as the same frame: DIR/depth.png,
/// DIR/intrinsics.json, DIR/color.png (if the frame has colour). Written as DIR.partial,
/// then renamed, so the folder is complete or absent.
void write_frame_folder(const std::string& dir, const RgbdFrame& frame);
/// Writes text (JSON) atomically.
void write_text_file(const std::string& path, const std::string& text);

// ---- sequences ----------------------------------------------------------------------

enum class InputFormat {
    Auto,          ///< decided from the path, see open_source
    Frames,        ///< frame folders: color.png, depth.png, intrinsics.json [, label.png]
    Tum,           ///< TUM RGB-D: rgb.txt, depth.txt, rgb/, depth/
    Unregistered,  ///< frame folders with colour and depth of different sizes + calibration
    Bag,           ///< a ROS 1 bag (wul3d/bag.hpp; only where built with librosbag)
    Ocid,          ///< one OCID sequence as downloaded: rgb/, depth/ [, label/, pcd/] of result_*.png
    Pcd,           ///< one organized PCD file (read_pcd_frame)
    Osd,           ///< an OSD-0.2-depth tree: image_color/, disparity/ (mm) [, annotation/, pcd/]
    Bop,           ///< one BOP scene: scene_camera.json, rgb/ or gray/, depth/ [, mask_visib/]
};
/// auto|frames|tum|unregistered|bag|ocid|pcd|osd|bop
InputFormat parse_input_format(const std::string& name);
const char* input_format_name(InputFormat format);       ///< the inverse of parse_input_format

struct SourceOptions {
    InputFormat format = InputFormat::Auto;
    /// TUM only: intrinsics preset name (camera.hpp) or empty to pick from the folder name
    /// (freiburg1/2/3 -> tum_fr1/2/3, else kinect_v1).
    std::string tum_camera;
    /// Overrides the intrinsics of every frame (any format but Unregistered). Width and
    /// height 0 mean "each frame's own size".
    std::optional<PinholeIntrinsics> intrinsics;
    /// Unregistered only: a calibration JSON path, or "kinect_v2" for the built-in preset.
    /// Empty: `calibration.json` in the input folder (or its parent).
    std::string calibration;
    RegistrationMode registration = RegistrationMode::DepthToColor;
    double tum_max_dt_s = 0.02;  ///< TUM colour/depth association tolerance
    /// Bags only: "COLOR,DEPTH[,INFO]" topics (`run --topics`); empty = detect the layout.
    std::string bag_topics;
    double bag_max_dt_s = 0.02;  ///< bags: colour/depth pairing tolerance, seconds
};

/// One item of a sequence: either already registered (`frame`) or raw (`raw`), which the
/// pipeline registers with `calibration()`.
struct SourceItem {
    bool is_raw = false;
    RgbdFrame frame;
    RawRgbdFrame raw;
};

/// A finite, ordered sequence of frames read from disk.
class FrameSource {
public:
    virtual ~FrameSource() = default;
    virtual std::size_t size() const = 0;   ///< number of frames
    /// Reads frame i (0 <= i < size()) into `item`, reusing its buffers. Throws InputError.
    virtual void read(std::size_t i, SourceItem& item) = 0;
    virtual std::string name(std::size_t i) const = 0;  ///< frame name, for OUT/<name>/
    virtual InputFormat format() const = 0;
    /// The calibration of raw items (Unregistered only); nullptr otherwise.
    virtual const StereoCalibration* calibration() const { return nullptr; }
    /// A second reader of the same frames (the same names, the same items), independent of
    /// this one, so that two threads may each read with their own; nullptr where the source
    /// has none (a bag, one PCD file). Lists no folder again.
    virtual std::unique_ptr<FrameSource> clone() const { return nullptr; }
};

/// Opens `path`. Auto-detection: a file that starts as a ROS bag does is a bag (bag.hpp);
/// a file that starts with a PCD header is one frame (read_pcd_frame); a folder with rgb/
/// and depth/ holding result_*.png is an OCID sequence (depth in mm, intrinsics from
/// pcd/<first frame>.pcd or SourceOptions::intrinsics); a folder with image_color/ is an
/// OSD-0.2-depth tree (disparity/ in mm, intrinsics from pcd/<first frame>.pcd, else
/// Kinect v1's); a folder with scene_camera.json is a BOP scene (per-image cam_K and
/// depth_scale); a folder with rgb.txt and depth.txt is TUM; a folder
/// with depth.png is one frame; a folder whose sub-folders hold depth.png is a sequence
/// (sorted by name); either of the last two is Unregistered when a calibration is given or
/// `calibration.json` lies beside the frames, else Frames. Throws InputError for a missing
/// path or an empty sequence.
std::unique_ptr<FrameSource> open_source(const std::string& path, const SourceOptions& options);

}  // namespace wul3d
