#!/usr/bin/env python3
"""The studies that write whole files (`fvr precision`, `trade`, `growth`)
and the tables of `fvr adaptive-table`. File generators write under
$DOCS_FIGURES_OUT at the paths the files have in the repository."""

import os

from common import fvr, need_env, serve


def study(*args, into):
    """`fvr STUDY ... --out-dir into`, run in $DOCS_FIGURES_OUT so that the
    command line the study writes into its Markdown names the repository's
    directory."""
    root = os.environ["DOCS_FIGURES_OUT"]
    os.makedirs(os.path.join(root, into), exist_ok=True)
    fvr(*args, "--out-dir", into, cwd=root)
    return ""


def precision():
    need_env("FVR_CT_HEAD", "the precision study's CT head column")
    return study("precision", "--volumes", "gaussians,shepp-logan,ct-head", into="docs/precision")


def extremes():
    return study("precision", "--extremes", "32", into="docs/precision")


def trade():
    return study("trade", "--sizes", "64,128,256", "--formats", "f16,f32,q15-line", into="docs/trade")


def growth():
    return study("growth", "--sizes", "64,128,256,512", "--large", into="docs/growth")


def adaptive_table(bound):
    need_env("FVR_CT_HEAD", "the adaptive table's CT head row")
    out = fvr("adaptive-table", "--bound", bound, "--runs", "3", "--quiet")
    return "\n".join(line for line in out.split("\n") if line.startswith("|"))


GENERATORS = {
    "study-precision": precision,
    "study-extremes": extremes,
    "study-trade": trade,
    "study-growth": growth,
    "adaptive-table-exact": lambda: adaptive_table("exact"),
    "adaptive-table-paper": lambda: adaptive_table("paper"),
}

if __name__ == "__main__":
    serve(GENERATORS)
