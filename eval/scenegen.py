#!/usr/bin/env python3
"""Procedural labelled RGB-D scenes: a table in a whole room, ray-cast in numpy.

Usage: eval/scenegen.py --out DIR --seeds A-B [--width W --height H]

Writes DIR/scene_SSSSS/{color.png, depth.png, intrinsics.json, label.png} for every seed in
[A, B] (the layout of ../shared/data; label.png: 16-bit, the objects on the table 1..n, 0 the
table, the room and everything else). The same seed gives the same frame.

What a scene holds (docs/EVAL.md, "Generated scenes"): a table (top and legs) on a floor,
two walls, chairs, a second table with things on it, pictures on the walls; on the table 2-20
objects drawn from boxes standing alone, boxes stacked, flat boxes lying on one another, two
or three boxes flush side by side (mostly of different colours), cylinders, bowls, cups and
boxes leaning on a neighbour, in plain or textured colours; most cylinders wear a label of
another colour, as cans and bottles do. The camera stands at the table and looks down at it
from 0.4-0.9 m above the top.

The depth is a structured-light sensor's (Kinect v1-like, baseline 7.5 cm): depth from
disparity quantized to 1/8 pixel with noise in disparity (so the depth error grows with
z^2), no depth where the projector does not see the point (shadows beside the objects),
holes along depth edges, nothing beyond 4.5 m.

Needs numpy and Pillow (Debian's python3-numpy and python3-pil).
"""
import argparse
import json
import pathlib
import sys

try:
    import numpy as np
    from PIL import Image
except ImportError:
    sys.exit("scenegen.py: numpy and Pillow are missing (apt-get install python3-numpy python3-pil)")

VERSION = 2          # of the scenes a seed gives; written to DIR/scenegen.json (2: labels on cylinders)
FOCAL = 525.0        # pixels at 640x480 (Kinect v1)
BASELINE = 0.075     # metres, projector to depth camera, along the camera's x
SUBPIXEL = 8.0       # disparity quantization: 1/8 pixel
DISPARITY_SIGMA = 0.06  # pixels of noise in disparity (at 640x480)
ZMAX = 4.5
LABELLED = 0.6      # the share of cylinders (cans, bottles) that wear a label of another colour
MIN_VISIBLE = 300    # an object with fewer pixels with depth is labelled 0 (background)
INF = np.float64(1e9)


# ---------------------------------------------------------------------------------------
# Primitives. Each intersects all rays at once: origins o (3,), directions d (N, 3); returns
# t (N,) (INF where missed) and normals (N, 3). World frame: z up, the table top at z = 0.
# ---------------------------------------------------------------------------------------
class Box:
    """An oriented box: centre c, rotation R (columns: its axes in the world), half sizes h."""

    def __init__(self, c, R, h):
        self.c, self.R, self.h = np.asarray(c, float), np.asarray(R, float), np.asarray(h, float)

    def bound(self):
        return self.c, float(np.linalg.norm(self.h))

    def intersect(self, o, d):
        lo = (o - self.c) @ self.R           # origin in the box's frame
        ld = d @ self.R
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / np.where(np.abs(ld) < 1e-12, 1e-12, ld)
            t1 = (-self.h - lo) * inv
            t2 = (self.h - lo) * inv
        tmin = np.minimum(t1, t2)
        tmax = np.maximum(t1, t2)
        tn = tmin.max(axis=1)
        tf = tmax.min(axis=1)
        hit = (tn <= tf) & (tf > 1e-6)
        t = np.where(hit, np.where(tn > 1e-6, tn, tf), INF)
        axis = tmin.argmax(axis=1)
        sign = -np.sign(np.take_along_axis(ld, axis[:, None], axis=1))[:, 0]
        n_local = np.zeros_like(ld)
        n_local[np.arange(len(ld)), axis] = sign
        return t, n_local @ self.R.T


