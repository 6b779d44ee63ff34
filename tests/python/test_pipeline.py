"""wul3d.Pipeline on the shipped frames: the same outputs as `wul3d run`, pixel for pixel,
and clear exceptions for bad arrays and parameters."""

import numpy as np
import pytest

import wul3d
from conftest import SAMPLES, read_objects_json, run_cli


def process_sequence(path, **params):
    pipeline = wul3d.Pipeline(**params)
    return [(f.name, pipeline.process(f.color, f.depth, f.intrinsics, depth_scale=f.depth_scale))
            for f in wul3d.read(path)]


def assert_same_as_cli(results, out_dir):
    assert [name for name, _ in results] == sorted(p.name for p in out_dir.iterdir() if p.is_dir())
    for name, r in results:
        frame_dir = out_dir / name
        np.testing.assert_array_equal(r.labels, wul3d.read_label_image(str(frame_dir / "labels.png")))
        np.testing.assert_array_equal(r.objects, wul3d.read_label_image(str(frame_dir / "objects.png")))
        np.testing.assert_array_equal(r.colors, wul3d.read_color_image(str(frame_dir / "colors.png")))
        doc = read_objects_json(frame_dir / "objects.json")
        assert len(r.instances) == len(doc["objects"])
        for inst, o in zip(r.instances, doc["objects"]):
            assert (inst.id, inst.track_id, inst.pixels) == (o["id"], o["track_id"], o["pixels"])
            np.testing.assert_array_equal(inst.centroid, np.float32(o["centroid_m"]))
            np.testing.assert_array_equal(inst.aabb, np.float32([o["aabb_m"]["min"], o["aabb_m"]["max"]]))
            np.testing.assert_array_equal(inst.obb["axes"], np.float32(o["obb_m"]["axes"]))
            np.testing.assert_array_equal(inst.obb["half_extent"], np.float32(o["obb_m"]["half_extent"]))
            box = o["box_px"]
            assert inst.box_px == (box["u_min"], box["v_min"], box["u_max"], box["v_max"])
            np.testing.assert_array_equal(inst.mean_rgb, np.float32(o["mean_rgb"]))
            assert inst.source_clusters == o["source_clusters"]
            assert inst.source_segments == o["source_segments"]
            mask = inst.mask()
            assert mask.dtype == np.bool_ and mask.shape == r.objects.shape
            assert int(mask.sum()) == inst.pixels
        if doc["support_plane"] is None:
            assert r.plane is None
        else:
            assert r.plane is not None
            np.testing.assert_array_equal(np.float32(r.plane["normal"]),
                                          np.float32(doc["support_plane"]["normal"]))
            assert np.float32(r.plane["d_m"]) == np.float32(doc["support_plane"]["d_m"])
        assert r.stats["low_support"] == (doc["low_support"] is not None)


def test_tabletop_frames_equal_wul3d_run(tabletop_cli_out):
    results = process_sequence(SAMPLES / "uois_tabletop")
    assert len(results) == 4
    assert any(r.instances for _, r in results), "the tabletop frames hold objects"
    assert_same_as_cli(results, tabletop_cli_out)


def test_depth_only_sequence_equals_wul3d_run_with_options(cli, tmp_path):
    # A depth-only sequence carries clusters and tracks from frame to frame; non-default
    # options go through the same rules as the command's flags (alpha sets delta).
    seq = SAMPLES / "pcl_kinect" / "pairwise_seq"
    proc = run_cli(cli, "run", seq, "--out", tmp_path, "-q", "--k", 5, "--alpha", 0.01,
                   "--decimate", 1, "--segmenter", "geometric")
    assert proc.returncode == 0, proc.stderr
    results = process_sequence(seq, k=5, alpha=0.01, decimate=1, segmenter="geometric")
    assert len(results) == 5
    assert all(f.color is None for f in wul3d.read(seq))
    assert_same_as_cli(results, tmp_path)


