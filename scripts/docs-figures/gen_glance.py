#!/usr/bin/env python3
"""docs/getting-started.md, "What to expect": one figure per line, each
from the run that the page it links to states in full."""

import os
import re
import tempfile

from common import ROOT, Unavailable, fvr_json, need_env, serve, span, thousands
from gen_accuracy import accuracy_rows, plan_rows


def accuracy():
    _, rows = accuracy_rows()
    sizes = sorted({r[0] for r in rows})
    kb4 = [db for r in rows if r[1:5] == ("kb4", "1", "f16", "exact") for db in r[5]]
    kb6 = [db for r in rows if r[1:5] == ("kb6", "2", "f32", "exact") for db in r[5]]
    with tempfile.TemporaryDirectory() as tmp:
        picks = {fvr_json("render", f"gaussians@{n}", "--dir", "1,0,0", "--out", os.path.join(tmp, "g.nrrd"))
                 ["accuracy"]["filter"] for n in sizes}
    if picks != {"kb4"}:
        raise SystemExit(f"the default --accuracy 50 picks {picks} for the Gaussians, not kb4: reword the line")
    at = " and ".join(f"{n}³" for n in sizes)
    return (f"- kb4 in f16, what the default `--accuracy 50` picks for the Gaussian phantoms,\n"
            f"  is {span(kb4)} dB from exact line integrals at {at}; kb6 at oversampling 2\n"
            f"  in f32 is {span(kb6)} dB ([accuracy](accuracy.md), `fvr accuracy`).")


def ct_head():
    rows = [r for r in plan_rows() if r["volume"].startswith("ct-head")]
    if not rows:
        raise Unavailable("the CT head's rows need FVR_CT_HEAD")
    given = next(r for r in rows if "(given)" in r["config"])
    chosen = next(r for r in rows if "the default" in r["config"])
    config = chosen["config"].split(" (")[0]
    return (f"- Volumes that touch their box lose that at oversampling 1: the CT head (at\n"
            f"  256) measures {span(given['measured'])} dB there with kb4 in f16. The default "
            f"`--accuracy 50`\n"
            f"  predicts this from the volume and picks {config}: predicted {chosen['predicted']:.1f} dB,\n"
            f"  measured {span(chosen['measured'])} dB ([accuracy](accuracy.md#predicted-against-measured)).")


def rtk():
    path = os.path.join(ROOT, "docs", "performance", "peers.md")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    command = re.search(r"^Command: `([^`]+)`", text, re.M)[1]
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in text.split("\n")
            if line.startswith("| ") and "method" not in line]
    rtk_row = next(r for r in rows if r[1].startswith("RTK"))
    fvr = {r[1].split()[1]: r for r in rows if r[1].startswith("fvr ")}
    if not {"kb4", "kb6"} <= set(fvr):
        raise Unavailable("docs/performance/peers.md holds no kb4 and kb6 rows")
    k4, k6 = fvr["kb4"], fvr["kb6"]
    return (f"- At {k6[0]} a kb6 f16 view of a turntable about z, {k6[10]} dB from the exact\n"
            f"  line integrals, is {k6[7]}× faster than RTK's Joseph projector at {rtk_row[10]} dB,\n"
            f"  and a kb4 view ({k4[10]} dB) {k4[7]}×; about a tilted axis, {k6[9]}× and {k4[9]}×\n"
            f"  ([performance](performance.md), [one run](performance/peers.md) of\n"
            f"  `{command}`).")


def firmware():
    from gen_firmware import agreement, frames
    plain = frames()[("fvr-scene", "plain-kb3")]
    same = agreement()[("fvr-scene", "plain-kb3")][0] == 0
    return (f"- On the Cortex-M4F a 64×64 kb3 view from a 64³ f16 spectrum takes {thousands(plain['render'])}\n"
            f"  instructions ({plain['render'] / 168e3:.1f} ms at 168 MHz) and is "
            f"{'bit-identical to' if same else 'not bit-identical to'} the host core\n"
            f"  ([firmware](firmware.md), `bash scripts/firmware.sh`).")


GENERATORS = {"glance-accuracy": accuracy, "glance-ct-head": ct_head, "glance-rtk": rtk,
              "glance-firmware": firmware}


def mni152_stats():
    """What `--stats` reports for the MNI152 template, and its times here."""
    path = need_env("FVR_MRI_HEAD", "the MNI152 template's figures")
    with tempfile.TemporaryDirectory() as tmp:
        s = fvr_json("render", path, "--dir", "1,0,0", "--out", os.path.join(tmp, "side.png"))
    load = os.getloadavg()[0]
    dims = " × ".join(str(d) for d in s["dims"])
    return (f"`--stats` prints the volume's size ({dims} for this template), the\n"
            f"spectrum size, the filter and the time of each step. On a {os.cpu_count()}-core machine "
            f"(load average {load:.1f})\n"
            f"the planning took {s['plan_ms'] / 1000:.2f} s, the preprocessing {s['prepare_ms'] / 1000:.2f} s "
            f"and the view {s['ms_per_view']:.0f} ms\n"
            f"(`fvr render mni152.nii.gz --dir 1,0,0 --out side.png --stats-json`: `plan_ms`,\n"
            f"`prepare_ms`, `ms_per_view`).")


GENERATORS["getting-started-mni152"] = mni152_stats


if __name__ == "__main__":
    serve(GENERATORS)
