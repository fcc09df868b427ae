#!/usr/bin/env python3
"""Blocks of docs/shading.md."""

import os
import re
import tempfile

from common import cargo_test, fvr_json, para, span, table, serve

# The scenes of tests/tests/shading.rs, as the table names them.
SCENES = [
    ("linear cue", "linear cue"),
    ("sine cue", "sine cue"),
    ("profile cue", "profile cue (0.2, 1, 0.2; M = 6)"),
    ("shaded", "shaded"),
    ("shaded + linear cue", "shaded + linear cue"),
    ("shaded + sine cue", "shaded + sine cue"),
]
CONFIGS = [("Kb6 os2 F32", "kb6, σ=2, f32"), ("Kb4 os1 F16", "kb4, σ=1, f16")]


def accuracy():
    log = cargo_test("shading-test", "shading")
    snr = {}
    for config, _, name, db in re.findall(r"^(Kb\d os\d F\d+) view (\d) (.+?): ([-\d.]+) dB$", log, re.M):
        snr.setdefault((config, name), []).append(float(db))
    rows = [[label] + [span(snr[(c, name)]) for c, _ in CONFIGS] for name, label in SCENES]
    good, bad = re.search(r"^eq\. 14: corrected ([\d.]+) dB, uncorrected ([-\d.]+) dB$", log, re.M).groups()
    f32_f64 = re.search(r"^vs exact: f64 [\d.]+ dB, f32 [\d.]+ dB; f32 vs f64 ([\d.]+) dB$", log, re.M)[1]
    return "\n".join([
        table(["scene"] + [label for _, label in CONFIGS], rows),
        "",
        "- The test's floors are 50 and 45 dB.",
        "- Shading is limited by |∇f|: it has a kink where the gradient vanishes, so its",
        "  samples alias.",
        "- Eq. 14 test, a light 30° off the view axis on the eye's side (d·L = −0.86):",
        f"  {good} dB with the correction and {bad} dB without.",
        f"- The f32 and f64 pipelines agree to {float(f32_f64):.0f} dB.",
    ])


# The scenes of `cargo bench -p fvr-host --bench cues`, as turntable options.
COSTS = [
    ("plain", []),
    ("linear", ["--depth-cue", "linear:1,0.2"]),
    ("sine", ["--depth-cue", "sine:1,0.2"]),
    ("profile M=8", ["--depth-cue", "profile:0.2,1,0.2", "--cue-harmonics", "8"]),
    ("3 lights", ["--light-ring", "3", "--ambient", "0.2"]),
    ("3 lights + linear", ["--light-ring", "3", "--ambient", "0.2", "--depth-cue", "linear:1,0.2"]),
    ("3 lights + sine", ["--light-ring", "3", "--ambient", "0.2", "--depth-cue", "sine:1,0.2"]),
]
FRAMES, RUNS = 24, 3


def cost():
    """ms_per_view of a turntable per scene, the best of RUNS runs taken in turn."""
    base = ["turntable", "gaussians@128", "--filter", "kb4", "--oversample", "1", "--precision", "f16",
            "--size", "128", "--frames", str(FRAMES)]
    best, load = {}, os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "t.apng")
        for _ in range(RUNS):
            for name, flags in COSTS:
                ms = fvr_json(*base, *flags, "--out", out)["ms_per_view"]
                best[name] = min(best.get(name, ms), ms)
    plain = best["plain"]
    cells = [f"1 ({plain:.2f} ms)"] + [f"{best[name] / plain:.1f}" for name, _ in COSTS[1:]]
    scenes = [best[name] / plain for name, _ in COSTS[1:]]
    linear = best["linear"]
    return "\n".join([
        para(f"`fvr turntable gaussians@128 --filter kb4 --oversample 1 --precision f16 --size 128 "
             f"--frames {FRAMES} --stats-json` with each scene's flags (`--depth-cue linear:1,0.2`, `sine:1,0.2`, "
             "`profile:0.2,1,0.2 --cue-harmonics 8`, `--light-ring 3 --ambient 0.2`): `ms_per_view` on "
             f"{os.cpu_count()} cores at load average {load:.1f}, the best of {RUNS} runs taken in turn; ratios are "
             "to the plain projection."),
        "",
        table([name for name, _ in COSTS], [cells]),
        "",
        para(f"A plain view takes the host's own walks (the column walk on these frames, prefetching, on all "
             f"cores: [performance.md](performance.md#view-time)); cued and lit views take the core's scene "
             f"passes, point by point, hence {min(scenes):.0f}–{max(scenes):.0f}× the plain view. Among the "
             f"scenes, three lights cost {best['3 lights'] / linear:.1f}× a linear cue, a sine cue "
             f"{best['sine'] / linear:.1f}× and a profile of 8 harmonics {best['profile M=8'] / linear:.1f}×."),
    ])


serve({"shading-accuracy": accuracy, "shading-cost": cost})
