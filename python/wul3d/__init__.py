"""wul3d: objects in RGB-D frames on a CPU, from Python.

Weighted unsupervised learning for 3D object detection (Kowsari & Alassaf) with object
segmentation and tracking. The C++ library does the work; this module hands it numpy arrays
and returns numpy arrays (docs/PYTHON.md).

    >>> import wul3d
    >>> pipeline = wul3d.Pipeline(k=7, decimate=2)
    >>> for frame in wul3d.read("data/samples/uois_tabletop"):
    ...     result = pipeline.process(frame.color, frame.depth, frame.intrinsics,
    ...                               depth_scale=frame.depth_scale)
    ...     print(frame.name, [(o.id, o.pixels) for o in result.instances])

Contents:
    Pipeline      the per-frame pipeline; process() returns a Result
    Intrinsics    pinhole intrinsics (fx, fy, cx, cy)
    Result        labels, objects, colors arrays; instances; plane; times
    Instance      one object: id, track_id, pixels, centroid, aabb, obb, box_px, mean_rgb, mask()
    read          the frames of any input `wul3d run` reads
    run           `wul3d run` as a call: a whole recording into an output folder
    evaluate      UOIS metrics of a prediction against ground truth
    wul3d.batch   many sequences on Dask (python3 -m wul3d.batch)
"""

import operator
import os
from collections.abc import Iterator, Sequence

import numpy as np

from ._wul3d import (  # noqa: F401  (re-exported)
    Frame,
    InputError,
    Instance,
    Intrinsics,
    IoError,
    Pipeline,
    Result,
    get_max_pixels,
    get_num_threads,
    parameters,
    read_color_image,
    read_label_image,
    set_max_pixels,
    set_num_threads,
)
from . import _wul3d
from ._wul3d import __version__  # noqa: F401  (CMake's project(VERSION))

__all__ = [
    "Frame", "InputError", "Instance", "Intrinsics", "IoError", "Pipeline", "Result",
    "Reader", "evaluate", "get_max_pixels", "get_num_threads", "parameters", "read", "read_color_image",
    "read_label_image", "run", "set_max_pixels", "set_num_threads",
]


class Reader(Sequence):
    """The frames of a recording, in order; a sequence of wul3d.Frame (len, index, iterate).

    Made by wul3d.read. Frames are read from disk when indexed; each holds its own arrays.
    """

    def __init__(self, path, format="auto", tum_camera="", intrinsics=None, calibration="",
                 registration="depth-to-color"):
        self._reader = _wul3d._Reader(path, format, tum_camera, intrinsics, calibration,
                                      registration)
        self.path = os.fsdecode(path)

    @property
    def format(self) -> str:
        """The format read: "frames", "tum" or "unregistered"."""
        return self._reader.format

    def __len__(self) -> int:
        return len(self._reader)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self._reader[i] for i in range(*index.indices(len(self)))]
        i = operator.index(index)  # TypeError for a non-int, as a list
        if not -len(self) <= i < len(self):
            raise IndexError(f"frame index {i} out of range ({len(self)} frames)")
        return self._reader[i]

    def __iter__(self) -> Iterator[Frame]:
        for i in range(len(self)):
            yield self._reader[i]

    def __repr__(self) -> str:
        return f"Reader({self.path!r}, {len(self)} frames, {self.format})"


def read(path, format="auto", tum_camera="", intrinsics=None, calibration="",
         registration="depth-to-color") -> Reader:
    """Opens a recording as `wul3d run` does and returns its frames (a wul3d.Reader).

    Args:
        path: a frame folder (color.png, depth.png, intrinsics.json), a folder of frame
            folders (a sequence, sorted by name), a TUM RGB-D sequence, or unregistered
            frames with a calibration (docs/INPUTS.md).
        format: "auto" (decided from the path), "frames", "tum" or "unregistered".
        tum_camera: TUM intrinsics preset (kinect_v1, tum_fr1, tum_fr2, tum_fr3); "" picks
            it from the folder name.
        intrinsics: wul3d.Intrinsics or dict overriding every frame's intrinsics.
        calibration: unregistered input: a calibration JSON or "kinect_v2".
        registration: "depth-to-color" or "color-to-depth" (unregistered input).

    Frames of unregistered input come back registered. Raises wul3d.InputError (a
    ValueError) for a missing path, an empty sequence or an image past wul3d.set_max_pixels,
    ValueError for a bad option, TypeError for an option of the wrong type. One reader may
    be shared by threads (they take turns).
    """
    return Reader(path, format, tum_camera, intrinsics, calibration, registration)


