#!/usr/bin/env python3
"""Fuzzes wul3d.batch's discovery (wul3d/discovery.py, discover_all) over random folder trees: symbolic links
back up the tree, to siblings, to themselves, to a tree outside ROOT, dangling and to files;
FIFOs and files where folders or depth.png are expected; ROS bags (*.bag files, links to
them, FIFOs so named, hidden ones); names with bytes that are not
UTF-8, newlines, spaces, 255 bytes, hidden names; folders that cannot be listed (when not
run as root). Each tree is also kept as a model (a graph of its folders); the model says which
folders are sequences, which bags lie in the folders a walk from ROOT lists, and which of
them it reaches; discovery must return each of those exactly once (by device and inode), end
within 10 s, and raise nothing.

    python3 fuzz/fuzz_batch_discovery.py [--seconds 20] [--seed 1] [--iteration I] [--keep DIR]

Deterministic: tree I of seed S is the same on every machine (random.Random(f"{S}:{I}")).
A finding prints the seed and the iteration and the command that rebuilds that tree and
runs discovery on it again; --keep DIR leaves the tree there to look at. Needs no build: it
loads python/wul3d/discovery.py by path (it uses the standard library only).
Exit 0 with "no finding", 1 on a finding (docs/FUZZING.md).
"""

import argparse
import importlib.util
import os
import pathlib
import random
import shutil
import signal
import sys
import tempfile
import time
import traceback

HERE = pathlib.Path(__file__).resolve().parent
DISCOVERY_PY = HERE.parent / "python" / "wul3d" / "discovery.py"
ITERATION_LIMIT_S = 10


