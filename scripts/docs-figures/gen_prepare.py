#!/usr/bin/env python3
"""docs/firmware.md, "Your own volume on your own part": what
`fvr prepare --for PART` budgets, from its own notes and refusals."""

import re
import tempfile

from common import fvr_bin, run_both, serve, table, thousands

PARTS = ["m4f", "m3", "m7"]
LAYOUT = {"m4f": "memory.x", "m3": "firmware/memory-m3.x", "m7": "firmware/memory-m7.x"}


def prepare(*args):
    with tempfile.TemporaryDirectory() as tmp:
        status, out = run_both([fvr_bin(), "prepare", "brainsmall", *args], cwd=tmp)
        header = None
        if status == 0 and "--emit" in args and args[args.index("--emit") + 1] == "c":
            name = args[args.index("--out") + 1]
            with open(f"{tmp}/{name}.h", encoding="utf-8") as f:
                header = f.read()
    return status, out, header


def parts():
    rows, full = [], {}
    for part in PARTS:
        for precision in ["f16", "f32"]:
            status, out, header = prepare("--for", part, "--precision", precision, "--filter", "kb3",
                                          "--emit", "c", "--out", "bs")
            if status != 0:
                raise SystemExit(out)
            wrote = re.search(r"f\d+ cube spectrum n = (\d+) of (\d+) x (\d+) x (\d+),", out)
            needs = re.search(r"needs (\d+) bytes of flash of (\d+) and (\d+) of RAM of (\d+)", out)
            image = re.search(r"#define BS_LEN (\d+)u", header)[1]
            halved = re.search(r"needs [\d.]+ \w+ of flash \((\d+)\)", out)
            if halved and precision == "f16":
                full[part] = int(halved[1])
            n, dims = wrote[1], " × ".join(wrote.group(2, 3, 4))
            flash_kib, ram_kib = int(needs[2]) // 1024, int(needs[4]) // 1024
            rows.append([f"{part} ({flash_kib} KiB / {ram_kib} KiB)", precision, f"{n}³ ({dims})",
                         thousands(image), thousands(needs[1]), thousands(needs[3])])
    status, out, _ = prepare("--for", "m4f", "--filter", "kb3", "--resample", "64", "--emit", "bin",
                             "--out", "bs.bin")
    ram = re.search(r"needs [\d.]+ \w+ of RAM \((\d+)\), the part has [\d.]+ \w+ \((\d+)\)", out)
    if status != 2 or not ram:
        raise SystemExit(f"fvr prepare --emit bin of a 64³ brainsmall for the m4f was not refused:\n{out}")
    sizes = sorted(set(full.values()))
    text = [
        table(["part (flash / RAM)", "precision", "cube (brainsmall resampled to)", "image bytes",
               "flash needed", "RAM needed"], rows, ["---", "---", "---", "---:", "---:", "---:"]),
        "",
    ]
    if len(sizes) == 1 and len(full) == len(PARTS):
        text += [f"At 128³ brainsmall needs {thousands(sizes[0])} bytes of flash in f16 (the f16 cube",
                 "alone is 4 MiB), more than any of these parts has, so every part gets a",
                 "smaller cube; a part with more flash, or `--for host`, keeps 128³."]
    text += [f"On the M4F an f16 64³ image loaded into RAM (`--emit bin`) is refused: it needs",
             f"{thousands(ram[1])} bytes of RAM of {thousands(ram[2])} (`fvr prepare brainsmall --for m4f "
             "--filter kb3",
             "--resample 64 --emit bin --out bs.bin`)."]
    return "\n".join(text)


