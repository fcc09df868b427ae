#!/usr/bin/env python3
"""Blocks of docs/cli.md."""

import os
import sys
import tempfile

from common import ROOT, fvr, fvr_bin, need_env, png_samples, run, serve


def cue_window():
    """How much a linear cue changes the PNG of sphere@32 along y, the
    cued view taking its uncued view's window times the cue's weight."""
    with tempfile.TemporaryDirectory() as tmp:
        plain, cued = os.path.join(tmp, "plain.png"), os.path.join(tmp, "cued.png")
        view = ["render", "sphere@32", "--dir", "0,1,0", "--quiet"]
        fvr(*view, "--out", plain)
        fvr(*view, "--depth-cue", "linear:1,0.3", "--out", cued)
        a, b = png_samples(plain)[3], png_samples(cued)[3]
    diff = sum(abs(x - y) for x, y in zip(a, b)) / len(a)
    return (f"On `sphere@32` along y, `linear:1,0.3` changes the PNG by {diff:.0f} of 255 on\n"
            "average (`fvr render sphere@32 --dir 0,1,0 [--depth-cue linear:1,0.3] --out\n"
            "FILE.png`, each pixel against the uncued one).")


def taper():
    """`--taper` on the CT head's lateral view (scripts/taper-effect.py)."""
    need_env("FVR_CT_HEAD", "the taper table")
    script = os.path.join(ROOT, "scripts", "taper-effect.py")
    return run([sys.executable, script], env={"FVR": fvr_bin()}).strip()


serve({"cli-cue-window": cue_window, "cli-taper": taper})
