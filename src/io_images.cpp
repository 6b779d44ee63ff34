// Single-file readers and the atomic writers of io.hpp.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io_detail.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

namespace fs = std::filesystem;
using detail::ImageScratch;
using detail::size_str;

namespace {

// ---- reading bytes --------------------------------------------------------------------

/// The whole file into `bytes` (capacity reused). InputError if missing or unreadable.
void read_file(const std::string& path, std::vector<unsigned char>& bytes) {
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (!fs::exists(status)) throw InputError(path + ": no such file");
    if (fs::is_directory(status)) throw InputError(path + ": is a folder, expected a file");
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
    const std::streamoff size = in.tellg();
    if (size < 0) throw InputError(path + ": cannot read (cannot tell its size)");
    bytes.resize(static_cast<std::size_t>(size));
    in.seekg(0);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
        throw InputError(path + ": cannot read (read error)");
    }
}

// ---- PNG integrity --------------------------------------------------------------------
// libpng reports a damaged file on stderr ("libpng error: IDAT: CRC error") before OpenCV
// gives up, and warns about harmless ancillary chunks ("iCCP: known incorrect sRGB
// profile"). So the chunk structure and every CRC are checked here first, and ancillary
// chunks (which OpenCV ignores anyway) are stripped: a bad file gives one InputError and
// nothing else on stderr.

constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

std::array<std::uint32_t, 256> make_crc_table() {
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t n = 0; n < 256; ++n) {
        std::uint32_t c = n;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
        table[n] = c;
    }
    return table;
}

/// CRC-32 of the PNG specification (ISO 3309), over [data, data + n).
std::uint32_t png_crc(const unsigned char* data, std::size_t n) {
    static const std::array<std::uint32_t, 256> table = make_crc_table();
    std::uint32_t c = 0xffffffffu;
    for (std::size_t i = 0; i < n; ++i) c = table[(c ^ data[i]) & 0xffu] ^ (c >> 8);
    return c ^ 0xffffffffu;
}

std::uint32_t be32(const unsigned char* p) {
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
           std::uint32_t{p[3]};
}

bool is_png(const std::vector<unsigned char>& b) {
    return b.size() >= kPngSignature.size() &&
           std::equal(kPngSignature.begin(), kPngSignature.end(), b.begin());
}

bool is_jpeg(const std::vector<unsigned char>& b) {
    return b.size() >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
}

/// Checks the chunk structure and CRCs of the PNG in `bytes`; returns the buffer to decode:
/// `bytes` itself, or `cleaned` (the critical chunks and tRNS only) when it had others.
const std::vector<unsigned char>& check_png(const std::string& path,
                                           const std::vector<unsigned char>& bytes,
                                           std::vector<unsigned char>& cleaned) {
    const std::size_t n = bytes.size();
    std::size_t pos = kPngSignature.size();
    bool ancillary = false, first = true;
    while (true) {
        if (pos + 12 > n) {
            throw InputError(path + ": cannot decode PNG (truncated: the file ends before its IEND chunk)");
        }
        const std::uint32_t len = be32(&bytes[pos]);
        if (len > 0x7fffffffu || pos + 12 + len > n) {
            throw InputError(path + ": cannot decode PNG (truncated or corrupt chunk at byte " +
                             std::to_string(pos) + ")");
        }
        const unsigned char* type = &bytes[pos + 4];
        const std::string name(reinterpret_cast<const char*>(type), 4);
        if (png_crc(type, 4 + std::size_t{len}) != be32(type + 4 + len)) {
            throw InputError(path + ": cannot decode PNG (CRC error in chunk at byte " +
                             std::to_string(pos) + ", the file is corrupt)");
        }
        if (first && name != "IHDR") {
            throw InputError(path + ": cannot decode PNG (first chunk is not IHDR)");
        }
        first = false;
        if (name != "IHDR" && name != "PLTE" && name != "IDAT" && name != "IEND" && name != "tRNS") {
            ancillary = true;
        }
        pos += 12 + std::size_t{len};
        if (name == "IEND") break;
    }
    if (!ancillary) return bytes;
    cleaned.assign(bytes.begin(), bytes.begin() + kPngSignature.size());
    for (std::size_t p = kPngSignature.size(); p < pos;) {
        const std::size_t chunk = 12 + std::size_t{be32(&bytes[p])};
        const std::string name(reinterpret_cast<const char*>(&bytes[p + 4]), 4);
        if (name == "IHDR" || name == "PLTE" || name == "IDAT" || name == "IEND" || name == "tRNS") {
            cleaned.insert(cleaned.end(), bytes.begin() + p, bytes.begin() + p + chunk);
        }
        p += chunk;
    }
    return cleaned;
}

