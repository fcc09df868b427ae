#!/usr/bin/env bash
# The Python package's tests (python/tests): a venv in target/py-venv with
# pinned maturin, numpy, pytest and dask.distributed (test_dask.py) from
# PyPI, the extension built into it by
# `maturin develop --release` in the workspace's target dir, then pytest
# against the `fvr` binary ($FVR_BIN, or a release build).
# Usage: bash scripts/test-python.sh      (run by scripts/test-all.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

venv=target/py-venv
if [[ ! -x "$venv/bin/python" ]]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    maturin==1.16.0 numpy==2.4.6 pytest==9.2.0 dask==2026.8.0 distributed==2026.8.0

# maturin builds in the workspace's target/ (python/ is a workspace member);
# its output is shown only when it fails.
log="$PWD/target/py-build.log"
if ! (cd python && VIRTUAL_ENV="$PWD/../$venv" PATH="$PWD/../$venv/bin:$PATH" \
    maturin develop --release --locked > "$log" 2>&1); then
    cat "$log"
    exit 1
fi
"$venv/bin/python" -c "import fvr, sys; sys.exit(0 if fvr.Renderer else 1)"

# The CLI the bit-for-bit tests compare with: $FVR_BIN when given
# (test-all.sh passes the one `cargo test --workspace` just built, in the
# test profile at opt-level 3: the same images as a release build, which
# python/tests/test_cli.py checks either way), else a release build.
if [[ -z "${FVR_BIN:-}" ]]; then
    cargo build --locked --release --quiet -p fvr-host --bin fvr
    FVR_BIN="$PWD/target/release/fvr"
fi
FVR_BIN="$FVR_BIN" "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
