#!/usr/bin/env python3
"""The engine of scripts/docs-figures.sh: finds the figure blocks in the
Markdown files, runs their generators, and rewrites or checks the blocks.

A block is the lines between `<!-- figures:NAME -->` and
`<!-- /figures:NAME -->` (each marker on a line of its own, the closing one
at any indentation); the generator's standard output replaces them,
indented as the opening marker. Usage: see scripts/docs-figures.sh.
"""

import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)

from registry import GENERATORS, UNAVAILABLE  # noqa: E402

OPEN = re.compile(r"^(?P<indent>[ \t]*)<!-- figures:(?P<name>[A-Za-z0-9_.-]+) -->[ \t]*$")
CLOSE = re.compile(r"^[ \t]*<!-- /figures:(?P<name>[A-Za-z0-9_.-]+) -->[ \t]*$")


class Problem(Exception):
    pass


def markdown_files():
    """Every Markdown file git knows, but the changelog (history, not results)."""
    try:
        out = subprocess.run(
            ["git", "ls-files", "--cached", "--others", "--exclude-standard", "*.md"],
            cwd=ROOT, check=True, capture_output=True, text=True,
        ).stdout
        files = sorted(set(out.split("\n")) - {""})
    except (OSError, subprocess.CalledProcessError):
        files = []
        for d, dirs, names in os.walk(ROOT):
            dirs[:] = sorted(x for x in dirs if x not in {".git", "target", "node_modules"})
            files += [os.path.relpath(os.path.join(d, n), ROOT) for n in names if n.endswith(".md")]
    return [f for f in files if f != "CHANGELOG.md" and os.path.isfile(os.path.join(ROOT, f))]


def blocks_of(path, lines):
    """[(name, first line of the block's body, index of its closing marker, indent)]."""
    found, current = [], None
    for i, line in enumerate(lines):
        m = OPEN.match(line)
        if m:
            if current:
                raise Problem(f"{path}:{i + 1}: block `{m['name']}` opens inside block `{current[0]}`")
            current = (m["name"], i + 1, m["indent"])
            continue
        m = CLOSE.match(line)
        if m:
            if not current or m["name"] != current[0]:
                raise Problem(f"{path}:{i + 1}: `/figures:{m['name']}` closes no open block of that name")
            found.append((current[0], current[1], i, current[2]))
            current = None
    if current:
        raise Problem(f"{path}: block `{current[0]}` is never closed")
    return found


def read_text(path):
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        return f.read()


def text_lines(data):
    return data.decode("utf-8", "replace").split("\n") if data is not None else []


def indented(output, indent):
    lines = output.rstrip("\n").split("\n") if output.strip() else []
    return [(indent + line) if line.strip() else "" for line in lines]


def ensure_fvr(env):
    if env.get("FVR"):
        env["FVR"] = os.path.abspath(env["FVR"])
        if not os.access(env["FVR"], os.X_OK):
            raise Problem(f"FVR={env['FVR']} is not an executable file")
        return
    target = env.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
    print("docs-figures: cargo build --locked --release -p fvr-host", file=sys.stderr)
    subprocess.run(["cargo", "build", "--locked", "--release", "-p", "fvr-host"], cwd=ROOT, check=True,
                   stdout=sys.stderr)
    env["FVR"] = os.path.join(target, "release", "fvr")


def run_generator(gen, env, out_dir):
    """(output, None) or (None, why it could not run). A generator of files
    writes them under out_dir; its output is then {path: bytes}."""
    print(f"docs-figures: {gen.name} ...", file=sys.stderr, flush=True)
    env = dict(env, DOCS_FIGURES_OUT=out_dir)
    proc = subprocess.run([sys.executable, os.path.join(HERE, gen.script), gen.name], cwd=ROOT, env=env,
                          stdout=subprocess.PIPE, text=True)
    if proc.returncode == UNAVAILABLE:
        return None, proc.stdout.strip() or "unavailable"
    if proc.returncode != 0:
        raise Problem(f"generator `{gen.name}` ({gen.script}) failed with status {proc.returncode}")
    if not gen.writes:
        return proc.stdout, None
    files = {}
    for path in gen.writes:
        made = os.path.join(out_dir, path)
        if not os.path.isfile(made):
            raise Problem(f"generator `{gen.name}` did not write {path}")
        with open(made, "rb") as f:
            files[path] = f.read()
    return files, None


def replace_file(path, data):
    """Writes bytes over a repository file through a temporary file beside
    it, renamed over it when whole (the mode kept)."""
    full = os.path.join(ROOT, path)
    os.makedirs(os.path.dirname(full), exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".docs-figures-", suffix=".tmp", dir=os.path.dirname(full))
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        if os.path.exists(full):
            shutil.copymode(full, tmp)
        os.replace(tmp, full)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def list_generators(uses):
    print("| name | checked | cost | needs | blocks |")
    print("|---|---|---|---|---|")
    for g in GENERATORS:
        where = ", ".join(uses.get(g.name, [])) or "(none)"
        print(f"| {g.name} | {'yes' if g.checked else 'no (times)'} | {g.cost} | "
              f"{', '.join(g.needs) or '—'} | {where} |")


