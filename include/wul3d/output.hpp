#pragma once
/// @file output.hpp
/// What `wul3d run` writes for one frame, as library calls an embedding program can make:
/// the frame folder OUT/<frame>/ (labels.png, colors.png, objects.png, objects.json, and on
/// request selected.png, selected_object.png, overlay.png, cloud.ply), the objects.json schema, and the
/// one atomic-write helper every writer of wul3d goes through (docs/OUTPUTS.md).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "wul3d/frame.hpp"
#include "wul3d/pipeline.hpp"

namespace wul3d {

/// The files wul3d writes directly in OUT, besides the frame folders: the run's summary
/// and the per-frame statistics, one JSON line per frame, appended as frames are written.
inline constexpr const char* kSummaryFile = "summary.json";
inline constexpr const char* kFramesFile = "frames.jsonl";

/// Writes `size` bytes to `path` through a temporary sibling `.wul3d.tmp-<pid>-<n>` (short
/// whatever the name's length) and a rename, so a failure never leaves a partial file under
/// the final name. Throws IoError naming the path.
void write_file_atomic(const std::string& path, const void* data, std::size_t size);

/// Makes the folder `dir` complete or not at all: `fill` writes into a new hidden sibling
/// `.wul3d.partial-<pid>-<n>`, which is then renamed to `dir`. Where `dir` exists already,
/// the new files replace theirs one by one, those of `own_names` that the new folder lacks
/// are removed, and nothing else in it is touched: a folder is never removed with files
/// wul3d did not write. If `fill` throws, the partial folder is removed and the exception
/// goes on; a failed rename is an IoError naming `dir`.
void write_folder_atomic(const std::string& dir,
                         const std::function<void(const std::string& tmp_dir)>& fill,
                         const std::vector<std::string>& own_names = {});

/// The files write_frame may write in OUT/<frame>/.
const std::vector<std::string>& frame_output_files();

/// Throws InputError unless `name` can be a frame folder in OUT: one path component (not
/// empty, ".", ".." nor with '/'), at most 255 bytes, not starting with '.' (wul3d's
/// temporaries), and neither kSummaryFile nor kFramesFile.
void check_frame_name(const std::string& name);

/// Makes OUT ready for a run: creates it if missing. An existing OUT may hold only what
/// wul3d writes (kSummaryFile, kFramesFile, its temporaries, frame folders of
/// frame_output_files()); anything else is an InputError naming it, unless `overwrite`,
/// and even then only wul3d's own files are replaced (write_folder_atomic). Throws IoError
/// when OUT cannot be created or listed.
void prepare_out_dir(const std::string& out, bool overwrite);

/// objects.json of one frame: every object with its boxes, colour and sources, and the
/// support plane (null when none was found). `selected_id` != 0 adds "selected" to every
/// object (true for the object with that id). Ends with a newline.
std::string objects_json(const FrameResult& result, int selected_id = 0);

/// What write_frame writes beyond the four images and objects.json.
/// Which files of OUT/<frame>/ are written. The first four by default: labels.png and
/// colors.png are the paper's outputs (its clusters, eq. 9's colours), objects.png and
/// objects.json the objects (what `wul3d eval` scores and what an object user reads).
/// Each costs a PNG encode (or the JSON text) a frame, the largest part of a run's output
/// time, so a user who needs only the objects leaves the others out (`wul3d run --outputs
/// objects,json`). cloud.ply and overlay.png are written on request.
struct OutputFiles {
    bool labels = true;    ///< labels.png: the paper's clusters, 16-bit
    bool colors = true;    ///< colors.png: eq. 9's display colours
    bool objects = true;   ///< objects.png: 0 background, else track id, 16-bit
    bool json = true;      ///< objects.json
    bool ply = false;      ///< cloud.ply: the labelled points, binary PLY
    /// overlay.png: the objects tinted, outlined and numbered over the frame's colour
    /// (render_object_overlay; over a grey depth picture for a depth-only frame).
    bool overlay = false;

    bool any() const { return labels || colors || objects || json || ply || overlay; }
    /// Whether a file asked for shows eq. 9's colours: colors.png, or cloud.ply (its
    /// points' colours). Without, a run need not make them (PipelineParams::render_colors).
    bool reads_colors() const { return colors || ply; }
};

/// "labels,colors,objects,json,ply,overlay": a comma-separated subset, in any order, at
/// least one. ParamError names an unknown or repeated name.
OutputFiles parse_output_files(const std::string& names);
/// The names of the files `files` asks for, comma-separated, in the order above.
std::string output_files_names(const OutputFiles& files);

struct FrameOutputs {
    /// selected.png: the followed cluster's mask (255 = in it), or nullptr for none.
    const Mask* selected = nullptr;
    /// selected_object.png: the followed object's mask, or nullptr for none.
    const Mask* selected_object = nullptr;
    int selected_id = 0;  ///< objects.json's "selected" (see objects_json)
    OutputFiles files;    ///< which of the frame's files are written
};

/// Writes one frame's outputs to OUT/<name>/ atomically (write_folder_atomic): the files
/// `extra.files` asks for (by default labels.png, colors.png, objects.png, objects.json)
/// and the selection's masks. `frame` is the frame
/// `result` came from (registered); `pipeline` the one that processed it (its cloud is
/// reused for cloud.ply when it has the frame's size). Throws IoError.
void write_frame(const std::string& out_dir, const std::string& name, const Pipeline& pipeline,
                 const RgbdFrame& frame, const FrameResult& result,
                 const FrameOutputs& extra = {});
/// The same with the cloud the stages ran on given directly (nullptr: cloud.ply is
/// back-projected from `frame`), for a writer that no longer has the pipeline at hand.
void write_frame(const std::string& out_dir, const std::string& name, const OrganizedCloud* cloud,
                 const RgbdFrame& frame, const FrameResult& result,
                 const FrameOutputs& extra = {});

}  // namespace wul3d
