#!/usr/bin/env python3
"""The README's Python snippet, as a file the tests run: the objects of every shipped
tabletop frame.  python3 examples/python/quickstart.py [INPUT]"""
import sys

import wul3d

path = sys.argv[1] if len(sys.argv) > 1 else "data/samples/uois_tabletop"
pipeline = wul3d.Pipeline(k=7, decimate=2)            # the flags of `wul3d run`
for frame in wul3d.read(path):                        # any input `wul3d run` reads
    result = pipeline.process(frame.color, frame.depth, frame.intrinsics,
                              depth_scale=frame.depth_scale)
    for obj in result.instances:                      # numpy arrays in, numpy arrays out
        x, y, z = obj.centroid
        print(f"{frame.name} object {obj.id}: {obj.pixels} px at ({x:.2f}, {y:.2f}, {z:.2f}) m")
