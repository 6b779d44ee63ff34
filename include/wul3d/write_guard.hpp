#pragma once
/// @file write_guard.hpp
/// The one guard every writer of wul3d goes through before it writes a file or a folder
/// (`wul3d run`, the batch, `view --screenshot`, `bench --csv`, `eval --json`, `run --video`,
/// `record`, `export-fakenect`, the Python module): a target never is, lies inside or holds an
/// input of the call; a link is never followed out; and one output folder has one writer at a
/// time (docs/OUTPUTS.md, "What wul3d will not overwrite").
#include <string>
#include <vector>

namespace wul3d {

/// What a writer is about to write.
enum class WriteTarget {
    File,    ///< one file, created or replaced whole (write_file_atomic)
    Folder,  ///< an output folder that the writer fills (OUT)
};

/// Throws InputError (one line, naming `flag` and the target) unless `target` may be written:
/// - it is not one of `inputs`, does not lie inside one, and (a folder) does not hold one;
///   paths are compared absolute, with `.`, `..` and symbolic links resolved as far as they
///   exist, so no spelling of the same place gets through;
/// - a File target that exists is a regular file with one name: not a symbolic link (a
///   link's target would be written, wherever it points), not a hard link (an input may be
///   the other name), not a FIFO or device (a write would block or go elsewhere), not a folder;
/// - a Folder target that exists is a folder; a dangling symbolic link is refused by name.
/// `flag` is how the caller names the target in messages ("--out", "--video"); empty: "output".
/// Inputs that do not exist are skipped (a live camera, a device spec).
void check_write_target(const std::string& target, WriteTarget kind,
                        const std::vector<std::string>& inputs, const std::string& flag = {});

/// An advisory lock (flock) on an output folder, held while a run or a batch writes into it:
/// a second writer of the same folder fails at once with an InputError naming the folder,
/// instead of interleaving its files. The folder itself is locked (no lock file is left in
/// it). Released by the destructor or by the process's end, however it ends.
class OutputLock {
public:
    /// Locks `dir`, which must exist. Throws InputError when another process holds it,
    /// IoError when the lock file cannot be opened.
    explicit OutputLock(const std::string& dir);
    ~OutputLock();
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;

private:
    int fd_ = -1;
};

/// Opens `path` for appending as a new, empty regular file and returns its descriptor: an
/// existing regular file of that name with one link is unlinked first (replaced, never
/// truncated in place), anything else there (a symbolic link, a hard-linked file, a FIFO, a
/// folder) is refused with an InputError; the new file is created with O_EXCL and
/// O_NOFOLLOW, so a link made in between is not followed either. Throws IoError when the
/// file cannot be created.
int open_new_append_file(const std::string& path);

/// Removes what an earlier wul3d process left in `dir` and in its direct sub-folders when it
/// was killed mid-write: `.wul3d.tmp-*` files and `.wul3d.partial-*` folders that hold only
/// frame outputs (frame_output_files()) and temporaries. Call with the OutputLock held (no
/// other writer is then using them). Returns how many entries were removed. Never throws.
std::size_t remove_stale_temporaries(const std::string& dir);

}  // namespace wul3d
