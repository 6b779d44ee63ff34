"""The scripts of examples/python run on shipped frames and write what they say."""

import os
import subprocess
import sys

import numpy as np

import wul3d
from conftest import BUILD, ROOT, SAMPLES


def run_example(name, *args):
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    return subprocess.run([sys.executable, str(ROOT / "examples" / "python" / name), *map(str, args)],
                          capture_output=True, text=True, timeout=180, env=env, check=False)


def test_segment_folder_writes_overlays(tmp_path):
    proc = run_example("segment_folder.py", SAMPLES / "uois_tabletop", tmp_path)
    assert proc.returncode == 0, proc.stderr
    names = sorted(p.name for p in (SAMPLES / "uois_tabletop").iterdir() if p.is_dir())
    assert sorted(p.stem for p in tmp_path.glob("*.png")) == names
    image = wul3d.read_color_image(str(tmp_path / f"{names[0]}.png"))
    color = wul3d.read_color_image(str(SAMPLES / "uois_tabletop" / names[0] / "color.png"))
    assert image.shape == color.shape
    assert (image != color).any(axis=2).sum() > 0  # objects were tinted
    assert len(proc.stdout.splitlines()) == len(names)


def test_to_open3d_writes_a_cloud_coloured_by_object(tmp_path):
    import open3d as o3d  # Debian's python3-open3d (scripts/install-deps.sh)

    frame_dir = SAMPLES / "uois_tabletop" / "image_0000"
    out = tmp_path / "objects.ply"
    proc = run_example("to_open3d.py", frame_dir, out)
    assert proc.returncode == 0, proc.stderr
    frame = wul3d.read(frame_dir)[0]
    result = wul3d.Pipeline().process(frame.color, frame.depth, frame.intrinsics, frame.depth_scale)
    cloud = o3d.io.read_point_cloud(str(out))
    assert len(cloud.points) == int((frame.depth > 0).sum())
    colours = np.unique(np.round(np.asarray(cloud.colors), 3), axis=0)
    assert len(colours) == len(result.instances) + 1  # each object and the background
    assert sum(line.startswith("object ") for line in proc.stdout.splitlines()) == len(result.instances)


def test_quickstart_prints_every_object():
    proc = run_example("quickstart.py", SAMPLES / "uois_tabletop")
    assert proc.returncode == 0, proc.stderr
    pipeline = wul3d.Pipeline()
    expected = [f"{f.name} object {i.id}: {i.pixels} px"
                for f in wul3d.read(SAMPLES / "uois_tabletop")
                for i in pipeline.process(f.color, f.depth, f.intrinsics, f.depth_scale).instances]
    lines = proc.stdout.splitlines()
    assert len(lines) == len(expected) > 0
    assert all(line.startswith(e + " at (") for line, e in zip(lines, expected))
