"""A comparison plot: one view of a volume at three accuracy targets and
the f64 reference, with the difference images, in one matplotlib figure.

    python python/examples/compare_plot.py [--volume brainsmall] [--out compare.png]
"""

import argparse

import numpy as np

import fvr


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--volume", default="brainsmall")
    ap.add_argument("--out", default="compare.png")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    vol, spacing = fvr.load(args.volume)
    view = np.array([1.0, 0.3, 0.2])
    ref = fvr.Renderer(vol, spacing, filter="kb6", oversample=2, precision="f64").project(view)
    fig, axes = plt.subplots(2, 4, figsize=(12, 6))
    axes[0, 0].imshow(ref, cmap="gray")
    axes[0, 0].set_title("kb6, oversample 2, f64")
    axes[1, 0].axis("off")
    for col, target in enumerate([30, 40, 50], start=1):
        r = fvr.Renderer(vol, spacing, accuracy_db=target)
        img = r.project(view)
        err = img - ref
        db = 10 * np.log10((ref.astype(float) ** 2).sum() / (err.astype(float) ** 2).sum())
        rep = r.report
        axes[0, col].imshow(img, cmap="gray")
        axes[0, col].set_title(f"{target} dB: {rep['filter']} x{rep['oversample']} {rep['precision']}")
        axes[1, col].imshow(err, cmap="RdBu", vmin=-np.abs(err).max(), vmax=np.abs(err).max())
        axes[1, col].set_title(f"error, {db:.1f} dB")
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(args.out, dpi=80)
    print(f"-> {args.out}")


if __name__ == "__main__":
    main()
