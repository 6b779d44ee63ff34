#!/usr/bin/env python3
"""Procedural labelled RGB-D scenes: a table in a whole room, ray-cast in numpy.

Usage: eval/scenegen.py --out DIR --seeds A-B [--width W --height H] [--family F]
                        [--sensor S] [--incremental]

Writes DIR/scene_SSSSS/{color.png, depth.png, intrinsics.json, label.png} for every seed in
[A, B] (the layout of ../shared/data; label.png: 16-bit, the objects on the table 1..n, 0 the
table, the room and everything else). The same seed gives the same frame. With
--incremental each seed is a sequence, DIR/seq_SSSSS/step_NN: step N shows the scene once its
first N objects were put down, in the order the generator placed them (each on the support
or on one before it), as OCID's sequences grow a pile one object at a time.

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

The shapes and the ray casts are in scene_shapes.py, the sensor models in scene_sensors.py.
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

from scene_sensors import SENSORS, depth_active_stereo, depth_structured_light, depth_tof  # noqa: E402
from scene_shapes import (INF, Box, Cone, Plane, Posed, Sphere, cast, material,  # noqa: E402
                          shade_any, speckled, with_label, yaw_matrix)

VERSION = 2          # of the scenes a seed gives; written to DIR/scenegen.json (2: labels on cylinders)
LABELLED = 0.6      # the share of cylinders (cans, bottles) that wear a label of another colour
MIN_VISIBLE = 300    # an object with fewer pixels with depth is labelled 0 (background)


# ---------------------------------------------------------------------------------------
# The scene: a list of (primitive, label, material).
# ---------------------------------------------------------------------------------------
def table_parts(L, D, table_h, wood):
    """A table L x D with its top at z = 0 (3 cm thick) and four legs down to the floor at
    z = -table_h, all of material `wood` and label 0. Draws nothing from the generator."""
    parts = [(Box([0, 0, -0.015], np.eye(3), [L / 2, D / 2, 0.015]), 0, wood)]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append((Box([sx * (L / 2 - 0.05), sy * (D / 2 - 0.05), -table_h / 2 - 0.015],
                              np.eye(3), [0.025, 0.025, table_h / 2 - 0.015]), 0, wood))
    return parts


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
    parts += table_parts(L, D, table_h, wood)
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


# ---------------------------------------------------------------------------------------
# Objects of the pile and floor families, placed on a support at height z0: each an item
# with its parts, its footprint on the support (a convex polygon, x y) and, for a box
# standing on its base, the top a stack may stand on.
# ---------------------------------------------------------------------------------------
def rect(cx, cy, hx, hy, yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    loc = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    return loc @ np.array([[c, s], [-s, c]]) + [cx, cy]


def disk(cx, cy, r):
    a = np.arange(12) * np.pi / 6
    rr = r / np.cos(np.pi / 12)  # circumscribed: a polygon that does not cut the circle
    return np.stack([cx + rr * np.cos(a), cy + rr * np.sin(a)], axis=1)


def overlap(a, b):
    """Whether two convex polygons overlap (separating axis test; touching is no overlap)."""
    for poly in (a, b):
        e = np.roll(poly, -1, axis=0) - poly
        for nx, ny in np.stack([-e[:, 1], e[:, 0]], axis=1):
            pa, pb = a @ [nx, ny], b @ [nx, ny]
            if pa.max() <= pb.min() + 1e-9 or pb.max() <= pa.min() + 1e-9:
                return False
    return True


def inside(poly, region):
    """Whether all of poly lies in the convex region (a counter-clockwise polygon)."""
    e = np.roll(region, -1, axis=0) - region
    for (x0, y0), (ex, ey) in zip(region, e):
        if ((poly[:, 0] - x0) * ey - (poly[:, 1] - y0) * ex > 1e-9).any():
            return False
    return True


def new_object(rng, prints, z0, allow_lying=True):
    """One YCB-like object centred at x = y = 0 on a support at height z0: a box (standing or
    lying flat), a can, a bottle (body, shoulder, neck, cap), a fruit-like sphere or a can or
    bottle lying on its side. Returns the item: kind, a `make(x, y)` that gives its parts,
    its footprint at the origin, and for boxes their half sizes and yaw."""
    kinds = ["box", "can", "bottle", "sphere", "lying"] if allow_lying else ["box", "can", "bottle", "sphere"]
    w = np.array([4, 2, 1.5, 1.5, 1.0])[:len(kinds)]
    kind = str(rng.choice(kinds, p=w / w.sum()))
    mat = material(rng)
    if kind == "box":
        dims = np.sort(rng.uniform(0.015, 0.09, 3))
        if rng.random() < 0.5:            # standing on its smallest face or lying on its largest
            hx, hy, hz = dims[1], dims[0], dims[2]
        else:
            hx, hy, hz = dims[2], dims[1], dims[0]
        yaw = rng.uniform(0, np.pi)
        return {"kind": kind, "foot": rect(0, 0, hx, hy, yaw), "h": (hx, hy, hz), "yaw": yaw, "top": z0 + 2 * hz,
                "make": lambda x, y: [(Box([x, y, z0 + hz], yaw_matrix(yaw), [hx, hy, hz]), mat)]}
    if kind == "can":
        r, h = rng.uniform(0.025, 0.05), rng.uniform(0.06, 0.15)
        m = mat
        if prints.random() < LABELLED:
            m = with_label(prints, mat, h)
            m["z0"] += z0
            m["z1"] += z0
        return {"kind": kind, "foot": disk(0, 0, r), "r": r, "height": h,
                "make": lambda x, y: [(Cone(x, y, z0, z0 + h, r, r), m)]}
    if kind == "bottle":
        r, hb = rng.uniform(0.025, 0.045), rng.uniform(0.08, 0.16)
        rn, hs, hn = r * rng.uniform(0.3, 0.5), rng.uniform(0.02, 0.05), rng.uniform(0.02, 0.05)
        cap = material(rng, textured=False)
        m = mat
        if prints.random() < LABELLED:
            m = with_label(prints, mat, hb)
            m["z0"] += z0
            m["z1"] += z0
        return {"kind": kind, "foot": disk(0, 0, r), "r": r, "height": hb + hs + hn + 0.015,
                "make": lambda x, y: [(Cone(x, y, z0, z0 + hb, r, r), m),
                                      (Cone(x, y, z0 + hb, z0 + hb + hs, r, rn), mat),
                                      (Cone(x, y, z0 + hb + hs, z0 + hb + hs + hn, rn, rn), mat),
                                      (Cone(x, y, z0 + hb + hs + hn, z0 + hb + hs + hn + 0.015, rn * 1.2,
                                            rn * 1.2), cap)]}
    if kind == "sphere":
        r = rng.uniform(0.025, 0.06)
        return {"kind": kind, "foot": disk(0, 0, r), "r": r,
                "make": lambda x, y: [(Sphere([x, y, z0 + r], r), mat)]}
    r, length = rng.uniform(0.025, 0.045), rng.uniform(0.08, 0.2)
    yaw = rng.uniform(0, np.pi)
    # The axis along the world's x turned by yaw: local z (the cone's axis) -> world.
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.array([[0, -s, c], [0, c, s], [-1, 0, 0.0]])
    return {"kind": kind, "foot": rect(0, 0, length / 2, r, yaw),
            "make": lambda x, y: [(Posed(Cone(0, 0, -length / 2, length / 2, r, r), [x, y, z0 + r], R), mat)]}


def lean_on(rng, box_item, z0):
    """A thin box (a packet, a board) or a bottle leaning on one side face of a standing box,
    its foot on the support: returns (parts, footprint) or None."""
    (bx, by), (hx, hy, hz), yaw = box_item["at"], box_item["h"], box_item["yaw"]
    R = yaw_matrix(yaw)
    axis = int(rng.integers(0, 2))
    sign = rng.choice([-1, 1])
    nf = R[:, axis] * sign                      # the face's outward normal (horizontal)
    half_face = (hx, hy)[axis]
    H = 2 * hz                                  # the box's height above the support
    phi = rng.uniform(0.2, 0.5)                 # tilt from the vertical, towards the face
    up = np.array([0, 0, 1.0])
    a_dir = -np.sin(phi) * nf + np.cos(phi) * up    # up the leaning object
    b_dir = np.cos(phi) * nf + np.sin(phi) * up     # through it, outwards
    t_dir = np.cross(up, nf)
    offset = rng.uniform(-0.5, 0.5) * (hy, hx)[axis]
    face = np.array([bx, by, z0]) + nf * half_face + t_dir * offset
    mat = material(rng)
    if rng.random() < 0.6:
        length, thick, width = rng.uniform(0.08, 0.22), rng.uniform(0.008, 0.025), rng.uniform(0.03, 0.08)
        # Its inner face's top corner on the box's face, or its inner face on the box's top edge.
        x0 = min(length * np.sin(phi), H * np.tan(phi))
        corner = face + nf * x0                 # the inner bottom edge, on the support
        centre = corner + a_dir * length / 2 + b_dir * thick / 2
        Rl = np.stack([b_dir, t_dir, a_dir], axis=1)
        if np.linalg.det(Rl) < 0:
            Rl[:, 1] = -Rl[:, 1]
        prim = Box(centre, Rl, [thick / 2, width / 2, length / 2])
        corners = centre + (np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)]) *
                            [thick / 2, width / 2, length / 2]) @ Rl.T
    else:
        r, length = rng.uniform(0.025, 0.04), rng.uniform(0.12, 0.22)
        # The bottom rim rests on the support; the top rim on the face, or the side on the top edge.
        if length * np.cos(phi) <= H:
            xb = length * np.sin(phi) + r * np.cos(phi)
        else:
            xb = ((H - r * np.sin(phi)) * np.sin(phi) + r) / np.cos(phi)
        base = face + nf * xb + up * r * np.sin(phi)
        centre = base + a_dir * length / 2
        Rl = np.stack([b_dir, t_dir, a_dir], axis=1)
        if np.linalg.det(Rl) < 0:
            Rl[:, 1] = -Rl[:, 1]
        prim = Posed(Cone(0, 0, -length / 2, length / 2, r, r), centre, Rl)
        ring = np.array([[np.cos(q) * r, np.sin(q) * r, e * length / 2] for q in np.arange(8) * np.pi / 4
                         for e in (-1, 1)])
        corners = centre + ring @ Rl.T
    if corners[:, 2].min() < z0 - 1e-6:
        return None
    return [(prim, mat)], hull(corners[:, :2])


def hull(pts):
    """The convex hull of 2-D points, counter-clockwise (monotone chain)."""
    pts = sorted(map(tuple, np.round(pts, 9)))

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1]) -
                                     (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def place_pile(rng, prints, n, z0, region, centre, spread, touch, items, kind_of, parts, label):
    """n objects on the support at height z0 inside `region` (a convex polygon): the first
    near `centre`, each next one slid against an object already there (share `touch`) until
    it touches it or another, else dropped at a free spot within `spread`. Then leans on
    some standing boxes and stacks two or three high on others. Appends to items, parts and
    kind_of; returns the last label used."""
    placed = 0
    tries = 0
    ground = [it for it in items if it["z0"] == z0]
    while placed < n and tries < 10 * n + 20:
        tries += 1
        obj = new_object(rng, prints, z0)
        foot = obj["foot"]
        at = None
        if ground and rng.random() < touch:
            anchor = ground[int(rng.integers(0, len(ground)))]
            theta = rng.uniform(0, 2 * np.pi)
            u = np.array([np.cos(theta), np.sin(theta)])
            prev = None
            for d in np.arange(0.0, 0.4, 0.004):
                p = np.array(anchor["at"]) + d * u
                if not any(overlap(foot + p, it["foot"]) for it in items):
                    prev = d
                    break
            if prev is not None and prev > 0:
                lo, hi = prev - 0.004, prev      # touching: the last overlap .. the first free
                for _ in range(8):
                    mid = (lo + hi) / 2
                    if any(overlap(foot + np.array(anchor["at"]) + mid * u, it["foot"]) for it in items):
                        lo = mid
                    else:
                        hi = mid
                gap = 0.0 if rng.random() < 0.75 else rng.uniform(0.002, 0.015)
                at = np.array(anchor["at"]) + (hi + gap) * u
        else:
            at = np.array(centre) + rng.uniform(-spread, spread, 2)
        if at is None or not inside(foot + at, region) or any(overlap(foot + at, it["foot"]) for it in items):
            continue
        label += 1
        placed += 1
        kind_of[label] = obj["kind"]
        for prim, mat in obj["make"](*at):
            parts.append((prim, label, mat))
        item = {"kind": obj["kind"], "foot": foot + at, "at": at, "z0": z0, "label": label,
                "h": obj.get("h"), "yaw": obj.get("yaw"), "top": obj.get("top"), "busy": False}
        items.append(item)
        ground.append(item)
    # Leaning on a standing box's side.
    for it in [g for g in ground if g["kind"] == "box" and g["h"][2] >= 0.03 and not g["busy"]]:
        if rng.random() < 0.3:
            got = lean_on(rng, it, z0)
            if got is None:
                continue
            lparts, foot = got
            others = [o for o in items if o is not it]
            if not inside(foot, region) or any(overlap(foot, o["foot"]) for o in others):
                continue
            label += 1
            kind_of[label] = "lean"
            for prim, mat in lparts:
                parts.append((prim, label, mat))
            items.append({"kind": "lean", "foot": foot, "at": foot.mean(axis=0), "z0": z0, "label": label,
                          "h": None, "yaw": None, "top": None, "busy": True})
            it["busy"] = True
    # Stacks: a smaller box (or a can) on a box's top, sometimes a third on that.
    for it in [g for g in ground if g["kind"] == "box" and not g["busy"]]:
        it["busy"] = True       # looked at once: a later call stacks nothing more on it
        below = it
        for level in range(2):
            if rng.random() >= (0.45 if level == 0 else 0.35):
                break
            (hx, hy, hz), yaw = below["h"], below["yaw"]
            top = below["top"]
            R2 = yaw_matrix(yaw)
            if rng.random() < 0.75:
                ux, uy = hx * rng.uniform(0.5, 0.95), hy * rng.uniform(0.5, 0.95)
                uz = rng.uniform(0.012, 0.06)
                off = R2 @ np.array([rng.uniform(-1, 1) * (hx - ux), rng.uniform(-1, 1) * (hy - uy), 0])
                c = np.array(below["at"]) + off[:2]
                label += 1
                kind_of[label] = "stack"
                parts.append((Box([c[0], c[1], top + uz], R2, [ux, uy, uz]), label, material(rng)))
                below = {"at": c, "h": (ux, uy, uz), "yaw": yaw, "top": top + 2 * uz}
            else:
                r = min(hx, hy) * rng.uniform(0.6, 0.95)
                if r < 0.02:
                    break
                h = rng.uniform(0.05, 0.12)
                label += 1
                kind_of[label] = "stack"
                parts.append((Cone(below["at"][0], below["at"][1], top, top + h, r, r), label, material(rng)))
                break
    return label


def look_at(target, dist, elevation, azimuth, rng):
    """A camera `dist` from target, `elevation` above the horizontal (pi/2: straight down),
    its heading `azimuth` from the world's +y; right is horizontal, so straight down works."""
    h = np.array([np.sin(azimuth), np.cos(azimuth), 0.0])
    pos = target - h * dist * np.cos(elevation) + np.array([0, 0, dist * np.sin(elevation)])
    fwd = (target - pos) / dist
    right = np.array([np.cos(azimuth), -np.sin(azimuth), 0.0])
    down = np.cross(fwd, right)
    roll = rng.normal(0, 0.03)
    cr, sr = np.cos(roll), np.sin(roll)
    right, down = cr * right + sr * down, -sr * right + cr * down
    return pos, np.stack([right, down, fwd])


