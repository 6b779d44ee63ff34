#!/usr/bin/env python3
"""eval/scenegen.py: small scenes whose labels and depth are checked against the ray cast;
eval/kinds.py on one of them.

Run by ctest (tests/CMakeLists.txt); needs Debian's python3-numpy and python3-pil."""
import contextlib
import io
import json
import pathlib
import sys
import tempfile
import unittest

import numpy as np
from PIL import Image

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "eval"))
import scenegen  # noqa: E402
import kinds as kinds_module  # noqa: E402

W, H = 320, 240


class Scenegen(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = {}
        cls.frame = scenegen.render(7, W, H, cls.truth)

    def test_same_seed_same_frame_other_seed_other_frame(self):
        again = scenegen.render(7, W, H)
        for a, b in zip(self.frame[:3], again[:3]):
            np.testing.assert_array_equal(a, b)
        other = scenegen.render(8, W, H)
        self.assertFalse(np.array_equal(self.frame[1], other[1]))

    def test_labels_are_the_visible_objects_numbered_from_one(self):
        _, depth, label, _ = self.frame
        raw = self.truth["raw_labels"]
        ids = np.unique(label)
        self.assertEqual(ids[0], 0)
        n = len(ids) - 1
        self.assertGreaterEqual(n, 1)
        self.assertLessEqual(n, 20)
        np.testing.assert_array_equal(ids, np.arange(n + 1))
        # Each label is exactly one object part of the scene, whole, and has enough depth.
        for lab in range(1, n + 1):
            m = label == lab
            parts = np.unique(raw[m])
            self.assertEqual(len(parts), 1, f"label {lab} covers parts {parts}")
            self.assertGreater(parts[0], 0)
            np.testing.assert_array_equal(m, raw == parts[0])
            self.assertGreaterEqual((m & (depth > 0)).sum() * (640 / W) ** 2, scenegen.MIN_VISIBLE)
        # Everything else with a label in the scene is hidden below the visibility rule.
        for part in np.setdiff1d(np.unique(raw), [0]):
            if not (label[raw == part] > 0).any():
                self.assertLess(((raw == part) & (depth > 0)).sum() * (640 / W) ** 2, scenegen.MIN_VISIBLE)

    def test_objects_stand_on_or_above_the_table_top(self):
        label = self.frame[2]
        world_z = self.truth["world"][..., 2]
        self.assertGreaterEqual(world_z[label > 0].min(), -1e-6)
        # The room is there too: points below the table top (floor, legs) without a label.
        self.assertTrue(((world_z < -0.3) & (label == 0) & (self.truth["z"] > 0)).any())

    def test_depth_is_the_ray_cast_within_the_sensor_model(self):
        _, depth, _, intr = self.frame
        z = self.truth["z"]
        valid = depth > 0
        self.assertGreater(valid.mean(), 0.5)
        fb = self.truth["fb"]
        # Disparity noise (5 sigma) and its 1/8-pixel step, as depth: both grow with z^2.
        bound = z * z / fb * (5 * self.truth["sigma_px"] + 1 / scenegen.SUBPIXEL) + 0.001
        err = np.abs(depth[valid] * intr["depth_scale_m_per_unit"] - z[valid])
        self.assertTrue((err <= bound[valid]).all(), f"worst {err.max():.4f} m")
        # Missing depth where the ray hit something: shadows, edges.
        self.assertGreater(((z > 0) & (z < scenegen.ZMAX) & ~valid).sum(), 0)

    def test_written_as_a_frame_folder(self):
        with tempfile.TemporaryDirectory() as tmp:
            scenegen.main(["--out", tmp, "--seeds", "3", "--width", str(W), "--height", str(H)])
            f = pathlib.Path(tmp) / "scene_00003"
            for name in ("color.png", "depth.png", "label.png", "intrinsics.json"):
                self.assertTrue((f / name).is_file(), name)
            with Image.open(f / "depth.png") as im:  # 16-bit grey (Pillow reads it as I)
                self.assertIn(im.mode, ("I;16", "I;16B", "I"))
            color, depth, label, _ = scenegen.render(3, W, H)
            np.testing.assert_array_equal(np.array(Image.open(f / "depth.png")), depth)
            np.testing.assert_array_equal(np.array(Image.open(f / "label.png")), label)
            np.testing.assert_array_equal(np.array(Image.open(f / "color.png")), color)
            stamp = json.loads((pathlib.Path(tmp) / "scenegen.json").read_text())
            self.assertEqual(stamp["version"], scenegen.VERSION)

    def test_cylinders_wear_labels_of_another_colour(self):
        labelled = []
        for seed in range(30):
            parts, _ = scenegen.build_scene(np.random.default_rng(seed), np.random.default_rng([seed, 1]))
            labelled += [(prim, mat) for prim, lab, mat in parts if lab > 0 and mat["kind"] == "label"]
        self.assertGreater(len(labelled), 5)
        for prim, mat in labelled:
            self.assertTrue(isinstance(prim, scenegen.Cone) and prim.r0 == prim.r1)
            self.assertTrue(prim.z0 < mat["z0"] < mat["z1"] < prim.z1)
            mid, below = np.array([[0.0, 0.0, (mat["z0"] + mat["z1"]) / 2]]), np.array([[0.0, 0.0, mat["z0"] / 2]])
            np.testing.assert_array_equal(scenegen.shade(mat, mid)[0], mat["b"])
            self.assertGreaterEqual(np.linalg.norm(scenegen.shade(mat, below)[0] - mat["b"]), 1)

    def test_each_object_has_the_kind_it_was_drawn_as(self):
        label = self.frame[2]
        kinds = self.truth["kinds"]
        self.assertEqual(sorted(kinds), list(range(1, int(label.max()) + 1)))
        self.assertLessEqual(set(kinds.values()), set(kinds_module.KINDS))
        # Over many scenes, the round kinds are cones and the others boxes.
        for seed in range(10):
            kind_of = {}
            parts, _ = scenegen.build_scene(np.random.default_rng(seed), np.random.default_rng([seed, 1]), kind_of)
            for prim, lab, _ in parts:
                if lab > 0:
                    round_kind = kind_of[lab] in ("cylinder", "cup", "bowl")
                    self.assertEqual(isinstance(prim, scenegen.Cone), round_kind, kind_of[lab])

    def test_kinds_scores_a_perfect_run_good_and_an_empty_one_missed_and_compares_them(self):
        with tempfile.TemporaryDirectory() as tmp:
            gen, perfect, empty = (pathlib.Path(tmp) / d for d in ("gen", "perfect", "empty"))
            scenegen.main(["--out", str(gen), "--seeds", "7", "--width", str(W), "--height", str(H)])
            label = np.array(Image.open(gen / "scene_00007" / "label.png"))
            for out, image in ((perfect, label), (empty, np.zeros_like(label))):
                (out / "scene_00007").mkdir(parents=True)
                Image.fromarray(image).save(out / "scene_00007" / "objects.png")
            n = int(label.max())
            for out, fate in ((perfect, "good"), (empty, "missed")):
                lines = io.StringIO()
                with contextlib.redirect_stdout(lines):
                    kinds_module.main([str(gen), str(out)])
                rows = [r.split() for r in lines.getvalue().splitlines()]
                header, body, total = rows[0], rows[1:-1], rows[-1]
                column = header.index(fate)
                self.assertEqual(sum(int(r[column]) for r in body), n)
                self.assertEqual(total[1], str(n))
                self.assertEqual(float(total[2]), 1.0 if fate == "good" else 0.0)
            with self.assertRaises(SystemExit) as e:
                kinds_module.main([str(gen), str(pathlib.Path(tmp) / "none")])
            self.assertIn("missing", str(e.exception.code))
            # --against: every object changes by 1 IoU between the empty and the perfect run.
            for out, against, gains in ((perfect, empty, n), (empty, perfect, 0)):
                lines = io.StringIO()
                with contextlib.redirect_stdout(lines):
                    kinds_module.main([str(gen), str(out), "--against", str(against)])
                text = lines.getvalue().splitlines()
                start = next(i for i, t in enumerate(text) if t.startswith("against "))
                listed = text[start + 1:-1]
                self.assertEqual(len(listed), n)
                for row in listed:
                    self.assertTrue(row.startswith("scene_00007 "), row)
                    self.assertTrue(row.endswith("0.00 missed -> 1.00 good" if gains else
                                                 "1.00 good -> 0.00 missed"), row)
                self.assertEqual(text[-1], f"{gains} gain, {n - gains} lose")
            # The same run against itself changes nothing.
            lines = io.StringIO()
            with contextlib.redirect_stdout(lines):
                kinds_module.main([str(gen), str(perfect), "--against", str(perfect)])
            self.assertEqual(lines.getvalue().splitlines()[-1], "0 gain, 0 lose")
            with self.assertRaises(SystemExit) as e:
                kinds_module.main([str(gen), str(perfect), "--against", str(pathlib.Path(tmp) / "none")])
            self.assertIn("missing", str(e.exception.code))

    def test_bad_seed_range_is_one_line(self):
        with self.assertRaises(SystemExit) as e:
            scenegen.main(["--out", "/nonexistent", "--seeds", "5-2"])
        self.assertIn("empty", str(e.exception.code))


if __name__ == "__main__":
    unittest.main()
