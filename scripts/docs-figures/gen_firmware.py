#!/usr/bin/env python3
"""firmware/README.md (and the firmware figures other pages quote): every
figure from one run of `bash scripts/firmware.sh` (its QEMU logs, the
tables it prints and the tests it runs), or from the file
DOCS_FIGURES_FIRMWARE_LOG that holds that output."""

import re

from common import bullet, log_or_run, para, serve, table, thousands


def log():
    return log_or_run("DOCS_FIGURES_FIRMWARE_LOG", "firmware", ["bash", "scripts/firmware.sh"])


def section(name):
    """The lines of one QEMU program's log (`-- name` up to the next header)."""
    lines, inside = [], False
    for line in log().split("\n"):
        if line.startswith(("-- ", "== ")):
            inside = line == f"-- {name}"
            continue
        if inside:
            lines.append(line)
    if not lines:
        raise SystemExit(f"no log of {name} in the firmware output")
    return "\n".join(lines)


def find(pattern, text=None, what=None):
    m = re.search(pattern, log() if text is None else text, re.M)
    if not m:
        raise SystemExit(f"the firmware output has no {what or pattern}")
    return m


def printed_table(title):
    """Rows (lists of words) of a table scripts/firmware.sh prints under `== firmware: title`."""
    rows, inside, header = [], False, False
    for line in log().split("\n"):
        if line.startswith("== "):
            if inside:
                break
            inside = line.startswith(f"== firmware: {title}")
            header = inside
            continue
        if inside:
            if header:  # the column names
                header = False
                continue
            if line.strip():
                rows.append(line.split())
    if not rows:
        raise SystemExit(f"the firmware output has no table `{title}`")
    return rows


def frames():
    """{(program, frame): {render, extract, inverse, again, dht}} of the M4F programs."""
    out = {}
    for m in re.finditer(r"^frame (\S+) (\S+): render (\d+) instructions = extraction (\d+) \+ inverse (\d+)"
                         r"(?:.*inverse again on other data (\d+))?.*; 2D DHT alone (\d+)", log(), re.M):
        out[(m[1], m[2])] = {"render": int(m[3]), "extract": int(m[4]), "inverse": int(m[5]),
                            "again": int(m[6]) if m[6] else None, "dht": int(m[7])}
    if not out:
        raise SystemExit("the firmware output has no frame counts")
    return out


def footprints(title):
    """{program: {text, rodata, data, bss, stack, flash, ram}}."""
    keys = ["text", "rodata", "data", "bss", "stack", "flash", "ram"]
    return {r[0]: dict(zip(keys, map(int, r[1:8]))) for r in printed_table(title)}


def m3():
    """The Cortex-M3's counts (fvr-fixed-bench)."""
    text = section("fvr-fixed-bench")
    g = lambda p: int(find(p, text)[1])  # noqa: E731
    view = find(r"^fixed view-q15: (\d+) instructions = set-up (\d+) \+ extraction (\d+) \+ finish (\d+)", text)
    soft = find(r"^fixed view-f32: (\d+) instructions = extraction (\d+) \+ inverse (\d+)", text)
    twiddles = find(r"^fixed twiddles-q15: build (\d+) instructions .*, flash (\d+) ", text)
    return {
        "q15": g(r"^fixed idht-2d-q15: (\d+) "), "q31": g(r"^fixed idht-2d-q31: (\d+) "),
        "f32": g(r"^fixed idht-2d-f32: (\d+) "), "phases": g(r"^fixed phases-q15: (\d+) "),
        "twiddles_build": int(twiddles[1]), "twiddles_flash": int(twiddles[2]),
        "view": int(view[1]), "setup": int(view[2]), "extract": int(view[3]), "finish": int(view[4]),
        "soft": int(soft[1]), "soft_extract": int(soft[2]), "soft_inverse": int(soft[3]),
    }


def preparations():
    """{program: {side, prep, dht, render, [phases], spectrum, beyond, stack, flash}} of the
    device preparations, f16 and Q15, as scripts/firmware.sh prints them."""
    out = {}
    for r in printed_table("device preparation"):
        out[r[0]] = dict(zip(["side", "prep", "dht", "render", "spectrum", "beyond", "stack", "flash"],
                             map(int, r[1:9])))
    for r in printed_table("Q15 device preparation"):
        out[r[0]] = dict(zip(["side", "prep", "dht", "render", "phases", "spectrum", "beyond", "stack", "flash"],
                             map(int, r[1:10])))
    return out