class Cone:
    """A vertical open or closed truncated cone (a cylinder when r0 == r1) from z0 to z1 with
    radii r0 (bottom) and r1 (top), axis through (cx, cy). `open_top`: a cup or a bowl, seen
    inside over its rim, with a floor `floor` above z0."""

    def __init__(self, cx, cy, z0, z1, r0, r1, open_top=False, floor=0.006):
        self.cx, self.cy, self.z0, self.z1, self.r0, self.r1 = cx, cy, z0, z1, r0, r1
        self.open_top, self.floor = open_top, floor

    def bound(self):
        half = (self.z1 - self.z0) / 2
        return np.array([self.cx, self.cy, self.z0 + half]), float(np.hypot(max(self.r0, self.r1), half))

    def intersect(self, o, d):
        k = (self.r1 - self.r0) / (self.z1 - self.z0)
        ox, oy, oz = o[0] - self.cx, o[1] - self.cy, o[2]
        dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
        # x^2 + y^2 = (r0 + k (z - z0))^2
        rz0 = self.r0 + k * (oz - self.z0)
        a = dx * dx + dy * dy - (k * dz) ** 2
        b = 2 * (ox * dx + oy * dy - rz0 * k * dz)
        c = ox * ox + oy * oy - rz0 * rz0
        disc = b * b - 4 * a * c
        ok = (disc >= 0) & (np.abs(a) > 1e-12)
        sq = np.sqrt(np.where(ok, disc, 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = np.where(ok, (-b - sq) / (2 * a), INF)
            tb = np.where(ok, (-b + sq) / (2 * a), INF)
        t1, t2 = np.minimum(ta, tb), np.maximum(ta, tb)
        z1, z2 = oz + t1 * dz, oz + t2 * dz
        in1 = (t1 > 1e-6) & (z1 >= self.z0) & (z1 <= self.z1)
        in2 = (t2 > 1e-6) & (z2 >= self.z0) & (z2 <= self.z1)
        t = np.full(len(d), INF)
        inner = np.zeros(len(d), bool)
        t = np.where(in1, t1, t)
        # Top cap (closed) or the inside (open): the ray enters through the top disk.
        with np.errstate(divide="ignore", invalid="ignore"):
            ttop = (self.z1 - oz) / dz
        xt, yt = ox + ttop * dx, oy + ttop * dy
        through_top = (ttop > 1e-6) & (xt * xt + yt * yt <= self.r1 * self.r1)
        if self.open_top:
            zf = self.z0 + self.floor
            with np.errstate(divide="ignore", invalid="ignore"):
                tf = (zf - oz) / dz
            xf, yf = ox + tf * dx, oy + tf * dy
            rf = self.r0 + k * self.floor
            floor_hit = through_top & (tf > 1e-6) & (xf * xf + yf * yf <= rf * rf)
            wall_in = through_top & in2 & (~floor_hit | (t2 < tf))
            use_in = ~in1 & wall_in
            t = np.where(use_in, t2, t)
            inner |= use_in
            use_floor = ~in1 & ~wall_in & floor_hit
            t = np.where(use_floor, tf, t)
        else:
            use_top = through_top & (~in1 | (ttop < t1))
            t = np.where(use_top, ttop, t)
        p = o + np.where(t[:, None] < INF, t[:, None], 0) * d
        px, py = p[:, 0] - self.cx, p[:, 1] - self.cy
        r = np.sqrt(px * px + py * py) + 1e-12
        n = np.stack([px / r, py / r, -k * np.ones_like(r)], axis=1)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        n = np.where(inner[:, None], -n, n)
        flat = np.abs(p[:, 2] - self.z1) < 1e-7
        if self.open_top:
            flat = np.abs(p[:, 2] - (self.z0 + self.floor)) < 1e-7
        n[flat] = [0.0, 0.0, 1.0]
        return t, n


class Plane:
    """An infinite plane n . X = off (the floor, a wall), seen from its front only."""

    def __init__(self, n, off):
        self.n, self.off = np.asarray(n, float), off

    def bound(self):
        return None

    def intersect(self, o, d):
        dn = d @ self.n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self.off - o @ self.n) / dn
        t = np.where((dn < -1e-9) & (t > 1e-6), t, INF)
        return t, np.broadcast_to(self.n, d.shape)


# ---------------------------------------------------------------------------------------
# Materials: a colour, optionally textured (stripes or checks in the surface's own
# coordinates, so a box's faces carry one pattern).
# ---------------------------------------------------------------------------------------
def material(rng, textured=None):
    base = rng.uniform(20, 235, 3)
    if textured is None:
        textured = rng.random() < 0.35
    if not textured:
        return {"kind": "plain", "a": base}
    other = np.clip(base + rng.choice([-1, 1], 3) * rng.uniform(40, 110, 3), 0, 255)
    return {"kind": rng.choice(["stripes", "checks"]), "a": base, "b": other,
            "scale": rng.uniform(0.01, 0.04)}


def with_label(rng, body, h):
    """A can's or a bottle's label: a band of another colour round the body, from z0 to z1
    (world heights; the cylinder stands on the table top, z = 0)."""
    a = body["a"]
    while True:
        b = rng.uniform(20, 235, 3)
        if np.linalg.norm(b - a) >= 60:
            break
    return {"kind": "label", "body": body, "b": b,
            "z0": h * rng.uniform(0.03, 0.35), "z1": h * rng.uniform(0.6, 0.97)}


def shade(mat, p):
    if mat["kind"] == "label":
        on = (p[:, 2] >= mat["z0"]) & (p[:, 2] <= mat["z1"])
        return np.where(on[:, None], mat["b"], shade(mat["body"], p))
    a = np.broadcast_to(mat["a"], p.shape)
    if mat["kind"] == "plain":
        return a
    s = mat["scale"]
    if mat["kind"] == "stripes":
        m = (np.floor((p[:, 0] + p[:, 1] + p[:, 2]) / s) % 2).astype(bool)
    else:
        m = ((np.floor(p[:, 0] / s) + np.floor(p[:, 1] / s) + np.floor(p[:, 2] / s)) % 2).astype(bool)
    return np.where(m[:, None], mat["b"], a)


def yaw_matrix(yaw, tilt_axis=None, tilt=0.0):
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    if tilt_axis is not None and tilt != 0.0:
        ax = R[:, tilt_axis]
        K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
        Rt = np.eye(3) + np.sin(tilt) * K + (1 - np.cos(tilt)) * K @ K
        R = Rt @ R
    return R


# ---------------------------------------------------------------------------------------
# The scene: a list of (primitive, label, material).
# ---------------------------------------------------------------------------------------
def build_scene(rng, prints, kind_of=None):
    """`prints`: the random stream of the cylinders' labels, apart from `rng` so that adding
    them left every layout as it was. `kind_of`, a dict, gets each object's label -> the kind
    of group it was drawn in (box, stack, flat, lean, flush, cylinder, cup, bowl); it draws
    nothing, so the layout is the same with or without it."""
    kind_of = {} if kind_of is None else kind_of
    parts = []
    table_h = rng.uniform(0.70, 0.78)
    L, D = rng.uniform(1.2, 1.8), rng.uniform(0.7, 1.0)
    wood = material(rng, textured=False)
    wood["a"] = np.array([rng.uniform(150, 210), rng.uniform(110, 160), rng.uniform(70, 120)])
    parts.append((Box([0, 0, -0.015], np.eye(3), [L / 2, D / 2, 0.015]), 0, wood))
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append((Box([sx * (L / 2 - 0.05), sy * (D / 2 - 0.05), -table_h / 2 - 0.015],
                              np.eye(3), [0.025, 0.025, table_h / 2 - 0.015]), 0, wood))
    # Room: floor, a wall behind the table and one to a side.
    parts.append((Plane([0, 0, 1], -table_h), 0, material(rng)))
    back = rng.uniform(0.3, 1.5) + D / 2
    side = rng.choice([-1, 1]) * (rng.uniform(0.2, 1.2) + L / 2)
    wall_mat = material(rng, textured=False)
    parts.append((Plane([0, -1, 0], -back), 0, wall_mat))
    parts.append((Plane([-np.sign(side), 0, 0], -abs(side)), 0, wall_mat))
    # Pictures on the back wall, a shelf with a box on it.
    for _ in range(rng.integers(0, 3)):
        w, h = rng.uniform(0.2, 0.6), rng.uniform(0.2, 0.5)
        parts.append((Box([rng.uniform(-L / 2, L / 2), back - 0.01, rng.uniform(0.2, 0.8)], np.eye(3),
                          [w / 2, 0.01, h / 2]), 0, material(rng)))
    if rng.random() < 0.5:
        sz = rng.uniform(0.3, 0.6)
        parts.append((Box([rng.uniform(-L / 2, L / 2), back - 0.1, sz], np.eye(3), [0.25, 0.1, 0.01]), 0,
                      material(rng)))
        parts.append((Box([parts[-1][0].c[0], back - 0.1, sz + 0.06], np.eye(3), [0.05, 0.05, 0.05]), 0,
                      material(rng)))
    # Chairs beside the table.
    for _ in range(rng.integers(0, 3)):
        x = rng.uniform(-L / 2, L / 2)
        y = rng.choice([-1, 1]) * (D / 2 + rng.uniform(0.1, 0.4))
        if y < 0 and rng.random() < 0.7:
            y = D / 2 + rng.uniform(0.1, 0.4)  # mostly on the far side, in view
        m = material(rng)
        seat = -table_h + 0.45
        parts.append((Box([x, y, seat], np.eye(3), [0.22, 0.22, 0.02]), 0, m))
        parts.append((Box([x, y + np.sign(y) * 0.2, seat + 0.25], np.eye(3), [0.22, 0.02, 0.25]), 0, m))
        parts.append((Box([x, y, (seat - table_h) / 2], np.eye(3), [0.02, 0.02, (seat + table_h) / 2]), 0, m))
    # A second table beside this one, with something on it.
    if rng.random() < 0.6:
        sgn = rng.choice([-1, 1])
        h2 = rng.uniform(-0.1, 0.1)
        x2 = sgn * (L / 2 + rng.uniform(0.3, 0.8) + 0.4)
        parts.append((Box([x2, 0.2, h2 - 0.015], np.eye(3), [0.4, 0.35, 0.015]), 0, wood))
        parts.append((Box([x2, 0.2, (h2 - table_h) / 2], np.eye(3), [0.03, 0.03, (h2 + table_h) / 2]), 0, wood))
        parts.append((Box([x2, 0.2, h2 + 0.06], yaw_matrix(rng.uniform(0, 3)), [0.08, 0.05, 0.06]), 0,
                      material(rng)))

    # Objects on the table.
    n_target = int(rng.integers(2, 21))
    footprints = []  # (x, y, radius)
    label = 0

    def free(x, y, r):
        if abs(x) > L / 2 - r - 0.02 or abs(y) > D / 2 - r - 0.02:
            return False
        return all((x - a) ** 2 + (y - b) ** 2 >= (r + c + 0.01) ** 2 for a, b, c in footprints)

    def spot(r):
        for _ in range(60):
            x, y = rng.uniform(-L / 2, L / 2), rng.uniform(-D / 2, D / 2)
            if free(x, y, r):
                return x, y
        return None

    kinds = ["box", "stack", "flat", "flush", "cylinder", "bowl", "cup", "lean"]
    weights = np.array([3, 1.5, 1.5, 2, 2, 1.2, 1.5, 1.0])
    tries = 0
    while label < n_target and tries < 200:
        tries += 1
        kind = rng.choice(kinds, p=weights / weights.sum())
        if kind in ("box", "stack", "flat", "lean"):
            hx, hy = rng.uniform(0.03, 0.12, 2)
            hz = rng.uniform(0.012, 0.03) if kind == "flat" else rng.uniform(0.025, 0.12)
            r = np.hypot(hx, hy)
            if kind == "lean":
                r += 0.08
            at = spot(r)
            if at is None:
                continue
            yaw = rng.uniform(0, np.pi)
            R = yaw_matrix(yaw)
            label += 1
            kind_of[label] = str(kind)
            parts.append((Box([at[0], at[1], hz], R, [hx, hy, hz]), label, material(rng)))
            footprints.append((at[0], at[1], r))
            top = 2 * hz
            if kind in ("stack", "flat") and label < n_target:
                # One (or two) boxes on top, smaller, offset a little.
                for _ in range(1 if kind == "stack" or rng.random() < 0.6 else 2):
                    if label >= n_target:
                        break
                    ux, uy = hx * rng.uniform(0.5, 0.95), hy * rng.uniform(0.5, 0.95)
                    uz = rng.uniform(0.012, 0.03) if kind == "flat" else rng.uniform(0.02, 0.08)
                    off = R @ np.array([rng.uniform(-1, 1) * (hx - ux), rng.uniform(-1, 1) * (hy - uy), 0])
                    Ru = yaw_matrix(yaw + rng.uniform(-0.3, 0.3))
                    label += 1
                    kind_of[label] = str(kind)
                    parts.append((Box([at[0] + off[0], at[1] + off[1], top + uz], Ru, [ux, uy, uz]), label,
                                  material(rng)))
                    top += 2 * uz
            if kind == "lean" and label < n_target:
                # A thin box leaning on this one's side, its foot on the table.
                tilt = rng.uniform(0.25, 0.5)
                lh = rng.uniform(0.6, 0.9) * hz / np.cos(tilt) + 0.02
                lw, lt = rng.uniform(0.03, hy), rng.uniform(0.008, 0.02)
                side_dir = R[:, 0]
                base = np.array([at[0], at[1], 0]) + side_dir * (hx + lh * np.sin(tilt) + lt)
                Rl = yaw_matrix(yaw, tilt_axis=1, tilt=-tilt)
                centre = base - Rl[:, 2] * 0 + Rl[:, 2] * lh
                centre[2] = max(centre[2], lh * np.cos(tilt))
                label += 1
                kind_of[label] = str(kind)
                parts.append((Box(centre, Rl, [lt, lw, lh]), label, material(rng)))
        elif kind == "flush":
            count = 2 if rng.random() < 0.6 else 3
            hy = rng.uniform(0.03, 0.1)
            hxs = rng.uniform(0.02, 0.08, count)
            hzs = rng.uniform(0.03, 0.12, count)
            if rng.random() < 0.5:
                hzs[:] = hzs[0]  # the same height: no step across the contact either
            width = 2 * hxs.sum()
            r = np.hypot(width / 2, hy)
            at = spot(r)
            if at is None or label + count > n_target + 1:
                continue
            yaw = rng.uniform(0, np.pi)
            R = yaw_matrix(yaw)
            same = rng.random() < 0.2
            m0 = material(rng)
            x = -width / 2
            for i in range(count):
                x += hxs[i]
                c = np.array([at[0], at[1], 0]) + R @ np.array([x, 0, 0])
                c[2] = hzs[i]
                label += 1
                kind_of[label] = str(kind)
                parts.append((Box(c, R, [hxs[i], hy, hzs[i]]), label, m0 if same else material(rng)))
                x += hxs[i]
            footprints.append((at[0], at[1], r))
        else:
            if kind == "cylinder":
                r0 = r1 = rng.uniform(0.025, 0.06)
                h, open_top = rng.uniform(0.06, 0.25), False
            elif kind == "cup":
                r0 = rng.uniform(0.025, 0.045)
                r1 = r0 * rng.uniform(1.0, 1.2)
                h, open_top = rng.uniform(0.07, 0.12), True
            else:
                r0 = rng.uniform(0.03, 0.06)
                r1 = r0 * rng.uniform(1.6, 2.2)
                h, open_top = rng.uniform(0.04, 0.08), True
            at = spot(r1)
            if at is None:
                continue
            label += 1
            kind_of[label] = str(kind)
            mat = material(rng)
            if kind == "cylinder" and prints.random() < LABELLED:
                mat = with_label(prints, mat, h)
            parts.append((Cone(at[0], at[1], 0.0, h, r0, r1, open_top), label, mat))
            footprints.append((at[0], at[1], r1))
    return parts, (L, D, table_h)


def camera(rng, L, D):
    """A pose looking at the table: position in the world, rotation world -> camera."""
    target = np.array([rng.uniform(-0.15, 0.15) * L, rng.uniform(-0.1, 0.15) * D, 0.0])
    dist = rng.uniform(0.7, 1.4)
    height = rng.uniform(0.4, 0.9)
    az = rng.uniform(-0.6, 0.6)
    back = np.sqrt(max(dist * dist - height * height, 0.05))
    pos = target + np.array([np.sin(az) * back, -D / 2 * 0.3 - np.cos(az) * back, height])
    fwd = target - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0, 0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(fwd, right)
    roll = rng.normal(0, 0.03)
    cr, sr = np.cos(roll), np.sin(roll)
    right, down = cr * right + sr * down, -sr * right + cr * down
    return pos, np.stack([right, down, fwd])  # rows: camera axes in the world


def near_rays(prim, o, d):
    """Indices of the rays (unit directions d from o) that pass within the primitive's
    bounding sphere, or None for all: a ray is only intersected with what it may hit."""
    b = prim.bound()
    if b is None:
        return None
    c, r = b
    w = c - o
    along = d @ w
    dist2 = w @ w - along * along
    return np.nonzero((dist2 <= r * r) & (along > -r))[0]


def cast(parts, o, d):
    t_best = np.full(len(d), INF)
    idx = np.full(len(d), -1)
    n_best = np.zeros_like(d)
    for i, (prim, _, _) in enumerate(parts):
        sel = near_rays(prim, o, d)
        if sel is None:
            t, n = prim.intersect(o, d)
            closer = t < t_best
            t_best = np.where(closer, t, t_best)
            idx = np.where(closer, i, idx)
            n_best = np.where(closer[:, None], n, n_best)
        elif len(sel):
            t, n = prim.intersect(o, d[sel])
            closer = t < t_best[sel]
            at = sel[closer]
            t_best[at] = t[closer]
            idx[at] = i
            n_best[at] = n[closer]
    return t_best, idx, n_best


def occluded(parts, o, d, t_max):
    """Whether anything lies on the rays from o along d before t_max (shadow rays)."""
    blocked = np.zeros(len(d), bool)
    for prim, _, _ in parts:
        sel = near_rays(prim, o, d)
        if sel is None:
            t, _ = prim.intersect(o, d)
            blocked |= t < t_max * (1 - 1e-4) - 1e-4
        elif len(sel):
            t, _ = prim.intersect(o, d[sel])
            blocked[sel] |= t < t_max[sel] * (1 - 1e-4) - 1e-4
    return blocked


def render(seed, width=640, height=480, truth=None):
    """The frame of `seed`: colour, depth (mm), labels, intrinsics. `truth`, a dict, gets the
    exact depth (`z`, metres), each pixel's world point (`world`), its part's label before
    the visibility rule (`raw_labels`) and each label's kind of group (`kinds`, label ->
    build_scene's kind), for the tests and eval/kinds.py."""
    rng = np.random.default_rng(seed)
    kind_of = {}
    parts, (L, D, _) = build_scene(rng, np.random.default_rng([seed, 1]), kind_of)
    pos, Rc = camera(rng, L, D)
    s = width / 640.0
    f, cx, cy = FOCAL * s, (width - 1) / 2.0, (height - 1) / 2.0
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    rays_cam = np.stack([(u - cx) / f, (v - cy) / f, np.ones_like(u, dtype=float)], axis=-1).reshape(-1, 3)
    d_world = rays_cam @ Rc  # camera -> world (rows of Rc are the camera axes)
    d_norm = d_world / np.linalg.norm(d_world, axis=1, keepdims=True)
    t, idx, n = cast(parts, pos, d_norm)
    hit = t < INF
    P = pos + np.where(hit[:, None], t[:, None], 0) * d_norm
    z = (P - pos) @ Rc[2]  # depth along the optical axis

    # Colour: each part's material, Lambert shading from a light above and a little behind
    # the camera, plus ambient; a little sensor noise.
    light = np.array([0.3, -0.5, 1.0])
    light /= np.linalg.norm(light)
    col = np.zeros((len(d_norm), 3))
    labels = np.zeros(len(d_norm), np.int32)
    for i, (_, lab, mat) in enumerate(parts):
        m = idx == i
        if not m.any():
            continue
        col[m] = shade(mat, P[m])
        labels[m] = lab
    lam = np.clip(n @ light, 0, 1)
    facing = np.clip(-(n * d_norm).sum(axis=1), 0, 1)
    col = col * (0.45 + 0.45 * lam[:, None] + 0.1 * facing[:, None])
    col += rng.normal(0, 2.0, col.shape)
    col[~hit] = 0
    color = np.clip(col, 0, 255).astype(np.uint8).reshape(height, width, 3)

    # Depth: the projector sits BASELINE to the camera's right; a point it does not see has
    # no depth (the shadow beside an object).
    proj = pos + Rc[0] * BASELINE
    to_p = P - proj
    dist_p = np.linalg.norm(to_p, axis=1)
    valid = hit & (z > 0.3) & (z < ZMAX)
    shadow = np.zeros(len(d_norm), bool)
    cand = np.nonzero(valid)[0]
    shadow[cand] = occluded(parts, proj, to_p[cand] / dist_p[cand, None], dist_p[cand])
    valid &= ~shadow
    # Disparity, its noise and its 1/8-pixel steps: depth error grows with z^2.
    disp = np.where(valid, f * BASELINE / np.where(z > 0, z, 1), 0)
    disp = disp + rng.normal(0, DISPARITY_SIGMA * s, disp.shape)
    disp = np.round(disp * SUBPIXEL) / SUBPIXEL
    zq = np.where(valid & (disp > 0), f * BASELINE / np.where(disp > 0, disp, 1), 0)
    zq = zq.reshape(height, width)
    valid = valid.reshape(height, width) & (zq > 0)
    # Depth edges: where depth jumps to a neighbour by more than 2 cm plus four disparity
    # steps, both edge pixels lose their depth half the time (the sensor's correlation
    # window straddles the edge).
    jump = np.zeros_like(valid)
    step = 0.02 + 4 * zq * zq / (f * BASELINE * SUBPIXEL)
    dz_u = np.abs(np.diff(zq, axis=1)) > np.minimum(step[:, 1:], step[:, :-1])
    dz_v = np.abs(np.diff(zq, axis=0)) > np.minimum(step[1:, :], step[:-1, :])
    jump[:, 1:] |= dz_u
    jump[:, :-1] |= dz_u
    jump[1:, :] |= dz_v
    jump[:-1, :] |= dz_v
    valid &= ~(jump & (rng.random(jump.shape) < 0.5))
    depth_mm = np.where(valid, np.round(zq * 1000), 0).astype(np.uint16)

    # Labels: objects with too few pixels with depth are background (nothing could find them).
    labels = labels.reshape(height, width)
    out = np.zeros_like(labels, dtype=np.uint16)
    next_id = 0
    out_kinds = {}
    for lab in range(1, labels.max() + 1):
        m = (labels == lab) & valid
        if m.sum() * (640.0 / width) ** 2 >= MIN_VISIBLE:
            next_id += 1
            out[labels == lab] = next_id
            out_kinds[next_id] = kind_of[lab]
    if truth is not None:
        truth["z"] = np.where(hit, z, 0).reshape(height, width)
        truth["world"] = P.reshape(height, width, 3)
        truth["raw_labels"] = labels
        truth["kinds"] = out_kinds
        truth["sigma_px"] = DISPARITY_SIGMA * s
        truth["fb"] = f * BASELINE
    intr = {"fx": f, "fy": f, "cx": cx, "cy": cy, "width": width, "height": height,
            "depth_scale_m_per_unit": 0.001}
    return color, depth_mm, out, intr


def write(folder, color, depth, label, intr):
    folder.mkdir(parents=True, exist_ok=True)
    Image.fromarray(color).save(folder / "color.png")
    Image.fromarray(depth).save(folder / "depth.png")
    Image.fromarray(label).save(folder / "label.png")
    (folder / "intrinsics.json").write_text(json.dumps(intr, indent=1) + "\n")


def parse_seeds(text):
    a, _, b = text.partition("-")
    a = int(a)
    b = int(b) if b else a
    if b < a:
        raise ValueError(f"--seeds {text}: the range is empty")
    return range(a, b + 1)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument("--out", required=True, type=pathlib.Path)
    ap.add_argument("--seeds", required=True, help="A-B (inclusive) or one seed")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    a = ap.parse_args(argv)
    try:
        seeds = parse_seeds(a.seeds)
    except ValueError as e:
        sys.exit(f"scenegen.py: {e}")
    if a.width < 32 or a.height < 24:
        sys.exit("scenegen.py: --width and --height must be at least 32 and 24")
    for seed in seeds:
        write(a.out / f"scene_{seed:05d}", *render(seed, a.width, a.height))
    # Last, so that a folder with it is whole: eval/benchmark.py reuses only such a folder.
    (a.out / "scenegen.json").write_text(json.dumps(
        {"version": VERSION, "seeds": a.seeds, "width": a.width, "height": a.height}) + "\n")
    print(f"scenegen.py: {len(seeds)} scenes -> {a.out}")


if __name__ == "__main__":
    main()