def build_pile(rng, prints, kind_of):
    """OCID-like: 5-20 small objects in a pile on a table, touching, leaning and stacked two or
    three high, seen from 0.8-1.5 m at 40-90 degrees (looking down); the table top at z = 0."""
    parts = []
    table_h = rng.uniform(0.70, 0.78)
    L, D = rng.uniform(1.4, 2.2), rng.uniform(0.9, 1.3)
    wood = material(rng, textured=False)
    wood["a"] = np.array([rng.uniform(150, 225), rng.uniform(110, 170), rng.uniform(60, 120)])
    parts += table_parts(L, D, table_h, wood)
    parts.append((Plane([0, 0, 1], -table_h), 0, material(rng)))
    parts.append((Plane([0, -1, 0], -(D / 2 + rng.uniform(0.0, 0.6))), 0, material(rng, textured=False)))
    n = int(rng.integers(5, 21))
    centre = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)])
    region = rect(0, 0, L / 2 - 0.03, D / 2 - 0.03, 0.0)
    items = []
    n_ground = max(3, int(round(n * rng.uniform(0.65, 0.85))))
    label = place_pile(rng, prints, n_ground, 0.0, region, centre, 0.12, 0.85, items, kind_of, parts, 0)
    for _ in range(3):          # stacks and leans fell short of n: more on the table
        if label >= n:
            break
        label = place_pile(rng, prints, n - label, 0.0, region, centre, 0.12, 0.85, items, kind_of, parts, label)
    # Drop the objects past n (stacks and leans may add a few).
    keep = [(p, (lab if lab <= n else 0), m) for p, lab, m in parts if lab <= n]
    for lab in list(kind_of):
        if lab > n:
            del kind_of[lab]
    target = np.array([centre[0], centre[1], 0.03]) + np.append(rng.uniform(-0.08, 0.08, 2), 0)
    pos, Rc = look_at(target, rng.uniform(0.8, 1.5), np.radians(rng.uniform(40, 90)), rng.uniform(-0.5, 0.5), rng)
    return keep, pos, Rc