def trig():
    """{core: {view_frame, libm-f64: (phasors, error, sqrt), ...}} of fvr-trig-bench."""
    out = {}
    for core in ["m4f", "m3"]:
        text = section(f"fvr-trig-bench-{core}")
        out[core] = {"view_frame": int(find(r"^trig view-frame: View::frame (\d+) ", text)[1])}
        for m in re.finditer(r"^trig (\S+): shift phasors \(4x(\d+) cos and sin\) (\d+) instructions, "
                             r"max \|error\| ([\d.e-]+) against libm-f64; sqrt (\d+) instructions", text, re.M):
            out[core][m[1]] = (int(m[3]), float(m[4]), int(m[5]))
    return out


def f16_conversion():
    m = find(r"^f16 -> f32: (\d+) of 65536 patterns differ from half \(VCVTB: (\d+)\); per conversion \(x100\): "
             r"half (\d+), rebias (\d+), VCVTB (\d+)")
    return {"differ": int(m[1]), "vcvtb_differ": int(m[2]), "half": int(m[3]) / 100, "rebias": int(m[4]) / 100,
            "vcvtb": int(m[5]) / 100}


SCENE_FRAMES = [
    ("fvr-scene", "plain-kb3", "kb3 plain"),
    ("fvr-scene", "cued-kb3", "kb3 linear cue"),
    ("fvr-scene", "lit-kb3", "kb3 three lights (RGB)"),
    ("fvr-scene", "lit-cued-kb3", "kb3 three lights + linear cue (RGB)"),
    ("fvr-filter-bench", "plain-kb4", "kb4 plain"),
    ("fvr-filter-bench", "plain-kb6", "kb6 plain"),
]


def ms_at_168(instructions):
    ms = instructions / 168e3
    return f"{ms:.1f}" if ms < 10 else f"{ms:.0f}"


def m4f_counts():
    f = frames()
    plain = f[("fvr-scene", "plain-kb3")]
    rows = []
    for program, frame, label in SCENE_FRAMES:
        c = f[(program, frame)]
        ratio = f"{c['render'] / plain['render']:.2f}" if program == "fvr-scene" else "—"
        rows.append([label, thousands(c["render"]), thousands(c["extract"]), thousands(c["inverse"]),
                     thousands(c["dht"]), "1" if frame == "plain-kb3" else ratio, ms_at_168(c["render"])])
    agains = [(c["inverse"], c["again"]) for c in f.values() if c["again"] is not None]
    worst = max(agains, key=lambda p: abs(p[0] - p[1]))
    same = f[("fvr-filter-bench", "plain-kb3")]["render"] == plain["render"]
    return "\n".join([
        table(["64×64 view", "render", "extraction", "inverse", "2D DHT", "× plain", "ms at 168 MHz (1 instr/cycle)"],
              rows),
        "",
        bullet(f"The kb3 view {'meets' if plain['render'] <= 1_500_000 else 'misses'} its goal of ≤ 1.5 M "
               f"instructions: {thousands(plain['render'])}, {ms_at_168(plain['render'])} ms at 168 MHz."),
        bullet(f"kb3 plain is `fvr-scene`'s; kb4 and kb6 are `fvr-filter-bench`'s, whose kb3 "
               f"{'is the same' if same else 'differs'}."),
        bullet("Each plain frame's inverse, timed again on other data, is within 80 instructions of its first "
               f"timing (the widest gap: {thousands(worst[0])} and {thousands(worst[1])}), so the cued and lit "
               "frames' split by timing their inverse again holds."),
    ])


def f16():
    c = f16_conversion()
    saved = c["half"] - c["rebias"]
    hardware = c["vcvtb"] - 2
    rows = [
        ["`half` 2.7 (software on this target)", f"{c['half']:.1f}", "—"],
        ["exponent rebias, `fvr_core::real::f16_bits_to_f32` (used by the core)", f"{c['rebias']:.1f}",
         "yes, all 65,536 patterns, on host and device" if c["differ"] == 0 else f"no: {c['differ']} differ"],
        ["`VCVTB.F32.F16` (FPv4-SP hardware) in `asm!`", f"{c['vcvtb']:.1f}, of which 2 save/restore `s0`",
         "yes, all 65,536" if c["vcvtb_differ"] == 0 else f"no: {c['vcvtb_differ']} differ"],
    ]
    return "\n".join([
        table(["conversion", "instructions", "bit-identical to `half`"], rows),
        "",
        para(f"The core's rebias takes {saved:.1f} fewer instructions per tap than `half`. The hardware "
             f"instruction, at {hardware:.0f} without the save and restore, would save about "
             f"{c['rebias'] - hardware:.0f} more per tap once compiler-emitted."),
    ])


