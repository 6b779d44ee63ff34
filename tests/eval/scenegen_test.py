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
import scene_sensors  # noqa: E402
import scene_shapes  # noqa: E402
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
        bound = z * z / fb * (5 * self.truth["sigma_px"] + 1 / scene_sensors.SUBPIXEL) + 0.001
        err = np.abs(depth[valid] * intr["depth_scale_m_per_unit"] - z[valid])
        self.assertTrue((err <= bound[valid]).all(), f"worst {err.max():.4f} m")
        # Missing depth where the ray hit something: shadows, edges.
        self.assertGreater(((z > 0) & (z < scene_sensors.ZMAX) & ~valid).sum(), 0)

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
            self.assertTrue(isinstance(prim, scene_shapes.Cone) and prim.r0 == prim.r1)
            self.assertTrue(prim.z0 < mat["z0"] < mat["z1"] < prim.z1)
            mid, below = np.array([[0.0, 0.0, (mat["z0"] + mat["z1"]) / 2]]), np.array([[0.0, 0.0, mat["z0"] / 2]])
            np.testing.assert_array_equal(scene_shapes.shade(mat, mid)[0], mat["b"])
            self.assertGreaterEqual(np.linalg.norm(scene_shapes.shade(mat, below)[0] - mat["b"]), 1)

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
                    self.assertEqual(isinstance(prim, scene_shapes.Cone), round_kind, kind_of[lab])

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


