#!/usr/bin/env python3
"""Every generated family under every sensor model: one table.

Usage: eval/families.py [--set report|tune] [--seeds N] [--families a,b] [--sensors a,b]
                        [--where-depth] [--incremental] [--wul3d build/wul3d]
                        [--work out/families] [-- RUN_FLAGS...]

For every family x sensor (eval/scenegen.py --family, --sensor) it writes the set's seeds
(docs/EVAL.md, "Generated scenes": tabletop tune 0-99 / report 1000-1099, pile 10000-10099 /
11000-11099, floor 20000-20099 / 21000-21099; `--seeds N` takes the first N of each range),
runs `wul3d run GEN --out OUT -q RUN_FLAGS` and `wul3d eval OUT GEN`, and prints one row each:
family, sensor, frames, objects, Overlap F, Boundary F, %>=75; with --where-depth, scored
only where the sensor gave depth (`wul3d eval --where-depth`: the generated labels cover
every pixel, OSD's and OCID's only those with depth). Generated folders are written
once to WORK/gen_<family>_<sensor>_<A-B> (WORK/gen_<A-B> for tabletop under structured
light, as eval/benchmark.py names them) and reused while their scenegen.json names the
generator's version, family, sensor and seeds. One process at a time: rendering is about 1-1.5 s
a 640x480 frame.

With --incremental every seed is a sequence whose objects are put down one at a time
(scenegen.py --incremental, WORK/gen_incremental_<family>_<sensor>_<A-B>, 5-20 frames a seed):
each sequence runs as one `wul3d run` (the objects' tracks carry from frame to frame, as in
OCID's sequences), and every frame of every sequence is scored.
"""
import argparse
import pathlib
import shutil
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from benchmark import generate, run, score  # noqa: E402

FAMILIES = ["tabletop", "pile", "floor"]
SENSORS = ["structured_light", "active_stereo", "tof"]
SEEDS = {"tabletop": {"tune": 0, "report": 1000},
         "pile": {"tune": 10000, "report": 11000},
         "floor": {"tune": 20000, "report": 21000}}  # each range 100 seeds from here


def run_sequences(wul3d, gen, out, flags):
    """Each GEN/seq_* run as one sequence into OUT/seq_*; returns the two folders `wul3d eval`
    scores, OUT/truth and OUT/frames, each frame of each sequence linked as seq_*_step_*."""
    truth, frames = out / "truth", out / "frames"
    for folder in (truth, frames):
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
    for seq in sorted(gen.glob("seq_*")):
        run(wul3d, seq, out / seq.name, flags)
        for step in sorted(seq.glob("step_*")):
            (truth / f"{seq.name}_{step.name}").symlink_to(step.resolve())
            (frames / f"{seq.name}_{step.name}").symlink_to((out / seq.name / step.name).resolve())
    return truth, frames


def main():
    argv = sys.argv[1:]
    flags = []
    if "--" in argv:
        i = argv.index("--")
        argv, flags = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument("--set", default="report", choices=["report", "tune"])
    ap.add_argument("--seeds", type=int, default=100, help="the first N seeds of each range (1-100)")
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--sensors", default=",".join(SENSORS))
    ap.add_argument("--where-depth", action="store_true",
                    help="score only pixels with depth, as OSD's and OCID's labels are drawn")
    ap.add_argument("--incremental", action="store_true",
                    help="each seed a sequence of its objects put down one at a time, run as one")
    ap.add_argument("--wul3d", default="build/wul3d")
    ap.add_argument("--work", default="out/families", type=pathlib.Path)
    a = ap.parse_args(argv)
    if not 1 <= a.seeds <= 100:
        sys.exit("families.py: --seeds must be 1-100")
    if not pathlib.Path(a.wul3d).is_file():
        sys.exit(f"families.py: {a.wul3d}: not found (build first, or pass --wul3d)")
    families, sensors = a.families.split(","), a.sensors.split(",")
    for name, known in ((families, FAMILIES), (sensors, SENSORS)):
        bad = [n for n in name if n not in known]
        if bad:
            sys.exit(f"families.py: unknown {', '.join(bad)} (known: {', '.join(known)})")
    a.work.mkdir(parents=True, exist_ok=True)
    tag = "default" if not flags else "_".join(f.strip("-").replace("/", "_") for f in flags)
    rows = []
    for family in families:
        first = SEEDS[family][a.set]
        seeds = f"{first}-{first + a.seeds - 1}"
        for sensor in sensors:
            gen = generate(a.work, seeds, family, sensor, incremental=a.incremental)
            out = gen.with_name(f"{gen.name}.{tag}")
            if a.incremental:
                truth, pred = run_sequences(a.wul3d, gen, out, flags)
            else:
                run(a.wul3d, gen, out, flags)
                truth, pred = gen, out
            rows.append((family, sensor, seeds, score(a.wul3d, pred, truth, where_depth=a.where_depth)))
    print(f"set: {a.set}{' (incremental sequences)' if a.incremental else ''}, "
          f"flags: {' '.join(flags) if flags else '(default)'}{', scored where depth' if a.where_depth else ''}")
    print("| family | sensor | seeds | frames | objects | Overlap F | Boundary F | %>=75 |")
    print("|---|---|---|---|---|---|---|---|")
    for family, sensor, seeds, s in rows:
        print(f"| {family} | {sensor} | {seeds} | {s.get('images', 0):.0f} | {s.get('objects', 0):.0f} | "
              f"{s.get('Overlap F', float('nan')):.1f} | {s.get('Boundary F', float('nan')):.1f} | "
              f"{s.get('%>=75', float('nan')):.1f} |")


if __name__ == "__main__":
    main()