def trig_table():
    t = trig()
    names = [("libm-f64", "`libm`, f64 (the core's)"), ("libm-f32", "`libm`, f32"), ("micromath", "`micromath` 2.1")]
    image = trig_image_db()
    sqrt_err = trig_sqrt_error()
    rows = []
    for key, label in names:
        m4f, m3_ = t["m4f"][key], t["m3"][key]
        rows.append([label, thousands(m4f[0]), str(m4f[2]), thousands(m3_[0]), str(m3_[2]),
                     "0" if m4f[1] == 0 else short_e(m4f[1]), image[key], sqrt_err[key]])
    micro, core = t["m4f"]["micromath"], t["m4f"]["libm-f64"]
    sqrt_pct = 100 * float(sqrt_err["micromath"])
    plain = frames()[("fvr-scene", "plain-kb3")]["render"]
    pt = prepare_tests()
    f16_path = "–".join(sorted({f"{float(pt[p]['image vs f64'][0]):.0f}" for p in ["fvr-prepare", "fvr-prepare-m7"]}))
    exact = agreement()[("fvr-scene", "plain-kb3")][2]
    return "\n".join([
        table(["", "M4F: 4·64 `cos` + `sin`", "M4F: one `sqrt`", "M3: 4·64 `cos` + `sin`", "M3: one `sqrt`",
               "largest phasor error", "shifted image against the core's (kb3, kb4, kb6)",
               "largest `sqrt` relative error"], rows),
        "",
        f"`View::frame` as a whole takes {thousands(t['m4f']['view_frame'])} instructions on the M4F and "
        f"{thousands(t['m3']['view_frame'])} on",
        "the M3. The scene's 64³ views have no sub-pixel shift, so the firmware",
        "evaluates none of these phasors per view; the M3's Q15 twiddles made on the",
        f"device (soft-float `sin`, {thousands(m3()['twiddles_build'])} instructions) are in",
        "[Cortex-M3 transforms](#cortex-m3-transforms).",
        "",
        bullet(f"micromath's square root saves about {core[2] - micro[2]} instructions a call (three a view, "
               f"{100 * 3 * (core[2] - micro[2]) / plain:.2f} % of the kb3 view) but errs by up to "
               f"{sqrt_pct:.1f} %, which would scale the slice axes."),
        bullet(f"For a view with a shift, micromath's phasors take {thousands(micro[0])} instructions on the M4F "
               f"instead of {thousands(core[0])} (`libm`'s f64 `cos` and `sin` in soft float: "
               f"{100 * core[0] / plain:.0f} % of a kb3 view), and the image lands "
               f"{image['micromath'].split(',')[0]} dB from the core's, below the f16 path's {f16_path} dB against "
               f"the f64 pipeline (the device-prepared views) and above kb3's own {exact:.1f} dB against exact line "
               f"integrals. On the M3, in soft float, micromath saves less ({thousands(t['m3']['micromath'][0])} "
               f"against {thousands(t['m3']['libm-f64'][0])}). `libm`'s f32 functions take "
               f"{thousands(t['m4f']['libm-f32'][0])} on the M4F at {image['libm-f32'].split(',')[0]} dB."),
    ])


# ---- What the tests scripts/firmware.sh runs print.

def agreement():
    """{(program, frame): (differing, values, f64 reference dB)} (qemu_agreement)."""
    out = {}
    for m in re.finditer(r"^(\S+) (\S+): (\d+) of (\d+) values differ from the host core; QEMU vs host .+?; "
                         r"QEMU vs its f64 reference ([\d.]+) dB$", log(), re.M):
        out[(m[1], m[2])] = (int(m[3]), int(m[4]), float(m[5]))
    return out


