// The guard of every write (write_guard.hpp, issue 46): targets apart from the inputs, no
// link followed out, one writer per output folder, leftovers of killed writers removed; the
// library calls, then `wul3d run` on the cases of the issue (frames.jsonl as a link, a hard
// link and a FIFO; two runs into one OUT; a run killed mid-write).
#include "wul3d/write_guard.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"

namespace {

namespace fs = std::filesystem;
using wul3d::check_write_target;
using wul3d::InputError;
using wul3d::WriteTarget;
using wul3d::test::CommandResult;
using wul3d::test::run_bounded;
using wul3d::test::slurp;
using wul3d::test::TempDir;
using wul3d::test::write_text;

/// The message of the InputError that `f` throws, or "" when it throws none.
template <class F>
std::string refusal(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return {};
}

/// A copy of one shipped frame as a one-frame recording in `dir`/rec/image_0000.
fs::path recording(const TempDir& tmp) {
    wul3d::test::copy_frame(wul3d::test::sample_dir() / "uois_tabletop" / "image_0000",
                            tmp / "rec" / "image_0000");
    return tmp / "rec";
}

// ---- the library -----------------------------------------------------------------------------

TEST(WriteGuard, FolderThatIsInsideOrHoldsAnInputIsRefused) {
    TempDir tmp;
    const fs::path in = recording(tmp);
    fs::create_directory(tmp / "elsewhere");
    fs::create_directory_symlink(in, tmp / "link_to_input");
    const std::vector<std::string> inputs = {in.string()};
    EXPECT_NE(refusal([&] { check_write_target(in.string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_NE(refusal([&] { check_write_target((in / "image_0000" / "out").string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_NE(refusal([&] { check_write_target(tmp.path().string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_NE(refusal([&] { check_write_target((tmp / "link_to_input").string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_NE(refusal([&] { check_write_target((in / "image_0000" / ".." / ".").string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_EQ(refusal([&] { check_write_target((tmp / "elsewhere").string(), WriteTarget::Folder, inputs); }), "");
    EXPECT_EQ(refusal([&] { check_write_target((tmp / "new" / "out").string(), WriteTarget::Folder, inputs); }), "");
}

TEST(WriteGuard, FileThatIsAnInputOrALinkOutIsRefused) {
    TempDir tmp;
    const fs::path in = recording(tmp);
    const fs::path depth = in / "image_0000" / "depth.png";
    const std::vector<std::string> inputs = {in.string()};
    // The cases: --video, --screenshot, --csv, --json naming a file of the input.
    const std::string is_input = refusal([&] { check_write_target(depth.string(), WriteTarget::File, inputs, "--csv"); });
    EXPECT_NE(is_input.find("--csv"), std::string::npos) << is_input;
    EXPECT_NE(is_input.find("input"), std::string::npos) << is_input;
    // A file beside the input, not in it: written.
    EXPECT_EQ(refusal([&] { check_write_target((tmp / "bench.csv").string(), WriteTarget::File, inputs); }), "");
    // Links: a symbolic link (even to a file apart), a hard link, a FIFO, a folder.
    write_text(tmp / "apart.txt", "x");
    fs::create_symlink(tmp / "apart.txt", tmp / "sym.csv");
    fs::create_hard_link(tmp / "apart.txt", tmp / "hard.csv");
    ASSERT_EQ(::mkfifo((tmp / "fifo.csv").c_str(), 0600), 0);
    for (const char* name : {"sym.csv", "hard.csv", "fifo.csv", "rec"})
        EXPECT_NE(refusal([&] { check_write_target((tmp / name).string(), WriteTarget::File, {}); }), "") << name;
    EXPECT_EQ(slurp(tmp / "apart.txt"), "x");
}

TEST(WriteGuard, DanglingLinkAsFolderIsNamedAsSuch) {
    TempDir tmp;
    fs::create_directory_symlink(tmp / "gone", tmp / "out");
    const std::string why = refusal([&] { check_write_target((tmp / "out").string(), WriteTarget::Folder, {}, "--out"); });
    EXPECT_NE(why.find("symbolic link to nothing"), std::string::npos) << why;
}

TEST(WriteGuard, SecondLockOfOneFolderIsRefused) {
    TempDir tmp;
    {
        const wul3d::OutputLock first(tmp.path().string());
        // flock locks belong to the open file: a second open in the same process conflicts too.
        const std::string why = refusal([&] { wul3d::OutputLock second(tmp.path().string()); });
        EXPECT_NE(why.find("another wul3d process"), std::string::npos) << why;
    }
    EXPECT_NO_THROW(wul3d::OutputLock again(tmp.path().string()));  // released with the first
}

TEST(WriteGuard, NewAppendFileReplacesAPlainFileAndRefusesLinks) {
    TempDir tmp;
    write_text(tmp / "input.json", "{\"fx\": 525}\n");
    fs::create_symlink(tmp / "input.json", tmp / "sym.jsonl");
    fs::create_hard_link(tmp / "input.json", tmp / "hard.jsonl");
    for (const char* name : {"sym.jsonl", "hard.jsonl"})
        EXPECT_NE(refusal([&] { ::close(wul3d::open_new_append_file((tmp / name).string())); }), "") << name;
    EXPECT_EQ(slurp(tmp / "input.json"), "{\"fx\": 525}\n");
    write_text(tmp / "old.jsonl", "old lines\n");
    const int fd = wul3d::open_new_append_file((tmp / "old.jsonl").string());
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, "new\n", 4), 4);
    ::close(fd);
    EXPECT_EQ(slurp(tmp / "old.jsonl"), "new\n");
}

TEST(WriteGuard, StaleTemporariesGoForeignFoldersStay) {
    TempDir tmp;
    fs::create_directories(tmp / "image_0000");
    fs::create_directories(tmp / ".wul3d.partial-99999-0");
    write_text(tmp / ".wul3d.partial-99999-0" / "labels.png", "half");
    write_text(tmp / ".wul3d.tmp-99999-1", "half");
    write_text(tmp / "image_0000" / ".wul3d.tmp-99999-2", "half");
    // A partial folder holding a file wul3d never writes is not wul3d's to remove.
    fs::create_directories(tmp / ".wul3d.partial-99999-3");
    write_text(tmp / ".wul3d.partial-99999-3" / "notes.txt", "the user's");
    EXPECT_EQ(wul3d::remove_stale_temporaries(tmp.path().string()), 3u);
    EXPECT_FALSE(fs::exists(tmp / ".wul3d.partial-99999-0"));
    EXPECT_FALSE(fs::exists(tmp / ".wul3d.tmp-99999-1"));
    EXPECT_FALSE(fs::exists(tmp / "image_0000" / ".wul3d.tmp-99999-2"));
    EXPECT_EQ(slurp(tmp / ".wul3d.partial-99999-3" / "notes.txt"), "the user's");
}

// ---- wul3d run ---------------------------------------------------------------------------------

// Issue 46, cases 3 and 7: OUT/frames.jsonl as a link to an input file, a hard link of one,
// and a FIFO. The input stays byte for byte, the run ends at once with exit 2.
TEST(WriteGuardCli, FramesFileThatIsALinkOrAFifoIsRefused) {
    TempDir tmp;
    const fs::path in = recording(tmp);
    const fs::path intrinsics = in / "image_0000" / "intrinsics.json";
    const std::string before = slurp(intrinsics);
    for (const char* kind : {"symlink", "hardlink", "fifo"}) {
        const fs::path out = tmp / (std::string("out_") + kind);
        fs::create_directories(out);
        const fs::path jsonl = out / "frames.jsonl";
        const std::string k = kind;
        if (k == "symlink") {
            fs::create_symlink(intrinsics, jsonl);
        } else if (k == "hardlink") {
            fs::create_hard_link(intrinsics, jsonl);
        } else {
            ASSERT_EQ(::mkfifo(jsonl.c_str(), 0600), 0);
        }
        for (const bool overwrite : {false, true}) {
            std::vector<std::string> args = {"run", in.string(), "--out", out.string(), "-q"};
            if (overwrite) args.push_back("--overwrite");
            const CommandResult r = run_bounded(args);
            EXPECT_EQ(r.exit_code, 2) << kind << " overwrite " << overwrite << "\n" << r.err;
            EXPECT_NE(r.err.find("frames.jsonl"), std::string::npos) << r.err;
        }
        EXPECT_EQ(slurp(intrinsics), before) << kind;
    }
}

// Issue 46, case 13: a second run into an OUT that a run is writing fails at once instead
// of interleaving frames.jsonl.
TEST(WriteGuardCli, SecondRunIntoALockedOutputIsRefused) {
    TempDir tmp;
    const fs::path in = recording(tmp);
    const fs::path out = tmp / "out";
    fs::create_directories(out);
    const wul3d::OutputLock held(out.string());  // as a run in progress holds it
    const CommandResult r = run_bounded({"run", in.string(), "--out", out.string(), "-q"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("another wul3d process"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "frames.jsonl"));
}

// Issue 46, case 16: what a run killed mid-write left in OUT is gone after the next run.
TEST(WriteGuardCli, NextRunRemovesAKilledRunsTemporaries) {
    TempDir tmp;
    const fs::path in = recording(tmp);
    const fs::path out = tmp / "out";
    fs::create_directories(out / ".wul3d.partial-4242-0");
    write_text(out / ".wul3d.partial-4242-0" / "labels.png", "half");
    write_text(out / ".wul3d.tmp-4242-1", "half");
    const CommandResult r = run_bounded({"run", in.string(), "--out", out.string(), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::exists(out / ".wul3d.partial-4242-0"));
    EXPECT_FALSE(fs::exists(out / ".wul3d.tmp-4242-1"));
    EXPECT_TRUE(fs::is_regular_file(out / "image_0000" / "objects.png"));
}

}  // namespace
