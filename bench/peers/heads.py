"""Peers on real heads, in one run on one machine: RTK's Joseph forward
projector against fvr at its default settings (the planner chooses filter,
grid and storage for --accuracy 50) and at 2x padding (kb4, oversampling 2,
f16), on the CT head and, when given, the MRI head.

Each head is converted once with `fvr convert` to a float NRRD with its
spacing, which both programs read. Times: RTK's median ms per oblique view
(parallel geometry, all ITK threads); fvr's preprocessing and ms per view
from `fvr turntable --stats-json` (all cores). Accuracy: one oblique view,
the one RTK times first, rendered by each fvr setting and scored in dB
against fvr's own kb6 / oversampling 2 / f64 rendering of the same view.
RTK is scored against that reference only when every RTK detector pixel
maps exactly onto an fvr pixel (checked below); its linear interpolation
is then compared with the band-limited interpolant, not the same model.

Run through bench/peers/run.sh --heads, which installs the Python side.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import time

import numpy as np

from peers import read_nrrd_image, rtk_project, snr_db

MIB = 1 << 20


def nrrd_layout(path):
    """Sizes (x, y, z) and spacings of a NRRD written by `fvr convert`."""
    head = pathlib.Path(path).read_bytes().split(b"\n\n", 1)[0].decode()
    fields = dict(line.split(": ", 1) for line in head.splitlines()[1:] if ": " in line)
    dims = [int(v) for v in fields["sizes"].split()]
    if "spacings" in fields:
        spacing = [float(v) for v in fields["spacings"].split()]
    else:
        # An oriented volume (NIfTI, DICOM) keeps its axes as space
        # directions; the spacing of each axis is its vector's length.
        vectors = fields["space directions"].replace("(", " ").replace(")", " ").split()
        values = [float(v) for v in ",".join(vectors).split(",") if v]
        spacing = [sum(x * x for x in values[3 * a:3 * a + 3]) ** 0.5 for a in range(3)]
    return dims, spacing


def run(cmd):
    return subprocess.run([str(c) for c in cmd], check=True, capture_output=True,
                          text=True).stdout


def turntable(fvr, volume, flags, views, work, tag):
    out = run([fvr, "turntable", volume, "--frames", views, "--stats-json", "--quiet",
               "--out", work / f"turn-{tag}.apng", *flags])
    return json.loads(out[out.index("{"):])


def run_rtk(path, dims, spacing, image, pixel, views):
    """RTK's median ms per view over `views` oblique views on a W x H
    detector of `pixel` mm, the first view's image (rows as RTK stores them)
    and the world position (mm, centre of the volume at 0) of each of its
    pixels, and the thread count."""
    import itk
    from itk import RTK as rtk

    image_type = itk.Image[itk.F, 3]
    volume = itk.imread(str(path), itk.F)
    # fvr's centre (n/2) D at the origin: voxel i sits at (i - n/2) D.
    volume.SetOrigin([-(dims[a] / 2.0) * spacing[a] for a in range(3)])
    volume.SetSpacing(spacing)
    # fvr renders in the voxel frame: an oriented file's axes (its space
    # directions, which ITK reads as the image's direction) do not turn it.
    volume.SetDirection(itk.matrix_from_array(np.eye(3)))
    w, h = image
    source = rtk.ConstantImageSource[image_type].New()
    # Column i at (i - W/2) P and row j at (j + 1 - H/2) P: fvr's pixels
    # with the rows in the other order (checked in `pixel_map`).
    source.SetOrigin([-(w / 2.0) * pixel, (1 - h / 2.0) * pixel, 0.0])
    source.SetSpacing([pixel, pixel, 1.0])
    source.SetSize([w, h, 1])
    source.SetConstant(0.0)
    source.Update()
    ms, first, geometry = rtk_project(volume, source, views)
    m = np.array(itk.array_from_matrix(
        geometry.GetProjectionCoordinatesToFixedSystemMatrix(0)))
    u = -(w / 2.0) * pixel + pixel * np.arange(w)
    v = (1 - h / 2.0) * pixel + pixel * np.arange(h)
    world = u[None, :, None] * m[:3, 0] + v[:, None, None] * m[:3, 1] + m[:3, 3]
    threads = itk.MultiThreaderBase.GetGlobalDefaultNumberOfThreads()
    return ms, first, world, threads


def view_frame(world):
    """The view direction (perpendicular to the detector) and an up hint
    along the detector's rows, from RTK's pixel positions."""
    a0 = world[0, 1] - world[0, 0]
    a1 = world[1, 0] - world[0, 0]
    # This sign of d makes fvr's r = normalize(d x a1) equal a0's direction.
    d = np.cross(a1, a0)
    return d / np.linalg.norm(d), a1 / np.linalg.norm(a1)


def pixel_map(world, d, up, image, pixel):
    """fvr's (row, col) of every RTK pixel when each lies on one exactly
    (docs/geometry.md: pixel (col, row) at C + (col - W/2) P r + (H/2 - row)
    P u, r = normalize(d x u0), u = r x d), else None."""
    w, h = image
    r = np.cross(d, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, d)
    col = world @ r / pixel + w / 2
    row = h / 2 - world @ u / pixel
    cols, rows = np.rint(col), np.rint(row)
    if max(np.abs(col - cols).max(), np.abs(row - rows).max()) > 1e-6:
        return None
    cols, rows = cols.astype(int), rows.astype(int)
    if cols.min() < 0 or rows.min() < 0 or cols.max() >= w or rows.max() >= h:
        return None
    if len(set(zip(rows.ravel(), cols.ravel()))) != w * h:
        return None
    return rows, cols


def render(fvr, volume, d, up, image, pixel, flags, out):
    run([fvr, "render", volume, "--dir", ",".join(f"{x:.17g}" for x in d),
         "--up", ",".join(f"{x:.17g}" for x in up), "--size", f"{image[0]}x{image[1]}",
         "--pixel-size", f"{pixel:.17g}", "--quiet", "--out", out, *flags])
    return read_nrrd_image(out)


PREPARED = []


def prepared(fvr, volume, d, up, work, slug):
    """`fvr prepare VOLUME --for host` once, then the whole `fvr render
    FILE.fvrs` process (read, check, one view, PNG) timed from outside:
    median ms of 5 runs, and the file's MiB."""
    path = work / f"{slug}.fvrs"
    run([fvr, "prepare", volume, "--for", "host", "--quiet", "--out", path])
    cmd = [str(c) for c in [fvr, "render", path, "--dir", ",".join(f"{x:.17g}" for x in d),
                            "--up", ",".join(f"{x:.17g}" for x in up), "--quiet",
                            "--out", work / f"{slug}-prepared.png"]]
    times = []
    for _ in range(5):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times), path.stat().st_size / MIB