def fixed_tests():
    text = log()
    out = {}
    for m in re.finditer(r"^fvr-fixed-bench-(q15|q31)\.bin: exponent .*?, (\d+) of (\d+) mantissas differ from the "
                         r"host; ([\d.]+) dB against f64 \(floor ([\d.]+) dB, crest factor ([\d.]+)\)$", text, re.M):
        out[m[1]] = {"differ": int(m[2]), "db": m[4], "floor": m[5], "crest": m[6]}
    m = find(r"^fvr-fixed-bench-f32\.bin: (\d+) of (\d+) values differ from the host; ([\d.]+) dB against f64")
    out["f32"] = {"differ": int(m[1]), "db": m[3]}
    m = find(r"^fvr-fixed-bench-view-q15\.bin: .*?, (\d+) of (\d+) pixels differ from the host; ([\d.]+) dB against "
             r"the f64 pipeline \(floor ([\d.]+) dB\), ([\d.]+) dB against exact line integrals$")
    out["view-q15"] = {"differ": int(m[1]), "db": m[3], "floor": m[4], "exact": m[5]}
    m = find(r"^fvr-fixed-bench-view-f32\.bin: (\d+) of (\d+) pixels differ from the host; ([\d.]+) dB against the "
             r"f64 pipeline, ([\d.]+) dB against exact line integrals")
    out["view-f32"] = {"differ": int(m[1]), "db": m[3], "exact": m[4]}
    return out


def prepare_tests():
    """{program: {figure: (dB, floor)}, program + ' bits': (fnv, differing)} (qemu_prepare, qemu_prepare_q15)."""
    out = {}
    for m in re.finditer(r"^(fvr-prepare\S*): (spectrum vs f64|image vs f64|image vs fast host preparation|"
                         r"image vs the f16 spectrum's view) ([\d.]+) dB \(floor ([\d.]+)\)$", log(), re.M):
        out.setdefault(m[1], {})[m[2]] = (m[3], m[4])
    for m in re.finditer(r"^(fvr-prepare\S*): side \d+, spectrum fnv1a (0x[0-9a-f]+), (\d+) of \d+ "
                         r"(?:coefficients|mantissas)(.*)$", log(), re.M):
        rest = [int(x) for x in re.findall(r"(\d+) of \d+", m[4])]
        out.setdefault(m[1], {})["bits"] = (m[2], int(m[3]) + sum(rest))
    for m in re.finditer(r"^(fvr-prepare\S*): (\d+) of \d+ pixels differ from the host core$", log(), re.M):
        fnv, d = out[m[1]]["bits"]
        out[m[1]]["bits"] = (fnv, d + int(m[2]))
    return out


def trig_image_db():
    """{functions: 'kb3, kb4, kb6 dB' or 'bit-identical'} (firmware/trig/tests/trig.rs)."""
    found = {}
    for m in re.finditer(r"^plain-(kb\d) shifted by \([\d.]+, [\d.]+\) (\S+): (.+) against the core image$",
                         log(), re.M):
        found.setdefault(m[2], []).append(m[3])
    out = {}
    for key, values in found.items():
        if all(v == "bit-identical" for v in values):
            out[key] = "bit-identical"
        else:
            out[key] = ", ".join(v.replace(" dB", "") for v in values) + " dB"
    return out


def trig_sqrt_error():
    out = {}
    for m in re.finditer(r"^sqrt (\S+): largest relative error ([\d.e+-]+)$", log(), re.M):
        value = float(m[2])
        out[m[1]] = "0" if value == 0 else short_e(value)
    return out


def short_e(value):
    """1.1e-3, not 1.1e-03."""
    mantissa, exponent = f"{value:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def budget_messages():
    tables = find(r"^FLASH 1 MiB, .*?: (does not fit: .*)$", what="the tables-alone budget failure")[1]
    linker = find(r"^FLASH 1600 KiB, .*?: (section .*)$", what="the linker's budget failure")[1]
    return re.sub(r"FLASH in \S+ holds", "FLASH … holds", tables), linker


# ---- The blocks.

def memory_lengths(layout):
    """(flash, RAM) bytes of a memory layout (memory.x and its siblings)."""
    import os
    from common import ROOT
    with open(os.path.join(ROOT, layout), encoding="utf-8") as f:
        text = re.sub(r"/\*.*?\*/", "", f.read(), flags=re.S)
    out = {}
    for region in ["FLASH", "RAM"]:
        m = re.search(rf"^\s*{region}\s*:\s*ORIGIN\s*=\s*\w+\s*,\s*LENGTH\s*=\s*(\w+?)([KM]?)\s*$", text, re.M)
        out[region] = int(m[1], 0) * {"": 1, "K": 1024, "M": 1024 * 1024}[m[2]]
    return out["FLASH"], out["RAM"]