def main():
    ap = argparse.ArgumentParser(prog="scripts/docs-figures.sh", description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="compare the deterministic blocks, change nothing")
    ap.add_argument("--quick", action="store_true", help="only the quick deterministic generators")
    ap.add_argument("--all", action="store_true", help="the manual generators too")
    ap.add_argument("--list", action="store_true", help="list the generators and where their blocks are")
    ap.add_argument("names", nargs="*", metavar="NAME")
    args = ap.parse_args()

    by_name = {g.name: g for g in GENERATORS}
    md_files = markdown_files()
    uses = {}
    for path in md_files:
        for name, *_ in blocks_of(path, read_text(path).split("\n")):
            if name not in by_name:
                raise Problem(f"{path}: block `{name}` has no generator in scripts/docs-figures/registry.py")
            uses.setdefault(name, []).append(path)
    if args.list:
        list_generators(uses)
        return 0

    for name in args.names:
        if name not in by_name:
            raise Problem(f"no generator `{name}` (scripts/docs-figures.sh --list names them)")
        if args.check and not by_name[name].checked:
            raise Problem(f"`{name}` measures times: it is regenerated, never checked")
    if args.names:
        selected = [by_name[n] for n in dict.fromkeys(args.names)]
    else:
        selected = [g for g in GENERATORS
                    if (args.all or g.cost != "manual")
                    and (not args.quick or g.cost == "quick")
                    and (g.checked or not (args.check or args.quick))]
    for g in GENERATORS:
        if g.writes:
            uses[g.name] = list(g.writes)
    unused = [g.name for g in selected if g.name not in uses]
    if unused:
        raise Problem(f"no block uses {', '.join(unused)}")

    env = dict(os.environ)
    if any("fvr" in g.needs for g in selected):
        ensure_fvr(env)
    own_cache = "DOCS_FIGURES_CACHE" not in env
    if own_cache:
        env["DOCS_FIGURES_CACHE"] = tempfile.mkdtemp(prefix="docs-figures-")
    out_dir = tempfile.mkdtemp(prefix="docs-figures-out-")
    differ, changed, files = [], [], set()
    try:
        outputs, skipped, ran = {}, {}, 0
        for gen in selected:
            out, why = run_generator(gen, env, os.path.join(out_dir, gen.name))
            if out is None:
                skipped[gen.name] = why
                print(f"docs-figures: skipped {gen.name}: {why}", file=sys.stderr)
            elif gen.writes:
                ran += 1
                # Written at once, so that the blocks made from these files
                # (later in the registry) read the new ones.
                for path, data in sorted(out.items()):
                    full = os.path.join(ROOT, path)
                    old = open(full, "rb").read() if os.path.exists(full) else None
                    if old == data:
                        continue
                    if args.check:
                        binary = path.endswith((".png", ".apng"))
                        differ.append((path, gen.name, [] if binary else text_lines(old),
                                       ["(the file differs)"] if binary else text_lines(data)))
                    else:
                        replace_file(path, data)
                        changed.append(path)
                    files.add(path)
            else:
                ran += 1
                outputs[gen.name] = out
    finally:
        shutil.rmtree(out_dir, ignore_errors=True)
        if own_cache:
            shutil.rmtree(env["DOCS_FIGURES_CACHE"], ignore_errors=True)

    for path in md_files:
        # Read again: a generator of files may have rewritten it.
        lines = read_text(path).split("\n")
        new = list(lines)
        # From the last block up, so that earlier indices stay valid.
        for name, body, close, indent in reversed(blocks_of(path, lines)):
            if name not in outputs:
                continue
            fresh = indented(outputs[name], indent)
            old = [line.rstrip() for line in lines[body:close]]
            if old != fresh:
                differ.append((path, name, old, fresh))
                new[body:close] = fresh
        if not args.check and new != lines:
            replace_file(path, "\n".join(new).encode("utf-8"))
            changed.append(path)

    if args.check:
        for path, name, old, fresh in differ:
            what = "the file" if path in files else f"block `{name}`"
            print(f"docs-figures: {path}: {what} differs from its generator's output "
                  f"(bash scripts/docs-figures.sh {name} rewrites it):", file=sys.stderr)
            for line in list(difflib.unified_diff(old, fresh, "doc", "run", n=0, lineterm=""))[2:40]:
                print("    " + line, file=sys.stderr)
        for name, why in skipped.items():
            print(f"docs-figures: {name} could not run: {why}", file=sys.stderr)
        if differ or skipped:
            return 1
        print(f"docs-figures: {ran} generators, every block and file as the program prints it", file=sys.stderr)
        return 0
    for path in changed:
        print(f"docs-figures: rewrote {path}", file=sys.stderr)
    print(f"docs-figures: {ran} generators run, {len(set(changed))} files changed"
          + (f", {len(skipped)} skipped ({', '.join(skipped)})" if skipped else ""), file=sys.stderr)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Problem as e:
        print(f"docs-figures: error: {e}", file=sys.stderr)
        sys.exit(2)
