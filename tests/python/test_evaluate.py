"""wul3d.evaluate: the UOIS metrics, against figures computed here and against `wul3d eval`."""

import json

import numpy as np
import pytest

import wul3d
from conftest import SAMPLES, run_cli


def test_two_squares_by_hand():
    gt = np.zeros((60, 80), np.uint16)
    gt[10:30, 10:30] = 1                    # 400 px
    pred = np.zeros((60, 80), np.int32)
    pred[10:30, 15:35] = 7                  # 400 px, 300 in common
    s = wul3d.evaluate(pred, gt, boundary_tolerance_px=0)
    assert s["gt_objects"] == 1 and s["pred_objects"] == 1
    assert s["overlap_p"] == pytest.approx(300 / 400)
    assert s["overlap_r"] == pytest.approx(300 / 400)
    assert s["overlap_f"] == pytest.approx(2 * 300 / 800)
    assert s["detected"] == 0 and s["detected_share"] == 0  # F = 0.75 is not above 0.75
    assert s["matches"] == [{"gt_id": 1, "pred_id": 7, "true_positives": 300,
                             "overlap_f": pytest.approx(0.75)}]
    same = wul3d.evaluate(gt, gt)
    assert same["overlap_f"] == 1 and same["boundary_f"] == 1 and same["detected"] == 1


def test_lists_equal_wul3d_eval(cli, tabletop_cli_out, tmp_path):
    # Objects scored against the clusters of the same frames: two real label images.
    frames = sorted(p for p in tabletop_cli_out.iterdir() if p.is_dir())
    preds = [wul3d.read_label_image(str(f / "objects.png")) for f in frames]
    gts = [wul3d.read_label_image(str(f / "labels.png")) for f in frames]
    ours = wul3d.evaluate(preds, gts)
    out = tmp_path / "eval.json"
    proc = run_cli(cli, "eval", tabletop_cli_out, tabletop_cli_out, "--gt-file", "labels.png",
                   "--pred-file", "objects.png", "--json", out)
    assert proc.returncode == 0, proc.stderr
    with open(out, encoding="utf-8") as f:
        theirs = json.load(f)
    summary = theirs["summary"] if "summary" in theirs else theirs
    assert ours["images"] == len(frames) == summary["images"]
    for key in ("overlap_p", "overlap_r", "overlap_f", "boundary_p", "boundary_r",
                "boundary_f"):
        assert ours[key] == pytest.approx(summary[key], abs=1e-12), key
    assert len(ours["per_image"]) == len(frames)


def test_where_depth_scores_only_pixels_with_depth():
    # Object 2 lies where the depth image has no reading: not counted, as `wul3d eval
    # --where-depth` does not count it.
    gt = np.zeros((60, 80), np.uint16)
    gt[10:30, 10:30] = 1
    gt[35:55, 40:70] = 2
    pred = np.zeros((60, 80), np.uint16)
    pred[10:30, 10:30] = 5
    depth = np.full((60, 80), 900, np.uint16)
    depth[35:55, 40:70] = 0
    assert wul3d.evaluate(pred, gt)["overlap_r"] == pytest.approx(400 / 1000)  # pixels found
    s = wul3d.evaluate(pred, gt, depth=depth)
    assert s["overlap_f"] == 1 and s["boundary_f"] == 1 and s["gt_objects"] == 1
    both = wul3d.evaluate([pred, pred], [gt, gt], depth=[depth, None])
    assert both["per_image"][0]["overlap_f"] == 1
    assert both["per_image"][1]["overlap_r"] == pytest.approx(400 / 1000)
    assert gt[40, 50] == 2  # the caller's arrays are left as they were
    with pytest.raises(ValueError, match="depth is"):
        wul3d.evaluate(pred, gt, depth=depth[:, :70])
    with pytest.raises(ValueError, match="a list of 2 depth images"):
        wul3d.evaluate([pred, pred], [gt, gt], depth=[depth])


def test_bad_label_images():
    gt = np.zeros((10, 10), np.uint16)
    with pytest.raises(TypeError, match="pred: dtype float32"):
        wul3d.evaluate(np.zeros((10, 10), np.float32), gt)
    with pytest.raises(ValueError, match="label -1 outside"):
        wul3d.evaluate(np.full((10, 10), -1, np.int16), gt)
    with pytest.raises(wul3d.InputError):
        wul3d.evaluate(np.zeros((10, 12), np.uint16), gt)
    with pytest.raises(ValueError, match="2 images, gt 1"):
        wul3d.evaluate([gt, gt], [gt])
    with pytest.raises(ValueError):
        wul3d.evaluate(gt, gt, detected_f=2.0)