class FamiliesAndSensors(unittest.TestCase):
    """Every family under every sensor: a small scene whose labels and depth agree with the
    ray cast, and each sensor's own artefacts where its model puts them."""
    W, H = 160, 120
    SEEDS = {"tabletop": 7, "pile": 10003, "floor": 20003}

    @classmethod
    def setUpClass(cls):
        cls.frames = {}
        for family in scenegen.FAMILIES:
            for sensor in scenegen.SENSORS:
                truth = {}
                frame = scenegen.render(cls.SEEDS[family], cls.W, cls.H, truth, family=family, sensor=sensor)
                cls.frames[family, sensor] = frame, truth

    def test_default_is_tabletop_under_structured_light_and_a_seed_renders_the_same_twice(self):
        a = scenegen.render(7, self.W, self.H)
        b = self.frames["tabletop", "structured_light"][0]
        for x, y in zip(a[:3], b[:3]):
            np.testing.assert_array_equal(x, y)
        for family, sensor in (("pile", "tof"), ("floor", "active_stereo")):
            again = scenegen.render(self.SEEDS[family], self.W, self.H, family=family, sensor=sensor)
            for x, y in zip(self.frames[family, sensor][0][:3], again[:3]):
                np.testing.assert_array_equal(x, y)

    def test_labels_are_whole_visible_objects_on_the_support(self):
        scale = (640 / self.W) ** 2
        for (family, sensor), ((_, depth, label, _), truth) in self.frames.items():
            with self.subTest(family=family, sensor=sensor):
                raw = truth["raw_labels"]
                n = int(label.max())
                self.assertGreaterEqual(n, 2 if family != "tabletop" else 1)
                self.assertLessEqual(n, 20)
                np.testing.assert_array_equal(np.unique(label), np.arange(n + 1))
                for lab in range(1, n + 1):
                    m = label == lab
                    parts = np.unique(raw[m])
                    self.assertEqual(len(parts), 1)
                    self.assertGreater(parts[0], 0)
                    np.testing.assert_array_equal(m, raw == parts[0])
                    self.assertGreaterEqual((m & (depth > 0)).sum() * scale, scenegen.MIN_VISIBLE)
                for part in np.setdiff1d(np.unique(raw), [0]):
                    if not (label[raw == part] > 0).any():
                        self.assertLess(((raw == part) & (depth > 0)).sum() * scale, scenegen.MIN_VISIBLE)
                # Objects rest on the support (the table top or the floor, z = 0) or above it.
                self.assertGreaterEqual(truth["world"][..., 2][label > 0].min(), -1e-6)
                self.assertEqual(sorted(truth["kinds"]), list(range(1, n + 1)))

    def test_depth_is_the_ray_cast_within_each_sensors_noise(self):
        for (family, sensor), ((_, depth, label, intr), truth) in self.frames.items():
            with self.subTest(family=family, sensor=sensor):
                z = truth["z"]
                valid = depth > 0
                clean = truth["clean"]
                self.assertTrue((valid[clean]).all())
                self.assertGreater(valid.mean(), 0.5)
                self.assertGreater(clean.sum(), 0.75 * valid.sum())
                err = np.abs(depth * intr["depth_scale_m_per_unit"] - z)
                self.assertTrue((err[clean] <= truth["bound"][clean]).all(),
                                f"worst {(err - truth['bound'])[clean].max():.4f} m over the bound")
                # The objects' pixels are mostly clean: the labels hold where the depth does.
                self.assertGreater((clean & (label > 0)).sum(), 0.6 * ((label > 0) & valid).sum())
                # Missing depth where the ray hit something (shadows, bands, edges, dropouts).
                self.assertGreater(((z > 0) & ~valid).sum(), 0)
                self.assertEqual(intr["fx"], scenegen.SENSORS[sensor]["focal"] * self.W / 640)

    def test_active_stereo_fattens_edges_and_leaves_a_band_left_of_near_objects(self):
        for family in scenegen.FAMILIES:
            (_, depth, _, _), truth = self.frames[family, "active_stereo"]
            with self.subTest(family=family):
                z, d = truth["z"], depth / 1000.0
                fat = truth["fattened"]
                self.assertGreater(fat.sum(), 0)
                # A fattened pixel took a nearer surface's depth, from within 3 px (at 640).
                self.assertTrue((d[fat] < z[fat] - 0.01).all())
                near = np.full(z.shape, np.inf)
                for dy in (-1, 0, 1):
                    for dx in (-1, 0, 1):
                        near = np.minimum(near, scene_sensors.shift(np.where(depth > 0, d, np.inf), dy, dx, np.inf))
                # The band: no depth, and a nearer surface a little to its right.
                band = truth["band"] & (z > 0)
                self.assertGreater(band.sum(), 0)
                self.assertFalse((depth[band] > 0).any())
                reach = int(np.ceil(self.W / 640 * scenegen.SENSORS["active_stereo"]["focal"] *
                                    scene_sensors.AS_BASELINE / scene_sensors.AS_ZMIN)) + 2
                right = np.full(z.shape, np.inf)
                for dx in range(1, reach + 1):
                    right = np.minimum(right, scene_sensors.shift(np.where(z > 0, z, np.inf), 0, dx, np.inf))
                self.assertTrue((right[band] < z[band] - 0.005).mean() > 0.95)

    def test_tof_flying_pixels_multipath_and_dark_dropouts(self):
        for family in scenegen.FAMILIES:
            (_, depth, _, _), truth = self.frames[family, "tof"]
            with self.subTest(family=family):
                d = depth / 1000.0
                fly = truth["flying"]
                self.assertGreater(fly.sum(), 0)
                tol = 0.0011
                self.assertTrue((d[fly] >= truth["near"][fly] - tol).all())
                self.assertTrue((d[fly] <= truth["far"][fly] + tol).all())
                mp = truth["multipath"]
                self.assertGreaterEqual(mp.min(), 0.0)
                self.assertGreater(mp.max(), 0.002)   # a corner somewhere pushes depth back
                amp, dropped = truth["amplitude"], truth["dropped"]
                lo, hi = scene_sensors.TOF_AMP_DROP
                self.assertTrue(dropped[amp <= lo].all())
                self.assertFalse(dropped[amp >= hi].any())
                self.assertFalse((depth[dropped] > 0).any())

    def test_the_families_hold_what_they_say(self):
        counts = {"pile": [], "floor": []}
        for family in counts:
            for seed in range(30):
                kind_of = {}
                rng = np.random.default_rng(seed)
                if family == "pile":
                    parts, pos, Rc = scenegen.build_pile(rng, np.random.default_rng([seed, 1]), kind_of)
                    # Looking down at 40-90 degrees (roll aside) from 0.8-1.5 m (a target 3 cm up).
                    self.assertGreaterEqual(-Rc[2][2], np.sin(np.radians(40)) - 0.01)
                    self.assertTrue(0.8 * np.sin(np.radians(40)) < pos[2] <= 1.5 + 0.03 + 1e-9, pos)
                    self.assertTrue(5 <= len(kind_of) <= 20, len(kind_of))
                else:
                    parts, pos, Rc = scenegen.build_floor(rng, np.random.default_rng([seed, 1]), kind_of)
                    self.assertTrue(1 <= len(kind_of) <= 20, len(kind_of))
                counts[family].append(kind_of)
                labels = sorted({lab for _, lab, _ in parts if lab > 0})
                self.assertEqual(labels, list(range(1, len(kind_of) + 1)))
        kinds = {k for ks in counts["pile"] for k in ks.values()}
        self.assertLessEqual({"box", "can", "bottle", "sphere", "stack", "lean"}, kinds)

    def test_incremental_puts_the_objects_down_one_at_a_time(self):
        seed, family = 10003, "pile"
        n = max(label for _, label, _ in scenegen.scene(seed, family)[0])
        whole = {}
        scenegen.render(seed, self.W, self.H, whole, family=family)
        before = None
        for step in range(1, n + 1):
            truth = {}
            scenegen.render(seed, self.W, self.H, truth, family=family, upto=step)
            raw = truth["raw_labels"]
            self.assertLessEqual(raw.max(), step)
            if before is not None:
                # Putting object `step` down changes only the pixels where it is now seen.
                np.testing.assert_array_equal(raw[raw != step], before[raw != step])
            before = raw
        np.testing.assert_array_equal(truth["z"], whole["z"])  # the last step is the whole scene
        np.testing.assert_array_equal(before, whole["raw_labels"])
        with tempfile.TemporaryDirectory() as tmp:
            scenegen.main(["--out", tmp, "--seeds", str(seed), "--width", "64", "--height", "48",
                           "--family", family, "--incremental"])
            seq = pathlib.Path(tmp) / f"seq_{seed:05d}"
            self.assertEqual(sorted(p.name for p in seq.iterdir()), [f"step_{i:02d}" for i in range(1, n + 1)])
            self.assertTrue(json.loads((pathlib.Path(tmp) / "scenegen.json").read_text())["incremental"])
            _, depth, _, _ = scenegen.render(seed, 64, 48, family=family, upto=2)
            np.testing.assert_array_equal(np.array(Image.open(seq / "step_02" / "depth.png")), depth)

    def test_family_and_sensor_are_written_and_unknown_ones_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            scenegen.main(["--out", tmp, "--seeds", "11000", "--width", "64", "--height", "48",
                           "--family", "pile", "--sensor", "tof"])
            stamp = json.loads((pathlib.Path(tmp) / "scenegen.json").read_text())
            self.assertEqual((stamp["family"], stamp["sensor"]), ("pile", "tof"))
            _, depth, label, _ = scenegen.render(11000, 64, 48, family="pile", sensor="tof")
            np.testing.assert_array_equal(np.array(Image.open(pathlib.Path(tmp) / "scene_11000" / "depth.png")), depth)
        with self.assertRaises(ValueError):
            scenegen.render(1, 64, 48, family="garden")
        with self.assertRaises(ValueError):
            scenegen.render(1, 64, 48, sensor="lidar")


if __name__ == "__main__":
    unittest.main()
