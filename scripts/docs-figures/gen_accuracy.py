#!/usr/bin/env python3
"""Blocks of docs/accuracy.md (and the accuracy figures other pages quote)."""

import re

from common import cached, cargo_test, fvr_bin, need_env, serve, span, table as md_table


def accuracy_rows():
    """The rows of `fvr accuracy`: (n, filter, oversample, precision, reference, [dB x3], floor)."""
    out = cached("fvr-accuracy", [fvr_bin(), "accuracy"])
    rows = []
    for line in out.split("\n"):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 9 and cells[0].isdigit():
            rows.append((int(cells[0]), cells[1], cells[2], cells[3], cells[4],
                         [float(c) for c in cells[5:8]], cells[8]))
    if not rows:
        raise SystemExit("fvr accuracy printed no table")
    return out, rows


def table():
    out, rows = accuracy_rows()
    lines = [line for line in out.strip().split("\n") if line.startswith("|")]
    linear = [db for r in rows if r[1] == "linear" for db in r[5]]
    f16_f64 = [db for r in rows if r[3] == "f16" and r[4] == "f64 pipeline" for db in r[5]]
    return "\n".join(lines + [
        "",
        f"- Trilinear is shown to make the point: at {min(linear):.0f}–{max(linear):.0f} dB it leaves"
        " visible ghosts,",
        "  which is why kb4 is the default.",
        f"- The f16 spectrum sits about {min(f16_f64):.0f}–{max(f16_f64):.0f} dB from f64 (it is rounded"
        " to f16 once,",
        "  after an f32 transform on the host), so f16 storage is never the limit",
        "  for kb3–kb6 at σ = 1.",
    ])



def smooth_lengths(limit):
    def smooth(n):
        for p in (2, 3, 5):
            while n % p == 0:
                n //= p
        return n == 1
    return sum(1 for n in range(1, limit + 1) if smooth(n))


def dims_name(text):
    return "×".join(x.strip() for x in text.strip("[]").split(","))


def mixed_dht():
    """The relative RMS errors `cargo test --test mixed_dht` prints."""
    log = cargo_test("mixed-dht-test", "mixed_dht")
    one = {m[0]: (float(m[1]), m[2]) for m in re.findall(
        r"^1D (f64|f32): worst relative RMS error ([\d.]+)·ε·log₂N \(N = (\d+)\)", log, re.M)}
    grid = [(int(n), float(e), float(r)) for n, e, r in re.findall(
        r"^1D f32 N = (\d+): relative RMS error ([\d.e+-]+) = ([\d.]+)·ε·log₂N$", log, re.M)]
    grid = [g for g in grid if g[0] in (160, 180, 320, 400)]
    round_trip = float(re.search(r"^round trip f64: worst ([\d.]+)", log, re.M)[1])
    two = re.findall(r"^2D (\d+)×(\d+): f64 ([\d.]+), f32 ([\d.]+) ", log, re.M)
    three = re.findall(r"^3D (\[[\d, ]+\]): f64 ([\d.]+), f32 ([\d.]+) ", log, re.M)
    radix2 = re.findall(r"^3D (\[[\d, ]+\]) mixed vs radix 2: ([\d.]+)", log, re.M)
    f16 = re.search(r"^3D (\[[\d, ]+\]) f16 storage: relative RMS error ([\d.]+)·u$", log, re.M)
    exps = {f"{e:.1e}".split("e")[1] for _, e, _ in grid}
    errs = [f"{e:.1e}".split("e")[0] for _, e, _ in grid]
    err_span = (f"{min(errs)}–{max(errs)}·10{superscript(int(exps.pop()))}" if len(exps) == 1
                else ", ".join(f"{e:.1e}" for _, e, _ in grid))
    worst = lambda rows, i: max(float(r[i]) for r in rows)  # noqa: E731
    # The cases the table names: no degenerate axis in 2D, at most one in 3D.
    two_named = [r for r in two if 1 not in (int(r[0]), int(r[1]))][:5]
    three_named = [r for r in three if dims_name(r[0]).split("×").count("1") < 2][:4]
    rows = [
        [f"1D, all {smooth_lengths(512)} lengths ≤ 512 (worst)", f"{one['f64'][0]:.2f} (N = {one['f64'][1]})",
         f"{one['f32'][0]:.2f} (N = {one['f32'][1]})", "2"],
        ["1D, N = " + ", ".join(str(n) for n, _, _ in grid), "—",
         f"{span([r for _, _, r in grid], 2)} ({err_span})", "2"],
        ["1D forward then inverse against the input", f"{round_trip:.2f}", "—", "4"],
        ["2D, " + ", ".join(f"{a}×{b}" for a, b, _, _ in two_named) + ", … (worst)",
         f"{worst(two, 2):.2f}", f"{worst(two, 3):.2f}", "2"],
        ["3D, " + ", ".join(dims_name(d) for d, _, _ in three_named) + ", … (worst)",
         f"{worst(three, 1):.2f}", f"{worst(three, 2):.2f}", "2"],
        ["3D against radix-2 `dht_3d`, " + ", ".join(dims_name(d) for d, _ in radix2),
         f"{worst(radix2, 1):.2f}", "—", "4"],
    ]
    return "\n".join([
        md_table(["case", "f64", "f32", "bound tested"], rows),
        "",
        "With f16 storage (f32 arithmetic, one rounding to f16 per pass) the 3D",
        f"transform of {dims_name(f16[1])} is {float(f16[2]):.2f} u from exact (u = 2⁻¹¹, bound tested 3u).",
    ])


