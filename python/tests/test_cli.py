"""The package against `fvr render` bit for bit: same defaults (size, up,
accuracy target, filter choice, units), same image."""

import numpy as np
import pytest

import fvr
from conftest import cli_render, vec


def random_rotations(count, seed):
    """Proper rotations from the QR decomposition of Gaussian matrices."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] = -q[:, 0]
        out.append(q)
    return np.array(out)


@pytest.fixture(scope="module")
def brain():
    return fvr.Renderer("brainsmall")


def test_directions_match_the_cli(brain, tmp_path):
    dirs = np.array([[1.0, 0.3, 0.2], [0.0, 1.0, 0.0], [-0.4, 0.2, 1.0]])
    imgs = brain.project(dirs)
    assert imgs.shape[0] == 3 and imgs.dtype == np.float32
    for i in (0, 2):
        cli = cli_render(tmp_path, "brainsmall", ["--dir", vec(dirs[i])])
        assert cli.shape == imgs[i].shape
        assert np.array_equal(cli.view(np.uint32), imgs[i].view(np.uint32)), i


def test_rotations_match_the_cli(brain, tmp_path):
    rots = random_rotations(2, seed=4)
    imgs = brain.project(rots, size=(90, 110))
    assert imgs.shape == (2, 90, 110)
    for i, rot in enumerate(rots):
        args = ["--dir", vec(-rot[:, 2]), "--up", vec(rot[:, 1]), "--size", "110x90"]
        cli = cli_render(tmp_path, "brainsmall", args)
        assert np.array_equal(cli.view(np.uint32), imgs[i].view(np.uint32)), i


def test_array_input_matches_the_cli_on_the_file(tmp_path):
    # The same volume through fvr.load and an array: the CLI's image.
    vol, spacing = fvr.load("gaussians@40")
    r = fvr.Renderer(vol, spacing, accuracy_db=60)
    d = [0.7, -0.5, 0.3]
    img = r.project(np.array(d))
    cli = cli_render(tmp_path, "gaussians@40", ["--dir", vec(d), "--accuracy", "60"])
    assert np.array_equal(cli.view(np.uint32), img.view(np.uint32))


def test_cued_and_lit_scenes_match_the_cli(tmp_path):
    r = fvr.Renderer("gaussians@32", depth_cue="linear:1,0.3", lights=["0.3,0.2,1:1,0.5,0.2"])
    d = [1.0, 0.3, 0.2]
    img = r.project(np.array([d]))[0]
    assert img.shape[-1] == 3
    args = ["--dir", vec(d), "--depth-cue", "linear:1,0.3", "--light", "0.3,0.2,1:1,0.5,0.2"]
    cli = cli_render(tmp_path, "gaussians@32", args)
    assert np.array_equal(cli.view(np.uint32), img.view(np.uint32))


def test_report_is_the_clis_choice(brain):
    rep = brain.report
    assert rep["volume"] == "brainsmall"
    assert rep["dims"] == [128, 128, 84]
    assert rep["accuracy"]["target_db"] == 50.0 and rep["accuracy"]["target_is_default"]
    assert rep["accuracy"]["predicted_db"] >= 50.0
    assert rep["spectrum_bytes"] == rep["spectrum_side"] ** 3 * {"f16": 2, "f32": 4, "f64": 8}[rep["precision"]]


def write_nrrd(path, vol_zyx, spacing_zyx):
    """A float NRRD (x fastest) with spacings listed x, y, z."""
    nz, ny, nx = vol_zyx.shape
    dz, dy, dx = spacing_zyx
    head = (
        f"NRRD0004\ntype: float\ndimension: 3\nsizes: {nx} {ny} {nz}\n"
        f"spacings: {dx} {dy} {dz}\nencoding: raw\nendian: little\n\n"
    )
    path.write_bytes(head.encode() + np.ascontiguousarray(vol_zyx, "<f4").tobytes())


def test_anisotropic_file_matches_the_cli(tmp_path):
    rng = np.random.default_rng(9)
    vol = rng.random((20, 30, 26)).astype(np.float32)
    path = tmp_path / "aniso.nrrd"
    write_nrrd(path, vol, (1.5, 0.8, 0.6))
    loaded, spacing = fvr.load(str(path))
    assert loaded.shape == (20, 30, 26) and np.array_equal(loaded, vol)
    assert spacing == (1.5, 0.8, 0.6)
    d = [0.3, 1.0, -0.4]
    from_file = fvr.Renderer(str(path)).project(np.array(d))
    from_array = fvr.Renderer(loaded, spacing).project(np.array(d))
    assert np.array_equal(from_file, from_array)
    cli = cli_render(tmp_path, str(path), ["--dir", vec(d)])
    assert np.array_equal(cli.view(np.uint32), from_file.view(np.uint32))
