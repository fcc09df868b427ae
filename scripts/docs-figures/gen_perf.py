#!/usr/bin/env python3
"""Blocks of docs/performance.md made from the reports the manual
generators write (docs/performance/*.md, docs/growth/growth.md): each
block restates the latest run of its report."""

import os

from common import ROOT, para, serve, span


def report(path):
    """(text, [header cells], [rows of cells]) of the first table of a report."""
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        text = f.read()
    tables, current = [], []
    for line in text.split("\n"):
        if line.startswith("|"):
            current.append([c.strip() for c in line.strip().strip("|").split("|")])
        elif current:
            tables.append(current)
            current = []
    if current:
        tables.append(current)
    return text, [(t[0], t[2:]) for t in tables]


def lines_of_table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return out + ["| " + " | ".join(r) + " |" for r in rows]


def peers():
    text, tables = report("docs/performance/peers.md")
    header, rows = tables[0]
    col = {name: i for i, name in enumerate(header)}
    rtk = next(r for r in rows if r[col["method"]].startswith("RTK"))
    fvr = {r[col["method"]].split()[1]: r for r in rows if r[col["method"]].startswith("fvr ")}
    k4, k6 = fvr["kb4"], fvr["kb6"]
    pre = [float(r[col["preprocess × scipy rfftn"]]) for r in fvr.values()]
    both = [float(r[col["plan + preprocess × scipy rfftn"]]) for r in fvr.values()]
    gain = float(k6[col["SNR dB"]]) - float(rtk[col["SNR dB"]])
    return "\n".join(lines_of_table(header, rows) + ["", para(
        f"About z a kb4 view is {k4[col['RTK ÷ this']]}× faster than RTK's and a kb6 view, "
        f"{abs(gain):.1f} dB {'above' if gain >= 0 else 'below'} RTK's accuracy, {k6[col['RTK ÷ this']]}×. "
        f"About a tilted axis (the exact walk, which does not prefetch), {k4[col['RTK ÷ this, tilted']]}× "
        f"and {k6[col['RTK ÷ this, tilted']]}×. RTK's own view took {rtk[col['ms / view']]} ms. "
        f"Preprocessing takes {span(pre)}× scipy's `rfftn` of the same f32 volume, {span(both)}× with the "
        "planner.")])


def heads():
    text, tables = report("docs/performance/heads.md")
    (header, rows), (pheader, prows) = tables[0], tables[1]
    col = {name: i for i, name in enumerate(header)}
    said = []
    for volume in dict.fromkeys(r[0] for r in rows):
        mine = [r for r in rows if r[0] == volume]
        default = next(r for r in mine if "default" in r[col["method"]])
        padded = next(r for r in mine if "2× padding" in r[col["method"]])
        said.append((volume, default, padded))
    sentences = []
    for i, (volume, d, p) in enumerate(said):
        sentences.append(
            f"{'On' if i == 0 else 'on'} the {volume} the default renders a view {d[col['RTK ÷ this']]}× faster "
            f"than RTK, in {d[col['default ÷ 2× per view']]} of 2× padding's time, and plans and preprocesses in "
            f"{d[col['plan + preprocess in RTK views']]} RTK views (the planner {d[col['plan ms']]} ms, "
            f"preprocessing {d[col['preprocess ms']]} ms)")
    padding = ", ".join(f"{p[col['RTK ÷ this']]}× RTK on the {v}" for v, _, p in said)
    return "\n".join(lines_of_table(header, rows) + ["", para(
        "; ".join(sentences) + f". 2× padding (a 512³ grid) is {padding}. A spectrum prepared once "
        "(`fvr prepare HEAD --for host`, kb5 or kb4 at σ = 1, f16) and re-rendered by a new "
        "`fvr render HEAD.fvrs` process costs, whole process (read, check, one view, PNG; median of 5):"),
        ""] + lines_of_table(pheader, prows))


def growth():
    text, tables = report("docs/growth/growth.md")
    header, rows = tables[0]
    steps = [float(r[4].rstrip("×")) for r in rows if r[4]]
    ideal = [float(r[6].rstrip("×")) for r in rows if r[6]]
    caster = [float(r[5].rstrip("×")) for r in rows if r[5]]
    first, last = float(rows[0][1].split()[0]), float(rows[-1][1].split()[0])
    per_doubling = (last / first) ** (1 / (len(rows) - 1))
    below = all(s < i for s, i in zip(steps, ideal))
    return "\n".join(lines_of_table(header, rows) + [
        "",
        para(f"- Every step grows {'less' if below else 'not always less'} than n² log n "
             f"({span(ideal)}×): {', '.join(f'{s:.2f}×' for s in steps)}, and from {rows[0][0]} to "
             f"{rows[-1][0]} the view grows {per_doubling:.2f}× per doubling on average.").replace("\n", "\n  "),
        f"- The ray caster grows {span(caster)}× per doubling (n³ is 8×).",
    ])


GENERATORS = {"perf-peers": peers, "perf-heads": heads, "perf-growth": growth}


SUMMARY = [("f16", "f16 (e5m10)", "2"), ("bf16", "bf16", "2"), ("e4m11", "e4m11", "2"),
           ("q15-line", "Q15, one exponent per line", "2 + 1/n"),
           ("q15-brick4", "Q15, one exponent per 4³ brick", None),
           ("q7-brick4", "Q7, one exponent per 4³ brick", None), ("q7-brick2", "Q7, one exponent per 2³ brick", None)]


