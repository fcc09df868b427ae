"""Python batch against the CLI turntable, time a view (issue 38).

    python bench/python/batch_vs_turntable.py [--volume gaussians@256] [--frames 64]
                                              [--fvr target/release/fvr] [--repeat 3]

Runs `fvr turntable VOLUME --frames F --stats-json` (its `ms_per_view`:
the views alone, without preparation or encoding) and renders the same F
orbit views (turntable::orbit: --dir 0,-1,0 turned about --up 0,0,1) with
`fvr.Renderer(VOLUME).project(...)` in one batch, best of --repeat runs of
each. Prints both and their ratio; the goal is a ratio <= 1.1. A benchmark,
not a test: run it on an idle machine.
"""

import argparse
import json
import os
import subprocess
import tempfile
import time

import numpy as np

import fvr


def orbit(start, axis, frames):
    """The turntable's directions: `start` turned by 2 pi k / frames about
    `axis` (Rodrigues' formula, as engine/src/render/turntable.rs)."""
    start = np.asarray(start, float)
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    cross, along = np.cross(u, start), u @ start
    theta = 2 * np.pi * np.arange(frames) / frames
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    return start * c + cross * s + u * along * (1 - c)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--volume", default="gaussians@256")
    ap.add_argument("--frames", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--fvr", default=os.path.join("target", "release", "fvr"))
    args = ap.parse_args()

    cli = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            out = subprocess.run(
                [args.fvr, "--quiet", "turntable", args.volume, "--frames", str(args.frames),
                 "--out", os.path.join(tmp, "spin.apng"), "--stats-json"],
                check=True, capture_output=True, text=True,
            ).stdout
            stats = json.loads(out.strip().splitlines()[-1])
            cli.append(stats["ms_per_view"])

    renderer = fvr.Renderer(args.volume)
    views = orbit([0.0, -1.0, 0.0], [0.0, 0.0, 1.0], args.frames)
    out = np.empty((args.frames, *renderer.default_size), np.float32)
    py = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        renderer.project(views, out=out)
        py.append(1e3 * (time.perf_counter() - t0) / args.frames)
    rep = renderer.report
    print(
        f"{args.volume}, {args.frames} views of {out.shape[1]}x{out.shape[2]}, "
        f"{rep['spectrum_side']}^3 {rep['precision']} {rep['filter']} oversample {rep['oversample']}"
    )
    print(f"  fvr turntable   {min(cli):8.2f} ms a view (best of {args.repeat})")
    print(f"  Renderer.project {min(py):7.2f} ms a view (best of {args.repeat})")
    print(f"  ratio           {min(py) / min(cli):8.3f}")


if __name__ == "__main__":
    main()
