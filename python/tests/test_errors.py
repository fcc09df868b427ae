"""Bad input raises one-line Python exceptions of the documented class
(never a crash), with the CLI's messages where the CLI has one."""

import subprocess
import sys

import numpy as np
import pytest

import fvr


@pytest.fixture(scope="module")
def renderer():
    return fvr.Renderer("gaussians@24")


def one_line(excinfo):
    message = str(excinfo.value)
    assert message and "\n" not in message, message
    return message


@pytest.mark.parametrize(
    "views, up, size, cls, words",
    [
        ([0, 0, 0], None, None, ValueError, "zero"),
        ([[1, 0, 0], [0, 0, 1]], None, None, ValueError, "view 1: "),
        ([[1, 0, 0], [np.nan, 0, 1]], None, None, ValueError, "view 1: "),
        (np.zeros((2, 4)), None, None, ValueError, "(B, 3)"),
        ([[1, 0, 0]], [1, 0], None, ValueError, "up must be"),
        (np.eye(3)[None] * 2, None, None, ValueError, "not a rotation"),
        (np.diag([1.0, 1.0, -1.0])[None], None, None, ValueError, "not a rotation"),
        ([[1, 0, 0]], None, 10_000, ValueError, ""),
        ([[1, 0, 0]], None, (0, 4), ValueError, "positive"),
        ([[1, 0, 0]], None, "big", TypeError, "size"),
        ("north", None, None, TypeError, "views"),
        (np.array([[1 + 1j, 0, 0]]), None, None, TypeError, "real numbers"),
    ],
)
def test_bad_views(renderer, views, up, size, cls, words):
    with pytest.raises(cls) as e:
        renderer.project(views, up=up, size=size)
    assert words in one_line(e)


def test_parallel_up_has_the_clis_message(renderer):
    with pytest.raises(ValueError) as e:
        renderer.project([0, 0, 1])
    assert "parallel" in one_line(e)


@pytest.mark.parametrize(
    "out, cls, words",
    [
        (np.zeros((1, 24, 24), np.float64), TypeError, "float32"),
        (np.zeros((2, 24, 24), np.float32), ValueError, "shape (2, 24, 24)"),
        (np.zeros((1, 24, 48), np.float32)[:, :, ::2], ValueError, "C-contiguous"),
        ([[0.0]], TypeError, "float32"),
    ],
)
def test_bad_out(renderer, out, cls, words):
    with pytest.raises(cls) as e:
        renderer.project([[1, 0.2, 0]], size=24, out=out)
    assert words in one_line(e)


def test_read_only_out(renderer):
    out = np.zeros((1, 24, 24), np.float32)
    out.setflags(write=False)
    with pytest.raises(ValueError) as e:
        renderer.project([[1, 0.2, 0]], size=24, out=out)
    assert "writeable" in one_line(e)


@pytest.mark.parametrize(
    "volume, kwargs, cls, words",
    [
        (np.zeros((4, 4)), {}, ValueError, "3-D"),
        (np.zeros((0, 4, 4)), {}, ValueError, "3-D"),
        (np.full((8, 8, 8), np.nan), {}, ValueError, "non-finite"),
        (np.ones((8, 8, 8), complex), {}, TypeError, "real numbers"),
        (np.ones((8, 8, 8), object), {}, TypeError, "real numbers"),
        (np.ones((8, 8, 8)), {"filter": "kb9"}, ValueError, "unknown filter `kb9`"),
        (np.ones((8, 8, 8)), {"precision": "f8"}, ValueError, "unknown precision"),
        (np.ones((8, 8, 8)), {"oversample": 3}, ValueError, "oversample"),
        (np.ones((8, 8, 8)), {"accuracy_db": -1}, ValueError, "accuracy_db"),
        (np.ones((8, 8, 8)), {"depth_cue": "ramp"}, ValueError, ""),
        (np.ones((8, 8, 8)), {"lights": ["1,0,0"]}, ValueError, ""),
        (np.ones((8, 8, 8)), {"lights": "1,0,0:1"}, TypeError, "list"),
        (np.ones((8, 8, 8)), {"spacing": (1, 1)}, ValueError, "spacing"),
        (np.ones((8, 8, 8)), {"spacing": (1, 0, 1)}, ValueError, "spacing"),
        ("/nonexistent/head.nii.gz", {}, FileNotFoundError, "no such file"),
        ("gaussians@3", {}, ValueError, ""),
    ],
)
def test_bad_volumes_and_settings(volume, kwargs, cls, words):
    with pytest.raises(cls) as e:
        fvr.Renderer(volume, **kwargs)
    assert words in one_line(e)