def superscript(n):
    return str(n).translate(str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"))


GENERATORS = {"accuracy-table": table, "accuracy-mixed-dht": mixed_dht}



def plan_log():
    need_env("FVR_CT_HEAD", "the table of predicted against measured")
    return cargo_test("plan-table", "plan", "predicted_against_measured_table", ignored=True)


def plan_rows():
    rows = []
    for line in plan_log().split("\n"):
        m = re.match(r"^\| (.+?) \| (.+?) \| ([-\d.]+) \| ([-\d.]+), ([-\d.]+), ([-\d.]+) \| (\w+) \|$", line)
        if m:
            rows.append({"volume": m[1], "config": m[2], "predicted": float(m[3]),
                         "measured": [float(m[i]) for i in (4, 5, 6)], "dominant": m[7]})
    return rows


def plan_table():
    lines = [line for line in plan_log().split("\n") if line.startswith("|")]
    return "\n".join(lines)


GENERATORS["accuracy-plan"] = plan_table



def tables_of(text):
    """The Markdown tables a test printed, in order: [[lines]]."""
    out, current = [], []
    for line in text.split("\n"):
        if line.startswith("|"):
            current.append(line.rstrip())
        elif current:
            out.append(current)
            current = []
    if current:
        out.append(current)
    return out


def table_starting(text, header):
    for t in tables_of(text):
        if t[0].startswith(header):
            return "\n".join(t)
    raise SystemExit(f"no table starting `{header}` in the test's output")


def mixed_grid():
    need_env("FVR_CT_HEAD", "the CT head's mixed-grid candidates")
    log = cargo_test("mixed-grid-table", "mixed_grid", ignored=True)
    return table_starting(log, "| config | MiB | predicted dB (edge, kernel, storage)")


def plan_real_log():
    need_env("FVR_CT_HEAD", "the real heads' tables")
    need_env("FVR_MRI_HEAD", "the real heads' tables")
    return cargo_test("plan-real", "plan_real", ignored=True)


GENERATORS.update({
    "accuracy-mixed-grid": mixed_grid,
    "accuracy-real-ideal": lambda: table_starting(plan_real_log(), "| volume | view | f64 kb6 σ2 against"),
    "accuracy-real-planner": lambda: table_starting(plan_real_log(),
                                                    "| volume | target | chooser | config | predicted dB (x, y, z; "),
    "accuracy-real-oblique": lambda: table_starting(plan_real_log(),
                                                    "| volume | view | ideal on an n slice against 2n"),
    "accuracy-real-mri": lambda: table_starting(plan_real_log(),
                                                "| volume | target | chooser | config | predicted dB (x, y, z) |"),
    "accuracy-oblique-heads": lambda: "\n".join(
        line for line in cached("oblique-heads", ["bash", "scripts/oblique-heads.sh"]).split("\n")
        if line.startswith("|")),
})


if __name__ == "__main__":
    serve(GENERATORS)
