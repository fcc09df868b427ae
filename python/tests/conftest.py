"""Shared helpers: the `fvr` binary, NRRD images, closed-form projections."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def fvr_binary():
    """The release `fvr` built from this tree (or $FVR_BIN)."""
    path = os.environ.get("FVR_BIN") or str(ROOT / "target" / "release" / "fvr")
    if not os.access(path, os.X_OK):
        pytest.fail(f"no fvr binary at {path}: run `cargo build --release -p fvr-host` first")
    return path


def read_nrrd_f32(path):
    """A float32 NRRD image as fvr writes it: raw little-endian samples,
    sizes W H (grey) or 3 W H (RGB); returned as (H, W) or (H, W, 3)."""
    data = pathlib.Path(path).read_bytes()
    head, _, body = data.partition(b"\n\n")
    fields = dict(
        line.split(": ", 1) for line in head.decode().splitlines()[1:] if ": " in line
    )
    assert fields["type"] == "float" and fields["encoding"] == "raw", fields
    assert fields.get("endian", "little") == "little", fields
    sizes = [int(s) for s in fields["sizes"].split()]
    arr = np.frombuffer(body, dtype="<f4")
    if len(sizes) == 2:
        return arr.reshape(sizes[1], sizes[0])
    return arr.reshape(sizes[2], sizes[1], sizes[0])


def cli_render(tmp_path, volume, view_args, extra=()):
    """`fvr render VOLUME --dir ... --out x.nrrd` and its image."""
    out = tmp_path / "cli.nrrd"
    cmd = [fvr_binary(), "--quiet", "render", volume, *view_args, *extra, "--out", str(out)]
    subprocess.run(cmd, check=True, capture_output=True)
    return read_nrrd_f32(out)


def vec(v):
    """A vector as the CLI parses it: repr round-trips every float64."""
    return ",".join(repr(float(c)) for c in v)


def frame(direction, up):
    """The engine's camera frame (fvr_core::geometry::View::frame)."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    right = np.cross(d, np.asarray(up, float))
    right /= np.linalg.norm(right)
    return right, np.cross(right, d), d


def gaussian_volume(shape_zyx, spacing_zyx, blobs):
    """Sum of isotropic Gaussians (centre (x, y, z) mm, sigma mm, amplitude)
    sampled at voxel (i, j, k) = (i dx, j dy, k dz) mm; (z, y, x) float32."""
    nz, ny, nx = shape_zyx
    dz, dy, dx = spacing_zyx
    z, y, x = np.meshgrid(
        np.arange(nz) * dz, np.arange(ny) * dy, np.arange(nx) * dx, indexing="ij"
    )
    vol = np.zeros(shape_zyx)
    for (cx, cy, cz), sigma, amp in blobs:
        vol += amp * np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (2 * sigma**2))
    return vol.astype(np.float32)


def exact_projection(shape_zyx, spacing_zyx, blobs, direction, up, h, w, pixel):
    """Closed-form line integrals (mm x volume units) of the Gaussians along
    `direction` through each pixel: pixel (col, row) sits at
    C + (col - w/2) p right + (h/2 - row) p up, C = dims/2 spacing."""
    right, upv, d = frame(direction, up)
    nz, ny, nx = shape_zyx
    dz, dy, dx = spacing_zyx
    centre = np.array([nx / 2 * dx, ny / 2 * dy, nz / 2 * dz])
    rows, cols = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    a = (cols - w / 2) * pixel
    b = (h / 2 - rows) * pixel
    pos = centre + a[..., None] * right + b[..., None] * upv
    img = np.zeros((h, w))
    for c, sigma, amp in blobs:
        rel = pos - np.asarray(c, float)
        perp = rel - (rel @ d)[..., None] * d
        img += amp * sigma * np.sqrt(2 * np.pi) * np.exp(-(perp**2).sum(-1) / (2 * sigma**2))
    return img


def snr_db(reference, image):
    """10 log10 of the reference's energy over the error's."""
    reference = np.asarray(reference, float)
    err = reference - np.asarray(image, float)
    return 10 * np.log10((reference**2).sum() / (err**2).sum())
