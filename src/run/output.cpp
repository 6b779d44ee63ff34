// The outputs of one frame (output.hpp): the atomic writes every writer uses, the
// objects.json schema and the frame folder OUT/<frame>/.
#include "wul3d/output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/io_detail.hpp"
#include "io/png_encode.hpp"
#include "json_text.hpp"
#include "output_detail.hpp"
#include "wul3d/error.hpp"
#include "wul3d/io.hpp"
#include "wul3d/visualization.hpp"

namespace wul3d {
namespace fs = std::filesystem;

namespace {
std::string errno_text() { return std::strerror(errno); }
}  // namespace

namespace {
/// A temporary name in `dir` of at most 40 bytes, whatever the final name's length (a name
/// of 250 bytes plus a suffix would pass NAME_MAX, 255), unique in this process.
fs::path temp_name(const fs::path& dir, const char* kind) {
    static std::atomic<unsigned> serial{0};
    return dir / (std::string(".wul3d.") + kind + "-" + std::to_string(::getpid()) + "-" +
                  std::to_string(serial++));
}
}  // namespace

void write_file_atomic(const std::string& path, const void* data, std::size_t size) {
    const std::string tmp = temp_name(fs::path(path).parent_path(), "tmp").string();
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
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
                         const std::function<void(const std::string& tmp_dir)>& fill,
                         const std::vector<std::string>& own_names) {
    const fs::path final_dir(dir);
    const fs::path tmp_dir = temp_name(final_dir.parent_path(), "partial");
    std::error_code ec;
    // The parent may not exist yet (a recording's first frame): made here, never removed.
    if (!final_dir.parent_path().empty()) fs::create_directories(final_dir.parent_path(), ec);
    if (!fs::create_directory(tmp_dir, ec) || ec)
        throw IoError(tmp_dir.string() + ": cannot create folder" + (ec ? ": " + ec.message() : ""));
    try {
        fill(tmp_dir.string());
        const auto status = fs::symlink_status(final_dir, ec);
        if (!fs::exists(status)) {
            fs::rename(tmp_dir, final_dir);
            return;
        }
        if (!fs::is_directory(status))
            throw IoError(dir + ": exists and is not a folder; not replaced");
        // A folder there already: only the writer's own files in it are replaced (or, those
        // the new folder lacks, removed); anything else in it stays.
        for (const std::string& name : own_names)
            if (!fs::exists(tmp_dir / name, ec)) fs::remove(final_dir / name, ec);
        for (const auto& e : fs::directory_iterator(tmp_dir))
            fs::rename(e.path(), final_dir / e.path().filename());
        fs::remove(tmp_dir);
    } catch (const fs::filesystem_error& e) {
        fs::remove_all(tmp_dir, ec);  // the folder this call made, holding only its files
        throw IoError(dir + ": cannot write (" + e.code().message() + ")");
    } catch (...) {
        fs::remove_all(tmp_dir, ec);
        throw;
    }
}

namespace {
/// OutputFiles's names and members, in the order of output_files_names.
const std::vector<std::pair<const char*, bool OutputFiles::*>>& output_file_members() {
    static const std::vector<std::pair<const char*, bool OutputFiles::*>> members = {
        {"labels", &OutputFiles::labels}, {"colors", &OutputFiles::colors},
        {"objects", &OutputFiles::objects}, {"json", &OutputFiles::json},
        {"ply", &OutputFiles::ply}, {"overlay", &OutputFiles::overlay}};
    return members;
}
}  // namespace

OutputFiles parse_output_files(const std::string& names) {
    OutputFiles files;
    for (const auto& member : output_file_members()) files.*member.second = false;
    std::string known;
    for (const auto& member : output_file_members()) {
        if (!known.empty()) known += ", ";
        known += member.first;
    }
    std::size_t start = 0;
    for (;;) {
        const std::size_t end = std::min(names.find(',', start), names.size());
        const std::string name = names.substr(start, end - start);
        bool found = false;
        for (const auto& member : output_file_members()) {
            if (name != member.first) continue;
            if (files.*member.second)
                throw ParamError("outputs '" + names + "': '" + name + "' given twice");
            files.*member.second = found = true;
        }
        if (!found)
            throw ParamError("outputs '" + names + "': '" + name + "' is not one of " + known);
        if (end == names.size()) break;
        start = end + 1;
    }
    return files;
}

std::string output_files_names(const OutputFiles& files) {
    std::string names;
    for (const auto& member : output_file_members()) {
        if (!(files.*member.second)) continue;
        if (!names.empty()) names += ',';
        names += member.first;
    }
    return names;
}

const std::vector<std::string>& frame_output_files() {
    static const std::vector<std::string> names = {"labels.png",      "colors.png",
                                                   "selected.png",    "objects.png",
                                                   "objects.json",    "selected_object.png",
                                                   "cloud.ply",       "overlay.png"};
    return names;
}

void check_frame_name(const std::string& name) {
    const char* why = nullptr;
    if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
        name.find('\0') != std::string::npos)
        why = "is not a folder name";
    else if (name.size() > 255)
        why = "is longer than a file name may be (255 bytes)";
    else if (name[0] == '.')
        why = "starts with '.', which wul3d keeps for its temporary files in OUT";
    else if (name == kSummaryFile || name == kFramesFile)
        why = "is the name of a file wul3d writes in OUT";
    if (why) throw InputError("frame name '" + name + "' " + why + "; rename the frame");
}

