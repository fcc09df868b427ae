#!/usr/bin/env python3
"""The studies that write whole files (`fvr precision`, `trade`, `growth`)
and the tables of `fvr adaptive-table`. File generators write under
$DOCS_FIGURES_OUT at the paths the files have in the repository."""

import os

from common import cached, fvr, fvr_bin, need_env, serve


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
    out = cached(f"adaptive-table-{bound}", [fvr_bin(), "adaptive-table", "--bound", bound, "--runs", "3", "--quiet"])
    return "\n".join(line for line in out.split("\n") if line.startswith("|"))


GENERATORS = {
    "study-precision": precision,
    "study-extremes": extremes,
    "study-trade": trade,
    "study-growth": growth,
    "adaptive-table-exact": lambda: adaptive_table("exact"),
    "adaptive-table-paper": lambda: adaptive_table("paper"),
}


def marks_cost():
    """The marks' cost, from both tables' last column (the runs above)."""
    import re
    from common import bullet, span

    def marks(bound):
        out = {}
        for line in adaptive_table(bound).split("\n"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            m = re.match(r"(\d+)³", cells[1]) if len(cells) > 9 else None
            if m:
                out.setdefault(int(m[1]), []).append(float(cells[9].rstrip(" s")))
        return out

    exact, paper = marks("exact"), marks("paper")
    sizes = sorted(exact)
    said = lambda m: " and ".join(f"{span(m[n], 2)} s for a {n}³ spectrum" for n in sizes)  # noqa: E731
    return bullet(f"**The exact marks cost {'seconds' if max(max(v) for v in exact.values()) >= 1 else 'under a second'} "
                  f"once**: {said(exact)} here, against {said(paper)} for the paper's bound (the tables' last "
                  "column).")


GENERATORS["adaptive-marks-cost"] = marks_cost


if __name__ == "__main__":
    serve(GENERATORS)
