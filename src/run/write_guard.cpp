// The guard every writer goes through (write_guard.hpp): targets apart from the inputs, no
// link followed out, one writer per output folder, and the leftovers of killed writers.
#include "wul3d/write_guard.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "wul3d/error.hpp"
#include "wul3d/output.hpp"

namespace wul3d {
namespace fs = std::filesystem;

namespace {

std::string errno_text() { return std::strerror(errno); }

/// `p` absolute, with `.`, `..` and symbolic links resolved as far as it exists.
fs::path resolved(const std::string& p) {
    std::error_code ec;
    const fs::path abs = fs::absolute(p, ec).lexically_normal();
    const fs::path c = fs::weakly_canonical(abs, ec);
    fs::path r = ec ? abs : c;
    if (r.filename().empty()) r = r.parent_path();  // no trailing separator
    return r;
}

/// Whether `inner` is `outer` or lies under it.
bool within(const fs::path& inner, const fs::path& outer) {
    auto o = outer.begin(), i = inner.begin();
    for (; o != outer.end(); ++o, ++i)
        if (i == inner.end() || *i != *o) return false;
    return true;
}

/// Why an existing file may not be written in place of, or nullptr.
const char* file_refusal(const struct stat& st) {
    if (S_ISLNK(st.st_mode)) return "is a symbolic link (its target would be written)";
    if (S_ISDIR(st.st_mode)) return "is a folder";
    if (!S_ISREG(st.st_mode)) return "is not a regular file (a FIFO, a device or a socket)";
    if (st.st_nlink > 1) return "is a hard link (another name of the same file would change)";
    return nullptr;
}

bool is_temporary_name(const std::string& name) {
    return name.rfind(".wul3d.tmp-", 0) == 0 || name.rfind(".wul3d.partial-", 0) == 0;
}

/// Whether the folder `dir` holds only frame outputs and temporaries (what write_frame puts
/// in a partial folder), so that removing it removes nothing wul3d did not write.
bool holds_only_outputs(const fs::path& dir) {
    const auto& own = frame_output_files();
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (!e.is_regular_file(ec) || e.is_symlink(ec)) return false;
        if (std::find(own.begin(), own.end(), name) == own.end() && !is_temporary_name(name))
            return false;
    }
    return !ec;
}

/// Removes the temporaries directly in `dir`; returns how many went.
std::size_t remove_temporaries_in(const fs::path& dir) {
    std::size_t removed = 0;
    std::error_code ec;
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (is_temporary_name(e.path().filename().string())) found.push_back(e.path());
    for (const fs::path& p : found) {
        const auto st = fs::symlink_status(p, ec);
        if (fs::is_regular_file(st)) {
            removed += fs::remove(p, ec) ? 1 : 0;
        } else if (fs::is_directory(st) && holds_only_outputs(p)) {
            removed += fs::remove_all(p, ec) > 0 ? 1 : 0;
        }
    }
    return removed;
}

}  // namespace

void check_write_target(const std::string& target, WriteTarget kind,
                        const std::vector<std::string>& inputs, const std::string& flag) {
    const std::string what = (flag.empty() ? std::string("output") : flag) + " " + target;
    if (target.empty()) throw InputError(what + ": an empty path");
    struct stat st{};
    if (::lstat(target.c_str(), &st) == 0) {
        if (kind == WriteTarget::File) {
            if (const char* why = file_refusal(st))
                throw InputError(what + " " + why + "; wul3d writes only new or plain files");
        } else if (S_ISLNK(st.st_mode)) {
            struct stat to{};
            if (::stat(target.c_str(), &to) != 0)
                throw InputError(what + " is a symbolic link to nothing (" + errno_text() +
                                 "); remove it or choose another folder");
            if (!S_ISDIR(to.st_mode)) throw InputError(what + " exists and is not a folder");
        } else if (!S_ISDIR(st.st_mode)) {
            throw InputError(what + " exists and is not a folder");
        }
    }
    const fs::path out = resolved(target);
    std::error_code ec;
    for (const std::string& input : inputs) {
        if (input.empty() || !fs::exists(fs::symlink_status(input, ec))) continue;
        const fs::path in = resolved(input);
        const char* how = out == in                                      ? "is the input"
                          : within(out, in)                               ? "lies inside the input"
                          : kind == WriteTarget::Folder && within(in, out) ? "contains the input"
                                                                          : nullptr;
        if (how)
            throw InputError(what + " " + how + " " + input +
                             "; the outputs would overwrite it: choose an output apart");
    }
}

OutputLock::OutputLock(const std::string& dir) {
    // The folder itself is locked: no lock file to leave behind or to be planted as a link.
    fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) throw IoError(dir + ": cannot open the output folder to lock it (" + errno_text() + ")");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        ::close(fd_);
        if (err == EWOULDBLOCK)
            throw InputError(dir + ": another wul3d process is writing this output folder; "
                             "wait for it or choose another");
        throw IoError(dir + ": cannot lock (" + std::strerror(err) + ")");
    }
}

OutputLock::~OutputLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

int open_new_append_file(const std::string& path) {
    struct stat st{};
    if (::lstat(path.c_str(), &st) == 0) {
        if (const char* why = file_refusal(st))
            throw InputError(path + " " + why + "; not replaced: remove it");
        if (::unlink(path.c_str()) != 0 && errno != ENOENT)
            throw IoError(path + ": cannot replace (" + errno_text() + ")");
    }
    const int fd =
        ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw IoError(path + ": cannot write (" + errno_text() + ")");
    return fd;
}

std::size_t remove_stale_temporaries(const std::string& dir) {
    std::size_t removed = remove_temporaries_in(dir);
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_directory(ec) && !e.is_symlink(ec) &&
            !is_temporary_name(e.path().filename().string()))
            removed += remove_temporaries_in(e.path());
    return removed;
}

}  // namespace wul3d
