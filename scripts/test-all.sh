#!/usr/bin/env bash
# Runs every test of the project, installing what the tests need first.
# Usage: bash scripts/test-all.sh
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== toolchain: thumbv7em-none-eabihf target (the core must build for Cortex-M4F)"
rustup target add thumbv7em-none-eabihf

echo "== data: the InVesalius CT head (GPL-2: installed from Debian, never committed)"
FVR_CT_HEAD="$(bash scripts/fetch-ct-head.sh)"
export FVR_CT_HEAD

echo "== data: an MRI head (MNI152 T1 from nilearn's PyPI wheel: fetched into target/, never committed)"
FVR_MRI_HEAD="$(bash scripts/fetch-mri-head.sh)"
export FVR_MRI_HEAD

echo "== no_std core for thumbv7em-none-eabihf"
cargo build --locked -p fvr-core --target thumbv7em-none-eabihf --release

echo "== layout: no fast_ files, none over 700 lines, no import cycle in the engine"
python3 scripts/check-layout.py

echo "== lints"
cargo fmt --all -- --check
cargo clippy --locked --workspace --all-targets -- -D warnings

echo "== tests (workspace)"
cargo test --locked --workspace

# The benches build with the tests' profile, reusing the build above: in
# the bench profile every dependency compiled again took 8 of a fresh
# clone's 26 minutes.
echo "== benchmarks compile"
cargo test --locked -p fvr-host --benches --no-run

echo "== Python package (python/): a venv in target/, maturin develop --release, pytest"
# The fvr binary `cargo test --workspace` built above (test profile) is the
# CLI the package is compared with bit for bit: no second build of it.
FVR_BIN="$PWD/target/debug/fvr" bash scripts/test-python.sh

# Their output is kept for the docs' check below, which reads the figures
# from it instead of running them again.
echo "== firmware on a Cortex-M4F in QEMU: bit-for-bit agreement, instruction counts, footprint, budget"
bash scripts/firmware.sh 2>&1 | tee target/firmware.log

echo "== C API: fvr prepare --emit c, the header with -Werror, a host C program, the C firmware example in QEMU bit for bit"
bash scripts/capi.sh 2>&1 | tee target/capi.log

# The quick deterministic figures only (docs/testing.md says how to check
# and regenerate the rest); the fvr of the test build above.
echo "== docs: the figures of README.md, docs/ and firmware/README.md as the program prints them"
FVR="$PWD/target/debug/fvr" DOCS_FIGURES_FIRMWARE_LOG=target/firmware.log DOCS_FIGURES_CAPI_LOG=target/capi.log \
    bash scripts/docs-figures.sh --check --quick

# target/debug/fvr is the binary `cargo test` built above for the
# integration tests (test profile, optimized): a release build, or even
# `cargo build --profile test`, would compile fvr-host again (9 minutes here).
echo "== browser viewer: wasm32 + SIMD128 build, then fvr view in headless Chromium (Debian's)"
bash scripts/web.sh
command -v chromium >/dev/null || { apt-get update -qq && apt-get install -y -qq chromium >/dev/null; }
python3 scripts/web-test.py --fvr target/debug/fvr