def test_result_fields():
    frame = wul3d.read(SAMPLES / "uois_tabletop" / "image_0000")[0]
    pipeline = wul3d.Pipeline()
    r = pipeline.process(frame.color, frame.depth, frame.intrinsics.to_dict(), frame.depth_scale)
    h, w = frame.depth.shape
    assert r.labels.shape == (h, w) and r.labels.dtype == np.uint16
    assert r.objects.shape == (h, w) and r.objects.dtype == np.uint16
    assert r.colors.shape == (h, w, 3) and r.colors.dtype == np.uint8
    assert set(np.unique(r.objects)) == {0} | {i.id for i in r.instances}
    assert r.times["total"] > 0 and set(r.times) >= {"clustering", "segmentation", "objects"}
    assert r.stats["active_points"] > 0
    assert r.stats["segments"] >= len(r.instances) > 0
    assert {"merges", "containers", "occluded_joins", "neck_joins", "gaps_filled", "color_splits", "texture_splits", "stack_splits",
            "piece_splits", "low_support"} <= set(r.stats)
    assert pipeline.params["k"] == 7 and pipeline.params["decimate"] == 2
    # The result owns its arrays: the next frame does not change it.
    before = r.labels.copy()
    pipeline.process(frame.color, np.zeros_like(frame.depth) + 900, frame.intrinsics)
    np.testing.assert_array_equal(before, r.labels)


def test_float_metres_equal_uint16_at_their_scale():
    frame = wul3d.read(SAMPLES / "uois_tabletop" / "image_0002")[0]
    metres = frame.depth.astype(np.float64) * frame.depth_scale
    metres[metres > 6.5] = 0  # float32 metres are stored in 0.1 mm units up to 6.55 m
    assert (metres > 0).sum() > 100000
    units = np.round(metres / 1e-4).astype(np.uint16)
    as_float = (units.astype(np.float64) * 1e-4).astype(np.float32)
    as_float[::7, ::5] = np.nan  # no depth, as 0 below
    units[::7, ::5] = 0
    a = wul3d.Pipeline().process(frame.color, units, frame.intrinsics, depth_scale=1e-4)
    b = wul3d.Pipeline().process(frame.color, as_float, frame.intrinsics)
    np.testing.assert_array_equal(a.labels, b.labels)
    np.testing.assert_array_equal(a.objects, b.objects)


@pytest.fixture(scope="module")
def frame():
    return wul3d.read(SAMPLES / "uois_tabletop" / "image_0005")[0]


def test_bad_dtypes(frame):
    p = wul3d.Pipeline()
    with pytest.raises(TypeError, match=r"depth: dtype float64, expected uint16"):
        p.process(frame.color, frame.depth.astype(np.float64), frame.intrinsics)
    with pytest.raises(TypeError, match=r"color: dtype int32, expected uint8"):
        p.process(frame.color.astype(np.int32), frame.depth, frame.intrinsics)
    with pytest.raises(TypeError, match=r"depth: expected a numpy array, got list"):
        p.process(frame.color, frame.depth.tolist(), frame.intrinsics)
    with pytest.raises(TypeError, match=r"intrinsics: expected wul3d.Intrinsics or a dict"):
        p.process(frame.color, frame.depth, (525, 525, 320, 240))


def test_bad_shapes(frame):
    p = wul3d.Pipeline()
    with pytest.raises(ValueError, match=r"color: shape \(480, 640\), expected \(H, W, 3\)"):
        p.process(frame.color[:, :, 0].copy(), frame.depth, frame.intrinsics)
    with pytest.raises(ValueError, match=r"depth: shape \(480, 640, 1\), expected \(H, W\)"):
        p.process(frame.color, frame.depth[:, :, None].copy(), frame.intrinsics)
    with pytest.raises(ValueError, match=r"color \(480, 320, 3\) and depth \(480, 640\) differ"):
        p.process(frame.color[:, :320].copy(), frame.depth, frame.intrinsics)
    with pytest.raises(ValueError, match=r"depth: empty image"):
        p.process(None, np.zeros((0, 5), np.uint16), frame.intrinsics)


