#!/usr/bin/env bash
# The Python package's tests (python/tests): a venv in target/py-venv with
# pinned maturin, numpy and pytest from PyPI, the extension built into it by
# `maturin develop --release` in the workspace's target dir (the release
# dependencies are shared with the `fvr` binary built next, which the
# bit-for-bit tests run), then pytest.
# Usage: bash scripts/test-python.sh      (run by scripts/test-all.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

venv=target/py-venv
if [[ ! -x "$venv/bin/python" ]]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    maturin==1.16.0 numpy==2.4.6 pytest==9.2.0

# maturin builds in the workspace's target/ (python/ is a workspace member);
# its output is shown only when it fails.
log="$PWD/target/py-build.log"
if ! (cd python && VIRTUAL_ENV="$PWD/../$venv" PATH="$PWD/../$venv/bin:$PATH" \
    maturin develop --release --locked > "$log" 2>&1); then
    cat "$log"
    exit 1
fi
"$venv/bin/python" -c "import fvr, sys; sys.exit(0 if fvr.Renderer else 1)"

cargo build --locked --release --quiet -p fvr-host --bin fvr
FVR_BIN="$PWD/target/release/fvr" "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