def precision_cells():
    """The study's SNR table against f64: (header, Gaussian columns,
    Shepp–Logan columns, {(format, arithmetic): row})."""
    _, tables = report("docs/precision/precision.md")
    header, rows = tables[0]
    gauss = [i for i, h in enumerate(header) if h.startswith("gaussians@")]
    shepp = [i for i, h in enumerate(header) if h.startswith("shepp-logan@")]
    return header, gauss, shepp, {(r[0], r[1]): r for r in rows}


def precision_summary():
    """docs/precision.md's summary of docs/precision/precision.md (the study's own file)."""
    header, gauss, shepp, cells = precision_cells()

    def both(fmt, arith):
        r = cells.get((fmt, arith))
        if not r:
            return None, None
        g, s = [float(r[i]) for i in gauss], [float(r[i]) for i in shepp]
        return f"{span(g)} / {span(s)} dB", (g, s)

    out = []
    for fmt, label, size in SUMMARY:
        in_place, values = both(fmt, "per-pass")
        if values and values[0][-1] < values[0][0] - 20:
            in_place = f"collapses as n grows ({values[0][-1]:.0f} dB at {header[gauss[-1]].split('@')[1]}³)"
        host, _ = both(fmt, "host-once")
        out.append([label, size or cells[(fmt, "host-once")][2].rstrip("0").rstrip("."), in_place or "—", host])
    _, f16 = both("f16", "per-pass")
    _, line = both("q15-line", "per-pass")
    gains = [b - a for a, b in zip(f16[0] + f16[1], line[0] + line[1])]
    sizes = [h.split("@")[1] for h in (header[i] for i in gauss)]
    return "\n".join([
        "| format | bytes/voxel | in place, per pass | host f32, one rounding |",
        "|---|---|---|---|",
    ] + ["| " + " | ".join(r) + " |" for r in out] + [
        "",
        f"These are SNRs against the f64 pipeline, worst of four views, over {sizes[0]}³–{sizes[-1]}³,",
        "for the Gaussians / Shepp–Logan.",
        "",
        "- **In place on a target:** f16 is the best float split, and Q15 with",
        f"  per-line exponents beats it by {min(gains):.0f}–{max(gains):.0f} dB.",
    ])


GENERATORS["precision-summary"] = precision_summary



def q15_tables():
    """The two tables of the core's `q15_table` test."""
    from common import cached
    from gen_accuracy import tables_of
    text = cached("core-q15-table", ["cargo", "test", "--locked", "-p", "fvr-core", "--lib", "q15_table", "--",
                                     "--ignored", "--nocapture"])
    tables = tables_of(text)
    if len(tables) < 2:
        raise SystemExit("the core's q15_table test printed no tables")
    return tables


GENERATORS["precision-q15"] = lambda: "\n".join(q15_tables()[0])
GENERATORS["precision-q15-halving"] = lambda: "\n".join(q15_tables()[1])



README_FORMATS = ["f32", "f16", "bf16", "e3m12", "e4m11", "e6m9", "e7m8", "q15", "q15-line", "q15-brick4",
                  "q15-brick8", "e3m4", "e4m3", "e5m2", "q7", "q7-line", "q7-brick4", "q7-brick2"]


def precision_table():
    """docs/precision/README.md's table: per format and arithmetic, the
    Gaussians / Shepp–Logan over the study's sizes (an arrow where the
    SNR falls by more than 20 dB as n grows)."""
    header, gauss, shepp, cells = precision_cells()

    def values(r, cols):
        v = [float(r[i]) for i in cols]
        if v[0] - v[-1] > 20:
            return " → ".join(f"{x:.1f}" if x else "0" for x in v)
        return span(v)

    def cell(fmt, arith):
        r = cells.get((fmt, arith))
        return f"{values(r, gauss)} / {values(r, shepp)}" if r else "—"

    out = ["| format | B/voxel | per-pass | per-stage | host-once |", "|---|---|---|---|---|"]
    for fmt in README_FORMATS:
        any_row = next(r for (f, _), r in cells.items() if f == fmt)
        size = any_row[2].rstrip("0").rstrip(".")
        out.append(f"| {fmt} | {size} | {cell(fmt, 'per-pass')} | {cell(fmt, 'per-stage')} | "
                   f"{cell(fmt, 'host-once')} |")
    return "\n".join(out)


def precision_ct():
    _, tables = report("docs/precision/precision.md")
    header, rows = tables[0]
    ct = next(i for i, h in enumerate(header) if h.startswith("ct-head"))
    v = {(r[0], r[1]): r[ct] for r in rows}
    return "\n".join([
        "Measured, worst of four views:",
        f"- f16 in place: {v[('f16', 'per-pass')]} dB; host-once: {v[('f16', 'host-once')]} dB.",
        f"- Q15 per line: {v[('q15-line', 'per-pass')]} dB in place and {v[('q15-line', 'host-once')]} dB host-once.",
        f"- Q15 per 4³ brick: {v[('q15-brick4', 'host-once')]} dB.",
        f"- The 8-bit formats: e4m3 host-once {v[('e4m3', 'host-once')]} dB, e5m2 {v[('e5m2', 'host-once')]} dB,",
        f"  q7-brick4 {v[('q7-brick4', 'host-once')]} dB.",
        "",
        para("At one byte per spectrum sample, 40 dB on the CT head is reached by "
             + (", ".join(f for f in ["e4m3", "e5m2", "q7-line", "q7-brick4", "q7-brick2"]
                          if float(v[(f, "host-once")]) >= 40) or "no format")
             + " (host-once)."),
    ])


GENERATORS["precision-readme-table"] = precision_table
GENERATORS["precision-ct"] = precision_ct


if __name__ == "__main__":
    serve(GENERATORS)
