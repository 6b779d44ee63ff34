// Organized PCD files (PCL's format, v0.7) as frames, and the writer the tests use: io.hpp.
// Every size the header declares is checked against the image limit before anything is
// allocated, and against the bytes present before anything is read.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {

namespace {

/// The largest PCD read, and the most its binary data may declare: 64 MiB plus 64 bytes a
/// pixel of the image limit (an ascii PCD takes some 40 bytes a point).
constexpr std::uint64_t kMaxPcdFileBytesBase = std::uint64_t{1} << 26;
constexpr std::uint64_t kMaxPcdFileBytesPerPixel = 64;

struct PcdField {
    std::string name;
    int size = 0;
    char type = 0;
    int count = 1;
    std::size_t offset = 0;  ///< in a point (binary) / in the field-major block (compressed)
};

struct PcdHeader {
    std::vector<PcdField> fields;
    std::uint64_t width = 0, height = 0, points = 0;
    bool has_points = false;
    std::string data;
    std::size_t data_start = 0;  ///< the byte after the DATA line
    std::size_t point_bytes = 0;
};

std::uint64_t parse_count(const std::string& what, const std::string& key, const std::string& text,
                          std::uint64_t max) {
    if (text.empty() || text.size() > 12 ||
        text.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(what + ": PCD header " + key + " '" + text.substr(0, 20) +
                         "' is not a count");
    const std::uint64_t v = std::stoull(text);
    if (v > max)
        throw InputError(what + ": PCD header " + key + " " + text + " exceeds the limit of " +
                         std::to_string(max) + " (--max-pixels)");
    return v;
}

PcdHeader parse_header(const std::string& what, const unsigned char* data, std::size_t size) {
    PcdHeader h;
    std::vector<std::string> sizes, types, counts;
    std::size_t pos = 0;
    bool have_fields = false;
    const std::size_t limit = std::min<std::size_t>(size, kMaxPcdHeaderBytes);
    while (true) {
        const void* nl = pos < limit ? std::memchr(data + pos, '\n', limit - pos) : nullptr;
        if (nl == nullptr)
            throw InputError(what + ": no PCD DATA line within the first " +
                             std::to_string(limit) + " bytes");
        const std::size_t end = static_cast<std::size_t>(static_cast<const unsigned char*>(nl) - data);
        std::string line(reinterpret_cast<const char*>(data + pos), end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        std::istringstream in(line);
        std::string key;
        in >> key;
        std::vector<std::string> values;
        for (std::string v; in >> v;) values.push_back(v);
        const std::uint64_t side = kMaxImageSide;
        if (key == "VERSION") {
        } else if (key == "FIELDS") {
            if (values.empty() || values.size() > 256)
                throw InputError(what + ": PCD header FIELDS lists " + std::to_string(values.size()) +
                                 " fields (1-256)");
            for (const std::string& v : values) h.fields.push_back({v, 0, 0, 1, 0});
            have_fields = true;
        } else if (key == "SIZE") {
            sizes = values;
        } else if (key == "TYPE") {
            types = values;
        } else if (key == "COUNT") {
            counts = values;
        } else if (key == "WIDTH") {
            h.width = parse_count(what, key, values.empty() ? "" : values[0], side);
        } else if (key == "HEIGHT") {
            h.height = parse_count(what, key, values.empty() ? "" : values[0], side);
        } else if (key == "VIEWPOINT") {
        } else if (key == "POINTS") {
            h.points = parse_count(what, key, values.empty() ? "" : values[0], max_image_pixels());
            h.has_points = true;
        } else if (key == "DATA") {
            h.data = values.empty() ? "" : values[0];
            h.data_start = pos;
            break;
        } else {
            throw InputError(what + ": not a PCD file (unknown header line '" + line.substr(0, 40) +
                             "')");
        }
    }
    if (!have_fields) throw InputError(what + ": PCD header has no FIELDS");
    const std::size_t n = h.fields.size();
    if (sizes.size() != n || types.size() != n || (!counts.empty() && counts.size() != n))
        throw InputError(what + ": PCD header's SIZE, TYPE and COUNT do not match its " +
                         std::to_string(n) + " FIELDS");
    for (std::size_t i = 0; i < n; ++i) {
        PcdField& f = h.fields[i];
        f.size = sizes[i] == "1" ? 1 : sizes[i] == "2" ? 2 : sizes[i] == "4" ? 4 : sizes[i] == "8" ? 8 : 0;
        f.type = types[i].size() == 1 ? types[i][0] : 0;
        if (f.size == 0 || (f.type != 'F' && f.type != 'U' && f.type != 'I'))
            throw InputError(what + ": PCD field " + f.name + " has SIZE '" + sizes[i] + "' TYPE '" +
                             types[i] + "' (SIZE 1, 2, 4 or 8; TYPE F, U or I)");
        if (!counts.empty()) f.count = static_cast<int>(parse_count(what, "COUNT", counts[i], 4096));
        if (f.count < 1) throw InputError(what + ": PCD field " + f.name + " has COUNT 0");
        f.offset = h.point_bytes;
        h.point_bytes += static_cast<std::size_t>(f.size) * static_cast<std::size_t>(f.count);
    }
    if (h.width == 0 || h.height == 0)
        throw InputError(what + ": PCD header WIDTH or HEIGHT is missing or 0");
    if (h.width * h.height > max_image_pixels())
        throw InputError(what + ": PCD of " + std::to_string(h.width) + "x" + std::to_string(h.height) +
                         " points exceeds the image limit of " + std::to_string(max_image_pixels()) +
                         " pixels (--max-pixels)");
    if (h.has_points && h.points != h.width * h.height)
        throw InputError(what + ": PCD header says POINTS " + std::to_string(h.points) +
                         " but WIDTH x HEIGHT is " + std::to_string(h.width * h.height));
    if (h.height < 2)
        throw InputError(what + ": PCD is not organized (HEIGHT 1): it cannot be read as a frame");
    return h;
}

const PcdField* find_field(const PcdHeader& h, const char* name) {
    for (const PcdField& f : h.fields)
        if (f.name == name) return &f;
    return nullptr;
}

/// LZF (liblzf's format, which PCL's binary_compressed uses) into exactly `out_size` bytes.
bool lzf_decompress(const unsigned char* in, std::size_t in_size, unsigned char* out,
                    std::size_t out_size) {
    std::size_t ip = 0, op = 0;
    while (ip < in_size) {
        std::size_t ctrl = in[ip++];
        if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
            const std::size_t len = ctrl + 1;
            if (len > in_size - ip || len > out_size - op) return false;
            std::memcpy(out + op, in + ip, len);
            ip += len;
            op += len;
        } else {  // a back reference
            std::size_t len = ctrl >> 5;
            if (len == 7) {
                if (ip >= in_size) return false;
                len += in[ip++];
            }
            if (ip >= in_size) return false;
            const std::size_t back = ((ctrl & 0x1f) << 8) + in[ip++] + 1;
            len += 2;
            if (back > op || len > out_size - op) return false;
            for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - back];
        }
    }
    return op == out_size;
}

float get_float(const unsigned char* p) {
    float v;
    std::memcpy(&v, p, 4);
    return v;
}
std::uint32_t get_u32(const unsigned char* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

/// The points' x y z and packed rgb, whatever the DATA, as arrays of the cloud's size.
struct Points {
    std::vector<float> x, y, z;
    std::vector<std::uint32_t> rgb;
};

void check_xyz(const std::string& what, const PcdField* f, const char* name) {
    if (f == nullptr) throw InputError(what + ": PCD has no field " + name + " (x y z are needed)");
    if (f->type != 'F' || f->size != 4 || f->count != 1)
        throw InputError(what + ": PCD field " + name + " must be F 4 1 (float)");
}

Points read_points(const std::string& what, const PcdHeader& h, const unsigned char* data,
                   std::size_t size) {
    const PcdField* fx = find_field(h, "x");
    const PcdField* fy = find_field(h, "y");
    const PcdField* fz = find_field(h, "z");
    check_xyz(what, fx, "x");
    check_xyz(what, fy, "y");
    check_xyz(what, fz, "z");
    const PcdField* fc = find_field(h, "rgb");
    if (fc == nullptr) fc = find_field(h, "rgba");
    if (fc != nullptr && (fc->size != 4 || fc->count != 1))
        throw InputError(what + ": PCD field " + fc->name + " must be 4 bytes, COUNT 1");

    const std::size_t n = static_cast<std::size_t>(h.width * h.height);
    Points p;
    const unsigned char* body = data + h.data_start;
    const std::size_t body_size = size - h.data_start;
    if (h.data == "ascii") {
        // Checked as it goes: as many values per point as the fields' counts.
        p.x.resize(n), p.y.resize(n), p.z.resize(n);
        if (fc) p.rgb.resize(n);
        const char* s = reinterpret_cast<const char*>(body);
        const char* e = s + body_size;
        std::string token;
        for (std::size_t i = 0; i < n; ++i) {
            for (const PcdField& f : h.fields) {
                for (int c = 0; c < f.count; ++c) {
                    while (s < e && (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n')) ++s;
                    const char* t = s;
                    while (s < e && !(*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n')) ++s;
                    if (t == s)
                        throw InputError(what + ": PCD ascii data ends at point " + std::to_string(i) +
                                         " of the " + std::to_string(n) + " declared");
                    if (c != 0) continue;
                    const bool xyz = &f == fx || &f == fy || &f == fz;
                    if (!xyz && &f != fc) continue;
                    token.assign(t, s);
                    char* end = nullptr;
                    if (xyz) {
                        const float v = std::strtof(token.c_str(), &end);
                        (&f == fx ? p.x : &f == fy ? p.y : p.z)[i] = v;
                    } else if (f.type == 'F') {
                        const float v = std::strtof(token.c_str(), &end);
                        std::memcpy(&p.rgb[i], &v, 4);
                    } else {
                        p.rgb[i] = static_cast<std::uint32_t>(std::strtoll(token.c_str(), &end, 10));
                    }
                    if (end == nullptr || *end != '\0')
                        throw InputError(what + ": PCD ascii value '" + token.substr(0, 20) +
                                         "' of point " + std::to_string(i) + " is not a number");
                }
            }
        }
        return p;
    }
    const std::uint64_t need = static_cast<std::uint64_t>(n) * h.point_bytes;
    if (need > kMaxPcdFileBytesBase + kMaxPcdFileBytesPerPixel * max_image_pixels())
        throw InputError(what + ": PCD points of " + std::to_string(h.point_bytes) +
                         " bytes each declare " + std::to_string(need) +
                         " bytes, over the limit for the image limit (--max-pixels)");
    std::vector<unsigned char> unpacked;
    const unsigned char* block = body;
    bool field_major = false;
    if (h.data == "binary") {
        if (body_size < need)
            throw InputError(what + ": PCD binary data is " + std::to_string(body_size) +
                             " bytes, but the header declares " + std::to_string(need));
    } else if (h.data == "binary_compressed") {
        if (body_size < 8) throw InputError(what + ": PCD binary_compressed data has no sizes");
        const std::uint32_t packed = get_u32(body), plain = get_u32(body + 4);
        if (plain != need)
            throw InputError(what + ": PCD binary_compressed says " + std::to_string(plain) +
                             " bytes uncompressed, but the header declares " + std::to_string(need));
        if (packed > body_size - 8)
            throw InputError(what + ": PCD binary_compressed data is " + std::to_string(body_size - 8) +
                             " bytes, but says " + std::to_string(packed));
        unpacked.resize(need);
        if (!lzf_decompress(body + 8, packed, unpacked.data(), unpacked.size()))
            throw InputError(what + ": PCD binary_compressed data does not decompress to " +
                             std::to_string(need) + " bytes");
        block = unpacked.data();
        field_major = true;
    } else {
        throw InputError(what + ": PCD DATA '" + h.data.substr(0, 20) +
                         "' (known: ascii, binary, binary_compressed)");
    }
    auto at = [&](const PcdField& f, std::size_t i) {
        // Binary: point after point. Compressed: field after field (each f.size * count wide).
        return field_major ? block + f.offset * n + i * f.size * static_cast<std::size_t>(f.count)
                           : block + i * h.point_bytes + f.offset;
    };
    p.x.resize(n), p.y.resize(n), p.z.resize(n);
    if (fc) p.rgb.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        p.x[i] = get_float(at(*fx, i));
        p.y[i] = get_float(at(*fy, i));
        p.z[i] = get_float(at(*fz, i));
        if (fc) p.rgb[i] = get_u32(at(*fc, i));
    }
    return p;
}

/// Least squares of u = f a + c (a = x/z) over the valid points: {f, c, rms}.
struct Fit1 {
    double f = 0, c = 0, rms = 0;
};
Fit1 fit_line(const std::vector<double>& a, const std::vector<double>& u) {
    const double n = static_cast<double>(a.size());
    double ma = 0, mu = 0;
    for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mu += u[i];
    ma /= n, mu /= n;
    double saa = 0, sau = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        saa += (a[i] - ma) * (a[i] - ma);
        sau += (a[i] - ma) * (u[i] - mu);
    }
    Fit1 r;
    if (!(saa > 0)) return r;
    r.f = sau / saa;
    r.c = mu - r.f * ma;
    double ss = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double d = r.f * a[i] + r.c - u[i];
        ss += d * d;
    }
    r.rms = std::sqrt(ss / n);
    return r;
}

}  // namespace

RgbdFrame parse_pcd_frame(const std::string& what, const unsigned char* data, std::size_t size) {
    const PcdHeader h = parse_header(what, data, size);
    const Points p = read_points(what, h, data, size);
    const int w = static_cast<int>(h.width), ht = static_cast<int>(h.height);
    const std::size_t n = p.z.size();
    RgbdFrame f;
    f.depth.width = w;
    f.depth.height = ht;
    f.depth.scale_m_per_unit = 0.001f;
    f.depth.data.assign(n, 0);
    std::vector<double> a, b, u, v;
    for (std::size_t i = 0; i < n; ++i) {
        const float z = p.z[i];
        if (!(z > 0.0f) || !std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) continue;
        const double mm = std::round(static_cast<double>(z) * 1000.0);
        if (mm < 1.0 || mm > 65535.0) continue;
        f.depth.data[i] = static_cast<std::uint16_t>(mm);
        a.push_back(static_cast<double>(p.x[i]) / z);
        b.push_back(static_cast<double>(p.y[i]) / z);
        u.push_back(static_cast<double>(i % h.width));
        v.push_back(static_cast<double>(i / h.width));
    }
    if (a.size() < static_cast<std::size_t>(kPcdMinFitPoints))
        throw InputError(what + ": PCD has " + std::to_string(a.size()) +
                         " valid points; at least " + std::to_string(kPcdMinFitPoints) +
                         " are needed to recover the intrinsics");
    const Fit1 fu = fit_line(a, u), fv = fit_line(b, v);
    if (!(fu.f > 0) || !(fv.f > 0) || !(fu.rms <= kPcdMaxFitRmsPx) || !(fv.rms <= kPcdMaxFitRmsPx))
        throw InputError(what + ": PCD points do not fit a pinhole camera (fx " +
                         detail::number_str(fu.f) + ", fy " + detail::number_str(fv.f) +
                         ", RMS residual " + detail::number_str(std::max(fu.rms, fv.rms)) +
                         " px; at most " + detail::number_str(kPcdMaxFitRmsPx) + ")");
    f.intrinsics.width = w;
    f.intrinsics.height = ht;
    f.intrinsics.fx = fu.f;
    f.intrinsics.cx = fu.c;
    f.intrinsics.fy = fv.f;
    f.intrinsics.cy = fv.c;
    try {
        f.intrinsics.validate(what + ": the intrinsics recovered from the PCD");
    } catch (const ParamError& e) {
        throw InputError(e.what());  // the file's fault, not a parameter's
    }
    if (!p.rgb.empty()) {
        f.color.width = w;
        f.color.height = ht;
        f.color.rgb.resize(3 * n);
        for (std::size_t i = 0; i < n; ++i) {
            f.color.rgb[3 * i] = static_cast<std::uint8_t>(p.rgb[i] >> 16);
            f.color.rgb[3 * i + 1] = static_cast<std::uint8_t>(p.rgb[i] >> 8);
            f.color.rgb[3 * i + 2] = static_cast<std::uint8_t>(p.rgb[i]);
        }
    }
    return f;
}

RgbdFrame read_pcd_frame(const std::string& path) {
    std::vector<unsigned char> bytes;
    detail::read_regular_file(path, kMaxPcdFileBytesBase + kMaxPcdFileBytesPerPixel * max_image_pixels(),
                              bytes);
    RgbdFrame f = parse_pcd_frame(path, bytes.data(), bytes.size());
    return f;
}

void write_pcd(const std::string& path, const RgbdFrame& frame, PcdData data, bool with_rgb) {
    const int w = frame.depth.width, h = frame.depth.height;
    const std::size_t n = frame.depth.data.size();
    const PinholeIntrinsics& K = frame.intrinsics;
    with_rgb = with_rgb && frame.has_color();
    std::ostringstream head;
    head << "# .PCD v0.7 - Point Cloud Data file format (written by wul3d)\nVERSION 0.7\n"
         << (with_rgb ? "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                      : "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n")
         << "WIDTH " << w << "\nHEIGHT " << h << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n
         << "\nDATA "
         << (data == PcdData::Ascii ? "ascii" : data == PcdData::Binary ? "binary" : "binary_compressed")
         << "\n";
    const int fields = with_rgb ? 4 : 3;
    std::vector<std::uint32_t> values(n * static_cast<std::size_t>(fields));  // point-major
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 0; i < n; ++i) {
        const float z = static_cast<float>(frame.depth.data[i]) * frame.depth.scale_m_per_unit;
        const double u = static_cast<double>(i % static_cast<std::size_t>(w));
        const double v = static_cast<double>(i / static_cast<std::size_t>(w));
        float xyz[3] = {nan, nan, nan};
        if (frame.depth.data[i] != 0) {
            xyz[0] = static_cast<float>((u - K.cx) * z / K.fx);
            xyz[1] = static_cast<float>((v - K.cy) * z / K.fy);
            xyz[2] = z;
        }
        std::memcpy(&values[i * fields], xyz, sizeof xyz);
        if (with_rgb) {
            const std::uint8_t* c = &frame.color.rgb[3 * i];
            values[i * fields + 3] = (255u << 24) | (std::uint32_t{c[0]} << 16) |
                                     (std::uint32_t{c[1]} << 8) | c[2];
        }
    }
    std::string out = head.str();
    if (data == PcdData::Ascii) {
        std::ostringstream body;
        body.precision(9);
        for (std::size_t i = 0; i < n; ++i) {
            for (int k = 0; k < 3; ++k) {
                float f;
                std::memcpy(&f, &values[i * fields + k], 4);
                if (std::isnan(f))
                    body << "nan";
                else
                    body << f;
                body << (k < fields - 1 ? ' ' : '\n');
            }
            if (with_rgb) body << values[i * fields + 3] << '\n';  // as PCL writes it: U 4
        }
        // rgb as TYPE U in ascii: a float's text would lose the packed bits' NaN payloads.
        if (with_rgb) {
            const std::string from = "TYPE F F F F", to = "TYPE F F F U";
            out.replace(out.find(from), from.size(), to);
        }
        out += body.str();
    } else if (data == PcdData::Binary) {
        out.append(reinterpret_cast<const char*>(values.data()), values.size() * 4);
    } else {
        // Field-major, then LZF of literal runs only (valid LZF, no compression).
        std::vector<std::uint32_t> soa(values.size());
        for (std::size_t i = 0; i < n; ++i)
            for (int k = 0; k < fields; ++k) soa[k * n + i] = values[i * fields + k];
        const auto* plain = reinterpret_cast<const unsigned char*>(soa.data());
        const std::size_t plain_size = soa.size() * 4;
        std::string packed;
        for (std::size_t pos = 0; pos < plain_size; pos += 32) {
            const std::size_t len = std::min<std::size_t>(32, plain_size - pos);
            packed.push_back(static_cast<char>(len - 1));
            packed.append(reinterpret_cast<const char*>(plain + pos), len);
        }
        const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(packed.size()),
                                        static_cast<std::uint32_t>(plain_size)};
        out.append(reinterpret_cast<const char*>(sizes), sizeof sizes);
        out += packed;
    }
    write_text_file(path, out);
}

}  // namespace wul3d