def footprint_table(title, with_share=None):
    rows = []
    for program, f in footprints(title).items():
        flash, ram = thousands(f["flash"]), thousands(f["ram"])
        if with_share:
            flash += f" ({100 * f['flash'] / with_share[0]:.0f} %)"
            ram += f" ({100 * f['ram'] / with_share[1]:.0f} %)"
        rows.append([f"`{program}`"] + [thousands(f[k]) for k in ["text", "rodata", "data", "bss", "stack"]]
                    + [flash, ram])
    return table(["program", ".text", ".rodata", ".data", ".bss", "peak stack", "flash", "RAM"], rows)


def m4f_footprint():
    return footprint_table("footprint (bytes)", memory_lengths("memory.x"))


def m3_footprint():
    flash, ram = memory_lengths("firmware/memory-m3.x")
    f = footprints("Cortex-M3 footprint")["fvr-fixed-bench"]
    return "\n".join([
        footprint_table("Cortex-M3 footprint"),
        "",
        f"The memory layout `memory-m3.x` holds {flash // 2**20} MiB of flash and {ram // 2**20} MiB of RAM: the",
        f"program uses {100 * f['flash'] / flash:.0f} % of the first and {100 * f['ram'] / ram:.0f} % of the second.",
    ])


def m4f_agreement():
    a = agreement()
    pipeline, channels = scene_pipeline_db(), scene_channels()
    rows = []
    for program, frame, label in [("fvr-scene", "plain-kb3", "kb3 plain"), ("fvr-scene", "cued-kb3", "kb3 linear cue"),
                                  ("fvr-scene", "lit-kb3", "kb3 three lights"),
                                  ("fvr-scene", "lit-cued-kb3", "kb3 three lights + linear cue"),
                                  ("fvr-filter-bench", "plain-kb4", "kb4 plain"),
                                  ("fvr-filter-bench", "plain-kb6", "kb6 plain")]:
        differ, values, ref = a[(program, frame)]
        same = "bit-identical" if differ == 0 else "differs"
        ref = f"{ref:.1f} dB" + (f" (R, G, B: {channels[frame]})" if frame in channels else "")
        rows.append([label, f"{same} ({differ} of {thousands(values)} values differ)", ref,
                     pipeline[frame][0] if frame in pipeline else "—"])
    f64 = ", ".join(pipeline[f][1] for f in ["cued-kb3", "lit-kb3", "lit-cued-kb3"])
    return "\n".join([
        table(["frame", "QEMU vs host core", "QEMU vs f64 reference", "QEMU vs f64 pipeline"], rows),
        "",
        "The f64 pipeline is as far from the closed forms as the firmware is",
        f"({f64} dB for the cued, lit and both frames), so kb3's aliasing sets the figure,",
        "not f16 storage or f32 arithmetic (`cargo test -p fvr-firmware --test scene -- --nocapture`",
        "prints the last column and these).",
    ])


def scene_log():
    from common import cargo_test
    return cargo_test("firmware-scene-test", "scene", "scene_frames_equal_the_host_pipeline_bit_for_bit",
                      "every_frame_matches_its_f64_reference_within_the_readme_floor")


def scene_channels():
    """{frame: 'R, G, B dB'} of the lit frames against their f64 reference."""
    return {m[1]: m[2] for m in re.finditer(r"^fvr-scene (\S+): [\d.]+ dB against its f64 reference "
                                            r"\(per channel: ([\d.]+, [\d.]+, [\d.]+)\)$", scene_log(), re.M)}


def scene_pipeline_db():
    """{frame: 'dB'} of the host's f16 frames against the f64 pipeline
    (`cargo test --test scene`, which prints them)."""
    from common import cargo_test
    out = {}
    text = scene_log()
    for m in re.finditer(r"^(\S+-kb3): firmware \(f16, f32\) vs the f64 pipeline ([\d.]+) dB; "
                         r"f64 pipeline vs its f64 reference ([\d.]+) dB$", text, re.M):
        out[m[1]] = (f"{float(m[2]):.1f} dB", m[3])
    if not out:
        raise SystemExit("cargo test --test scene printed no figure against the f64 pipeline")
    return out


