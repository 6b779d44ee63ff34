#!/usr/bin/python3
"""Runs wul3d and the classical peers on the same OSD frames, scores each with `wul3d eval`
and writes the CSVs that scripts/plot-peers.py draws (docs/peers_quality.png, peers_speed.png).

Usage: eval/peers.py [--wul3d build/wul3d] [--pcl build/eval/wul3d_pcl_peers]
                     [--data ../shared/data] [--out /tmp/wul3d-peers] [--csv-dir docs] [--threads N]

Methods, each on osd_mosd (78 frames, 640x480; learn*, test* and all) and on osd_uncropped
(2 whole frames with floor, walls and furniture), all at 640x480 on this machine in one run:
- wul3d's default (`wul3d run`, objects.png);
- PCL plane + Euclidean clustering and PCL organized multi-plane + connected components
  (eval/pcl_peers.cpp, `--pcl`; built only where CMake finds PCL, Debian's libpcl-dev; skipped
  with a note when the program is missing; its header lists the values): the first on the
  Open3D peer's grid with its plane and size rules, the second PCL's organized segmentation
  demo on the full organized cloud;
- Open3D plane + DBSCAN (Debian's python3-open3d; skipped with a note when it is missing):
  the points in wul3d's depth range (0.2-4.5 m) on every 2nd pixel of every 2nd row (wul3d's
  default --decimate 2 works on the same grid), RANSAC's largest plane (1 cm, 3 points, 1000
  iterations), the points more than 1 cm above it on the camera's side (the usual tabletop
  recipe), DBSCAN (eps 2 cm, 10 points), clusters of 100 input pixels or more are objects;
  each pixel takes its 2 x 2 block's label. Fixed textbook values, not tuned on OSD.

Quality: `wul3d eval` (the OSD/OCID metric), Overlap F and Boundary F. Speed: each method's
median milliseconds per frame without disk I/O (wul3d: summary.json's ms_per_frame_median;
PCL: the program's summary.json, timed around its compute per frame; Open3D: timed around its
compute in this process), the same frames, one after the other,
each method with --threads OpenMP threads (default 1: on a shared machine, OpenMP's barriers
between oversubscribed threads slow every method by a factor that changes from run to run).
OSD is research-only data: it is read from ../shared/data, never shipped; only the scores are.
"""
import argparse
import csv
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

# --threads N sets every method's OpenMP threads; OpenMP reads it when it starts, so before
# Open3D is imported.
os.environ["OMP_NUM_THREADS"] = (sys.argv[sys.argv.index("--threads") + 1]
                                if "--threads" in sys.argv[:-1] else "1")

import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

try:
    import open3d as o3d  # noqa: E402
except ImportError:  # optional peer
    o3d = None

SETS = [("osd_mosd", "learn"), ("osd_mosd", "test"), ("osd_mosd", ""), ("osd_uncropped", "")]


def run(cmd):
    print("$ " + " ".join(map(str, cmd)), file=sys.stderr)
    subprocess.run([str(c) for c in cmd], check=True, stdout=subprocess.DEVNULL)


def frames(folder):
    return sorted(p for p in folder.iterdir() if (p / "depth.png").is_file())


def load(frame):
    k = json.loads((frame / "intrinsics.json").read_text())
    depth = np.asarray(Image.open(frame / "depth.png")).astype(np.float64) * k.get("depth_scale_m_per_unit", 0.001)
    return depth, k


def open3d_plane_dbscan(depth, k):
    """Labels (0 background, 1..n objects) for one frame, at the depth image's size."""
    sub = depth[::2, ::2]
    h, w = sub.shape
    v, u = np.mgrid[0:h, 0:w]
    u, v = u * 2, v * 2
    ok = (sub >= 0.2) & (sub <= 4.5)
    z = sub[ok]
    x = (u[ok] - k["cx"]) * z / k["fx"]
    y = (v[ok] - k["cy"]) * z / k["fy"]
    pts = np.stack([x, y, z], axis=1)
    labels_small = np.zeros((h, w), np.int32)
    if len(pts) >= 100:
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
        (a, b, c, d), _ = pc.segment_plane(distance_threshold=0.01, ransac_n=3, num_iterations=1000)
        dist = pts @ np.array([a, b, c]) + d
        if d < 0:  # the camera (origin) on the positive side
            dist = -dist
        above = dist > 0.01
        idx = np.flatnonzero(above)
        if len(idx) >= 10:
            sel = pc.select_by_index(idx.tolist())
            lab = np.asarray(sel.cluster_dbscan(eps=0.02, min_points=10))
            full = np.full(len(pts), -1, np.int64)
            full[idx] = lab
            # Clusters of 100 input pixels or more (25 grid points of 2 x 2 pixels) are objects.
            ids, counts = np.unique(full[full >= 0], return_counts=True)
            keep = {i: n + 1 for n, i in enumerate(ids[counts * 4 >= 100])}
            mapped = np.array([keep.get(int(l), 0) for l in full], np.int32) if keep else np.zeros(len(full), np.int32)
            labels_small[ok] = mapped
    labels = np.repeat(np.repeat(labels_small, 2, axis=0), 2, axis=1)[: depth.shape[0], : depth.shape[1]]
    return labels