namespace {

bool is_own_file_name(const std::string& name) { return name.rfind(".wul3d.", 0) == 0; }

/// Whether `entry` of OUT is wul3d's: summary.json, frames.jsonl, a temporary, or a frame
/// folder holding nothing but frame outputs. Sets `what` to the first foreign thing seen.
bool is_own_entry(const fs::directory_entry& entry, std::string& what) {
    const std::string name = entry.path().filename().string();
    std::error_code ec;
    if (is_own_file_name(name)) return true;
    if (name == kSummaryFile || name == kFramesFile) {
        // Only as a plain file: a link or a FIFO under the name is not wul3d's.
        if (entry.is_regular_file(ec) && !entry.is_symlink(ec)) return true;
        what = entry.path().string();
        return false;
    }
    if (!entry.is_directory(ec) || entry.is_symlink(ec)) {
        what = entry.path().string();
        return false;
    }
    const auto& own = frame_output_files();
    for (const auto& e : fs::directory_iterator(entry.path(), ec)) {
        const std::string file = e.path().filename().string();
        if ((!e.is_regular_file(ec) || std::find(own.begin(), own.end(), file) == own.end()) &&
            !is_own_file_name(file)) {
            what = e.path().string();
            return false;
        }
    }
    if (ec) {
        what = entry.path().string() + " (" + ec.message() + ")";
        return false;
    }
    return true;
}

}  // namespace

void prepare_out_dir(const std::string& out, bool overwrite) {
    const fs::path dir(out);
    std::error_code ec;
    const auto status = fs::status(dir, ec);
    if (!fs::exists(status)) {
        fs::create_directories(dir, ec);
        if (ec || !fs::is_directory(dir))
            throw IoError(out + ": cannot create output folder" + (ec ? ": " + ec.message() : ""));
        return;
    }
    if (!fs::is_directory(status)) throw InputError(out + ": exists and is not a folder");
    if (overwrite) return;
    std::string what;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (!is_own_entry(e, what))
            throw InputError(out + ": holds what wul3d did not write (" + what +
                             "); choose another output folder, or --overwrite to replace "
                             "only wul3d's own files there");
    if (ec) throw IoError(out + ": cannot list the folder (" + ec.message() + ")");
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
    nlohmann::json j = {{"objects", objs},
                        {"scope", r.segment_stats.scope.applied ? "support" : "scene"},
                        {"support_plane", nullptr},
                        {"low_support", nullptr}};
    if (r.plane.found) {
        const Plane& pl = r.plane.support;
        j["support_plane"] = {{"normal", {pl.nx, pl.ny, pl.nz}}, {"d_m", pl.d}};
    }
    if (r.plane.low_found) {
        const Plane& pl = r.plane.low_support;
        j["low_support"] = {{"normal", {pl.nx, pl.ny, pl.nz}}, {"d_m", pl.d}};
    }
    return json_text(j, 1) + "\n";
}

namespace {

/// overlay.png's picture: the objects over the frame's colour, or over its depth in grey
/// (near bright) for a depth-only frame.
void overlay_picture(const RgbdFrame& frame, const FrameResult& r, ColorImage& out) {
    ColorImage base;
    render_frame_picture(frame, base);
    if (r.objects.labels.size() != base.rgb.size() / 3) {
        out = std::move(base);  // no object stages ran (PipelineParams::detect_objects)
        return;
    }
    render_object_overlay(base, r.objects, r.object_list, frame.intrinsics, out);
}

}  // namespace

void write_frame(const std::string& out_dir, const std::string& name, const Pipeline& pipeline,
                 const RgbdFrame& frame, const FrameResult& r, const FrameOutputs& extra) {
    write_frame(out_dir, name, &pipeline.cloud(), frame, r, extra);
}

void write_frame(const std::string& out_dir, const std::string& name, const OrganizedCloud* cloud,
                 const RgbdFrame& frame, const FrameResult& r, const FrameOutputs& extra) {
    detail::PngEncoder encoder;
    detail::write_frame(out_dir, name, cloud, frame, r, extra, encoder);
}

void detail::write_frame(const std::string& out_dir, const std::string& name, const OrganizedCloud* cloud,
                         const RgbdFrame& frame, const FrameResult& r, const FrameOutputs& extra,
                         PngEncoder& encoder) {
    check_frame_name(name);
    write_folder_atomic((fs::path(out_dir) / name).string(), [&](const std::string& dir) {
        const fs::path tmp_dir(dir);
        const OutputFiles& files = extra.files;
        if (files.labels) detail::write_label_png((tmp_dir / "labels.png").string(), r.labels, encoder);
        if (files.colors) detail::write_color_png((tmp_dir / "colors.png").string(), r.colors, encoder);
        if (extra.selected)
            detail::write_mask_png((tmp_dir / "selected.png").string(), r.labels.width, r.labels.height,
                                   *extra.selected, encoder);
        if (files.objects) detail::write_label_png((tmp_dir / "objects.png").string(), r.objects, encoder);
        if (files.json)
            write_text_file((tmp_dir / "objects.json").string(), objects_json(r, extra.selected_id));
        if (extra.selected_object)
            detail::write_mask_png((tmp_dir / "selected_object.png").string(), r.objects.width,
                                   r.objects.height, *extra.selected_object, encoder);
        if (files.overlay) {
            ColorImage picture;
            overlay_picture(frame, r, picture);
            detail::write_color_png((tmp_dir / "overlay.png").string(), picture, encoder);
        }
        if (files.ply && cloud && cloud->size() == r.labels.labels.size()) {
            write_ply((tmp_dir / "cloud.ply").string(), *cloud, r.labels, r.colors);
        } else if (files.ply) {  // decimation: the results are at the input's size, the cloud not
            OrganizedCloud full;
            back_project(frame, full);
            write_ply((tmp_dir / "cloud.ply").string(), full, r.labels, r.colors);
        }
    }, frame_output_files());
}

}  // namespace wul3d
