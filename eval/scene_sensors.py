"""The depth sensors of eval/scenegen.py's scenes: structured light (Kinect v1), active
stereo (RealSense D4xx) and time of flight (Kinect v2, Azure Kinect), each a function from
the ray-cast scene to the depth image it would give (docs/EVAL.md, "Sensors").
"""
import sys

try:
    import numpy as np
except ImportError:
    sys.exit("scenegen.py: numpy is missing (apt-get install python3-numpy)")

from scene_shapes import occluded  # noqa: E402

FOCAL = 525.0        # pixels at 640x480 (Kinect v1)
BASELINE = 0.075     # metres, projector to depth camera, along the camera's x
SUBPIXEL = 8.0       # disparity quantization: 1/8 pixel
DISPARITY_SIGMA = 0.06  # pixels of noise in disparity (at 640x480)
ZMAX = 4.5


# ---------------------------------------------------------------------------------------
# Sensors. Colour and depth come from one camera (depth registered to the colour image),
# 640x480 for all (or --width/--height, the focal length scaled with the width); each
# sensor's focal length is its colour camera's at 640x480.
# ---------------------------------------------------------------------------------------
SENSORS = {
    # Kinect v1: colour and depth 640x480, f = 525 px (the OpenNI default).
    "structured_light": {"focal": FOCAL},
    # RealSense D435: its colour stream at 640x480 has f of about 615 px (69 x 42 degrees).
    "active_stereo": {"focal": 615.0},
    # Azure Kinect, narrow-field unbinned depth (640x576, 75 x 65 degrees: f of about 504 px),
    # cropped to 640x480, colour transformed into the depth camera (as its SDK does).
    "tof": {"focal": 504.0},
}

# Active stereo (RealSense D4xx). Depth RMS error = z^2 x subpixel RMS / (f x baseline)
# (Intel's D400 depth-quality white paper): the noise is in disparity, so it grows with z^2.
AS_FOCAL_DEPTH = 383.0   # px: the D435's depth imagers at 640x480 (87 x 58 degrees full field, cropped)
AS_BASELINE = 0.050      # m: the D435's left-right imager baseline (D415: 55 mm)
AS_SUBPIXEL_RMS = 0.08   # px: the white paper's typical subpixel RMS on a textured target
AS_ZMIN, AS_ZMAX = 0.3, 6.0  # m: about the D435's minimum depth at 640x480; far enough for a room
AS_FATTEN = 3            # px at 640: foreground bleeds into the background up to half a 7 x 7
                         # correlation window (edge fattening of block matching), 1-3 px a pixel
AS_HOLES = 0.02          # share of pixels lost in speckle holes (blobs of a few px where matching fails)

# Time of flight (Kinect v2 / Azure Kinect, AMCW).
TOF_ZMIN, TOF_ZMAX = 0.5, 3.86   # m: Azure Kinect NFOV unbinned operating range
TOF_SIGMA_REF = 0.0015   # m of random error at amplitude TOF_AMP_REF (Kinect v2 / Azure: 1-2 mm at
TOF_AMP_REF = 0.25       # 1 m on a mid-grey target); it grows as 1/sqrt(amplitude)
TOF_SIGMA_MAX = 0.017    # m: the Azure Kinect's documented bound on the random error's std
TOF_SIGMA_MIN = 0.0005
TOF_AMP_DROP = (0.02, 0.06)  # amplitude (albedo x cos / range^2, m^-2) below which a pixel is
                             # always / never invalidated: the depth engine drops low-signal pixels
                             # (dark surfaces, grazing angles, far)
TOF_EDGE = 0.02          # m: a jump to a neighbour that makes a pixel's footprint straddle an edge
TOF_FLY = 0.6            # share of edge pixels that return a mixed depth (flying pixels)...
TOF_EDGE_INVALID = 0.25  # ...and that the depth engine's mixed-pixel test invalidates
TOF_MP_GAIN = 4.0        # strength of the second bounce (multipath) between facing surfaces: a few
                         # mm to about 1 cm in a concave corner, as measured on Kinect v2 / Azure