def evaluate(pred, gt, boundary_fraction=0.003, boundary_tolerance_px=-1, detected_f=0.75,
             depth=None):
    """UOIS metrics of predicted instances against ground truth, as `wul3d eval` computes them.

    Args:
        pred: (H, W) integer label image (0 = background, each other value one object), or a
            list of them (one per frame).
        gt: the ground truth, same shapes as pred.
        boundary_fraction: boundary tolerance as a share of the image diagonal (3 px at
            640x480).
        boundary_tolerance_px: >= 0 overrides boundary_fraction; -1 uses it.
        detected_f: an object counts as detected (%>=75) when its matched overlap F is above
            this.
        depth: None, or the frames' (H, W) depth images (a list with lists): only the pixels
            with depth (non-zero) are scored, both labels 0 elsewhere, as `wul3d eval
            --where-depth` does.

    Returns:
        For one image: a dict with overlap_p/r/f, boundary_p/r/f, detected_share (%>=75),
        gt_objects, pred_objects, detected, boundary_tolerance_px and matches (the
        Hungarian pairs). For a list: the macro average over images (docs/EVAL.md) with
        "images" and the summed counts, and "per_image", the list of the per-image dicts.
    """
    def where_depth(p, g, d):
        if d is None:
            return p, g
        d, p, g = np.asarray(d), np.array(p, copy=True), np.array(g, copy=True)
        if d.shape != g.shape:
            raise ValueError(f"depth is {d.shape}, gt {g.shape}: one depth image per label image")
        p[d == 0] = 0
        g[d == 0] = 0
        return p, g

    def score(p, g, d):
        p, g = where_depth(p, g, d)
        return _wul3d._score_image(p, g, boundary_fraction, boundary_tolerance_px, detected_f)

    if isinstance(pred, (list, tuple)) or isinstance(gt, (list, tuple)):
        if not isinstance(pred, (list, tuple)) or not isinstance(gt, (list, tuple)):
            raise TypeError("pred and gt: both lists of images, or both one image")
        if len(pred) != len(gt):
            raise ValueError(f"pred has {len(pred)} images, gt {len(gt)}")
        if depth is not None and (not isinstance(depth, (list, tuple)) or len(depth) != len(gt)):
            raise ValueError(f"depth: a list of {len(gt)} depth images, one per label image")
        depths = depth if depth is not None else [None] * len(gt)
        scores = [score(p, g, d) for p, g, d in zip(pred, gt, depths)]
        summary = _wul3d._summarize(scores)
        summary["per_image"] = scores
        return summary
    return score(pred, gt, depth)


def run(input, out, **options) -> dict:
    """Runs a whole recording as `wul3d run INPUT --out OUT [options]` does, with the same
    outputs (OUT/<frame>/ and OUT/summary.json, docs/OUTPUTS.md), in this process.

    Args:
        input: any input `wul3d run` reads (frame folders, TUM, unregistered frames).
        out: the output folder (created if missing).
        **options: the flags of `wul3d run`, with underscores: the Pipeline's parameters
            (preset, k, alpha, ..., decimate, no_plane=True), format, tum_camera,
            intrinsics ("fx,fy,cx,cy", wul3d.Intrinsics or dict), calibration,
            registration, select ("u,v" or (u, v)), frames (stop after N), outputs
            ("objects,json" or a sequence of those names, as `wul3d run --outputs`), ply,
            overlay, overwrite (as `wul3d run --overwrite`).

    Returns:
        dict: frames, stopped_by, ms_per_frame_median, fps, wall_s, fps_end_to_end,
        peak_rss_mb (as in summary.json). The GIL is released while it runs.

    Ctrl-C stops the run within a second, even mid-frame: the frames before are complete,
    OUT/summary.json says "stopped_by": "signal", then KeyboardInterrupt is raised. SIGTERM
    (with no handler of the caller's) stops it the same way, then ends the process.

    Raises ValueError (parameters, select out of range), wul3d.InputError (input; OUT equal
    to, inside or holding the input), wul3d.IoError (output), TypeError (an unknown option,
    a value of the wrong type; the message names it).
    """
    if not hasattr(_wul3d, "_run"):
        raise NotImplementedError("wul3d.run: this build's library has no run loop")
    return _wul3d._run(input, out, dict(options))
