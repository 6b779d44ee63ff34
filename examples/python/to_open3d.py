#!/usr/bin/env python3
"""Hands a wul3d result to Open3D: the frame's points as an open3d.geometry.PointCloud
coloured by object (background grey), plus one oriented box per object.

    python3 examples/python/to_open3d.py data/samples/uois_tabletop/image_0000 out/objects.ply

Needs Debian's python3-open3d. Writes the cloud as PLY; --show opens Open3D's viewer.
"""
import argparse
import sys

import numpy as np
import open3d as o3d

import wul3d


def object_cloud(frame, result):
    """Back-projects every pixel with depth; colours each point by its object."""
    K = frame.intrinsics
    h, w = frame.depth.shape
    z = frame.depth.astype(np.float64) * frame.depth_scale
    u, v = np.meshgrid(np.arange(w), np.arange(h))
    valid = z > 0
    xyz = np.stack([(u - K.cx) * z / K.fx, (v - K.cy) * z / K.fy, z], axis=-1)[valid]
    palette = np.random.default_rng(7).uniform(0.2, 1.0, size=(65536, 3))
    palette[0] = 0.5  # background
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))
    cloud.colors = o3d.utility.Vector3dVector(palette[result.objects[valid]])
    return cloud


def object_boxes(result):
    """One open3d OrientedBoundingBox per object (wul3d's obb: centre, axes as rows)."""
    boxes = []
    for inst in result.instances:
        obb = inst.obb
        box = o3d.geometry.OrientedBoundingBox(obb["centre"].astype(np.float64),
                                               obb["axes"].T.astype(np.float64),
                                               2.0 * obb["half_extent"].astype(np.float64))
        boxes.append(box)
    return boxes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frame", help="a frame folder (color.png, depth.png, intrinsics.json)")
    parser.add_argument("out", help="PLY file to write")
    parser.add_argument("--show", action="store_true", help="open Open3D's viewer")
    args = parser.parse_args(argv)
    frame = wul3d.read(args.frame)[0]
    result = wul3d.Pipeline().process(frame.color, frame.depth, frame.intrinsics,
                                      depth_scale=frame.depth_scale)
    cloud = object_cloud(frame, result)
    boxes = object_boxes(result)
    if not o3d.io.write_point_cloud(args.out, cloud):
        print(f"{args.out}: cannot write", file=sys.stderr)
        return 1
    for inst, box in zip(result.instances, boxes):
        print(f"object {inst.id}: {inst.pixels} px, box volume {box.volume() * 1e6:.0f} cm^3")
    print(f"{len(cloud.points)} points -> {args.out}")
    if args.show:
        o3d.visualization.draw_geometries([cloud, *boxes])
    return 0


if __name__ == "__main__":
    sys.exit(main())
