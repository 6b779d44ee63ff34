#!/usr/bin/env python3
"""Draws `wul3d run` objects over their colour frames: each object tinted in its own colour
and outlined in white, at half size (the pictures under docs/objects/).

Usage: scripts/overlay-objects.py RUN_OUT FRAMES DEST [PREFIX]

RUN_OUT is a `wul3d run --out` folder (RUN_OUT/<frame>/objects.png), FRAMES the input folder
(FRAMES/<frame>/color.png), DEST the folder the pictures go to, as DEST/<PREFIX><frame>.png.
Needs numpy and Pillow (Debian's python3-numpy and python3-pil, which python3-matplotlib
brings in).
"""
import pathlib
import sys

try:
    import numpy as np
    from PIL import Image
except ImportError:
    sys.exit("overlay-objects.py: numpy and Pillow are missing (apt-get install python3-matplotlib)")


def palette(ids):
    """A fixed, well-spread colour per object id (golden-ratio hues)."""
    hue = (ids.astype(np.float64) * 0.618033988749895) % 1.0
    h6 = hue * 6.0
    c = np.stack([np.abs(h6 - 3.0) - 1.0, 2.0 - np.abs(h6 - 2.0), 2.0 - np.abs(h6 - 4.0)], axis=-1)
    return (np.clip(c, 0.0, 1.0) * 200.0 + 55.0).astype(np.uint8)


def overlay(colour, objects):
    out = colour.astype(np.float64)
    mask = objects > 0
    tint = palette(objects)
    out[mask] = 0.45 * out[mask] + 0.55 * tint[mask]
    # Outline: an object pixel with a 4-neighbour of another label.
    edge = np.zeros_like(mask)
    edge[1:, :] |= objects[1:, :] != objects[:-1, :]
    edge[:-1, :] |= objects[:-1, :] != objects[1:, :]
    edge[:, 1:] |= objects[:, 1:] != objects[:, :-1]
    edge[:, :-1] |= objects[:, :-1] != objects[:, 1:]
    out[edge & mask] = 255.0
    image = Image.fromarray(out.astype(np.uint8))
    return image.resize((colour.shape[1] // 2, colour.shape[0] // 2), Image.BILINEAR)


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__.strip().splitlines()[3])
    run_out, frames, dest = (pathlib.Path(a) for a in sys.argv[1:4])
    prefix = sys.argv[4] if len(sys.argv) == 5 else ""
    dest.mkdir(parents=True, exist_ok=True)
    done = 0
    for folder in sorted(p for p in run_out.iterdir() if (p / "objects.png").is_file()):
        colour_path = frames / folder.name / "color.png"
        if not colour_path.is_file():
            sys.exit(f"overlay-objects.py: {colour_path}: missing")
        colour = np.asarray(Image.open(colour_path).convert("RGB"))
        objects = np.asarray(Image.open(folder / "objects.png")).astype(np.int64)
        if objects.shape != colour.shape[:2]:
            sys.exit(f"overlay-objects.py: {folder.name}: objects.png and color.png differ in size")
        overlay(colour, objects).save(dest / f"{prefix}{folder.name}.png")
        done += 1
    if done == 0:
        sys.exit(f"overlay-objects.py: no <frame>/objects.png under {run_out}")
    print(f"overlay-objects.py: {done} pictures -> {dest}")


if __name__ == "__main__":
    main()
