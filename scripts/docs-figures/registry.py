"""Every generator of a figure block: its name (the block's), the script
that prints it (or the files it writes), whether its output is deterministic (checked by
`--check`) or holds times (regenerated only), its cost, and what it needs.

cost: quick   seconds; `--check --quick` runs these in scripts/test-all.sh;
      slow    minutes (release builds, the heads, firmware in QEMU);
      manual  long benchmarks and peers (RTK, FINUFFT, FFTW): run only when
              named, or with --all.
"""

from collections import namedtuple

from common import UNAVAILABLE  # noqa: F401 (re-exported for main.py)

Generator = namedtuple("Generator", "name script checked cost needs writes")


def gen(name, script, checked, cost, *needs, writes=()):
    """A block generator, or with `writes` one that writes whole files (a
    study's Markdown, CSV and plot) under $DOCS_FIGURES_OUT, at the paths
    they have in the repository."""
    return Generator(name, script, checked, cost, needs, tuple(writes))


# In the order they run: the files first, then the blocks, some of which
# restate a file (perf-*, precision-summary, glance-rtk).
GENERATORS = [
    # The studies' own files
    gen("study-extremes", "gen_studies.py", True, "slow", "fvr", writes=["docs/precision/extremes.md"]),
    gen("study-precision", "gen_studies.py", True, "slow", "fvr", "ct-head",
        writes=["docs/precision/precision.md", "docs/precision/precision.csv", "docs/precision/precision.png"]),
    gen("study-trade", "gen_studies.py", False, "manual", "fvr",
        writes=["docs/trade/trade.md", "docs/trade/trade.csv", "docs/trade/trade.png"]),
    gen("study-growth", "gen_studies.py", False, "manual", "fvr",
        writes=["docs/growth/growth.md", "docs/growth/growth.csv", "docs/growth/growth.png"]),
    # docs/performance/: the peers (bench/peers/run.sh)
    gen("peers-rtk", "gen_peers.py", False, "manual", "peers", writes=["docs/performance/peers.md"]),
    gen("peers-heads", "gen_peers.py", False, "manual", "peers", "ct-head", "mri-head",
        writes=["docs/performance/heads.md"]),
    gen("peers-finufft", "gen_peers.py", False, "manual", "peers", writes=["docs/performance/finufft.md"]),
    gen("peers-finufft-measure", "gen_peers.py", False, "manual", "peers",
        writes=["docs/performance/finufft-fftw-measure.md"]),
    # docs/cli.md
    gen("cli-cue-window", "gen_cli.py", True, "quick", "fvr"),
    gen("cli-taper", "gen_cli.py", True, "slow", "fvr", "ct-head"),
    # docs/accuracy.md
    gen("accuracy-table", "gen_accuracy.py", True, "quick", "fvr"),
    gen("accuracy-mixed-dht", "gen_accuracy.py", True, "quick", "cargo"),
    gen("accuracy-plan", "gen_accuracy.py", True, "slow", "cargo", "ct-head"),
    gen("accuracy-mixed-grid", "gen_accuracy.py", True, "slow", "cargo", "ct-head"),
    gen("accuracy-real-ideal", "gen_accuracy.py", True, "slow", "cargo", "ct-head", "mri-head"),
    gen("accuracy-real-planner", "gen_accuracy.py", True, "slow", "cargo", "ct-head", "mri-head"),
    gen("accuracy-real-oblique", "gen_accuracy.py", True, "slow", "cargo", "ct-head", "mri-head"),
    gen("accuracy-real-mri", "gen_accuracy.py", True, "slow", "cargo", "ct-head", "mri-head"),
    gen("accuracy-oblique-heads", "gen_accuracy.py", True, "slow", "fvr", "ct-head", "mri-head"),
    # docs/precision.md, from docs/precision/precision.md
    gen("precision-summary", "gen_perf.py", True, "quick"),
    gen("precision-readme-table", "gen_perf.py", True, "quick"),
    gen("precision-ct", "gen_perf.py", True, "quick"),
    gen("precision-q15", "gen_perf.py", True, "slow", "cargo"),
    gen("precision-q15-halving", "gen_perf.py", True, "slow", "cargo"),
    # docs/geometry.md
    gen("geometry-anisotropic", "gen_geometry.py", True, "slow", "cargo"),
    # docs/shading.md
    gen("shading-accuracy", "gen_shading.py", True, "slow", "cargo"),
    gen("shading-cost", "gen_shading.py", False, "slow", "fvr"),
    # docs/adaptive.md
    gen("adaptive-table-exact", "gen_studies.py", False, "slow", "fvr", "ct-head"),
    gen("adaptive-table-paper", "gen_studies.py", False, "slow", "fvr", "ct-head"),
    gen("adaptive-marks-cost", "gen_studies.py", False, "slow", "fvr", "ct-head"),
    # docs/performance.md, from the reports above
    gen("perf-peers", "gen_perf.py", False, "quick"),
    gen("perf-heads", "gen_perf.py", False, "quick"),
    gen("perf-growth", "gen_perf.py", False, "quick"),
    # firmware/README.md and docs/firmware.md: scripts/firmware.sh and scripts/capi.sh
    gen("firmware-run-time", "gen_firmware.py", False, "slow", "firmware"),
    # (the agreement and the M3 view also read a host test's output)
    *(gen(f"firmware-{name}", "gen_firmware.py", True, "quick", "firmware", *(("cargo",) if host else ()))
      for name, host in [("targets", False), ("device-prep", False), ("trig", False), ("m4f-agreement", True),
                         ("m4f-counts", False), ("f16", False), ("m4f-footprint", False),
                         ("m3-transforms", False), ("m3-view", True), ("m3-footprint", False),
                         ("budget", False)]),
    gen("firmware-q15-lines", "gen_firmware.py", True, "slow", "cargo"),
    gen("prepare-budget", "gen_prepare.py", True, "quick", "fvr"),
    gen("prepare-parts", "gen_prepare.py", True, "quick", "fvr"),
    gen("capi", "gen_prepare.py", True, "quick", "fvr", "capi"),
    # docs/getting-started.md
    gen("getting-started-mni152", "gen_glance.py", False, "quick", "fvr", "mri-head"),
    gen("glance-accuracy", "gen_glance.py", True, "quick", "fvr"),
    gen("glance-ct-head", "gen_glance.py", True, "slow", "cargo", "ct-head"),
    gen("glance-rtk", "gen_glance.py", False, "quick"),
    gen("glance-firmware", "gen_glance.py", True, "quick", "firmware"),
    # docs/testing.md: this table
    gen("testing-generators", "gen_testing.py", True, "quick"),
]
