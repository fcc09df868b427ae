#!/usr/bin/env python3
"""docs/performance/*.md from bench/peers/run.sh: fvr against RTK's Joseph
projector, scipy's rfftn and FINUFFT. Manual: each installs its peers in a
venv under the target directory and runs for many minutes; run them on an
idle machine (scripts/docs-figures.sh --all, or by name)."""

import os

from common import need_env, run, serve


def peers(*args, name=None):
    out = os.environ["DOCS_FIGURES_OUT"]
    perf = os.path.join(out, "docs", "performance")
    os.makedirs(perf, exist_ok=True)
    extra = ["--out", os.path.join(perf, name)] if name else []
    run(["bash", "bench/peers/run.sh", *args, *extra], env={"PEERS_OUT_DIR": perf})
    if name:
        # The command line the report quotes names the file where it lives.
        path = os.path.join(perf, name)
        with open(path, encoding="utf-8") as f:
            text = f.read().replace(out + os.sep, "")
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
    return ""


def heads():
    need_env("FVR_CT_HEAD", "fvr against RTK on the heads")
    need_env("FVR_MRI_HEAD", "fvr against RTK on the heads")
    return peers("--heads", "--views", "21")


GENERATORS = {
    "peers-rtk": lambda: peers("--sizes", "256", "--filters", "kb4,kb6", "--precision", "f16", "--views", "21"),
    "peers-heads": heads,
    "peers-finufft": lambda: peers("--finufft", "--sizes", "128,256"),
    "peers-finufft-measure": lambda: peers("--finufft", "--sizes", "128,256", "--fftw", "measure",
                                           "--upsampfacs", "1.25", name="finufft-fftw-measure.md"),
}

if __name__ == "__main__":
    serve(GENERATORS)