def m3_transforms():
    c, t = m3(), fixed_tests()
    twiddles = "equal to the flash table" if re.search(r"^fixed twiddles-q15: .*; equal tables$", log(), re.M) \
        else "differs from the flash table"
    rows = [
        ["Q15 `idht_2d`", thousands(c["q15"]), f"{t['q15']['db']} ({t['q15']['floor']})"],
        ["Q31 `idht_2d`", thousands(c["q31"]), f"{t['q31']['db']} ({t['q31']['floor']})"],
        ["f32 `idht_2d`, soft float", thousands(c["f32"]), t["f32"]["db"]],
        ["Q15 twiddles made on the device (soft-float `sin`)", thousands(c["twiddles_build"]), twiddles],
        ["Q15 twiddles from flash", thousands(c["twiddles_flash"]), "—"],
    ]
    identical = all(t[k]["differ"] == 0 for k in ["q15", "q31", "f32"])
    return "\n".join([
        table(["64×64 block, Cortex-M3", "instructions", "dB against f64 (floor)"], rows),
        "",
        para(f"Soft-float f32 takes {c['f32'] / c['q15']:.2f} times the instructions of Q15. "
             + ("All three results are bit-identical to the host. " if identical
                else "A result differs from the host. ")
             + f"The block's crest factor κ (the floors' model) is {t['q15']['crest']}."),
    ])


def m3_view():
    c, t = m3(), fixed_tests()
    rows = [
        ["integer (Q15 spectrum, Q15 weights, `i32`/`i64` sums, Q15 inverse)", thousands(c["view"]),
         f"{t['view-q15']['db']} ({t['view-q15']['floor']})", t["view-q15"]["exact"]],
        ["— set-up (soft float)", thousands(c["setup"]), "", ""],
        ["— extraction", thousands(c["extract"]), "", ""],
        ["— finish (to Q15, `idht_2d`, crop)", thousands(c["finish"]), "", ""],
        ["f32, soft float (f16 spectrum)", thousands(c["soft"]), t["view-f32"]["db"], t["view-f32"]["exact"]],
        ["— extraction (with the camera frame)", thousands(c["soft_extract"]), "", ""],
        ["— inverse", thousands(c["soft_inverse"]), "", ""],
        ["Q15 phase table from the f32 kernel (once per filter, soft float)", thousands(c["phases"]), "", ""],
    ]
    pipeline = fixed_view_exact_db()
    return "\n".join([
        table(["plain kb3 64×64 view, Cortex-M3", "instructions", "dB against the f64 pipeline (floor)",
               "dB against exact line integrals"], rows),
        "",
        para(f"The integer view takes {c['soft'] / c['view']:.2f} times fewer instructions than soft-float f32. "
             "Against exact line integrals both sit at kb3's own limit at oversampling 1 (the f64 pipeline: "
             f"{pipeline} dB): the integer arithmetic costs {float(pipeline) - float(t['view-q15']['exact']):.1f} "
             "dB there (`cargo test -p fvr-firmware --test fixed_view -- --nocapture` prints the f64 "
             "pipeline's)."),
    ])


def fixed_view_exact_db():
    from common import cargo_test
    text = cargo_test("firmware-fixed-view-test", "fixed_view")
    return find(r"f64 pipeline against exact: ([\d.]+) dB", text, what="the f64 pipeline's dB against exact")[1]


def prepared_ram(p):
    return p["spectrum"] + p["beyond"]


