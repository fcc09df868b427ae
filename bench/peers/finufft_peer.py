"""FINUFFT type 2 as a peer of fvr: the same parallel-beam projection of the
Gaussian-mixture phantom (bench/peers/peers.py), made the way a FINUFFT user
would, scored in dB against the closed-form line integrals.

Geometry. fvr's pixel (col, row) of an n x n view sits at
c + (col - n/2) r + (n/2 - row) u with c = n/2 (voxel index units) and
r = normalize(d x up), u = r x d (docs/geometry.md). By the projection-slice
theorem the projection's 2D Fourier transform at (ka, kb)/n cycles per voxel
is the volume's 3D transform at s = (ka r + kb u)/n, with the phase origin at
c:  F(s) = sum_x f(x) exp(-2 pi i s.(x - c)).  With FINUFFT's default mode
order (modeord 0: modes -n/2 .. n/2-1) voxel index i is mode i - n/2, so the
volume goes in as it is and the points are 2 pi s (type 2, isign -1). The
projection is real, so only half the lattice (ka = 0 .. n/2) is evaluated and
numpy's irfft2 inverts it. The band-limited interpolant of the voxels has no
spectrum outside |s_i| < 1/2 (FINUFFT's answer there would be an alias), so
those points are left out and set to zero.

Per volume: the FINUFFT plan (Plan(2, (n, n, n), eps, nthreads = all cores)):
it depends only on the grid, the tolerance and the options, not on the view.
Per view: setpts (its sort of the points), execute (which, in FINUFFT's
design, deconvolves and zero-pads the volume into the sigma-oversampled grid
and takes its 3D FFT on every call: nothing of the transformed grid is kept
between executes), the 2D inverse FFT and the reordering into the image.

Run through bench/peers/run.sh --finufft, which installs the Python side.
"""

import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from peers import (  # noqa: E402
    line_integrals, median_ms, phantom, read_nrrd_image, snr_db, write_nrrd,
)

# View directions (d, up): an axis view on the turntable about z, two views
# tilted off every axis, and the first view of the tilted orbit fvr times.
VIEWS = [
    ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ((1.0, 0.45, 0.3), (0.0, 0.0, 1.0)),
    ((0.2, 0.3, 1.0), (0.0, 1.0, 0.0)),
    ((0.3, -1.0, 0.3), (0.2, 0.3, 1.0)),
]
ORBIT_UP = (0.2, 0.3, 1.0)
ORBIT_DIR = (0.3, -1.0, 0.3)


def frame(d, up):
    """fvr's view frame (docs/geometry.md): r = normalize(d x up), u = r x d."""
    d = np.asarray(d, dtype=np.float64)
    d = d / np.linalg.norm(d)
    r = np.cross(d, np.asarray(up, dtype=np.float64))
    r /= np.linalg.norm(r)
    return d, r, np.cross(r, d)


def reference(gaussians, n, d, up):
    d, r, u = frame(d, up)
    col = np.arange(n) - n / 2
    row = n / 2 - np.arange(n)
    points = (np.full(3, n / 2) + col[None, :, None] * r[None, None, :]
              + row[:, None, None] * u[None, None, :])
    return line_integrals(gaussians, points, d)


def orbit(n_frames, d0=ORBIT_DIR, up=ORBIT_UP):
    """Directions of a full turn about up starting at d0 (Rodrigues)."""
    k = np.asarray(up, dtype=np.float64)
    k /= np.linalg.norm(k)
    v = np.asarray(d0, dtype=np.float64)
    v /= np.linalg.norm(v)
    out = []
    for i in range(n_frames):
        a = 2 * np.pi * i / n_frames
        out.append((tuple(v * np.cos(a) + np.cross(k, v) * np.sin(a)
                          + k * np.dot(k, v) * (1 - np.cos(a))), tuple(up)))
    return out


