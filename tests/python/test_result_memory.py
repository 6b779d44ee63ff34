"""The memory of Result's images (reused from frame to frame, docs/PYTHON.md "Cost of the
binding") and process(outputs=...): results stay valid and their own, whatever is reused."""

import gc

import numpy as np
import pytest

import wul3d
from conftest import SAMPLES

IMAGES = ("labels", "objects", "colors")


@pytest.fixture(scope="module")
def frames():
    return list(wul3d.read(SAMPLES / "uois_tabletop"))


def process(pipeline, f, **kwargs):
    return pipeline.process(f.color, f.depth, f.intrinsics, f.depth_scale, **kwargs)


def images(r):
    return {name: getattr(r, name).copy() for name in IMAGES}


def assert_images_equal(r, expected):
    for name in IMAGES:
        np.testing.assert_array_equal(getattr(r, name), expected[name], err_msg=name)


def reference_of(frames, **params):
    """Two passes over the frames with a fresh pipeline: the images, instances and planes."""
    p = wul3d.Pipeline(**params)
    out = []
    for f in frames + frames:
        r = process(p, f)
        out.append((images(r), [(i.id, i.pixels, i.box_px) for i in r.instances], r.plane))
    return out


@pytest.fixture(scope="module")
def reference(frames):
    return reference_of(frames)


# With decimation (the default) the pipeline hands its images over and writes the frame
# after next into the vectors a dropped result gives back; at every pixel it copies the
# next result into them. Either way every byte is written again.
@pytest.mark.parametrize("decimate, reused_at", [(2, 3), (1, 2)])
def test_dropped_results_memory_is_reused_and_overwritten(frames, reference, decimate, reused_at):
    expected = reference if decimate == 2 else reference_of(frames, decimate=decimate)
    p = wul3d.Pipeline(decimate=decimate)
    kept = process(p, frames[0])  # kept to the end: its memory is not reused meanwhile
    r = process(p, frames[1])
    addresses = {getattr(r, n).ctypes.data for n in IMAGES}
    for name in IMAGES:  # scribbled over: the result that reuses them must overwrite every byte
        getattr(r, name).fill(77)
    del r
    for k, f in enumerate(frames[2:] + frames, start=2):
        r = process(p, f)
        assert_images_equal(r, expected[k][0])
        if k == reused_at:  # the dropped result's memory holds this one
            assert {getattr(r, n).ctypes.data for n in IMAGES} == addresses
        assert not ({getattr(r, n).ctypes.data for n in IMAGES} &
                    {getattr(kept, n).ctypes.data for n in IMAGES})
    assert_images_equal(kept, expected[0][0])


def test_results_are_independent_and_writable(frames, reference):
    p = wul3d.Pipeline()
    results = [process(p, f) for f in frames + frames]
    for r in results:
        assert all(getattr(r, n).flags.writeable for n in IMAGES)
    results[0].labels[:] = 0
    results[0].colors[:] = 0
    for r, (expected, _, _) in zip(results[1:], reference[1:]):
        assert_images_equal(r, expected)


def test_result_outlives_its_pipeline(frames, reference):
    p = wul3d.Pipeline()
    r = process(p, frames[0])
    instance = r.instances[0]
    del p
    gc.collect()
    assert_images_equal(r, reference[0][0])
    assert int(instance.mask().sum()) == instance.pixels
    del r
    gc.collect()
    # The instance still holds the objects image, freed after the pipeline with it.
    assert int(instance.mask().sum()) == instance.pixels
    del instance
    gc.collect()


@pytest.mark.parametrize("outputs", [(), ("objects",), ("labels", "colors"), ["colors"],
                                     ("labels", "objects", "colors"), None])
