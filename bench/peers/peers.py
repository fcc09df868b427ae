"""Peers side by side, in one run on one machine: fvr's frequency-domain
view, RTK's Joseph forward projector and scipy's 3D FFT, on the same volume,
each image scored in dB against the analytic line integrals.

The volume is a mixture of axis-aligned Gaussians (sigma 1.5 to 0.12 n
voxels, inside the sphere of radius 0.4 n). A Gaussian of sigma >= 1.5 voxels
is band-limited to about -96 dB at Nyquist, so its closed-form line integral
is the exact projection of the band-limited interpolant up to that floor:

    int a exp(-1/2 (x - c)^T D (x - c)) dt along x = p + t d, D = diag(1/s^2),
    = a sqrt(2 pi / d^T D d) exp(-1/2 [q^T D q - (d^T D q)^2 / d^T D d]), q = p - c.

Run through bench/peers/run.sh, which installs the Python side.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import time

import numpy as np


def phantom(n, count=8, seed=1):
    """The volume (numpy [z, y, x], f32) and its Gaussians (a, centre, sigma),
    centre and sigma in voxel index units (x, y, z)."""
    rng = np.random.default_rng(seed)
    ax = np.arange(n, dtype=np.float64)
    vol = np.zeros((n, n, n), dtype=np.float64)
    gaussians = []
    for _ in range(count):
        s = rng.uniform(1.5, max(1.5, 0.12 * n), 3)
        c = n / 2 + rng.uniform(-0.2 * n, 0.2 * n, 3)
        a = rng.uniform(0.3, 1.0)
        g = [np.exp(-0.5 * ((ax - c[k]) / s[k]) ** 2) for k in range(3)]
        vol += a * (g[2][:, None, None] * g[1][None, :, None] * g[0][None, None, :])
        gaussians.append((a, c, s))
    return vol.astype(np.float32), gaussians


def line_integrals(gaussians, points, d):
    """Closed-form integrals along unit direction d through points [..., 3]
    (voxel index units)."""
    d = np.asarray(d, dtype=np.float64)
    d = d / np.linalg.norm(d)
    out = np.zeros(points.shape[:-1])
    for a, c, s in gaussians:
        w = 1.0 / s**2
        q = points - c
        ddd = np.sum(d * d * w)
        dq = np.sum(q * d * w, axis=-1)
        qq = np.sum(q * q * w, axis=-1)
        out += a * np.sqrt(2 * np.pi / ddd) * np.exp(-0.5 * (qq - dq * dq / ddd))
    return out


def snr_db(reference, image):
    err = np.sum((image - reference) ** 2)
    return 10 * np.log10(np.sum(reference**2) / err) if err > 0 else float("inf")


def write_nrrd(path, vol):
    n = vol.shape
    header = (
        "NRRD0004\ntype: float\ndimension: 3\n"
        f"sizes: {n[2]} {n[1]} {n[0]}\nendian: little\nencoding: raw\n\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vol.astype("<f4").tobytes())


def read_nrrd_image(path):
    raw = pathlib.Path(path).read_bytes()
    head, _, body = raw.partition(b"\n\n")
    fields = dict(
        line.split(": ", 1) for line in head.decode().splitlines()[1:] if ": " in line
    )
    w, h = (int(v) for v in fields["sizes"].split())
    return np.frombuffer(body, dtype="<f4").reshape(h, w).astype(np.float64)


def fvr_frame(d, up=(0.0, 0.0, 1.0)):
    """fvr's view frame (docs/geometry.md): r = normalize(d x u0), u = r x d."""
    d = np.asarray(d, dtype=np.float64)
    d = d / np.linalg.norm(d)
    r = np.cross(d, up)
    r /= np.linalg.norm(r)
    return d, r, np.cross(r, d)


def fvr_reference(gaussians, n, d):
    """Pixel (col, row) of an n x n image sits at c + (col - n/2) r + (n/2 - row) u."""
    d, r, u = fvr_frame(d)
    col = np.arange(n) - n / 2
    row = n / 2 - np.arange(n)
    points = (
        np.full(3, n / 2)
        + col[None, :, None] * r[None, None, :]
        + row[:, None, None] * u[None, None, :]
    )
    return line_integrals(gaussians, points, d)