/// A JPEG ends with an EOI marker (FF D9), possibly followed by a little padding.
void check_jpeg(const std::string& path, const std::vector<unsigned char>& bytes) {
    const std::size_t n = bytes.size();
    const std::size_t from = n > 1024 ? n - 1024 : 2;
    for (std::size_t i = n - 1; i > from; --i) {
        if (bytes[i - 1] == 0xff && bytes[i] == 0xd9) return;
    }
    throw InputError(path + ": cannot decode JPEG (truncated: no end-of-image marker)");
}

std::string describe(const cv::Mat& m) {
    const int depth = m.depth();
    const char* bits = depth == CV_8U || depth == CV_8S     ? "8-bit"
                       : depth == CV_16U || depth == CV_16S ? "16-bit"
                                                            : "32-bit or wider";
    return std::string(bits) + " " + std::to_string(m.channels()) + "-channel";
}

/// Reads, checks and decodes `path` into scratch.decoded. PNG only unless allow_jpeg.
void decode(const std::string& path, ImageScratch& s, bool allow_jpeg) {
    read_file(path, s.bytes);
    const std::vector<unsigned char>* buf = &s.bytes;
    if (is_png(s.bytes)) {
        buf = &check_png(path, s.bytes, s.cleaned);
    } else if (allow_jpeg && is_jpeg(s.bytes)) {
        check_jpeg(path, s.bytes);
    } else {
        throw InputError(path + (allow_jpeg ? ": cannot decode (not a PNG or JPEG file)"
                                            : ": cannot decode (not a PNG file)"));
    }
    try {
        const cv::Mat raw(1, static_cast<int>(buf->size()), CV_8U,
                          const_cast<unsigned char*>(buf->data()));
        cv::imdecode(raw, cv::IMREAD_UNCHANGED, &s.decoded);
    } catch (const cv::Exception& e) {
        throw InputError(path + ": cannot decode (" + e.err + ")");
    }
    if (s.decoded.empty()) throw InputError(path + ": cannot decode (damaged image data)");
}

// ---- writing ------------------------------------------------------------------------

std::string errno_text() { return std::strerror(errno); }

/// Writes `path` through `<path>.tmp-<pid>` and a rename, so a failure never leaves a
/// partial file under the final name. IoError names the path.
void write_file_atomic(const std::string& path, const void* data, std::size_t size) {
    const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw IoError(path + ": cannot write (" + errno_text() + ")");
    auto fail = [&](const std::string& why) {
        ::unlink(tmp.c_str());
        throw IoError(path + ": cannot write (" + why + ")");
    };
    const char* p = static_cast<const char*>(data);
    std::size_t left = size;
    while (left > 0) {
        const ssize_t n = ::write(fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const std::string why = n < 0 ? errno_text() : "short write";
            ::close(fd);
            fail(why);
        }
        p += n;
        left -= static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0) fail(errno_text());
    if (std::rename(tmp.c_str(), path.c_str()) != 0) fail(errno_text());
}

void write_png(const std::string& path, const cv::Mat& image) {
    if (image.empty()) throw IoError(path + ": cannot write an empty image");
    std::vector<unsigned char> buf;
    try {
        if (!cv::imencode(".png", image, buf)) throw IoError(path + ": cannot encode PNG");
    } catch (const cv::Exception& e) {
        throw IoError(path + ": cannot encode PNG (" + e.err + ")");
    }
    write_file_atomic(path, buf.data(), buf.size());
}

void check_buffer(const std::string& path, const char* what, int w, int h, std::size_t have,
                  std::size_t per_pixel) {
    if (w <= 0 || h <= 0 || have != static_cast<std::size_t>(w) * h * per_pixel) {
        throw IoError(path + ": cannot write " + what + " of " + size_str(w, h) + " from " +
                      std::to_string(have) + " values");
    }
}

