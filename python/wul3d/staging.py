"""What the batch writes and how (wul3d.batch; docs/SCALE.md): a sequence's output folder,
what in it wul3d wrote (the only things the batch removes or replaces), the staging folders
a task runs into, and the move of a finished one into place.
"""

import os
import pathlib
import stat

from . import _wul3d
from .discovery import text

STAGING_PREFIX = ".wul3d.staging-"  # OUT/.wul3d.staging-<pid>-<id>/: one batch's tries
LIVE_MARKER = ".wul3d.live"  # in a staging folder while its batch runs
OWN_PREFIX = ".wul3d."  # names wul3d keeps for itself in OUT (check_frame_name refuses them)
DONE_MARKER = "summary.json"  # written last by the run loop
FRAMES_FILE = "frames.jsonl"
# The files wul3d writes in a frame folder: the library's frame_output_files()
# (src/run/output.cpp).
FRAME_OUTPUT_FILES = frozenset(_wul3d._frame_output_files())


def output_dir(out, root, rel) -> pathlib.Path:
    """OUT/<rel>, or OUT/<root's name> for root itself."""
    return pathlib.Path(out) / (pathlib.Path(root).resolve().name if rel == "." else rel)


def is_finished(out_dir: pathlib.Path) -> bool:
    """Whether summary.json, the run loop's last write, is there (a plain file)."""
    try:
        st = os.lstat(pathlib.Path(out_dir) / DONE_MARKER)
    except OSError:
        return False
    return stat.S_ISREG(st.st_mode)


def lstat_or_none(path):
    """os.lstat (links not followed), or None where it fails."""
    try:
        return os.lstat(path)
    except OSError:
        return None


def _own_listing(d):
    """(the entries of folder `d` by name, but for `.wul3d.*` temporaries, None), or
    ([], why it cannot be listed)."""
    try:
        entries = sorted(os.scandir(d), key=lambda e: e.name)
    except OSError as e:
        return [], f"{text(str(d))} ({e.strerror})"
    return [e for e in entries if not e.name.startswith(OWN_PREFIX)], None


def _foreign_in_frame_folder(d: pathlib.Path):
    """The first entry of frame folder `d` that write_frame does not write, or None."""
    entries, why = _own_listing(d)
    for e in entries:
        if e.name not in FRAME_OUTPUT_FILES or not e.is_file(follow_symlinks=False):
            return text(e.path)
    return why


def foreign_entry(out_dir, nested=()):
    """The first thing in the sequence output `out_dir` that wul3d did not write, or None:
    the library's rule for an existing OUT (prepare_out_dir): summary.json and frames.jsonl
    as plain files, `.wul3d.*` temporaries, frame folders holding only frame outputs; and
    `nested`, the names of folders that hold other sequences' outputs of this batch."""
    entries, why = _own_listing(out_dir)
    for e in entries:
        if e.name in (DONE_MARKER, FRAMES_FILE):
            if not e.is_file(follow_symlinks=False):
                return text(e.path)
            continue
        if not e.is_dir(follow_symlinks=False):
            return text(e.path)
        if e.name in nested:
            continue
        what = _foreign_in_frame_folder(pathlib.Path(e.path))
        if what is not None:
            return what
    return why


def _is_run_output(d: pathlib.Path) -> bool:
    """Whether `d` holds only what a run into it writes (a task's staging folder)."""
    return lstat_or_none(d) is not None and stat.S_ISDIR(lstat_or_none(d).st_mode) and \
        foreign_entry(d) is None


def remove_run_output(d: pathlib.Path) -> bool:
    """Removes the folder `d` if it holds only what wul3d writes (foreign_entry's rule):
    its files of those names, its frame folders, then itself. Anything else stays (and so
    does `d`). Returns whether `d` is gone."""
    if not _is_run_output(d):
        return False
    for e in list(os.scandir(d)):
        try:
            if e.is_dir(follow_symlinks=False):
                for f in list(os.scandir(e.path)):
                    if f.is_dir(follow_symlinks=False):  # a .wul3d.partial-* of a killed run
                        remove_run_output(pathlib.Path(f.path))
                    elif f.name in FRAME_OUTPUT_FILES or f.name.startswith(OWN_PREFIX):
                        os.unlink(f.path)
                os.rmdir(e.path)
            elif e.name in (DONE_MARKER, FRAMES_FILE) or e.name.startswith(OWN_PREFIX):
                os.unlink(e.path)
        except OSError:
            pass
    try:
        os.rmdir(d)
        return True
    except OSError:
        return False