def targets():
    f, c, t, fp = frames(), m3(), fixed_tests(), footprints("footprint (bytes)")
    m3fp = footprints("Cortex-M3 footprint")["fvr-fixed-bench"]
    prep, pt = preparations(), prepare_tests()
    scene, plain = fp["fvr-scene"], f[("fvr-scene", "plain-kb3")]
    exact = agreement()[("fvr-scene", "plain-kb3")][2]
    rows = [
        ["M4F (`mps2-an386`)", "f32, hard float", "64³ f16 in flash", thousands(plain["render"]),
         thousands(plain["dht"]), thousands(scene["flash"]), thousands(scene["ram"]), thousands(scene["stack"]),
         f"— / {exact:.1f}"],
        ["M3 (`mps2-an385`)", "f32, soft float", "64³ f16 in flash", thousands(c["soft"]), thousands(c["f32"]),
         thousands(m3fp["flash"]), thousands(m3fp["ram"]), thousands(m3fp["stack"]),
         f"{t['view-f32']['db']} / {t['view-f32']['exact']}"],
        ["M3 (`mps2-an385`)", "integer Q15 (`i32`/`i64` sums)", "64³ Q15, an exponent per x-line, in flash",
         thousands(c["view"]), thousands(c["q15"]), thousands(m3fp["flash"]), thousands(m3fp["ram"]),
         thousands(m3fp["stack"]), f"{t['view-q15']['db']} / {t['view-q15']['exact']}"],
    ]
    for program, target, arith, spectrum in [
        ("fvr-prepare-m7", "M7 (`mps2-an500`)", "f32, hard float", "64³ f16 prepared on the device"),
        ("fvr-prepare", "M4F (`mps2-an386`)", "f32, hard float", "32³ f16 prepared on the device (32² view)"),
        ("fvr-prepare-q15-m7", "M7 (`mps2-an500`)", "integer Q15", "64³ Q15 prepared on the device"),
        ("fvr-prepare-q15-m3", "M3 (`mps2-an385`)", "integer Q15", "64³ Q15 prepared on the device"),
        ("fvr-prepare-q15", "M4F (`mps2-an386`)", "integer Q15", "32³ Q15 prepared on the device (32² view)"),
    ]:
        p = prep[program]
        rows.append([target, arith, spectrum, thousands(p["render"]),
                     f"{thousands(p['prep'])} (3D DHT {thousands(p['dht'])})", thousands(p["flash"]),
                     f"{thousands(prepared_ram(p))} ({thousands(p['beyond'])} beyond the spectrum)",
                     thousands(p["stack"]), f"{pt[program]['image vs f64'][0]} / —"])
    return table(["target (QEMU machine)", "arithmetic", "spectrum", "instructions per view",
                  "instructions for the transform", "flash", "RAM", "of which stack",
                  "dB against f64 pipeline / exact"], rows)


DEVICE = [("fvr-prepare", "M4F, 32³ f16"), ("fvr-prepare-m7", "M7, 64³ f16"), ("fvr-prepare-q15", "M4F, 32³ Q15"),
          ("fvr-prepare-q15-m7", "M7, 64³ Q15"), ("fvr-prepare-q15-m3", "M3, 64³ Q15")]


def device_prep():
    prep, pt = preparations(), prepare_tests()
    goal = 40

    def cell(program, figure, extra=""):
        db, floor = pt[program][figure]
        return f"{db} dB ({floor}{extra})"

    rows = {k: [] for k in ["cube", "prep", "dht", "view", "beyond", "stack", "flash", "bits", "spectrum", "image",
                            "f16"]}
    for program, _ in DEVICE:
        p, q15 = prep[program], "q15" in program
        side = p["side"]
        rows["cube"].append(thousands(p["spectrum"]))
        rows["prep"].append(thousands(p["prep"]))
        rows["dht"].append(thousands(p["dht"]))
        rows["view"].append(f"{thousands(p['render'])} ({side}²{', integer' if q15 else ''})")
        rows["beyond"].append(thousands(p["beyond"]))
        rows["stack"].append(thousands(p["stack"]))
        rows["flash"].append(thousands(p["flash"]))
        fnv, differ = pt[program]["bits"]
        same = "bit-identical" if differ == 0 else f"{differ} values differ"
        if program == "fvr-prepare-q15-m3" and fnv == pt["fvr-prepare-q15-m7"]["bits"][0]:
            same += ", equal to the M7's"
        rows["bits"].append(same)
        rows["spectrum"].append(cell(program, "spectrum vs f64"))
        rows["image"].append(cell(program, "image vs f64", f"; goal {goal}" if q15 else ""))
        against = "image vs the f16 spectrum's view" if q15 else "image vs fast host preparation"
        rows["f16"].append(cell(program, against))
    labels = [("cube", "cube (bytes)"), ("prep", "preparation (instructions)"), ("dht", "of which 3D DHT"),
              ("view", "view (instructions)"), ("beyond", "RAM beyond the spectrum (bytes)"),
              ("stack", "of which stack"), ("flash", "flash"), ("bits", "spectrum and image against the host core"),
              ("spectrum", "spectrum against the f64 preparation (floor)"),
              ("image", "image against the f64 pipeline (floor)"),
              ("f16", "image against the host-prepared f16 spectrum's (floor)")]
    body = table([""] + [label for _, label in DEVICE], [[label] + rows[key] for key, label in labels])
    f16_32, f16_64 = prep["fvr-prepare"], prep["fvr-prepare-m7"]
    q_32, q_m7 = prep["fvr-prepare-q15"], prep["fvr-prepare-q15-m7"]
    rest = lambda p: p["prep"] - p["dht"]  # noqa: E731
    q15_64 = max(prep[p]["beyond"] for p in ["fvr-prepare-q15-m7", "fvr-prepare-q15-m3"])
    return "\n".join([
        body,
        "",
        bullet(f"Besides the 3D DHT, the f16 preparation takes {rest(f16_32) / 1e6:.1f} M instructions at 32³ "
               f"and {rest(f16_64) / 1e6:.1f} M at 64³ (the premultiplier table and the two passes over the "
               f"volume); the Q15 preparation {thousands(rest(q_32))} at 32³ on the M4F and "
               f"{thousands(rest(q_m7))} at 64³ on the M7 (about {rest(q_m7) / 64 ** 3:.0f} per voxel)."),
        bullet(f"Against the f16 path the Q15 preparation takes {q_m7['prep'] / f16_64['prep']:.2f} (M7, 64³) and "
               f"{q_32['prep'] / f16_32['prep']:.2f} (M4F, 32³) times the instructions, and its 3D DHT "
               f"{q_m7['dht'] / f16_64['dht']:.2f} and {q_32['dht'] / f16_32['dht']:.2f} times."),
        bullet(f"RAM beyond the spectrum at 64³: {thousands(f16_64['beyond'])} bytes in f16 on the M7, "
               f"{thousands(f16_64['beyond'] - f16_64['stack'])} of `.bss` and a {thousands(f16_64['stack'])}-byte "
               f"stack ({f16_64['beyond'] / 1024:.1f} KiB); at most {thousands(q15_64)} bytes in Q15, "
               f"{thousands(q_m7['beyond'] - q_m7['stack'])} of `.bss` and a {thousands(q_m7['stack'])}-byte "
               f"stack: {'within' if q15_64 <= 65536 else 'beyond'} the 64 KiB (65,536) target."),
    ])