// ---- JSON -----------------------------------------------------------------------------

nlohmann::json read_json(const std::string& path) {
    std::vector<unsigned char> bytes;
    read_file(path, bytes);
    try {
        return nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::parse_error& e) {
        throw InputError(path + ": invalid JSON (" + e.what() + ")");
    }
}

const nlohmann::json& member(const std::string& path, const nlohmann::json& obj,
                             const std::string& prefix, const char* key) {
    if (!obj.is_object()) {
        throw InputError(path + ": " + (prefix.empty() ? "the top level" : "'" + prefix + "'") +
                         " must be a JSON object");
    }
    const auto it = obj.find(key);
    if (it == obj.end()) throw InputError(path + ": missing key '" + prefix + key + "'");
    return *it;
}

double number(const std::string& path, const nlohmann::json& obj, const std::string& prefix,
              const char* key) {
    const nlohmann::json& v = member(path, obj, prefix, key);
    if (!v.is_number()) throw InputError(path + ": key '" + prefix + key + "' must be a number");
    return v.get<double>();
}

int integer(const std::string& path, const nlohmann::json& obj, const std::string& prefix,
            const char* key) {
    const double v = number(path, obj, prefix, key);
    if (v != std::floor(v) || v < 0 || v > 1e6) {
        throw InputError(path + ": key '" + prefix + key + "' must be a whole number of pixels");
    }
    return static_cast<int>(v);
}

float depth_scale(const std::string& path, const nlohmann::json& obj) {
    // Optional: 16-bit depth in millimetres is the common default (OpenNI, RealSense, Kinect).
    if (!obj.contains("depth_scale_m_per_unit")) return 0.001f;
    const double s = number(path, obj, "", "depth_scale_m_per_unit");
    if (!(s > 0.0) || !std::isfinite(s)) {
        throw InputError(path + ": key 'depth_scale_m_per_unit' must be positive");
    }
    return static_cast<float>(s);
}

PinholeIntrinsics intrinsics_from(const std::string& path, const nlohmann::json& obj,
                                  const std::string& prefix) {
    PinholeIntrinsics K;
    K.fx = number(path, obj, prefix, "fx");
    K.fy = number(path, obj, prefix, "fy");
    K.cx = number(path, obj, prefix, "cx");
    K.cy = number(path, obj, prefix, "cy");
    K.width = integer(path, obj, prefix, "width");
    K.height = integer(path, obj, prefix, "height");
    try {
        K.validate(prefix.empty() ? "intrinsics" : prefix.substr(0, prefix.size() - 1));
    } catch (const ParamError& e) {
        throw InputError(path + ": " + e.what());
    }
    return K;
}

nlohmann::json intrinsics_to_json(const PinholeIntrinsics& K) {
    return {{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy},
            {"width", K.width}, {"height", K.height}};
}

/// The float's shortest decimal form as a double: 0.001f is written "0.001", not
/// "0.0010000000474974513".
double float_for_json(float f) {
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, f);
    return std::strtod(std::string(buf, res.ptr).c_str(), nullptr);
}

}  // namespace

// ---- detail: readers into reused buffers ---------------------------------------------

