"""The GIL is released while a pipeline runs: two threads, two pipelines, both inside
process() at once. Shown by the module's count of calls running without the GIL (which can
never pass 1 if process() held it), not by timing."""

import threading

import wul3d
from conftest import SAMPLES


def test_two_pipelines_run_at_once():
    frames = list(wul3d.read(SAMPLES / "uois_tabletop"))
    wul3d._wul3d._reset_concurrency()
    stop = threading.Event()
    errors = []

    def work(pipeline):
        try:
            for i in range(200):  # bounded: stops as soon as the overlap was seen
                if stop.is_set():
                    return
                f = frames[i % len(frames)]
                pipeline.process(f.color, f.depth, f.intrinsics, f.depth_scale)
                if wul3d._wul3d._concurrency()[1] >= 2:
                    stop.set()
        except Exception as e:  # noqa: BLE001  (reported below)
            errors.append(e)
            stop.set()

    threads = [threading.Thread(target=work, args=(wul3d.Pipeline(decimate=1),))
               for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads)
    assert not errors, errors
    running, most = wul3d._wul3d._concurrency()
    assert running == 0
    assert most == 2


def test_one_pipeline_shared_by_two_threads_takes_turns():
    # A pipeline's state carries across frames: two threads on one pipeline are serialized,
    # each result whole (same as processing the frames one after the other).
    f = list(wul3d.read(SAMPLES / "uois_tabletop"))[0]
    shared = wul3d.Pipeline()
    results = [None, None]

    def work(i):
        results[i] = shared.process(f.color, f.depth, f.intrinsics, f.depth_scale)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    reference = wul3d.Pipeline()
    first = reference.process(f.color, f.depth, f.intrinsics, f.depth_scale)
    second = reference.process(f.color, f.depth, f.intrinsics, f.depth_scale)
    assert all(r is not None for r in results)
    # Whichever thread went first got the first frame's result.
    pairs = {(bytes(r.labels.data), bytes(r.objects.data)) for r in results}
    assert pairs == {(bytes(first.labels.data), bytes(first.objects.data)),
                     (bytes(second.labels.data), bytes(second.objects.data))}