def shift(a, dy, dx, fill=0):
    """out[y, x] = a[y + dy, x + dx], `fill` outside."""
    out = np.full_like(a, fill)
    H, W = a.shape[:2]
    ys, yd = (slice(dy, H), slice(0, H - dy)) if dy >= 0 else (slice(0, H + dy), slice(-dy, H))
    xs, xd = (slice(dx, W), slice(0, W - dx)) if dx >= 0 else (slice(0, W + dx), slice(-dx, W))
    out[yd, xd] = a[ys, xs]
    return out


def box_blur(a, r):
    """Mean over a (2r+1)^2 window (edges padded)."""
    p = np.pad(a, r, mode="edge")
    c = np.cumsum(np.cumsum(p, axis=0), axis=1)
    c = np.pad(c, ((1, 0), (1, 0)))
    k = 2 * r + 1
    return (c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]) / (k * k)


def depth_structured_light(rng, parts, pos, Rc, P, z, hit, d_norm, f, s, width, height):
    """Kinect v1 (the generator's model since version 1; unchanged)."""
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
    zt = z.reshape(height, width)
    fb = f * BASELINE
    info = {"clean": valid.copy(), "sigma_px": DISPARITY_SIGMA * s, "fb": fb,
            "bound": zt * zt / fb * (5 * DISPARITY_SIGMA * s + 1 / SUBPIXEL) + 0.001}
    return zq, valid, info


def depth_active_stereo(rng, parts, pos, Rc, P, z, hit, s, width, height):
    """RealSense D4xx-like: disparity noise (error ~ z^2), no depth where the right imager does
    not see the point (the invalid band left of near objects, as wide as the disparity step
    between them and what is behind), edges fattened into the background, speckle holes."""
    valid = hit & (z > AS_ZMIN) & (z < AS_ZMAX)
    right = pos + Rc[0] * AS_BASELINE
    to_r = P - right
    dist_r = np.linalg.norm(to_r, axis=1)
    band = np.zeros(len(z), bool)
    cand = np.nonzero(valid)[0]
    band[cand] = occluded(parts, right, to_r[cand] / dist_r[cand, None], dist_r[cand])
    valid &= ~band
    fb = AS_FOCAL_DEPTH * s * AS_BASELINE
    sigma = AS_SUBPIXEL_RMS * s
    disp = np.where(valid, fb / np.where(z > 0, z, 1), 0) + rng.normal(0, sigma, len(z))
    zq = np.where(valid & (disp > 0), fb / np.where(disp > 0, disp, 1), 0).reshape(height, width)
    valid = valid.reshape(height, width) & (zq > 0)
    # Fattening: a background pixel within 1-3 px of a nearer surface takes its depth.
    R = max(1, int(round(AS_FATTEN * s)))
    reach = rng.integers(1, R + 1, (height, width))
    step = 0.02 + 3 * zq * zq / fb * sigma
    near = np.where(valid, zq, np.inf)
    zf = zq.copy()
    fat = np.zeros_like(valid)
    for dy in range(-R, R + 1):
        for dx in range(-R, R + 1):
            if (dy or dx) and max(abs(dy), abs(dx)) <= R:
                nb = shift(near, dy, dx, np.inf)
                take = valid & (max(abs(dy), abs(dx)) <= reach) & (nb < zf - step)
                zf = np.where(take, nb, zf)
                fat |= take
    # Speckle holes: blobs of a few pixels where matching fails.
    blur = box_blur(rng.random((height, width)), max(1, int(round(2 * s))))
    holes = blur > np.quantile(blur, 1 - AS_HOLES)
    valid &= ~holes
    zt = z.reshape(height, width)
    info = {"clean": valid & ~fat, "fattened": fat & valid, "band": band.reshape(height, width),
            "sigma_px": sigma, "fb": fb, "bound": zt * zt / fb * 5 * sigma + 0.001}
    return np.where(valid, zf, 0), valid, info


