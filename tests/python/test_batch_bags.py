"""wul3d.batch finds ROS 1 bags (docs/INPUTS.md, section 4) as sequences of their own, beside
frame folders, and runs each as `wul3d run BAG` does. The bags are written here by rosbag's
own Python writer (Debian's python3-rosbag), from the shipped uois_tabletop frames."""

import filecmp
import json
import pathlib

import numpy as np
import pytest

from conftest import SAMPLES, run_cli
from test_batch import BUILD  # noqa: E402,F401  (sets PYTHONPATH for the workers)

import genpy  # noqa: E402  (Debian's python3-genpy, with python3-rosbag)
import rosbag  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402

import wul3d  # noqa: E402
from wul3d import batch  # noqa: E402


def write_bag(path: pathlib.Path, frames):
    """The frames as a bag of layout 1: rgb8 colour, 16UC1 depth (mm) and its CameraInfo,
    one frame every 100 ms, colour 5 ms after depth."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with rosbag.Bag(str(path), "w") as bag:
        for i, f in enumerate(frames):
            h, w = f.depth.shape
            t = genpy.Time(1700000000, 0) + genpy.Duration(0, i * 100_000_000)
            depth_mm = np.ascontiguousarray(np.round(f.depth * (f.depth_scale / 0.001)).astype("<u2"))
            depth = Image(height=h, width=w, encoding="16UC1", is_bigendian=0, step=2 * w,
                          data=depth_mm.tobytes())
            color = Image(height=h, width=w, encoding="rgb8", is_bigendian=0, step=3 * w,
                          data=np.ascontiguousarray(f.color).tobytes())
            fx, fy, cx, cy = (getattr(f.intrinsics, k) for k in ("fx", "fy", "cx", "cy"))
            info = CameraInfo(height=h, width=w, K=[fx, 0, cx, 0, fy, cy, 0, 0, 1])
            bag.write("/camera/aligned_depth_to_color/camera_info", info, t)
            bag.write("/camera/aligned_depth_to_color/image_raw", depth, t)
            bag.write("/camera/color/image_raw", color, t + genpy.Duration(0, 5_000_000))


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    """ROOT: recs/a.bag (frames 0-1), recs/b.bag (frames 2-3), recs/broken.bag (not a bag: a
    text file so named), a hidden bag, a file that is not a bag, and a folder of frames
    beside the bags."""
    root = tmp_path_factory.mktemp("bags")
    frames = list(wul3d.read(str(SAMPLES / "uois_tabletop")))
    write_bag(root / "recs" / "a.bag", frames[:2])
    write_bag(root / "recs" / "b.bag", frames[2:])
    write_bag(root / "recs" / ".hidden.bag", frames[:1])
    (root / "recs" / "notes.txt").write_text("not a sequence\n")
    (root / "recs" / "broken.bag").write_text("#ROSBAG V2.0\ncut short\n")
    for src in sorted(p for p in (SAMPLES / "uois_tabletop").iterdir() if p.is_dir())[:2]:
        (root / "recs" / "frames" / src.name).mkdir(parents=True)
        for p in src.iterdir():
            (root / "recs" / "frames" / src.name / p.name).write_bytes(p.read_bytes())
    return root


def test_discover_finds_each_bag_beside_frames(root):
    assert batch.discover(root) == ["recs/a.bag", "recs/b.bag", "recs/broken.bag", "recs/frames"]
    assert batch.discover(root / "recs" / "a.bag") == ["."]  # ROOT may be one bag


def test_batch_of_bags_equals_wul3d_run_of_each(cli, root, tmp_path):
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        report = batch.run_batch(root, tmp_path / "out", client=client, threads_per_worker=1,
                                 progress=False, timeout_s=300)
        # ROOT one bag: OUT/<its name>/.
        one = batch.run_batch(root / "recs" / "a.bag", tmp_path / "one", client=client,
                              threads_per_worker=1, progress=False, timeout_s=300)
    by_name = {s["sequence"]: s for s in report["sequences"]}
    assert sorted(by_name) == ["recs/a.bag", "recs/b.bag", "recs/broken.bag", "recs/frames"]
    # The file that is no bag fails alone, with the reader's one line; nothing of it is written.
    broken = by_name.pop("recs/broken.bag")
    assert broken["status"] == "failed" and "broken.bag" in broken["error"], broken
    assert "\n" not in broken["error"]
    assert not (tmp_path / "out" / "recs" / "broken.bag").exists()
    assert all(s["status"] == "ok" and s["error"] is None for s in by_name.values()), by_name
    assert by_name["recs/a.bag"]["frames"] == 2 and by_name["recs/b.bag"]["frames"] == 2
    assert [(s["sequence"], s["status"], s["frames"]) for s in one["sequences"]] == [("a.bag", "ok", 2)]
    for bag_name, out in (("a.bag", tmp_path / "out" / "recs" / "a.bag"),
                          ("b.bag", tmp_path / "out" / "recs" / "b.bag"),
                          ("a.bag", tmp_path / "one" / "a.bag")):
        ref = tmp_path / "ref" / bag_name
        if not ref.exists():
            proc = run_cli(cli, "run", root / "recs" / bag_name, "--out", ref, "-q", "--threads", 1)
            assert proc.returncode == 0, proc.stderr
        names = sorted(p.name for p in ref.iterdir() if p.is_dir())
        assert names and names == sorted(p.name for p in out.iterdir() if p.is_dir())
        for name in names:
            files = sorted(p.name for p in (ref / name).iterdir())
            _, mismatch, errors = filecmp.cmpfiles(ref / name, out / name, files, shallow=False)
            assert not mismatch and not errors, (bag_name, name, mismatch, errors)
    assert json.loads((tmp_path / "out" / "batch.json").read_text()) == report