namespace detail {

void read_depth_png_into(const std::string& path, float scale_m_per_unit, ImageScratch& s,
                         DepthImage& out) {
    decode(path, s, false);
    const cv::Mat& m = s.decoded;
    if (m.depth() != CV_16U || m.channels() != 1) {
        throw InputError(path + ": depth must be 16-bit single-channel PNG, got " + describe(m) +
                         " (8-bit depth has no known units)");
    }
    out.width = m.cols;
    out.height = m.rows;
    out.scale_m_per_unit = scale_m_per_unit;
    out.data.resize(static_cast<std::size_t>(m.cols) * m.rows);
    cv::Mat dst(m.rows, m.cols, CV_16UC1, out.data.data());
    m.copyTo(dst);
}

void read_color_image_into(const std::string& path, ImageScratch& s, ColorImage& out) {
    decode(path, s, true);
    const cv::Mat& m = s.decoded;
    const int ch = m.channels();
    if (m.depth() != CV_8U || (ch != 1 && ch != 3 && ch != 4)) {
        throw InputError(path + ": colour must be 8-bit grey, RGB or RGBA, got " + describe(m));
    }
    out.width = m.cols;
    out.height = m.rows;
    out.rgb.resize(3 * static_cast<std::size_t>(m.cols) * m.rows);
    cv::Mat dst(m.rows, m.cols, CV_8UC3, out.rgb.data());
    const int code = ch == 1 ? cv::COLOR_GRAY2RGB : ch == 3 ? cv::COLOR_BGR2RGB : cv::COLOR_BGRA2RGB;
    cv::cvtColor(m, dst, code);
}

void read_label_png_into(const std::string& path, ImageScratch& s, LabelImage& out) {
    decode(path, s, false);
    const cv::Mat& m = s.decoded;
    // 8-bit labels are accepted too: ids, unlike depth, have no units to get wrong.
    if ((m.depth() != CV_16U && m.depth() != CV_8U) || m.channels() != 1) {
        throw InputError(path + ": labels must be 16-bit single-channel PNG, got " + describe(m));
    }
    out.width = m.cols;
    out.height = m.rows;
    out.labels.resize(static_cast<std::size_t>(m.cols) * m.rows);
    cv::Mat dst(m.rows, m.cols, CV_16UC1, out.labels.data());
    m.convertTo(dst, CV_16U);
}

}  // namespace detail

// ---- single files -------------------------------------------------------------------

DepthImage read_depth_png(const std::string& path, float scale_m_per_unit) {
    ImageScratch s;
    DepthImage out;
    detail::read_depth_png_into(path, scale_m_per_unit, s, out);
    return out;
}

ColorImage read_color_image(const std::string& path) {
    ImageScratch s;
    ColorImage out;
    detail::read_color_image_into(path, s, out);
    return out;
}

LabelImage read_label_png(const std::string& path) {
    ImageScratch s;
    LabelImage out;
    detail::read_label_png_into(path, s, out);
    return out;
}

IntrinsicsFile read_intrinsics_json(const std::string& path) {
    const nlohmann::json j = read_json(path);
    IntrinsicsFile f;
    f.intrinsics = intrinsics_from(path, j, "");
    f.depth_scale_m_per_unit = depth_scale(path, j);
    return f;
}

StereoCalibration read_calibration_json(const std::string& path) {
    const nlohmann::json j = read_json(path);
    StereoCalibration c;
    c.depth = intrinsics_from(path, member(path, j, "", "depth"), "depth.");
    c.color = intrinsics_from(path, member(path, j, "", "color"), "color.");
    const nlohmann::json& ext = member(path, j, "", "depth_to_color");
    auto read_array = [&](const char* key, double* dst, std::size_t n) {
        const nlohmann::json& a = member(path, ext, "depth_to_color.", key);
        if (!a.is_array() || a.size() != n) {
            throw InputError(path + ": key 'depth_to_color." + key + "' must be an array of " +
                             std::to_string(n) + " numbers");
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (!a[i].is_number()) {
                throw InputError(path + ": key 'depth_to_color." + key + "' must hold numbers only");
            }
            dst[i] = a[i].get<double>();
        }
    };
    read_array("rotation", c.rotation.data(), 9);
    read_array("translation_m", c.translation_m.data(), 3);
    c.depth_scale_m_per_unit = depth_scale(path, j);
    try {
        c.validate();
    } catch (const ParamError& e) {
        throw InputError(path + ": " + e.what());
    }
    return c;
}

void write_calibration_json(const std::string& path, const StereoCalibration& calib) {
    nlohmann::json j;
    j["depth"] = intrinsics_to_json(calib.depth);
    j["color"] = intrinsics_to_json(calib.color);
    j["depth_to_color"] = {{"rotation", calib.rotation}, {"translation_m", calib.translation_m}};
    j["depth_scale_m_per_unit"] = float_for_json(calib.depth_scale_m_per_unit);
    write_text_file(path, j.dump(2) + "\n");
}

// ---- outputs ------------------------------------------------------------------------

void write_label_png(const std::string& path, const LabelImage& labels) {
    check_buffer(path, "labels", labels.width, labels.height, labels.labels.size(), 1);
    const cv::Mat m(labels.height, labels.width, CV_16UC1,
                    const_cast<std::uint16_t*>(labels.labels.data()));
    write_png(path, m);
}

