#!/usr/bin/env python3
"""Segments every frame of a recording and saves an overlay per frame: the colour image with
each object tinted in its own colour and boxed.

    python3 examples/python/segment_folder.py data/samples/uois_tabletop out/overlays

Writes OUT/<frame>.png (8-bit RGB PNG through matplotlib) and prints the objects found.
"""
import argparse
import pathlib
import sys

import matplotlib
import numpy as np

import wul3d

matplotlib.use("Agg")  # no display needed
import matplotlib.image  # noqa: E402  (after the backend is chosen)


def overlay(color, result):
    """The colour image (grey where there is none) with objects tinted and boxed."""
    if color is None:
        color = np.repeat((result.labels > 0).astype(np.uint8)[:, :, None] * 128, 3, axis=2)
    out = color.astype(np.float32)
    rng = np.random.default_rng(7)
    palette = rng.integers(64, 256, size=(65536, 3)).astype(np.float32)
    objects = result.objects
    tinted = objects > 0
    out[tinted] = 0.5 * out[tinted] + 0.5 * palette[objects[tinted]]
    for inst in result.instances:
        u0, v0, u1, v1 = inst.box_px
        out[v0:v1 + 1, [u0, u1]] = palette[inst.id]
        out[[v0, v1], u0:u1 + 1] = palette[inst.id]
    return out.astype(np.uint8)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", help="a frame folder, a folder of them, or a TUM sequence")
    parser.add_argument("out", help="folder for the overlays")
    args = parser.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    pipeline = wul3d.Pipeline()  # default parameters, as `wul3d run`
    for frame in wul3d.read(args.input):
        result = pipeline.process(frame.color, frame.depth, frame.intrinsics,
                                  depth_scale=frame.depth_scale)
        matplotlib.image.imsave(out / f"{frame.name}.png", overlay(frame.color, result))
        objects = ", ".join(f"#{i.id} {i.pixels} px at z {i.centroid[2]:.2f} m"
                            for i in result.instances)
        print(f"{frame.name}: {len(result.instances)} objects ({objects})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