def run_peer(name, fn, data_dir, out):
    times = []
    for frame in frames(data_dir):
        depth, k = load(frame)
        t0 = time.perf_counter()
        labels = fn(depth, k)
        times.append((time.perf_counter() - t0) * 1000.0)
        (out / frame.name).mkdir(parents=True, exist_ok=True)
        Image.fromarray(labels.astype(np.uint16)).save(out / frame.name / "objects.png")
    return times


def score(wul3d, pred, gt, prefix):
    # Beside the predictions, not in them: wul3d eval writes no file inside its inputs.
    out = pred.parent / "scores" / f"{pred.name}-{prefix or 'all'}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [wul3d, "eval", pred, gt, "--json", out]
    if prefix:
        cmd += ["--only", prefix]
    run(cmd)
    return json.loads(out.read_text())["summary"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wul3d", default="build/wul3d")
    ap.add_argument("--pcl", default="build/eval/wul3d_pcl_peers",
                    help="wul3d_pcl_peers (built when CMake finds PCL); skipped when missing")
    ap.add_argument("--data", default="../shared/data")
    ap.add_argument("--out", default="/tmp/wul3d-peers")
    ap.add_argument("--csv-dir", default="docs")
    ap.add_argument("--threads", type=int, default=1, help="OpenMP threads of every method")
    args = ap.parse_args()
    data, out, csv_dir = pathlib.Path(args.data), pathlib.Path(args.out), pathlib.Path(args.csv_dir)
    for name in ("osd_mosd", "osd_uncropped"):
        if not (data / name).is_dir():
            sys.exit(f"peers.py: {data / name} not found (OSD is research-only and not in the repository)")

    # Each method: how its objects.png are made (wul3d, the PCL program, or a function here).
    methods = {"wul3d (default)": ("wul3d", None)}
    if os.access(args.pcl, os.X_OK):
        methods["PCL plane + Euclidean clustering"] = ("pcl", "plane-euclidean")
        methods["PCL organized planes + components"] = ("pcl", "organized")
    else:
        print(f"peers.py: note: {args.pcl} is missing (PCL not found when building): "
              "the PCL peers not run", file=sys.stderr)
    if o3d is None:
        print("peers.py: note: python3-open3d is missing: Open3D plane + DBSCAN not run", file=sys.stderr)
    else:
        methods["Open3D plane + DBSCAN"] = ("python", open3d_plane_dbscan)

    quality, speed = [], []
    for m, (method, (kind, fn)) in enumerate(methods.items()):
        ms = []
        for set_name in ("osd_mosd", "osd_uncropped"):
            pred = out / f"{m}-{set_name}"
            if kind == "wul3d":
                # --overwrite: a rerun finds its own eval-*.json there, which wul3d did not write.
                run([args.wul3d, "run", data / set_name, "--out", pred, "-q", "--overwrite",
                     "--threads", args.threads])
                times = [json.loads((pred / "summary.json").read_text())["ms_per_frame_median"]]
            elif kind == "pcl":
                run([args.pcl, "--method", fn, data / set_name, pred])
                times = [f["ms"] for f in json.loads((pred / "summary.json").read_text())["frames"]]
            else:
                times = run_peer(method, fn, data / set_name, pred)
            if set_name == "osd_mosd":
                ms = times
            for s, prefix in SETS:
                if s != set_name:
                    continue
                r = score(args.wul3d, pred, data / set_name, prefix)
                label = f"{set_name}/{prefix}*" if prefix else set_name
                quality.append({"method": method, "set": label, "images": r["images"],
                                "overlap_f": round(100 * r["overlap_f"], 1),
                                "boundary_f": round(100 * r["boundary_f"], 1)})
                print(f"{method:28s} {label:18s} Overlap F {100 * r['overlap_f']:5.1f}  "
                      f"Boundary F {100 * r['boundary_f']:5.1f}", file=sys.stderr)
        med = statistics.median(ms)
        speed.append({"method": method, "frames": "osd_mosd (78, 640x480)",
                      "threads": args.threads, "ms_median": round(med, 2),
                      "fps": round(1000.0 / med, 1)})
        print(f"{method:28s} {med:8.1f} ms/frame ({1000.0 / med:.1f} FPS)", file=sys.stderr)

    csv_dir.mkdir(parents=True, exist_ok=True)
    for rows, name in ((quality, "peers_quality.csv"), (speed, "peers_speed.csv")):
        with open(csv_dir / name, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        print(f"peers.py: {csv_dir / name}", file=sys.stderr)


if __name__ == "__main__":
    main()