def test_outputs_selects_the_images_and_nothing_else(frames, reference, outputs):
    p = wul3d.Pipeline()
    full = wul3d.Pipeline()
    chosen = set(IMAGES if outputs is None else outputs)
    for k, f in enumerate(frames + frames):
        r = process(p, f, outputs=outputs)
        r_full = process(full, f)
        expected, instances, plane = reference[k]
        for name in IMAGES:
            if name in chosen:
                np.testing.assert_array_equal(getattr(r, name), expected[name], err_msg=name)
            else:
                assert getattr(r, name) is None, name
        assert [(i.id, i.pixels, i.box_px) for i in r.instances] == instances
        assert r.plane == plane
        assert r.stats == r_full.stats
        assert (r.width, r.height) == f.depth.shape[::-1]
        assert repr(r) == repr(r_full)
        # Colours not asked for are not made at all.
        assert (r.times["colors"] > 0) == ("colors" in chosen)
        for inst in r.instances:
            if "objects" in chosen:
                assert int(inst.mask().sum()) == inst.pixels
            else:
                with pytest.raises(ValueError, match=r"mask\(\): the result has no objects image"):
                    inst.mask()


def test_colors_left_out_then_asked_for_again_are_the_full_pipelines(frames, reference):
    # They are made from the clusters' weights, which go on either way.
    p = wul3d.Pipeline()
    for k, f in enumerate(frames + frames):
        with_colors = k % 2 == 1
        r = process(p, f, outputs=("objects", "colors") if with_colors else ("objects",))
        expected = reference[k][0]
        np.testing.assert_array_equal(r.objects, expected["objects"])
        if with_colors:
            np.testing.assert_array_equal(r.colors, expected["colors"])
        else:
            assert r.colors is None and r.times["colors"] == 0


def test_bad_outputs_raise_before_the_frame_is_processed(frames, reference):
    p = wul3d.Pipeline()
    f = frames[0]
    with pytest.raises(TypeError, match=r"outputs: expected a tuple of names .*got str"):
        process(p, f, outputs="labels")
    with pytest.raises(TypeError, match=r"outputs: expected a tuple of names .*got int"):
        process(p, f, outputs=3)
    with pytest.raises(ValueError, match=r"outputs: 'mask' is not one of 'labels', 'objects', 'colors'"):
        process(p, f, outputs=("labels", "mask"))
    with pytest.raises(TypeError, match=r"outputs\[\]: expected a str, got int"):
        process(p, f, outputs=(1,))
    with pytest.raises(TypeError):  # keyword only
        p.process(f.color, f.depth, f.intrinsics, f.depth_scale, ("labels",))
    # None of the refused calls ran a frame: the stream is where a fresh pipeline's is.
    for k, g in enumerate(frames):
        assert_images_equal(process(p, g), reference[k][0])


def test_odd_sizes_are_copied_to_the_last_byte(frames):
    # 631 x 475: rows of neither 16 nor 64 bytes, images not a whole number of cache lines.
    f = frames[0]
    color = np.ascontiguousarray(f.color[:475, :631])
    depth = np.ascontiguousarray(f.depth[:475, :631])
    K = {"fx": f.intrinsics.fx, "fy": f.intrinsics.fy, "cx": f.intrinsics.cx, "cy": f.intrinsics.cy}
    p = wul3d.Pipeline()
    r = p.process(color, depth, K, f.depth_scale)
    for name in IMAGES:  # scribbled over, then given back to the pool for the next result
        getattr(r, name).fill(0xEE)
    del r
    r = p.process(color, depth, K, f.depth_scale)
    assert r.objects.shape == r.labels.shape == (475, 631) and r.colors.shape == (475, 631, 3)
    assert r.instances
    assert set(np.unique(r.objects)) == {0} | {i.id for i in r.instances}
    for inst in r.instances:
        assert int(inst.mask().sum()) == inst.pixels
    assert int(r.labels.max()) <= p.params["k"]
    assert int((r.labels > 0).sum()) == r.stats["active_points"]
    assert not (r.colors == 0xEE).all(axis=2).any()


def test_fields_read_late_are_the_frames_own(frames, reference):
    # instances, plane, times and stats become Python objects on first read: read after
    # the whole sequence (and the pipeline gone), they are still each frame's.
    p = wul3d.Pipeline()
    results = [process(p, f) for f in frames + frames]
    del p
    gc.collect()
    for r, (_, instances, plane) in zip(results, reference):
        assert [(i.id, i.pixels, i.box_px) for i in r.instances] == instances
        assert r.plane == plane
        assert r.instances is r.instances and r.times is r.times and r.stats is r.stats
        assert set(r.times) >= {"total", "call", "segmentation"}
        assert r.stats["segments"] >= len(r.instances)
    assert len({r.stats["active_points"] for r in results[:len(frames)]}) > 1
