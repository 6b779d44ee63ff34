"""wul3d.read: the frames `wul3d run` reads, by name and content."""

import json

import numpy as np
import pytest

import wul3d
from conftest import SAMPLES


def test_sequence_of_frame_folders():
    frames = wul3d.read(SAMPLES / "uois_tabletop")
    names = sorted(p.name for p in (SAMPLES / "uois_tabletop").iterdir() if p.is_dir())
    assert len(frames) == len(names) and frames.format == "frames"
    assert [f.name for f in frames] == names
    f = frames[-1]
    assert f.name == names[-1]
    with open(SAMPLES / "uois_tabletop" / names[-1] / "intrinsics.json", encoding="utf-8") as fh:
        K = json.load(fh)
    assert (f.intrinsics.fx, f.intrinsics.fy, f.intrinsics.cx, f.intrinsics.cy) == (
        K["fx"], K["fy"], K["cx"], K["cy"])
    assert f.depth.shape == (K["height"], K["width"]) and f.depth.dtype == np.uint16
    assert f.color.shape == (K["height"], K["width"], 3) and f.color.dtype == np.uint8
    np.testing.assert_array_equal(
        f.color, wul3d.read_color_image(str(SAMPLES / "uois_tabletop" / names[-1] / "color.png")))
    assert [x.name for x in frames[1:3]] == names[1:3]


def test_single_frame_and_intrinsics_override():
    path = SAMPLES / "pcl_kinect" / "region_growing_rgb_tutorial"
    frames = wul3d.read(path, intrinsics={"fx": 500.0, "fy": 501.0, "cx": 300.0, "cy": 200.0})
    assert len(frames) == 1
    K = frames[0].intrinsics
    assert (K.fx, K.fy, K.cx, K.cy) == (500.0, 501.0, 300.0, 200.0)
    assert (K.width, K.height) == frames[0].depth.shape[::-1]


def test_meaningless_intrinsics_override_is_refused():
    """As `--intrinsics 600,600,nan,nan`: a ValueError, not a run that labels nothing."""
    path = SAMPLES / "pcl_kinect" / "region_growing_rgb_tutorial"
    with pytest.raises(ValueError, match="intrinsics"):
        wul3d.read(path, intrinsics={"fx": 600.0, "fy": 600.0, "cx": float("nan"), "cy": 200.0})
    with pytest.raises(ValueError, match="intrinsics"):
        wul3d.run(path, "/nonexistent-never-written", intrinsics="600,600,nan,nan")


def test_bad_inputs():
    with pytest.raises(wul3d.InputError, match="no_such_folder"):
        wul3d.read(SAMPLES / "no_such_folder")
    with pytest.raises(ValueError, match="format"):
        wul3d.read(SAMPLES / "uois_tabletop", format="mp4")
    with pytest.raises(IndexError):
        wul3d.read(SAMPLES / "uois_tabletop")[4]