def make_staging(staging: pathlib.Path):
    """A batch's staging folder, with the marker that tells its tasks it is live."""
    staging.mkdir()
    fd = os.open(staging / LIVE_MARKER, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW
                 | os.O_CLOEXEC, 0o644)
    os.close(fd)


def remove_staging(staging: pathlib.Path) -> bool:
    """Removes a batch's staging folder: each task folder in it that holds only run outputs,
    then the folder if that emptied it. Returns whether it is gone."""
    try:
        entries = list(os.scandir(staging))
    except FileNotFoundError:
        return True
    except OSError:
        return False
    for e in entries:
        if e.is_dir(follow_symlinks=False):
            remove_run_output(pathlib.Path(e.path))
        elif e.name == LIVE_MARKER and e.is_file(follow_symlinks=False):
            os.unlink(e.path)
    try:
        os.rmdir(staging)
        return True
    except OSError:
        return False


class Refused(ValueError):
    """A sequence's output would replace what wul3d did not write."""


def check_write_target(target, kind, inputs, flag):
    _wul3d._check_write_target(os.fsencode(target), kind, [os.fsencode(i) for i in inputs],
                               flag)


def _replace_file(entry: pathlib.Path, target: pathlib.Path):
    """Moves `entry` to `target`, replacing a plain file there; a link, hard link, FIFO or
    folder under the name is refused (the library's guard), not replaced."""
    check_write_target(target, "file", [], text(str(target)))
    os.replace(entry, target)


def no_link_on_the_way(top: pathlib.Path, final: pathlib.Path):
    """Refuses a symbolic link among the folders between OUT and `final` (OUT/a -> elsewhere
    for the sequence a/b): outputs are never written through a link out of OUT."""
    path = top
    for part in final.relative_to(top).parts[:-1]:
        path = path / part
        st = lstat_or_none(path)
        if st is not None and stat.S_ISLNK(st.st_mode):
            raise Refused(f"{text(str(path))}: is a symbolic link; the batch writes no output "
                          "through one: move it away")


def publish(staging: pathlib.Path, final: pathlib.Path, nested=(), overwrite=False):
    """Moves a complete staging folder to `final`: one rename when `final` does not exist;
    else (it holds a nested sequence's output, or an unfinished earlier try) entry by entry
    with the marker last, and in a frame folder file by file, only the files of
    FRAME_OUTPUT_FILES: nothing wul3d did not write is removed or replaced. An existing
    `final` holding anything else is Refused, unless `overwrite` (then what is foreign stays
    where it is, beside the new outputs)."""
    final.parent.mkdir(parents=True, exist_ok=True)
    if lstat_or_none(final) is None:
        try:
            os.rename(staging, final)
            return
        except OSError:
            if lstat_or_none(final) is None:
                raise
    st = lstat_or_none(final)
    if not stat.S_ISDIR(st.st_mode):  # a link (never followed) or a file
        raise Refused(f"{text(str(final))}: exists and is not a folder wul3d wrote; "
                      "move it away")
    if not overwrite:
        what = foreign_entry(final, nested)
        if what is not None:
            raise Refused(f"{text(str(final))}: holds what wul3d did not write ({what}); "
                          "choose another --out, or --overwrite to replace only wul3d's "
                          "own files there")
    marker = final / DONE_MARKER
    m = lstat_or_none(marker)
    if m is not None and stat.S_ISREG(m.st_mode):
        marker.unlink()  # unfinished until the new marker is in place
    entries = sorted(staging.iterdir(), key=lambda p: (p.name == DONE_MARKER, p.name))
    for entry in entries:
        target = final / entry.name
        if not entry.is_dir() or entry.is_symlink():
            _replace_file(entry, target)
            continue
        t = lstat_or_none(target)
        if t is None:
            os.rename(entry, target)
            continue
        if not stat.S_ISDIR(t.st_mode):
            raise Refused(f"{text(str(target))}: exists and is not a frame folder; move it away")
        new = {f.name for f in entry.iterdir()}
        for name in sorted(new):
            _replace_file(entry / name, target / name)
        for name in sorted(FRAME_OUTPUT_FILES - new):  # what an earlier run wrote, not this
            old = lstat_or_none(target / name)
            if old is not None and stat.S_ISREG(old.st_mode):
                (target / name).unlink()
        entry.rmdir()
    staging.rmdir()
