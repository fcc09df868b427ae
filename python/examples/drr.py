"""A DRR set: random rotations of the CT head, one batch, saved as one .npy.

    python python/examples/drr.py [--volume ct-head] [--count 64] [--size 256]
                                  [--out drr.npy] [--png drr-grid.png]

Parallel-beam DRRs (fvr renders parallel rays only): for the CT head, line
integrals in mm of the attenuation relative to water, (HU + 1000) / 1000
clipped at 0. The rotations are uniform on SO(3) (QR of Gaussian
matrices) and saved beside the images (`*_rotations.npy`) so each image
can be matched to its pose. With --png, the first 16 images as a 4x4 grid
(needs matplotlib).
"""

import argparse
import time

import numpy as np

import fvr


def random_rotations(count, seed=0):
    """`count` rotations uniform on SO(3): Q of the QR of a Gaussian matrix,
    its columns' signs fixed by R's diagonal, reflections turned proper."""
    rng = np.random.default_rng(seed)
    q, r = np.linalg.qr(rng.normal(size=(count, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--volume", default="ct-head")
    ap.add_argument("--count", type=int, default=64)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--out", default="drr.npy")
    ap.add_argument("--png", default=None)
    args = ap.parse_args()

    t0 = time.perf_counter()
    vol, spacing = fvr.load(args.volume)
    if args.volume == "ct-head":
        # Hounsfield units to attenuation relative to water (air 0, water 1),
        # so that air adds nothing to a ray and the DRR shows no box.
        np.maximum(vol + 1000.0, 0.0, out=vol)
        vol /= 1000.0
    renderer = fvr.Renderer(vol, spacing)
    t1 = time.perf_counter()
    rotations = random_rotations(args.count)
    images = renderer.project(rotations, size=args.size)
    t2 = time.perf_counter()
    np.save(args.out, images)
    np.save(args.out.replace(".npy", "_rotations.npy"), rotations)
    rep = renderer.report
    print(
        f"{args.volume}: {vol.shape} (z, y, x) at {spacing} mm -> {rep['filter']} "
        f"oversample {rep['oversample']} {rep['precision']}, predicted "
        f"{rep['accuracy']['predicted_db']:.1f} dB; prepared in {t1 - t0:.2f} s"
    )
    print(
        f"{images.shape} float32 in {t2 - t1:.2f} s "
        f"({1e3 * (t2 - t1) / args.count:.1f} ms a view) -> {args.out}"
    )
    if args.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(4, 4, figsize=(8, 8))
        for ax, img in zip(axes.flat, images):
            ax.imshow(img, cmap="gray")
            ax.axis("off")
        fig.suptitle(f"fvr DRRs of {args.volume}: 16 of {args.count} random rotations")
        fig.tight_layout()
        fig.savefig(args.png, dpi=80)
        print(f"-> {args.png}")


if __name__ == "__main__":
    main()
