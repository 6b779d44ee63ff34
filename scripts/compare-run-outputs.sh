#!/usr/bin/env bash
# Compares what two wul3d binaries write with `wul3d run` on the same inputs: every output
# file byte for byte (a PNG whose bytes differ, by its decoded pixels), summary.json on every
# key but the timings (the PNGs through Debian's python3-pil). Used to show that a
# restructuring changed no output.
#   scripts/compare-run-outputs.sh OLD_WUL3D NEW_WUL3D [WORKDIR]
# Inputs: the shipped samples (with --select and --ply once), and ../shared/data's osd_mosd
# (first 10 frames) and osd_moving/slide_learn38 when present.
set -euo pipefail
old=$1 new=$2
work=${3:-$(mktemp -d)}
root=$(cd "$(dirname "$0")/.." && pwd)
shared=$root/../shared/data
cases=(
  "uois|$root/data/samples/uois_tabletop|"
  "uois_sel|$root/data/samples/uois_tabletop|--select 320,240 --ply"
  "pcl|$root/data/samples/pcl_kinect|"
  "pcl_paper|$root/data/samples/pcl_kinect|--preset paper"
)
[[ -d $shared/osd_mosd ]] && cases+=("mosd|$shared/osd_mosd|--frames 10")
[[ -d $shared/osd_moving/slide_learn38 ]] && cases+=("slide|$shared/osd_moving/slide_learn38|")
status=0
for c in "${cases[@]}"; do
  IFS='|' read -r name input args <<<"$c"
  rm -rf "$work/$name"
  # shellcheck disable=SC2086
  "$old" run "$input" -o "$work/$name/old" -q $args >/dev/null
  # shellcheck disable=SC2086
  "$new" run "$input" -o "$work/$name/new" -q $args >/dev/null
  ok=1
  # Every file byte for byte; a PNG whose bytes differ compares by its pixels (an encoder
  # change writes other bytes for the same image), and is counted apart.
  pngs=$(/usr/bin/python3 - "$work/$name/old" "$work/$name/new" <<'PY'
import pathlib, sys
from PIL import Image
old, new = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
skip = {"summary.json", "frames.jsonl"}
def files(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*") if p.is_file() and p.name not in skip)
a, b = files(old), files(new)
if a != b:
    sys.exit(f"different files: {sorted(set(a) ^ set(b))}")
by_pixels = 0
for f in a:
    x, y = (old / f).read_bytes(), (new / f).read_bytes()
    if x == y:
        continue
    if f.endswith(".png"):
        ix, iy = Image.open(old / f), Image.open(new / f)
        if ix.mode == iy.mode and ix.size == iy.size and ix.tobytes() == iy.tobytes():
            by_pixels += 1
            continue
    sys.exit(f"{f} differs")
print(by_pixels)
PY
) || ok=0
  python3 - "$work/$name/old" "$work/$name/new" <<'PY' || ok=0
import json, pathlib, sys
# Per-frame statistics: summary.json's "per_frame" before issue 24, OUT/frames.jsonl since.
timing = {"stage_ms_median", "ms_per_frame_median", "fps", "wall_s", "fps_end_to_end", "peak_rss_mb",
          "threads_stages", "threads_writers"}  # timings, and how a run shared its threads
def load(out):
    s = json.loads((pathlib.Path(out) / "summary.json").read_text())
    lines = pathlib.Path(out) / "frames.jsonl"
    frames = s.pop("per_frame", None)
    if frames is None and lines.exists():
        frames = [json.loads(l) for l in lines.read_text().splitlines()]
    for k in timing | {"frames_file", "error"}: s.pop(k, None)
    for f in frames or []: f.pop("ms", None)
    return s, frames
a, b = load(sys.argv[1]), load(sys.argv[2])
# A key one build writes and the other does not (summary.json's "outputs", a new parameter,
# a new figure of frames.jsonl) is named, not counted: every key both write must agree.
def one_side(what, x, y):
    added = sorted(set(x) ^ set(y))
    for k in added: x.pop(k, None); y.pop(k, None)
    return [f"{what}{k}" for k in added]
added = one_side("", a[0], b[0])
if isinstance(a[0].get("parameters"), dict) and isinstance(b[0].get("parameters"), dict):
    added += one_side("parameters.", a[0]["parameters"], b[0]["parameters"])
frame_keys = set()
for fa, fb in zip(a[1] or [], b[1] or []): frame_keys.update(one_side("frames.jsonl: ", fa, fb))
added += sorted(frame_keys)
if added:
    print(f"keys in one build only (not compared): {', '.join(added)}")
sys.exit(0 if a == b else f"summary.json / frames.jsonl differ beyond timings: {sys.argv[1]}")
PY
  if [[ $ok == 0 ]]; then status=1; echo "$name: DIFFERS"; continue; fi
  by_pixels=""
  [[ ${pngs:-0} != 0 ]] && by_pixels=" (of them $pngs PNGs by their pixels)"
  echo "$name: $(find "$work/$name/new" -type f | wc -l) files identical$by_pixels (summary.json: but timings)"
done
[[ -z ${3:-} ]] && rm -rf "$work"
exit $status