def spectrum_flags(stats):
    return ["--filter", stats["filter"], "--oversample", str(stats["oversample"]),
            "--precision", stats["precision"]]


def head(fvr, name, source, background, views, work):
    """The rows of one head: RTK, fvr default, fvr 2x padding."""
    name_slug = name.lower().replace(" ", "-")
    volume = work / f"{name_slug}.nrrd"
    cmd = [fvr, "convert", source, "--out", volume, "--quiet"]
    if background is not None:
        cmd += ["--background", str(background)]
    run(cmd)
    dims, spacing = nrrd_layout(volume)
    default = turntable(fvr, volume, [], views, work, f"{name_slug}-default")
    image = default["image"][:2]  # [W, H, channels]
    longest = max(n * s for n, s in zip(dims, spacing))
    # fvr's default pixel size for this image (UnitArgs::sampling).
    pixel = max(min(spacing), longest / image[0])
    shape = ["--size", f"{image[0]}x{image[1]}", "--pixel-size", f"{pixel:.17g}"]
    padded = turntable(fvr, volume, ["--filter", "kb4", "--oversample", "2",
                                     "--precision", "f16", *shape], views, work, f"{name_slug}-2x")
    rtk_ms, rtk_image, world, threads = run_rtk(volume, dims, spacing, image, pixel, views)
    d, up = view_frame(world)
    reference = render(fvr, volume, d, up, image, pixel,
                       ["--filter", "kb6", "--oversample", "2", "--precision", "f64"],
                       work / f"{name_slug}-ref.nrrd")
    mapping = pixel_map(world, d, up, image, pixel)
    rtk_snr = None
    if mapping is not None:
        mapped = np.zeros_like(reference)
        mapped[mapping] = rtk_image
        rtk_snr = snr_db(reference, mapped)
    print(f"{name}: {dims} at {spacing} mm, {image[0]}x{image[1]} pixels of {pixel:.4g} mm; "
          f"RTK {rtk_ms:.1f} ms/view ({threads} threads, median of {views}), "
          f"{'—' if rtk_snr is None else f'{rtk_snr:.1f} dB'}", flush=True)
    prepared_ms, prepared_mib = prepared(fvr, volume, d, up, work, name_slug)
    print(f"{name}: fvr render of a prepared .fvrs ({prepared_mib:.0f} MiB): whole process "
          f"{prepared_ms:.0f} ms (median of 5) = {prepared_ms / rtk_ms:.1f} RTK views", flush=True)
    PREPARED.append((name, prepared_mib, prepared_ms, rtk_ms))
    rows = [(name, "RTK Joseph (f32)", None, None, None, rtk_ms, rtk_snr)]
    for label, stats in (("default", default), ("2× padding", padded)):
        img = render(fvr, volume, d, up, image, pixel, spectrum_flags(stats),
                     work / f"{name_slug}-{stats['filter']}-{stats['oversample']}.nrrd")
        snr = snr_db(reference, img)
        method = (f"fvr {label}: {stats['filter']} os{stats['oversample']} "
                  f"{stats['precision']}")
        print(f"{name}: {method}: spectrum {stats['spectrum_bytes'] / MIB:.0f} MiB, "
              f"plan {stats['plan_ms']:.0f} ms, preprocess {stats['prepare_ms']:.0f} ms, "
              f"{stats['ms_per_view']:.2f} ms/view, {snr:.1f} dB", flush=True)
        rows.append((name, method, stats["spectrum_bytes"], stats["plan_ms"], stats["prepare_ms"],
                     stats["ms_per_view"], snr))
    return rows