def load_discovery():
    spec = importlib.util.spec_from_file_location("wul3d_discovery_under_fuzz", DISCOVERY_PY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Node:
    """A real folder of the tree: its path (bytes) and what the model knows of it."""

    def __init__(self, path: bytes, in_root: bool):
        self.path, self.in_root = path, in_root
        self.children = {}  # name (bytes) -> Node (a folder, real or through a link)
        self.files = {}  # name (bytes) -> whether it is a regular file, links followed
        self.bags = {}  # name (bytes, *.bag) -> (device, inode) of the regular file it is
        self.readable = True

    @property
    def frame(self) -> bool:  # depth.png is a regular file (or a link to one)
        return self.files.get(b"depth.png", False)

    @property
    def tum(self) -> bool:  # rgb.txt and depth.txt are
        return self.files.get(b"rgb.txt", False) and self.files.get(b"depth.txt", False)


def random_name(rng: random.Random, taken, long_ok=True) -> bytes:
    """A new name: plain, with bytes that are not UTF-8, with spaces or a newline, long
    (where `long_ok`), hidden, or one that discovery looks for."""
    for _ in range(100):
        kind = rng.random()
        if kind < 0.45:
            name = bytes(rng.choice(b"abcdefxyz_-0123456789") for _ in range(rng.randint(1, 8)))
        elif kind < 0.6:
            name = b"n" + bytes(rng.randint(0x80, 0xff) for _ in range(rng.randint(1, 4)))
        elif kind < 0.68:
            name = rng.choice([b"a b", b"new\nline", b"tab\tx", b" lead", b"trail ", b"\\x"])
        elif kind < 0.74:
            if not long_ok:
                continue
            name = b"L" * rng.randint(200, 255)
        elif kind < 0.82:
            name = b"." + bytes(rng.choice(b"hidnst") for _ in range(rng.randint(1, 5)))
        else:
            name = rng.choice([b"depth.png", b"rgb.txt", b"depth.txt", b"summary.json",
                               b"batch.json", b"-", b"--out", b"\xef\xbb\xbfbom"])
        if name not in taken and b"/" not in name and b"\0" not in name:
            return name
    raise RuntimeError("no free name")


def make_marker(rng: random.Random, path: bytes, other_file: bytes, other_dir: bytes) -> bool:
    """Creates depth.png / rgb.txt / depth.txt at `path` in one of the shapes a tree may
    hold; returns whether it is a regular file once links are followed."""
    kind = rng.random()
    if kind < 0.7:
        with open(path, "wb") as f:
            f.write(b"x")
        return True
    if kind < 0.78:
        os.mkfifo(path)
        return False
    if kind < 0.84:
        os.mkdir(path)
        return False
    if kind < 0.92:
        os.symlink(other_file, path)
        return True
    if kind < 0.96:
        os.symlink(path + b".missing", path)
        return False
    os.symlink(other_dir, path)
    return False


def build_tree(rng: random.Random, base: bytes):
    """A random tree under base/root and base/outside; returns (root node, every node).
    At most 3 names of 200-255 bytes: every path a walk makes stays under PATH_MAX."""
    root = Node(base + b"/root", True)
    outside = Node(base + b"/outside", False)
    os.mkdir(root.path)
    os.mkdir(outside.path)
    plain_file = base + b"/plain"
    with open(plain_file, "wb") as f:
        f.write(b"p")
    nodes = [root, outside]
    taken = {id(root): set(), id(outside): set()}
    longs = [0]

    def new_name(parent):
        name = random_name(rng, taken[id(parent)], long_ok=longs[0] < 3)
        longs[0] += len(name) >= 200
        taken[id(parent)].add(name)
        return name

    def marker(node, name):
        node.files[name] = make_marker(rng, node.path + b"/" + name, plain_file, root.path)
        taken[id(node)].add(name)

    for _ in range(rng.randint(0, 24)):  # real folders
        parent = rng.choice(nodes)
        if parent.frame and rng.random() < 0.8:
            continue
        name = new_name(parent)
        node = Node(parent.path + b"/" + name, parent.in_root)
        try:
            os.mkdir(node.path)
        except OSError:
            continue
        parent.files[name] = False
        taken[id(node)] = set()
        parent.children[name] = node
        nodes.append(node)
        kind = rng.random()
        if kind < 0.35:  # a frame
            marker(node, b"depth.png")
        elif kind < 0.45:  # a TUM sequence
            marker(node, b"rgb.txt")
            marker(node, b"depth.txt")
    bag_files = []  # the regular *.bag files made, for links to them
    for _ in range(rng.randint(0, 6)):  # ROS bags: files, links to them, FIFOs so named
        parent = rng.choice(nodes)
        name = new_name(parent)
        name = (b"." if rng.random() < 0.15 else b"") + name[:200] + b".bag"
        if name in taken[id(parent)] or name in parent.children:
            continue
        taken[id(parent)].add(name)
        path = parent.path + b"/" + name
        kind = rng.random()
        try:
            if kind < 0.5 or not bag_files:
                with open(path, "wb") as f:
                    f.write(b"#ROSBAG V2.0\n")
                bag_files.append(path)
                parent.bags[name] = key(path)
            elif kind < 0.8:
                target = rng.choice(bag_files)
                os.symlink(target, path)
                parent.bags[name] = key(target)
            else:
                os.mkfifo(path)
        except OSError:
            continue
        parent.files[name] = name in parent.bags
    for _ in range(rng.randint(0, 10)):  # links, FIFOs and files among them
        parent = rng.choice(nodes)
        name = new_name(parent)
        path = parent.path + b"/" + name
        kind = rng.random()
        try:
            if kind < 0.7:
                target = rng.choice(nodes)
                relative = rng.random() < 0.3
                os.symlink(os.path.relpath(target.path, parent.path) if relative else target.path,
                           path)
                parent.children[name] = target
                parent.files[name] = False
            elif kind < 0.8:
                os.symlink(path if rng.random() < 0.5 else path + b".gone", path)  # loop, dangling
                parent.files[name] = False
            elif kind < 0.9:
                os.mkfifo(path)
                parent.files[name] = False
            else:
                os.symlink(plain_file, path)
                parent.files[name] = True
        except OSError:
            continue
    if os.geteuid() != 0:  # permissions bind only others than root
        for node in rng.sample(nodes[2:], k=min(len(nodes) - 2, rng.randint(0, 2))):
            if rng.random() < 0.5:
                os.chmod(node.path, 0)
                node.readable = False
    return root, nodes


def expected(root: Node):
    """What discovery must return according to the model: the sequence folders a walk from
    ROOT reaches (links followed, hidden names and frame folders not entered) and the bags
    in the folders it lists but for sequence folders (by (device, inode), each once), and the
    folders it reaches but cannot list."""
    def is_frame(n):
        return n.readable and n.frame

    def is_tum(n):
        return n.readable and n.tum

    if is_tum(root) or is_frame(root):
        return [root], [], set()
    sequences, unread, seen, todo = [], [], {id(root)}, [root]
    bags = set()
    while todo:
        n = todo.pop()
        if not n.readable:
            unread.append(n)
            continue
        if is_tum(n):
            sequences.append(n)
            continue
        bags.update(k for name, k in n.bags.items() if not name.startswith(b"."))
        children = [c for name, c in n.children.items() if not name.startswith(b".")]
        if any(is_frame(c) for c in children):
            sequences.append(n)
        for c in children:
            if not is_frame(c) and id(c) not in seen:
                seen.add(id(c))
                todo.append(c)
    return sequences, unread, bags


class Stuck(Exception):
    pass


def _alarm(signum, frame):  # noqa: ARG001
    raise Stuck(f"discovery ran over {ITERATION_LIMIT_S} s")


def key(path) -> tuple:
    st = os.stat(path)
    return (st.st_dev, st.st_ino)


def one(discovery, seed, iteration, keep=None):
    """Builds tree `iteration` of `seed`, runs discovery; returns None or what went wrong."""
    rng = random.Random(f"{seed}:{iteration}")
    base = (keep.encode() if keep else os.fsencode(tempfile.mkdtemp(prefix="wul3d-fuzz-")))
    if keep:
        shutil.rmtree(base, ignore_errors=True)
        os.makedirs(base)
    root, nodes = build_tree(rng, base)
    try:
        want, want_unread, want_bags = expected(root)
        signal.setitimer(signal.ITIMER_REAL, ITERATION_LIMIT_S)
        try:
            found = discovery.discover_all(os.fsdecode(root.path))
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        got = [key(os.path.join(os.fsdecode(root.path), rel)) for rel in found.sequences]
        if len(set(got)) != len(got):
            return f"a sequence found twice: {found.sequences}"
        if set(got) != {key(n.path) for n in want} | want_bags:
            return (f"found {found.sequences}; the model's sequences: "
                    f"{sorted(os.fsdecode(n.path[len(root.path) + 1:]) or '.' for n in want)}")
        def parts(rel):
            return () if rel == "." else tuple(rel.split("/"))
        if sorted(found.sequences, key=parts) != found.sequences:
            return f"not in the tree's order (sorted by path components): {found.sequences}"
        unread_keys = {key(os.path.join(os.fsdecode(root.path), p)) for p, _ in found.unread}
        if unread_keys != {key(n.path) for n in want_unread}:
            return f"unread {found.unread}, the model's: {[n.path for n in want_unread]}"
        return None
    except Stuck as e:
        return str(e)
    except Exception:  # noqa: BLE001  (any exception is a finding)
        return "raised:\n" + traceback.format_exc()
    finally:
        for n in nodes:
            if not n.readable:
                os.chmod(n.path, 0o755)
        if not keep:
            shutil.rmtree(base, ignore_errors=True)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float,
                   default=float(os.environ.get("WUL3D_FUZZ_SECONDS", "20")))
    p.add_argument("--seed", type=int, default=int(os.environ.get("WUL3D_FUZZ_SEED", "1")))
    p.add_argument("--iteration", type=int, help="run this one tree only")
    p.add_argument("--keep", help="build the tree here and leave it (with --iteration)")
    args = p.parse_args(argv)
    seed = args.seed if args.seed != 0 else random.SystemRandom().randrange(1, 2**31)
    discovery = load_discovery()
    signal.signal(signal.SIGALRM, _alarm)
    iterations = [args.iteration] if args.iteration is not None else None
    start = time.monotonic()
    i, done = 0, 0
    while True:
        if iterations is not None:
            if not iterations:
                break
            i = iterations.pop()
        elif time.monotonic() - start >= args.seconds:
            break
        problem = one(discovery, seed, i, args.keep)
        done += 1
        if problem is not None:
            print(f"fuzz_batch_discovery: FINDING with seed {seed}, iteration {i}: {problem}")
            print(f"reproduce: python3 fuzz/fuzz_batch_discovery.py --seed {seed} "
                  f"--iteration {i} --keep /tmp/wul3d-fuzz-tree")
            return 1
        i += 1
    took = time.monotonic() - start
    print(f"fuzz_batch_discovery: seed {seed}, {done} trees in {took:.1f} s "
          f"({done / took if took > 0 else 0:.0f}/s), no finding")
    return 0


if __name__ == "__main__":
    sys.exit(main())
