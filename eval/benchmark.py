#!/usr/bin/env python3
"""One table for every labelled set: the shared real frames, the whole frames, generated scenes.

Usage: eval/benchmark.py [--wul3d build/wul3d] [--data ../shared/data] [--work out/benchmark]
                         [--tune A-B] [--report A-B] [--sets NAME,...] [-- RUN_FLAGS...]

Every set is run with `wul3d run SET --out WORK/... -q RUN_FLAGS` and scored with `wul3d eval`
(the same metric as `wul3d eval`, its own numbers). Sets, each when its data is there:

  osd_mosd learn / test   ../shared/data/osd_mosd (research use only: read in place, never copied)
  whole (uncropped)       ../shared/data/osd_uncropped, and the same scenes cropped (osd_mosd
                          learn6, test42): precision of whole frames against cropped
  generated tune          eval/scenegen.py scenes, seeds --tune (default 0-99): the seeds any
                          parameter may be chosen on
  generated report        seeds --report (default 1000-1099): never looked at while tuning;
                          the number to report (docs/EVAL.md, "Generated scenes")

Generated scenes are written once to WORK/gen_A-B and reused. RUN_FLAGS after `--` go to every
`wul3d run` (an ablation: `eval/benchmark.py -- --scope scene`).
"""
import argparse
import json
import pathlib
import re
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
KEYS = ["Overlap P", "Overlap R", "Overlap F", "Boundary F", "%>=75"]


def score(wul3d, out, data, only=(), where_depth=False):
    cmd = [wul3d, "eval", str(out), str(data)] + (["--where-depth"] if where_depth else [])
    for o in only:
        cmd += ["--only", o]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"benchmark.py: {' '.join(cmd)} failed: {res.stderr.strip()}")
    got = {}
    for line in res.stdout.splitlines():
        for k in KEYS + ["images", "objects"]:
            if line.startswith(k + " "):
                got[k] = float(line[len(k):].split()[0])
    return got


def run(wul3d, data, out, flags):
    cmd = [wul3d, "run", str(data), "--out", str(out), "-q"] + flags
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"benchmark.py: {' '.join(cmd)} failed: {res.stderr.strip()}")


def generate(work, seeds, family="tabletop", sensor="structured_light", incremental=False):
    """WORK/gen_<A-B> (or gen_<family>_<sensor>_<A-B> for another family or sensor, and
    gen_incremental_<family>_<sensor>_<A-B> for the seeds' sequences, scenegen.py
    --incremental): the seeds' scenes, written by eval/scenegen.py unless its scenegen.json
    already names this generator version, family, sensor, seeds and kind."""
    default = (family, sensor) == ("tabletop", "structured_light")
    if incremental:
        folder = work / f"gen_incremental_{family}_{sensor}_{seeds}"
    else:
        folder = work / (f"gen_{seeds}" if default else f"gen_{family}_{sensor}_{seeds}")
    a, _, b = seeds.partition("-")
    n = int(b or a) - int(a) + 1
    stamp = folder / "scenegen.json"
    version = re.search(r"^VERSION = (\d+)", (HERE / "scenegen.py").read_text(), re.M).group(1)
    if stamp.is_file():
        got = json.loads(stamp.read_text())
        if (str(got.get("version")), got.get("family", "tabletop"), got.get("sensor", "structured_light"),
                got.get("seeds", seeds), got.get("incremental", False)) == \
                (version, family, sensor, seeds, incremental):
            return folder
    t = time.time()
    res = subprocess.run([sys.executable, str(HERE / "scenegen.py"), "--out", str(folder), "--seeds", seeds,
                          "--family", family, "--sensor", sensor] + (["--incremental"] if incremental else []),
                         capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"scenegen.py failed: {res.stderr.strip()}")
    kind = "sequences" if incremental else "scenes"
    print(f"generated {n} {family} {kind} under {sensor} (seeds {seeds}) in {time.time() - t:.0f} s "
          f"-> {folder}", file=sys.stderr)
    return folder


def main():
    argv = sys.argv[1:]
    flags = []
    if "--" in argv:
        i = argv.index("--")
        argv, flags = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument("--wul3d", default="build/wul3d")
    ap.add_argument("--data", default="../shared/data", type=pathlib.Path)
    ap.add_argument("--work", default="out/benchmark", type=pathlib.Path)
    ap.add_argument("--tune", default="0-99")
    ap.add_argument("--report", default="1000-1099")
    ap.add_argument("--sets", default="osd,whole,tune,report",
                    help="comma-separated: osd, whole, tune, report")
    a = ap.parse_args(argv)
    if not pathlib.Path(a.wul3d).is_file():
        sys.exit(f"benchmark.py: {a.wul3d}: not found (build first, or pass --wul3d)")
    sets = set(a.sets.split(","))
    a.work.mkdir(parents=True, exist_ok=True)
    tag = "default" if not flags else "_".join(f.strip("-").replace("/", "_") for f in flags)
    rows = []
    osd = a.data / "osd_mosd"
    if "osd" in sets and osd.is_dir():
        out = a.work / f"osd_mosd.{tag}"
        run(a.wul3d, osd, out, flags)
        for part in ("learn", "test"):
            rows.append((f"osd_mosd {part}", score(a.wul3d, out, osd, [part])))
        rows.append(("osd_mosd all", score(a.wul3d, out, osd)))
    whole = a.data / "osd_uncropped"
    if "whole" in sets and whole.is_dir() and osd.is_dir():
        out = a.work / f"osd_uncropped.{tag}"
        run(a.wul3d, whole, out, flags)
        names = sorted(p.name for p in whole.iterdir() if (p / "depth.png").is_file())
        rows.append(("whole frames (osd_uncropped)", score(a.wul3d, out, whole)))
        if "osd" in sets:
            cropped = a.work / f"osd_mosd.{tag}"
        else:
            # The cropped frames alone: a folder of links to them, run as one input.
            links = a.work / "osd_mosd_cropped_frames"
            links.mkdir(exist_ok=True)
            for n in names:
                if not (links / n).exists():
                    (links / n).symlink_to((osd / n).resolve())
            cropped = a.work / f"osd_mosd_cropped.{tag}"
            run(a.wul3d, links, cropped, flags)
        rows.append(("the same scenes cropped (osd_mosd)", score(a.wul3d, cropped, osd, names)))
    for key, seeds in (("tune", a.tune), ("report", a.report)):
        if key not in sets:
            continue
        gen = generate(a.work, seeds)
        out = a.work / f"gen_{seeds}.{tag}"
        run(a.wul3d, gen, out, flags)
        rows.append((f"generated {key} (seeds {seeds})", score(a.wul3d, out, gen)))
    print(f"flags: {' '.join(flags) if flags else '(default)'}")
    print("| set | frames | objects | Overlap P | Overlap R | Overlap F | Boundary F | %>=75 |")
    print("|---|---|---|---|---|---|---|---|")
    for name, s in rows:
        print(f"| {name} | {s.get('images', 0):.0f} | {s.get('objects', 0):.0f} | " +
              " | ".join(f"{s.get(k, float('nan')):.1f}" for k in KEYS) + " |")


if __name__ == "__main__":
    main()
