"""What the generators share: the fvr binary, commands run once per
docs-figures run (their output cached), and Markdown formatting.

A generator module maps block names to functions returning the block's
Markdown; `serve(GENERATORS)` runs the one named on the command line.
"""

import json
import os
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
UNAVAILABLE = 3


class Unavailable(Exception):
    """The block cannot be made here (a data set or a tool is missing)."""


def fvr_bin():
    path = os.environ.get("FVR") or os.path.join(
        os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target"), "release", "fvr")
    path = os.path.join(ROOT, path)  # relative to the repository, as main.py runs it
    if not os.access(path, os.X_OK):
        raise Unavailable(f"no fvr binary at {path} (set FVR)")
    return path


def run(argv, env=None, stdin=None, cwd=ROOT):
    """Runs a command (in the repository root); its stdout, stderr passed through."""
    full = dict(os.environ, **(env or {}))
    proc = subprocess.run(argv, cwd=cwd, env=full, stdout=subprocess.PIPE, text=True, input=stdin)
    if proc.returncode != 0:
        sys.exit(f"`{' '.join(argv)}` failed with status {proc.returncode}")
    return proc.stdout


def fvr(*args, cwd=ROOT):
    return run([fvr_bin(), *args], cwd=cwd)


def fvr_json(*args):
    """The --stats-json object of an fvr command (its one line of stdout)."""
    out = fvr(*args, "--stats-json", "--quiet")
    return json.loads(out.strip().split("\n")[-1])


def cached(key, argv, env=None):
    """stdout + stderr of a command, run once per docs-figures run (the
    cache directory is DOCS_FIGURES_CACHE) and kept for the other blocks."""
    cache = os.environ.get("DOCS_FIGURES_CACHE")
    path = os.path.join(cache, key + ".log") if cache else None
    if path and os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            return f.read()
    print(f"docs-figures: running {' '.join(argv)}", file=sys.stderr, flush=True)
    import resource
    import time
    load, start, cpu = os.getloadavg()[0], time.monotonic(), resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    proc = subprocess.run(argv, cwd=ROOT, env=dict(os.environ, **(env or {})), stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    took = (time.monotonic() - start, resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - cpu, load)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-4000:])
        sys.exit(f"`{' '.join(argv)}` failed with status {proc.returncode}")
    if path:
        for name, text in [(path, proc.stdout), (path[:-4] + ".time", json.dumps(took))]:
            with open(name + ".tmp", "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(name + ".tmp", name)
    return proc.stdout


def run_seconds(key):
    """(wall s, user CPU s, load average at the start) of a command cached() ran, or None."""
    cache = os.environ.get("DOCS_FIGURES_CACHE")
    path = os.path.join(cache, key + ".time") if cache else None
    if not path or not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as f:
        return tuple(json.load(f))


def log_or_run(env_name, key, argv):
    """The output of a script that scripts/test-all.sh runs anyway: the file
    named by `env_name` when set, else a run of `argv` (cached)."""
    given = os.environ.get(env_name)
    if given:
        with open(given, encoding="utf-8", errors="replace") as f:
            return f.read()
    return cached(key, argv)


def cargo_test(key, test, *filters, release=False, ignored=False, env=None):
    """The output of one test target with --nocapture, built as the
    workspace's own test build is (`--workspace`: the same features, so
    scripts/test-all.sh's build is reused, not redone)."""
    argv = ["cargo", "test", "--locked", "--workspace"] + (["--release"] if release else [])
    argv += ["--test", test, "--", "--nocapture", "--test-threads", "1"] + (["--ignored"] if ignored else [])
    out = cached(key, argv + list(filters), env)
    # With --nocapture a test's first line follows `test NAME ... ` on its line.
    return re.sub(r"^(test \S+ \.\.\. )(?!ok$|FAILED$|ignored)", r"\1\n", out, flags=re.M)


def need_env(name, what):
    path = os.environ.get(name)
    if not path or not os.path.exists(path):
        raise Unavailable(f"{what} needs {name} (see scripts/fetch-{'ct' if 'CT' in name else 'mri'}-head.sh)")
    return path


def table(header, rows, align=None):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join(align or ["---"] * len(header)) + "|"]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def thousands(n):
    return f"{int(n):,}"


def span(values, digits=1, sep="–"):
    """`lo–hi` of values rounded to `digits`, or one value when they agree."""
    lo, hi = f"{min(values):.{digits}f}", f"{max(values):.{digits}f}"
    return lo if lo == hi else f"{lo}{sep}{hi}"


def serve(generators):
    name = sys.argv[1] if len(sys.argv) > 1 else ""
    if name not in generators:
        sys.exit(f"{sys.argv[0]}: no block `{name}` here (known: {', '.join(generators)})")
    try:
        text = generators[name]()
    except Unavailable as e:
        print(e)
        sys.exit(UNAVAILABLE)
    sys.stdout.write(text.rstrip("\n") + "\n")


def png_samples(path):
    """(width, height, channels, samples) of a non-interlaced 8-bit grey or
    RGB PNG (what `fvr render` writes), the samples row by row."""
    import struct
    import zlib

    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3}.get(colour)
    if depth != 8 or channels is None or interlace:
        sys.exit(f"{path}: only 8-bit grey or RGB PNGs, not interlaced")
    raw, stride = zlib.decompress(idat), width * channels
    out, prev = bytearray(), bytearray(stride)
    for row in range(height):
        kind, line = raw[row * (stride + 1)], bytearray(raw[row * (stride + 1) + 1:(row + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        prev = line
    return width, height, channels, bytes(out)


def run_both(argv, cwd=ROOT):
    """(status, stdout + stderr) of a command that may fail on purpose."""
    proc = subprocess.run(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return proc.returncode, proc.stdout


def para(text, width=76, indent=""):
    """A paragraph of Markdown wrapped as the docs are (code spans kept whole)."""
    import textwrap

    return textwrap.fill(" ".join(text.split()), width=width, initial_indent=indent, subsequent_indent=indent,
                         break_long_words=False, break_on_hyphens=False)


def bullet(text):
    """A list item of Markdown, wrapped, its continuation lines indented."""
    return para("- " + text).replace("\n", "\n  ")
