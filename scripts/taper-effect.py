#!/usr/bin/env python3
"""The effect of `--taper` on the CT head cut at the neck, as a markdown table.

Renders the lateral view (`--view left`, air at 0 with `--background -1024`)
without a taper and with tapers of 4, 8 and 16 voxels, then prints for each:
the deepest undershoot below the cut (the ringing, as a share of the image's
largest value), the change the taper makes to the image (`fvr compare`
against the untapered render, in dB), and the share of pixels it changes by
more than 0.1 % of the peak.

    FVR=target/release/fvr FVR_CT_HEAD=... python3 scripts/taper-effect.py

docs/cli.md ("Cut volumes") holds its output, as the `cli-taper` block of
scripts/docs-figures.sh.
"""
import array
import json
import os
import subprocess
import sys
import tempfile

FVR = os.environ.get("FVR", "target/release/fvr")
VIEW = ["ct-head", "--background", "-1024", "--view", "left"]


def read_nrrd(path):
    """A 2D float NRRD as a list of rows."""
    raw = open(path, "rb").read()
    end = raw.index(b"\n\n")
    header = dict(
        line.split(": ", 1) for line in raw[:end].decode().splitlines()[1:] if ": " in line
    )
    width, height = (int(s) for s in header["sizes"].split())
    values = array.array("f", raw[end + 2 :])
    if sys.byteorder != "little":
        values.byteswap()
    return [values[r * width : (r + 1) * width] for r in range(height)]


def render(out, *extra):
    """The image, and the faces `--stats-json` says were tapered."""
    stats = subprocess.run(
        [FVR, "render", *VIEW, *extra, "--out", out, "--quiet", "--stats-json"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    taper = json.loads(stats)["taper"]
    return read_nrrd(out), taper["faces"] if taper else []


def compare_db(a, b):
    out = subprocess.run(
        [FVR, "compare", a, b, "--json"], check=True, capture_output=True, text=True
    ).stdout
    return json.loads(out)["snr_db"]


def table():
    """The markdown table of the module's docstring."""
    lines = []
    with tempfile.TemporaryDirectory() as d:
        plain_path = os.path.join(d, "plain.nrrd")
        plain, _ = render(plain_path)
        peak = max(max(row) for row in plain)
        # The cut is the lowest row the head reaches in the untapered view;
        # the ringing is what lies below it.
        last = max(r for r, row in enumerate(plain) if max(row) > 0.05 * peak)

        def undershoot(img):
            return -min(min(min(row) for row in img[last + 1 :]), 0.0) / peak

        lines.append(
            "| `--taper` | faces tapered | undershoot below the cut | "
            "image change (`fvr compare`) | pixels changed |"
        )
        lines.append("|---|---|---|---|---|")
        lines.append(f"| none | — | {100 * undershoot(plain):.1f} % of the peak | — | — |")
        for voxels in (4, 8, 16):
            path = os.path.join(d, f"t{voxels}.nrrd")
            img, faces = render(path, f"--taper={voxels}")
            changed = sum(
                abs(a - b) > 1e-3 * peak for ra, rb in zip(img, plain) for a, b in zip(ra, rb)
            )
            pixels = len(img) * len(img[0])
            lines.append(
                f"| {voxels} | {', '.join(faces)} | {100 * undershoot(img):.1f} % | "
                f"{compare_db(plain_path, path):.1f} dB | "
                f"{100 * changed / pixels:.1f} % |"
            )
    return "\n".join(lines)


def main():
    print(table())


if __name__ == "__main__":
    sys.exit(main())
