// The outputs of one frame (output.hpp): the atomic writes every writer uses, the
// objects.json schema and the frame folder OUT/<frame>/.
#include "wul3d/output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "wul3d/error.hpp"
#include "wul3d/io.hpp"

namespace wul3d {
namespace fs = std::filesystem;

namespace {
std::string errno_text() { return std::strerror(errno); }
}  // namespace

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

void write_folder_atomic(const std::string& dir,
                         const std::function<void(const std::string& tmp_dir)>& fill) {
    const fs::path final_dir(dir);
    std::string tmp_name = final_dir.filename().string();
    tmp_name.insert(0, 1, '.');
    tmp_name.append(".partial");
    const fs::path tmp_dir = final_dir.parent_path() / tmp_name;
    std::error_code ec;
    fs::remove_all(tmp_dir, ec);
    fs::create_directories(tmp_dir, ec);
    if (ec) throw IoError(tmp_dir.string() + ": cannot create folder: " + ec.message());
    try {
        fill(tmp_dir.string());
        fs::remove_all(final_dir, ec);
        fs::rename(tmp_dir, final_dir);
    } catch (...) {
        fs::remove_all(tmp_dir, ec);
        throw;
    }
}

std::string objects_json(const FrameResult& r, int selected_id) {
    nlohmann::json objs = nlohmann::json::array();
    for (const DetectedObject& d : r.object_list) {
        nlohmann::json o = {{"id", d.id},
                            {"track_id", d.track_id},
                            {"pixels", d.pixels},
                            {"centroid_m", d.centroid},
                            {"aabb_m", {{"min", d.aabb_min}, {"max", d.aabb_max}}},
                            {"obb_m",
                             {{"centre", d.obb_centre},
                              {"axes", {{d.obb_axes[0], d.obb_axes[1], d.obb_axes[2]},
                                        {d.obb_axes[3], d.obb_axes[4], d.obb_axes[5]},
                                        {d.obb_axes[6], d.obb_axes[7], d.obb_axes[8]}}},
                              {"half_extent", d.obb_half_extent}}},
                            {"box_px", {{"u_min", d.u_min}, {"v_min", d.v_min},
                                        {"u_max", d.u_max}, {"v_max", d.v_max}}},
                            {"mean_rgb", d.mean_rgb},
                            {"source_clusters", d.source_clusters},
                            {"source_segments", d.source_segments}};
        if (selected_id != 0) o["selected"] = d.id == selected_id;
        objs.push_back(std::move(o));
    }
    nlohmann::json j = {{"objects", objs}, {"support_plane", nullptr}};
    if (r.plane.found) {
        const Plane& pl = r.plane.support;
        j["support_plane"] = {{"normal", {pl.nx, pl.ny, pl.nz}}, {"d_m", pl.d}};
    }
    return j.dump(1) + "\n";
}

void write_frame(const std::string& out_dir, const std::string& name, const Pipeline& pipeline,
                 const RgbdFrame& frame, const FrameResult& r, const FrameOutputs& extra) {
    write_folder_atomic((fs::path(out_dir) / name).string(), [&](const std::string& dir) {
        const fs::path tmp_dir(dir);
        write_label_png((tmp_dir / "labels.png").string(), r.labels);
        write_color_png((tmp_dir / "colors.png").string(), r.colors);
        if (extra.selected)
            write_mask_png((tmp_dir / "selected.png").string(), r.labels.width,
                           r.labels.height, *extra.selected);
        write_label_png((tmp_dir / "objects.png").string(), r.objects);
        write_text_file((tmp_dir / "objects.json").string(), objects_json(r, extra.selected_id));
        if (extra.selected_object)
            write_mask_png((tmp_dir / "selected_object.png").string(), r.objects.width,
                           r.objects.height, *extra.selected_object);
        if (extra.ply && pipeline.cloud().size() == r.labels.labels.size()) {
            write_ply((tmp_dir / "cloud.ply").string(), pipeline.cloud(), r.labels, r.colors);
        } else if (extra.ply) {  // decimation: the results are at the input's size, the cloud not
            OrganizedCloud full;
            back_project(frame, full);
            write_ply((tmp_dir / "cloud.ply").string(), full, r.labels, r.colors);
        }
    });
}

}  // namespace wul3d