def median_ms(fn, repeats, warm=True):
    """Median wall time of `repeats` calls of `fn` in ms, after one
    untimed warm-up call unless `warm` is false."""
    if warm:
        fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def rtk_geometry(i):
    """RTK view `i`: parallel rays (sid 1000, sdd 0) at gantry angle
    20 + 137.5 i degrees, tilted by 25 degrees."""
    from itk import RTK as rtk

    geometry = rtk.ThreeDCircularProjectionGeometry.New()
    geometry.AddProjection(1000.0, 0.0, 20.0 + 137.5 * i, 0.0, 0.0, 25.0, 0.0)
    return geometry


def rtk_project(volume, detector, views):
    """RTK's Joseph projector over the views 0 ... `views` of `rtk_geometry`
    onto `detector` (an updated ConstantImageSource): the median ms of
    views 1 ... `views`, view 0's image (float64, rows as RTK stores them)
    and view 0's geometry."""
    import itk
    from itk import RTK as rtk

    image_type = itk.Image[itk.F, 3]
    times, first, first_geometry = [], None, None
    for i in range(views + 1):
        geometry = rtk_geometry(i)
        joseph = rtk.JosephForwardProjectionImageFilter[image_type, image_type].New()
        joseph.SetInput(0, detector.GetOutput())
        joseph.SetInput(1, volume)
        joseph.SetGeometry(geometry)
        t = time.perf_counter()
        joseph.Update()
        if i > 0:
            times.append((time.perf_counter() - t) * 1e3)
        else:
            first = itk.array_from_image(joseph.GetOutput())[0].astype(np.float64)
            first_geometry = geometry
    return statistics.median(times), first, first_geometry


def run_rtk(vol, gaussians, views):
    """Median ms per view of RTK's Joseph projector in parallel geometry at
    oblique angles, and the first view's SNR against the closed form."""
    import itk
    from itk import RTK as rtk

    n = vol.shape[0]
    image_type = itk.Image[itk.F, 3]
    volume = itk.image_from_array(vol)
    volume.SetOrigin([-(n - 1) / 2.0] * 3)
    volume.SetSpacing([1.0] * 3)
    source = rtk.ConstantImageSource[image_type].New()
    source.SetOrigin([-(n - 1) / 2.0, -(n - 1) / 2.0, 0.0])
    source.SetSpacing([1.0] * 3)
    source.SetSize([n, n, 1])
    source.SetConstant(0.0)
    source.Update()
    ms, image, geometry = rtk_project(volume, source, views)
    to_world = np.array(
        itk.array_from_matrix(geometry.GetProjectionCoordinatesToFixedSystemMatrix(0))
    )
    ray = np.array(itk.array_from_matrix(geometry.GetRotationMatrix(0)))[2, :3]
    uv = np.arange(n) - (n - 1) / 2
    world = (
        uv[None, :, None] * to_world[:3, 0]
        + uv[:, None, None] * to_world[:3, 1]
        + to_world[:3, 3]
    )
    # Physical coordinates put voxel index i at i - (n - 1)/2.
    snr = snr_db(line_integrals(gaussians, world + (n - 1) / 2, ray), image)
    return ms, snr, itk.MultiThreaderBase.GetGlobalDefaultNumberOfThreads()


# The tilted turntable's axis and first direction (not along the axis).
TILTED_UP = "0.2,0.3,1"
TILTED_DIR = "0.3,-1,0.3"


