"""Which sequences lie under a folder, for wul3d.batch (docs/SCALE.md): TUM, OCID, OSD and
BOP sequences, ROS 1 bags and folders of frame folders, each once, links followed safely.

The standard library only: fuzz/fuzz_batch_discovery.py loads this file alone.
"""

import os
import stat

MAX_DEPTH = 64  # folders below ROOT that discovery descends (a path stays under PATH_MAX)


def text(name) -> str:
    """`name` as valid Unicode: bytes that are not UTF-8 (a str from os.fsdecode carries them
    as lone surrogates) become \\xNN escapes, so that JSON and terminals take it."""
    if isinstance(name, bytes):
        return name.decode("utf-8", "backslashreplace")
    try:
        name.encode("utf-8")
        return name
    except UnicodeEncodeError:
        return os.fsencode(name).decode("utf-8", "backslashreplace")


def _stat(path):
    """os.stat (links followed), or None where it fails (gone, a dangling link, a loop)."""
    try:
        return os.stat(path)
    except (OSError, ValueError):
        return None


def _is_file(path) -> bool:
    st = _stat(path)
    return st is not None and stat.S_ISREG(st.st_mode)


def _is_frame(d) -> bool:
    return _is_file(os.path.join(d, "depth.png"))


def _is_tum(d) -> bool:
    return _is_file(os.path.join(d, "rgb.txt")) and _is_file(os.path.join(d, "depth.txt"))


def _is_dir(path) -> bool:
    st = _stat(path)
    return st is not None and stat.S_ISDIR(st.st_mode)


def _is_bag(path) -> bool:
    """A ROS 1 bag file as the batch finds one: a plain file (links followed) named *.bag,
    not hidden. `wul3d run` checks its first bytes (`#ROSBAG V2.0`) when it reads it."""
    name = os.path.basename(os.fsdecode(path))
    return name.endswith(".bag") and not name.startswith(".") and _is_file(path)


def _is_dataset_sequence(d) -> bool:
    """A dataset as downloaded that `wul3d run` takes whole: an OCID sequence (rgb/ and
    depth/ holding result_*.png), an OSD-0.2-depth tree (image_color/) or a BOP scene
    (scene_camera.json)."""
    if _is_dir(os.path.join(d, "image_color")) or _is_file(os.path.join(d, "scene_camera.json")):
        return True
    depth = os.path.join(d, "depth")
    if not (_is_dir(os.path.join(d, "rgb")) and _is_dir(depth)):
        return False
    try:
        with os.scandir(depth) as it:
            return any(e.name.startswith("result_") and e.name.endswith(".png") for e in it)
    except OSError:
        return False


class Discovery:
    """What discover found under a root: `sequences` (paths relative to the root, "/"
    separated, "." for the root itself; str as os.fsdecode gives them), `links` (the folders
    outside the walk that symbolic links led to: inputs too, which OUT must stay apart from)
    and `unread` ((path, reason) of folders that could not be listed or were too deep)."""

    def __init__(self, sequences, links, unread):
        self.sequences, self.links, self.unread = sequences, links, unread


def discover_all(root) -> Discovery:
    root = os.fsdecode(root)
    if _is_bag(root):
        return Discovery(["."], [], [])
    st = _stat(root)
    if st is None or not stat.S_ISDIR(st.st_mode):
        raise FileNotFoundError(f"{text(root)}: no such folder")
    if _is_tum(root) or _is_frame(root) or _is_dataset_sequence(root):
        return Discovery(["."], [], [])
    # Every folder is listed once, by (device, inode): a link back into the tree (a loop)
    # or a second link to one folder adds nothing. Real folders first, then the folders
    # links lead to, so that a sequence is named by its real path where it has one.
    visited = {(st.st_dev, st.st_ino)}
    found, links, unread = [], [], []
    bags = {}  # (device, inode) -> (reached through a link, relative path): each bag once
    walk = [()]  # relative paths as tuples of names, real folders
    deferred = []  # (relative path, key) of folders reached through a symbolic link

    def listing(rel):
        path = os.path.join(root, *rel)
        try:
            with os.scandir(path) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError as e:
            unread.append((rel, e.strerror or type(e).__name__))
            return
        subdirs, here_bags = [], []
        for e in entries:
            if e.name.startswith("."):
                continue
            cst = _stat(e.path)
            if cst is not None and stat.S_ISREG(cst.st_mode) and e.name.endswith(".bag"):
                try:
                    via_link = e.is_symlink()
                except OSError:
                    continue
                bag_key = (cst.st_dev, cst.st_ino)
                # A bag is named by its real path where it has one (as a folder is).
                if bag_key not in bags or (bags[bag_key][0] and not via_link):
                    here_bags.append((bag_key, (via_link, rel + (e.name,))))
                continue
            if cst is None or not stat.S_ISDIR(cst.st_mode):
                continue
            try:
                is_link = e.is_symlink()
            except OSError:
                continue
            subdirs.append((e.name, (cst.st_dev, cst.st_ino), is_link))
        if _is_tum(path) or _is_dataset_sequence(path):
            found.append(rel)
            return
        for bag_key, entry in here_bags:  # each bag a sequence of its own
            bags[bag_key] = entry
        frames = {name for name, _, _ in subdirs if _is_frame(os.path.join(path, name))}
        if frames:
            found.append(rel)
        for name, key, is_link in subdirs:
            if name in frames:
                continue
            child = rel + (name,)
            if is_link:
                deferred.append((child, key))
            elif key not in visited:
                visited.add(key)
                if len(child) > MAX_DEPTH:
                    unread.append((child, f"deeper than {MAX_DEPTH} folders"))
                else:
                    walk.append(child)

    while walk or deferred:
        if walk:
            listing(walk.pop())
            continue
        child, key = deferred.pop(0)
        if key in visited:
            continue
        visited.add(key)
        if len(child) > MAX_DEPTH:
            unread.append((child, f"deeper than {MAX_DEPTH} folders"))
            continue
        links.append(os.path.realpath(os.path.join(root, *child)))
        walk.append(child)
    found.extend(rel for _, rel in bags.values())
    found.sort()
    return Discovery(["/".join(rel) if rel else "." for rel in found], links,
                     [("/".join(rel) or ".", why) for rel, why in sorted(unread)])


def discover(root) -> list:
    """The sequences under `root`, as paths relative to it ("." for root itself), sorted.

    A TUM sequence (rgb.txt and depth.txt), an OCID sequence, an OSD-0.2-depth tree or a
    BOP scene (docs/INPUTS.md, sections 5 and 6) is one sequence; so is each ROS 1 bag
    (`*.bag`, section 4; its output folder keeps the name, OUT/<path>/rec.bag/; each bag
    once, by device and inode, named by its real path where it has one), and root itself
    may be one; a folder whose sub-folders are frames (depth.png) is one sequence of
    those frames, as `wul3d run FOLDER` reads it; root itself being one frame is a sequence
    of one. Other folders are searched further (a
    folder can hold frames and sequences of its own). Hidden folders are skipped.
    Symbolic links to folders are followed, each folder once (by device and inode): a loop
    back into the tree, or two links to one folder, find nothing twice; a sequence reached
    both by its real path and through a link is named by its real path. Folders more than
    MAX_DEPTH (64) below root, and folders that cannot be listed, are not searched (the
    batch reports them). Names that are not UTF-8 come back as os.fsdecode gives them.
    """
    return discover_all(root).sequences