def budget():
    tables, linker = budget_messages()
    return "\n".join(para(line).replace("\n", "\n  ") for line in [
        f"- tables alone too big (FLASH = 1 MiB), from `build.rs`: \"… {tables}\";",
        f"- tables plus code too big (FLASH = 1600 KiB), from the linker: \"{linker}\".",
    ])


def run_time():
    """How long the run of scripts/firmware.sh that made these figures took."""
    import os
    from common import Unavailable, run_seconds
    if os.environ.get("DOCS_FIGURES_FIRMWARE_LOG"):
        raise Unavailable("the firmware output was given (DOCS_FIGURES_FIRMWARE_LOG), not timed here")
    log()
    took = run_seconds("firmware")
    if took is None:
        raise Unavailable("this run of scripts/firmware.sh was not timed (a cache without its time)")
    wall, user, load = took
    span_ = f"{int(wall // 60)} min {wall % 60:.0f} s" if wall >= 60 else f"{wall:.0f} s"
    return para(f"The run that made these figures took {span_} of wall time and {user:.0f} s of user CPU on a "
                f"{os.cpu_count()}-core machine at load average {load:.1f}, compiling only what was out of date.")


GENERATORS = {
    "firmware-targets": targets, "firmware-device-prep": device_prep, "firmware-trig": trig_table,
    "firmware-m4f-agreement": m4f_agreement, "firmware-m4f-counts": m4f_counts, "firmware-f16": f16,
    "firmware-m4f-footprint": m4f_footprint, "firmware-m3-transforms": m3_transforms, "firmware-m3-view": m3_view,
    "firmware-m3-footprint": m3_footprint, "firmware-budget": budget, "firmware-run-time": run_time,
}


def q15_lines():
    """One exponent for the cube against one per x-line (a core unit test)."""
    from common import cached
    text = cached("core-per-line-exponents", ["cargo", "test", "--locked", "-p", "fvr-core", "--lib",
                                              "per_line_exponents_keep_more", "--", "--nocapture"])
    balls = re.findall(r"ball (\d+)³: one exponent ([\d.]+) dB, per x-line ([\d.]+) dB", text)
    if not balls:
        raise SystemExit("the core's test printed no ball")
    said = "; ".join(f"at {n}³ {one} dB with one exponent for the whole cube and {lines} dB with one per x-line"
                     for n, one, lines in balls)
    return para(f"On a ball, {said} (`dht::fixed::dht_3d` against `dht_3d_lines`; `cargo test -p fvr-core --lib "
                "per_line_exponents_keep_more -- --nocapture`).")


GENERATORS["firmware-q15-lines"] = q15_lines


if __name__ == "__main__":
    serve(GENERATORS)
