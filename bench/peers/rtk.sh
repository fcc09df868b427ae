#!/usr/bin/env bash
# Peer benchmark: RTK's Joseph forward projector (ITK's Reconstruction
# Toolkit, `pip install itk-rtk`) in parallel geometry, on the CPU.
#
# It installs itk-rtk and numpy from PyPI into a venv under the Cargo target
# directory (nothing is vendored), builds an n³ Gaussian-mixture phantom of
# unit voxels, and forward-projects it one view at a time: an n × n detector
# with unit pixels, in parallel geometry (RTK's source-to-detector distance
# of 0), at oblique gantry angles. It prints the median wall-clock ms per view
# for each size, using all the threads that ITK uses by default (every core).
#
# Usage: bash bench/peers/rtk.sh [SIZES] [VIEWS]
#   SIZES  comma-separated sides, default 128,256 (512 holds 512 MiB of f32 volume)
#   VIEWS  timed views per size, default 7 (after one warm-up view)
#
# Compare with the frequency-domain renderer in the same session, on the same
# machine, as a ratio. Absolute times drift with the machine's load.
#   cargo bench -p fvr-host --bench peers     # kb3 f16 view (one thread) and
#                                             # our ray caster (all cores), 128³ and 256³
#   bash bench/peers/rtk.sh 128,256
# ratio = RTK ms per view / frequency_kb3_f16 time per view, at each n.
# The work is the same: one n² image of line integrals through an n³ f32
# volume. RTK's Joseph interpolation is bilinear in the slices it crosses.
# `fvr trade` gives the frequency path's time for every filter and format
# at each size, but with a noisier wall clock (see docs/trade/README.md).
#
# RTK's time depends on the view: rays along an axis or in the detector
# plane walk memory differently. The views here are oblique (25° tilt), as in
# `fvr trade`. Check that the printed image sum / volume sum is about 1: the
# detector then sees the whole volume.
#
# This is a manual benchmark: it is not part of scripts/test-all.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."

SIZES="${1:-128,256}"
VIEWS="${2:-7}"
TARGET="${CARGO_TARGET_DIR:-target}"
VENV="$TARGET/peers/rtk-venv"

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import itk; from itk import RTK" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet itk-rtk numpy
fi

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$VENV/bin/python" - "$SIZES" "$VIEWS" <<'PY'
import statistics
import sys
import time

import itk
import numpy as np
from itk import RTK as rtk

sizes = [int(s) for s in sys.argv[1].split(",")]
views = int(sys.argv[2])
ImageType = itk.Image[itk.F, 3]
print(f"itk {itk.Version.GetITKVersion()}, RTK Joseph forward projector, "
      f"{itk.MultiThreaderBase.GetGlobalDefaultNumberOfThreads()} ITK threads")


def phantom(n, count=8, seed=1):
    """n³ f32 sum of `count` random axis-aligned Gaussians inside the sphere
    of radius 0.4 n, sigma 1.5 to 0.12 n voxels."""
    rng = np.random.default_rng(seed)
    ax = np.arange(n, dtype=np.float32)
    vol = np.zeros((n, n, n), dtype=np.float32)
    for _ in range(count):
        s = rng.uniform(1.5, max(1.5, 0.12 * n), 3)
        c = n / 2 + rng.uniform(-0.2 * n, 0.2 * n, 3)
        g = [np.exp(-0.5 * ((ax - c[a]) / s[a]) ** 2).astype(np.float32) for a in range(3)]
        vol += rng.uniform(0.3, 1.0) * (g[2][:, None, None] * g[1][None, :, None] * g[0][None, None, :])
    return vol


for n in sizes:
    volume = itk.image_from_array(phantom(n))
    volume.SetOrigin([-(n - 1) / 2.0] * 3)
    volume.SetSpacing([1.0] * 3)
    source = rtk.ConstantImageSource[ImageType].New()
    source.SetOrigin([-(n - 1) / 2.0, -(n - 1) / 2.0, 0.0])
    source.SetSpacing([1.0] * 3)
    source.SetSize([n, n, 1])
    source.SetConstant(0.0)
    source.Update()
    times = []
    total = None
    for i in range(views + 1):
        geometry = rtk.ThreeDCircularProjectionGeometry.New()
        # sid 1000, sdd 0: parallel geometry; oblique gantry angle and tilt.
        geometry.AddProjection(1000.0, 0.0, 20.0 + 137.5 * i, 0.0, 0.0, 25.0, 0.0)
        joseph = rtk.JosephForwardProjectionImageFilter[ImageType, ImageType].New()
        joseph.SetInput(0, source.GetOutput())
        joseph.SetInput(1, volume)
        joseph.SetGeometry(geometry)
        t = time.perf_counter()
        joseph.Update()
        dt = (time.perf_counter() - t) * 1e3
        if i > 0:
            times.append(dt)
        total = float(itk.array_view_from_image(joseph.GetOutput()).sum())
    # The mean pixel times n² is the volume's mass if the projection saw it all.
    mass = float(itk.array_view_from_image(volume).sum())
    print(f"n={n}: RTK Joseph {statistics.median(times):.1f} ms per view "
          f"(median of {views}; min {min(times):.1f}, max {max(times):.1f}); "
          f"image sum / volume sum = {total / mass:.4f}")
PY