class View:
    """The slice's points for one view: a lattice of spacing 1/m cycles per
    voxel, m = pad * n (even), so the image's period is m pixels; only the
    half ka = 0..m/2 (kb in FFT order) inside the band (|s_i| < 1/2). The
    n x n image is the centre of the m x m inverse."""

    def __init__(self, n, d, up, pad=1.0):
        _, r, u = frame(d, up)
        m = 2 * int(round(pad * n / 2))
        ka = np.arange(m // 2 + 1, dtype=np.float64)
        kb = np.fft.fftfreq(m, 1.0 / m)
        s = (kb[:, None, None] * u + ka[None, :, None] * r) / m  # [kb, ka, xyz]
        inside = np.all(np.abs(s) < 0.5, axis=-1)
        self.n, self.m = n, m
        self.inside = inside
        pts = 2 * np.pi * s[inside]
        # The volume is [z, y, x]: FINUFFT's first mode axis is z.
        self.xyz = [np.ascontiguousarray(pts[:, 2]), np.ascontiguousarray(pts[:, 1]),
                    np.ascontiguousarray(pts[:, 0])]
        # The inverse's index j holds coordinate j (mod m); the image's row
        # holds b = n/2 - row, its column a = col - n/2.
        self.rows = (n // 2 - np.arange(n)) % m
        self.cols = (np.arange(n) - n // 2) % m

    def image(self, vals):
        m = self.m
        half = np.zeros((m, m // 2 + 1), dtype=vals.dtype)
        half[self.inside] = vals
        # irfft2 divides by m^2; the projection's inverse transform at
        # spacing 1/m cycles per voxel needs exactly that.
        img = np.fft.irfft2(half, s=(m, m))
        return img[self.rows[:, None], self.cols[None, :]]

    def render(self, plan, vol):
        plan.setpts(*(x.astype(plan_real(plan)) for x in self.xyz))
        return self.image(plan.execute(vol))


def plan_real(plan):
    return np.float32 if plan.dtype == np.complex64 else np.float64


FFTW_FLAGS = {"estimate": 64, "measure": 0}  # FFTW_ESTIMATE (FINUFFT's default), FFTW_MEASURE
FFTW = "estimate"


def make_plan(n, eps, upsampfac, threads):
    import finufft

    dtype = "complex64" if eps >= 1e-5 else "complex128"
    return finufft.Plan(2, (n, n, n), eps=eps, dtype=dtype, nthreads=threads,
                        upsampfac=upsampfac, fftw=FFTW_FLAGS[FFTW])


def run_finufft(vol, gaussians, n, eps, upsampfac, pad, threads, repeats, refs):
    t = time.perf_counter()
    plan = make_plan(n, eps, upsampfac, threads)
    plan_ms = (time.perf_counter() - t) * 1e3
    v = vol.astype(plan.dtype)
    dbs, mss = [], []
    for (d, up), ref in zip(VIEWS, refs):
        view = View(n, d, up, pad)
        dbs.append(snr_db(ref, view.render(plan, v)))  # also the warm-up
        mss.append(median_ms(lambda: view.render(plan, v), repeats, warm=False))
    del plan
    return plan_ms, dbs, mss


def run_finufft_batched(vol, n, eps, upsampfac, pad, threads, frames, repeats):
    """All frames of the tilted orbit in one setpts and one execute, per view."""
    plan = make_plan(n, eps, upsampfac, threads)
    v = vol.astype(plan.dtype)
    views = [View(n, d, up, pad) for d, up in orbit(frames)]
    xyz = [np.concatenate([w.xyz[i] for w in views]).astype(plan_real(plan)) for i in range(3)]
    counts = np.cumsum([0] + [int(w.inside.sum()) for w in views])

    def go():
        plan.setpts(*xyz)
        vals = plan.execute(v)
        for i, w in enumerate(views):
            w.image(vals[counts[i]:counts[i + 1]])

    ms = median_ms(go, repeats) / frames
    del plan
    return ms


def run_fvr(fvr, path, gaussians, n, accuracy, frames, repeats, work, refs):
    apng = work / f"fin-turn-{n}.apng"
    cmd = [fvr, "turntable", str(path), "--frames", str(frames), "--size", str(n),
           "--up", ",".join(map(str, ORBIT_UP)), "--dir", ",".join(map(str, ORBIT_DIR)),
           "--accuracy", str(accuracy), "--stats-json", "--quiet", "--out", str(apng)]
    runs = []
    for _ in range(repeats):
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        runs.append(json.loads(out[out.index("{"):]))
    stats = runs[0]
    ms = statistics.median(r["ms_per_view"] for r in runs)
    dbs = []
    for (d, up), ref in zip(VIEWS, refs):
        img = work / f"fin-view-{n}.nrrd"
        subprocess.run(
            [fvr, "render", str(path), "--dir", ",".join(map(str, d)),
             "--up", ",".join(map(str, up)), "--size", str(n), "--accuracy", str(accuracy),
             "--out", str(img)], check=True, capture_output=True, text=True)
        dbs.append(snr_db(ref, read_nrrd_image(img)))
    config = f"{stats['filter']} σ={stats['oversample']} {stats['precision']}"
    return dict(ms=ms, dbs=dbs, config=config, plan_ms=stats["plan_ms"],
                prepare_ms=stats["prepare_ms"], predicted=stats.get("predicted_db"))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fvr", required=True)
    p.add_argument("--sizes", default="128,256")
    p.add_argument("--accuracies", default="50,60,80")
    p.add_argument("--eps", default="1e-2,1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9")
    p.add_argument("--upsampfacs", default="2.0,1.25")
    p.add_argument("--upsampfacs-large", default="1.25",
                   help="upsampfacs for n >= 256 (2.0 there means a 512^3 FFT every view)")
    p.add_argument("--frames", type=int, default=21)
    p.add_argument("--repeats", type=int, default=2,
                   help="timed repeats per view (after one warm-up)")
    p.add_argument("--fvr-repeats", type=int, default=3,
                   help="turntable runs per accuracy (median of their ms/view)")
    p.add_argument("--pads", default="1,1.25",
                   help="slice lattice spacing 1/(pad n): the image's period is pad n pixels")
    p.add_argument("--fftw", choices=sorted(FFTW_FLAGS), default="estimate",
                   help="the plan's FFTW flag: estimate (FINUFFT's default) or measure "
                        "(slow plan, per volume; FFTW keeps its wisdom for later plans)")
    p.add_argument("--margin", type=float, default=1.0,
                   help="stop tightening eps once the worst view is this many dB "
                        "above fvr's best")
    p.add_argument("--work", default="target/peers/work")
    p.add_argument("--out", help="also write the Markdown report to this file")
    p.add_argument("--command", default=None, help="the command line to print at the top")
    args = p.parse_args()
    global FFTW
    FFTW = args.fftw
    work = pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    import finufft
    import scipy

    threads = os.cpu_count()
    cpu = next((line.split(":", 1)[1].strip() for line in
                pathlib.Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor())
    machine = (f"machine: {threads} cores, {cpu}; python {sys.version.split()[0]}, "
               f"numpy {np.__version__}, scipy {scipy.__version__}, finufft {finufft.__version__}")
    command = args.command or ("bash bench/peers/run.sh --finufft " + " ".join(sys.argv[1:]))
    print(machine)
    accuracies = [int(a) for a in args.accuracies.split(",")]
    detail, table = [], []
    def report(final):
        lines = [
            "# FINUFFT type 2 against fvr: time per view at matched accuracy",
            "",
            machine,
            "",
            f"Command: `{command}`",
            "",
            "Generated by bench/peers/finufft_peer.py (its docstring gives the geometry). "
            "Phantom: the Gaussian mixture of bench/peers/peers.py; dB = SNR of a view against "
            "the closed-form line integrals. Each dB below is the worst of "
            f"{len(VIEWS)} views: " + "; ".join(
                f"d=({','.join(f'{c:g}' for c in d)}) up=({','.join(f'{c:g}' for c in up)})"
                for d, up in VIEWS) + ".",
            "",
            f"- fvr: `fvr turntable VOL --up {','.join(map(str, ORBIT_UP))} --dir "
            f"{','.join(map(str, ORBIT_DIR))} --frames {args.frames} --accuracy A --stats-json`, "
            f"`ms_per_view` (all cores, median of {args.fvr_repeats} runs); its dB from "
            "`fvr render --accuracy A` at each of the views above (NRRD).",
            f"- FINUFFT {finufft.__version__}, plan option fftw = FFTW_{args.fftw.upper()}"
            + (" (plan ms includes FFTW's measuring, paid once per grid: later plans of "
               "the same grid reuse the wisdom)" if args.fftw == "measure" else
               " (FINUFFT's default)")
            + ": per view = setpts + execute (type 2, "
            "nthreads = all cores; execute redoes the σ-padded 3D FFT every call) + "
            f"numpy irfft2 + reordering; median over {args.repeats} timed repeats of each view "
            "after the scored render, then median over the views. The slice lattice has spacing "
            "1/(pad·n) cycles per voxel (pad·n squared points, half of them evaluated as the "
            "image is real): pad 1 is the n×n lattice, and its image period n wraps the "
            "phantom's tails on oblique views (a floor near 67 dB); pad 1.25 lifts it. complex64 for eps ≥ 1e-5, complex128 "
            "below. The plan is per volume (it depends on the grid, eps and options only). "
            "Cheapest setting = least ms/view among the eps × upsampfac settings whose worst view "
            "is within 1 dB of fvr's worst view (or better). eps is swept from loose to tight "
            f"and stops once {args.margin:g} dB above fvr's best, or when a tighter eps gains "
            "under 1 dB.",
            "- Batched: the same setting with all "
            f"{args.frames} frames of the tilted orbit in one setpts + one execute (one 3D FFT "
            "for all), per view — how a FINUFFT user rendering a whole orbit at once would do it.",
            "",
            "| n | accuracy | fvr config | fvr ms/view | fvr dB | FINUFFT setting | "
            "FINUFFT ms/view | FINUFFT dB | fvr ÷ FINUFFT | FINUFFT batched ms/view | "
            "fvr ÷ batched |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for n, acc, r, fdb, best, batched in table:
            if best is None:
                lines.append(f"| {n}³ | {acc} | {r['config']} | {r['ms']:.2f} | {fdb:.1f} | "
                             "none reached | — | — | — | — | — |")
            else:
                lines.append(
                    f"| {n}³ | {acc} | {r['config']} | {r['ms']:.2f} | {fdb:.1f} | "
                    f"eps {best['eps']:.0e}, upsampfac {best['usf']}, pad {best['pad']} | "
                    f"{best['ms']:.2f} | "
                    f"{best['db']:.1f} | {r['ms'] / best['ms']:.3f} | {batched:.2f} | "
                    f"{r['ms'] / batched:.2f} |")
        lines += [
            "",
            "fvr ÷ FINUFFT below 1 means fvr takes less time per view.",
            "",
            "## Every FINUFFT setting measured",
            "",
            "| n | eps | upsampfac | pad | plan ms | ms/view per view | dB per view | worst dB |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for n, s in detail:
            lines.append(f"| {n}³ | {s['eps']:.0e} | {s['usf']} | {s['pad']} | {s['plan_ms']:.0f} | "
                         + " / ".join(f"{x:.1f}" for x in s["mss"]) + " | "
                         + " / ".join(f"{x:.1f}" for x in s["dbs"]) + f" | {s['db']:.1f} |")
        lines += ["", "## fvr runs", "",
                  "| n | accuracy | config | plan ms | prepare ms | ms/view | dB per view |",
                  "|---|---|---|---|---|---|---|"]
        for n, acc, r, fdb, best, batched in table:
            lines.append(f"| {n}³ | {acc} | {r['config']} | {r['plan_ms']:.0f} | "
                         f"{r['prepare_ms']:.0f} | {r['ms']:.2f} | "
                         + " / ".join(f"{x:.1f}" for x in r["dbs"]) + " |")
        text = "\n".join(lines) + "\n"
        if final:
            print()
            print(text, end="")
        if args.out:
            pathlib.Path(args.out).write_text(text)


    for n in (int(s) for s in args.sizes.split(",")):
        vol, gaussians = phantom(n)
        path = work / f"gaussians-{n}.nrrd"
        write_nrrd(path, vol)
        refs = [reference(gaussians, n, d, up) for d, up in VIEWS]
        fvr_rows = {}
        for acc in accuracies:
            r = run_fvr(args.fvr, path, gaussians, n, acc, args.frames, args.fvr_repeats,
                        work, refs)
            fvr_rows[acc] = r
            print(f"n={n} fvr --accuracy {acc}: {r['config']}, plan {r['plan_ms']:.0f} ms, "
                  f"prepare {r['prepare_ms']:.0f} ms, {r['ms']:.2f} ms/view (tilted orbit, "
                  f"{args.frames} frames), dB per view "
                  + " ".join(f"{x:.1f}" for x in r["dbs"]), flush=True)
        goal = max(min(r["dbs"]) for r in fvr_rows.values()) + args.margin
        settings = []
        usfs = args.upsampfacs if n < 256 else args.upsampfacs_large
        for usf in (float(u) for u in usfs.split(",")):
            for pad in (float(x) for x in args.pads.split(",")):
                prev = None
                for eps in (float(e) for e in args.eps.split(",")):
                    plan_ms, dbs, mss = run_finufft(vol, gaussians, n, eps, usf, pad, threads,
                                                    args.repeats, refs)
                    s = dict(eps=eps, usf=usf, pad=pad, plan_ms=plan_ms, dbs=dbs, mss=mss,
                             db=min(dbs), ms=statistics.median(mss))
                    settings.append(s)
                    print(f"n={n} FINUFFT eps {eps:.0e} upsampfac {usf} pad {pad}: plan "
                          f"{plan_ms:.0f} ms, ms/view " + " ".join(f"{x:.1f}" for x in mss)
                          + ", dB " + " ".join(f"{x:.1f}" for x in dbs), flush=True)
                    detail.append((n, s))
                    # Stop at the goal, or once tightening eps no longer helps
                    # (the slice's period or the phantom sets the floor).
                    if s["db"] >= goal or (prev is not None and s["db"] < prev + 1.0):
                        break
                    prev = s["db"]
        for acc in accuracies:
            r = fvr_rows[acc]
            fdb = min(r["dbs"])
            ok = [s for s in settings if s["db"] >= fdb - 1.0]
            best = min(ok, key=lambda s: s["ms"]) if ok else None
            batched = None
            if best is not None:
                batched = run_finufft_batched(vol, n, best["eps"], best["usf"], best["pad"], threads,
                                              args.frames, max(1, args.repeats - 1))
            table.append((n, acc, r, fdb, best, batched))
            if best:
                print(f"n={n} accuracy {acc}: fvr {r['ms']:.2f} ms/view {fdb:.1f} dB; FINUFFT "
                      f"eps {best['eps']:.0e} upsampfac {best['usf']} pad {best['pad']} "
                      f"{best['ms']:.2f} ms/view "
                      f"{best['db']:.1f} dB (batched {batched:.2f}); fvr ÷ FINUFFT "
                      f"{r['ms'] / best['ms']:.2f}", flush=True)
        report(False)
    report(True)

if __name__ == "__main__":
    main()