def run_fvr(fvr, path, gaussians, n, filt, precision, views, work):
    """fvr's preprocessing and ms per view (turntable, all cores), and the SNR
    of one oblique view against the closed form."""
    d = (1.0, 0.3, 0.2)
    apng = work / f"turn-{n}-{filt}.apng"
    out = subprocess.run(
        [fvr, "turntable", str(path), "--frames", str(views), "--filter", filt,
         "--precision", precision, "--size", str(n), "--stats-json", "--quiet",
         "--out", str(apng)],
        check=True, capture_output=True, text=True,
    ).stdout
    stats = json.loads(out[out.index("{"):])
    # The same turntable about a tilted axis: its slices' rows hold no
    # coordinate, so no view takes the strip walk.
    out = subprocess.run(
        [fvr, "turntable", str(path), "--frames", str(views), "--filter", filt,
         "--precision", precision, "--size", str(n), "--up", TILTED_UP,
         "--dir", TILTED_DIR, "--stats-json", "--quiet", "--out", str(apng)],
        check=True, capture_output=True, text=True,
    ).stdout
    tilted = json.loads(out[out.index("{"):])["ms_per_view"]
    image_path = work / f"view-{n}-{filt}.nrrd"
    subprocess.run(
        [fvr, "render", str(path), "--dir", ",".join(map(str, d)), "--filter", filt,
         "--precision", precision, "--size", str(n), "--out", str(image_path)],
        check=True, capture_output=True, text=True,
    )
    snr = snr_db(fvr_reference(gaussians, n, d), read_nrrd_image(image_path))
    return stats["plan_ms"], stats["prepare_ms"], stats["ms_per_view"], tilted, snr


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fvr", help="the fvr binary (not needed with --rtk-only)")
    p.add_argument("--rtk-only", action="store_true",
                   help="time RTK alone and print its lines; write nothing")
    p.add_argument("--sizes", default="128,256")
    p.add_argument("--filters", default="kb3,kb4,kb6")
    p.add_argument("--precision", default="f16")
    p.add_argument("--views", type=int, default=7)
    p.add_argument("--work", default="target/peers/work")
    p.add_argument("--out", help="also write the Markdown table to this file")
    args = p.parse_args()
    if not args.rtk_only and not args.fvr:
        p.error("--fvr is required unless --rtk-only")
    work = pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    import scipy
    import scipy.fft

    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, scipy {scipy.__version__}")
    rows = []
    for n in (int(s) for s in args.sizes.split(",")):
        vol, gaussians = phantom(n)
        rtk_ms, rtk_snr, threads = run_rtk(vol, gaussians, args.views)
        print(f"n={n}: RTK Joseph {rtk_ms:.1f} ms/view, {rtk_snr:.1f} dB "
              f"({threads} threads, median of {args.views} views)")
        if args.rtk_only:
            continue
        path = work / f"gaussians-{n}.nrrd"
        write_nrrd(path, vol)
        fft_ms = median_ms(lambda: scipy.fft.rfftn(vol, workers=-1), 5)
        print(f"n={n}: scipy.fft.rfftn f32 {fft_ms:.1f} ms (all cores)")
        rows.append((n, "RTK Joseph (f32)", None, rtk_ms, None, rtk_snr, rtk_ms, fft_ms))
        for filt in args.filters.split(","):
            plan, prep, view, tilted, snr = run_fvr(args.fvr, path, gaussians, n, filt,
                                                    args.precision, args.views, work)
            print(f"n={n}: fvr {filt} {args.precision}: plan {plan:.1f} ms, "
                  f"preprocess {prep:.1f} ms, {view:.2f} ms/view "
                  f"({tilted:.2f} about a tilted axis), {snr:.1f} dB")
            rows.append((n, f"fvr {filt} {args.precision}", (plan, prep), view, tilted, snr,
                         rtk_ms, fft_ms))
    if args.rtk_only:
        return
    lines = [
        f"Command: `bash bench/peers/run.sh --sizes {args.sizes} --filters {args.filters} "
        f"--precision {args.precision} "
        f"--views {args.views}` ({len(rows)} rows, one run).",
        "",
        "| n | method | plan ms | preprocess ms | preprocess × scipy rfftn | "
        "plan + preprocess × scipy rfftn | ms / view | RTK ÷ this | "
        "ms / view, tilted axis | RTK ÷ this, tilted | SNR dB |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for n, name, times, view, tilted, snr, rtk_ms, fft_ms in rows:
        if times is None:
            cells = ["—"] * 4
        else:
            plan, prep = times
            cells = [f"{plan:.0f}", f"{prep:.0f}", f"{prep / fft_ms:.1f}",
                     f"{(plan + prep) / fft_ms:.1f}"]
        tilt = ["—", "—"] if tilted is None else [f"{tilted:.2f}", f"{rtk_ms / tilted:.1f}"]
        lines.append(f"| {n}³ | {name} | {' | '.join(cells)} | {view:.2f} | "
                     f"{rtk_ms / view:.1f} | {' | '.join(tilt)} | {snr:.1f} |")
    table = "\n".join(lines) + "\n"
    print()
    print(table, end="")
    if args.out:
        pathlib.Path(args.out).write_text(table)


if __name__ == "__main__":
    main()
