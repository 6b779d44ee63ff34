#pragma once
// Private to the library: image readers and writers that reuse the caller's buffers, so that
// a FrameSource allocates nothing per frame once the first frame has been read, and a writer
// thread nothing once it has written its first frame.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "wul3d/clustering.hpp"
#include "wul3d/frame.hpp"

struct libdeflate_decompressor;

namespace wul3d {
class FrameSource;
struct SourceOptions;
}  // namespace wul3d

namespace wul3d::detail {

/// Scratch of the image readers. The pixels are decoded straight into the image read, so
/// no decoded copy of the image is kept here.
struct ImageScratch {
    std::vector<unsigned char> bytes;
    std::vector<unsigned char> cleaned;  ///< PNG without ancillary chunks, when it had any
    std::vector<unsigned char*> rows;    ///< where each image row goes, for libpng / libjpeg
    std::vector<unsigned char> pixels;   ///< 8-bit labels before widening; a CMYK JPEG row
    /// decode_png_rows' (png_rows.hpp): the IDAT chunks joined (a file of several), the
    /// inflated rows with their filter bytes, and libdeflate's decompressor, made on first
    /// use. A copy of the scratch makes its own.
    std::vector<unsigned char> idat, inflated;
    struct Inflater {
        Inflater() = default;
        Inflater(const Inflater&) {}
        Inflater& operator=(const Inflater&) { return *this; }
        ~Inflater();
        libdeflate_decompressor* get();  ///< nullptr when out of memory

    private:
        libdeflate_decompressor* d_ = nullptr;
    } inflater;
};

/// The whole of the regular file `path` into `bytes` (capacity reused). InputError naming the
/// file if it is missing, not a regular file (a FIFO, device or folder is refused by its type
/// before it is opened), larger than `max_bytes`, or unreadable.
void read_regular_file(const std::string& path, std::uint64_t max_bytes,
                       std::vector<unsigned char>& bytes);

/// Called with an image's width and height from its header, before its pixels are
/// allocated: throws to refuse a size the caller already knows is wrong (a 32768 x 32768
/// depth.png beside a 640 x 480 intrinsics.json is refused without its 2 GB).
using HeaderCheck = std::function<void(int width, int height)>;

/// As read_depth_png / read_color_image / read_label_png, into `out` (buffers reused);
/// `check`, if given, sees the header's size first.
void read_depth_png_into(const std::string& path, float scale_m_per_unit, ImageScratch& scratch,
                         DepthImage& out, const HeaderCheck& check = {});
void read_color_image_into(const std::string& path, ImageScratch& scratch, ColorImage& out,
                           const HeaderCheck& check = {});
/// As read_color_image_into, of the PNG or JPEG already in `scratch.bytes` (a bag's
/// CompressedImage); `what` names it in errors.
void decode_color_image_into(const std::string& what, ImageScratch& scratch, ColorImage& out);
void read_label_png_into(const std::string& path, ImageScratch& scratch, LabelImage& out);

class PngEncoder;  // png_encode.hpp
/// write_label_png, write_color_png and write_mask_png (io.hpp) through the encoder the
/// writer keeps.
void write_label_png(const std::string& path, const LabelImage& labels, PngEncoder& encoder);
void write_color_png(const std::string& path, const ColorImage& image, PngEncoder& encoder);
void write_mask_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& mask,
                    PngEncoder& encoder);

/// "WxH".
inline std::string size_str(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

/// A number for a message, short whatever its size ("1e+300", "1e-300", "0.001"), where
/// std::to_string prints 300 digits or "0.000000".
inline std::string number_str(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

// ---- shared by the sequence readers (io_sources.cpp, io_osd.cpp, io_bop.cpp) -------------

bool is_file(const std::filesystem::path& p);  ///< a regular file (links followed)
bool is_dir(const std::filesystem::path& p);
/// Whether the optional file `p` is there. Something there that is not a regular file (a
/// FIFO, a device, a folder) is an error, not an absent file.
bool present(const std::filesystem::path& p);
/// InputError "`dir`: colour is WxH but depth is WxH" unless the sizes agree.
void check_same_size(const std::string& what, int w, int h, int depth_w, int depth_h);
void clear_colour(ColorImage& c);  ///< no colour, capacity kept
/// std::out_of_range unless i < n.
void check_index(std::size_t i, std::size_t n);
/// The PNG files of `dir` by stem, sorted; InputError if it cannot be listed.
std::vector<std::filesystem::path> list_pngs(const std::filesystem::path& dir);

/// A frame's 16-bit millimetre depth at `path` into `f.depth`, and `K` as its intrinsics:
/// InputError when sized intrinsics differ from the depth's size (`from` says where they
/// came from); unsized ones take the depth's size and are checked then.
void read_mm_depth_with_intrinsics(const std::string& path, const PinholeIntrinsics& K,
                                   const std::string& from, ImageScratch& scratch, RgbdFrame& f);

/// A registered sequence's intrinsics when the caller gave them (checked; `from` =
/// "given") or an organized PCD at `pcd` holds them (fitted to its points, as read_pcd_frame
/// does; `from` names the file); false when neither, for the caller's own fallback.
bool given_or_pcd_intrinsics(const SourceOptions& options, const std::filesystem::path& pcd,
                             PinholeIntrinsics& K, std::string& from);

/// `p` made absolute and without a trailing separator, so that filename() and
/// parent_path() mean the folder itself and its parent even for "." or "seq/".
std::filesystem::path normalized(const std::filesystem::path& p);

/// TUM RGB-D (io_tum.cpp): a folder holding rgb.txt and depth.txt.
std::unique_ptr<FrameSource> open_tum(const std::string& path, const std::filesystem::path& root,
                                      const SourceOptions& options);

/// OSD-0.2-depth (io_osd.cpp): a folder holding image_color/.
bool is_osd_tree(const std::filesystem::path& root);
std::unique_ptr<FrameSource> open_osd(const std::string& path, const std::filesystem::path& root,
                                      const SourceOptions& options);

/// BOP (io_bop.cpp): a scene folder (scene_camera.json, or depth/ beside rgb/ or gray/ and
/// BOP's ground truth).
bool is_bop_scene(const std::filesystem::path& dir);
std::unique_ptr<FrameSource> open_bop(const std::string& path, const std::filesystem::path& scene,
                                      const SourceOptions& options);
/// The first BOP scene at most `levels` folders below `root` (a split folder holds scenes,
/// a dataset folder splits), or empty.
std::filesystem::path find_bop_scene(const std::filesystem::path& root, int levels);

}  // namespace wul3d::detail