def table(rows, command):
    lines = [
        f"Command: `{command}` ({len(rows)} rows, one run).",
        "",
        "| volume | method | spectrum MiB | plan ms | preprocess ms | "
        "plan + preprocess in RTK views | ms / view | RTK ÷ this | default ÷ 2× per view | SNR dB |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in dict.fromkeys(r[0] for r in rows):
        mine = [r for r in rows if r[0] == name]
        rtk_ms = mine[0][5]
        padded_ms = mine[2][5]
        for _, method, spectrum, plan, prep, view, snr in mine:
            fvr_row = spectrum is not None
            cells = [
                name, method,
                f"{spectrum / MIB:.0f}" if fvr_row else "—",
                f"{plan:.0f}" if fvr_row else "—",
                f"{prep:.0f}" if fvr_row else "—",
                f"{(plan + prep) / rtk_ms:.1f}" if fvr_row else "—",
                f"{view:.2f}",
                f"{rtk_ms / view:.1f}",
                f"{view / padded_ms:.2f}" if fvr_row else "—",
                "—" if snr is None else f"{snr:.1f}",
            ]
            lines.append("| " + " | ".join(cells) + " |")
    if PREPARED:
        lines += ["", "A prepared spectrum re-rendered (`fvr prepare HEAD --for host`, then the "
                  "whole `fvr render HEAD.fvrs` process: read, check, one view, PNG; median of 5):",
                  "", "| volume | .fvrs MiB | whole process ms | in RTK views |", "|---|---|---|---|"]
        for name, mib, ms, rtk_ms in PREPARED:
            lines.append(f"| {name} | {mib:.0f} | {ms:.0f} | {ms / rtk_ms:.1f} |")
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fvr", required=True, help="the fvr binary")
    p.add_argument("--ct", required=True, help="the CT head (Cranium.inv3)")
    p.add_argument("--mri", help="the MRI head (NIfTI), if any")
    p.add_argument("--views", type=int, default=7)
    p.add_argument("--work", default="target/peers/work")
    p.add_argument("--out", help="also write the Markdown table to this file")
    args = p.parse_args()
    work = pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    import itk

    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, itk {itk.__version__}")
    rows = head(args.fvr, "CT head", args.ct, -1024, args.views, work)
    if args.mri:
        rows += head(args.fvr, "MRI head", args.mri, None, args.views, work)
    command = f"bash bench/peers/run.sh --heads --views {args.views}"
    if args.mri:
        command = "FVR_MRI_HEAD=$(bash scripts/fetch-mri-head.sh) " + command
    text = table(rows, command)
    print()
    print(text, end="")
    if args.out:
        pathlib.Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