def test_unreadable_file_is_an_oserror(tmp_path):
    bad = tmp_path / "broken.nrrd"
    bad.write_bytes(b"NRRD0004\nsizes: banana\n\n")
    with pytest.raises(OSError) as e:
        fvr.load(str(bad))
    assert "broken.nrrd" in one_line(e)


def test_views_in_a_non_contiguous_array_are_converted(renderer):
    dirs = np.array([[1, 9, 0.2, 9, 0.1], [0, 9, 1, 9, 0.3]], float)[:, ::2]
    assert not dirs.flags.c_contiguous
    assert np.array_equal(renderer.project(dirs), renderer.project(np.ascontiguousarray(dirs)))


def test_volume_dtypes_and_orders_are_converted():
    vol = (np.random.default_rng(1).random((16, 12, 14)) * 100).astype(np.uint8)
    a = fvr.Renderer(vol).project([1, 0.3, 0.2])
    b = fvr.Renderer(np.asfortranarray(vol.astype(np.float64))).project([1, 0.3, 0.2])
    assert np.array_equal(a, b)


MEMORY_SCRIPT = """
import numpy as np, fvr
fvr.set_max_memory("1M")
def expect(cls, call):
    try:
        call()
    except cls as e:
        assert "\\n" not in str(e) and "memory limit" in str(e), str(e)
        return
    raise AssertionError("no " + cls.__name__)
expect(MemoryError, lambda: fvr.Renderer(np.ones((96, 96, 96), np.float32)))
expect(MemoryError, lambda: fvr.load("gaussians@128"))
r = fvr.Renderer("gaussians@16")
expect(MemoryError, lambda: r.project(np.tile([1.0, 0.2, 0.1], (2000, 1))))
assert r.project(np.tile([1.0, 0.2, 0.1], (10, 1))).shape == (10, 16, 16)
try:
    fvr.set_max_memory("2M")
except ValueError as e:
    assert "once" in str(e), str(e)
else:
    raise AssertionError("a second limit was taken")
print("ok")
"""


def test_beyond_the_memory_limit_is_a_memory_error():
    # The limit is set once per process (as --max-memory): a child process.
    done = subprocess.run(
        [sys.executable, "-c", MEMORY_SCRIPT], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@pytest.mark.parametrize(
    "views, up",
    [([1e-320, 0, 0], None), ([[1, 0, 0]], [0, 0, 1e-320]), ([[1, 0.2, 0], [0, -5e-324, 0]], None)],
)
def test_subnormal_view_vectors_are_refused_not_rendered_as_nan(renderer, views, up):
    # Subnormal components pass a test for zero but overflow on the way to
    # a unit vector; the core refuses them for every front end.
    with pytest.raises(ValueError) as e:
        renderer.project(views, up=up)
    assert "too short to normalise" in one_line(e)


def test_subnormal_light_direction_is_refused():
    with pytest.raises(ValueError) as e:
        fvr.Renderer("gaussians@16", lights=["1e-320,0,0:1"]).project([1, 0.2, 0])
    assert "too short to normalise" in one_line(e)


@pytest.mark.parametrize(
    "scale, kwargs, words",
    [
        (3e38, {}, "rescale the volume"),
        (1.0, {"ambient": 1e300}, "lower the ambient colour"),
        (1.0, {"lights": ["1,0,0:1e300"]}, "lower the light colours"),
        (1.0, {"depth_cue": "linear:1e300,0"}, "lower the depth-cue weights"),
    ],
)
def test_images_that_overflow_float32_raise_instead_of_returning_nan(scale, kwargs, words):
    volume = np.random.default_rng(1).random((16, 16, 16)).astype(np.float32)
    volume *= np.float32(scale)
    renderer = fvr.Renderer(volume, **kwargs)
    out = np.full((1, 16, 16, 3) if "lights" in kwargs else (1, 16, 16), 7, np.float32)
    with pytest.raises(ValueError) as e:
        renderer.project([[1, 0.2, 0.1]], size=16, out=out)
    message = one_line(e)
    assert "non-finite pixels" in message and words in message, message
    assert np.isfinite(out).all()