def test_non_contiguous_arrays(frame):
    p = wul3d.Pipeline()
    with pytest.raises(ValueError, match=r"depth: array is not C-contiguous"):
        p.process(frame.color[:, ::2].copy(), frame.depth[:, ::2], frame.intrinsics)
    with pytest.raises(ValueError, match=r"color: array is not C-contiguous"):
        p.process(np.asfortranarray(frame.color), frame.depth, frame.intrinsics)


def test_bad_intrinsics(frame):
    p = wul3d.Pipeline()
    with pytest.raises(ValueError, match=r"intrinsics: invalid intrinsics .*fx nan"):
        p.process(frame.color, frame.depth, wul3d.Intrinsics(float("nan"), 525, 320, 240))
    with pytest.raises(ValueError, match=r"intrinsics: invalid intrinsics .*cy inf"):
        p.process(frame.color, frame.depth, {"fx": 525, "fy": 525, "cx": 320, "cy": float("inf")})
    with pytest.raises(ValueError, match=r"intrinsics: dict has no 'cy'"):
        p.process(frame.color, frame.depth, {"fx": 525, "fy": 525, "cx": 320})
    with pytest.raises(ValueError, match=r"intrinsics: for a 320x240 image, the arrays are 640x480"):
        p.process(frame.color, frame.depth, wul3d.Intrinsics(525, 525, 320, 240, 320, 240))
    with pytest.raises(ValueError, match=r"depth_scale"):
        p.process(frame.color, frame.depth, frame.intrinsics, depth_scale=float("nan"))


def test_frame_without_depth_is_an_input_error(frame):
    with pytest.raises(wul3d.InputError, match="no valid pixel"):
        wul3d.Pipeline().process(frame.color, np.zeros_like(frame.depth), frame.intrinsics)
    assert issubclass(wul3d.InputError, ValueError)


@pytest.mark.parametrize("kwargs, flags", [
    ({"k": 0}, ["--k", "0"]),
    ({"alpha": 0.5}, ["--alpha", "0.5"]),
    ({"decimate": 9}, ["--decimate", "9"]),
    ({"segmenter": "watershed"}, ["--segmenter", "watershed"]),
    ({"preset": "fast"}, ["--preset", "fast"]),
    ({"zmin": 3.0, "zmax": 2.0}, ["--zmin", "3", "--zmax", "2"]),
])
def test_bad_parameters_give_the_commands_message(cli, tmp_path, kwargs, flags):
    with pytest.raises(ValueError) as err:
        wul3d.Pipeline(**kwargs)
    message = str(err.value)
    assert "\n" not in message
    proc = run_cli(cli, "run", SAMPLES / "uois_tabletop" / "image_0000", "--out", tmp_path, *flags)
    assert proc.returncode == 2
    # The library's message names the keyword ("k = 0: must be ..."), the command's its flag
    # ("--k 0: must be ..."); a limit across two parameters is worded the same in both.
    name = next(iter(kwargs))
    if message.startswith(name + " = "):
        assert proc.stderr == f"wul3d: {flags[0]} {message[len(name) + 3:]}\n"
    else:
        assert proc.stderr == f"wul3d: {message}\n"


def test_help_reads_like_a_reference():
    assert "Args:" in wul3d.Pipeline.__doc__ and "decimate" in wul3d.Pipeline.__doc__
    assert "GIL" in wul3d.Pipeline.process.__doc__
    for obj in (wul3d.Intrinsics, wul3d.Result, wul3d.Instance, wul3d.read, wul3d.evaluate,
                wul3d.Reader, wul3d.Frame):
        assert obj.__doc__ and len(obj.__doc__.strip()) > 20, obj


def test_paper_preset_and_no_plane_equal_wul3d_run(cli, tmp_path):
    frame = SAMPLES / "uois_tabletop" / "image_0007"
    proc = run_cli(cli, "run", frame, "--out", tmp_path, "-q", "--preset", "paper",
                   "--no-plane", "--object-psi", 1)
    assert proc.returncode == 0, proc.stderr
    results = process_sequence(frame, preset="paper", remove_plane=False, object_psi=1.0)
    assert wul3d.Pipeline(preset="paper").params["decimate"] == 1
    assert_same_as_cli(results, tmp_path)