def multipath(P, nrm, albedo, pos, ok, height, width, s):
    """Extra range (m, >= 0) from light that bounced off a facing surface nearby before
    reaching the point: the ToF phase of the mix lies behind the direct one. Sampled on rings
    of 4, 10 and 20 px (at 640) around each pixel; only surfaces that face each other count
    (concave corners: an object's foot on the table, boxes side by side, floor and wall)."""
    P3, N3 = P.reshape(height, width, 3), nrm.reshape(height, width, 3)
    A, ok2 = albedo.reshape(height, width), ok.reshape(height, width)
    CP = np.linalg.norm(P3 - pos, axis=2)
    bias = np.zeros((height, width))
    wsum = np.zeros((height, width))
    samples = [(r, a) for r in (4, 10, 20) for a in np.arange(8) * np.pi / 4]
    for r, a in samples:
        rr = max(1.0, r * s)
        dy, dx = int(round(rr * np.sin(a))), int(round(rr * np.cos(a)))
        Q, NQ = shift(P3, dy, dx), shift(N3, dy, dx)
        AQ, okq = shift(A, dy, dx), shift(ok2, dy, dx, False)
        d = Q - P3
        dist = np.linalg.norm(d, axis=2) + 1e-9
        cp = (d * N3).sum(axis=2) / dist
        cq = -(d * NQ).sum(axis=2) / dist
        m = ok2 & okq & (cp > 0.1) & (cq > 0.1)
        w = np.where(m, TOF_MP_GAIN * AQ * cp * cq / len(samples), 0)
        excess = np.linalg.norm(Q - pos, axis=2) + dist - CP
        bias += w * np.maximum(excess, 0) / 2
        wsum += w
    return (bias / (1 + wsum)).reshape(-1)


def depth_tof(rng, P, z, hit, nrm, d_norm, lum, pos, width, height, s):
    """Kinect v2 / Azure Kinect-like: noise growing as the returned signal falls, dropouts
    where it is too weak (dark surfaces, grazing, far), multipath pushing depth back in
    concave corners, flying pixels (mixed depths) along depth edges."""
    valid = hit & (z > TOF_ZMIN) & (z < TOF_ZMAX)
    rng_m = np.linalg.norm(P - pos, axis=1)
    facing = np.clip(-(nrm * d_norm).sum(axis=1), 0, 1)
    albedo = lum / 255.0    # the colour's brightness stands for the near-infrared albedo
    amp = albedo * np.maximum(facing, 0.05) / np.maximum(rng_m, 0.1) ** 2
    lo, hi = TOF_AMP_DROP
    dropped = rng.random(len(z)) < np.clip((hi - amp) / (hi - lo), 0, 1)
    sigma = np.clip(TOF_SIGMA_REF * np.sqrt(TOF_AMP_REF / np.maximum(amp, 1e-6)), TOF_SIGMA_MIN, TOF_SIGMA_MAX)
    mp = np.where(valid, multipath(P, nrm, albedo, pos, valid, height, width, s), 0)
    zt = np.where(valid, z * (1 + mp / np.maximum(rng_m, 1e-6)) + rng.normal(0, 1, len(z)) * sigma, 0)
    zt = zt.reshape(height, width)
    valid = valid.reshape(height, width)
    # Flying pixels: a pixel with a neighbour across a depth jump mixes the two depths (or is
    # invalidated); the neighbour with the largest jump is the other side.
    best = np.zeros_like(zt)
    other = np.zeros_like(zt)
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        nb = shift(zt, dy, dx)
        nv = shift(valid, dy, dx, False)
        j = np.where(valid & nv, np.abs(nb - zt), 0)
        better = j > best
        best = np.where(better, j, best)
        other = np.where(better, nb, other)
    edge = best > TOF_EDGE
    r = rng.random(zt.shape)
    fly = edge & (r < TOF_FLY)
    inval = edge & (r >= TOF_FLY) & (r < TOF_FLY + TOF_EDGE_INVALID)
    w = rng.random(zt.shape)
    zout = np.where(fly, w * zt + (1 - w) * other, zt)
    valid = valid & ~inval & ~dropped.reshape(height, width)
    z2 = z.reshape(height, width)
    s2 = sigma.reshape(height, width)
    mp2 = mp.reshape(height, width)
    info = {"clean": valid & ~fly, "flying": fly & valid, "multipath": mp2,
            "amplitude": amp.reshape(height, width), "dropped": dropped.reshape(height, width),
            "sigma_m": s2, "bound": 5 * s2 + 0.0011 + mp2 * z2 / np.maximum(rng_m.reshape(height, width), 1e-6),
            "near": np.minimum(zt, np.where(fly, other, zt)), "far": np.maximum(zt, np.where(fly, other, zt))}
    return np.where(valid, zout, 0), valid, info
