"""Batches: the same images as one view at a time, into a caller's array,
from two Python threads at once, and without leaking over 1,000 calls."""

import gc
import sys
import threading
import tracemalloc

import numpy as np
import pytest

import fvr

DIRS = np.array(
    [[1, 0, 0], [0, 1, 0], [0.3, 1, 0.2], [1, 0.4, -0.3], [-0.2, 0.5, 1], [0.6, 0.1, -0.3]],
    float,
)


@pytest.fixture(scope="module")
def renderer():
    return fvr.Renderer("gaussians@48")


def test_batch_equals_one_by_one(renderer):
    batch = renderer.project(DIRS)
    assert batch.shape == (len(DIRS), *renderer.default_size) and batch.flags.c_contiguous
    for d, img in zip(DIRS, batch):
        one = renderer.project(d)
        assert one.shape == img.shape
        assert np.array_equal(one.view(np.uint32), img.view(np.uint32))
    assert np.abs(batch).sum(axis=(1, 2)).min() > 0


def test_lit_batch_equals_one_by_one():
    r = fvr.Renderer("gaussians@32", lights=[((0.3, 0.2, 1.0), (1.0, 0.5, 0.2))])
    batch = r.project(DIRS[:3])
    assert batch.shape == (3, 32, 32, 3)
    for d, img in zip(DIRS[:3], batch):
        assert np.array_equal(r.project(d), img)


def test_out_is_written_in_place(renderer):
    out = np.full((len(DIRS), 30, 20), np.nan, np.float32)
    got = renderer.project(DIRS, size=(30, 20), out=out)
    assert got is out
    assert np.array_equal(out, renderer.project(DIRS, size=(30, 20)))


def test_per_view_up_and_float32_directions(renderer):
    ups = np.tile([0.0, 1.0, 0.0], (3, 1))
    ups[1] = [0, 0, 1]
    dirs = np.array([[1, 0, 0.1], [1, 0.2, 0], [0.2, 0.1, 1]], np.float32)
    batch = renderer.project(dirs, up=ups)
    for d, u, img in zip(dirs, ups, batch):
        assert np.array_equal(renderer.project(d.astype(float), up=u), img)


def test_two_threads_render_at_once(renderer):
    want = renderer.project(DIRS)
    results = [None, None]
    errors = []

    def work(slot):
        try:
            for _ in range(5):
                results[slot] = renderer.project(DIRS)
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for got in results:
        assert np.array_equal(got, want)


def test_no_reference_leaks_over_1000_calls(renderer):
    views = DIRS[:2].copy()
    out = np.zeros((2, 16, 16), np.float32)
    before = (sys.getrefcount(views), sys.getrefcount(out), sys.getrefcount(renderer))
    for _ in range(50):
        renderer.project(views, size=16)
    gc.collect()
    tracemalloc.start()
    base, _ = tracemalloc.get_traced_memory()
    for _ in range(1000):
        renderer.project(views, size=16, out=out)
        renderer.project(views, size=16)
        try:
            renderer.project(np.zeros((2, 3)))
        except ValueError:
            pass
    gc.collect()
    grown = tracemalloc.get_traced_memory()[0] - base
    tracemalloc.stop()
    after = (sys.getrefcount(views), sys.getrefcount(out), sys.getrefcount(renderer))
    assert before == after
    # 3,000 calls: a leaked 2 KiB image or a leaked exception each call
    # would hold megabytes.
    assert grown < 200_000, grown


def test_empty_batch(renderer):
    imgs = renderer.project(np.zeros((0, 3)))
    assert imgs.shape == (0, *renderer.default_size)


def misaligned(a):
    """`a` copied into a buffer at an odd address (as unpickled out-of-band
    buffers can be)."""
    a = np.ascontiguousarray(a)
    raw = np.zeros(a.nbytes + 1, np.uint8)
    out = np.frombuffer(raw.data, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned
    return out


def test_misaligned_views_and_volume_are_copied(renderer):
    assert np.array_equal(renderer.project(misaligned(DIRS)), renderer.project(DIRS))
    vol = (np.random.default_rng(2).random((12, 10, 14))).astype(np.float32)
    want = fvr.Renderer(vol).project(DIRS[:2])
    assert np.array_equal(fvr.Renderer(misaligned(vol)).project(DIRS[:2]), want)


def test_spectrum_is_the_stored_one_read_only():
    fixed = {"filter": "kb4", "oversample": 1}
    spectra = {}
    for precision, dtype in [("f16", np.float16), ("f32", np.float32), ("f64", np.float64)]:
        r = fvr.Renderer("gaussians@24", precision=precision, **fixed)
        spec, scale = r.spectrum()
        n = r.report["spectrum_side"]
        assert spec.shape == (n, n, n) and spec.dtype == dtype
        assert spec.nbytes == r.report["spectrum_bytes"]
        with pytest.raises(ValueError):
            spec[0, 0, 0] = 1
        spectra[precision] = (spec.astype(np.float64), scale)
    ref, scale = spectra["f64"]
    assert np.abs(ref).max() > 0
    for precision, rel in [("f16", 2.0**-11), ("f32", 2.0**-24)]:
        got, s = spectra[precision]
        assert s == scale
        # The same coefficients, each rounded once to the storage format,
        # after an f32 transform (error ~1e-7 of the largest, measured).
        bound = rel * np.abs(ref) + 1e-6 * np.abs(ref).max()
        assert np.all(np.abs(got - ref) <= bound), precision


def test_the_gil_is_released_while_rendering():
    r = fvr.Renderer("gaussians@64")
    views = np.tile(DIRS, (16, 1))
    count = [0]
    running = threading.Event()
    stop = threading.Event()

    def spin():
        running.set()
        while not stop.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    running.wait()
    sys.setswitchinterval(1e-4)
    try:
        before = count[0]
        r.project(views)
        during = count[0] - before
    finally:
        stop.set()
        t.join()
        sys.setswitchinterval(0.005)
    # With the GIL held the spinning thread runs only around the call: a
    # C call holding it for 140 ms (sorted() of 300,000 floats) let it count
    # 1,821 here. Released, it counts on through the 96 views (about
    # 200,000 in 60 ms measured, with both cores rendering).
    assert during > 20_000, during
