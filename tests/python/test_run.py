"""wul3d.run: `wul3d run` as one call, through the library's run loop; the same files."""

import filecmp
import json

import pytest

import wul3d
from conftest import SAMPLES, run_cli


def test_run_writes_what_the_command_writes(cli, tmp_path):
    flags = ["--k", "5", "--select", "320,300", "--ply", "--frames", "3", "--intrinsics",
             "530,530,320,240", "--threads", "1"]
    ref, out = tmp_path / "ref", tmp_path / "out"
    proc = run_cli(cli, "run", SAMPLES / "uois_tabletop", "--out", ref, "-q", *flags)
    assert proc.returncode == 0, proc.stderr
    threads = wul3d.get_num_threads()
    wul3d.set_num_threads(1)
    try:
        summary = wul3d.run(SAMPLES / "uois_tabletop", out, k=5, select="320,300", ply=True,
                            frames=3, intrinsics="530,530,320,240")
    finally:
        wul3d.set_num_threads(threads)
    assert summary["frames"] == 3 and summary["stopped_by"] == "frames"
    frames = sorted(p.name for p in ref.iterdir() if p.is_dir())
    assert frames == sorted(p.name for p in out.iterdir() if p.is_dir()) and len(frames) == 3
    for name in frames:
        files = sorted(p.name for p in (ref / name).iterdir())
        assert {"selected.png", "selected_object.png", "cloud.ply"} <= set(files)
        _, mismatch, errors = filecmp.cmpfiles(ref / name, out / name, files, shallow=False)
        assert not mismatch and not errors, (name, mismatch, errors)
    a, b = (json.loads((d / "summary.json").read_text()) for d in (ref, out))
    assert a["parameters"] == b["parameters"] and a["selected_cluster"] == b["selected_cluster"]


def test_run_rejects_bad_options(tmp_path):
    with pytest.raises(TypeError, match="unknown option"):
        wul3d.run(SAMPLES / "uois_tabletop", tmp_path, colour="red")
    with pytest.raises(ValueError, match="k = 0"):
        wul3d.run(SAMPLES / "uois_tabletop", tmp_path, k=0)
    with pytest.raises(ValueError, match="--intrinsics"):
        wul3d.run(SAMPLES / "uois_tabletop", tmp_path, intrinsics="1,2")
    with pytest.raises(wul3d.InputError):
        wul3d.run(SAMPLES / "nothing_here", tmp_path)


@pytest.mark.parametrize("outputs", ["objects,json", ("objects", "json"), ["json", "objects"]])
def test_outputs_writes_only_the_files_named(cli, tmp_path, outputs):
    ref, out = tmp_path / "ref", tmp_path / "out"
    proc = run_cli(cli, "run", SAMPLES / "uois_tabletop", "--out", ref, "-q", "--frames", "2",
                   "--outputs", "objects,json")
    assert proc.returncode == 0, proc.stderr
    summary = wul3d.run(SAMPLES / "uois_tabletop", out, frames=2, outputs=outputs)
    assert summary["frames"] == 2
    for name in ("image_0000", "image_0002"):
        assert sorted(p.name for p in (out / name).iterdir()) == ["objects.json", "objects.png"]
        _, mismatch, errors = filecmp.cmpfiles(ref / name, out / name,
                                               ["objects.json", "objects.png"], shallow=False)
        assert not mismatch and not errors
    summary_json = json.loads((out / "summary.json").read_text())
    assert summary_json["outputs"] == "objects,json"
    assert summary_json["stage_ms_median"]["colors"] == 0  # no colours made for no file
    with pytest.raises(ValueError, match="'masks' is not one of"):
        wul3d.run(SAMPLES / "uois_tabletop", tmp_path / "bad", outputs="objects,masks")
    with pytest.raises(TypeError, match="outputs"):
        wul3d.run(SAMPLES / "uois_tabletop", tmp_path / "bad", outputs=[1])