def budget():
    """The step that prepares: the halving note and the one-line refusal."""
    status, out, _ = prepare("--for", "m4f", "--filter", "kb3", "--emit", "c", "--out", "bs")
    m = re.search(r"at (\d+) x (\d+) x (\d+) does not fit .*resampled to (\d+) x (\d+) x (\d+) ", out)
    if status != 0 or not m:
        raise SystemExit(out)
    status, out, _ = prepare("--for", "m4f", "--resample", "128", "--emit", "c", "--out", "big")
    line = next((x for x in out.split("\n") if x.startswith("fvr: error:")), None)
    if status != 2 or not line:
        raise SystemExit(f"fvr prepare brainsmall --for m4f --resample 128 was not refused:\n{out}")
    return "\n".join([
        "This writes `bs.c` (a 64-byte-aligned `const uint8_t bs[BS_LEN]`) and",
        "`bs.h` (`BS_LEN`, `BS_CRC32`): a `.fvrs` image ([fvrs.md](fvrs.md)) of the",
        "f16 spectrum, the kernel table and the twiddles. `--for m4f|m3|m7|host`",
        "budgets it against the part's flash and RAM (the table below) **before**",
        "anything is prepared or written; a volume too large is halved until it",
        f"fits, said on stderr (brainsmall's {' × '.join(m.group(1, 2, 3))} becomes "
        f"{' × '.join(m.group(4, 5, 6))}",
        "on the M4F), or, with `--resample N`, refused in one line with the",
        "numbers (`fvr prepare brainsmall --for m4f --resample 128 --emit c --out big`):",
        "",
        "```text",
        line,
        "```",
    ])


GENERATORS = {"prepare-parts": parts, "prepare-budget": budget}


def capi():
    """The C API in QEMU, from `bash scripts/capi.sh` (or DOCS_FIGURES_CAPI_LOG)."""
    from common import log_or_run
    text = log_or_run("DOCS_FIGURES_CAPI_LOG", "capi", ["bash", "scripts/capi.sh"])
    counts = re.search(r"^c-example: instructions \(exact to \+-40\): open (\d+) render (\d+)", text, re.M)
    rust = re.search(r"^Rust firmware, beside it: fvr-scene plain-kb3 render (\d+)", text, re.M)
    size = re.search(r"^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+[0-9a-f]+\s+\S*c-example\.elf$", text, re.M)
    if not (counts and rust and size):
        raise SystemExit("scripts/capi.sh printed no counts, Rust count or size of c-example.elf")
    status, out, header = prepare("--for", "m4f", "--filter", "kb3", "--emit", "c", "--out", "bs")
    image = int(re.search(r"#define BS_LEN (\d+)u", header)[1])
    opened, rendered, rust_view = int(counts[1]), int(counts[2]), int(rust[1])
    flash, bss = int(size[1]) + int(size[2]), int(size[3])
    return "\n".join([
        "Measured with `bash scripts/capi.sh`:",
        "",
        table(["", "instructions (exact to ±40)"], [
            [f"`fvr_source_open` (CRC-32 and value scan of {thousands(image)} bytes, once)", thousands(opened)],
            ["`fvr_render`, 64 × 64 kb3 f16 view", thousands(rendered)],
            ["Rust `fvr-scene` plain-kb3, same size, filter and precision", thousands(rust_view)],
        ], ["---", "---:"]),
        "",
        f"The C API's view costs about {round((rendered - rust_view) / 1000)} k instructions more than the Rust",
        "firmware's. The Rust program fixes the cube side at compile time",
        "(`Spectrum::with_side`, which drops the bounds tests of the tap reads) and keeps its kernel",
        "table in flash; the C API reads the side from the image and copies the",
        "kernel table out of it per view. The rest is not yet attributed (the",
        "counts also move with how the code falls into codegen units).",
        f"Footprint (`arm-none-eabi-size`): {thousands(flash)} bytes of flash (the image",
        f"{thousands(image)}, the program {thousands(flash - image)} with every filter and both precisions),",
        f"{thousands(bss)} bytes of `.bss`.",
    ])


GENERATORS["capi"] = capi


if __name__ == "__main__":
    serve(GENERATORS)
