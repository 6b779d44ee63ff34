"""eval/osd_table.py and eval/peers.py score their predictions with `wul3d eval --json`.
The command writes nothing inside its inputs, so each score's JSON must land beside the
prediction folder, not in it. Checked on the shipped frames, labelled with wul3d's own
objects (so every score is 1), without ../shared's OSD frames."""
import importlib.util
import shutil
import subprocess

import pytest

from conftest import ROOT, SAMPLES, run_cli


def load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "eval" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def self_labelled(cli, tmp_path_factory):
    """A prediction folder (`wul3d run` on the shipped tabletop frames) and a ground-truth
    folder whose labels are those predictions."""
    root = tmp_path_factory.mktemp("eval_scripts")
    pred, gt = root / "pred", root / "gt"
    proc = run_cli(cli, "run", SAMPLES / "uois_tabletop", "-o", pred, "-q", "--outputs", "objects,json")
    assert proc.returncode == 0, proc.stderr
    frames = sorted(p.name for p in (SAMPLES / "uois_tabletop").iterdir() if p.is_dir())
    assert frames
    for name in frames:
        (gt / name).mkdir(parents=True)
        shutil.copy(pred / name / "objects.png", gt / name / "label.png")
    return pred, gt


def files_in(folder):
    return sorted(p.relative_to(folder) for p in folder.rglob("*"))


@pytest.mark.parametrize("script", ["osd_table", "peers"])
def test_scores_land_beside_the_predictions(script, cli, self_labelled, monkeypatch):
    pred, gt = self_labelled
    before = files_in(pred)
    scores = pred.parent / "scores"
    scores_before = set(files_in(scores)) if scores.exists() else set()
    module = load(script)
    # The scripts' own runner, bounded in time here (theirs waits as long as a dataset takes).
    monkeypatch.setattr(module, "run", lambda cmd: subprocess.run(
        [str(c) for c in cmd], check=True, stdout=subprocess.DEVNULL, timeout=120))
    for prefix in ("", "image_000"):
        if script == "osd_table":
            summary = module.score(str(cli), pred, gt, prefix, "objects.png")
        else:
            summary = module.score(str(cli), pred, gt, prefix)
        assert summary["overlap_f"] == pytest.approx(1.0)
        assert summary["boundary_f"] == pytest.approx(1.0)
    assert files_in(pred) == before
    written = sorted(str(p) for p in set(files_in(scores)) - scores_before)
    assert len(written) == 2 and all(name.startswith("pred-") for name in written), written
