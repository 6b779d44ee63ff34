// Seed corpora of the fuzzers, made from the shipped samples (data/samples) at CI time:
//   make_seeds SAMPLES_DIR OUT_DIR
// writes OUT_DIR/<harness>/<seed> for every harness of fuzz/. Frames are cut down to 80 x 60
// (nearest pixel) so that each fuzzing run stays fast.
#include <cstdio>  // before jpeglib.h, which needs FILE and size_t
#include <jpeglib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "wul3d/io.hpp"
#include "wul3d/kinect_v1.hpp"

namespace fs = std::filesystem;
using namespace wul3d;

namespace {

constexpr int kW = 80, kH = 60;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void spit(const fs::path& p, const std::string& bytes) {
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
}

DepthImage shrink(const DepthImage& d) {
    DepthImage s;
    s.width = kW;
    s.height = kH;
    s.scale_m_per_unit = d.scale_m_per_unit;
    s.data.resize(kW * kH);
    for (int v = 0; v < kH; ++v)
        for (int u = 0; u < kW; ++u)
            s.data[v * kW + u] = d.data[static_cast<std::size_t>(v * d.height / kH) * d.width + u * d.width / kW];
    return s;
}

ColorImage shrink(const ColorImage& c) {
    ColorImage s;
    s.width = kW;
    s.height = kH;
    s.rgb.resize(3 * kW * kH);
    for (int v = 0; v < kH; ++v)
        for (int u = 0; u < kW; ++u)
            for (int ch = 0; ch < 3; ++ch)
                s.rgb[3 * (v * kW + u) + ch] =
                    c.rgb[3 * (static_cast<std::size_t>(v * c.height / kH) * c.width + u * c.width / kW) + ch];
    return s;
}

std::string jpeg_of(const ColorImage& c) {
    jpeg_compress_struct cinfo{};
    jpeg_error_mgr err{};
    cinfo.err = jpeg_std_error(&err);
    jpeg_create_compress(&cinfo);
    unsigned char* buf = nullptr;
    unsigned long size = 0;
    jpeg_mem_dest(&cinfo, &buf, &size);
    cinfo.image_width = static_cast<JDIMENSION>(c.width);
    cinfo.image_height = static_cast<JDIMENSION>(c.height);
    cinfo.input_components = 3;
    cinfo.in_color_space = JCS_RGB;
    jpeg_set_defaults(&cinfo);
    jpeg_set_quality(&cinfo, 85, TRUE);
    jpeg_start_compress(&cinfo, TRUE);
    while (cinfo.next_scanline < cinfo.image_height) {
        JSAMPROW row = const_cast<unsigned char*>(&c.rgb[3 * cinfo.next_scanline * static_cast<std::size_t>(c.width)]);
        jpeg_write_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_compress(&cinfo);
    std::string out(reinterpret_cast<const char*>(buf), size);
    jpeg_destroy_compress(&cinfo);
    std::free(buf);
    return out;
}

std::string u32(std::size_t n) {
    std::string s(4, '\0');
    for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((n >> (8 * i)) & 0xff);
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: make_seeds SAMPLES_DIR OUT_DIR\n";
        return 2;
    }
    const fs::path samples = argv[1], out = argv[2], tmp = out / ".tmp";
    fs::create_directories(tmp);
    int n = 0;
    for (const char* frame : {"uois_tabletop/image_0000", "uois_tabletop/image_0005",
                              "pcl_kinect/milk_cartoon_all_small_clorox"}) {
        const fs::path dir = samples / frame;
        const std::string id = std::to_string(n++);
        const IntrinsicsFile K = read_intrinsics_json((dir / "intrinsics.json").string());
        const DepthImage depth = shrink(read_depth_png((dir / "depth.png").string(), K.depth_scale_m_per_unit));
        const ColorImage color = shrink(read_color_image((dir / "color.png").string()));
        write_depth_png((tmp / "d.png").string(), depth);
        write_color_png((tmp / "c.png").string(), color);
        PinholeIntrinsics k = K.intrinsics;
        const double sx = double(kW) / k.width, sy = double(kH) / k.height;
        k.fx *= sx, k.cx *= sx, k.fy *= sy, k.cy *= sy, k.width = kW, k.height = kH;
        write_intrinsics_json((tmp / "i.json").string(), k, K.depth_scale_m_per_unit);
        const std::string d = slurp(tmp / "d.png"), c = slurp(tmp / "c.png"), i = slurp(tmp / "i.json");
        spit(out / "png" / ("depth" + id + ".png"), d);
        spit(out / "png" / ("color" + id + ".png"), c);
        spit(out / "jpeg" / ("color" + id + ".jpg"), jpeg_of(color));
        spit(out / "intrinsics_json" / ("shipped" + id + ".json"), slurp(dir / "intrinsics.json"));
        spit(out / "intrinsics_json" / ("small" + id + ".json"), i);
        spit(out / "frame" / ("frame" + id), u32(d.size()) + d + u32(c.size()) + c + i);
        spit(out / "frame" / ("depth_only" + id), u32(d.size()) + d + u32(0) + i);
        {
            // Organized PCDs of the small frame: every DATA kind, with and without rgb.
            RgbdFrame f;
            f.depth = depth;
            f.color = color;
            f.intrinsics = k;
            const std::pair<PcdData, const char*> kinds[] = {{PcdData::Ascii, "ascii"},
                                                             {PcdData::Binary, "binary"},
                                                             {PcdData::BinaryCompressed, "compressed"}};
            for (const auto& [kind, kind_name] : kinds)
                for (const bool rgb : {false, true}) {
                    write_pcd((tmp / "p.pcd").string(), f, kind, rgb);
                    spit(out / "pcd" / (std::string(kind_name) + (rgb ? "_rgb" : "") + id + ".pcd"),
                         slurp(tmp / "p.pcd"));
                }
        }
    }
    write_calibration_json((tmp / "k.json").string(), kinect_v2_default_calibration());
    spit(out / "calibration_json" / "kinect_v2.json", slurp(tmp / "k.json"));
    write_calibration_json((tmp / "k.json").string(), kinect_v1_calibration());
    spit(out / "calibration_json" / "kinect_v1.json", slurp(tmp / "k.json"));
    spit(out / "tum_list" / "lists",
         "# colour images\n1305031102.175304 rgb/1305031102.175304.png\n"
         "1305031102.211214 rgb/1305031102.211214.png\n----\n"
         "# depth maps\n1305031102.160407 depth/1305031102.160407.png\n"
         "1305031102.194330 depth/1305031102.194330.png\n");
    {
        // A shipped frame as the Kinect v1's raw depth, little-endian.
        const DepthImage depth = read_depth_png((samples / "uois_tabletop/image_0000/depth.png").string(), 0.001f);
        RegistrationWorkspace ws;
        std::vector<std::uint16_t> raw;
        kinect_v1_depth_to_raw(depth, ws, raw);
        std::string bytes;
        for (std::uint16_t r : raw) bytes += {static_cast<char>(r & 0xff), static_cast<char>(r >> 8)};
        spit(out / "fakenect" / "tabletop.raw", bytes);
        spit(out / "fakenect" / "row.raw", bytes.substr(2 * 640 * 240, 2 * 640));
    }
    fs::remove_all(tmp);
    std::cout << "seeds written to " << out.string() << "\n";
    return 0;
}
