#!/usr/bin/env python3
"""Scores wul3d on the labelled OSD frames and prints the table of issue 3 with wul3d's rows.

Usage: eval/osd_table.py [--wul3d build/wul3d] [--data ../shared/data] [--out /tmp/wul3d-osd]

Runs `wul3d run` on osd_mosd (78 frames) once per variant (default, --segmenter geometric,
--segmenter kmeans, --no-plane, every pixel: --decimate 1, and the paper's clusters:
labels.png at k = 10 over every pixel), scores each with `wul3d eval` on the learn* frames,
the test* frames and all, then the two osd_moving sequences with the paper's weights on
objects (--object-psi 0.5), without (1), and both again at every pixel. Prints Markdown. OSD is research-only data: it is read from ../shared/data, never shipped.
"""
import argparse
import json
import pathlib
import subprocess
import sys


def run(cmd):
    print("$ " + " ".join(cmd), file=sys.stderr)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def score(wul3d, pred, gt, prefix, pred_file, extra=()):
    # Beside the predictions, not in them: wul3d eval writes no file inside its inputs.
    out = pred.parent / "scores" / f"{pred.name}-{pred_file}-{prefix or 'all'}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [wul3d, "eval", str(pred), str(gt), "--pred-file", pred_file, "--json", str(out), *extra]
    if prefix:
        cmd += ["--only", prefix]
    run(cmd)
    report = json.loads(out.read_text())
    return {**report["summary"], **report.get("temporal", {})}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wul3d", default="build/wul3d")
    ap.add_argument("--data", default="../shared/data")
    ap.add_argument("--out", default="/tmp/wul3d-osd")
    args = ap.parse_args()
    data, out = pathlib.Path(args.data), pathlib.Path(args.out)
    mosd = data / "osd_mosd"
    if not (mosd / "frames.csv").is_file():
        sys.exit(f"osd_table.py: {mosd} not found (OSD is research-only and not in the repository)")

    variants = [
        ("wul3d default (hybrid, plane removal, object psi 0.5, --decimate 2)", [], "objects.png"),
        ("wul3d --segmenter geometric", ["--segmenter", "geometric"], "objects.png"),
        ("wul3d --segmenter kmeans (the paper's clusters as objects, plane removed)",
         ["--segmenter", "kmeans"], "objects.png"),
        ("wul3d --no-plane", ["--no-plane"], "objects.png"),
        ("wul3d --decimate 1 (every pixel)", ["--decimate", "1"], "objects.png"),
        ("the paper's method as published (clusters, labels.png, k = 10, every pixel)",
         ["--k", "10", "--decimate", "1"], "labels.png"),
    ]
    rows = []
    for i, (name, flags, pred_file) in enumerate(variants):
        pred = out / f"mosd-{i}"
        run([args.wul3d, "run", str(mosd), "--out", str(pred), "-q", *flags])
        ms = json.loads((pred / "summary.json").read_text())["ms_per_frame_median"]
        scores = {p: score(args.wul3d, pred, mosd, p, pred_file) for p in ("learn", "test", "")}
        rows.append((name, scores, ms))

    print("| method, osd_mosd | frames | Overlap F | Boundary F | %>=75 | ms/frame |")
    print("|---|---|---|---|---|---|")
    for name, scores, ms in rows:
        for part, label in (("learn", "learn (45)"), ("test", "test (33)"), ("", "all (78)")):
            s = scores[part]
            print(f"| {name} | {label} | {100 * s['overlap_f']:.1f} | {100 * s['boundary_f']:.1f} | "
                  f"{100 * s['detected_share']:.1f} | {ms:.1f} |")

    print()
    print("| osd_moving sequence | object psi | Overlap F | Boundary F | id switches (max per object) | flicker % |")
    print("|---|---|---|---|---|---|")
    for seq in sorted(p for p in (data / "osd_moving").iterdir() if p.is_dir()):
        for psi, flags in (("0.5", []), ("1", []), ("0.5, --decimate 1", ["--decimate", "1"]),
                           ("1, --decimate 1", ["--decimate", "1"])):
            pred = out / f"moving-{seq.name}-{psi.replace(', ', '-').replace(' ', '')}"
            run([args.wul3d, "run", str(seq), "--out", str(pred), "-q", "--object-psi",
                 psi.split(",")[0], *flags])
            s = score(args.wul3d, pred, seq, "", "objects.png", ["--temporal"])
            print(f"| {seq.name} | {psi} | {100 * s['overlap_f']:.1f} | {100 * s['boundary_f']:.1f} | "
                  f"{s['id_switches']} ({s['max_switches']}) | {100 * s['flicker']:.1f} |")


if __name__ == "__main__":
    main()