def build_floor(rng, prints, kind_of):
    """Objects on the floor (z = 0) or a carpet, and on a low board or tray lying on it; the
    floor, the carpet, the board or tray, the walls and a cabinet are background."""
    parts = []
    floor_mat = material(rng)
    parts.append((Plane([0, 0, 1], 0.0), 0, floor_mat))
    back = rng.uniform(0.8, 2.0)
    wall = material(rng, textured=False)
    parts.append((Plane([0, -1, 0], -back), 0, wall))
    side = rng.choice([-1, 1]) * rng.uniform(0.9, 2.0)
    parts.append((Plane([-np.sign(side), 0, 0], -abs(side)), 0, wall))
    if rng.random() < 0.5:
        parts.append((Box([rng.uniform(-0.8, 0.8), back - 0.22, 0.4], np.eye(3), [0.4, 0.2, 0.4]), 0,
                      material(rng)))
    ground_z = 0.0
    region = rect(0, 0, 1.2, min(back, 1.2) - 0.25, 0.0)
    if rng.random() < 0.7:
        cl, cd, ch = rng.uniform(0.6, 1.3), rng.uniform(0.5, 0.9), rng.uniform(0.004, 0.012)
        cc = np.array([rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.1)])
        parts.append((Box([cc[0], cc[1], ch / 2], yaw_matrix(0), [cl, cd, ch / 2]), 0,
                      speckled(rng) if rng.random() < 0.6 else material(rng, textured=True)))
        ground_z = ch
        region = rect(cc[0], cc[1], cl - 0.02, cd - 0.02, 0.0)
    # The board or the tray.
    bl, bd = rng.uniform(0.2, 0.4), rng.uniform(0.15, 0.3)
    bh = rng.uniform(0.01, 0.03)
    byaw = rng.uniform(-0.4, 0.4)
    bc = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)])
    Rb = yaw_matrix(byaw)
    board_mat = material(rng, textured=False)
    if rng.random() < 0.5:
        board_mat["a"] = rng.uniform(200, 245) * np.ones(3)   # a white board, as YCB-Video's
    parts.append((Box([bc[0], bc[1], ground_z + bh / 2], Rb, [bl, bd, bh / 2]), 0, board_mat))
    top = ground_z + bh
    inner_l, inner_d = bl - 0.01, bd - 0.01
    if rng.random() < 0.4:   # a tray: a rim round the board
        rim_h, rim_t = rng.uniform(0.015, 0.04), 0.008
        for (ox, oy, hx, hy) in ((bl - rim_t, 0, rim_t, bd), (-(bl - rim_t), 0, rim_t, bd),
                                 (0, bd - rim_t, bl, rim_t), (0, -(bd - rim_t), bl, rim_t)):
            c = np.append(bc + (Rb @ [ox, oy, 0])[:2], top + rim_h / 2)
            parts.append((Box(c, Rb, [hx, hy, rim_h / 2]), 0, board_mat))
        inner_l, inner_d = bl - 2 * rim_t - 0.003, bd - 2 * rim_t - 0.003
    board_foot = rect(bc[0], bc[1], bl, bd, byaw)
    items = []
    n_board = int(rng.integers(2, 10))
    label = place_pile(rng, prints, n_board, top, rect(bc[0], bc[1], inner_l, inner_d, byaw), bc, 0.08, 0.7,
                       items, kind_of, parts, 0)
    items.append({"kind": "board", "foot": board_foot, "at": bc, "z0": -1.0, "label": 0, "h": None, "yaw": None,
                  "top": None, "busy": True})
    n_floor = int(rng.integers(1, 8))
    label = place_pile(rng, prints, n_floor, ground_z, region, bc + rng.uniform(-0.4, 0.4, 2), 0.4, 0.4,
                       items, kind_of, parts, label)
    target = np.array([bc[0], bc[1], 0.0]) + np.append(rng.uniform(-0.15, 0.15, 2), 0)
    pos, Rc = look_at(target, rng.uniform(0.9, 1.8), np.radians(rng.uniform(35, 80)), rng.uniform(-0.5, 0.5), rng)
    return parts, pos, Rc