void write_color_png(const std::string& path, const ColorImage& image) {
    check_buffer(path, "a colour image", image.width, image.height, image.rgb.size(), 3);
    const cv::Mat rgb(image.height, image.width, CV_8UC3,
                      const_cast<std::uint8_t*>(image.rgb.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    write_png(path, bgr);
}

void write_mask_png(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& mask) {
    check_buffer(path, "a mask", width, height, mask.size(), 1);
    // Any non-zero entry is written as 255, so the mask is visible in an image viewer.
    cv::Mat m(height, width, CV_8UC1);
    for (int v = 0; v < height; ++v) {
        std::uint8_t* row = m.ptr<std::uint8_t>(v);
        const std::uint8_t* src = mask.data() + static_cast<std::size_t>(v) * width;
        for (int u = 0; u < width; ++u) row[u] = src[u] ? 255 : 0;
    }
    write_png(path, m);
}

void write_depth_png(const std::string& path, const DepthImage& depth) {
    check_buffer(path, "a depth image", depth.width, depth.height, depth.data.size(), 1);
    const cv::Mat m(depth.height, depth.width, CV_16UC1,
                    const_cast<std::uint16_t*>(depth.data.data()));
    write_png(path, m);
}

void write_ply(const std::string& path, const OrganizedCloud& cloud, const LabelImage& labels,
               const ColorImage& colors) {
    const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
    const bool sizes_ok = cloud.valid.size() == n && cloud.x.size() == n && cloud.y.size() == n &&
                          cloud.z.size() == n && labels.width == cloud.width &&
                          labels.height == cloud.height && labels.labels.size() == n;
    const bool own_colors = !colors.empty();
    if (!sizes_ok || (own_colors && (colors.width != cloud.width || colors.height != cloud.height ||
                                     colors.rgb.size() != 3 * n))) {
        throw IoError(path + ": cannot write PLY: cloud " + size_str(cloud.width, cloud.height) +
                      ", labels " + size_str(labels.width, labels.height) + " and colours " +
                      size_str(colors.width, colors.height) + " differ in size");
    }
    const bool cloud_colors = !own_colors && cloud.has_color && cloud.r.size() == n &&
                              cloud.g.size() == n && cloud.b.size() == n;
    std::size_t count = 0;
    for (std::size_t p = 0; p < n; ++p) count += (labels.labels[p] > 0 && cloud.valid[p]) ? 1 : 0;

    const std::string header = "ply\nformat binary_little_endian 1.0\ncomment wul3d labelled points\n"
                               "element vertex " + std::to_string(count) +
                               "\nproperty float x\nproperty float y\nproperty float z\n"
                               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                               "property ushort label\nend_header\n";
    constexpr std::size_t kVertexBytes = 3 * 4 + 3 + 2;
    std::vector<char> buf(header.size() + count * kVertexBytes);
    std::memcpy(buf.data(), header.data(), header.size());
    char* out = buf.data() + header.size();
    static_assert(std::endian::native == std::endian::little,
                  "write_ply writes the host's floats as little-endian");
    for (std::size_t p = 0; p < n; ++p) {
        if (labels.labels[p] == 0 || !cloud.valid[p]) continue;
        const float xyz[3] = {cloud.x[p], cloud.y[p], cloud.z[p]};
        std::uint8_t rgb[3] = {200, 200, 200};  // depth-only without colours: light grey
        if (own_colors) {
            std::memcpy(rgb, &colors.rgb[3 * p], 3);
        } else if (cloud_colors) {
            rgb[0] = cloud.r[p], rgb[1] = cloud.g[p], rgb[2] = cloud.b[p];
        }
        const std::uint16_t label = labels.labels[p];
        std::memcpy(out, xyz, 12);
        std::memcpy(out + 12, rgb, 3);
        std::memcpy(out + 15, &label, 2);
        out += kVertexBytes;
    }
    write_file_atomic(path, buf.data(), buf.size());
}

void write_text_file(const std::string& path, const std::string& text) {
    write_file_atomic(path, text.data(), text.size());
}

}  // namespace wul3d
