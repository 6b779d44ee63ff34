#!/usr/bin/env python3
"""Generated scenes scored per kind of object: where a run's losses lie.

Usage: eval/kinds.py GENERATED OUT [--against BEFORE [--min-change 0.02]]

GENERATED: a folder eval/scenegen.py wrote (scene_SSSSS frames and scenegen.json); OUT: what
`wul3d run GENERATED --out OUT` wrote (OUT/scene_SSSSS/objects.png). Each scene is built again
from its seed (the generator draws the same scene) to learn the kind of group each labelled
object was drawn in: on the tabletop a box standing alone, a stack, a flat box lying on a box,
a box leaning on another, boxes flush side by side, a cylinder, a cup, a bowl; in the pile and
floor families a box, a can, a bottle, a sphere, a can or bottle lying down, a stack, a lean. Per kind it prints the objects,
their mean best IoU with any output object (IoU), what the kind loses of the mean IoU over all
objects (its 1 - IoU summed, over all objects, in points), and how each object fared: good (IoU >= 0.75), missed (over
half its pixels in no object), merged (its best object over 1.5 times its size) or split.
Rendering again takes about a second a scene.

With --against BEFORE (another run's output of the same GENERATED folder) it also lists each
object whose best IoU changed by --min-change (0.02) or more between BEFORE and OUT, as
"scene label kind: IoU fate -> IoU fate", and counts those that gain and those that lose:
what a rule changed, object by object.
"""
import argparse
import json
import pathlib
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import scenegen  # noqa: E402

FATES = ["good", "merged", "split", "missed"]
KINDS = ["box", "stack", "flat", "lean", "flush", "cylinder", "cup", "bowl"]  # build_scene's


def fate(truth, pred, label):
    """Best IoU of truth object `label` with any output object, and its fate."""
    m = truth == label
    n = int(m.sum())
    ids, counts = np.unique(pred[m], return_counts=True)
    uncovered = counts[ids == 0].sum() / n if (ids == 0).any() else 0.0
    best, best_id = 0.0, 0
    for i, c in zip(ids, counts):
        if i == 0:
            continue
        iou = c / (n + int((pred == i).sum()) - c)
        if iou > best:
            best, best_id = iou, i
    if best >= 0.75:
        return best, "good"
    if uncovered > 0.5:
        return best, "missed"
    if best_id and (pred == best_id).sum() > 1.5 * n:
        return best, "merged"
    return best, "split"


def read_objects(out, scene, generated, truth):
    """OUT/<scene>/objects.png, the same size as the scene's truth; exits with one line if not."""
    path = out / scene.name / "objects.png"
    if not path.exists():
        sys.exit(f"kinds.py: {path}: missing (run `wul3d run {generated} --out {out}`)")
    pred = np.array(Image.open(path))
    if pred.shape != truth.shape:
        sys.exit(f"kinds.py: {path}: {pred.shape[1]}x{pred.shape[0]}, the frame is "
                 f"{truth.shape[1]}x{truth.shape[0]}")
    return pred


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument("generated", type=pathlib.Path)
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--against", type=pathlib.Path, metavar="BEFORE",
                    help="another run's output of GENERATED: list the objects that changed")
    ap.add_argument("--min-change", type=float, default=0.02,
                    help="with --against: the smallest change of best IoU listed (default 0.02)")
    a = ap.parse_args(argv)
    if a.min_change <= 0:
        sys.exit(f"kinds.py: --min-change {a.min_change}: must be > 0")
    meta_path = a.generated / "scenegen.json"
    try:
        meta = json.loads(meta_path.read_text())
    except (OSError, ValueError) as e:
        sys.exit(f"kinds.py: {meta_path}: not a generated set ({e})")
    if meta.get("version") != scenegen.VERSION:
        sys.exit(f"kinds.py: {a.generated} was written by generator version {meta.get('version')}, "
                 f"this is version {scenegen.VERSION}: write it again")
    rows = {}
    changes = []  # (scene, label, kind, before, after) with before, after = (IoU, fate)
    scenes = sorted(p for p in a.generated.glob("scene_*") if (p / "label.png").exists())
    if not scenes:
        sys.exit(f"kinds.py: {a.generated}: no scene_* frames")
    for scene in scenes:
        truth = np.array(Image.open(scene / "label.png"))
        pred = read_objects(a.out, scene, a.generated, truth)
        before = read_objects(a.against, scene, a.generated, truth) if a.against else None
        drawn = {}
        _, _, labels, _ = scenegen.render(int(scene.name.split("_")[1]), meta["width"], meta["height"], drawn,
                                          family=meta.get("family", "tabletop"),
                                          sensor=meta.get("sensor", "structured_light"))
        if not np.array_equal(labels, truth):
            sys.exit(f"kinds.py: {scene}: its labels are not the ones its seed draws")
        for label, kind in drawn["kinds"].items():
            after = fate(truth, pred, label)
            rows.setdefault(kind, []).append(after)
            if before is not None:
                was = fate(truth, before, label)
                if abs(after[0] - was[0]) >= a.min_change:
                    changes.append((scene.name, label, kind, was, after))
    total = sum(len(r) for r in rows.values())
    print(f"{'kind':<10}{'objects':>8}{'IoU':>10}{'loses':>8}" + "".join(f"{f:>8}" for f in FATES))
    for kind in sorted(rows):
        r = rows[kind]
        loses = 100 * sum(1 - iou for iou, _ in r) / total
        counts = "".join(f"{sum(1 for _, f in r if f == name):>8}" for name in FATES)
        print(f"{kind:<10}{len(r):>8}{np.mean([iou for iou, _ in r]):>10.3f}{loses:>8.1f}{counts}")
    print(f"{'all':<10}{total:>8}{np.mean([iou for r in rows.values() for iou, _ in r]):>10.3f}")
    if a.against:
        print(f"against {a.against}: objects whose best IoU changed by {a.min_change} or more")
        for name, label, kind, (iou0, fate0), (iou1, fate1) in changes:
            print(f"{name} {label} {kind}: {iou0:.2f} {fate0} -> {iou1:.2f} {fate1}")
        gain = sum(1 for *_, was, now in changes if now[0] > was[0])
        print(f"{gain} gain, {len(changes) - gain} lose")


if __name__ == "__main__":
    main()