FAMILIES = ["tabletop", "pile", "floor"]



def scene(seed, family="tabletop"):
    """The scene of `seed` in `family`: its parts (primitive, label, material; the objects'
    labels 1..n in the order they were put down, each on the support or on one put down
    before), the camera's position and rotation, each label's kind of group, and the
    generator, whose next numbers draw the frame's noise."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r} (one of {', '.join(FAMILIES)})")
    rng = np.random.default_rng(seed)
    kind_of = {}
    prints = np.random.default_rng([seed, 1])
    if family == "tabletop":
        parts, (L, D, _) = build_scene(rng, prints, kind_of)
        pos, Rc = camera(rng, L, D)
    elif family == "pile":
        parts, pos, Rc = build_pile(rng, prints, kind_of)
    else:
        parts, pos, Rc = build_floor(rng, prints, kind_of)
    return parts, pos, Rc, kind_of, rng


def render(seed, width=640, height=480, truth=None, family="tabletop", sensor="structured_light", upto=None):
    """The frame of `seed` in `family` seen by `sensor`: colour, depth (mm), labels,
    intrinsics. With `upto`, the scene as it stood once its object `upto` was put down (the
    objects after it left out), with a sensor noise of its own. `truth`, a dict, gets the
    exact depth (`z`, metres), each pixel's world point (`world`), its part's label before the
    visibility rule (`raw_labels`), each label's kind of group (`kinds`, label -> kind) and
    the sensor model's `clean` pixels (their depth is the ray cast's within `bound`, metres)
    and masks, for the tests and eval/kinds.py."""
    if sensor not in SENSORS:
        raise ValueError(f"unknown sensor {sensor!r} (one of {', '.join(SENSORS)})")
    parts, pos, Rc, kind_of, rng = scene(seed, family)
    if upto is not None:
        parts = [p for p in parts if p[1] <= upto]
        rng = np.random.default_rng([seed, 2, upto])
    s = width / 640.0
    f, cx, cy = SENSORS[sensor]["focal"] * s, (width - 1) / 2.0, (height - 1) / 2.0
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
        col[m] = shade_any(mat, P[m])
        labels[m] = lab
    lum = col.mean(axis=1)
    lam = np.clip(n @ light, 0, 1)
    facing = np.clip(-(n * d_norm).sum(axis=1), 0, 1)
    col = col * (0.45 + 0.45 * lam[:, None] + 0.1 * facing[:, None])
    col += rng.normal(0, 2.0, col.shape)
    col[~hit] = 0
    color = np.clip(col, 0, 255).astype(np.uint8).reshape(height, width, 3)

    if sensor == "structured_light":
        zq, valid, info = depth_structured_light(rng, parts, pos, Rc, P, z, hit, d_norm, f, s, width, height)
    elif sensor == "active_stereo":
        zq, valid, info = depth_active_stereo(rng, parts, pos, Rc, P, z, hit, s, width, height)
    else:
        zq, valid, info = depth_tof(rng, P, z, hit, n, d_norm, lum, pos, width, height, s)
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
        truth["sensor"] = sensor
        truth.update(info)
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
    ap.add_argument("--family", default="tabletop", choices=FAMILIES,
                    help="the kind of scene (default tabletop: a table in a room)")
    ap.add_argument("--sensor", default="structured_light", choices=list(SENSORS),
                    help="the depth sensor's model (default structured_light: Kinect v1)")
    ap.add_argument("--incremental", action="store_true",
                    help="each seed a sequence, DIR/seq_SSSSS/step_NN: its objects put down one at a time")
    a = ap.parse_args(argv)
    try:
        seeds = parse_seeds(a.seeds)
    except ValueError as e:
        sys.exit(f"scenegen.py: {e}")
    if a.width < 32 or a.height < 24:
        sys.exit("scenegen.py: --width and --height must be at least 32 and 24")
    frames = 0
    for seed in seeds:
        if not a.incremental:
            write(a.out / f"scene_{seed:05d}", *render(seed, a.width, a.height, family=a.family, sensor=a.sensor))
            frames += 1
            continue
        n = max(label for _, label, _ in scene(seed, a.family)[0])
        for step in range(1, n + 1):
            write(a.out / f"seq_{seed:05d}" / f"step_{step:02d}",
                  *render(seed, a.width, a.height, family=a.family, sensor=a.sensor, upto=step))
            frames += 1
    # Last, so that a folder with it is whole: eval/benchmark.py reuses only such a folder.
    (a.out / "scenegen.json").write_text(json.dumps(
        {"version": VERSION, "seeds": a.seeds, "width": a.width, "height": a.height,
         "family": a.family, "sensor": a.sensor, "incremental": a.incremental}) + "\n")
    print(f"scenegen.py: {len(seeds)} scenes, {frames} frames -> {a.out}")


if __name__ == "__main__":
    main()
