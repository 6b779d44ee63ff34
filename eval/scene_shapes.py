"""The shapes of eval/scenegen.py's scenes and how rays meet them: boxes, cones (cylinders,
bowls, cups), planes, spheres and posed primitives, their materials, and the ray casts
(first hit, and whether anything lies before a point).
"""
import sys

try:
    import numpy as np
except ImportError:
    sys.exit("scenegen.py: numpy is missing (apt-get install python3-numpy)")

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
# More primitives for the pile and floor families: a sphere (fruit, balls) and any
# primitive turned and moved (a can or a bottle lying on its side).
# ---------------------------------------------------------------------------------------
class Sphere:
    def __init__(self, c, r):
        self.c, self.r = np.asarray(c, float), float(r)

    def bound(self):
        return self.c, self.r

    def intersect(self, o, d):
        w = o - self.c
        b = d @ w
        c = w @ w - self.r * self.r
        disc = b * b - c
        sq = np.sqrt(np.maximum(disc, 0))
        t1, t2 = -b - sq, -b + sq
        t = np.where(disc >= 0, np.where(t1 > 1e-6, t1, np.where(t2 > 1e-6, t2, INF)), INF)
        p = o + np.where(t[:, None] < INF, t[:, None], 0) * d
        n = (p - self.c) / self.r
        return t, n


class Posed:
    """A primitive built in its own frame, placed at c with rotation R (columns: its axes in
    the world). Directions stay unit length, so t is the world's."""

    def __init__(self, prim, c, R):
        self.prim, self.c, self.R = prim, np.asarray(c, float), np.asarray(R, float)

    def bound(self):
        b = self.prim.bound()
        return None if b is None else (self.c + self.R @ b[0], b[1])

    def intersect(self, o, d):
        t, n = self.prim.intersect((o - self.c) @ self.R, d @ self.R)
        return t, n @ self.R.T


def speckled(rng):
    """A carpet's material: two close colours in small cells, hashed from the cell's position."""
    base = rng.uniform(40, 200, 3)
    return {"kind": "speckle", "a": base, "b": np.clip(base + rng.uniform(-45, 45, 3), 0, 255),
            "scale": rng.uniform(0.004, 0.012)}


def shade_any(mat, p):
    """shade(), and the carpet's speckle (tabletop never draws it)."""
    if mat["kind"] == "speckle":
        s = mat["scale"]
        h = np.sin(np.floor(p[:, 0] / s) * 12.9898 + np.floor(p[:, 1] / s) * 78.233) * 43758.5453
        m = (h - np.floor(h)) < 0.5
        return np.where(m[:, None], mat["b"], np.broadcast_to(mat["a"], p.shape))
    return shade(mat, p)


# ---------------------------------------------------------------------------------------
# Ray casting over a scene's parts: (primitive, label, material) triples.
# ---------------------------------------------------------------------------------------
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
