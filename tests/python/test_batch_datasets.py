"""wul3d.batch's discovery finds datasets as downloaded (OCID sequences, OSD-0.2-depth trees,
BOP scenes) as one sequence each, as `wul3d run` takes them, and does not look inside them.
Only the folder layout matters to discovery, so the files are empty."""

import pathlib

from wul3d import batch


def touch(path: pathlib.Path):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"")


def test_discover_finds_ocid_osd_and_bop_sequences(tmp_path):
    for seq in ("ocid/ARID20/table/top/seq01", "ocid/ARID20/floor/bottom/seq02"):
        for sub in ("rgb", "depth", "label"):
            touch(tmp_path / seq / sub / "result_2018-08-20-11-25-02.png")
    for sub in ("image_color", "disparity", "annotation"):
        touch(tmp_path / "OSD-0.2-depth" / sub / "learn0.png")
    for scene in ("ycbv/test/000048", "ycbv/test/000049"):
        touch(tmp_path / scene / "scene_camera.json")
        for sub in ("rgb", "depth", "mask_visib"):
            touch(tmp_path / scene / sub / "000000.png")
    # Not a sequence: rgb/ and depth/ without OCID's names, nor a scene's camera.
    touch(tmp_path / "other" / "rgb" / "a.png")
    touch(tmp_path / "other" / "depth" / "a.png")
    assert batch.discover(tmp_path) == [
        "OSD-0.2-depth", "ocid/ARID20/floor/bottom/seq02", "ocid/ARID20/table/top/seq01",
        "ycbv/test/000048", "ycbv/test/000049"]
    assert batch.discover(tmp_path / "ycbv" / "test" / "000048") == ["."]
    assert batch.discover(tmp_path / "OSD-0.2-depth") == ["."]
